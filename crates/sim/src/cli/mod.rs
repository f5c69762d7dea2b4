//! Command line of `deflect-sim` (binary): the clap definitions and the argument types, with
//! their conversions to the library's types; the documented range of every numeric flag
//! ([`Range`], shown in its `--help`) and the checks of the arguments before any work
//! ([`Command::check`]); the two kinds of errors and their exit codes ([`CliError`]).
//!
//! The ranges keep every accepted command within a few minutes of run time and a few hundred
//! MB of memory. Release build, measured on 2 cores: `milling` (the 16-body KR 300) at its
//! largest cut, feed, force and smallest cycle about 1.5 min and 35 MB; `serial` with the
//! defaults about 30 s and 17 MB (most of it the six static-compliance checks); `contour` is
//! bounded by the tracer's 4000-step limit per object
//! (about 0.7 M physics steps, under 10 s per object); `reproduce` with 50 fixed-point
//! iterations about 2 s.

use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};
use deflect_sim::SimError;
use deflect_sim::scenes::parallel::robot;
use deflect_sim::scenes::parallel::robot::{Constraint, Head};
use deflect_sim::scenes::parallel::run::Motion;

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

/// The ranges of the numeric flags (in `cli/range.rs`).
mod atlas;
mod range;
pub use atlas::AtlasArgs;
pub use range::*;

// The command line.
#[derive(Parser, Debug)]
#[command(
    name = "deflect-sim",
    version,
    about = "Simulated reproduction of the D'Alembert trajectory correction (Paksoy et al.) on a \
             rapier3d-f64 model of the 2-DoF parallel robot. Without a subcommand: reproduce."
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
    StaticTest {
        /// Mechanism.
        #[arg(long, value_enum, default_value_t = Mech::Oc)]
        mechanism: Mech,
    },
    /// Fits a compliance map from a static-test CSV (or runs the static tests first) and
    /// reports its held-out prediction error.
    Fit {
        /// Mechanism (for fresh static tests and the held-out tests).
        #[arg(long, value_enum, default_value_t = Mech::Oc)]
        mechanism: Mech,
        /// Static-test CSV written by `static-test` (columns x_mm, y_mm, force_axis, force_N,
        /// dx_mm, dy_mm; the older header x, y, force_axis, force, dx, dy is read in mm and N);
        /// a regular file of at most 16 MiB.
        #[arg(long)]
        input: Option<PathBuf>,
    },
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
}

