//! Four loaded poses at a time: the exact deflection of four rows of a batch in the lanes of
//! [`super::lanes`], one row per lane, every operation that of the one-row path
//! ([`super::deflection`] with [`super::Load::Exact`]) so that each row's result is the same
//! number (only the sign of a zero may differ: `0.0 == -0.0`).
//!
//! The one-row path spends a third of its time in the rigid pass, a chain of dependent
//! quaternion products that no lane layout over springs can share; over rows the whole chain
//! runs four times at once. The compositions are the general products where the one-row pass
//! skips the terms with exact zeros and ones of coordinate axes: the same sums in the same
//! order, so the same results. The joints' sines and cosines are [`super::trig`]'s, in the
//! lanes (the quadrant applied as exact products with 0 and +-1). UR5 over random rows: 308
//! ns per row one at a time, 213 ns four at a time (`cargo bench --bench vjm`).

use nalgebra::{Isometry3, Quaternion, UnitQuaternion};

use super::data::check_q;
use super::lanes::{LaneKernel, Lanes, V4, dispatch};
use super::model::{MAX_SPRINGS, Pass, TcpStep};
use super::rotation::rotation_vector;
use super::turns::{Frames4, Motion4, SERIES_ANGLE, splat3};
use super::{Data, MAX_SPRING_ANGLE, Model, Vector6};
use crate::error::check_finite;

/// Rows per call of [`exact_deflection_x4`]: the lanes.
const ROWS: usize = 4;

/// The exact deflections `[dx, dy, dz, rx, ry, rz]` \[m, rad\] of four loaded poses at once:
/// row `r` is joints `q[r]` \[rad or m\] under the TCP wrench `wrench[r]` \[N, N m\], each
/// what [`super::deflection`] with [`super::Load::Exact`] returns for it (the same number; a
/// zero's sign aside), at about two thirds of the cost per row (batches of poses:
/// `deflection_batch`).
///
/// `None` when a row is not for the four-row path: a row [`super::deflection`] would refuse
/// (wrong length, non-finite, past the joint range, a spring past [`MAX_SPRING_ANGLE`], an
/// overflowing result), or a spring turned past 0.02 rad (which the one-row path takes one
/// spring at a time). Call [`super::deflection`] on each row then: it returns that row's error
/// or its value. `data` is checked against the model and otherwise left as it was.
pub fn exact_deflection_x4(
    model: &Model,
    data: &Data,
    q: [&[f64]; ROWS],
    wrench: [&Vector6; ROWS],
) -> Option<[Vector6; ROWS]> {
    for (q, w) in q.iter().zip(wrench) {
        check_q(model, data, q).ok()?;
        check_finite("wrench", w.as_slice()).ok()?;
    }
    let [w, x, y, z, tx, ty, tz, largest] = dispatch(Rows { model, q, wrench });
    let mut out = [Vector6::zeros(); ROWS];
    for (r, out) in out.iter_mut().enumerate() {
        let at = |v: [f64; 4]| v.get(r).copied().unwrap_or(f64::NAN);
        // The one-row path's guard and its series' range (a NaN angle, from an overflow,
        // makes the result NaN, refused below).
        let a = at(largest);
        if a.is_nan() || a > MAX_SPRING_ANGLE || a >= SERIES_ANGLE {
            return None;
        }
        let turn = UnitQuaternion::new_unchecked(Quaternion::new(at(w), at(x), at(y), at(z)));
        let dr = rotation_vector(&turn);
        let d = Vector6::new(at(tx), at(ty), at(tz), dr.x, dr.y, dr.z);
        if !d.iter().all(|v| v.is_finite()) {
            return None;
        }
        *out = d;
    }
    Some(out)
}

