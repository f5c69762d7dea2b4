//! `deflect-sim`: the project's main command. With no arguments it runs `reproduce`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use clap::{Parser, Subcommand, ValueEnum};
use deflect_core::compliance_map::{ComplianceMap, ForceUnit, LengthUnit};
use deflect_sim::pipeline::{
    self, Motion, RunOptions, RunResult, StaticOptions, StaticReading, configurations,
};
use deflect_sim::robot::{Constraint, Head, RobotParams};
use deflect_sim::{SimError, output, report};
use indicatif::{ProgressBar, ProgressStyle};

#[derive(Parser, Debug)]
#[command(
    name = "deflect-sim",
    version,
    about = "Simulated reproduction of the D'Alembert trajectory correction (Paksoy et al.) on a \
             rapier3d-f64 model of the 2-DoF parallel robot. Without a subcommand: reproduce."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Output directory.
    #[arg(long, global = true, default_value = "out")]
    out: PathBuf,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// The whole pipeline: static tests, fit, all motions at 1-5 g for OC/NC x GU/GL, with and
    /// without correction; tables, CSV/JSON, MCAP and plots.
    Reproduce(ReproduceArgs),
    /// Simulated static tests (15 nodes x 2 axes x 49..245 N), written as CSV (mm, N).
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
        /// Static-test CSV written by `static-test` (columns x, y [mm], force_axis, force [N],
        /// dx, dy [mm]).
        #[arg(long)]
        input: Option<PathBuf>,
    },
    /// One motion on one configuration, uncorrected and/or corrected; writes an MCAP log.
    Run(RunArgs),
    /// Milling scenario for the online force-based compensation (Hähn & Weigold): a 4-axis
    /// flexible arm mills a groove; uncompensated, Cartesian compensation and pilot control;
    /// stiffness and sensor identification. Writes milling_summary.{txt,csv,json},
    /// milling.mcap and PNG plots.
    Milling(MillingArgs),
    /// Force-feedback contour tracing (ContourTracer, Eq. 21) of a circle, a rectangle and an
    /// L-shape by a 2R arm with compliant, backlashed joints; shape recovered raw and with the
    /// Eq. 10 compensation. Writes contour_summary.{txt,csv,json}, contour.mcap, contour_*.png.
    Contour(ContourArgs),
}

#[derive(clap::Args, Debug)]
struct ContourArgs {
    /// Tracer step along the edge [mm].
    #[arg(long, default_value_t = 1.5)]
    step_mm: f64,
    /// Target contact force [N] (window: 1.5 N .. 30 N).
    #[arg(long, default_value_t = 6.0)]
    target_force: f64,
    /// Force sensor noise, standard deviation per sample and axis [N].
    #[arg(long, default_value_t = 0.3)]
    noise: f64,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// Worker threads (one object each; results do not depend on it).
    #[arg(long, default_value_t = 2)]
    jobs: usize,
}

#[derive(clap::Args, Debug)]
struct MillingArgs {
    /// Feed speed [mm/s] (paper: 25).
    #[arg(long, default_value_t = 25.0)]
    feed: f64,
    /// Magnitude of the process force [N] (direction as the default [-386, 386, -60] N).
    #[arg(long, default_value_t = 550.0)]
    force: f64,
    /// Cutting time [s].
    #[arg(long, default_value_t = 1.2)]
    cut: f64,
    /// Rise and fall time of the force at cutter entry and exit [ms].
    #[arg(long, default_value_t = 100.0)]
    rise_ms: f64,
    /// Control cycle [ms] (paper: 4, KUKA RSI).
    #[arg(long, default_value_t = 4.0)]
    cycle_ms: f64,
    /// Lead of the offline force estimate over the real force [ms].
    #[arg(long, default_value_t = 40.0)]
    lead_ms: f64,
    /// Relative error of the offline force estimate (0.1 = 10 % too large).
    #[arg(long, default_value_t = 0.1)]
    estimate_error: f64,
    /// Seed of the sensor and measurement noise.
    #[arg(long, default_value_t = 6)]
    seed: u64,
}

#[derive(clap::Args, Debug)]
struct ReproduceArgs {
    /// Mass parameter m* of the correction [kg].
    #[arg(long, default_value_t = 5.0)]
    mass: f64,
    /// Acceleration levels [g].
    #[arg(long, value_delimiter = ',', default_values_t = vec![1u8, 2, 3, 4, 5])]
    g: Vec<u8>,
    /// Fixed-point iterations of the corrector (0 = the paper's one-shot update).
    #[arg(long, default_value_t = 0)]
    fixed_point: usize,
    /// Worker threads for the runs (results do not depend on it).
    #[arg(long, default_value_t = 2)]
    jobs: usize,
}

