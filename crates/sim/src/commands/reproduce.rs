//! `reproduce`: the paper's whole pipeline (Paksoy, Dede and Kiper (2025), sec. 4-5): static
//! tests and fits for OC and NC, every motion at every acceleration level for OC/NC x GU/GL
//! with and without the D'Alembert correction on parallel worker threads, the tables of
//! Figs. 10, 12 and 14, the m* tuning of sec. 5.1, CSV/JSON, MCAP and plots.

use std::path::Path;
use std::time::Instant;

use deflect_core::compliance_map::ComplianceMap;
use deflect_sim::scenes::parallel::params::{Constraint, RobotParams};
use deflect_sim::scenes::parallel::run::{self, Motion, RunOptions, RunResult, configurations};
use deflect_sim::scenes::parallel::{output, report};
use deflect_sim::workers::{parallel_map, progress};
use deflect_sim::{SimError, write_file};

use super::Cmd;
use super::calibrate_all;
use crate::cli::{CliError, ReproduceArgs};

/// One run of the sweep.
struct Job {
    params: RobotParams,
    motion: Motion,
    g: u8,
    corrected: bool,
}

/// Runs `jobs` on `threads` worker threads (with a progress bar), the corrected ones with
/// their mechanism's map; results in job order.
fn run_jobs(
    jobs: &[Job],
    maps: &[(Constraint, ComplianceMap)],
    opts: &RunOptions,
    threads: usize,
) -> Result<Vec<RunResult>, SimError> {
    let pb = progress(jobs.len(), "runs");
    let results = parallel_map(jobs, threads, |job| {
        let map = if job.corrected {
            maps.iter()
                .find(|(c, _)| *c == job.params.constraint)
                .map(|(_, m)| m)
        } else {
            None
        };
        let r = run::run(&job.params, job.motion, job.g, map, opts);
        pb.inc(1);
        r
    })?;
    pb.finish_and_clear();
    results.into_iter().collect()
}

/// The `reproduce` command.
fn run(args: &ReproduceArgs, out: &Path) -> Result<(), SimError> {
    let t0 = Instant::now();
    let maps = calibrate_all(&[Constraint::Oc, Constraint::Nc], out)?;
    let t_static = t0.elapsed().as_secs_f64();
    let mut jobs = Vec::new();
    for params in configurations() {
        for motion in [Motion::XLine, Motion::YLine, Motion::Triangle] {
            for &g in &args.g {
                for corrected in [false, true] {
                    jobs.push(Job {
                        params,
                        motion,
                        g,
                        corrected,
                    });
                }
            }
        }
    }
    let opts = RunOptions {
        mass: args.mass,
        fixed_point: args.fixed_point,
        ..Default::default()
    };
    let t1 = Instant::now();
    let runs = run_jobs(&jobs, &maps, &opts, args.jobs)?;
    let wall = t1.elapsed().as_secs_f64();
    let simulated: f64 = runs
        .iter()
        .map(|r| r.samples.last().map_or(0.0, |s| s.t))
        .sum();
    let table = report::tables(&runs);
    say!("{table}");
    let speed = simulated / wall;
    say!(
        "\n{} runs, {:.1} s simulated at 2 kHz in {:.1} s wall on {} thread(s): {:.1}x real time \
         ({:.1}x per thread); static tests and fits {:.1} s",
        runs.len(),
        simulated,
        wall,
        args.jobs.max(1),
        speed,
        speed / args.jobs.max(1) as f64,
        t_static
    );
    write_outputs(&runs, out, &table)?;
    mass_sweep(&maps, out)?;
    say!("outputs in {}", out.display());
    Ok(())
}

/// The paper's preliminary tuning of m* (sec. 5.1), redone in simulation: y-line at 5 g,
/// corrected, for several mass parameters.
fn mass_sweep(maps: &[(Constraint, ComplianceMap)], out: &Path) -> Result<(), SimError> {
    let masses = [3.6, 4.0, 4.5, 5.0, 5.5, 6.0, 7.0];
    let mut text =
        String::from("\nm* tuning (y-line, 5 g, corrected): max path dev / max tracking [mm]\n");
    text.push_str(&format!("{:<8}", "m* [kg]"));
    for m in masses {
        text.push_str(&format!(" {m:>13.1}"));
    }
    text.push('\n');
    let mut csv = String::from("config,mass_kg,max_dev_mm,rms_dev_mm,area_mm2,max_track_mm\n");
    for params in configurations() {
        let Some((_, map)) = maps.iter().find(|(c, _)| *c == params.constraint) else {
            continue;
        };
        text.push_str(&format!("{:<8}", params.label()));
        for mass in masses {
            let opts = RunOptions {
                mass,
                ..Default::default()
            };
            let r = run::run(&params, Motion::YLine, 5, Some(map), &opts)?;
            let m = &r.metrics;
            text.push_str(&format!(" {:>6.4}/{:.4}", m.max_dev_mm, m.max_track_mm));
            csv.push_str(&format!(
                "{},{},{:.6},{:.6},{:.6},{:.6}\n",
                params.label(),
                mass,
                m.max_dev_mm,
                m.rms_dev_mm,
                m.area_mm2,
                m.max_track_mm
            ));
        }
        text.push('\n');
    }
    say!("{text}");
    write_file(&out.join("mass_sweep.csv"), "the m* sweep CSV", csv)?;
    write_file(&out.join("mass_sweep.txt"), "the m* sweep table", text)?;
    Ok(())
}

/// Summary, MCAP log of the top acceleration level and plots.
fn write_outputs(runs: &[RunResult], out: &Path, table: &str) -> Result<(), SimError> {
    output::write_summary(out, "summary", table, &output::summary_csv(runs), runs)?;
    let gmax = runs.iter().map(|r| r.g).max().unwrap_or(5);
    let top: Vec<&RunResult> = runs.iter().filter(|r| r.g == gmax).collect();
    output::write_mcap(&out.join("reproduce.mcap"), "reproduce", &top)?;
    for motion in [Motion::XLine, Motion::YLine, Motion::Triangle] {
        let sel: Vec<&RunResult> = top.iter().copied().filter(|r| r.motion == motion).collect();
        if sel.is_empty() {
            continue;
        }
        output::plot_paths(
            &out.join(format!("paths_{}_{}g.png", motion.label(), gmax)),
            &sel,
        )?;
        output::plot_error_vs_g(
            &out.join(format!("error_vs_g_{}.png", motion.label())),
            motion,
            runs,
        )?;
    }
    Ok(())
}

impl Cmd for ReproduceArgs {
    type Input = ();

    fn load(&self) -> Result<(), CliError> {
        Ok(())
    }

    fn run(&self, (): (), out: &Path) -> Result<(), SimError> {
        run(self, out)
    }
}
