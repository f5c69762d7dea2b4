//! Outputs of the serial testbed: the summary table (text, CSV, JSON), an MCAP log of every
//! run and a PNG of the path and orientation errors against time.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;

use super::motion::PathKind;
use super::run::{SerialResult, SerialRun};
use crate::SimError;
use crate::mcap_log::{self, Kind, Line, McapLog, RunInfo, scene_update};
use crate::plot_style::{
    CHART, Entry, Role, Swatch, canvas, color, draw_legend, figure, line, new_chart, padded_range,
    present,
};
use crate::summary::{reduction, write_summary};

fn run_label(r: &SerialRun) -> String {
    format!(
        "{}_{}",
        r.path.label(),
        if r.corrected {
            "corrected"
        } else {
            "uncorrected"
        }
    )
}

fn find(r: &SerialResult, path: PathKind, corrected: bool) -> Option<&SerialRun> {
    r.runs
        .iter()
        .find(|x| x.path == path && x.corrected == corrected)
}

/// The summary table printed on stdout and written to `serial_summary.txt`.
pub fn table(r: &SerialResult) -> String {
    let o = &r.options;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "serial testbed: {} in rapier ({} bodies; static compliance vs J K^-1 J^T: {:.2} % \
         max rel. error), payload {} kg, {:.2} g peak, {} model, corrector cancels the {}",
        o.robot,
        r.bodies,
        r.static_rel_error * 100.0,
        if o.payload.mass < 1.0 {
            format!("{:.3}", o.payload.mass)
        } else {
            format!("{:.1}", o.payload.mass)
        },
        o.motion.g,
        match o.model {
            deflect_core::vjm::Deflection::Exact => "exact",
            deflect_core::vjm::Deflection::Linearized => "linearized",
        },
        if o.link_inertia {
            "payload's and the links' inertial loads"
        } else {
            "payload's inertial wrench only"
        }
    );
    if o.task != deflect_core::mechanism::Task::POSE {
        let _ = writeln!(
            s,
            "task: {} ({} joints; the rotations the task leaves free are not corrected: the \
             rot columns show them)",
            o.task.name(),
            o.q0.len()
        );
    }
    let q0: Vec<String> = o.q0.iter().map(|q| format!("{q:.3}")).collect();
    let _ = writeln!(
        s,
        "start joints [{}] rad; line ({:.0}, {:.0}, {:.0}) mm with a {:.2} rad turn, circle of \
         radius {:.0} mm; v_max {:.2} m/s, ramp {:.0} ms\n",
        q0.join(", "),
        300.0 * o.motion.scale,
        200.0 * o.motion.scale,
        -100.0 * o.motion.scale,
        o.motion.turn,
        150.0 * o.motion.scale,
        o.motion.v_max,
        o.motion.ramp * 1e3
    );
    let _ = writeln!(
        s,
        "path   | run         | path max | path RMS | track max | rot max | rot RMS | correction"
    );
    let _ = writeln!(
        s,
        "       |             |     [mm] |     [mm] |      [mm] |  [mrad] |  [mrad] |   max [mm]"
    );
    for run in &r.runs {
        let m = &run.metrics;
        let _ = writeln!(
            s,
            "{:<6} | {:<11} | {:8.3} | {:8.3} | {:9.3} | {:7.3} | {:7.3} | {:10.3}",
            run.path.label(),
            if run.corrected {
                "corrected"
            } else {
                "uncorrected"
            },
            m.path_max_mm,
            m.path_rms_mm,
            m.track_max_mm,
            m.rot_max_mrad,
            m.rot_rms_mrad,
            m.correction_max_mm
        );
    }
    reduction_table(r, &mut s);
    let _ = writeln!(
        s,
        "\n{:.2} s simulated (steps of {} ms) in {:.2} s wall clock ({:.2}x real time)",
        r.sim_seconds,
        o.servo.dt * 1e3,
        r.wall_seconds,
        r.sim_seconds / r.wall_seconds.max(f64::MIN_POSITIVE)
    );
    s
}

/// The reduction of each error by the correction \[%\], per path.
fn reduction_table(r: &SerialResult, s: &mut String) {
    let _ = writeln!(s, "\nreduction by the correction [%]");
    let _ = writeln!(s, "path   | path max | path RMS | rot max | rot RMS");
    for path in [PathKind::Line, PathKind::Circle] {
        if let (Some(a), Some(b)) = (find(r, path, false), find(r, path, true)) {
            let (a, b) = (&a.metrics, &b.metrics);
            let _ = writeln!(
                s,
                "{:<6} | {:8.1} | {:8.1} | {:7.1} | {:7.1}",
                path.label(),
                reduction(a.path_max_mm, b.path_max_mm),
                reduction(a.path_rms_mm, b.path_rms_mm),
                reduction(a.rot_max_mrad, b.rot_max_mrad),
                reduction(a.rot_rms_mrad, b.rot_rms_mrad)
            );
        }
    }
}

