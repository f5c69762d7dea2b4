//! `static-test`: the paper's simulated static tests (Paksoy, Dede and Kiper (2025), sec.
//! 3.1: 15 nodes x 2 axes x 5 forces) on one mechanism, written as CSV, with their agreement
//! with the linearized `J K^-1 J^T`.

use std::path::Path;

use deflect_sim::scenes::parallel::params::{Head, RobotParams};
use deflect_sim::scenes::parallel::run::{self, StaticOptions};
use deflect_sim::workers::progress;
use deflect_sim::{SimError, write_file};

use super::Cmd;
use crate::cli::{CliError, StaticTestArgs};
use deflect_sim::scenes::parallel::calibrate::static_csv;

/// The `static-test` command.
fn run(a: &StaticTestArgs, out: &Path) -> Result<(), SimError> {
    let mechanism = a.mechanism;
    let params = RobotParams::new(mechanism.constraint(), Head::Upper);
    let pb = progress(30, "static");
    let r = run::static_tests(&params, &StaticOptions::default(), || pb.inc(1))?;
    pb.finish_and_clear();
    let (worst, rms) = run::linear_agreement(&r, 50.0);
    let path = out.join(format!(
        "static_tests_{}.csv",
        mechanism.constraint().label().to_lowercase()
    ));
    write_file(&path, "the static-test CSV", static_csv(&r))?;
    say!(
        "{} readings -> {}; vs J K^-1 J^T at 49 N: worst {:.2e}, RMS {:.2e} (relative)",
        r.len(),
        path.display(),
        worst,
        rms
    );
    Ok(())
}

impl Cmd for StaticTestArgs {
    type Input = ();

    fn load(&self) -> Result<(), CliError> {
        Ok(())
    }

    fn run(&self, (): (), out: &Path) -> Result<(), SimError> {
        run(self, out)
    }
}