// Arguments of `serial` (help texts with their ranges in the `help` attributes).
#[derive(clap::Args, Debug)]
pub struct SerialArgs {
    /// Robot URDF (a regular file of at most 16 MiB, with <inertial> for the links' masses);
    /// default: the KR 300 R2500 built into deflect-sim. Needs --stiffness.
    #[arg(long, requires = "stiffness")]
    pub urdf: Option<PathBuf>,
    /// Stiffness TOML of the virtual joints (deflect's format, see robots/); default: the
    /// KR 300's.
    #[arg(long)]
    pub stiffness: Option<PathBuf>,
    /// Base link of the chain (default: the URDF's root).
    #[arg(long)]
    pub base: Option<String>,
    /// Tip (TCP) link of the chain; default: "tcp" for the KR 300, else the URDF's deepest
    /// leaf link (an error if two leaves are equally deep).
    #[arg(long)]
    pub tip: Option<String>,
    /// Start joints [rad], comma-separated, one per actuated joint; default: the KR 300's
    /// milling pose, else the most dexterous pose of the grid {-1, -0.5, 0, 0.5, 1}^n rad
    /// inside the joint limits (largest smallest singular value of the Jacobian).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub q0: Option<Vec<f64>>,
    #[arg(long, allow_negative_numbers = true, help = PAYLOAD_MASS.help(
        "Payload and tool mass [kg], a cube of aluminium (2700 kg/m^3) centred on the tool \
         axis half a side beyond the flange",
        "Default: 150 kg on the KR 300, else 10 % of the URDF's link masses"
    ))]
    pub payload_mass: Option<f64>,
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true, help = SERIAL_G.help("Peak acceleration [g]", ""))]
    pub g: f64,
    #[arg(long, allow_negative_numbers = true, help = SCALE.help(
        "Size of the motions [m]: line (0.3, 0.2, -0.1) x scale, circle radius 0.15 x scale",
        "Default: 1 on the KR 300, else a third of the TCP's distance from the base at zero joints"
    ))]
    pub scale: Option<f64>,
    #[arg(long, allow_negative_numbers = true, help = V_MAX.help("Largest speed [m/s]", "Default: 2 x scale per second"))]
    pub v_max: Option<f64>,
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true, help = RAMP.help(
        "Time to ramp the acceleration up [s] (sets the jerk)",
        ""
    ))]
    pub ramp: f64,
    #[arg(long, default_value_t = 0.3, allow_negative_numbers = true, help = TURN.help(
        "Turn of the tool about the vertical over each motion [rad]",
        ""
    ))]
    pub turn: f64,
    /// Correct the payload's inertial wrench only (the paper's D'Alembert force); by default
    /// the links' own inertial loads are corrected as well when the URDF has masses.
    #[arg(long)]
    pub payload_only: bool,
    /// Deflection model the corrector inverts.
    #[arg(long, value_enum, default_value_t = ModelArg::Exact)]
    pub model: ModelArg,
    #[arg(long, default_value_t = 2, help = JOBS.help(
        "Worker threads (one run each; results do not depend on it)",
        "0 is refused"
    ))]
    pub jobs: usize,
}

// Deflection model of the serial corrector.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq)]
pub enum ModelArg {
    // Virtual-joint deflection, Eq. 2-9 of Hahn and Weigold.
    Exact,
    // The linearized compliance J K^-1 J^T.
    Linearized,
}

impl SerialArgs {
    /// See [`Command::check`]; the files are checked and loaded by the scenario's `load`.
    pub fn check(&self) -> Result<(), CliError> {
        if let Some(m) = self.payload_mass {
            PAYLOAD_MASS.check(m)?;
        }
        SERIAL_G.check(self.g)?;
        if let Some(v) = self.scale {
            SCALE.check(v)?;
        }
        if let Some(v) = self.v_max {
            V_MAX.check(v)?;
        }
        RAMP.check(self.ramp)?;
        TURN.check(self.turn)?;
        if let Some(q) = &self.q0
            && let Some((i, v)) = q.iter().enumerate().find(|(_, v)| !v.is_finite())
        {
            return Err(CliError::Usage(format!(
                "--q0: joint {i} is {v}: expected a finite angle [rad]"
            )));
        }
        JOBS.check_int(count(self.jobs))
    }
}

// Arguments of `contour` (help texts with their ranges in the `help` attributes).
#[derive(clap::Args, Debug)]
pub struct ContourArgs {
    #[arg(long, default_value_t = 1.5, help = STEP_MM.help("Tracer step along the edge [mm]", ""))]
    pub step_mm: f64,
    #[arg(long, default_value_t = 6.0, help = TARGET_FORCE.help(
        "Target contact force [N]",
        "Between the tracer's contact (1.5 N) and jam (30 N) forces, both excluded"
    ))]
    pub target_force: f64,
    #[arg(long, default_value_t = 0.3, help = NOISE.help(
        "Force sensor noise, standard deviation per sample and axis [N]",
        ""
    ))]
    pub noise: f64,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    #[arg(long, default_value_t = 2, help = JOBS.help(
        "Worker threads (one object each; results do not depend on it)",
        "0 is refused"
    ))]
    pub jobs: usize,
}

