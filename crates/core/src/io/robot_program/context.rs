//! What the per-language writers share: the target, the options, the workspace for the
//! configuration words and what the output has set so far, and the number and pose formats.

use std::fmt::Write as _;
use std::string::String;
use std::vec::Vec;

use nalgebra::Isometry3;

use super::{ProgramError, ProgramOptions, Target};
use crate::controller::{Convention, Vendor};
use crate::error::TickError;
use crate::io::decimate::Kept;
use crate::machining::job::JobSample;
use crate::machining::{Motion, PathControl};
use crate::vjm::{Data, Model};

/// What the per-language writers share: the target, the options, the workspace for the
/// configuration words, and what the output has set so far.
#[derive(Debug)]
pub(crate) struct Context<'a> {
    pub target: Target<'a>,
    pub options: ProgramOptions,
    pub data: Data,
    /// The program line of the last comment.
    pub line: usize,
    /// The last speed written \[m/s\] (NaN: none yet).
    pub speed: f64,
    /// The last blending tolerance written \[m\] (NaN: none yet).
    pub blend: f64,
    /// The dwell move last waited for.
    pub dwelt: usize,
    /// Motions written.
    pub motions: usize,
}

impl Context<'_> {
    /// The convention (checked present by [`super::RobotProgram::new`] for the vendors' languages).
    pub fn convention(&self) -> Convention {
        self.target.convention.copied().unwrap_or_else(|| {
            // CSV only: it reads the model as it is (never reached for the others).
            Convention {
                vendor: Vendor::UniversalRobots,
                sign: [1.0; crate::vjm::MAX_DOF],
                offset: [0.0; crate::vjm::MAX_DOF],
                revolute: [true; crate::vjm::MAX_DOF],
                dof: self.target.model.dof(),
                base: Isometry3::identity(),
                tool: Isometry3::identity(),
            }
        })
    }

    /// The controller's axis values of a sample's compensated joints, as its programs write
    /// them: degrees and mm (`degrees`, KRL and RAPID) or rad and m (URScript).
    pub fn axes(&self, s: &JobSample, degrees: bool) -> Vec<f64> {
        let c = self.convention();
        let a = c.to_controller(self.joints(s));
        a.iter()
            .take(c.dof)
            .zip(&c.revolute)
            .map(|(v, revolute)| match (degrees, revolute) {
                (false, _) => *v,
                (true, true) => v.to_degrees(),
                (true, false) => v * 1e3,
            })
            .collect()
    }

    /// The model's joints of a sample (compensated) \[rad or m\].
    pub fn joints<'s>(&self, s: &'s JobSample) -> &'s [f64] {
        s.q_commanded.get(..self.target.model.dof()).unwrap_or(&[])
    }

    /// The configuration words' inputs: the model, the workspace, the sample's joints.
    pub fn arm<'s>(&mut self, s: &'s JobSample) -> (&Model, &mut Data, &'s [f64]) {
        let dof = self.target.model.dof();
        (
            self.target.model,
            &mut self.data,
            s.q_commanded.get(..dof).unwrap_or(&[]),
        )
    }

    /// The comment of a new program line, with `prefix` (`;`, `!`, `#`).
    pub fn line_comment(&mut self, out: &mut String, indent: &str, prefix: &str, s: &JobSample) {
        if s.path.line != self.line {
            self.line = s.path.line;
            let _ = writeln!(
                out,
                "{indent}{prefix} line {}, t = {:.3} s",
                s.path.line, s.path.time
            );
        }
    }

    /// What every language writes before a motion: the comment of a new program line
    /// (`prefix` `;`, `!`, `#`) and, on a dwell's move, the language's `wait` once (`true`:
    /// the motion itself is skipped).
    pub fn preamble(
        &mut self,
        out: &mut String,
        indent: &str,
        prefix: &str,
        s: &JobSample,
        wait: impl Fn(f64) -> String,
    ) -> bool {
        self.line_comment(out, indent, prefix, s);
        match self.dwell(s) {
            Some(Some(seconds)) => {
                let _ = writeln!(out, "{indent}{}", wait(seconds));
                true
            }
            Some(None) => true,
            None => false,
        }
    }

    /// The dwell of a sample's move, `Some(seconds)` once per dwell (the motion is skipped).
    pub fn dwell(&mut self, s: &JobSample) -> Option<Option<f64>> {
        let mv = self.target.program.moves.get(s.path.move_index)?;
        let Motion::Dwell { seconds } = mv.motion else {
            return None;
        };
        if self.dwelt == s.path.move_index {
            return Some(None);
        }
        self.dwelt = s.path.move_index;
        Some(Some(seconds))
    }

    /// The programmed speed of a sample's move \[m/s\]: its feed, or the rapid speed.
    pub fn speed_of(&self, s: &JobSample) -> f64 {
        match self.target.program.moves.get(s.path.move_index) {
            Some(m) if m.is_feed() && m.feed > 0.0 => m.feed,
            _ => self.target.rapid_speed,
        }
    }

    /// How far the motion may blend past a kept sample \[m\]: 0 at an exact stop, else the
    /// move's `G64 P` tolerance, or the decimation's.
    pub fn blend_of(&self, k: &Kept) -> f64 {
        if k.stop {
            return 0.0;
        }
        match self
            .target
            .program
            .moves
            .get(k.sample.path.move_index)
            .map(|m| m.path_control)
        {
            Some(PathControl::Blend { tolerance, .. }) if tolerance > 0.0 => tolerance,
            _ => self.options.tolerance,
        }
    }

    /// A sample's error for the program.
    pub fn at(s: &JobSample, error: TickError) -> ProgramError {
        ProgramError::Sample {
            line: s.path.line,
            time: s.path.time,
            error,
        }
    }
}

/// `values` joined by `sep`, each with `decimals` decimals.
pub(crate) fn join(values: &[f64], sep: &str, decimals: usize) -> String {
    let mut out = String::new();
    for (i, v) in values.iter().enumerate() {
        let _ = write!(out, "{}{v:.decimals$}", if i > 0 { sep } else { "" });
    }
    out
}

/// The pose a Cartesian program writes for a sample: the commanded TCP, workpiece frame.
pub(crate) fn pose(s: &JobSample) -> Isometry3<f64> {
    s.commanded
}
