//! The springs' loads (Eq. 5-7), turns (Eq. 3-4, 8) and first-order sums, four springs at a
//! time in the lanes of [`super::lanes`], in one pass over the springs.
//!
//! The deflected chain of Eq. 8 is `T = Q_1 ... Q_n T_tcp`, `Q_k` the turn of spring `k` about
//! its origin `o_k` (`x -> q_k (x - o_k) + o_k`, `q_k` the rotation of Eq. 4 in world axes).
//! Taken relative to the rigid TCP (`x' = x - p_tcp`), `Q_k` becomes the small motion
//! `(q_k, q_k L_k - L_k)` with the lever `L_k = p_tcp - o_k`, and `q_k L_k - L_k` is computed
//! without forming `q_k L_k` (no cancellation of metre-sized terms). The TCP's deflection is
//! then the translation of the product `Q'_1 ... Q'_n` and the rotation vector of its rotation,
//! each accurate relative to the deflection itself rather than to the arm's size.
//!
//! Lane `g` takes the `g`-th run of `ceil(n / 4)` consecutive springs, and step `c` of the pass
//! spring `g ceil(n / 4) + c` of each run: the loads and turns of four springs at once, and the
//! product as four independent runs (combined at the end) instead of one dependency chain
//! through all springs.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

use super::lanes::{Arith, LaneKernel, Lanes, V4, dispatch};
use super::rotation::{MAX_SPRING_ANGLE, euler_zyx, rotation_vector};
use super::{Data, Model, Vector6};
use crate::error::TickError;

/// Below this elastic angle \[rad\] (half-angle 1e-2) the turns' sines and cosines are the
/// series of the deflection's `sin_cos_small`; with a spring turned further the turns are
/// formed one by one with the library's.
pub(super) const SERIES_ANGLE: f64 = 2.0e-2;

/// Lane-wise `a * s` for a vector of lanes and one lane value.
#[inline(always)]
fn scale<V: Copy + core::ops::Mul<Output = V>>(a: V4<V>, s: V) -> V4<V> {
    V4 {
        x: a.x * s,
        y: a.y * s,
        z: a.z * s,
    }
}

#[inline(always)]
fn add<V: Copy + core::ops::Add<Output = V>>(a: V4<V>, b: V4<V>) -> V4<V> {
    V4 {
        x: a.x + b.x,
        y: a.y + b.y,
        z: a.z + b.z,
    }
}

#[inline(always)]
fn sub<V: Copy + core::ops::Sub<Output = V>>(a: V4<V>, b: V4<V>) -> V4<V> {
    V4 {
        x: a.x - b.x,
        y: a.y - b.y,
        z: a.z - b.z,
    }
}

/// Four vectors as lanes.
#[inline(always)]
fn load3<L: Lanes>(l: L, v: [Vector3<f64>; 4]) -> V4<L::V> {
    V4 {
        x: l.load(v.map(|v| v.x)),
        y: l.load(v.map(|v| v.y)),
        z: l.load(v.map(|v| v.z)),
    }
}

/// One vector in every lane.
#[inline(always)]
pub(super) fn splat3<L: Lanes>(l: L, v: &Vector3<f64>) -> V4<L::V> {
    V4 {
        x: l.splat(v.x),
        y: l.splat(v.y),
        z: l.splat(v.z),
    }
}

/// Writes lane `g` of `v` into `out[k_g]` for the springs `k_g` in `at`.
#[inline(always)]
fn scatter<L: Lanes>(l: L, v: V4<L::V>, out: &mut [Vector3<f64>], at: [Option<usize>; 4]) {
    let (x, y, z) = (l.store(v.x), l.store(v.y), l.store(v.z));
    for (g, k) in at.into_iter().enumerate() {
        if let Some(k) = k
            && let (Some(slot), Some(x), Some(y), Some(z)) =
                (out.get_mut(k), x.get(g), y.get(g), z.get(g))
        {
            *slot = Vector3::new(*x, *y, *z);
        }
    }
}