// Arguments of `milling` (help texts with their ranges in the `help` attributes).
#[derive(clap::Args, Debug)]
pub struct MillingArgs {
    #[arg(long, default_value_t = 25.0, help = FEED.help("Feed speed [mm/s] (paper: 25)", ""))]
    pub feed: f64,
    #[arg(long, default_value_t = 550.0, help = FORCE.help(
        "Magnitude of the process force [N] (direction as the default [-386, 386, -60] N)",
        ""
    ))]
    pub force: f64,
    #[arg(long, default_value_t = 1.2, help = CUT.help("Cutting time [s]", ""))]
    pub cut: f64,
    #[arg(long, default_value_t = 100.0, help = RISE_MS.help(
        "Rise and fall time of the force at cutter entry and exit [ms]",
        ""
    ))]
    pub rise_ms: f64,
    #[arg(long, default_value_t = 4.0, help = CYCLE_MS.help(
        "Control cycle [ms] (paper: 4, KUKA RSI)",
        "A multiple of the 0.5 ms physics step"
    ))]
    pub cycle_ms: f64,
    #[arg(long, default_value_t = 40.0, help = LEAD_MS.help(
        "Lead of the offline force estimate over the real force [ms]",
        ""
    ))]
    pub lead_ms: f64,
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true, help = ESTIMATE_ERROR.help(
        "Relative error of the offline force estimate (0.1 = 10 % too large)",
        "Negative values: an estimate too small"
    ))]
    pub estimate_error: f64,
    /// Seed of the sensor and measurement noise.
    #[arg(long, default_value_t = 6)]
    pub seed: u64,
    #[arg(long, default_value_t = 3, help = ID_POSES.help(
        "Poses of the stiffness identification's static tests (each about 3.4 s simulated)",
        "Fewer poses: a faster run, fewer identifiable axes"
    ))]
    pub id_poses: usize,
}

// Arguments of `reproduce` (help texts with their ranges in the `help` attributes).
#[derive(clap::Args, Debug)]
pub struct ReproduceArgs {
    #[arg(long, default_value_t = 5.0,
        help = MASS.help("Mass parameter m* of the correction [kg]", ""))]
    pub mass: f64,
    #[arg(long, value_delimiter = ',', default_values_t = vec![1u8, 2, 3, 4, 5],
        help = G_LEVEL.help("Acceleration levels [g], comma-separated", "Each level at most once"))]
    pub g: Vec<u8>,
    #[arg(long, default_value_t = 0, help = FIXED_POINT.help(
        "Fixed-point iterations of the corrector (0 = the paper's one-shot update)",
        ""
    ))]
    pub fixed_point: usize,
    #[arg(long, default_value_t = 2, help = JOBS.help(
        "Worker threads for the runs (results do not depend on it)",
        "0 is refused"
    ))]
    pub jobs: usize,
}

impl Default for ReproduceArgs {
    /// What `deflect-sim` without a subcommand runs: the defaults above.
    fn default() -> Self {
        Self {
            mass: 5.0,
            g: vec![1, 2, 3, 4, 5],
            fixed_point: 0,
            jobs: 2,
        }
    }
}

// Arguments of `run`.
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    /// Mechanism.
    #[arg(long, value_enum, default_value_t = Mech::Oc)]
    pub mechanism: Mech,
    /// Head position.
    #[arg(long, value_enum, default_value_t = HeadArg::Upper)]
    pub head: HeadArg,
    /// Motion.
    #[arg(long, value_enum, default_value_t = MotionArg::Y)]
    pub motion: MotionArg,
    #[arg(long, default_value_t = 5, help = G_LEVEL.help("Acceleration level [g]", ""))]
    pub g: u8,
    /// Correction off, on, or both runs.
    #[arg(long, value_enum, default_value_t = Correction::Both)]
    pub correction: Correction,
    #[arg(long, default_value_t = 5.0, help = MASS.help("Mass parameter m* [kg]", ""))]
    pub mass: f64,
    /// Compliance map JSON (from `fit`; a regular file of at most 16 MiB); default: simulate
    /// the static tests and fit.
    #[arg(long)]
    pub map: Option<PathBuf>,
}

