//! Corner blending: the next run starts before the last one has stopped.
//!
//! A controller in blending mode (`G64 P`, KUKA's approximate positioning, a UR blend radius)
//! does not stop at a corner: it starts the next move while the last one decelerates. deflect
//! blends as the velocity-superposition controllers do. Each run keeps its own time-optimal
//! jerk-limited rest-to-rest profile. At a blended corner the next run's profile starts
//! `overlap` seconds before the last one ends, and the tool's displacement is the sum of the
//! two runs' displacements from the corner. That makes the blend:
//!
//! * **jerk-limited**: the sum of two jerk-limited profiles (along each axis at most twice
//!   the jerk limit, as at most twice the acceleration limit: the summary's peak acceleration
//!   per line shows what the corner asks of the arm);
//! * **within the tolerance**: during the overlap the tool is `r_a + d_b` from the corner at
//!   most, `r_a` the last run's distance still to go and `d_b` the next run's distance gone.
//!   `overlap` is the largest time for which both together stay within the tolerance `P`. The
//!   path therefore stays within `P` of the corner: its distance from the programmed path is
//!   smaller still;
//! * **no faster than the feed** at a corner between runs of one feed: the deceleration is
//!   the time-reversed acceleration, so the two speeds sum to the feed. `overlap` is at most
//!   the shorter of the two ramps, so at most two runs move at once;
//! * **an exact stop where the program says so**: at `G61`/`G61.1` and at a dwell.
//!
//! `P = 0` is LinuxCNC's "as fast as possible". The overlap is then the whole shorter ramp.

use super::plan::{Plan, Run};
use crate::error::{BuildError, param};
use crate::machining::{Motion, PathControl, Program};

/// How corners between runs are driven ([`super::PathOptions::blending`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Blending {
    /// Exact stop at every corner, whatever the program says: the tool stays on the
    /// programmed geometry (what a prediction of the programmed part needs).
    #[default]
    ExactStop,
    /// The program's path control per move: `G64 P` blends the corner at the move's end
    /// within `P` (`P` = 0: as far as the two ramps allow), `G61` and `G61.1` stop.
    Program,
    /// Every corner blended within this tolerance \[m\] (>= 0, 0 as in `G64` without `P`),
    /// whatever the program says: a controller's own blending setting.
    Tolerance(f64),
}

/// Largest blending tolerance \[m\] ([`Blending::Tolerance`] and a program's `G64 P`): 0.1 m.
/// No machining controller blends corners by more.
pub const MAX_BLEND_TOLERANCE: f64 = 0.1;

impl Blending {
    /// Checks the tolerance ([`BuildError::InvalidParameter`] naming it).
    pub fn validate(&self) -> Result<(), BuildError> {
        if let Self::Tolerance(p) = *self {
            param(
                "blending tolerance",
                p,
                (0.0..=MAX_BLEND_TOLERANCE).contains(&p),
                "in [0, MAX_BLEND_TOLERANCE] = [0, 0.1] m",
            )?;
        }
        Ok(())
    }

    /// The tolerance \[m\] at the corner after `m`, or None for an exact stop there.
    fn at(&self, m: &crate::machining::Move) -> Option<f64> {
        match (*self, m.path_control) {
            (Self::ExactStop, _) => None,
            (Self::Tolerance(p), _) => Some(p),
            (Self::Program, PathControl::Blend { tolerance, .. }) => Some(tolerance),
            (Self::Program, PathControl::ExactPath | PathControl::ExactStop) => None,
        }
    }
}

/// Sets each run's [`Run::blend_in`] and moves the runs' start times by the overlaps.
/// [`BuildError::InvalidEntry`] for a tolerance past the moves at its corner (longer than both
/// of them: the blend could not reach it) or past [`MAX_BLEND_TOLERANCE`].
pub(super) fn overlap(
    program: &Program,
    blending: &Blending,
    plan: &mut Plan,
) -> Result<(), BuildError> {
    if *blending == Blending::ExactStop {
        return Ok(());
    }
    let move_of = |plan: &Plan, seg: usize| plan.segs.get(seg).and_then(|&i| program.moves.get(i));
    for k in 1..plan.runs.len() {
        let (Some(&a), Some(&b)) = (plan.runs.get(k - 1), plan.runs.get(k)) else {
            continue;
        };
        let (Some(ma), Some(mb)) = (move_of(plan, a.last), move_of(plan, b.first)) else {
            continue;
        };
        let dwell = |m: &crate::machining::Move| matches!(m.motion, Motion::Dwell { .. });
        if dwell(ma) || dwell(mb) || a.hold > 0.0 || b.hold > 0.0 {
            continue;
        }
        let Some(p) = blending.at(ma) else {
            continue;
        };
        let longer = ma.length().max(mb.length());
        if !(p <= MAX_BLEND_TOLERANCE && p <= longer) {
            return Err(BuildError::InvalidEntry {
                what: "blending tolerance (G64 P) past the moves at its corner (index: the \
                       program line of the move into the corner)",
                index: ma.line,
                value: p,
                expected: "at most the longer of the two moves and MAX_BLEND_TOLERANCE",
            });
        }
        let t = window(&a, &b, p);
        if let Some(run) = plan.runs.get_mut(k) {
            run.blend_in = t;
        }
    }
    let mut t0 = 0.0;
    for run in &mut plan.runs {
        t0 -= run.blend_in;
        run.t0 = t0;
        t0 += run.duration();
    }
    Ok(())
}

/// The overlap \[s\] of run `b`'s start with run `a`'s end under tolerance `p` \[m\]: the
/// largest time within both ramps whose distances (the last run's tail, by the profile's
/// symmetry its head's, and the next run's head) sum to at most `p`; the whole shorter ramp
/// for `p = 0`. Bisection to 1e-12 s (the two distances rise with the time).
fn window(a: &Run, b: &Run, p: f64) -> f64 {
    let most = a.profile.accel_time().min(b.profile.accel_time());
    let reach = |t: f64| a.profile.sample(t).s + b.profile.sample(t).s;
    if most.is_nan() || most <= 0.0 {
        return 0.0;
    }
    if p == 0.0 || reach(most) <= p {
        return most;
    }
    let (mut lo, mut hi) = (0.0, most);
    while hi - lo > 1.0e-12 {
        let mid = 0.5 * (lo + hi);
        if reach(mid) <= p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}
