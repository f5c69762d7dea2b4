//! Stiffness-optimal posture: the redundant rotation about the tool axis.
//!
//! A 5-axis task (a TCP position and a tool axis) leaves a 6-axis arm one free coordinate,
//! the rotation `theta` about the tool axis. The compliance, and so the deflection under a
//! process wrench, changes with it; choosing it is a known lever in robot machining (the
//! papers compensate the deflection the posture gives; this picks the posture that deflects
//! least). [`sweep`] solves the 6-D pose IK ([`mechanism::pose_ik()`], the same solver the
//! serial D'Alembert corrector uses) for every angle of a sweep, warm-started from the angle
//! before, from one or several seeds (one per IK branch the caller wants explored), keeps the
//! solutions inside the joint limits and away from singularities, evaluates the exact
//! virtual-joint deflection (Hähn and Weigold 2020, Eq. 2-9) under the wrench, and refines
//! the best angle by a golden-section search between its neighbours.
//!
//! Conventions: the tool axis is the TCP frame's z axis, in the base frame; `theta = 0` is the
//! orientation whose x axis is the base x axis projected normal to the tool axis (the base y
//! axis when the tool axis is along x); `theta` turns the TCP frame about the tool axis.
//!
//! Allocation-free: the caller gives the output slice, one [`AnglePoint`] per angle.

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3};

use crate::error::{TickError, check_finite};
use crate::mechanism::{self, PoseIkOptions};
use crate::vjm::{self, Data, MAX_DOF, Model, Vector6};

/// Most angles one sweep takes (a 0.1 degree scan of the full turn).
pub const MAX_ANGLES: usize = 3600;

/// Most IK seeds (branches) one sweep explores.
pub const MAX_SEEDS: usize = 8;

/// Most directions of [`Measure::Along`].
pub const MAX_DIRECTIONS: usize = 3;

/// Golden-section iterations of the refinement: the bracket shrinks by 0.618 each, so 24 take
/// a 2 degree bracket below 1e-6 degrees.
const REFINE_ITERATIONS: usize = 24;

/// What "deflects least" means. All act on the translational deflection `dp` \[m\] of the
/// TCP, base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Measure {
    /// `|dp|` (Euclidean norm).
    Norm,
    /// `max_i |dp_i|` over the base axes.
    Max,
    /// `max_k |u_k . dp|` over up to [`MAX_DIRECTIONS`] unit directions (e.g. the surface
    /// normal of a milled face: only the error normal to the surface shows on the part).
    Along([Vector3<f64>; MAX_DIRECTIONS], usize),
}

impl Measure {
    /// The measure of the deflection `d = [dp; dr]` [m, rad].
    pub fn of(&self, d: &Vector6) -> f64 {
        let dp = Vector3::new(d.x, d.y, d.z);
        match self {
            Self::Norm => dp.norm(),
            Self::Max => dp.amax(),
            Self::Along(u, n) => u
                .iter()
                .take(*n)
                .map(|u| u.dot(&dp).abs())
                .fold(0.0, f64::max),
        }
    }

    /// `Along` from directions (normalised here); `None` for no direction, more than
    /// [`MAX_DIRECTIONS`], or a zero or non-finite one.
    pub fn along(directions: &[Vector3<f64>]) -> Option<Self> {
        if directions.is_empty() || directions.len() > MAX_DIRECTIONS {
            return None;
        }
        let mut u = [Vector3::zeros(); MAX_DIRECTIONS];
        for (dst, d) in u.iter_mut().zip(directions) {
            let n = d.norm();
            if !(n.is_finite() && n > 0.0) {
                return None;
            }
            *dst = d / n;
        }
        Some(Self::Along(u, directions.len()))
    }
}

/// Why an angle has no posture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Reach {
    /// A posture within the joint limits and the singularity margin.
    Reachable,
    /// The IK did not converge from any seed: out of reach (or too far from the seeds).
    #[default]
    OutOfReach,
    /// The only solutions found are closer to a singularity than the margin.
    Singular,
    /// The only solutions found violate a joint limit.
    JointLimit,
    /// A posture exists, but the wrench turns a spring past
    /// [`vjm::MAX_SPRING_ANGLE`] (or overflows the deflection): the point is reachable,
    /// its deflection is beyond the small-deflection model's validity.
    BeyondModel,
}

impl Reach {
    /// How much a failure says about the point, for reporting the most telling one: a
    /// posture outside the model's validity says more than a limit or a singularity, which
    /// say more than "out of reach".
    fn rank(self) -> u8 {
        match self {
            Self::Reachable => 4,
            Self::BeyondModel => 3,
            Self::JointLimit | Self::Singular => 2,
            Self::OutOfReach => 1,
        }
    }

