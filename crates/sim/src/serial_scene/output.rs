//! Outputs of the serial testbed: the summary table (text, CSV, JSON), an MCAP log of every
//! run and a PNG of the path and orientation errors against time.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;
use serde_json::json;

use super::{PathKind, SerialResult, SerialRun, SerialSample};
use crate::SimError;
use crate::output::{
    CHART, McapLog, canvas, labelled_line, legend, new_chart, present, stamp, stamp_schema,
    write_summary,
};
use crate::report::reduction;

/// Topics written per run, as `/serial/<path>_<corrected|uncorrected>/<topic>`.
pub const TOPICS: [&str; 4] = ["desired", "actual", "commanded", "wrench"];

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
         max rel. error), payload {:.1} kg, {:.2} g peak, {} model, corrector cancels the {}",
        o.robot,
        r.bodies,
        r.static_rel_error * 100.0,
        o.payload.mass,
        o.motion.g,
        match o.model {
            deflect_core::dalembert::Deflection::Exact => "exact",
            deflect_core::dalembert::Deflection::Linearized => "linearized",
        },
        if o.link_inertia {
            "payload's and the links' inertial loads"
        } else {
            "payload's inertial wrench only"
        }
    );
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

fn pose_schema(title: &str) -> serde_json::Value {
    let mut props = json!({"timestamp": stamp_schema(), "run": {"type": "string"}});
    for f in ["x", "y", "z"] {
        props[f] = json!({"type": "number", "description": "m"});
    }
    for f in ["qw", "qx", "qy", "qz"] {
        props[f] = json!({"type": "number", "description": "unit quaternion"});
    }
    json!({"title": title, "type": "object", "properties": props})
}

fn wrench_schema() -> serde_json::Value {
    let mut props = json!({"timestamp": stamp_schema(), "run": {"type": "string"}});
    for (i, f) in ["fx", "fy", "fz", "mx", "my", "mz"].iter().enumerate() {
        props[*f] = json!({"type": "number", "description": if i < 3 { "N" } else { "N m" }});
    }
    json!({"title": "inertial wrench the corrector cancels", "type": "object", "properties": props})
}

fn message(topic: &str, run: &str, s: &SerialSample) -> serde_json::Value {
    let mut m = json!({"timestamp": stamp(s.t), "run": run});
    let put = |m: &mut serde_json::Value, names: &[&str], v: &[f64]| {
        for (n, x) in names.iter().zip(v) {
            m[*n] = json!(x);
        }
    };
    const POSE: [&str; 7] = ["x", "y", "z", "qw", "qx", "qy", "qz"];
    match topic {
        "desired" => put(&mut m, &POSE, &s.desired),
        "actual" => put(&mut m, &POSE, &s.actual),
        "commanded" => put(&mut m, &POSE[..3], &s.commanded),
        _ => put(&mut m, &["fx", "fy", "fz", "mx", "my", "mz"], &s.wrench),
    }
    m
}

/// Writes every run to `path`; all runs share the time axis from t = 0. Returns the number
/// of messages.
pub fn write_mcap(path: &Path, r: &SerialResult) -> Result<usize, SimError> {
    let mut log = McapLog::create(path)?;
    let pose = log.add_schema("deflect.serial.Pose", &pose_schema("TCP pose"))?;
    let wrench = log.add_schema("deflect.serial.Wrench", &wrench_schema())?;
    for run in &r.runs {
        let name = run_label(run);
        let mut channels = Vec::new();
        for topic in TOPICS {
            let schema = if topic == "wrench" { wrench } else { pose };
            channels.push(log.add_channel(
                schema,
                &format!("/serial/{name}/{topic}"),
                "run",
                &name,
            )?);
        }
        for (seq, s) in (0u32..).zip(&run.samples) {
            for (topic, ch) in TOPICS.iter().zip(&channels) {
                log.write(*ch, seq, s.t, &message(topic, &name, s))?;
            }
        }
    }
    log.finish()
}

/// Path error (top) and orientation error (bottom) against time, one curve per run.
pub fn plot(path: &Path, r: &SerialResult) -> Result<(), SimError> {
    let root = canvas(path, (1100, 900))?;
    let (top, bottom) = root.split_vertically(450);
    let t_end = r
        .runs
        .iter()
        .map(|x| x.duration)
        .fold(0.1, f64::max)
        .max(0.1);
    let start = |run: &SerialRun| {
        let p = run.samples.first().map(|s| s.desired).unwrap_or_default();
        super::pose_of(&p)
    };
    let series = |run: &SerialRun, rot: bool| -> Vec<(f64, f64)> {
        let s0 = start(run);
        run.samples
            .iter()
            .filter(|s| s.active)
            .map(|s| {
                let (a, d) = (super::pose_of(&s.actual), super::pose_of(&s.desired));
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
    };
    let colors = [
        (PathKind::Line, false, RED),
        (PathKind::Line, true, BLUE),
        (PathKind::Circle, false, MAGENTA),
        (PathKind::Circle, true, GREEN),
    ];
    for (area, rot) in [(&top, false), (&bottom, true)] {
        let ymax = r
            .runs
            .iter()
            .flat_map(|x| series(x, rot).into_iter().map(|p| p.1))
            .fold(1e-3, f64::max)
            * 1.35;
        let (caption, unit) = if rot {
            ("orientation error", "orientation error [mrad]")
        } else {
            ("distance from the planned path", "path deviation [mm]")
        };
        let mut chart = new_chart(
            area,
            CHART,
            &format!("{}: {caption}", r.options.robot),
            0.0..t_end,
            0.0..ymax,
            ("time [s]", unit),
        )?;
        for &(p, c, color) in &colors {
            if let Some(run) = find(r, p, c) {
                let m = &run.metrics;
                let (mx, rms) = if rot {
                    (m.rot_max_mrad, m.rot_rms_mrad)
                } else {
                    (m.path_max_mm, m.path_rms_mm)
                };
                labelled_line(
                    &mut chart,
                    series(run, rot),
                    color,
                    if c { 2 } else { 1 },
                    format!("{}: max {mx:.3}, RMS {rms:.3}", run_label(run)),
                )?;
            }
        }
        legend(&mut chart, 0.85, 14)?;
    }
    present(&root, path)?;
    Ok(())
}

/// Writes `serial_summary.{txt,csv,json}`, `serial.mcap` and `serial.png` into `out`.
pub fn write_all(out: &Path, r: &SerialResult) -> Result<usize, SimError> {
    write_summary(out, "serial_summary", &table(r), &csv(r), r)?;
    let n = write_mcap(&out.join("serial.mcap"), r)?;
    plot(&out.join("serial.png"), r)?;
    Ok(n)
}