#[derive(clap::Args, Debug)]
struct RunArgs {
    /// Mechanism.
    #[arg(long, value_enum, default_value_t = Mech::Oc)]
    mechanism: Mech,
    /// Head position.
    #[arg(long, value_enum, default_value_t = HeadArg::Upper)]
    head: HeadArg,
    /// Motion.
    #[arg(long, value_enum, default_value_t = MotionArg::Y)]
    motion: MotionArg,
    /// Acceleration level [g], 1..5.
    #[arg(long, default_value_t = 5)]
    g: u8,
    /// Correction off, on, or both runs.
    #[arg(long, value_enum, default_value_t = Correction::Both)]
    correction: Correction,
    /// Mass parameter m* [kg].
    #[arg(long, default_value_t = 5.0)]
    mass: f64,
    /// Compliance map JSON (from `fit`); default: simulate the static tests and fit.
    #[arg(long)]
    map: Option<PathBuf>,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum Mech {
    Oc,
    Nc,
}
#[derive(ValueEnum, Clone, Copy, Debug)]
enum HeadArg {
    Upper,
    Lower,
}
#[derive(ValueEnum, Clone, Copy, Debug)]
enum MotionArg {
    X,
    Y,
    Triangle,
}
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq)]
enum Correction {
    Off,
    On,
    Both,
}

impl Mech {
    fn constraint(self) -> Constraint {
        match self {
            Self::Oc => Constraint::Oc,
            Self::Nc => Constraint::Nc,
        }
    }
}

fn progress(len: usize, msg: &str) -> ProgressBar {
    let hidden = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
        || !std::io::stderr().is_terminal();
    let pb = if hidden {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(len as u64)
    };
    if let Ok(style) =
        ProgressStyle::with_template("{msg:>14} [{bar:40}] {pos}/{len} {elapsed_precise}")
    {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_message(msg.to_string());
    pb
}

fn static_csv(readings: &[StaticReading]) -> String {
    let mut s = String::from("x,y,force_axis,force,dx,dy,dx_linear,dy_linear\n");
    for r in readings {
        s.push_str(&format!(
            "{},{},{},{},{:e},{:e},{:e},{:e}\n",
            r.x * 1e3,
            r.y * 1e3,
            if r.axis == 0 { "x" } else { "y" },
            r.force,
            r.d[0] * 1e3,
            r.d[1] * 1e3,
            r.d_linear[0] * 1e3,
            r.d_linear[1] * 1e3
        ));
    }
    s
}

/// Static tests + fit + held-out for one mechanism; writes its files; returns the map and a
/// printable summary.
fn calibrate(
    constraint: Constraint,
    out: &Path,
    pb: &ProgressBar,
) -> Result<(ComplianceMap, String), SimError> {
    let params = RobotParams::new(constraint, Head::Upper);
    let opts = StaticOptions::default();
    let readings = pipeline::static_tests(&params, &opts, || pb.inc(1))?;
    let tag = constraint.label().to_lowercase();
    std::fs::write(
        out.join(format!("static_tests_{tag}.csv")),
        static_csv(&readings),
    )?;
    let (worst_small, rms_small) = pipeline::linear_agreement(&readings, 50.0);
    let (worst, rms) = pipeline::linear_agreement(&readings, f64::INFINITY);
    let dmax = readings
        .iter()
        .map(|r| (r.d[0].powi(2) + r.d[1].powi(2)).sqrt())
        .fold(0.0, f64::max);
    let mut text = format!(
        "{}: static tests, 15 nodes x 2 axes x 5 forces: up to {:.3} mm at 245 N; vs J K^-1 J^T \
         (relative): at 49 N worst {:.1e} RMS {:.1e}, up to 245 N worst {:.1e} RMS {:.1e}\n",
        constraint.label(),
        dmax * 1e3,
        worst_small,
        rms_small,
        worst,
        rms
    );
    let map = pipeline::fit_map(&readings)?;
    std::fs::write(
        out.join(format!("compliance_map_{tag}.json")),
        map.to_json()?,
    )?;
    let ho = pipeline::held_out(&params, &map, &opts)?;
    pb.inc(1);
    text.push_str(&format!(
        "{}: map held-out error: cell centres (fresh static tests, 245 N) RMS {:.4} mm, max \
         {:.4} mm (RMS displacement there {:.3} mm); leave-one-line-out RMS y {:.4} mm, x {:.4} mm",
        constraint.label(),
        ho.centre_rms * 1e3,
        ho.centre_max * 1e3,
        ho.centre_rms_displacement * 1e3,
        ho.loo_rms_y * 1e3,
        ho.loo_rms_x * 1e3
    ));
    std::fs::write(
        out.join(format!("held_out_{tag}.json")),
        serde_json::to_string_pretty(&ho)?,
    )?;
    Ok((map, text))
}

/// [`calibrate`] for several mechanisms, one thread each; prints the summaries in order.
fn calibrate_all(
    constraints: &[Constraint],
    out: &Path,
) -> Result<Vec<(Constraint, ComplianceMap)>, SimError> {
    let pb = progress(31 * constraints.len(), "static tests");
    let results: Vec<Result<(ComplianceMap, String), SimError>> = std::thread::scope(|s| {
        let handles: Vec<_> = constraints
            .iter()
            .map(|c| {
                let pb = pb.clone();
                s.spawn(move || calibrate(*c, out, &pb))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(SimError::new("calibration thread panicked")))
            })
            .collect()
    });
    pb.finish_and_clear();
    let mut maps = Vec::new();
    for (c, r) in constraints.iter().zip(results) {
        let (map, text) = r?;
        println!("{text}");
        maps.push((*c, map));
    }
    Ok(maps)
}