    /// Short name: `reachable`, `out_of_reach`, `singular`, `joint_limit`, `beyond_model`
    /// (the bindings' and the testbed's spelling).
    pub fn name(self) -> &'static str {
        match self {
            Self::Reachable => "reachable",
            Self::OutOfReach => "out_of_reach",
            Self::Singular => "singular",
            Self::JointLimit => "joint_limit",
            Self::BeyondModel => "beyond_model",
        }
    }

    /// Stable numeric code (0 reachable, 1 out of reach, 2 singular, 3 joint limit, 4
    /// beyond the model), the order of [`Self::ALL`]: what tables and archives store.
    pub fn code(self) -> u8 {
        match self {
            Self::Reachable => 0,
            Self::OutOfReach => 1,
            Self::Singular => 2,
            Self::JointLimit => 3,
            Self::BeyondModel => 4,
        }
    }

    /// Every status, in code order.
    pub const ALL: [Self; 5] = [
        Self::Reachable,
        Self::OutOfReach,
        Self::Singular,
        Self::JointLimit,
        Self::BeyondModel,
    ];
}

/// One angle of a sweep.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AnglePoint {
    /// The angle about the tool axis \[rad\].
    pub angle: f64,
    /// Whether (and why not) it has a posture.
    pub reach: Reach,
    /// The measure of the deflection \[m\]; NaN when not reachable.
    pub measure: f64,
    /// The TCP deflection `[dp; dr]` \[m, rad\], base frame; NaN when not reachable.
    pub deflection: Vector6,
    /// Joints of the posture (entries past the dof are zero; NaN when not reachable).
    pub q: [f64; MAX_DOF],
    /// The seed (IK branch) the posture came from.
    pub seed: usize,
}

/// The optimum of a sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepSummary {
    /// Reachable angles.
    pub reachable: usize,
    /// Angles with a posture whose deflection is beyond the model ([`Reach::BeyondModel`]).
    pub beyond_model: usize,
    /// The point's status: [`Reach::Reachable`] when an angle is, otherwise the most telling
    /// failure over the angles ([`Reach::BeyondModel`] before a joint limit or a
    /// singularity, those before [`Reach::OutOfReach`]).
    pub status: Reach,
    /// Index of the best angle of the sweep, if any is reachable.
    pub best_index: Option<usize>,
    /// Index of the worst reachable angle.
    pub worst_index: Option<usize>,
    /// The refined optimum (golden section between the best angle's reachable neighbours;
    /// the best sampled angle when a neighbour is not reachable).
    pub best: Option<AnglePoint>,
}

/// Settings of a sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PostureOptions {
    /// What to minimise.
    pub measure: Measure,
    /// The IK's settings; its `min_sigma` is the singularity margin \[m/rad\].
    pub ik: PoseIkOptions,
    /// Refine the best sampled angle by a golden-section search.
    pub refine: bool,
}

/// IK iterations per angle by default: the first angle of a sweep (and the first after an
/// unreachable stretch) starts from afar; the others, warm-started, take 2-3.
pub const SWEEP_IK_ITERATIONS: usize = 64;

impl Default for PostureOptions {
    /// Norm of the deflection, the default IK (1e-8 m / 1e-8 rad, margin 1e-3) with
    /// [`SWEEP_IK_ITERATIONS`] iterations, refined.
    fn default() -> Self {
        Self {
            measure: Measure::Norm,
            ik: PoseIkOptions {
                max_iterations: SWEEP_IK_ITERATIONS,
                ..PoseIkOptions::default()
            },
            refine: true,
        }
    }
}

/// The TCP orientation with z along `axis` (unit) turned by `theta` about it (see the
/// module docs for `theta = 0`).
pub fn tool_orientation(axis: &Unit<Vector3<f64>>, theta: f64) -> UnitQuaternion<f64> {
    let z = axis.into_inner();
    // The base x axis projected normal to the tool axis, or y when the axis is along x.
    let reference = if z.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let x0 = reference - z * z.dot(&reference);
    let x0 = x0 / x0.norm();
    let y0 = z.cross(&x0);
    let r0 = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x0, y0, z]));
    UnitQuaternion::from_axis_angle(axis, theta) * UnitQuaternion::from_rotation_matrix(&r0)
}

/// Everything fixed during one sweep.
struct Task<'a> {
    model: &'a Model,
    limits: &'a [(f64, f64)],
    position: Translation3<f64>,
    axis: Unit<Vector3<f64>>,
    wrench: &'a Vector6,
    options: &'a PostureOptions,
}

