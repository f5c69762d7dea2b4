//! `job`: a machining job offline (deflect-core's `machining::job`) on the built-in KR 300 or
//! the user's arm. [`load`] reads and checks the program, the arm, the placement and the
//! stock before any work; [`job_cmd`] runs the pass, prints the summary and writes the
//! compensated program, the samples, the part's heat map and the summary files.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::io::tool_table::{self, TblOptions};
use deflect_core::io::{job_out, points_csv};
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::job::{self, Job, Report, Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::machining::{Motion, Program};
use deflect_core::mechanism::PoseIkOptions;
use deflect_core::units::LengthUnit;
use deflect_sim::SimError;
use deflect_sim::scenes::milling::part_map;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};

use super::serial::{load_robot, read_program, read_text};
use super::stdout;
use crate::cli::{CliError, JobArgs, ToolArgs};

/// The built-in program: a groove, a ramp and a circular pocket (mm).
const DEFAULT_PROGRAM: &str = include_str!("../../../../data/groove_and_pocket.nc");
/// The KR 300's defaults: the tool down over a table in front of it.
const KR300_PLACEMENT: [f64; 6] = [2.45, 0.02, 0.92, 0.0, 0.0, std::f64::consts::PI];
const KR300_SEED: [f64; 6] = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0];
/// Where the tool is before the program's first move, workpiece frame \[m\].
const START: [f64; 3] = [0.0, 0.0, 0.02];

/// Everything `job` needs, read and checked.
pub struct JobTask {
    job: Job,
    program: Program,
    program_name: String,
    robot_name: String,
    seed: Vec<f64>,
}

