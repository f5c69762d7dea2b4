//! The rigid chain's compositions, specialised at build for what URDF chains mostly are:
//! joints about a coordinate axis (`<axis xyz="0 0 1"/>`) and fixed transforms without
//! rotation (`rpy="0 0 0"`). A rotation about a coordinate axis is a quaternion with two
//! zero entries, and a composition with the identity rotation is a copy: skipping the
//! products with exact zeros and ones gives nalgebra's general results bit for bit (the
//! sums keep their order; only the sign of a zero may differ) at half the arithmetic of the
//! rigid pass (perf: the pass was a third to a half of `deflection` and `compliance`).

use nalgebra::{Isometry3, Quaternion, Unit, UnitQuaternion, Vector3};

/// The axis a joint moves about or along, as the rigid pass uses it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum AxisKind {
    /// `+x` exactly.
    X,
    /// `+y` exactly.
    Y,
    /// `+z` exactly.
    Z,
    /// Any other unit axis.
    Other,
}

impl AxisKind {
    pub(crate) fn of(axis: &Unit<Vector3<f64>>) -> Self {
        let a = axis.as_ref();
        match (a.x, a.y, a.z) {
            (1.0, 0.0, 0.0) => Self::X,
            (0.0, 1.0, 0.0) => Self::Y,
            (0.0, 0.0, 1.0) => Self::Z,
            _ => Self::Other,
        }
    }
}

/// What a fixed transform does, decided once at build: how it rotates and whether it
/// translates (a spring placed at a joint's own frame only rotates; `rpy="0 0 0"` only
/// translates).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Shape {
    pub turn: Turn,
    pub shifts: bool,
}

/// How a fixed transform rotates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Turn {
    /// Not at all.
    None,
    /// About a coordinate axis (`rpy` with one non-zero angle, the usual URDF case; the axis
    /// as [`AxisKind`], never `Other`).
    Axis(AxisKind),
    /// Any other rotation.
    General,
}

impl Shape {
    pub(crate) fn of(t: &Isometry3<f64>) -> Self {
        let q = &t.rotation;
        let turn = if q.coords == UnitQuaternion::identity().coords {
            Turn::None
        } else {
            match (q.i != 0.0, q.j != 0.0, q.k != 0.0) {
                (true, false, false) => Turn::Axis(AxisKind::X),
                (false, true, false) => Turn::Axis(AxisKind::Y),
                (false, false, true) => Turn::Axis(AxisKind::Z),
                _ => Turn::General,
            }
        };
        Self {
            turn,
            shifts: t.translation.vector != Vector3::zeros(),
        }
    }
}

/// `frame * t` for `t` of the given shape, without the products by zeros and ones: bit for
/// bit nalgebra's product (the rotation, and the translation `frame.rotation * t.translation`
/// added to the frame's).
#[inline(always)]
pub(crate) fn compose(frame: &Isometry3<f64>, t: &Isometry3<f64>, shape: Shape) -> Isometry3<f64> {
    let rotation = match shape.turn {
        Turn::None => frame.rotation,
        Turn::Axis(kind) => {
            let s = match kind {
                AxisKind::X => t.rotation.i,
                AxisKind::Y => t.rotation.j,
                AxisKind::Z => t.rotation.k,
                AxisKind::Other => 0.0, // not built: `Shape::of` names X, Y or Z only
            };
            match coordinate_turn(&frame.rotation, kind, s, t.rotation.w) {
                Some(q) => UnitQuaternion::new_unchecked(q),
                None => frame.rotation * t.rotation,
            }
        }
        Turn::General => frame.rotation * t.rotation,
    };
    let translation = if shape.shifts {
        frame.translation.vector + frame.rotation * t.translation.vector
    } else {
        frame.translation.vector
    };
    Isometry3::from_parts(translation.into(), rotation)
}

/// `r * e`, `e = [c, s axis]` the joint's rotation by an angle with half-angle sine `s` and
/// cosine `c`: nalgebra's quaternion product with the zero terms of a coordinate axis left out.
#[inline(always)]
pub(crate) fn turn(
    r: &UnitQuaternion<f64>,
    kind: AxisKind,
    axis: &Unit<Vector3<f64>>,
    s: f64,
    c: f64,
) -> UnitQuaternion<f64> {
    match coordinate_turn(r, kind, s, c) {
        Some(q) => UnitQuaternion::new_unchecked(q),
        None => r * UnitQuaternion::new_unchecked(Quaternion::from_parts(c, axis.as_ref() * s)),
    }
}

/// [`turn`] about a coordinate axis; `None` for [`AxisKind::Other`].
#[inline(always)]
fn coordinate_turn(
    r: &UnitQuaternion<f64>,
    kind: AxisKind,
    s: f64,
    c: f64,
) -> Option<Quaternion<f64>> {
    let (w, x, y, z) = (r.w, r.i, r.j, r.k);
    Some(match kind {
        AxisKind::X => Quaternion::new(w * c - x * s, w * s + x * c, y * c + z * s, z * c - y * s),
        AxisKind::Y => Quaternion::new(w * c - y * s, x * c - z * s, w * s + y * c, x * s + z * c),
        AxisKind::Z => Quaternion::new(w * c - z * s, x * c + y * s, y * c - x * s, w * s + z * c),
        AxisKind::Other => return None,
    })
}

