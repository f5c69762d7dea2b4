//! The streamed decimation every writer of a run shares (`std`): samples are dropped while
//! the straight motion between the kept ones holds every dropped one (a test each writer
//! gives: a tip within a distance of the chord, a pose, joints), within a window of at most
//! [`MAX_DROPPED`] samples, whatever the program's length. The first and the last sample are
//! kept, and the last sample of every program move (the move ends there: a corner, a feed
//! change, an exact stop), so a block of the output never spans two lines of the program.

use std::collections::VecDeque;

use crate::machining::job::JobSample;

/// Most samples one dropped run may hold before a sample is kept anyway (bounds the
/// decimation's time to `O(n x MAX_DROPPED)`).
pub const MAX_DROPPED: usize = 256;

/// A sample the decimation keeps.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Kept {
    /// The sample.
    pub sample: JobSample,
    /// The path stops after it (its rest-to-rest run ends: an exact stop), or the run ends.
    pub stop: bool,
}

/// The state of a streamed decimation: the samples from the last kept one (the anchor) to
/// the newest decided one, and the newest sample, decided when the next one arrives.
#[derive(Debug, Default)]
pub(crate) struct Decimator {
    window: VecDeque<JobSample>,
    pending: Option<JobSample>,
    last_kept: Option<f64>,
}

impl Decimator {
    /// The next sample, in time order: `holds(anchor, end, dropped)` says whether the
    /// straight motion from `anchor` to `end` holds `dropped`; `keep` gets each kept sample
    /// once, in time order.
    pub fn push(
        &mut self,
        s: &JobSample,
        holds: &impl Fn(&JobSample, &JobSample, &JobSample) -> bool,
        keep: &mut impl FnMut(&Kept),
    ) {
        if let Some(prev) = self.pending.replace(*s) {
            let move_end = prev.path.move_index != s.path.move_index;
            let stop = prev.path.run != s.path.run;
            self.decide(prev, move_end, stop, holds, keep);
        }
    }

    /// The last sample, kept (the run ends there).
    pub fn finish(
        &mut self,
        holds: &impl Fn(&JobSample, &JobSample, &JobSample) -> bool,
        keep: &mut impl FnMut(&Kept),
    ) {
        if let Some(last) = self.pending.take() {
            self.decide(last, true, true, holds, keep);
        }
    }

    fn emit(&mut self, kept: Kept, keep: &mut impl FnMut(&Kept)) {
        if self.last_kept == Some(kept.sample.path.time) {
            return;
        }
        self.last_kept = Some(kept.sample.path.time);
        keep(&kept);
    }

    /// Sample `s` joins the window: kept (with the one before it) where the straight motion
    /// from the anchor no longer holds the dropped samples, and where its move ends.
    fn decide(
        &mut self,
        s: JobSample,
        move_end: bool,
        stop: bool,
        holds: &impl Fn(&JobSample, &JobSample, &JobSample) -> bool,
        keep: &mut impl FnMut(&Kept),
    ) {
        let through = |sample: JobSample| Kept {
            sample,
            stop: false,
        };
        if self.window.is_empty() {
            // The first sample is kept: where the motion starts (at rest).
            self.window.push_back(s);
            self.emit(
                Kept {
                    sample: s,
                    stop: true,
                },
                keep,
            );
            return;
        }
        self.window.push_back(s);
        let n = self.window.len();
        let within = n - 1 <= MAX_DROPPED
            && match (self.window.front(), self.window.back()) {
                (Some(a), Some(b)) => self.window.range(1..n - 1).all(|x| holds(a, b, x)),
                _ => true,
            };
        if !within {
            // Keep the sample before this one; it anchors the next stretch.
            self.window.pop_back();
            if let Some(before) = self.window.pop_back() {
                self.emit(through(before), keep);
                self.window.clear();
                self.window.push_back(before);
            }
            self.window.push_back(s);
        }
        if move_end {
            self.emit(Kept { sample: s, stop }, keep);
            self.window.clear();
            self.window.push_back(s);
        }
    }
}