// Mechanism variant.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum Mech {
    // Over-constrained.
    Oc,
    // Normal-constrained.
    Nc,
}

// Head position.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum HeadArg {
    // Centre of mass high above G.
    Upper,
    // Centre of mass low above G.
    Lower,
}

// One of the paper's motions.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum MotionArg {
    // 100 mm along x.
    X,
    // 150 mm along y.
    Y,
    // The triangle (combined motion).
    Triangle,
}

// Which runs of `run`.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq)]
pub enum Correction {
    // Uncorrected only.
    Off,
    // Corrected only.
    On,
    // Both.
    Both,
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
            Self::StaticTest { .. } | Self::Fit { .. } => Ok(()),
            Self::Run(a) => a.check(),
            Self::Milling(a) => a.check(),
            Self::Contour(a) => a.check(),
            Self::Serial(a) => a.check(),
            Self::Atlas(a) => a.check(),
        }
    }
}

impl ReproduceArgs {
    /// See [`Command::check`]; the levels are also distinct.
    pub fn check(&self) -> Result<(), CliError> {
        MASS.check(self.mass)?;
        if self.g.is_empty() {
            return Err(CliError::Usage(
                "--g: no acceleration level given: allowed 1 to 5 levels, each in [1, 5] g".into(),
            ));
        }
        for (k, &g) in self.g.iter().enumerate() {
            G_LEVEL.check_int(g)?;
            if self.g.iter().take(k).any(|&h| h == g) {
                return Err(CliError::Usage(format!(
                    "--g {g} is given twice: allowed each level in {} at most once",
                    G_LEVEL.text()
                )));
            }
        }
        FIXED_POINT.check_int(count(self.fixed_point))?;
        JOBS.check_int(count(self.jobs))
    }
}

impl RunArgs {
    /// See [`Command::check`].
    pub fn check(&self) -> Result<(), CliError> {
        G_LEVEL.check_int(self.g)?;
        MASS.check(self.mass)
    }
}

impl MillingArgs {
    /// See [`Command::check`]; the control cycle is also a whole number of physics steps.
    pub fn check(&self) -> Result<(), CliError> {
        FEED.check(self.feed)?;
        FORCE.check(self.force)?;
        CUT.check(self.cut)?;
        RISE_MS.check(self.rise_ms)?;
        CYCLE_MS.check(self.cycle_ms)?;
        let dt_ms = robot::DT * 1e3;
        let steps = self.cycle_ms / dt_ms;
        if (steps - steps.round()).abs() > 1e-9 {
            return Err(CliError::Usage(format!(
                "--cycle-ms {} is not a multiple of the {dt_ms} ms physics step: allowed {}, \
                 in steps of {dt_ms} ms",
                shown(self.cycle_ms),
                CYCLE_MS.text()
            )));
        }
        LEAD_MS.check(self.lead_ms)?;
        ESTIMATE_ERROR.check(self.estimate_error)?;
        ID_POSES.check_int(count(self.id_poses))
    }
}

impl ContourArgs {
    /// See [`Command::check`].
    pub fn check(&self) -> Result<(), CliError> {
        STEP_MM.check(self.step_mm)?;
        TARGET_FORCE.check(self.target_force)?;
        NOISE.check(self.noise)?;
        JOBS.check_int(count(self.jobs))
    }
}

impl Mech {
    /// The library's mechanism variant.
    pub fn constraint(self) -> Constraint {
        match self {
            Self::Oc => Constraint::Oc,
            Self::Nc => Constraint::Nc,
        }
    }
}

impl HeadArg {
    /// The library's head position.
    pub fn head(self) -> Head {
        match self {
            Self::Upper => Head::Upper,
            Self::Lower => Head::Lower,
        }
    }
}

impl MotionArg {
    /// The library's motion.
    pub fn motion(self) -> Motion {
        match self {
            Self::X => Motion::XLine,
            Self::Y => Motion::YLine,
            Self::Triangle => Motion::Triangle,
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::panic)]
mod tests;
