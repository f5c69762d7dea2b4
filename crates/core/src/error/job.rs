//! The offline pass over a machining program ([`crate::machining::job`]) failed: every
//! failure names the program line (and the time into the program) where it happened.

use core::fmt;

use super::{BuildError, TickError};

/// A machining job that could not be run: its setup was invalid, or a sample of the program
/// could not be reached, cut or corrected. No heap, `Copy`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum JobError {
    /// The setup (placement, tool, stock, path options, ...) or the program as a whole.
    Setup(BuildError),
    /// A sample failed: the pose out of reach, off the joint limits or singular
    /// ([`TickError::NotConverged`], [`TickError::JointLimit`], [`TickError::Singular`]), an
    /// engagement out of the force model's range, ...
    AtLine {
        /// Program line (1-based).
        line: usize,
        /// Time into the program \[s\].
        time: f64,
        /// What went wrong there.
        error: TickError,
    },
    /// The tool cuts material with the spindle off (no `M3`/`S` before the move).
    SpindleOff {
        /// Program line (1-based).
        line: usize,
        /// Time into the program \[s\].
        time: f64,
    },
    /// The tool in the spindle cuts, and the job's tool table does not have it.
    UnknownTool {
        /// Program line (1-based).
        line: usize,
        /// Time into the program \[s\].
        time: f64,
        /// The program's tool number (`T`).
        tool: u32,
    },
    /// A rapid move (`G0`) runs more than [`crate::machining::job::RAPID_SKIM`] into the
    /// stock: a crash on the machine.
    RapidInStock {
        /// Program line (1-based).
        line: usize,
        /// Time into the program \[s\].
        time: f64,
        /// Stock above the tip there \[m\].
        depth: f64,
    },
}

impl JobError {
    /// The program line the error names, if it names one.
    pub fn line(&self) -> Option<usize> {
        match *self {
            Self::Setup(_) => None,
            Self::AtLine { line, .. }
            | Self::SpindleOff { line, .. }
            | Self::UnknownTool { line, .. }
            | Self::RapidInStock { line, .. } => Some(line),
        }
    }
}

impl fmt::Display for JobError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Setup(e) => write!(f, "machining job setup: {e}"),
            Self::AtLine { line, time, error } => {
                let what = match error {
                    TickError::NotConverged { .. } => "the pose is out of reach: ",
                    TickError::JointLimit { .. } => "the pose is off the joint limits: ",
                    TickError::Singular { .. } => "the pose is singular: ",
                    _ => "",
                };
                write!(f, "program line {line} (t = {time:.3} s): {what}{error}")
            }
            Self::SpindleOff { line, time } => write!(
                f,
                "program line {line} (t = {time:.3} s): the tool cuts the stock with the spindle \
                 off (expected M3 or M4 with an S word before the cut; a program for a \
                 hand-started spindle needs its speed: CLI --spindle-rpm, Python spindle_rpm=)"
            ),
            Self::UnknownTool { line, time, tool } => write!(
                f,
                "program line {line} (t = {time:.3} s): tool T{tool} cuts, and the tool table \
                 has no T{tool} (expected a [[tool]] or a T{tool} line for it)"
            ),
            Self::RapidInStock { line, time, depth } => write!(
                f,
                "program line {line} (t = {time:.3} s): a rapid move (G0) runs {:.3} mm into \
                 the stock (expected G1 for cutting moves)",
                depth * 1e3
            ),
        }
    }
}

impl core::error::Error for JobError {}

impl From<BuildError> for JobError {
    fn from(e: BuildError) -> Self {
        Self::Setup(e)
    }
}