/// `r * axis` (the joint's axis in world axes): nalgebra's vector rotation
/// (`t = 2 v x a`, `a + w t + v x t`) with the zero terms of a coordinate axis left out.
#[inline(always)]
pub(crate) fn rotate_axis(
    r: &UnitQuaternion<f64>,
    kind: AxisKind,
    axis: &Unit<Vector3<f64>>,
) -> Vector3<f64> {
    let (w, x, y, z) = (r.w, r.i, r.j, r.k);
    match kind {
        AxisKind::X => {
            // t = 2 (0, z, -y)
            let (ty, tz) = (z * 2.0, -y * 2.0);
            Vector3::new(y * tz - z * ty + 1.0, ty * w - x * tz, tz * w + x * ty)
        }
        AxisKind::Y => {
            // t = 2 (-z, 0, x)
            let (tx, tz) = (-z * 2.0, x * 2.0);
            Vector3::new(tx * w + y * tz, z * tx - x * tz + 1.0, tz * w - y * tx)
        }
        AxisKind::Z => {
            // t = 2 (y, -x, 0)
            let (tx, ty) = (y * 2.0, -x * 2.0);
            Vector3::new(tx * w - z * ty, ty * w + z * tx, x * ty - y * tx + 1.0)
        }
        AxisKind::Other => r * axis.into_inner(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specialised_compositions_are_nalgebras_bit_for_bit() {
        let r = UnitQuaternion::from_euler_angles(0.3, -1.1, 2.4);
        let t = Isometry3::translation(0.3, -0.2, 1.7);
        let f = Isometry3::from_parts(Vector3::new(1.0, 2.0, -0.5).into(), r);
        let turn_only = Isometry3::from_parts(Vector3::zeros().into(), r);
        let check = |t: Isometry3<f64>| {
            let general = f * t;
            let fast = compose(&f, &t, Shape::of(&t));
            assert_eq!(general.translation.vector, fast.translation.vector);
            assert_eq!(
                general.rotation.coords,
                fast.rotation.coords,
                "{:?}",
                Shape::of(&t)
            );
        };
        for t in [t, turn_only, Isometry3::identity(), f] {
            check(t);
        }
        // URDF's usual rotations: one non-zero rpy angle, with and without a translation.
        for angle in [
            core::f64::consts::FRAC_PI_2,
            -core::f64::consts::FRAC_PI_2,
            0.3,
            3.0,
        ] {
            for axis in [Vector3::x_axis(), Vector3::y_axis(), Vector3::z_axis()] {
                let q = UnitQuaternion::from_axis_angle(&axis, angle);
                check(Isometry3::from_parts(Vector3::zeros().into(), q));
                check(Isometry3::from_parts(
                    Vector3::new(0.1, -0.4, 0.25).into(),
                    q,
                ));
            }
        }
        let about_x = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -1.0);
        let shifted = Isometry3::from_parts(Vector3::new(0.0, 0.0, 0.2).into(), about_x);
        assert_eq!(
            Shape::of(&shifted),
            Shape {
                turn: Turn::Axis(AxisKind::X),
                shifts: true
            }
        );
        let about_z = Isometry3::from_parts(
            Vector3::zeros().into(),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.5),
        );
        assert_eq!(
            Shape::of(&about_z),
            Shape {
                turn: Turn::Axis(AxisKind::Z),
                shifts: false
            }
        );
        for (axis, kind) in [
            (Vector3::x_axis(), AxisKind::X),
            (Vector3::y_axis(), AxisKind::Y),
            (Vector3::z_axis(), AxisKind::Z),
        ] {
            assert_eq!(AxisKind::of(&axis), kind);
            for a in [-2.9, -0.4, 0.0, 0.7, 3.1] {
                let (s, c) = super::super::trig::sin_cos(a * 0.5);
                let e = UnitQuaternion::new_unchecked(Quaternion::from_parts(c, axis.as_ref() * s));
                let general = r * e;
                let fast = turn(&r, kind, &axis, s, c);
                for (g, v) in general.coords.iter().zip(fast.coords.iter()) {
                    assert_eq!(
                        g.to_bits() & !(1 << 63),
                        v.to_bits() & !(1 << 63),
                        "{kind:?} {a}"
                    );
                    assert!(g == v, "{kind:?} {a}");
                }
            }
            let general = r * axis.into_inner();
            let fast = rotate_axis(&r, kind, &axis);
            assert_eq!(general, fast, "{kind:?}");
        }
        let other = Unit::new_normalize(Vector3::new(0.0, 0.0, -1.0));
        assert_eq!(AxisKind::of(&other), AxisKind::Other);
        assert_eq!(
            Shape::of(&t),
            Shape {
                turn: Turn::None,
                shifts: true
            }
        );
        assert_eq!(
            Shape::of(&f),
            Shape {
                turn: Turn::General,
                shifts: true
            }
        );
    }
}
