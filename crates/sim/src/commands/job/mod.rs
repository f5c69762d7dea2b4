//! `job`: a machining job offline (deflect-core's `machining::job`) on the built-in KR 300 or
//! the user's arm. [`load`] reads and checks the program, the arm, the placement and the
//! stock before any work; [`Cmd::run`] runs the pass, prints the summary and writes the
//! compensated program, the samples, the part's heat map and the summary files.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use deflect_core::io::apt::AptCutter;
use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::io::tool_table::{self, TblOptions};
use deflect_core::io::{job_out, points_csv};
use deflect_core::machining::Program;
use deflect_core::machining::cutting::Tool;
use deflect_core::machining::job::{self, Job, Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::machining::spin::{self, LoadPath, SpinOptions, SpinPlan, SpinSchedule};
use deflect_core::machining::tools::ToolTable;
use deflect_core::mechanism::PoseIkOptions;
use deflect_core::units::LengthUnit;
use deflect_sim::SimError;
use deflect_sim::scenes::milling::part_map;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};

use super::inputs::{
    apt_tools, load_robot, program_and_cutters, read_program, read_text, tool_and_material,
};
mod files;
mod five_axis;
mod stream;
mod summary;
mod task;

use super::{Cmd, stdout};
use crate::cli::{CliError, JobArgs, SpinArg};
use files::{FileOptions, JobFiles};
use stream::stream_pass;
use summary::summary;
pub use task::JobTask;
use task::five_axis_options;

/// The built-in program: a groove, a ramp and a circular pocket (mm).
const DEFAULT_PROGRAM: &str = include_str!("../../../../../data/groove_and_pocket.nc");
/// The KR 300's defaults: the tool down over a table in front of it.
const KR300_PLACEMENT: [f64; 6] = [2.45, 0.02, 0.92, 0.0, 0.0, std::f64::consts::PI];
const KR300_SEED: [f64; 6] = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0];
/// The KR 300's default for five-axis programs: the table lower and closer, so that the
/// wrist stays bent (A5 about -40 to -70 degrees) as the tool tilts; over the 2.5-D default
/// A5 is near 0, the wrist's singularity, where a tilt of a few degrees turns A4 and A6 by
/// half a turn.
pub(crate) const KR300_FIVE_AXIS_PLACEMENT: [f64; 6] =
    [2.0, 0.0, 0.4, 0.0, 0.0, std::f64::consts::PI];
/// Where the tool is before the program's first move, workpiece frame \[m\].
const START: [f64; 3] = [0.0, 0.0, 0.02];

/// `job --explain FILE`: the program's word report and whether it reads, on stdout.
pub fn explain(a: &JobArgs, path: &Path) -> Result<(), CliError> {
    let text = read_program("--explain", path)?;
    let options = GcodeOptions {
        dialect: a.dialect.dialect(),
        ..GcodeOptions::default()
    };
    let words = gcode::words(&text, &options)
        .map_err(|e| CliError::Failure(format!("--explain {}: {e}", path.display())))?;
    let mut out = format!(
        "{}: the words of the program ({} dialect)\n{:<22} {:<9} {:>7} {:>6}  meaning\n",
        path.display(),
        options.dialect.name(),
        "word",
        "status",
        "count",
        "line"
    );
    for w in &words {
        let _ = writeln!(
            out,
            "{:<22} {:<9} {:>7} {:>6}  {}",
            w.word,
            w.status.name(),
            w.count,
            w.first_line,
            w.meaning
        );
    }
    match gcode::from_str(&text, &options) {
        Ok(p) => {
            let tools: Vec<String> = p.tools().iter().map(|t| format!("T{t}")).collect();
            let _ = writeln!(
                out,
                "reads: {} moves, {:.3} m of feed moves, tools {}",
                p.moves.len(),
                p.cutting_length(),
                if tools.is_empty() {
                    "none".to_string()
                } else {
                    tools.join(", ")
                }
            );
        }
        Err(e) => {
            let _ = writeln!(out, "refused: {e}");
        }
    }
    stdout(format_args!("{out}")).map_err(CliError::from)
}