impl Task<'_> {
    /// The posture at `theta` from `seed`, with its deflection and measure.
    fn solve(&self, data: &mut Data, theta: f64, seed: &[f64]) -> Result<AnglePoint, Reach> {
        let target = Isometry3::from_parts(self.position, tool_orientation(&self.axis, theta));
        let dof = self.model.dof();
        let sol = match mechanism::pose_ik(
            self.model,
            data,
            &target,
            seed,
            &vjm::Vector6::zeros(),
            vjm::Load::Rigid,
            &self.options.ik,
        ) {
            Ok(s) => s,
            Err(TickError::Singular { .. }) => return Err(Reach::Singular),
            Err(_) => return Err(Reach::OutOfReach),
        };
        let q = sol.q.get(..dof).unwrap_or(&[]);
        if crate::mechanism::check_limits(q, self.limits, crate::mechanism::JOINT_LIMIT_TOLERANCE)
            .is_err()
        {
            return Err(Reach::JointLimit);
        }
        // The pose IK succeeded: a failing deflection is the spring-angle guard (or an
        // overflow), a load beyond the model, not a point out of reach.
        let d = vjm::deflection(self.model, data, q, self.wrench, vjm::Load::Exact)
            .map_err(|_| Reach::BeyondModel)?;
        Ok(AnglePoint {
            angle: theta,
            reach: Reach::Reachable,
            measure: self.options.measure.of(&d),
            deflection: d,
            q: sol.q,
            seed: 0,
        })
    }

    /// The best of the seeds at `theta`; `warm[k]` is seed `k`'s last solution.
    fn best_of_seeds(
        &self,
        data: &mut Data,
        theta: f64,
        warm: &mut [[f64; MAX_DOF]],
        seeds: usize,
    ) -> AnglePoint {
        let dof = self.model.dof();
        let mut best: Option<AnglePoint> = None;
        // The most telling failure: a limit or singularity says more than "out of reach".
        let mut why = Reach::OutOfReach;
        for (k, w) in warm.iter_mut().enumerate().take(seeds) {
            match self.solve(data, theta, w.get(..dof).unwrap_or(&[])) {
                Ok(mut p) => {
                    p.seed = k;
                    *w = p.q;
                    if best.is_none_or(|b| p.measure < b.measure) {
                        best = Some(p);
                    }
                }
                Err(r) => {
                    if r.rank() > why.rank() {
                        why = r;
                    }
                }
            }
        }
        best.unwrap_or(AnglePoint {
            angle: theta,
            reach: why,
            measure: f64::NAN,
            deflection: Vector6::repeat(f64::NAN),
            q: [f64::NAN; MAX_DOF],
            seed: 0,
        })
    }
}

