//! Command line of `deflect-sim` (binary): the clap definitions and the argument types, with
//! their conversions to the library's types; the documented range of every numeric flag
//! ([`Range`], shown in its `--help`) and the checks of the arguments before any work
//! ([`Command::check`]); the two kinds of errors and their exit codes ([`CliError`]). Each
//! subcommand's arguments have their file: `parallel` (`reproduce`, `static-test`, `fit`,
//! `run`), `milling`, `contour`, `serial`, `atlas`, `job` (with `tool`, the flags it shares
//! with `milling`), `place`, `delta`.
//!
//! The ranges keep every accepted command within a few minutes of run time and a few hundred
//! MB of memory. Release build, measured on 2 cores: `milling` (the 16-body KR 300) at its
//! largest cut, feed, force and smallest cycle about 1.5 min and 35 MB; `serial` with the
//! defaults about 30 s and 17 MB (most of it the six static-compliance checks); `contour` is
//! bounded by the tracer's 4000-step limit per object
//! (about 0.7 M physics steps, under 10 s per object); `reproduce` with 50 fixed-point
//! iterations about 2 s.

use std::path::PathBuf;

use clap::{Parser, Subcommand};
use deflect_sim::SimError;

/// Why a command did not succeed, with its exit code.
#[derive(Debug, Clone, PartialEq)]
pub enum CliError {
    /// A refused command line: a value out of range, an input path that is not a readable
    /// file, an output directory that cannot be created or written. Exit code 2, as clap's
    /// own usage errors.
    Usage(String),
    /// The command failed: an input file's content, a scenario error, a file that could not be
    /// written. Exit code 1.
    Failure(String),
}

impl CliError {
    /// The process exit code: 2 for usage, 1 for failure.
    pub fn code(&self) -> u8 {
        match self {
            Self::Usage(_) => 2,
            Self::Failure(_) => 1,
        }
    }

    /// The message.
    pub fn message(&self) -> &str {
        match self {
            Self::Usage(m) | Self::Failure(m) => m,
        }
    }
}

impl From<SimError> for CliError {
    fn from(e: SimError) -> Self {
        Self::Failure(e.0)
    }
}

mod atlas;
mod contour;
mod delta;
mod job;
mod milling;
mod parallel;
mod place;
/// The ranges of the numeric flags.
mod range;
mod serial;
mod tool;

pub use atlas::AtlasArgs;
pub use contour::ContourArgs;
pub use delta::DeltaArgs;
pub use job::{JobArgs, SpinArg};
pub use milling::MillingArgs;
pub use parallel::{Correction, FitArgs, ReproduceArgs, RunArgs, StaticTestArgs};
pub use place::PlaceArgs;
pub use range::*;
pub use serial::{ModelArg, SerialArgs, TaskArg};
pub use tool::ToolArgs;

// The command line.
#[derive(Parser, Debug)]
#[command(
    name = "deflect-sim",
    version,
    about = "deflect's testbed in rapier3d-f64: the D'Alembert trajectory correction (Paksoy et \
             al.) on the five-bar (reproduce, static-test, fit, run), the Delta (delta) and serial \
             arms (serial); robot machining after Hähn and Weigold: online and hybrid compensation \
             on the flexible KR 300 (milling), machining jobs from CAM programs, 2.5-D and \
             five-axis (job), the workpiece's placement (place), the compliance atlas (atlas); \
             force-feedback contour tracing (contour). Without a subcommand: reproduce."
)]
pub struct Cli {
    // The scenario; `reproduce` if none.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Output directory (created if missing; must be writable).
    #[arg(long, global = true, default_value = "out")]
    pub out: PathBuf,
}