/// The largest elastic angle of any spring \[rad\]; [`TickError::InvalidArgument`] for the first
/// spring (chain order) turned past [`MAX_SPRING_ANGLE`] or by NaN (moments overflowing): the
/// one guard of the small-deflection model.
pub(super) fn check_angles(model: &Model, data: &Data) -> Result<f64, TickError> {
    let mut all = 0.0_f64;
    for a in data.spring_angles.iter().take(model.springs) {
        let largest = a.amax();
        if largest.is_nan() || largest > MAX_SPRING_ANGLE {
            return Err(TickError::InvalidArgument {
                what: "load (an elastic angle exceeds MAX_SPRING_ANGLE, outside the \
                       small-deflection model)",
                value: largest,
            });
        }
        all = all.max(largest);
    }
    Ok(all)
}

/// `(sin x, cos x)` by the series of `sin_cos_small` (to x^7 / x^6, the same operations), lane
/// by lane: exact to rounding for |x| < 1e-2.
#[inline(always)]
fn sin_cos_series<L: Lanes>(l: L, x: L::V) -> (L::V, L::V) {
    let k = |v: f64| l.splat(v);
    let one = k(1.0);
    let x2 = x * x;
    let s = x * (one - x2 * k(1.0 / 6.0) * (one - x2 * k(1.0 / 20.0) * (one - x2 * k(1.0 / 42.0))));
    let c = one - x2 * k(0.5) * (one - x2 * k(1.0 / 12.0) * (one - x2 * k(1.0 / 30.0)));
    (s, c)
}

/// The turn of one spring relative to the rigid TCP at `p` (see the module): `q = F e F^-1`
/// with `e` the rotation of Eq. 4 from the spring's angles `a` and `F` its world frame, and the
/// translation `q L - L`, `L = p - o`. The scalar twin of [`Frames4::turn`], for springs
/// turned past the series' range.
fn turn_of(f: &Isometry3<f64>, a: &Vector3<f64>, p: &Vector3<f64>) -> Isometry3<f64> {
    let e = euler_zyx(a.x, a.y, a.z);
    let v = f.rotation * e.imag();
    let lever = p - f.translation.vector;
    let t = v.cross(&lever) * 2.0;
    let shift = t * e.scalar() + v.cross(&t);
    Isometry3::from_parts(
        Translation3::from(shift),
        UnitQuaternion::new_unchecked(Quaternion::from_parts(e.scalar(), v)),
    )
}

/// A rigid motion in four lanes: rotation `w`, `u` (vector part) and translation `t`.
#[derive(Clone, Copy)]
pub(super) struct Motion4<V> {
    pub(super) w: V,
    pub(super) u: V4<V>,
    pub(super) t: V4<V>,
}

impl<V: Arith> Motion4<V> {
    /// `self * o`, lane by lane: `(q_a q_b, t_a + q_a t_b)`, the quaternion product and the
    /// rotation in nalgebra's order of operations.
    #[inline(always)]
    pub(super) fn then(self, o: Self, two: V) -> Self {
        let (a, b) = (self, o);
        let w = a.w * b.w - a.u.x * b.u.x - a.u.y * b.u.y - a.u.z * b.u.z;
        let u = V4 {
            x: a.w * b.u.x + a.u.x * b.w + a.u.y * b.u.z - a.u.z * b.u.y,
            y: a.w * b.u.y - a.u.x * b.u.z + a.u.y * b.w + a.u.z * b.u.x,
            z: a.w * b.u.z + a.u.x * b.u.y - a.u.y * b.u.x + a.u.z * b.w,
        };
        let r = scale(a.u.cross(b.t), two);
        let rc = a.u.cross(r);
        let t = add(a.t, add(add(scale(r, a.w), rc), b.t));
        Self { w, u, t }
    }
}

/// The rigid world frames of four springs as lanes: rotation `w`, `u` and origin `o`.
#[derive(Clone, Copy)]
pub(super) struct Frames4<V> {
    pub(super) w: V,
    pub(super) u: V4<V>,
    pub(super) o: V4<V>,
}

