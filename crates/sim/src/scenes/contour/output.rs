//! Outputs of the `contour` scenario: summary table (text, CSV, JSON), an MCAP log and one PNG
//! per object (true outline vs raw and compensated recovered contours, and the distance of
//! each recorded point to the outline).

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Vector2;
use plotters::prelude::*;

use super::{ContourRun, Sample, TraceOptions};
use crate::SimError;
use crate::mcap_log::{self, IDENTITY, Kind, Line, McapLog, RunInfo, scene_update};
use crate::plot_style::{
    Area, ChartStyle, Entry, Role, Swatch, canvas, color, draw_legend, figure, line, new_chart,
    present,
};
use crate::summary::{reduction, write_summary};

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

/// Topics per shape, as `/contour/<shape>/<topic>`, and their message types; the recorded
/// points only at contact samples.
pub const TOPICS: [(&str, Kind); 11] = [
    ("command", Kind::Point),
    ("tool_actual", Kind::Point),
    ("recorded_raw", Kind::Point),
    ("recorded_compensated", Kind::Point),
    ("force", Kind::Force),
    ("force_sensed", Kind::Force),
    ("force_true", Kind::Force),
    ("joints", Kind::JointState),
    ("state", Kind::TracerState),
    ("tcp_pose", Kind::PosesInFrame),
    ("paths", Kind::SceneUpdate),
];

/// Planar point or force with z = 0.
fn p3(p: &[f64; 2]) -> [f64; 3] {
    [p[0], p[1], 0.0]
}

fn messages(shape: &str, s: &Sample, t: f64) -> [Option<serde_json::Value>; 10] {
    [
        Some(mcap_log::point(shape, t, p3(&s.command))),
        Some(mcap_log::point(shape, t, p3(&s.tool_actual))),
        s.raw.as_ref().map(|p| mcap_log::point(shape, t, p3(p))),
        s.compensated
            .as_ref()
            .map(|p| mcap_log::point(shape, t, p3(p))),
        Some(mcap_log::force(shape, t, p3(&s.force))),
        Some(mcap_log::force(shape, t, p3(&s.force_sensed))),
        Some(mcap_log::force(shape, t, p3(&s.force_true))),
        // The motors are ideal position servos: the reading is the command.
        Some(mcap_log::joints(
            shape, t, &s.q_motor, &s.q_motor, &s.q_link,
        )),
        Some(mcap_log::tracer_state(shape, t, s.state)),
        Some(mcap_log::poses_in_frame(t, p3(&s.tool_actual), IDENTITY)),
    ]
}

fn run_info(r: &ContourRun, o: &TraceOptions) -> RunInfo {
    RunInfo {
        scenario: "contour".into(),
        run: r.name.clone(),
        robot: format!(
            "planar 2R arm in rapier (links {} / {} m), compliant backlashed joints, penalty \
             contact at the tool point",
            o.arm.lengths[0], o.arm.lengths[1]
        ),
        motion: format!(
            "counter-clockwise force-feedback contour tracing of the {} (perimeter {:.1} mm), \
             step {:.2} mm, target force {:.1} N",
            r.name,
            r.perimeter * 1e3,
            o.step * 1e3,
            o.target_force
        ),
        acceleration: format!(
            "quasi-static: position steps ramped over {:.0} ms, then {:.0} ms settling",
            o.ramp * 1e3,
            o.settle * 1e3
        ),
        correction: "none on the arm; the shape is recovered raw (FK of the motor readings) \
                     and compensated (Eq. 10), both logged"
            .into(),
        options: serde_json::to_value(o).unwrap_or_default(),
    }
}

/// Writes every run into one MCAP file by the convention of [`crate::mcap_log`]: topics
/// `/contour/<shape>/<topic>` ([`TOPICS`]), each shape's log time from its first reading
/// (t = 0), a `deflect.run` metadata record per shape. Returns the number of messages.
pub fn write_mcap(path: &Path, runs: &[ContourRun], o: &TraceOptions) -> Result<usize, SimError> {
    let mut log = McapLog::create(path)?;
    for r in runs {
        let info = run_info(r, o);
        log.run_metadata(&info)?;
        let prefix = info.prefix();
        let mut channels = Vec::new();
        for (topic, kind) in TOPICS {
            channels.push(log.channel(&prefix, topic, kind)?);
        }
        let name = r.name.as_str();
        let outline = r.outline.polyline();
        let lines = [
            Line {
                id: format!("{name}/outline"),
                points: outline.iter().map(|p| [p.x, p.y, 0.0]).collect(),
                rgb: color(Role::Desired).rgb(),
                closed: true,
            },
            Line {
                id: format!("{name}/tool_actual"),
                points: r.samples.iter().map(|s| p3(&s.tool_actual)).collect(),
                rgb: color(Role::Guide).rgb(),
                closed: false,
            },
            Line {
                id: format!("{name}/recorded_raw"),
                points: r
                    .samples
                    .iter()
                    .filter_map(|s| s.raw.as_ref())
                    .map(p3)
                    .collect(),
                rgb: color(Role::Uncorrected).rgb(),
                closed: false,
            },
            Line {
                id: format!("{name}/recorded_compensated"),
                points: r
                    .samples
                    .iter()
                    .filter_map(|s| s.compensated.as_ref())
                    .map(p3)
                    .collect(),
                rgb: color(Role::Corrected).rgb(),
                closed: false,
            },
        ];
        if let Some(ch) = channels.last() {
            log.write(*ch, 0.0, &scene_update(0.0, &lines))?;
        }
        let t0 = r.samples.first().map_or(0.0, |s| s.t);
        for s in &r.samples {
            let t = s.t - t0;
            for (ch, msg) in channels.iter().zip(messages(name, s, t)) {
                let Some(msg) = msg else { continue };
                log.write(*ch, t, &msg)?;
            }
        }
    }
    log.finish()
}