/// CSV: one row per run, SI-suffixed columns.
pub fn csv(r: &SerialResult) -> String {
    let mut s = String::from(
        "path,corrected,duration_s,path_max_mm,path_rms_mm,track_max_mm,rot_max_mrad,\
         rot_rms_mrad,correction_max_mm\n",
    );
    for run in &r.runs {
        let m = &run.metrics;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{}",
            run.path.label(),
            run.corrected,
            run.duration,
            m.path_max_mm,
            m.path_rms_mm,
            m.track_max_mm,
            m.rot_max_mrad,
            m.rot_rms_mrad,
            m.correction_max_mm
        );
    }
    s
}

/// `[w, x, y, z]` -> `[x, y, z, w]`.
fn xyzw(q: &[f64]) -> [f64; 4] {
    [q[1], q[2], q[3], q[0]]
}

fn position(p: &[f64]) -> [f64; 3] {
    [p[0], p[1], p[2]]
}

fn run_info(r: &SerialResult, run: &SerialRun) -> RunInfo {
    let o = &r.options;
    let m = &o.motion;
    let motion = match run.path {
        PathKind::Line => format!(
            "line ({:.0}, {:.0}, {:.0}) mm with a {:.2} rad turn about the vertical, rest to rest",
            300.0 * m.scale,
            200.0 * m.scale,
            -100.0 * m.scale,
            m.turn
        ),
        PathKind::Circle => format!(
            "horizontal circle of radius {:.0} mm with a {:.2} rad turn, rest to rest",
            150.0 * m.scale,
            m.turn
        ),
    };
    RunInfo {
        scenario: "serial".into(),
        run: run_label(run),
        robot: format!(
            "{} as a flexible arm in rapier ({} bodies), payload {:.1} kg",
            o.robot, r.bodies, o.payload.mass
        ),
        motion,
        acceleration: format!(
            "{} g peak ({:.2} m/s^2), jerk-limited (ramp {:.0} ms), v_max {:.2} m/s",
            m.g,
            m.g * deflect_core::units::STANDARD_GRAVITY,
            m.ramp * 1e3,
            m.v_max
        ),
        correction: if run.corrected {
            format!(
                "deflect-core's 6-D D'Alembert corrector for serial arms, cancelling the {}",
                if o.link_inertia {
                    "payload's and the links' inertial loads"
                } else {
                    "payload's inertial wrench only"
                }
            )
        } else {
            "none".into()
        },
        options: serde_json::to_value(o).unwrap_or_default(),
    }
}

/// Topics per run, as `/serial/<path>_<corrected|uncorrected>/<topic>`, and their types.
pub const TOPICS: [(&str, Kind); 6] = [
    ("desired", Kind::Pose),
    ("actual", Kind::Pose),
    ("commanded", Kind::Point),
    ("wrench", Kind::Wrench),
    ("tcp_pose", Kind::PosesInFrame),
    ("paths", Kind::SceneUpdate),
];

/// Writes every run to `path` by the convention of [`crate::mcap_log`]: topics
/// `/serial/<run>/<topic>` ([`TOPICS`]), every run from t = 0, a `deflect.run` metadata
/// record per run. Returns the number of messages.
pub fn write_mcap(path: &Path, r: &SerialResult) -> Result<usize, SimError> {
    let mut log = McapLog::create(path)?;
    for run in &r.runs {
        let info = run_info(r, run);
        log.run_metadata(&info)?;
        let prefix = info.prefix();
        let name = info.run.as_str();
        let mut channels = Vec::new();
        for (topic, kind) in TOPICS {
            channels.push(log.channel(&prefix, topic, kind)?);
        }
        let role = if run.corrected {
            Role::Corrected
        } else {
            Role::Uncorrected
        };
        let lines = [
            Line {
                id: format!("{name}/desired"),
                points: run.samples.iter().map(|s| position(&s.desired)).collect(),
                rgb: color(Role::Desired).rgb(),
                closed: false,
            },
            Line {
                id: format!("{name}/actual"),
                points: run.samples.iter().map(|s| position(&s.actual)).collect(),
                rgb: color(role).rgb(),
                closed: false,
            },
        ];
        if let Some(ch) = channels.last() {
            log.write(*ch, 0.0, &scene_update(0.0, &lines))?;
        }
        for s in &run.samples {
            let t = s.t;
            let (d, a) = (&s.desired, &s.actual);
            let msgs = [
                mcap_log::pose(name, t, position(d), xyzw(&d[3..])),
                mcap_log::pose(name, t, position(a), xyzw(&a[3..])),
                mcap_log::point(name, t, s.commanded),
                mcap_log::wrench(name, t, &s.wrench),
                mcap_log::poses_in_frame(t, position(a), xyzw(&a[3..])),
            ];
            for (ch, msg) in channels.iter().zip(&msgs) {
                log.write(*ch, t, msg)?;
            }
        }
    }
    log.finish()
}