impl<V: Arith> Frames4<V> {
    /// The vector `v` (world axes) in the frames' axes, `R^T v`: nalgebra's rotation by the
    /// conjugate `(w, -u)`, `(t' w + (-u) x t') + v` with `t' = 2 (-u) x v`, written with
    /// `t = 2 u x v` as `(u x t - t w) + v` (the same bits).
    #[inline(always)]
    pub(super) fn local(&self, v: V4<V>, two: V) -> V4<V> {
        let t = scale(self.u.cross(v), two);
        add(sub(self.u.cross(t), scale(t, self.w)), v)
    }

    /// Eq. 5-7 for the four springs: the moment `m = M + L x F` of the TCP's force `F` and
    /// moment `M` on a spring with lever `L` (TCP minus the spring's origin, world axes), and
    /// its angles `c * (R^T m)` for the compliances `c`.
    #[inline(always)]
    pub(super) fn loads(
        &self,
        lever: V4<V>,
        force: V4<V>,
        moment: V4<V>,
        c: V4<V>,
        two: V,
    ) -> (V4<V>, V4<V>) {
        let m = add(moment, lever.cross(force));
        let local = self.local(m, two);
        let a = V4 {
            x: c.x * local.x,
            y: c.y * local.y,
            z: c.z * local.z,
        };
        (m, a)
    }

    /// The vector `v` (the frames' axes) in world axes, `R v`: nalgebra's
    /// `(t w + u x t) + v`, `t = 2 u x v`.
    #[inline(always)]
    pub(super) fn world(&self, v: V4<V>, two: V) -> V4<V> {
        let t = scale(self.u.cross(v), two);
        add(add(scale(t, self.w), self.u.cross(t)), v)
    }

    /// The turns of the four springs by the angles `a` relative to the rigid TCP at `p`, with
    /// the series' sines (all angles below [`SERIES_ANGLE`]): the lanes of [`turn_of`].
    #[inline(always)]
    pub(super) fn turn<L: Lanes<V = V>>(&self, l: L, a: V4<V>, p: V4<V>, two: V) -> Motion4<V> {
        let half = l.splat(0.5);
        // Eq. 4, `Rz(gamma) Ry(beta) Rx(alpha)` from the half-angles (as `euler_zyx`, the
        // same operations).
        let (sr, cr) = sin_cos_series(l, a.x * half);
        let (sp, cp) = sin_cos_series(l, a.y * half);
        let (sy, cy) = sin_cos_series(l, a.z * half);
        let ew = cr * cp * cy + sr * sp * sy;
        let e = V4 {
            x: sr * cp * cy - cr * sp * sy,
            y: cr * sp * cy + sr * cp * sy,
            z: cr * cp * sy - sr * sp * cy,
        };
        // F e F^-1: the vector part turned by F.
        let v = self.world(e, two);
        // q L - L without q L: `t2 ew + v x t2`, `t2 = 2 v x L`.
        let t2 = scale(v.cross(sub(p, self.o)), two);
        Motion4 {
            w: ew,
            u: v,
            t: add(scale(t2, ew), v.cross(t2)),
        }
    }
}

/// One pass over the springs in lanes: with `LOADS`, the moments and angles of the TCP wrench
/// (into `data` with `KEEP`), else the angles already in `data`; with `EXACT`, the four runs'
/// products of the turns (lanes of `w, u.x, u.y, u.z, t.x, t.y, t.z`), else the first-order
/// sums `sum_s [theta_s x L_s; theta_s]` (lanes of the six components; the seventh is zero
/// with `KEEP`, else each lane's largest `|angle|`, in place of [`check_angles`]' pass over
/// the angles in `data`).
struct Springs<'a, const LOADS: bool, const EXACT: bool, const KEEP: bool> {
    model: &'a Model,
    data: &'a mut Data,
    p: Vector3<f64>,
    force: Vector3<f64>,
    moment: Vector3<f64>,
}

