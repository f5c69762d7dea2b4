//! The rotations of the deflection: the elastic angle's bound, a virtual joint's small turn
//! (Eq. 4) and the rotation vector of a nearly identical pair of poses, with series that are
//! exact to rounding for the small angles of a stiff arm.

use nalgebra::{UnitQuaternion, Vector3};

/// Largest elastic angle of a virtual joint the deflection accepts \[rad\]: 0.5 rad (29 deg). Real
/// robots turn their springs by milliradians; a load that turns one by more is far outside
/// the small-deflection model of Eq. 5-7 (which takes the moments in the undeformed pose), and
/// its "deflection" would be garbage (or NaN for loads near `f64::MAX`), so it is refused.
pub const MAX_SPRING_ANGLE: f64 = 0.5;

/// `(sin x, cos x)`. Elastic angles are tiny (1e-6..1e-3 rad): below 0.01 rad a Taylor series
/// to x^7 / x^6 is exact to rounding (the next terms, x^9 / 9! and x^8 / 8!, are below 3e-21
/// relative) and several times cheaper than the library call; the lanes of
/// [`super::turns`] evaluate the same series. Multiplications by the reciprocal factorial
/// ratios, not divisions: a chain of divisions would dominate the deflection's latency.
#[inline]
fn sin_cos_small(x: f64) -> (f64, f64) {
    const R6: f64 = 1.0 / 6.0;
    const R20: f64 = 1.0 / 20.0;
    const R42: f64 = 1.0 / 42.0;
    const R12: f64 = 1.0 / 12.0;
    const R30: f64 = 1.0 / 30.0;
    if x.abs() < 1.0e-2 {
        let x2 = x * x;
        let s = x * (1.0 - x2 * R6 * (1.0 - x2 * R20 * (1.0 - x2 * R42)));
        let c = 1.0 - x2 * 0.5 * (1.0 - x2 * R12 * (1.0 - x2 * R30));
        (s, c)
    } else {
        (
            nalgebra::ComplexField::sin(x),
            nalgebra::ComplexField::cos(x),
        )
    }
}

/// The rotation vector (axis times angle, in [0, pi]) of the unit quaternion `q`, as
/// nalgebra's `scaled_axis`, with a series for small rotations instead of an arctangent: with
/// `t = |v| / w` below 1e-2 (rotations below 1.1 deg),
/// `2 atan(t) / |v| = (2 / w) (1 - t^2/3 + t^4/5 - t^6/7 + t^8/9 - t^10/11)` to rounding (the
/// next term is below 1e-25). The kernels compare nearly equal rotations (deflected against
/// rigid TCP, loaded pose against target) every tick; a milling load turns the KR 300's TCP
/// by about 1e-3 rad, past the series' old bound of 1e-4.
#[inline]
pub(crate) fn rotation_vector(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    const R3: f64 = 1.0 / 3.0;
    const R5: f64 = 1.0 / 5.0;
    const R7: f64 = 1.0 / 7.0;
    const R9: f64 = 1.0 / 9.0;
    const R11: f64 = 1.0 / 11.0;
    let (w, v) = (q.scalar(), q.imag());
    // q and -q are the same rotation: take the one with w >= 0 (angle <= pi).
    let (w, v) = if w < 0.0 { (-w, -v) } else { (w, v) };
    let n2 = v.norm_squared();
    if w > 0.0 && n2 < 1.0e-4 * w * w {
        let t2 = n2 / (w * w);
        let series = 1.0 - t2 * (R3 - t2 * (R5 - t2 * (R7 - t2 * (R9 - t2 * R11))));
        v * (2.0 / w * series)
    } else {
        q.scaled_axis()
    }
}

/// `Rz(gamma) Ry(beta) Rx(alpha)` as a unit quaternion (Eq. 4; nalgebra's
/// `from_euler_angles(alpha, beta, gamma)`), from half-angle sines and cosines.
#[inline]
pub(super) fn euler_zyx(alpha: f64, beta: f64, gamma: f64) -> UnitQuaternion<f64> {
    let (sr, cr) = sin_cos_small(alpha * 0.5);
    let (sp, cp) = sin_cos_small(beta * 0.5);
    let (sy, cy) = sin_cos_small(gamma * 0.5);
    UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_zyx_equals_nalgebra_small_and_large() {
        for &(a, b, g) in &[
            (1e-4, -2e-5, 3e-4),
            (0.009, -0.0099, 0.005),
            (0.3, -1.2, 2.5),
            (0.0, 0.0, 0.0),
            (0.02, 0.019, -0.021),
        ] {
            let ours = euler_zyx(a, b, g);
            let theirs = UnitQuaternion::from_euler_angles(a, b, g);
            assert!(ours.angle_to(&theirs) < 1e-15, "{a} {b} {g}");
            assert!((ours.coords - theirs.coords).amax() < 2e-16, "{a} {b} {g}");
            assert!((ours.quaternion().norm() - 1.0).abs() < 1e-15);
        }
        for i in -1000..=1000 {
            let x = i as f64 * 1.0e-5; // up to 0.01, both branches
            let (s, c) = sin_cos_small(x);
            assert!(
                (s - x.sin()).abs() <= 1e-18 + 2.0 * f64::EPSILON * x.abs(),
                "{x}"
            );
            assert!((c - x.cos()).abs() <= 2.0 * f64::EPSILON, "{x}");
        }
    }

    #[test]
    fn rotation_vector_equals_nalgebra() {
        for v in [
            Vector3::new(1e-9, -2e-9, 3e-10),
            Vector3::new(1e-5, 2e-5, -3e-5),
            Vector3::new(3e-3, 0.0, 0.0),
            Vector3::new(1.5e-2, -0.9e-2, 0.4e-2),
            Vector3::new(0.0, 1.99e-2, 0.0),
            Vector3::new(0.0, 2.01e-2, 0.0),
            Vector3::new(0.1, -0.2, 0.3),
            Vector3::new(0.0, 3.1, 0.0),
            Vector3::zeros(),
        ] {
            let q = UnitQuaternion::from_scaled_axis(v);
            for q in [q, UnitQuaternion::new_unchecked(-q.into_inner())] {
                let ours = rotation_vector(&q);
                let theirs = q.scaled_axis();
                assert!(
                    (ours - theirs).amax() <= 4.0 * f64::EPSILON * v.amax().max(1e-300),
                    "{v:?}: {ours:?} vs {theirs:?}"
                );
            }
        }
    }
}