/// Path error (top) and orientation error (bottom) against time, one curve per run: colour
/// uncorrected / corrected, solid line, dashed circle; the legend in a column on the right.
pub fn plot(path: &Path, r: &SerialResult) -> Result<(), SimError> {
    let root = canvas(path, (1250, 900))?;
    let order = [
        (PathKind::Line, false),
        (PathKind::Line, true),
        (PathKind::Circle, false),
        (PathKind::Circle, true),
    ];
    let runs: Vec<&SerialRun> = order.iter().filter_map(|&(p, c)| find(r, p, c)).collect();
    let entries: Vec<Entry> = runs
        .iter()
        .map(|run| {
            let (role, dashed) = run_style(run);
            let m = &run.metrics;
            Entry::new(
                format!(
                    "{}: path max {:.3} mm, rot. max {:.2} mrad",
                    run_label(run).replace('_', ", "),
                    m.path_max_mm,
                    m.rot_max_mrad
                ),
                role,
                if dashed {
                    Swatch::Dashed(2)
                } else {
                    Swatch::Line(2)
                },
            )
        })
        .collect();
    let o = &r.options;
    let title = format!(
        "{} carrying {:.0} kg: line and circle at {} g peak, with and without the D'Alembert \
         correction",
        o.robot, o.payload.mass, o.motion.g
    );
    let (plot, legend) = figure(&root, &title, CHART.caption, &entries)?;
    let (_, h) = plot.dim_in_pixel();
    let (top, bottom) = plot.split_vertically(h / 2);
    for (area, rot) in [(&top, false), (&bottom, true)] {
        let all: Vec<Vec<(f64, f64)>> = runs.iter().map(|x| error_series(r, x, rot)).collect();
        let ymax = all.iter().flatten().map(|p| p.1).fold(1e-3, f64::max) * 1.06;
        let x = padded_range(all.iter().flatten().map(|p| p.0), 0.01, 0.01);
        let (caption, unit) = if rot {
            ("orientation error", "orientation error [mrad]")
        } else {
            ("distance from the planned path", "path deviation [mm]")
        };
        let area = area
            .titled(caption, ("sans-serif", 16))
            .map_err(crate::plot_style::perr)?;
        let mut chart = new_chart(
            &area,
            CHART,
            x,
            0.0..ymax,
            ("time since the motion start [s]", unit),
        )?;
        for (run, pts) in runs.iter().zip(all) {
            let (role, dashed) = run_style(run);
            line(&mut chart, pts, color(role), 2, dashed)?;
        }
    }
    draw_legend(&legend, &entries)?;
    present(&root, path)?;
    Ok(())
}

/// A run's error against time over its motion \[s, mm\] (`rot`: the orientation error
/// \[s, mrad\]).
fn error_series(r: &SerialResult, run: &SerialRun, rot: bool) -> Vec<(f64, f64)> {
    let start = |run: &SerialRun| {
        let p = run.samples.first().map(|s| s.desired).unwrap_or_default();
        super::run::pose_of(&p)
    };
    let s0 = start(run);
    run.samples
        .iter()
        .filter(|s| s.active)
        .map(|s| {
            let (a, d) = (
                super::run::pose_of(&s.actual),
                super::run::pose_of(&s.desired),
            );
            let v = if rot {
                a.rotation.angle_to(&d.rotation) * 1e3
            } else {
                super::motion::path_distance(
                    run.path,
                    &s0,
                    &r.options.motion,
                    &a.translation.vector,
                ) * 1e3
            };
            (s.t, v)
        })
        .collect()
}

/// A run's line: its role (corrected or not) and whether dashed (the circle).
fn run_style(run: &SerialRun) -> (Role, bool) {
    let role = if run.corrected {
        Role::Corrected
    } else {
        Role::Uncorrected
    };
    let dashed = run.path == PathKind::Circle;
    (role, dashed)
}

/// Writes `serial_summary.{txt,csv,json}`, `serial.mcap` and `serial.png` into `out`.
pub fn write_all(out: &Path, r: &SerialResult) -> Result<usize, SimError> {
    write_summary(out, "serial_summary", &table(r), &csv(r), r)?;
    let n = write_mcap(&out.join("serial.mcap"), r)?;
    plot(&out.join("serial.png"), r)?;
    Ok(n)
}