impl<const LOADS: bool, const EXACT: bool, const KEEP: bool> LaneKernel
    for Springs<'_, LOADS, EXACT, KEEP>
{
    type Output = [[f64; 4]; 7];
    #[inline(always)]
    fn run<L: Lanes>(self, l: L) -> [[f64; 4]; 7] {
        let Self {
            model,
            data,
            p,
            force,
            moment,
        } = self;
        let n = model.springs;
        let run = n.div_ceil(4);
        let (p, force, moment) = (splat3(l, &p), splat3(l, &force), splat3(l, &moment));
        let (zero, one, two) = (l.splat(0.0), l.splat(1.0), l.splat(2.0));
        let none = V4 {
            x: zero,
            y: zero,
            z: zero,
        };
        let mut product = Motion4 {
            w: one,
            u: none,
            t: none,
        };
        let (mut lin, mut rot) = (none, none);
        let mut largest = zero;
        let identity = Isometry3::identity();
        let still = Vector3::zeros();
        for c in 0..run {
            // Spring g run + c of each run; past the count, an identity frame, no
            // compliance and no angle (no moment, no turn: the identity motion, exactly).
            let at = [0, 1, 2, 3].map(|g| Some(g * run + c).filter(|k| *k < n));
            let pick = |table: &[Vector3<f64>]| {
                at.map(|k| k.and_then(|k| table.get(k)).copied().unwrap_or(still))
            };
            let fs = at.map(|k| {
                k.and_then(|k| data.spring_frames.get(k))
                    .unwrap_or(&identity)
            });
            let q = fs.map(|f| f.rotation.coords);
            let frames = Frames4 {
                w: l.load(q.map(|v| v.w)),
                u: load3(l, q.map(|v| v.xyz())),
                o: load3(l, fs.map(|f| f.translation.vector)),
            };
            let lever = sub(p, frames.o);
            let a = if LOADS {
                let c = load3(l, pick(&model.spring_compliance));
                let (m, a) = frames.loads(lever, force, moment, c, two);
                if KEEP {
                    scatter(l, m, &mut data.spring_moments, at);
                    scatter(l, a, &mut data.spring_angles, at);
                }
                a
            } else {
                load3(l, pick(&data.spring_angles))
            };
            if EXACT {
                product = product.then(frames.turn(l, a, p, two), two);
            } else {
                // theta = R a, the world rotation vector; its translation theta x L.
                let theta = frames.world(a, two);
                lin = add(lin, theta.cross(lever));
                rot = add(rot, theta);
                if !KEEP {
                    let most = l.max(l.abs(a.x), l.max(l.abs(a.y), l.abs(a.z)));
                    largest = l.max(largest, most);
                }
            }
        }
        let s = |v: L::V| l.store(v);
        if EXACT {
            let (w, u, t) = (product.w, product.u, product.t);
            [s(w), s(u.x), s(u.y), s(u.z), s(t.x), s(t.y), s(t.z)]
        } else {
            [
                s(lin.x),
                s(lin.y),
                s(lin.z),
                s(rot.x),
                s(rot.y),
                s(rot.z),
                s(largest),
            ]
        }
    }
}

/// Runs [`Springs`] for the TCP at `tcp`, with the TCP `wrench`'s loads or (`None`) the angles
/// in `data`; with `KEEP`, the loads' moments and angles stored in `data`.
fn springs<const EXACT: bool, const KEEP: bool>(
    model: &Model,
    data: &mut Data,
    tcp: &Isometry3<f64>,
    wrench: Option<&Vector6>,
) -> [[f64; 4]; 7] {
    let p = tcp.translation.vector;
    match wrench {
        Some(w) => dispatch(Springs::<true, EXACT, KEEP> {
            model,
            data,
            p,
            force: Vector3::new(w[0], w[1], w[2]),
            moment: Vector3::new(w[3], w[4], w[5]),
        }),
        None => dispatch(Springs::<false, EXACT, KEEP> {
            model,
            data,
            p,
            force: Vector3::zeros(),
            moment: Vector3::zeros(),
        }),
    }
}

