//! Arguments of the parallel-robot commands, `deflect-sim reproduce` (the default) and
//! `deflect-sim run`, and their value enums.

use std::path::PathBuf;

use clap::ValueEnum;
use deflect_sim::scenes::parallel::params::{Constraint, Head};
use deflect_sim::scenes::parallel::run::Motion;

use super::range::*;
use super::{CliError, count};

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

impl RunArgs {
    /// See [`Command::check`].
    pub fn check(&self) -> Result<(), CliError> {
        G_LEVEL.check_int(self.g)?;
        MASS.check(self.mass)
    }
}

// Mechanism variant.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum Mech {
    // Over-constrained.
    Oc,
    // Normal-constrained.
    Nc,
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

// Head position.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum HeadArg {
    // Centre of mass high above G.
    Upper,
    // Centre of mass low above G.
    Lower,
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

/// `static-test`'s flags.
#[derive(clap::Args, Debug)]
pub struct StaticTestArgs {
    /// Mechanism.
    #[arg(long, value_enum, default_value_t = Mech::Oc)]
    pub mechanism: Mech,
}

/// `fit`'s flags.
#[derive(clap::Args, Debug)]
pub struct FitArgs {
    /// Mechanism (for fresh static tests and the held-out tests).
    #[arg(long, value_enum, default_value_t = Mech::Oc)]
    pub mechanism: Mech,
    /// Static-test CSV written by `static-test` (columns x_mm, y_mm, force_axis, force_N,
    /// dx_mm, dy_mm; the older header x, y, force_axis, force, dx, dy is read in mm and N);
    /// a regular file of at most 16 MiB.
    #[arg(long)]
    pub input: Option<PathBuf>,
}
