//! Outputs of the `contour` scenario: summary table (text, CSV, JSON), an MCAP log and one PNG
//! per object (true outline vs raw and compensated recovered contours, and the distance of
//! each recorded point to the outline).

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Vector2;
use plotters::prelude::*;
use serde_json::json;

use super::{ContourRun, Sample};
use crate::SimError;
use crate::output::{
    ChartStyle, McapLog, canvas, labelled_line, legend, new_chart, present, stamp, stamp_schema,
    write_summary,
};
use crate::report::reduction;

/// The summary table: shape errors raw vs compensated, forces, contact losses.
pub fn table(runs: &[ContourRun]) -> String {
    let mut s = String::from(
        "Contour tracing (ContourTracer, Eq. 21) and shape recovery: raw = FK of the motor readings, \
         comp = Eq. 10 (stiffness + backlash)\n",
    );
    let _ = writeln!(
        s,
        "{:<10} {:<6} {:>5} {:>5} | {:>17} | {:>17} | {:>15} | {:>10} | {:>6} {:>6} {:>4} {:>4} | {:>7}",
        "shape",
        "state",
        "steps",
        "pts",
        "raw rms/max [mm]",
        "comp rms/max [mm]",
        "rms, max red.",
        "tool [mm]",
        "maxF N",
        "peakF",
        "loss",
        "run",
        "path"
    );
    for r in runs {
        let _ = writeln!(
            s,
            "{:<10} {:<6} {:>5} {:>5} | {:>8.4}/{:<8.4} | {:>8.4}/{:<8.4} | {:>6.1}% {:>6.1}% | {:>10.4} | {:>6.2} {:>6.1} {:>4} {:>4} | {:>6.1}%",
            r.name,
            r.state,
            r.tracer_steps,
            r.contacts,
            r.raw.rms_mm,
            r.raw.max_mm,
            r.compensated.rms_mm,
            r.compensated.max_mm,
            reduction(r.raw.rms_mm, r.compensated.rms_mm),
            reduction(r.raw.max_mm, r.compensated.max_mm),
            r.actual.rms_mm,
            r.max_force,
            r.peak_force,
            r.contact_losses,
            r.longest_loss,
            100.0 * r.path_length / r.perimeter
        );
    }
    s.push_str(
        "tool = RMS distance of the true tool point to the outline (penalty-contact penetration floor); \
         maxF = largest settled contact force, peakF = largest of any physics step; loss = readings out \
         of contact after first contact (bisections), run = longest run of them; path = traced length / \
         perimeter\n",
    );
    s
}

/// CSV of the runs' metrics.
pub fn summary_csv(runs: &[ContourRun]) -> String {
    let mut s = String::from(
        "shape,state,tracer_steps,contacts,eq21_steps,normal_steps,contact_losses,longest_loss,jams,\
         raw_rms_mm,raw_max_mm,comp_rms_mm,comp_max_mm,tool_rms_mm,tool_max_mm,max_force_n,peak_force_n,\
         path_m,perimeter_m,sim_time_s,physics_steps,wall_s\n",
    );
    for r in runs {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.4},{:.4},{:.6},{:.6},{:.3},{},{:.3}",
            r.name,
            r.state,
            r.tracer_steps,
            r.contacts,
            r.eq21_steps,
            r.normal_steps,
            r.contact_losses,
            r.longest_loss,
            r.jams,
            r.raw.rms_mm,
            r.raw.max_mm,
            r.compensated.rms_mm,
            r.compensated.max_mm,
            r.actual.rms_mm,
            r.actual.max_mm,
            r.max_force,
            r.peak_force,
            r.path_length,
            r.perimeter,
            r.sim_time,
            r.physics_steps,
            r.wall
        );
    }
    s
}

fn point_schema(title: &str, unit: &str) -> serde_json::Value {
    json!({"title": title, "type": "object", "properties": {
        "timestamp": stamp_schema(),
        "shape": {"type": "string"},
        "state": {"type": "string"},
        "x": {"type": "number", "description": unit},
        "y": {"type": "number", "description": unit},
    }})
}

/// Topics per shape, under `/contour/<shape>/`.
pub const TOPICS: [&str; 6] = [
    "command",
    "tool_actual",
    "recorded_raw",
    "recorded_compensated",
    "force",
    "joints",
];

fn messages(shape: &str, s: &Sample, t: f64) -> [Option<serde_json::Value>; 6] {
    let ts = stamp(t);
    let pt = |p: &[f64; 2]| json!({"timestamp": ts, "shape": shape, "state": s.state, "x": p[0], "y": p[1]});
    [
        Some(pt(&s.command)),
        Some(pt(&s.tool_actual)),
        s.raw.as_ref().map(pt),
        s.compensated.as_ref().map(pt),
        Some(
            json!({"timestamp": ts, "shape": shape, "state": s.state, "x": s.force[0], "y": s.force[1],
            "sensed_x": s.force_sensed[0], "sensed_y": s.force_sensed[1],
            "true_x": s.force_true[0], "true_y": s.force_true[1]}),
        ),
        Some(json!({"timestamp": ts, "shape": shape, "motor": s.q_motor, "link": s.q_link})),
    ]
}

