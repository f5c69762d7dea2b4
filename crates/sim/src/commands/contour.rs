//! `contour`: force-feedback contour tracing and shape recovery ("Shape recovery from robot
//! contour tracking with force feedback", Eq. 10 and 21) of the default objects of
//! [`deflect_sim::scenes::contour`], one worker thread per object; prints the summary table and
//! writes its files.

use std::path::Path;
use std::time::Instant;

use deflect_sim::SimError;
use deflect_sim::scenes::contour::{self, output};

use super::Cmd;
use crate::cli::{CliError, ContourArgs};

/// The `contour` command (arguments checked by [`ContourArgs::check`]).
fn run(a: &ContourArgs, out: &Path) -> Result<(), SimError> {
    let mut opts = contour::TraceOptions {
        step: a.step_mm * 1e-3,
        target_force: a.target_force,
        noise: a.noise,
        seed: a.seed,
        ..Default::default()
    };
    opts.approach_step = opts.approach_step.min(opts.step);
    let t = Instant::now();
    let runs = contour::trace_all(&contour::default_objects(), &opts, a.jobs)?;
    let wall = t.elapsed().as_secs_f64();
    let table = output::table(&runs);
    put!("{table}");
    let sim: f64 = runs.iter().map(|r| r.sim_time).sum();
    let steps: usize = runs.iter().map(|r| r.physics_steps).sum();
    say!(
        "{} shapes, {:.1} s simulated ({} physics steps at {:.1} kHz) in {:.2} s wall on {} \
         thread(s): {:.1}x real time",
        runs.len(),
        sim,
        steps,
        1e-3 / contour::DT,
        wall,
        a.jobs.max(1),
        sim / wall
    );
    let n = output::write_all(out, &runs, &table, &opts)?;
    say!(
        "wrote {0}/contour_summary.{{txt,csv,json}}, {0}/contour.mcap ({n} messages), {0}/contour_<shape>.png",
        out.display()
    );
    Ok(())
}

impl Cmd for ContourArgs {
    type Input = ();

    fn load(&self) -> Result<(), CliError> {
        Ok(())
    }

    fn run(&self, (): (), out: &Path) -> Result<(), SimError> {
        run(self, out)
    }
}