/// Reads the program and the arm, checks the seed and the placement, builds the job.
pub fn load(a: &JobArgs) -> Result<JobTask, CliError> {
    let options = GcodeOptions {
        start: Vector3::from(START),
        units: LengthUnit::Millimetre,
        dialect: a.dialect.dialect(),
        ..GcodeOptions::default()
    };
    let (program, program_name, cutters) = job_program(a, &options)?;
    let loaded = load_robot(
        a.urdf.as_deref(),
        a.stiffness.as_deref(),
        a.base.as_deref(),
        a.tip.as_deref(),
    )?;
    let robot = loaded.robot;
    let dof = robot.model.dof();
    let seed = match (&a.seed, loaded.builtin) {
        (Some(q), _) => q.clone(),
        (None, _) => KR300_SEED.to_vec(),
    };
    if seed.len() != dof {
        return Err(CliError::Usage(format!(
            "--seed: {} values; expected {dof}, one per joint of {}",
            seed.len(),
            loaded.name
        )));
    }
    let placement = placement(a, &program)?;
    let (min, max) = stock_corners(a, &program, &program_name)?;
    let (tool, coefficients) = tool_and_material(&a.tool)?;
    let table = tool_table(a, &program, &program_name, &cutters)?;
    // A cutter before any LOADTL is the tool the program starts with (T0): the setup's.
    let first = cutters.iter().rev().find(|c| c.tool == 0);
    let tool = match first {
        Some(c) => Tool::new(c.diameter, tool.flutes, tool.helix).map_err(|e| {
            CliError::Failure(format!("{program_name} line {}: CUTTER: {e}", c.line))
        })?,
        None => tool,
    };
    let shape = first.map_or(a.shape.0, |c| c.shape);
    let cell_mm = cell_mm(a, table.as_ref(), &program);
    let setup = Setup {
        placement,
        tool_orientation: Setup::tool_down(),
        tool,
        coefficients,
        stock: Stock {
            min,
            max,
            top: a.top * 1e-3,
            cell: cell_mm * 1e-3,
        },
        path: PathOptions {
            rate_hz: a.rate,
            acceleration: a.acceleration,
            jerk: a.jerk,
            rapid_speed: a.rapid_speed,
            ..PathOptions::default()
        },
        ik: PoseIkOptions::default(),
        hand_spindle: a.spindle_rpm.map(|rpm| rpm / 60.0),
        rapid_skim: a.rapid_skim * 1e-3,
    };
    let mut job = Job::new(robot.model.clone(), &robot.joint_limits, setup)
        .map_err(|e| CliError::Usage(format!("--stock/--cell and the job's settings: {e}")))?;
    if let Some(t) = table {
        job = job.with_tools(t);
    }
    if let Some(c) = robot.controller {
        job = job.with_controller(c);
    }
    check_robot_program(a, &job, &loaded.name)?;
    let five = program.is_multi_axis().then(|| five_axis_options(a, shape));
    let (job, spin) = spin(a, job, &program, &program_name, &seed, five.as_ref())?;
    Ok(JobTask {
        job,
        program,
        program_name,
        robot_name: loaded.name,
        seed,
        spin,
        shape,
    })
}

/// The program (`--program`, `--points` or the built-in one), its name and its APT cutters.
fn job_program(
    a: &JobArgs,
    options: &GcodeOptions,
) -> Result<(Program, String, Vec<AptCutter>), CliError> {
    let mut cutters = Vec::new();
    let (program, program_name) = match (&a.program, &a.points) {
        (Some(p), _) => {
            let (program, c) = program_and_cutters("--program", p, options)?;
            cutters = c;
            (program, p.display().to_string())
        }
        (None, Some(p)) => {
            let text = read_text("--points", p, "tool points CSV")?;
            let program = points_csv::from_str(&text, options)
                .map_err(|e| CliError::Failure(format!("--points {}: {e}", p.display())))?;
            (program, p.display().to_string())
        }
        (None, None) => (
            gcode::from_str(DEFAULT_PROGRAM, options)
                .map_err(|e| CliError::Failure(format!("built-in program: {e}")))?,
            "data/groove_and_pocket.nc (built in)".to_string(),
        ),
    };
    Ok((program, program_name, cutters))
}

