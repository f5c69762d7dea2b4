//! The springs' loads (Eq. 5-7) and turns (Eq. 3-4, 8) four springs at a time, in the lanes of
//! [`super::lanes`], and the deflected TCP as a product of the turns.
//!
//! The deflected chain of Eq. 8 is `T = Q_1 ... Q_n T_tcp`, `Q_k` the turn of spring `k` about
//! its origin `o_k` (`x -> q_k (x - o_k) + o_k`, `q_k` the rotation of Eq. 4 in world axes).
//! Taken relative to the rigid TCP (`x' = x - p_tcp`), `Q_k` becomes the small motion
//! `(q_k, q_k L_k - L_k)` with the lever `L_k = p_tcp - o_k`, and `q_k L_k - L_k` is computed
//! without forming `q_k L_k` (no cancellation of metre-sized terms). The TCP's deflection is
//! then the translation of the product `Q'_1 ... Q'_n` and the rotation vector of its rotation,
//! each accurate relative to the deflection itself rather than to the arm's size. The product is
//! formed as four interleaved runs of consecutive springs, then combined: four independent
//! dependency chains instead of one through all springs.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

use super::deflection::{MAX_SPRING_ANGLE, euler_zyx};
use super::lanes::{LaneKernel, Lanes, V4, dispatch};
use super::{Data, Model, Vector6};
use crate::error::TickError;

/// Below this elastic angle \[rad\] (half-angle 1e-2) the turns' sines and cosines are the
/// series of [`super::deflection`]'s `sin_cos_small`; a spring turned further is recomputed
/// with the library's.
const SERIES_ANGLE: f64 = 2.0e-2;

/// The four entries of a per-spring table from `base` (past the spring count the tables hold
/// identity frames, zero compliances and zero angles, which add nothing).
#[inline(always)]
fn four<T>(table: &[T], base: usize) -> Option<&[T; 4]> {
    table.get(base..base + 4)?.try_into().ok()
}

/// Rotation (`w`, vector part `u`) and origin `o` of four frames, as lanes.
#[inline(always)]
fn frame_lanes<L: Lanes>(l: L, fs: &[Isometry3<f64>; 4]) -> (L::V, V4<L::V>, V4<L::V>) {
    let q = fs.each_ref().map(|f| f.rotation.coords);
    let o = fs.each_ref().map(|f| f.translation.vector);
    let w = l.load(q.map(|v| v.w));
    let u = V4 {
        x: l.load(q.map(|v| v.x)),
        y: l.load(q.map(|v| v.y)),
        z: l.load(q.map(|v| v.z)),
    };
    let o = V4 {
        x: l.load(o.map(|v| v.x)),
        y: l.load(o.map(|v| v.y)),
        z: l.load(o.map(|v| v.z)),
    };
    (w, u, o)
}

/// `a * s` lane by lane, for a vector of lanes and one lane value.
#[inline(always)]
fn scale<L: Lanes>(a: V4<L::V>, s: L::V) -> V4<L::V> {
    V4 {
        x: a.x * s,
        y: a.y * s,
        z: a.z * s,
    }
}

#[inline(always)]
fn add<L: Lanes>(a: V4<L::V>, b: V4<L::V>) -> V4<L::V> {
    V4 {
        x: a.x + b.x,
        y: a.y + b.y,
        z: a.z + b.z,
    }
}

#[inline(always)]
fn sub<L: Lanes>(a: V4<L::V>, b: V4<L::V>) -> V4<L::V> {
    V4 {
        x: a.x - b.x,
        y: a.y - b.y,
        z: a.z - b.z,
    }
}

/// Writes lane `j < n - base` of `v` into `out[base + j]`.
#[inline(always)]
fn scatter<L: Lanes>(l: L, v: V4<L::V>, out: &mut [Vector3<f64>], base: usize, n: usize) {
    let (x, y, z) = (l.store(v.x), l.store(v.y), l.store(v.z));
    for j in 0..4 {
        if base + j < n
            && let (Some(slot), Some(x), Some(y), Some(z)) =
                (out.get_mut(base + j), x.get(j), y.get(j), z.get(j))
        {
            *slot = Vector3::new(*x, *y, *z);
        }
    }
}