struct Job {
    params: RobotParams,
    motion: Motion,
    g: u8,
    corrected: bool,
}

fn run_jobs(
    jobs: &[Job],
    maps: &[(Constraint, ComplianceMap)],
    opts: &RunOptions,
    threads: usize,
) -> Result<Vec<RunResult>, SimError> {
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<RunResult, SimError>>>> =
        Mutex::new((0..jobs.len()).map(|_| None).collect());
    let pb = progress(jobs.len(), "runs");
    std::thread::scope(|s| {
        for _ in 0..threads.max(1) {
            s.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::SeqCst);
                    let Some(job) = jobs.get(k) else { break };
                    let map = if job.corrected {
                        maps.iter()
                            .find(|(c, _)| *c == job.params.constraint)
                            .map(|(_, m)| m)
                    } else {
                        None
                    };
                    let r = pipeline::run(&job.params, job.motion, job.g, map, opts);
                    if let Ok(mut v) = results.lock() {
                        if let Some(slot) = v.get_mut(k) {
                            *slot = Some(r);
                        }
                    }
                    pb.inc(1);
                }
            });
        }
    });
    pb.finish_and_clear();
    let v = results
        .into_inner()
        .map_err(|_| SimError::new("worker panicked"))?;
    v.into_iter()
        .map(|r| r.unwrap_or_else(|| Err(SimError::new("run missing"))))
        .collect()
}

fn reproduce(args: &ReproduceArgs, out: &Path) -> Result<(), SimError> {
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
    println!("{table}");
    let speed = simulated / wall;
    println!(
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
    println!("outputs in {}", out.display());
    Ok(())
}

/// The paper's preliminary tuning of m* (section 5.1), redone in simulation: y-line at 5 g,
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
            let r = pipeline::run(&params, Motion::YLine, 5, Some(map), &opts)?;
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
    println!("{text}");
    std::fs::write(out.join("mass_sweep.csv"), csv)?;
    std::fs::write(out.join("mass_sweep.txt"), text)?;
    Ok(())
}