/// The stock by default: the feed moves' bounding box grown by the tool radius \[m\].
pub(crate) fn default_stock(
    program: &Program,
    radius: f64,
) -> Option<(Vector2<f64>, Vector2<f64>)> {
    let mut lo = Vector2::repeat(f64::INFINITY);
    let mut hi = Vector2::repeat(f64::NEG_INFINITY);
    for m in program.moves.iter().filter(|m| m.is_feed()) {
        for p in [m.start.xy(), m.end.xy()] {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
        if let Motion::Arc { sweep, .. } = m.motion {
            // Points along the arc (a spiral in any plane) every 5 degrees.
            let n = ((sweep.abs() / 5f64.to_radians()).ceil() as usize).clamp(2, 10_000);
            for k in 1..n {
                let p = m.point(k as f64 / n as f64).xy();
                lo = lo.inf(&p);
                hi = hi.sup(&p);
            }
        }
    }
    (lo.x.is_finite() && hi.x.is_finite())
        .then(|| (lo - Vector2::repeat(radius), hi + Vector2::repeat(radius)))
}

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
    let (program, program_name) = match (&a.program, &a.points) {
        (Some(p), _) => {
            let text = read_program("--program", p)?;
            let program = gcode::from_str(&text, &options)
                .map_err(|e| CliError::Failure(format!("--program {}: {e}", p.display())))?;
            (program, p.display().to_string())
        }
        (None, Some(p)) => {
            let text = read_text("--points", p, "tool points CSV")?;
            let program = points_csv::from_str(&text, &options)
                .map_err(|e| CliError::Failure(format!("--points {}: {e}", p.display())))?;
            (program, p.display().to_string())
        }
        (None, None) => (
            gcode::from_str(DEFAULT_PROGRAM, &options)
                .map_err(|e| CliError::Failure(format!("built-in program: {e}")))?,
            "data/groove_and_pocket.nc (built in)".to_string(),
        ),
    };
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
    let p = a.placement.clone().unwrap_or(KR300_PLACEMENT.to_vec());
    let [x, y, z, roll, pitch, yaw] = p.as_slice() else {
        return Err(CliError::Usage(format!(
            "--placement: {} values; expected 6",
            p.len()
        )));
    };
    let placement = Isometry3::from_parts(
        Translation3::new(*x, *y, *z),
        UnitQuaternion::from_euler_angles(*roll, *pitch, *yaw),
    );
    let radius = 0.5e-3 * a.tool.diameter;
    let (min, max) = match &a.stock {
        Some(s) => match s.as_slice() {
            [x0, y0, x1, y1] => (Vector2::new(*x0, *y0) * 1e-3, Vector2::new(*x1, *y1) * 1e-3),
            _ => return Err(CliError::Usage("--stock: expected 4 values".into())),
        },
        None => default_stock(&program, radius).ok_or_else(|| {
            CliError::Failure(format!(
                "{program_name}: no feed move (G1-G3) to size the stock from; give --stock"
            ))
        })?,
    };
    let (tool, coefficients) = tool_and_material(&a.tool)?;
    let table = match &a.tools {
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
        None => None,
    };
    let setup = Setup {
        placement,
        tool_orientation: Setup::tool_down(),
        tool,
        coefficients,
        stock: Stock {
            min,
            max,
            top: a.top * 1e-3,
            cell: a.cell * 1e-3,
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
    Ok(JobTask {
        job,
        program,
        program_name,
        robot_name: loaded.name,
        seed,
    })
}

/// Which tool cuts each `T` of the program, and which spindle: the summary's words.
fn tools_text(t: &JobTask) -> (String, Vec<serde_json::Value>) {
    let used = t.program.tools();
    let setup = t.job.setup();
    let mut json = Vec::new();
    let mut text = match t.job.tools() {
        Some(table) => {
            let mut parts = Vec::new();
            for n in &used {
                if let Some(spec) = table.get(*n) {
                    parts.push(format!(
                        "T{n} {:.3} mm {} {} flutes{}",
                        spec.tool.diameter * 1e3,
                        spec.shape.name(),
                        spec.tool.flutes,
                        if spec.name.is_empty() {
                            String::new()
                        } else {
                            format!(" ({})", spec.name)
                        }
                    ));
                    json.push(serde_json::json!({
                        "tool": n, "diameter_m": spec.tool.diameter, "shape": spec.shape.name(),
                        "flutes": spec.tool.flutes, "helix_rad": spec.tool.helix, "length_m": spec.length,
                    }));
                }
            }
            let ends = table
                .tools()
                .iter()
                .any(|s| s.shape != deflect_core::machining::tools::ToolShape::Flat);
            format!(
                "tools (from the tool table): {}{}",
                if parts.is_empty() {
                    "none cut".to_string()
                } else {
                    parts.join("; ")
                },
                if ends {
                    "; ball and bull-nose ends cut the z-map as ball and flat ends and feel the flat \
                     end mill's force"
                } else {
                    ""
                }
            )
        }
        None => {
            let names: Vec<String> = used
                .iter()
                .filter(|&&n| n > 0)
                .map(|n| format!("T{n}"))
                .collect();
            json.push(serde_json::json!({
                "tool": "every", "diameter_m": setup.tool.diameter, "shape": "flat",
                "flutes": setup.tool.flutes, "helix_rad": setup.tool.helix,
            }));
            format!(
                "tool: no tool table; the --diameter/--flutes tool ({:.3} mm flat, {} flutes) serves \
                 every T of the program ({})",
                setup.tool.diameter * 1e3,
                setup.tool.flutes,
                if names.is_empty() {
                    "it names none".to_string()
                } else {
                    names.join(", ")
                }
            )
        }
    };
    if let Some(hand) = setup.hand_spindle {
        let _ = write!(
            text,
            "\nspindle: hand-started at {:.0} rpm wherever the program's spindle is off",
            hand * 60.0
        );
    }
    (text, json)
}

/// The summary as text lines and JSON.
fn summary(t: &JobTask, r: &Report, wall: f64) -> (String, serde_json::Value) {
    let (pu, pc) = (r.path_error(false), r.path_error(true));
    let (su, sc) = (
        r.surface_error(&r.uncompensated),
        r.surface_error(&r.compensated),
    );
    let duration = r.samples.last().map_or(0.0, |s| s.path.time);
    let fmax = r.samples.iter().map(|s| s.force.norm()).fold(0.0, f64::max);
    let mut text = String::new();
    let _ = writeln!(
        text,
        "job: {} on {}: {} samples at {} Hz over {duration:.2} s of program, in {wall:.2} s \
         ({:.0} samples/s, {:.0} z-map cell updates/s); {} plunge samples (no side force)",
        t.program_name,
        t.robot_name,
        r.samples.len(),
        r.rate_hz,
        r.samples.len() as f64 / wall.max(1e-9),
        r.cell_updates as f64 / wall.max(1e-9),
        r.plunge_samples
    );
    let (tools, tools_json) = tools_text(t);
    let _ = writeln!(text, "{tools}");
    if let Some(c) = r.rapid_contact {
        let _ = writeln!(
            text,
            "rapids in the stock: the deepest {:.3} mm at line {} (t = {:.2} s), within --rapid-skim \
             {:.3} mm",
            c.depth * 1e3,
            c.line,
            c.time,
            t.job.setup().rapid_skim * 1e3
        );
    }
    let _ = writeln!(text, "largest force on the tool: {fmax:.1} N");
    let _ = writeln!(text, "line  samples  mean |F| [N]  max |F| [N]");
    let lines = r.line_forces();
    for l in lines.iter().filter(|l| l.max > 0.0) {
        let _ = writeln!(
            text,
            "{:>4}  {:>7}  {:>12.1}  {:>11.1}",
            l.line,
            l.samples,
            l.mean.norm(),
            l.max
        );
    }
    let mut off: Vec<_> = lines.iter().filter(|l| l.deviation.is_some()).collect();
    off.sort_by(|a, b| b.error_compensated.total_cmp(&a.error_compensated));
    for l in off.iter().take(10) {
        let _ = writeln!(
            text,
            "DEBUG line {} compensated error {:.4} mm residual {:.2e} m ({})",
            l.line,
            l.error_compensated * 1e3,
            l.residual,
            l.deviation.map_or("", |d| d.name())
        );
    }
    for (label, p, s) in [("uncompensated", pu, su), ("compensated", pc, sc)] {
        let _ = writeln!(
            text,
            "{label:<13}  path error max {:.4} mm, RMS {:.4} mm; part floors max {:.4} mm, \
             RMS {:.4} mm; walls {:.1} mm^2 left, {:.1} mm^2 overcut",
            p.max * 1e3,
            p.rms * 1e3,
            s.floor.max * 1e3,
            s.floor.rms * 1e3,
            s.material_left * 1e6,
            s.overcut * 1e6
        );
    }
    let stats = |p: job::ErrorStats, s: job::SurfaceError| {
        serde_json::json!({
            "path_error_max_m": p.max, "path_error_rms_m": p.rms,
            "floor_error_max_m": s.floor.max, "floor_error_rms_m": s.floor.rms,
            "material_left_m2": s.material_left, "overcut_m2": s.overcut,
        })
    };
    let json = serde_json::json!({
        "program": t.program_name,
        "robot": t.robot_name,
        "samples": r.samples.len(),
        "rate_hz": r.rate_hz,
        "duration_s": duration,
        "wall_time_s": wall,
        "cell_updates": r.cell_updates,
        "plunge_samples": r.plunge_samples,
        "max_force_n": fmax,
        "tools": tools_json,
        "rapid_contact": r.rapid_contact.map(|c| serde_json::json!({
            "line": c.line, "time_s": c.time, "depth_m": c.depth,
        })),
        "hand_spindle_rpm": t.job.setup().hand_spindle.map(|v| v * 60.0),
        "lines": lines.iter().map(|l| serde_json::json!({
            "line": l.line, "samples": l.samples,
            "mean_force_n": [l.mean.x, l.mean.y, l.mean.z], "max_force_n": l.max,
        })).collect::<Vec<_>>(),
        "uncompensated": stats(pu, su),
        "compensated": stats(pc, sc),
    });
    (text, json)
}

/// Runs the pass and writes its files.
pub fn job_cmd(a: &JobArgs, t: &JobTask, out: &Path) -> Result<(), SimError> {
    let started = Instant::now();
    let r = job::run(&t.job, &t.program, &t.seed)
        .map_err(|e| SimError::new(format!("{}: {e}", t.program_name)))?;
    let wall = started.elapsed().as_secs_f64();
    let write = |name: &str, text: &str| {
        job_out::write(out.join(name), text).map_err(|e| SimError::new(e.to_string()))
    };
    write(
        "job_compensated.nc",
        &job_out::compensated_gcode(&r, &t.program, a.tolerance * 1e-3),
    )?;
    write(
        "job_samples.csv",
        &job_out::samples_csv(&r, a.lead_ms * 1e-3),
    )?;
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
    part_map::plot_part_deviation(
        &png,
        &format!(
            "{} on {}: the part's height above the nominal one",
            t.program_name, t.robot_name
        ),
        &r.nominal,
        &[(&lu, &r.uncompensated), (&lc, &r.compensated)],
        t.job.setup().stock.top,
    )?;
    let (text, json) = summary(t, &r, wall);
    write("job_summary.txt", &text)?;
    write(
        "job_summary.json",
        &serde_json::to_string_pretty(&json).map_err(|e| SimError::new(e.to_string()))?,
    )?;
    stdout(format_args!(
        "{text}outputs: {}/job_compensated.nc, job_samples.csv, job_part.png, \
         job_summary.{{txt,json}}\n",
        out.display()
    ))
}

/// The cutter and the material of `--diameter/--flutes/--helix` and `--coefficients` (ranges
/// checked by [`crate::cli::ToolArgs::check`]; the core's checks name what else is wrong).
pub(crate) fn tool_and_material(a: &ToolArgs) -> Result<(Tool, Coefficients), CliError> {
    let tool = Tool::new(a.diameter * 1e-3, a.flutes, a.helix.to_radians())
        .map_err(|e| CliError::Usage(format!("--diameter/--flutes/--helix: {e}")))?;
    let coefficients = match a.coefficients.as_deref() {
        Some(&[tc, rc, ac, te, re, ae]) => {
            Coefficients::new(tc * 1e6, rc * 1e6, ac * 1e6, te * 1e3, re * 1e3, ae * 1e3)
                .map_err(|e| CliError::Usage(format!("--coefficients: {e}")))?
        }
        Some(_) => return Err(CliError::Usage("--coefficients: expected 6 values".into())),
        None => Coefficients::AL7075_T6_CARBIDE,
    };
    Ok((tool, coefficients))
}