/// The moment on every spring of the TCP `wrench` at `tcp` (Eq. 5-6: the load moved to the
/// spring's origin, world axes) and its angles (Eq. 7), from the rigid frames of the last
/// pass, into `data.spring_moments` and `data.spring_angles`; then [`check_angles`] (the
/// largest angle).
pub(super) fn tcp_loads(
    model: &Model,
    data: &mut Data,
    tcp: &Isometry3<f64>,
    wrench: &Vector6,
) -> Result<f64, TickError> {
    /// The lane kernel.
    struct Loads<'a> {
        model: &'a Model,
        data: &'a mut Data,
        p: Vector3<f64>,
        force: Vector3<f64>,
        moment: Vector3<f64>,
    }
    impl LaneKernel for Loads<'_> {
        type Output = ();
        #[inline(always)]
        fn run<L: Lanes>(self, l: L) {
            let Self {
                model,
                data,
                p,
                force,
                moment,
            } = self;
            let n = model.springs;
            let splat = |v: Vector3<f64>| V4 {
                x: l.splat(v.x),
                y: l.splat(v.y),
                z: l.splat(v.z),
            };
            let (p, force, moment) = (splat(p), splat(force), splat(moment));
            let two = l.splat(2.0);
            for base in (0..n).step_by(4) {
                let (Some(fs), Some(cs)) = (
                    four(&data.spring_frames, base),
                    four(&model.spring_compliance, base),
                ) else {
                    continue; // unreachable: the tables hold whole chunks
                };
                let (w, u, o) = frame_lanes(l, fs);
                // Eq. 5-6: m = M + (p_tcp - o) x F.
                let m = add::<L>(moment, sub::<L>(p, o).cross(force));
                // The moment in the spring's axes, R^T m: nalgebra's rotation by the
                // conjugate (w, -u), `(t' w + (-u) x t') + m` with `t' = 2 (-u) x m`,
                // written with `t = 2 u x m` as `(u x t - t w) + m` (the same bits).
                let t = scale::<L>(u.cross(m), two);
                let local = add::<L>(sub::<L>(u.cross(t), scale::<L>(t, w)), m);
                // Eq. 7: the angles M / k.
                let c = V4 {
                    x: l.load(cs.map(|c| c.x)),
                    y: l.load(cs.map(|c| c.y)),
                    z: l.load(cs.map(|c| c.z)),
                };
                let angles = V4 {
                    x: c.x * local.x,
                    y: c.y * local.y,
                    z: c.z * local.z,
                };
                scatter(l, m, &mut data.spring_moments, base, n);
                scatter(l, angles, &mut data.spring_angles, base, n);
            }
        }
    }
    dispatch(Loads {
        model,
        data: &mut *data,
        p: tcp.translation.vector,
        force: Vector3::new(wrench[0], wrench[1], wrench[2]),
        moment: Vector3::new(wrench[3], wrench[4], wrench[5]),
    });
    check_angles(model, data)
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
/// translation `q L - L`, `L = p - o`. The scalar twin of [`lane_turns`], for springs turned
/// past the series' range.
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
struct Motion4<V> {
    w: V,
    u: V4<V>,
    t: V4<V>,
}