/// The workpiece frame in the base frame (`--placement` x y z \[m\], roll pitch yaw \[rad\],
/// else the KR 300's default for the program).
fn placement(a: &JobArgs, program: &Program) -> Result<Isometry3<f64>, CliError> {
    let p = a.placement.clone().unwrap_or(if program.is_multi_axis() {
        KR300_FIVE_AXIS_PLACEMENT.to_vec()
    } else {
        KR300_PLACEMENT.to_vec()
    });
    let [x, y, z, roll, pitch, yaw] = p.as_slice() else {
        return Err(CliError::Usage(format!(
            "--placement: {} values; expected 6",
            p.len()
        )));
    };
    Ok(Isometry3::from_parts(
        Translation3::new(*x, *y, *z),
        UnitQuaternion::from_euler_angles(*roll, *pitch, *yaw),
    ))
}

/// The stock's corners (x, y) \[m\]: `--stock` \[mm\], else around the program's feed moves.
fn stock_corners(
    a: &JobArgs,
    program: &Program,
    program_name: &str,
) -> Result<(Vector2<f64>, Vector2<f64>), CliError> {
    let radius = 0.5e-3 * a.tool.diameter;
    Ok(match &a.stock {
        Some(s) => match s.as_slice() {
            [x0, y0, x1, y1] => (Vector2::new(*x0, *y0) * 1e-3, Vector2::new(*x1, *y1) * 1e-3),
            _ => return Err(CliError::Usage("--stock: expected 4 values".into())),
        },
        None => Stock::around(program, radius).ok_or_else(|| {
            CliError::Failure(format!(
                "{program_name}: no feed move (G1-G3) to size the stock from; give --stock"
            ))
        })?,
    })
}

/// The tool table: `--tools` (checked to have every tool the program cuts with), else the
/// program's APT cutters (none when it names none).
fn tool_table(
    a: &JobArgs,
    program: &Program,
    program_name: &str,
    cutters: &[AptCutter],
) -> Result<Option<ToolTable>, CliError> {
    Ok(match &a.tools {
        Some(path) => {
            let o = TblOptions {
                units: LengthUnit::Millimetre,
                flutes: a.tool.flutes,
                helix: a.tool.helix.to_radians(),
            };
            let text = read_text("--tools", path, "tool table")?;
            let toml = path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
            let table = if toml {
                tool_table::toml_from_str(&text)
            } else {
                tool_table::tbl_from_str(&text, &o)
            }
            .map_err(|e| CliError::Failure(format!("--tools {}: {e}", path.display())))?;
            if let Some(m) = program
                .moves
                .iter()
                .find(|m| m.is_feed() && table.get(m.tool).is_none())
            {
                return Err(CliError::Failure(format!(
                    "--tools {}: {program_name} line {} cuts with T{}, which the table does not \
                     have{}",
                    path.display(),
                    m.line,
                    m.tool,
                    if m.tool == 0 {
                        " (T0: no tool selected; number the tool, or leave out --tools)"
                    } else {
                        ""
                    }
                )));
            }
            Some(table)
        }
        None => apt_tools(
            (
                a.tool.flutes,
                a.tool.helix.to_radians(),
                a.flute_length * 1e-3,
            ),
            cutters,
            program_name,
        )?,
    })
}