/// An object's name in words: "l_shape" -> "L-shaped object", "circle" -> "circle".
fn shape_words(name: &str) -> String {
    match name {
        "l_shape" => "L-shaped object".to_string(),
        other => other.replace('_', " "),
    }
}

/// One PNG per run: left the true outline, the raw and compensated recovered contours in mm
/// (equal scales), right the signed distance of each recorded point to the outline; the
/// legend in a column on the right.
pub fn plot_run(path: &Path, r: &ContourRun) -> Result<(), SimError> {
    let root = canvas(path, (1500, 700))?;
    let mm = |p: &Vector2<f64>| (p.x * 1e3, p.y * 1e3);
    let outline: Vec<(f64, f64)> = r.outline.polyline().iter().map(mm).collect();
    let recorded = |f: fn(&Sample) -> Option<[f64; 2]>| -> Vec<(f64, f64)> {
        r.samples
            .iter()
            .filter_map(f)
            .map(|p| (p[0] * 1e3, p[1] * 1e3))
            .collect()
    };
    let raw = recorded(|s| s.raw);
    let comp = recorded(|s| s.compensated);
    let entries = [
        Entry::new("true outline", Role::Desired, Swatch::Line(2)),
        Entry::new(
            format!("raw (FK of the motor readings): RMS {:.3} mm", r.raw.rms_mm),
            Role::Uncorrected,
            Swatch::Line(2),
        ),
        Entry::new(
            format!("compensated (Eq. 10): RMS {:.4} mm", r.compensated.rms_mm),
            Role::Corrected,
            Swatch::Line(2),
        ),
    ];
    let title = format!(
        "2R arm with compliant, backlashed joints tracing the {} by force feedback: recovered \
         contour, raw and compensated",
        shape_words(&r.name)
    );
    let (plot, legend) = figure(&root, &title, 20, &entries)?;
    let (pw, _) = plot.dim_in_pixel();
    let (left, right) = plot.split_horizontally(pw * 45 / 100);
    plot_contour(left, outline, &raw, &comp)?;
    plot_distances(right, r, &raw, &comp)?;
    draw_legend(&legend, &entries)?;
    present(&root, path)?;
    Ok(())
}

/// The left panel: the true outline and the raw and compensated contours \[mm\], equal scales.
fn plot_contour(
    left: Area<'_>,
    outline: Vec<(f64, f64)>,
    raw: &[(f64, f64)],
    comp: &[(f64, f64)],
) -> Result<(), SimError> {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in outline.iter().chain(raw).chain(comp) {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    // Equal scales on both axes.
    let half = 0.5 * (x1 - x0).max(y1 - y0) + 8.0;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let style = ChartStyle {
        caption: 16,
        label_areas: (40, 55),
        labels: 14,
    };
    let left = left
        .titled("contour in the plane", ("sans-serif", style.caption))
        .map_err(crate::plot_style::perr)?;
    // Equal scales: the ranges in the proportions of the plotting area (the panel less its
    // label areas and 12 px margins).
    let (lw, lh) = left.dim_in_pixel();
    let aw = f64::from(lw.saturating_sub(style.label_areas.1 + 24).max(1));
    let ah = f64::from(lh.saturating_sub(style.label_areas.0 + 24).max(1));
    let (hx, hy) = if aw > ah {
        (half * aw / ah, half)
    } else {
        (half, half * ah / aw)
    };
    let mut chart = new_chart(
        &left,
        style,
        cx - hx..cx + hx,
        cy - hy..cy + hy,
        ("x [mm]", "y [mm]"),
    )?;
    for (pts, role) in [
        (outline, Role::Desired),
        (raw.to_vec(), Role::Uncorrected),
        (comp.to_vec(), Role::Corrected),
    ] {
        line(&mut chart, pts, color(role), 2, false)?;
    }
    Ok(())
}

/// The right panel: the signed distance \[mm\] of each recorded point (raw, compensated) to
/// the outline.
fn plot_distances(
    right: Area<'_>,
    r: &ContourRun,
    raw: &[(f64, f64)],
    comp: &[(f64, f64)],
) -> Result<(), SimError> {
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
    let (draw, dcomp) = (dist(raw), dist(comp));
    let lim = draw
        .iter()
        .chain(&dcomp)
        .map(|p| p.1.abs())
        .fold(0.05, f64::max)
        * 1.06;
    let n = raw.len().max(2) as f64;
    let style = ChartStyle {
        caption: 16,
        label_areas: (40, 60),
        labels: 14,
    };
    let right = right
        .titled(
            "distance of each recorded point to the outline",
            ("sans-serif", style.caption),
        )
        .map_err(crate::plot_style::perr)?;
    let mut chart = new_chart(
        &right,
        style,
        0.0..n,
        -lim..lim,
        ("contact sample [count]", "signed distance, + outside [mm]"),
    )?;
    for (pts, role) in [(draw, Role::Uncorrected), (dcomp, Role::Corrected)] {
        line(&mut chart, pts, color(role), 2, false)?;
    }
    Ok(())
}

/// Writes `contour_summary.{txt,csv,json}`, `contour.mcap` and `contour_<shape>.png` into
/// `out`; returns the number of MCAP messages.
pub fn write_all(
    out: &Path,
    runs: &[ContourRun],
    table: &str,
    opts: &TraceOptions,
) -> Result<usize, SimError> {
    write_summary(out, "contour_summary", table, &summary_csv(runs), runs)?;
    let n = write_mcap(&out.join("contour.mcap"), runs, opts)?;
    for r in runs {
        plot_run(&out.join(format!("contour_{}.png", r.name)), r)?;
    }
    Ok(n)
}
