//! `place`: where to put the workpiece (deflect-core's `machining::placement`). Loads the job
//! as `job` does, computes the program's nominal loads once, searches the box on every
//! thread, prints and writes the best placement (`place_summary.{txt,json}`) and the heat map
//! of the grid (`place.png`: per x-y cell the best over z and yaw).

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use deflect_core::machining::placement::{self, PlacementBox, Problem, Search};
use deflect_core::machining::spin::SpinOptions;
use deflect_sim::SimError;
use deflect_sim::scenes::serial::atlas::{HeatMap, heat_map};

use super::Cmd;
use super::job::{self, JobTask};
use super::stdout;
use crate::cli::{CliError, PlaceArgs, SpinArg};

/// The search's inputs, read and checked.
pub struct PlaceTask {
    task: JobTask,
    problem: Problem,
    bx: PlacementBox,
    load_s: f64,
}

/// Reads the job (as `job` does) and builds the problem (the nominal pass, once).
pub fn load(a: &PlaceArgs) -> Result<PlaceTask, CliError> {
    let started = Instant::now();
    let (optimise, options) = match a.job.spin {
        SpinArg::Keep => (false, SpinOptions::default()),
        SpinArg::Optimize => (
            true,
            SpinOptions {
                step: a.job.spin_step.to_radians(),
                per_metre: a.job.spin_rate[0].to_radians() * 1e3,
                per_second: a.job.spin_rate[1].to_radians(),
                measure: a.job.spin_measure.measure(),
                ..SpinOptions::default()
            },
        ),
        SpinArg::Degrees(_) => {
            return Err(CliError::Usage(
                "--spin: place searches with keep or optimize, not a constant spin".into(),
            ));
        }
    };
    // The job itself with the setup's spin: the search turns it per placement.
    let mut args = a.job.clone();
    args.spin = SpinArg::Keep;
    let task = job::load(&args)?;
    let p = task.job.setup().placement.translation.vector;
    let b = a.bounds.clone().unwrap_or_else(|| {
        vec![
            p.x - 0.2,
            p.x + 0.2,
            p.y - 0.2,
            p.y + 0.2,
            p.z - 0.1,
            p.z + 0.1,
        ]
    });
    let bx = PlacementBox {
        min: [b[0], b[2], b[4], a.yaw[0].to_radians()],
        max: [b[1], b[3], b[5], a.yaw[1].to_radians()],
        steps: [a.steps[0], a.steps[1], a.steps[2], a.steps[3]],
    };
    bx.validate()
        .map_err(|e| CliError::Usage(format!("--box/--yaw/--steps: {e}")))?;
    let problem = Problem::new(
        task.job.clone(),
        &task.program,
        &task.seed,
        options,
        optimise,
    )
    .map_err(|e| CliError::Failure(format!("{}: {e}", task.program_name)))?;
    Ok(PlaceTask {
        task,
        problem,
        bx,
        load_s: started.elapsed().as_secs_f64(),
    })
}