/// The exact deflection (Eq. 8-9) of the TCP at `tcp` from the rigid frames of the last pass:
/// under the TCP `wrench` (its moments and angles into `data`), or (`None`) from the angles in
/// `data`. The deflection `[dp; dr]` and the deflected pose; [`check_angles`]' error.
pub(super) fn exact(
    model: &Model,
    data: &mut Data,
    tcp: &Isometry3<f64>,
    wrench: Option<&Vector6>,
) -> Result<(Vector6, Isometry3<f64>), TickError> {
    let [w, x, y, z, tx, ty, tz] = springs::<true, true>(model, data, tcp, wrench);
    let largest = check_angles(model, data)?;
    let p = tcp.translation.vector;
    let total = if largest < SERIES_ANGLE {
        let run = |g: usize| {
            let at = |v: [f64; 4]| v.get(g).copied().unwrap_or(0.0);
            Isometry3::from_parts(
                Translation3::new(at(tx), at(ty), at(tz)),
                UnitQuaternion::new_unchecked(Quaternion::new(at(w), at(x), at(y), at(z))),
            )
        };
        (run(0) * run(1)) * (run(2) * run(3))
    } else {
        // A spring past the series' range (rare: 0.02 rad is a large elastic angle): the
        // turns one by one, with the library's sines.
        let springs = data.spring_frames.iter().zip(data.spring_angles.iter());
        springs
            .take(model.springs)
            .fold(Isometry3::identity(), |t, (f, a)| t * turn_of(f, a, &p))
    };
    let dp = total.translation.vector;
    let dr = rotation_vector(&total.rotation);
    let deflected = Isometry3::from_parts((p + dp).into(), total.rotation * tcp.rotation);
    Ok((Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z), deflected))
}

/// The first-order deflection `sum_s [theta_s x (p_tcp - o_s); theta_s]` of the TCP at `tcp`,
/// `theta_s = R_s a_s` the world rotation vector of spring `s` about its origin `o_s`, under
/// the TCP `wrench` (its moments and angles into `data`; then the deflection is `C(q) w`) or
/// (`None`) from the angles in `data`; [`check_angles`]' error.
pub(super) fn linear(
    model: &Model,
    data: &mut Data,
    tcp: &Isometry3<f64>,
    wrench: Option<&Vector6>,
) -> Result<Vector6, TickError> {
    let sums = springs::<false, true>(model, data, tcp, wrench);
    check_angles(model, data)?;
    Ok(first_order(sums).0)
}

/// The first-order sums' lanes added up (`((l0 + l1) + l2) + l3`): the deflection, and the
/// seventh row's largest lane (the largest elastic angle without `KEEP`).
fn first_order(sums: [[f64; 4]; 7]) -> (Vector6, f64) {
    let total = |v: [f64; 4]| {
        let [a, b, c, d] = v;
        ((a + b) + c) + d
    };
    let [x, y, z, rx, ry, rz, largest] = sums;
    let d = Vector6::new(
        total(x),
        total(y),
        total(z),
        total(rx),
        total(ry),
        total(rz),
    );
    (d, largest.into_iter().fold(0.0_f64, f64::max))
}

/// [`linear`] under the TCP `wrench` without storing the springs' moments and angles: the
/// same deflection bit for bit, with the largest elastic angle taken in the lanes. A load
/// [`linear`] or the caller's output check would refuse (an angle past [`MAX_SPRING_ANGLE`]
/// or NaN, a non-finite sum) is passed through [`linear`] again, which returns that error
/// (or the non-finite value the caller refuses).
pub(super) fn linear_alone(
    model: &Model,
    data: &mut Data,
    tcp: &Isometry3<f64>,
    wrench: &Vector6,
) -> Result<Vector6, TickError> {
    let (d, largest) = first_order(springs::<false, false>(model, data, tcp, Some(wrench)));
    // A NaN angle makes every sum NaN (it enters each component of its world rotation).
    if largest <= MAX_SPRING_ANGLE && d.iter().all(|v| v.is_finite()) {
        return Ok(d);
    }
    linear(model, data, tcp, Some(wrench))
}