/// Sweeps the rotation about `tool_axis` (base frame, any length > 0) at the TCP position
/// `position` \[m\] over `angles` \[rad\], in order (a monotone list keeps the warm start
/// effective), from each of `seeds` (`seeds.len()` a multiple of the dof, at most
/// [`MAX_SEEDS`] seeds), under the TCP wrench `wrench` \[N, N m\], base frame. Fills
/// `out[..angles.len()]` and returns the optimum. Joint limits `limits` (one `(lower,
/// upper)` per joint) and the IK's singularity margin are respected: an angle whose only
/// solutions break them is reported as such, never as a zero deflection.
///
/// Errors: [`TickError::WrongLength`] for mismatched lengths or too many angles or seeds,
/// [`TickError::NonFinite`] for non-finite inputs, [`TickError::InvalidArgument`] for a zero
/// tool axis.
#[allow(clippy::too_many_arguments)] // reason: the task's inputs, as in the Python signature
pub fn sweep(
    model: &Model,
    data: &mut Data,
    limits: &[(f64, f64)],
    position: &Vector3<f64>,
    tool_axis: &Vector3<f64>,
    wrench: &Vector6,
    angles: &[f64],
    seeds: &[f64],
    options: &PostureOptions,
    out: &mut [AnglePoint],
) -> Result<SweepSummary, TickError> {
    let dof = model.dof();
    let length = |what, expected, got| TickError::WrongLength {
        what,
        expected,
        got,
    };
    if limits.len() != dof {
        return Err(length("joint limits", dof, limits.len()));
    }
    if angles.is_empty() || angles.len() > MAX_ANGLES {
        return Err(length("angles", MAX_ANGLES, angles.len()));
    }
    if out.len() < angles.len() {
        return Err(length("output", angles.len(), out.len()));
    }
    let n_seeds = seeds.len().checked_div(dof).unwrap_or(0);
    if n_seeds == 0 || n_seeds > MAX_SEEDS || seeds.len() != n_seeds * dof {
        return Err(length("seeds", dof, seeds.len()));
    }
    check_finite("position", position.as_slice())?;
    check_finite("tool axis", tool_axis.as_slice())?;
    check_finite("wrench", wrench.as_slice())?;
    check_finite("angles", angles)?;
    check_finite("seeds", seeds)?;
    let n = tool_axis.norm();
    if n <= 1e-12 {
        return Err(TickError::InvalidArgument {
            what: "tool axis (zero length)",
            value: n,
        });
    }
    let task = Task {
        model,
        limits,
        position: Translation3::from(*position),
        axis: Unit::new_unchecked(tool_axis / n),
        wrench,
        options,
    };
    let mut warm = [[0.0; MAX_DOF]; MAX_SEEDS];
    for (w, s) in warm.iter_mut().zip(seeds.chunks(dof)) {
        for (d, v) in w.iter_mut().zip(s) {
            *d = *v;
        }
    }
    let mut summary = SweepSummary {
        reachable: 0,
        beyond_model: 0,
        status: Reach::OutOfReach,
        best_index: None,
        worst_index: None,
        best: None,
    };
    let mut best_m = f64::INFINITY;
    let mut worst_m = f64::NEG_INFINITY;
    for (i, (o, &theta)) in out.iter_mut().zip(angles).enumerate() {
        *o = task.best_of_seeds(data, theta, &mut warm, n_seeds);
        if o.reach.rank() > summary.status.rank() {
            summary.status = o.reach;
        }
        if o.reach == Reach::BeyondModel {
            summary.beyond_model += 1;
        }
        if o.reach == Reach::Reachable {
            summary.reachable += 1;
            if o.measure < best_m {
                best_m = o.measure;
                summary.best_index = Some(i);
            }
            if o.measure > worst_m {
                worst_m = o.measure;
                summary.worst_index = Some(i);
            }
        }
    }
    summary.best = summary
        .best_index
        .and_then(|i| out.get(i).copied())
        .map(|b| {
            if options.refine {
                refine(&task, data, out, summary.best_index.unwrap_or(0), b)
            } else {
                b
            }
        });
    Ok(summary)
}

/// Golden-section search for the minimum between the best sampled angle's neighbours (the
/// best angle itself closes the bracket at either end of the sweep), each evaluation
/// warm-started from the best posture. An unreachable angle counts as an infinite measure, so
/// an optimum against a joint limit or the edge of the workspace is found up to that edge.
/// Keeps the sampled best unless the search finds a lower measure.
fn refine(
    task: &Task<'_>,
    data: &mut Data,
    out: &[AnglePoint],
    i: usize,
    best: AnglePoint,
) -> AnglePoint {
    // A sweep over the full turn is a circle: its first and last angles are neighbours.
    let turn = core::f64::consts::TAU;
    let (first, last) = match (out.first(), out.last()) {
        (Some(f), Some(l)) => (f.angle, l.angle),
        _ => return best,
    };
    let step = match (out.first(), out.get(1)) {
        (Some(a), Some(b)) => (b.angle - a.angle).abs(),
        _ => 0.0,
    };
    let full = step > 0.0 && (last - first).abs() >= turn - 1.5 * step;
    // The direction the sweep runs in (+1 increasing angles, -1 decreasing).
    let dir = (last - first).signum();
    let before = match i.checked_sub(1).and_then(|k| out.get(k)) {
        Some(p) => p.angle,
        None if full => last - dir * turn,
        None => best.angle,
    };
    let after = match out.get(i + 1) {
        Some(p) => p.angle,
        None if full => first + dir * turn,
        None => best.angle,
    };
    let (a, b) = (before.min(after), before.max(after));
    if b - a <= 0.0 {
        return best;
    }
    let dof = task.model.dof();
    let seed = best.q;
    let seed = seed.get(..dof).unwrap_or(&[]);
    let eval = |theta: f64| task.solve(data, theta, seed).ok();
    let m = |p: &Option<AnglePoint>| p.map_or(f64::INFINITY, |p| p.measure);
    let found = crate::golden::minimise(a, b, REFINE_ITERATIONS, eval, m);
    match found {
        Some(mut f) if f.measure < best.measure => {
            f.seed = best.seed;
            // Back into the sweep's own range when the search crossed one of its ends.
            let (lo, hi) = (first.min(last), first.max(last));
            if full && f.angle < lo - 0.5 * step {
                f.angle += turn;
            } else if full && f.angle > hi + 0.5 * step {
                f.angle -= turn;
            }
            f
        }
        _ => best,
    }
}
