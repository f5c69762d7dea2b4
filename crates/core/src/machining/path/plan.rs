//! The program planned as runs: each a rest-to-rest profile over consecutive moves (or a
//! dwell), with its start time and its overlap with the run before when the corner blends.

use alloc::vec::Vec;

use crate::motion::Profile;

/// One rest-to-rest profile over the moves `segs[first..=last]`, or a dwell of `hold`
/// seconds at the one move `segs[first]` (then `profile` is the zero-length profile);
/// `blend_in` \[s\] is how long it overlaps the run before (0: it starts from rest).
#[derive(Debug, Clone, Copy)]
pub(super) struct Run {
    pub(super) first: usize,
    pub(super) last: usize,
    pub(super) t0: f64,
    pub(super) profile: Profile,
    pub(super) hold: f64,
    pub(super) blend_in: f64,
}

impl Run {
    pub(super) fn duration(&self) -> f64 {
        self.profile.duration() + self.hold
    }
}

/// The program planned: the moves with motion (`segs`, indices into the program), the arc
/// length at which each starts within its run (`s0`, parallel to `segs`), and the runs.
#[derive(Debug, Clone)]
pub(super) struct Plan {
    pub(super) segs: Vec<usize>,
    pub(super) s0: Vec<f64>,
    pub(super) runs: Vec<Run>,
}

impl Plan {
    pub(super) fn duration(&self) -> f64 {
        self.runs.last().map_or(0.0, |r| r.t0 + r.duration())
    }

    /// The move of `run` holding arc length `s`: the last one starting at or before it,
    /// searched forwards from `seg`.
    pub(super) fn locate(&self, run: &Run, s: f64, seg: usize) -> usize {
        let mut seg = seg.max(run.first);
        while seg < run.last && self.s0.get(seg + 1).is_some_and(|&x| s >= x) {
            seg += 1;
        }
        seg
    }

    /// [`Self::locate`] searched backwards from the run's last move (a blend's tail is near
    /// the end).
    pub(super) fn locate_back(&self, run: &Run, s: f64) -> usize {
        let mut seg = run.last;
        while seg > run.first && self.s0.get(seg).is_some_and(|&x| s < x) {
            seg -= 1;
        }
        seg
    }
}