/// The lane kernel: the product of the springs' turns relative to each row's rigid TCP (lanes
/// of `w, u.x, u.y, u.z, t.x, t.y, t.z`) and each row's largest elastic angle.
struct Rows<'a> {
    model: &'a Model,
    q: [&'a [f64]; ROWS],
    wrench: [&'a Vector6; ROWS],
}

/// A fixed transform in every lane.
#[inline(always)]
fn splat_iso<L: Lanes>(l: L, t: &Isometry3<f64>) -> Motion4<L::V> {
    Motion4 {
        w: l.splat(t.rotation.w),
        u: splat3(l, &t.rotation.imag()),
        t: splat3(l, &t.translation.vector),
    }
}

/// A lane value per row.
#[inline(always)]
fn per_row<L: Lanes>(l: L, f: impl Fn(usize) -> f64) -> L::V {
    l.load([f(0), f(1), f(2), f(3)])
}

/// The lane constants of the kernel: `0` and `2` in every lane (`2` for the quaternion
/// products), the zero vector and the identity motion.
struct Consts<L: Lanes> {
    zero: L::V,
    two: L::V,
    none: V4<L::V>,
    identity: Motion4<L::V>,
}

impl<L: Lanes> Consts<L> {
    /// The constants in the lanes `l`.
    #[inline(always)]
    fn new(l: L) -> Self {
        let (zero, one, two) = (l.splat(0.0), l.splat(1.0), l.splat(2.0));
        let none = V4 {
            x: zero,
            y: zero,
            z: zero,
        };
        let identity = Motion4 {
            w: one,
            u: none,
            t: none,
        };
        Self {
            zero,
            two,
            none,
            identity,
        }
    }
}

impl LaneKernel for Rows<'_> {
    type Output = [[f64; 4]; 8];
    #[inline(always)]
    fn run<L: Lanes>(self, l: L) -> [[f64; 4]; 8] {
        let Self { model, q, wrench } = self;
        let consts = Consts::new(l);
        let mut springs = [consts.identity; MAX_SPRINGS];
        let tcp = rigid_pass(l, &consts, model, &q, &mut springs);
        let (total, largest) = spring_turns(l, &consts, model, &springs, tcp.t, &wrench);
        let s = |v: L::V| l.store(v);
        let (w, u, t) = (total.w, total.u, total.t);
        [
            s(w),
            s(u.x),
            s(u.y),
            s(u.z),
            s(t.x),
            s(t.y),
            s(t.z),
            s(largest),
        ]
    }
}

/// The rigid pass (`deflection::rigid_pass`) of the four rows: the springs' world frames
/// into `springs` (by spring index), kept as lanes, and the rigid TCP returned.
#[inline(always)]
fn rigid_pass<L: Lanes>(
    l: L,
    consts: &Consts<L>,
    model: &Model,
    q: &[&[f64]; ROWS],
    springs: &mut [Motion4<L::V>; MAX_SPRINGS],
) -> Motion4<L::V> {
    let mut frame = consts.identity;
    for p in model.pass.iter() {
        match p {
            Pass::Joint(k) => {
                let Some(step) = model.tcp_chain.get(*k) else {
                    continue; // unreachable: built together
                };
                frame = joint(l, consts, frame, step, q);
            }
            Pass::Spring { local, index, .. } => {
                if let Some(slot) = springs.get_mut(*index) {
                    *slot = frame.then(splat_iso(l, local), consts.two);
                }
            }
        }
    }
    frame.then(splat_iso(l, &model.tcp_tail), consts.two)
}

/// One joint of the rigid pass: `frame` followed by the fixed transform before the joint and
/// the joint's motion by each row's `q[r][step.index]` \[rad or m\].
#[inline(always)]
fn joint<L: Lanes>(
    l: L,
    consts: &Consts<L>,
    frame: Motion4<L::V>,
    step: &TcpStep,
    q: &[&[f64]; ROWS],
) -> Motion4<L::V> {
    let (two, none) = (consts.two, consts.none);
    let mut frame = frame.then(splat_iso(l, &step.pre), two);
    let qi = |r: usize| {
        q.get(r)
            .and_then(|q| q.get(step.index))
            .copied()
            .unwrap_or(0.0)
    };
    let axis = step.axis.into_inner();
    if step.revolute {
        let half = [0, 1, 2, 3].map(|r| qi(r) * 0.5);
        let (s, c) = super::trig::sin_cos_lanes(l, half);
        let turn = Motion4 {
            w: c,
            u: V4 {
                x: l.splat(axis.x) * s,
                y: l.splat(axis.y) * s,
                z: l.splat(axis.z) * s,
            },
            t: none,
        };
        // The rotation only: `frame.rotation * turn`.
        let t = frame.t;
        frame = frame.then(turn, two);
        frame.t = t;
    } else {
        let rot = Frames4 {
            w: frame.w,
            u: frame.u,
            o: none,
        };
        let u = rot.world(splat3(l, &axis), two);
        let qi = per_row(l, qi);
        frame.t = V4 {
            x: frame.t.x + u.x * qi,
            y: frame.t.y + u.y * qi,
            z: frame.t.z + u.z * qi,
        };
    }
    frame
}