/// Writes every run into one MCAP file, topics `/contour/<shape>/<topic>`; shapes follow each
/// other in log time. Returns the number of messages.
pub fn write_mcap(path: &Path, runs: &[ContourRun]) -> Result<usize, SimError> {
    let mut log = McapLog::create(path)?;
    let schemas = [
        (
            "deflect.ContourCommand",
            point_schema("commanded tool point (motor side)", "m"),
        ),
        (
            "deflect.ContourToolActual",
            point_schema("true tool point (simulation)", "m"),
        ),
        (
            "deflect.ContourRecordedRaw",
            point_schema("recovered contour point, FK of the motor readings", "m"),
        ),
        (
            "deflect.ContourRecordedCompensated",
            point_schema("recovered contour point, Eq. 10 compensated", "m"),
        ),
        (
            "deflect.ContourForce",
            json!({"title": "force the tool exerts on the object [N]", "type": "object", "properties": {
                "timestamp": stamp_schema(), "shape": {"type": "string"}, "state": {"type": "string"},
                "x": {"type": "number", "description": "bias removed, N"}, "y": {"type": "number", "description": "bias removed, N"},
                "sensed_x": {"type": "number"}, "sensed_y": {"type": "number"},
                "true_x": {"type": "number"}, "true_y": {"type": "number"}}}),
        ),
        (
            "deflect.ContourJoints",
            json!({"title": "joint angles [rad]", "type": "object", "properties": {
                "timestamp": stamp_schema(), "shape": {"type": "string"},
                "motor": {"type": "array", "items": {"type": "number"}},
                "link": {"type": "array", "items": {"type": "number"}}}}),
        ),
    ];
    let mut ids = Vec::new();
    for (name, s) in &schemas {
        ids.push(log.add_schema(name, s)?);
    }
    let mut offset = 0.0;
    for r in runs {
        let mut channels = Vec::new();
        for (topic, id) in TOPICS.iter().zip(&ids) {
            channels.push(log.add_channel(
                *id,
                &format!("/contour/{}/{topic}", r.name),
                "shape",
                &r.name,
            )?);
        }
        let mut last = 0.0;
        for (seq, s) in (0u32..).zip(&r.samples) {
            let t = offset + s.t;
            for (ch, msg) in channels.iter().zip(messages(&r.name, s, t)) {
                let Some(msg) = msg else { continue };
                log.write(*ch, seq, t, &msg)?;
            }
            last = s.t;
        }
        offset += last + 1.0;
    }
    log.finish()
}

/// One PNG per run: left the true outline (black), the raw (red) and compensated (blue)
/// recovered contours in mm, right the signed distance of each recorded point to the outline.
pub fn plot_run(path: &Path, r: &ContourRun) -> Result<(), SimError> {
    let root = canvas(path, (1500, 700))?;
    let (left, right) = root.split_horizontally(700);
    let mm = |p: &Vector2<f64>| (p.x * 1e3, p.y * 1e3);
    let outline: Vec<(f64, f64)> = r.outline.polyline().iter().map(mm).collect();
    let raw: Vec<(f64, f64)> = r
        .samples
        .iter()
        .filter_map(|s| s.raw)
        .map(|p| (p[0] * 1e3, p[1] * 1e3))
        .collect();
    let comp: Vec<(f64, f64)> = r
        .samples
        .iter()
        .filter_map(|s| s.compensated)
        .map(|p| (p[0] * 1e3, p[1] * 1e3))
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in outline.iter().chain(&raw).chain(&comp) {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    // Equal scales on both axes.
    let half = 0.5 * (x1 - x0).max(y1 - y0) + 8.0;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let style = ChartStyle {
        caption: 22,
        label_areas: (40, 55),
        labels: 14,
    };
    let mut chart = new_chart(
        &left,
        style,
        &format!("{}: recovered contour", r.name),
        cx - half..cx + half,
        cy - half..cy + half,
        ("x [mm]", "y [mm]"),
    )?;
    let series = [
        (outline.clone(), BLACK, "true outline"),
        (raw.clone(), RED, "raw (motor readings)"),
        (comp.clone(), BLUE, "compensated (Eq. 10)"),
    ];
    for (pts, c, label) in series {
        labelled_line(&mut chart, pts, c, 2, label)?;
    }
    legend(&mut chart, 0.85, 14)?;

    let dist = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> {
        pts.iter()
            .enumerate()
            .map(|(i, (x, y))| {
                (
                    i as f64,
                    r.outline.signed_distance(&Vector2::new(x * 1e-3, y * 1e-3)) * 1e3,
                )
            })
            .collect()
    };
    let (draw, dcomp) = (dist(&raw), dist(&comp));
    let lim = draw
        .iter()
        .chain(&dcomp)
        .map(|p| p.1.abs())
        .fold(0.05, f64::max)
        * 1.1;
    let n = raw.len().max(2) as f64;
    let style = ChartStyle {
        caption: 20,
        label_areas: (40, 60),
        labels: 14,
    };
    let mut chart = new_chart(
        &right,
        style,
        &format!(
            "distance to the outline: raw RMS {:.3} mm, compensated RMS {:.4} mm",
            r.raw.rms_mm, r.compensated.rms_mm
        ),
        0.0..n,
        -lim..lim,
        ("contact sample", "signed distance (+ outside) [mm]"),
    )?;
    for (pts, c, label) in [(draw, RED, "raw"), (dcomp, BLUE, "compensated")] {
        labelled_line(&mut chart, pts, c, 2, label)?;
    }
    legend(&mut chart, 0.85, 14)?;
    present(&root, path)?;
    Ok(())
}

/// Writes `contour_summary.{txt,csv,json}`, `contour.mcap` and `contour_<shape>.png` into
/// `out`; returns the number of MCAP messages.
pub fn write_all(out: &Path, runs: &[ContourRun], table: &str) -> Result<usize, SimError> {
    write_summary(out, "contour_summary", table, &summary_csv(runs), runs)?;
    let n = write_mcap(&out.join("contour.mcap"), runs)?;
    for r in runs {
        plot_run(&out.join(format!("contour_{}.png", r.name)), r)?;
    }
    Ok(n)
}