/// Runs the search, prints the best placement, writes the heat map and the summary.
fn run(a: &PlaceArgs, t: &PlaceTask, out: &Path) -> Result<(), SimError> {
    let started = Instant::now();
    let threads = a.job.threads;
    let found = placement::search(&t.bx, a.refine, |ps: &[[f64; 4]]| -> Result<_, SimError> {
        Ok(t.problem.evaluate_all(ps, threads))
    })?
    .map_err(|e| SimError::new(format!("{}: {e}", t.task.program_name)))?;
    let wall = started.elapsed().as_secs_f64();
    let (best, score) = found.best;
    let job_p = t.task.job.setup().placement.translation.vector;
    let at_job = t.problem.evaluate(&[job_p.x, job_p.y, job_p.z, 0.0]);
    let feasible = found.grid.iter().filter(|(_, s)| s.feasible()).count();
    let (optimise, spin) = (t.problem.spin().1, t.problem.spin().0);
    let mut text = String::new();
    let _ = writeln!(
        text,
        "place: {} on {}: {} placements ({} of the grid's {} reach the program) in {wall:.2} s on \
         {threads} thread{} ({:.0} placements/s; the program's loads once, {:.2} s); spin {}",
        t.task.program_name,
        t.task.robot_name,
        found.evaluations,
        feasible,
        found.grid.len(),
        if threads == 1 { "" } else { "s" },
        found.evaluations as f64 / wall.max(1e-9),
        t.load_s,
        if optimise {
            "optimised along the program"
        } else {
            "the setup's"
        }
    );
    let _ = writeln!(
        text,
        "best placement: x {:.4} m, y {:.4} m, z {:.4} m, yaw {:.2} degrees: predicted deflection \
         ({}) RMS {:.4} mm, max {:.4} mm",
        best[0],
        best[1],
        best[2],
        best[3].to_degrees(),
        spin.measure.name(),
        score.rms * 1e3,
        score.max * 1e3
    );
    let _ = writeln!(
        text,
        "the job's own placement (x {:.4}, y {:.4}, z {:.4} m): RMS {:.4} mm, max {:.4} mm",
        job_p.x,
        job_p.y,
        job_p.z,
        at_job.rms * 1e3,
        at_job.max * 1e3
    );
    plot_grid(t, &found, out)?;
    let json = serde_json::json!({
        "program": t.task.program_name,
        "robot": t.task.robot_name,
        "spin_optimised": optimise,
        "measure": spin.measure.name(),
        "box_min": t.bx.min, "box_max": t.bx.max, "steps": t.bx.steps,
        "refine": a.refine,
        "evaluations": found.evaluations,
        "wall_time_s": wall,
        "threads": threads,
        "best": {"x_m": best[0], "y_m": best[1], "z_m": best[2], "yaw_rad": best[3],
                 "rms_m": score.rms, "max_m": score.max},
        "job_placement": {"rms_m": at_job.rms, "max_m": at_job.max},
        "grid": found.grid.iter().map(|(p, s)| serde_json::json!({
            "x_m": p[0], "y_m": p[1], "z_m": p[2], "yaw_rad": p[3],
            "rms_m": if s.feasible() { Some(s.rms) } else { None },
            "max_m": if s.feasible() { Some(s.max) } else { None },
            "line": s.line,
        })).collect::<Vec<_>>(),
    });
    let write = |name: &str, body: &str| {
        deflect_core::io::job_out::write(out.join(name), body)
            .map_err(|e| SimError::new(e.to_string()))
    };
    write("place_summary.txt", &text)?;
    write(
        "place_summary.json",
        &serde_json::to_string_pretty(&json).map_err(|e| SimError::new(e.to_string()))?,
    )?;
    stdout(format_args!(
        "{text}outputs in {}: place.png, place_summary.{{txt,json}}\n",
        out.display()
    ))
}

/// Plots the grid's heat map to `place.png`: per x-y cell the best RMS deflection \[mm\] over
/// z and yaw.
fn plot_grid(t: &PlaceTask, found: &Search, out: &Path) -> Result<(), SimError> {
    let [nx, ny, _, _] = t.bx.steps;
    let grid = t.bx.grid();
    let (xs, ys): (Vec<f64>, Vec<f64>) = (
        grid.iter().take(nx).map(|p| p[0]).collect(),
        grid.iter().step_by(nx).take(ny).map(|p| p[1]).collect(),
    );
    // Per x-y cell the best over z and yaw, x-major for the plot.
    let mut mm = vec![f64::INFINITY; nx * ny];
    for (k, (_, s)) in found.grid.iter().enumerate() {
        let (ix, iy) = (k % nx, (k / nx) % ny);
        if let Some(v) = mm.get_mut(ix * ny + iy) {
            *v = v.min(s.rms * 1e3);
        }
    }
    let png = out.join("place.png");
    heat_map(
        &png,
        &HeatMap {
            title: &format!(
                "{} on {}: predicted deflection RMS over the program, best over z and yaw",
                Path::new(&t.task.program_name).file_name().map_or_else(
                    || t.task.program_name.clone(),
                    |n| n.to_string_lossy().into_owned()
                ),
                t.task.robot_name
            ),
            xs: &xs,
            ys: &ys,
            mm: &mm,
            bar: "RMS deflection [mm]",
            axes: (
                "workpiece origin x [m], base frame",
                "workpiece origin y [m], base frame",
            ),
        },
    )?;
    Ok(())
}

impl Cmd for PlaceArgs {
    type Input = PlaceTask;

    fn load(&self) -> Result<PlaceTask, CliError> {
        load(self)
    }

    fn run(&self, input: PlaceTask, out: &Path) -> Result<(), SimError> {
        run(self, &input, out)
    }
}
