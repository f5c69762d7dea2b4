//! Arguments of `deflect-sim delta`: the Delta robot's static tests, map and corrected move.

use super::range::*;
use super::{CliError, count};

// Arguments of `delta` (help texts with their ranges in the `help` attributes).
#[derive(clap::Args, Debug)]
pub struct DeltaArgs {
    #[arg(long, default_value_t = 8.0, allow_negative_numbers = true, help = DELTA_G.help(
        "Peak acceleration of the pick-and-place move [g]", "Pick and place: 5-10 g"
    ))]
    pub g: f64,
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true, help = DELTA_PAYLOAD.help(
        "Payload on the platform [kg]", ""
    ))]
    pub payload_mass: f64,
    #[arg(long, default_value_t = 3, allow_negative_numbers = true, help = DELTA_NODES.help(
        "Static-test grid nodes per axis (x, y, z over the move's workspace)",
        "Each node takes 6 static tests"
    ))]
    pub nodes: usize,
    #[arg(long, default_value_t = 50.0, allow_negative_numbers = true, help = DELTA_TEST_FORCE.help(
        "Static-test force along each axis, both signs [N]", ""
    ))]
    pub test_force: f64,
    #[arg(long, default_value_t = 2, help = JOBS.help(
        "Worker threads (results do not depend on it)", "0 is refused"
    ))]
    pub jobs: usize,
}

impl DeltaArgs {
    /// Checks every flag against its range.
    pub fn check(&self) -> Result<(), CliError> {
        DELTA_G.check(self.g)?;
        DELTA_PAYLOAD.check(self.payload_mass)?;
        DELTA_NODES.check_int(count(self.nodes))?;
        DELTA_TEST_FORCE.check(self.test_force)?;
        JOBS.check_int(count(self.jobs))
    }
}