// The scenario commands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// The whole pipeline: static tests, fit, all motions at 1-5 g for OC/NC x GU/GL, with and
    /// without correction; tables, CSV/JSON, MCAP and plots.
    Reproduce(ReproduceArgs),
    /// Simulated static tests (15 nodes x 2 axes x 49..245 N), written as CSV (columns
    /// x_mm, y_mm, force_axis, force_N, dx_mm, dy_mm).
    StaticTest(StaticTestArgs),
    /// Fits a compliance map from a static-test CSV (or runs the static tests first) and
    /// reports its held-out prediction error.
    Fit(FitArgs),
    /// One motion on one configuration, uncorrected and/or corrected; writes an MCAP log.
    Run(RunArgs),
    /// Milling scenario for the online force-based compensation (Hähn & Weigold): their
    /// KR 300 R2500 (robots/) as a flexible arm in rapier mills a groove; uncompensated,
    /// Cartesian compensation and pilot control; stiffness and sensor identification. Writes milling_summary.{txt,csv,json},
    /// milling.mcap and PNG plots.
    Milling(MillingArgs),
    /// Force-feedback contour tracing (deflect-core's contour tracer, Eq. 21) of a circle, a
    /// rectangle and an L-shape by a 2R arm with compliant, backlashed joints; shape recovered
    /// raw and with the Eq. 10 compensation. Writes contour_summary.{txt,csv,json},
    /// contour.mcap, contour_*.png.
    Contour(ContourArgs),
    /// A flexible serial arm from a URDF and a stiffness file (default: the KR 300 R2500 of
    /// deflect's robots/) in rapier carries a payload along a line and a circle in pose at
    /// high acceleration, uncorrected and with deflect-core's 6-D D'Alembert corrector for
    /// serial arms. Writes serial_summary.{txt,csv,json}, serial.mcap, serial.png.
    Serial(SerialArgs),
    /// Workspace compliance atlas: for every point of a grid on a horizontal plane, the
    /// rotation about the tool axis that deflects least under the process wrench (posture IK
    /// within the joint limits, exact virtual-joint deflection), on worker threads. Writes
    /// atlas.npz (compressed NumPy archive, SI units) and atlas.png (heat map of the best
    /// deflection).
    Atlas(AtlasArgs),
    /// A machining job offline (the offline half of Hähn & Weigold's hybrid compensation): a
    /// G-code program (or tool points CSV) driven at its feeds on an arm (default: the KR 300
    /// R2500 and data/groove_and_pocket.nc, built in), the stock cut along it, the milling
    /// force from the chip at every sample, the arm's deflection and the compensated joints,
    /// streamed in bounded memory. Writes job_samples.npz (every sample), job.mcap (Foxglove),
    /// job_compensated.nc, job_part.png (the part's deviation, with and without
    /// compensation) and job_summary.{txt,json} (per operation, the ten lines of largest
    /// force); job_samples.csv with --samples-csv.
    Job(JobArgs),
    /// Where to put the workpiece: the placement (position in --box, turn about the vertical
    /// in --yaw) of least predicted deflection along the job's program (with --spin optimize:
    /// the spin optimised along it at every placement), a grid and a compass refinement on
    /// --threads threads, the program's forces computed once. Takes every `job` flag. Writes
    /// place_summary.{txt,json} (the best placement, the grid) and place.png (heat map).
    Place(PlaceArgs),
    /// The D'Alembert correction on a Delta robot (Clavel's parallel robot of pick and
    /// place): a flexible Delta in rapier, static tests on a 3-D grid over the workspace, the
    /// compliance map fitted per node, a 0.3 m move at 5-10 g uncorrected and corrected every
    /// tick. Writes delta_summary.{txt,json}, delta_map.json (format_version 2) and
    /// delta_samples.csv.
    Delta(DeltaArgs),
}

/// `n` as a `u64` (saturating; usize is 64 bits or less on every supported target).
fn count(n: usize) -> u64 {
    u64::try_from(n).unwrap_or(u64::MAX)
}

impl Command {
    /// Checks the arguments against their documented ranges before any work: the first value
    /// out of range is a usage error naming the flag, the value and the range.
    pub fn check(&self) -> Result<(), CliError> {
        match self {
            Self::Reproduce(a) => a.check(),
            Self::StaticTest(_) | Self::Fit(_) => Ok(()),
            Self::Run(a) => a.check(),
            Self::Milling(a) => a.check(),
            Self::Contour(a) => a.check(),
            Self::Serial(a) => a.check(),
            Self::Atlas(a) => a.check(),
            Self::Job(a) => a.check(),
            Self::Place(a) => a.check(),
            Self::Delta(a) => a.check(),
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::panic)]
mod tests;
