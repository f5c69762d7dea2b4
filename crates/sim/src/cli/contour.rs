//! Arguments of `deflect-sim contour`.

use super::range::*;
use super::{CliError, count};

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
    #[arg(long, default_value_t = 7, allow_negative_numbers = true)]
    pub seed: u64,
    #[arg(long, default_value_t = 2, help = JOBS.help(
        "Worker threads (one object each; results do not depend on it)",
        "0 is refused"
    ))]
    pub jobs: usize,
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