#[cfg(test)]
mod tests {
    use nalgebra::{Isometry3, UnitQuaternion, Vector3};

    use super::*;
    use crate::vjm::lanes::Plain;
    use crate::vjm::{Load, deflection};

    /// Eq. 8 as written: the product of `F_k R*_k F_k^-1` over the springs in chain order, with
    /// nalgebra's Euler rotation, then the rigid TCP; the deflection against the rigid pose.
    fn definition(data: &Data, n: usize) -> (Vector3<f64>, Vector3<f64>) {
        let mut t = Isometry3::identity();
        for (f, a) in data.spring_frames.iter().zip(&data.spring_angles).take(n) {
            let e = UnitQuaternion::from_euler_angles(a.x, a.y, a.z);
            t = t * f * Isometry3::from_parts(Vector3::zeros().into(), e) * f.inverse();
        }
        let deflected = t * data.tcp;
        (
            deflected.translation.vector - data.tcp.translation.vector,
            (deflected.rotation * data.tcp.rotation.inverse()).scaled_axis(),
        )
    }

    #[test]
    fn deflection_is_the_product_of_eq_8_for_small_and_large_turns() {
        let (model, q) = crate::vjm::lanes::tests::arm();
        let mut data = Data::new(&model);
        // This load turns the softest spring by 0.007 rad (the series' lanes); five times it,
        // past 0.02 rad (one by one, with the library's sines).
        for (scale, series) in [(1.0, true), (5.0, false)] {
            let w = Vector6::new(120.0, -80.0, 45.0, 30.0, -20.0, 15.0) * scale;
            let d = deflection(&model, &mut data, &q, &w, Load::Exact).unwrap();
            let largest = check_angles(&model, &data).unwrap();
            assert_eq!(largest < SERIES_ANGLE, series, "largest angle {largest}");
            let (dp, dr) = definition(&data, model.springs);
            let (ours_p, ours_r) = (d.fixed_rows::<3>(0), d.fixed_rows::<3>(3));
            assert!(
                (ours_p - dp).norm() <= 1e-13 * dp.norm(),
                "{ours_p} vs {dp}"
            );
            assert!(
                (ours_r - dr).norm() <= 1e-13 * dr.norm(),
                "{ours_r} vs {dr}"
            );
            // The deflected pose is the rigid one moved by the deflection.
            let moved = data.tcp_deflected.translation.vector - data.tcp.translation.vector;
            assert!((moved - dp).norm() <= 1e-12 * dp.norm());
        }
    }

    /// The kernel in AVX2 registers (where the CPU has them) and in plain arrays: the same
    /// results and the same moments and angles in `data`, bit for bit.
    fn lanes_agree<const LOADS: bool, const EXACT: bool>(model: &Model, data: &Data) {
        let (mut a, mut b) = (data.clone(), data.clone());
        let p = data.tcp.translation.vector;
        let kernel = |data| Springs::<LOADS, EXACT, true> {
            model,
            data,
            p,
            force: Vector3::new(120.0, -80.0, 45.0),
            moment: Vector3::new(30.0, -20.0, 15.0),
        };
        let plain = kernel(&mut a).run(Plain);
        assert!(plain.iter().flatten().any(|v| *v != 0.0));
        assert_eq!(dispatch(kernel(&mut b)), plain);
        assert_eq!(a.spring_angles, b.spring_angles);
        assert_eq!(a.spring_moments, b.spring_moments);
    }

    #[test]
    fn avx2_lanes_equal_the_plain_lanes_bit_for_bit() {
        let (model, q) = crate::vjm::lanes::tests::arm();
        let mut data = Data::new(&model);
        let w = Vector6::new(120.0, -80.0, 45.0, 30.0, -20.0, 15.0);
        deflection(&model, &mut data, &q, &w, Load::Exact).unwrap();
        lanes_agree::<true, true>(&model, &data);
        lanes_agree::<true, false>(&model, &data);
        lanes_agree::<false, true>(&model, &data);
        lanes_agree::<false, false>(&model, &data);
    }
}