fn write_outputs(runs: &[RunResult], out: &Path, table: &str) -> Result<(), SimError> {
    output::write_summary(out, "summary", table, &output::summary_csv(runs), runs)?;
    let gmax = runs.iter().map(|r| r.g).max().unwrap_or(5);
    let top: Vec<&RunResult> = runs.iter().filter(|r| r.g == gmax).collect();
    output::write_mcap(&out.join("reproduce.mcap"), &top, true)?;
    for motion in [Motion::XLine, Motion::YLine, Motion::Triangle] {
        let sel: Vec<&RunResult> = top.iter().copied().filter(|r| r.motion == motion).collect();
        if sel.is_empty() {
            continue;
        }
        output::plot_paths(
            &out.join(format!("paths_{}_{}g.png", motion.label(), gmax)),
            &format!(
                "{} at {} g: tool path across the line",
                motion.label(),
                gmax
            ),
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

fn run_one(args: &RunArgs, out: &Path) -> Result<(), SimError> {
    let head = match args.head {
        HeadArg::Upper => Head::Upper,
        HeadArg::Lower => Head::Lower,
    };
    let constraint = args.mechanism.constraint();
    let params = RobotParams::new(constraint, head);
    let motion = match args.motion {
        MotionArg::X => Motion::XLine,
        MotionArg::Y => Motion::YLine,
        MotionArg::Triangle => Motion::Triangle,
    };
    let map = if args.correction == Correction::Off {
        None
    } else if let Some(p) = &args.map {
        Some(ComplianceMap::from_json(&std::fs::read_to_string(p)?)?)
    } else {
        calibrate_all(&[constraint], out)?.pop().map(|(_, m)| m)
    };
    let opts = RunOptions {
        mass: args.mass,
        ..Default::default()
    };
    let mut runs = Vec::new();
    for corrected in [false, true] {
        let wanted = match args.correction {
            Correction::Off => !corrected,
            Correction::On => corrected,
            Correction::Both => true,
        };
        if wanted {
            let t = Instant::now();
            let r = pipeline::run(
                &params,
                motion,
                args.g,
                map.as_ref().filter(|_| corrected),
                &opts,
            )?;
            let sim = r.samples.last().map_or(0.0, |s| s.t);
            println!(
                "{} {} {} g {}: max path dev {:.4} mm, RMS {:.4} mm, area {:.4} mm2, length dev \
                 {:.4} mm, max tracking {:.4} mm ({:.1}x real time)",
                r.config,
                motion.label(),
                r.g,
                if corrected {
                    "corrected"
                } else {
                    "uncorrected"
                },
                r.metrics.max_dev_mm,
                r.metrics.rms_dev_mm,
                r.metrics.area_mm2,
                r.metrics.length_dev_mm,
                r.metrics.max_track_mm,
                sim / t.elapsed().as_secs_f64()
            );
            runs.push(r);
        }
    }
    let refs: Vec<&RunResult> = runs.iter().collect();
    let name = format!(
        "run_{}_{}_{}_{}g",
        constraint.label().to_lowercase(),
        head.label().to_lowercase(),
        motion.label(),
        args.g
    );
    let mcap_path = out.join(format!("{name}.mcap"));
    let n = output::write_mcap(&mcap_path, &refs, runs.len() > 1)?;
    output::plot_paths(&out.join(format!("{name}.png")), &name, &refs)?;
    std::fs::write(
        out.join(format!("{name}.json")),
        serde_json::to_string_pretty(&runs)?,
    )?;
    println!("{} messages in {}", n, mcap_path.display());
    Ok(())
}

fn fit_cmd(mech: Mech, input: Option<&Path>, out: &Path) -> Result<(), SimError> {
    let constraint = mech.constraint();
    let map = match input {
        None => calibrate_all(&[constraint], out)?
            .pop()
            .map(|(_, m)| m)
            .ok_or_else(|| SimError::new("no map"))?,
        Some(p) => {
            let text = std::fs::read_to_string(p)?;
            let map = ComplianceMap::fit_static_csv(
                &text,
                ForceUnit::Newton,
                LengthUnit::Millimetre,
                Some(2),
                1e-6,
            )?
            .with_options(pipeline::map_options());
            let tag = constraint.label().to_lowercase();
            std::fs::write(
                out.join(format!("compliance_map_{tag}.json")),
                map.to_json()?,
            )?;
            let ho = pipeline::held_out(
                &RobotParams::new(constraint, Head::Upper),
                &map,
                &StaticOptions::default(),
            )?;
            println!(
                "{}: held-out RMS {:.4} mm (cell centres), leave-one-line-out RMS y {:.4} mm",
                constraint.label(),
                ho.centre_rms * 1e3,
                ho.loo_rms_y * 1e3
            );
            map
        }
    };
    println!(
        "map: {} x {} nodes, written to {}",
        map.x().len(),
        map.y().len(),
        out.display()
    );
    Ok(())
}

fn milling_cmd(a: &MillingArgs, out: &Path) -> Result<(), SimError> {
    use deflect_sim::{milling, milling_output};
    let mut opts = milling::MillingOptions::default();
    let dir = nalgebra::Vector3::from(opts.force).normalize();
    opts.force = (dir * a.force).into();
    opts.feed = a.feed * 1e-3;
    opts.cut = a.cut;
    opts.cycle = a.cycle_ms * 1e-3;
    opts.force_rise = a.rise_ms * 1e-3;
    opts.estimate_lead = a.lead_ms * 1e-3;
    opts.estimate_error = a.estimate_error;
    opts.seed = a.seed;
    let ok = |v: f64, lo: f64| v.is_finite() && v >= lo;
    let valid = ok(opts.feed, 1e-6)
        && ok(a.force, 0.0)
        && ok(opts.cut, 0.01)
        && ok(opts.cycle, 5e-4)
        && ok(opts.estimate_lead, 0.0)
        && ok(opts.force_rise, 1e-4)
        && opts.estimate_error.is_finite();
    if !valid {
        return Err(SimError::new(
            "milling: feed > 0, force >= 0, cut >= 0.01 s, cycle >= 0.5 ms, lead >= 0, rise >= 0.1 ms",
        ));
    }
    let r = milling::milling(&opts)?;
    let table = milling_output::table(&r);
    print!("{table}");
    milling_output::write_all(out, &r)?;
    println!(
        "wrote {}/milling_summary.{{txt,csv,json}}, milling.mcap, milling_error.png, milling_stiffness.png",
        out.display()
    );
    Ok(())
}

fn contour_cmd(a: &ContourArgs, out: &Path) -> Result<(), SimError> {
    use deflect_sim::{contour_output, contour_scene};
    let mut opts = contour_scene::TraceOptions {
        step: a.step_mm * 1e-3,
        target_force: a.target_force,
        noise: a.noise,
        seed: a.seed,
        ..Default::default()
    };
    opts.approach_step = opts.approach_step.min(opts.step);
    let ok = |v: f64| v.is_finite() && v > 0.0;
    let valid = ok(opts.step)
        && opts.step <= 0.02
        && opts.target_force > opts.contact_force
        && opts.target_force < opts.jam_force
        && opts.noise.is_finite()
        && opts.noise >= 0.0;
    if !valid {
        return Err(SimError::new(
            "contour: 0 < step <= 20 mm, 1.5 N < target force < 30 N, noise >= 0",
        ));
    }
    let t = Instant::now();
    let runs = contour_scene::trace_all(&contour_scene::default_objects(), &opts, a.jobs)?;
    let wall = t.elapsed().as_secs_f64();
    let table = contour_output::table(&runs);
    print!("{table}");
    let sim: f64 = runs.iter().map(|r| r.sim_time).sum();
    let steps: usize = runs.iter().map(|r| r.physics_steps).sum();
    println!(
        "{} shapes, {:.1} s simulated ({} physics steps at {:.1} kHz) in {:.2} s wall on {} \
         thread(s): {:.1}x real time",
        runs.len(),
        sim,
        steps,
        1e-3 / contour_scene::DT,
        wall,
        a.jobs.max(1),
        sim / wall
    );
    let n = contour_output::write_all(out, &runs, &table)?;
    println!(
        "wrote {0}/contour_summary.{{txt,csv,json}}, {0}/contour.mcap ({n} messages), {0}/contour_<shape>.png",
        out.display()
    );
    Ok(())
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = std::fs::create_dir_all(&cli.out)
        .map_err(SimError::from)
        .and_then(|()| match &cli.command {
            None => reproduce(
                &ReproduceArgs {
                    mass: 5.0,
                    g: vec![1, 2, 3, 4, 5],
                    fixed_point: 0,
                    jobs: 2,
                },
                &cli.out,
            ),
            Some(Command::Reproduce(a)) => reproduce(a, &cli.out),
            Some(Command::StaticTest { mechanism }) => {
                let params = RobotParams::new(mechanism.constraint(), Head::Upper);
                let pb = progress(30, "static");
                let r = pipeline::static_tests(&params, &StaticOptions::default(), || pb.inc(1))?;
                pb.finish_and_clear();
                let (worst, rms) = pipeline::linear_agreement(&r, 50.0);
                let path = cli.out.join(format!(
                    "static_tests_{}.csv",
                    mechanism.constraint().label().to_lowercase()
                ));
                std::fs::write(&path, static_csv(&r))?;
                println!(
                    "{} readings -> {}; vs J K^-1 J^T at 49 N: worst {:.2e}, RMS {:.2e} (relative)",
                    r.len(),
                    path.display(),
                    worst,
                    rms
                );
                Ok(())
            }
            Some(Command::Fit { mechanism, input }) => {
                fit_cmd(*mechanism, input.as_deref(), &cli.out)
            }
            Some(Command::Run(a)) => run_one(a, &cli.out),
            Some(Command::Milling(a)) => milling_cmd(a, &cli.out),
            Some(Command::Contour(a)) => contour_cmd(a, &cli.out),
        });
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