/// The springs (`turns::Springs` with the loads and the exact product) of the frames
/// `springs` about the rigid TCP at `p` \[m\] under the rows' wrenches \[N, N m\], each row's
/// spring k in lane r, the four runs of springs one after the other: the product of the
/// springs' turns and each row's largest elastic angle \[rad\].
#[inline(always)]
fn spring_turns<L: Lanes>(
    l: L,
    consts: &Consts<L>,
    model: &Model,
    springs: &[Motion4<L::V>; MAX_SPRINGS],
    p: V4<L::V>,
    wrench: &[&Vector6; ROWS],
) -> (Motion4<L::V>, L::V) {
    let two = consts.two;
    let column = |i: usize| per_row(l, |r| wrench.get(r).map_or(0.0, |w| w[i]));
    let force = V4 {
        x: column(0),
        y: column(1),
        z: column(2),
    };
    let moment = V4 {
        x: column(3),
        y: column(4),
        z: column(5),
    };
    let n = model.springs;
    let run = n.div_ceil(4);
    let mut largest = consts.zero;
    let mut runs = [consts.identity; 4];
    // Step c turns spring g run + c of every run g: four independent products at once.
    for c in 0..run {
        for (g, acc) in runs.iter_mut().enumerate() {
            let k = g * run + c;
            let (Some(f), Some(cs)) = (springs.get(k), model.spring_compliance.get(k)) else {
                continue;
            };
            if k >= n {
                continue;
            }
            let frames = Frames4 {
                w: f.w,
                u: f.u,
                o: f.t,
            };
            let lever = V4 {
                x: p.x - frames.o.x,
                y: p.y - frames.o.y,
                z: p.z - frames.o.z,
            };
            let (_, a) = frames.loads(lever, force, moment, splat3(l, cs), two);
            let big = l.max(l.max(l.abs(a.x), l.abs(a.y)), l.abs(a.z));
            largest = l.max(largest, big);
            *acc = acc.then(frames.turn(l, a, p, two), two);
        }
    }
    let [r0, r1, r2, r3] = runs;
    let total = r0.then(r1, two).then(r2.then(r3, two), two);
    (total, largest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vjm::{Load, deflection};

    #[test]
    fn four_rows_are_the_one_row_path_exactly() {
        let (model, q0) = crate::vjm::lanes::tests::arm();
        let mut data = Data::new(&model);
        let qs: [[f64; 3]; 4] = [q0, [0.1, 2.0, -0.3], [-2.5, 0.4, 0.02], [3.0, -1.0, 0.5]];
        let ws = [
            Vector6::new(120.0, -80.0, 45.0, 30.0, -20.0, 15.0),
            Vector6::new(-60.0, 10.0, 90.0, -5.0, 2.0, 8.0),
            Vector6::new(0.0, 0.0, -150.0, 0.0, 0.0, 0.0),
            Vector6::new(20.0, 20.0, 20.0, 1.0, 1.0, 1.0),
        ];
        let rows = exact_deflection_x4(
            &model,
            &data,
            qs.each_ref().map(|q| q.as_slice()),
            ws.each_ref(),
        )
        .unwrap();
        for ((q, w), d) in qs.iter().zip(&ws).zip(rows) {
            let one = deflection(&model, &mut data, q, w, Load::Exact).unwrap();
            assert_eq!(d, one, "{q:?}");
        }
        // A row past the series' range, or one the one-row path refuses: not for this path.
        let big = ws[0] * 5.0;
        let q = qs.each_ref().map(|q| q.as_slice());
        assert!(exact_deflection_x4(&model, &data, q, [&ws[0], &ws[1], &big, &ws[3]]).is_none());
        let nan = Vector6::repeat(f64::NAN);
        assert!(exact_deflection_x4(&model, &data, q, [&ws[0], &nan, &ws[2], &ws[3]]).is_none());
        let short = [0.0; 2];
        let q = [q[0], q[1], q[2], short.as_slice()];
        assert!(exact_deflection_x4(&model, &data, q, ws.each_ref()).is_none());
    }
}