/// The z-map's cell \[mm\]: `--cell`, else resolving the smallest cutting tool.
fn cell_mm(a: &JobArgs, table: Option<&ToolTable>, program: &Program) -> f64 {
    // The z-map resolves the smallest cutting tool: a twelfth of its diameter, within
    // [0.1, 0.5] mm (finer cells for small tools keep the force's sensitivity to the tool's
    // position what the cutter, not the grid, makes it).
    let smallest = match table {
        Some(t) => t
            .tools()
            .iter()
            .filter(|spec| {
                program
                    .moves
                    .iter()
                    .any(|m| m.is_feed() && m.tool == spec.number)
            })
            .map(|spec| spec.tool.diameter * 1e3)
            .fold(f64::INFINITY, f64::min),
        None => a.tool.diameter,
    };
    a.cell.unwrap_or_else(|| {
        if smallest.is_finite() {
            // At least 0.1 mm, but never past half the smallest radius (a tool below 0.4 mm),
            // which the job refuses.
            (smallest / 12.0).clamp((smallest / 4.0).min(0.1), 0.5)
        } else {
            0.5
        }
    })
}

/// Refuses a robot program (`--robot-program`) its controller does not run, before any work.
fn check_robot_program(a: &JobArgs, job: &Job, robot_name: &str) -> Result<(), CliError> {
    if let Some(vendor) = a.robot_program.and_then(|k| k.language().vendor()) {
        let language = a
            .robot_program
            .map(|k| k.language().name())
            .unwrap_or_default();
        match job.controller() {
            None => {
                return Err(CliError::Usage(format!(
                    "--robot-program {language}: {} has no controller convention ([controller] \
                     with vendor = \"{}\" in its stiffness file)",
                    robot_name,
                    vendor.name()
                )));
            }
            Some(c) if c.vendor != vendor => {
                return Err(CliError::Usage(format!(
                    "--robot-program {language}: {}'s controller convention is {}'s ({})",
                    robot_name,
                    c.vendor.name(),
                    c.vendor.language()
                )));
            }
            Some(_) => {}
        }
    }
    Ok(())
}

/// The job with `--spin`: a constant spin, or the schedule the search finds (and what it
/// found, with its wall time).
fn spin(
    a: &JobArgs,
    job: Job,
    program: &Program,
    name: &str,
    seed: &[f64],
    five: Option<&deflect_core::machining::five_axis::Options>,
) -> Result<(Job, Option<(SpinPlan, f64)>), CliError> {
    match a.spin {
        SpinArg::Keep => Ok((job, None)),
        SpinArg::Degrees(d) => {
            let s = SpinSchedule::constant(d.to_radians())
                .map_err(|e| CliError::Usage(format!("--spin: {e}")))?;
            Ok((job.with_spin(s), None))
        }
        SpinArg::Optimize => {
            let started = Instant::now();
            let options = SpinOptions {
                step: a.spin_step.to_radians(),
                per_metre: a.spin_rate[0].to_radians() * 1e3,
                per_second: a.spin_rate[1].to_radians(),
                measure: a.spin_measure.measure(),
                ..SpinOptions::default()
            };
            let fail = |e: deflect_core::JobError| {
                CliError::Failure(format!("{name}: --spin optimize: {e}"))
            };
            let loads = match five {
                Some(o) => LoadPath::new_five_axis(
                    &job,
                    program,
                    o,
                    options.step,
                    options.per_metre,
                    options.per_second,
                ),
                None => LoadPath::new(
                    &job,
                    program,
                    options.step,
                    options.per_metre,
                    options.per_second,
                ),
            }
            .map_err(fail)?;
            let plan = spin::plan(&job, &loads, seed, &options).map_err(fail)?;
            let job = job.with_spin(plan.schedule.clone());
            Ok((job, Some((plan, started.elapsed().as_secs_f64()))))
        }
    }
}