impl<V: Copy + core::ops::Add<Output = V> + core::ops::Sub<Output = V> + core::ops::Mul<Output = V>>
    Motion4<V>
{
    /// `self * o`, lane by lane: `(q_a q_b, t_a + q_a t_b)`, the quaternion product and the
    /// rotation in nalgebra's order of operations.
    #[inline(always)]
    fn then(self, o: Self, two: V) -> Self {
        let (a, b) = (self, o);
        let w = a.w * b.w - a.u.x * b.u.x - a.u.y * b.u.y - a.u.z * b.u.z;
        let u = V4 {
            x: a.w * b.u.x + a.u.x * b.w + a.u.y * b.u.z - a.u.z * b.u.y,
            y: a.w * b.u.y - a.u.x * b.u.z + a.u.y * b.w + a.u.z * b.u.x,
            z: a.w * b.u.z + a.u.x * b.u.y - a.u.y * b.u.x + a.u.z * b.w,
        };
        let c = a.u.cross(b.t);
        let r = V4 {
            x: c.x * two,
            y: c.y * two,
            z: c.z * two,
        };
        let rc = a.u.cross(r);
        let t = V4 {
            x: a.t.x + ((r.x * a.w + rc.x) + b.t.x),
            y: a.t.y + ((r.y * a.w + rc.y) + b.t.y),
            z: a.t.z + ((r.z * a.w + rc.z) + b.t.z),
        };
        Self { w, u, t }
    }
}

/// The lane kernel of [`turn_product`]: the four runs' products, as arrays of lanes.
#[derive(Clone, Copy)]
struct Runs<'a> {
    model: &'a Model,
    data: &'a Data,
    p: Vector3<f64>,
}
impl LaneKernel for Runs<'_> {
    type Output = [[f64; 4]; 7];
    #[inline(always)]
    fn run<L: Lanes>(self, l: L) -> [[f64; 4]; 7] {
        let Self { model, data, p } = self;
        let n = model.springs;
        let run = n.div_ceil(4);
        let p = V4 {
            x: l.splat(p.x),
            y: l.splat(p.y),
            z: l.splat(p.z),
        };
        let (zero, one, two, half) = (l.splat(0.0), l.splat(1.0), l.splat(2.0), l.splat(0.5));
        let none = V4 {
            x: zero,
            y: zero,
            z: zero,
        };
        let mut acc = Motion4 {
            w: one,
            u: none,
            t: none,
        };
        let identity = Isometry3::identity();
        let still = Vector3::zeros();
        for c in 0..run {
            // Spring g run + c of each run; past the count, an identity frame and no
            // turn (the identity motion, exactly).
            let pick = |g: usize| {
                let k = g * run + c;
                match (data.spring_frames.get(k), data.spring_angles.get(k)) {
                    (Some(f), Some(a)) if k < n => (f, a),
                    _ => (&identity, &still),
                }
            };
            let springs = [pick(0), pick(1), pick(2), pick(3)];
            let fs = springs.map(|(f, _)| f);
            let a = springs.map(|(_, a)| a);
            let turn = lane_turns(l, fs, a, p, two, half);
            acc = acc.then(turn, two);
        }
        [
            l.store(acc.w),
            l.store(acc.u.x),
            l.store(acc.u.y),
            l.store(acc.u.z),
            l.store(acc.t.x),
            l.store(acc.t.y),
            l.store(acc.t.z),
        ]
    }
}
/// The product `Q'_1 ... Q'_n` of every spring's turn relative to the rigid TCP at `p` (see the
/// module), from `data.spring_angles` and the rigid frames of the last pass. Lane `g` forms the
/// product of the `g`-th run of consecutive springs (`ceil(n / 4)` springs each), step `c`
/// turning spring `g ceil(n / 4) + c` of each run at once; the four runs are combined at the end.
/// With a spring past the series' range (`largest`, the largest angle, from [`check_angles`];
/// rare: 0.02 rad is a large elastic angle), the turns one by one with the library's sines.
fn turn_product(model: &Model, data: &Data, p: &Vector3<f64>, largest: f64) -> Isometry3<f64> {
    if largest >= SERIES_ANGLE {
        let springs = data.spring_frames.iter().zip(data.spring_angles.iter());
        return springs
            .take(model.springs)
            .fold(Isometry3::identity(), |t, (f, a)| t * turn_of(f, a, p));
    }
    let [w, x, y, z, tx, ty, tz] = dispatch(Runs { model, data, p: *p });
    let motion = |g: usize| {
        let at = |v: [f64; 4]| v.get(g).copied().unwrap_or(0.0);
        Isometry3::from_parts(
            Translation3::new(at(tx), at(ty), at(tz)),
            UnitQuaternion::new_unchecked(Quaternion::new(at(w), at(x), at(y), at(z))),
        )
    };
    (motion(0) * motion(1)) * (motion(2) * motion(3))
}

