//! Arguments of `deflect-sim milling`.

use deflect_sim::scenes::parallel::params;

use super::range::*;
use super::{CliError, count};

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

impl MillingArgs {
    /// See [`Command::check`]; the control cycle is also a whole number of physics steps.
    pub fn check(&self) -> Result<(), CliError> {
        FEED.check(self.feed)?;
        FORCE.check(self.force)?;
        CUT.check(self.cut)?;
        RISE_MS.check(self.rise_ms)?;
        CYCLE_MS.check(self.cycle_ms)?;
        let dt_ms = params::DT * 1e3;
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