/// Runs the pass, streaming its samples to the files on a writer thread, then writes the
/// part map and the summary.
fn run(a: &JobArgs, t: &JobTask, out: &Path) -> Result<(), SimError> {
    if t.program.is_multi_axis() {
        return five_axis::five_axis_cmd(a, t, out);
    }
    let started = Instant::now();
    let setup = t.job.setup();
    let duration = deflect_core::machining::path::duration(&t.program, &setup.path)
        .map_err(|e| SimError::new(format!("{}: {e}", t.program_name)))?;
    let options = FileOptions {
        out: out.to_path_buf(),
        tolerance: a.tolerance * 1e-3,
        csv: a.samples_csv.then_some(a.lead_ms * 1e-3),
        log_rate: a.log_rate,
        rate_hz: setup.path.rate_hz,
        robot: t.robot_name.clone(),
        dof: t.job.model().dof(),
        to_base: setup.placement.rotation,
        robot_program: a.robot_program.map(|k| k.language()),
    };
    let target = deflect_core::io::robot_program::Target {
        model: t.job.model(),
        convention: t.job.controller(),
        robot: &t.robot_name,
        placement: setup.placement,
        program: &t.program,
        rate_hz: setup.path.rate_hz,
        rapid_speed: setup.path.rapid_speed,
    };
    let files = JobFiles::create(&t.program, target, &options)?;
    let (report, written) = stream_pass(a, t, files, duration)?;
    let (ops, paths) = written;
    let wall = started.elapsed().as_secs_f64();
    let r = report;
    let png = plot_part(t, &r, out)?;
    let (text, json) = summary(t, &r, &ops, wall, a.threads);
    let write = |name: &str, text: &str| {
        job_out::write(out.join(name), text).map_err(|e| SimError::new(e.to_string()))
    };
    write("job_summary.txt", &text)?;
    write(
        "job_summary.json",
        &serde_json::to_string_pretty(&json).map_err(|e| SimError::new(e.to_string()))?,
    )?;
    let names: Vec<String> = paths
        .iter()
        .chain([&png])
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    stdout(format_args!(
        "{text}outputs in {}: {}, job_summary.{{txt,json}}\n",
        out.display(),
        names.join(", ")
    ))
}

/// Plots the part's deviation, uncompensated and compensated, to `job_part.png`.
fn plot_part(t: &JobTask, r: &job::Report, out: &Path) -> Result<PathBuf, SimError> {
    let setup = t.job.setup();
    let png = out.join("job_part.png");
    let label = |name: &str, part| {
        let s = r.surface_error(part);
        format!(
            "{name}: floors max {:.3} mm, RMS {:.3} mm; walls {:.0} mm^2 left, {:.0} overcut",
            s.floor.max * 1e3,
            s.floor.rms * 1e3,
            s.material_left * 1e6,
            s.overcut * 1e6
        )
    };
    let (lu, lc) = (
        label("uncompensated", &r.uncompensated),
        label("compensated offline", &r.compensated),
    );
    let short_name = Path::new(&t.program_name).file_name().map_or_else(
        || t.program_name.clone(),
        |n| n.to_string_lossy().into_owned(),
    );
    part_map::plot_part_deviation(
        &png,
        &format!(
            "{short_name} on {}: the part's height above the nominal one",
            t.robot_name
        ),
        &r.nominal,
        &[(&lu, &r.uncompensated), (&lc, &r.compensated)],
        setup.stock.top,
    )?;
    Ok(png)
}

/// `job`: with `--explain` the program's word report only (nothing read but the program,
/// nothing written); otherwise the job.
impl Cmd for JobArgs {
    type Input = Option<JobTask>;

    fn load(&self) -> Result<Option<JobTask>, CliError> {
        match &self.explain {
            Some(path) => explain(self, path).map(|()| None),
            None => load(self).map(Some),
        }
    }

    fn writes(&self, input: &Option<JobTask>) -> bool {
        input.is_some()
    }

    fn run(&self, input: Option<JobTask>, out: &Path) -> Result<(), SimError> {
        match input {
            Some(task) => run(self, &task, out),
            None => Ok(()),
        }
    }
}