/// The turns of four springs relative to the rigid TCP at `p`, with the series' sines (all
/// angles below [`SERIES_ANGLE`]): the lanes of [`turn_of`].
#[inline(always)]
fn lane_turns<L: Lanes>(
    l: L,
    fs: [&Isometry3<f64>; 4],
    a: [&Vector3<f64>; 4],
    p: V4<L::V>,
    two: L::V,
    half: L::V,
) -> Motion4<L::V> {
    let q = fs.map(|f| f.rotation.coords);
    let o = fs.map(|f| f.translation.vector);
    let w = l.load(q.map(|v| v.w));
    let u = V4 {
        x: l.load(q.map(|v| v.x)),
        y: l.load(q.map(|v| v.y)),
        z: l.load(q.map(|v| v.z)),
    };
    let o = V4 {
        x: l.load(o.map(|v| v.x)),
        y: l.load(o.map(|v| v.y)),
        z: l.load(o.map(|v| v.z)),
    };
    // Eq. 4, `Rz(gamma) Ry(beta) Rx(alpha)` from the half-angles (as `euler_zyx`, the same
    // operations).
    let (sr, cr) = sin_cos_series(l, l.load(a.map(|a| a.x)) * half);
    let (sp, cp) = sin_cos_series(l, l.load(a.map(|a| a.y)) * half);
    let (sy, cy) = sin_cos_series(l, l.load(a.map(|a| a.z)) * half);
    let ew = cr * cp * cy + sr * sp * sy;
    let e = V4 {
        x: sr * cp * cy - cr * sp * sy,
        y: cr * sp * cy + sr * cp * sy,
        z: cr * cp * sy - sr * sp * cy,
    };
    // F e F^-1: the vector part turned by F (nalgebra's `(t w + u x t) + v`, `t = 2 u x v`).
    let t = scale::<L>(u.cross(e), two);
    let v = add::<L>(add::<L>(scale::<L>(t, w), u.cross(t)), e);
    // q L - L without q L: `t2 ew + v x t2`, `t2 = 2 v x L`.
    let lever = sub::<L>(p, o);
    let t2 = scale::<L>(v.cross(lever), two);
    let shift = add::<L>(scale::<L>(t2, ew), v.cross(t2));
    Motion4 {
        w: ew,
        u: v,
        t: shift,
    }
}

/// The deflected TCP (Eq. 8) from `data.spring_angles` (the largest `largest`, from
/// [`check_angles`]) and the rigid frames of the last pass: the deflection `[dp; dr]` of the
/// TCP at `tcp` and the deflected pose (see the module).
pub(super) fn deflected_tcp(
    model: &Model,
    data: &Data,
    tcp: &Isometry3<f64>,
    largest: f64,
) -> (Vector6, Isometry3<f64>) {
    let total = turn_product(model, data, &tcp.translation.vector, largest);
    let dp = total.translation.vector;
    let dr = super::deflection::rotation_vector(&total.rotation);
    let deflected = Isometry3::from_parts(
        (tcp.translation.vector + dp).into(),
        total.rotation * tcp.rotation,
    );
    (Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z), deflected)
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

    #[test]
    fn avx2_runs_equal_the_plain_runs_bit_for_bit() {
        let (model, q) = crate::vjm::lanes::tests::arm();
        let mut data = Data::new(&model);
        let w = Vector6::new(120.0, -80.0, 45.0, 30.0, -20.0, 15.0);
        deflection(&model, &mut data, &q, &w, Load::Exact).unwrap();
        let runs = Runs {
            model: &model,
            data: &data,
            p: data.tcp.translation.vector,
        };
        let plain = runs.run(Plain);
        assert!(plain.iter().flatten().all(|v| v.is_finite()));
        assert_eq!(dispatch(runs), plain);
    }
}
