//! Outputs of the milling scenario: summary table (text, CSV, JSON), MCAP log and PNG plots.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;
use serde_json::json;

use super::{MillingResult, Sample};
use crate::SimError;
use crate::output::{
    CHART, McapLog, canvas, labelled_line, legend, new_chart, perr, present, stamp, stamp_schema,
    write_summary,
};

/// Topics written per run, as `/milling/<run>/<topic>`.
pub const TOPICS: [&str; 7] = [
    "nominal",
    "actual",
    "commanded",
    "force_measured",
    "force_filtered",
    "correction",
    "error",
];

/// The summary table printed on stdout and written to `milling_summary.txt`.
pub fn table(r: &MillingResult) -> String {
    let o = &r.options;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "milling: KR 300 R2500 flexible arm (rapier), groove along +x at {:.0} mm/s, {:.1} s cut, \
         force [{:.0}, {:.0}, {:.0}] N (|F| = {:.0} N), cycle {:.1} ms, correction delay {} cycles \
         + {:.0} ms servo lag",
        o.feed * 1e3,
        o.cut,
        o.force[0],
        o.force[1],
        o.force[2],
        nalgebra::Vector3::from(o.force).norm(),
        o.cycle * 1e3,
        o.delay_cycles,
        o.servo_tau * 1e3
    );
    let _ = writeln!(
        s,
        "pilot: estimate leads by {:.0} ms, {:+.0} % off; threshold {:.0} N, ramp {:.0} ms\n",
        o.estimate_lead * 1e3,
        o.estimate_error * 100.0,
        o.pilot.0,
        o.pilot.1 * 1e3
    );
    let _ = writeln!(
        s,
        "path error across the feed [mm] (window: entry .. 0.1 s after the force has fallen at exit)"
    );
    let _ = writeln!(
        s,
        "run            |   max |   RMS | steady max | entry max | exit max"
    );
    for run in &r.runs {
        let m = &run.metrics;
        let _ = writeln!(
            s,
            "{:<14} | {:5.3} | {:5.3} |      {:5.3} |     {:5.3} |    {:5.3}",
            run.mode.label(),
            m.max_mm,
            m.rms_mm,
            m.steady_max_mm,
            m.entry_max_mm,
            m.exit_max_mm
        );
    }
    let _ = writeln!(
        s,
        "\nstiffness identification ({} N and {} N m static loads in rapier, {} poses) \
         [kN m/rad]; n/a: not identifiable from these loads (the file's value is used)",
        o.id_load,
        0.25 * o.id_load,
        o.id_poses.clamp(1, 3)
    );
    let _ = writeln!(
        s,
        "spring axis  | true     | frames (+- se)        | err %   | TCP 6-D (+- se)        | err %"
    );
    let k = |v: f64| {
        if v.is_finite() {
            format!("{:8.1}", v * 1e-3)
        } else {
            "     n/a".to_string()
        }
    };
    let pct = |v: f64, t: f64| {
        if v.is_finite() {
            format!("{:+7.2}", (v / t - 1.0) * 100.0)
        } else {
            "    n/a".to_string()
        }
    };
    for e in &r.stiffness {
        let _ = writeln!(
            s,
            "{:<12} | {:8.1} | {} (+- {}) | {} | {} (+- {}) | {}",
            e.label,
            e.k_true * 1e-3,
            k(e.k_frames),
            k(e.se_frames),
            pct(e.k_frames, e.k_true),
            k(e.k_tcp),
            k(e.se_tcp),
            pct(e.k_tcp, e.k_true)
        );
    }
    let c = &r.sensor;
    let _ = writeln!(
        s,
        "\nsensor identification ({} orientations, unloaded; force RMS {:.3} N)",
        c.orientations, c.force_rms
    );
    let v = |a: &[f64; 3], k: f64| format!("[{:.3}, {:.3}, {:.3}]", a[0] * k, a[1] * k, a[2] * k);
    let _ = writeln!(
        s,
        "force offset [N]   true {}  identified {}",
        v(&c.force_offset.0, 1.0),
        v(&c.force_offset.1, 1.0)
    );
    let _ = writeln!(
        s,
        "moment offset [Nm] true {}  identified {}",
        v(&c.moment_offset.0, 1.0),
        v(&c.moment_offset.1, 1.0)
    );
    let _ = writeln!(
        s,
        "weight [N]         true {:.3}  identified {:.3}",
        c.weight.0, c.weight.1
    );
    let _ = writeln!(
        s,
        "CoG [mm]           true {}  identified {}",
        v(&c.center_of_gravity.0, 1e3),
        v(&c.center_of_gravity.1, 1e3)
    );
    let _ = writeln!(
        s,
        "\n{:.1} s simulated ({} steps of {} ms) in {:.2} s wall clock, identification included",
        r.sim_seconds,
        (r.sim_seconds / o.dt).round(),
        o.dt * 1e3,
        r.wall_seconds
    );
    s
}

/// CSV: one row per run (errors), then one row per joint (identification).
pub fn csv(r: &MillingResult) -> String {
    let mut s = String::from("run,max_mm,rms_mm,steady_max_mm,entry_max_mm,exit_max_mm\n");
    for run in &r.runs {
        let m = &run.metrics;
        let _ = writeln!(
            s,
            "{},{:.6},{:.6},{:.6},{:.6},{:.6}",
            run.mode.label(),
            m.max_mm,
            m.rms_mm,
            m.steady_max_mm,
            m.entry_max_mm,
            m.exit_max_mm
        );
    }
    s.push_str("\nspring,axis,label,k_true,k_frames,se_frames,k_tcp,se_tcp\n");
    for e in &r.stiffness {
        let _ = writeln!(
            s,
            "{},{},{},{:.3},{:.3},{:.3},{:.3},{:.3}",
            e.spring, e.axis, e.label, e.k_true, e.k_frames, e.se_frames, e.k_tcp, e.se_tcp
        );
    }
    s
}

/// JSON summary (without the per-cycle logs).
pub fn json(r: &MillingResult) -> serde_json::Value {
    json!({
        "options": r.options,
        "runs": r.runs.iter().map(|x| json!({"run": x.mode.label(), "metrics": x.metrics})).collect::<Vec<_>>(),
        "stiffness": r.stiffness,
        "sensor": r.sensor,
        "sim_seconds": r.sim_seconds,
        "wall_seconds": r.wall_seconds,
    })
}

fn schema(title: &str, fields: &[(&str, &str)]) -> serde_json::Value {
    let mut props = json!({
        "timestamp": stamp_schema(),
        "run": {"type": "string"},
    });
    for (f, unit) in fields {
        props[*f] = json!({"type": "number", "description": unit});
    }
    json!({"title": title, "type": "object", "properties": props})
}

const XYZ: [&str; 3] = ["x", "y", "z"];
const WRENCH: [&str; 6] = ["fx", "fy", "fz", "mx", "my", "mz"];
const TWIST: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

fn fields(topic: &str) -> Vec<(&'static str, &'static str)> {
    match topic {
        "nominal" | "actual" | "commanded" => XYZ.iter().map(|f| (*f, "m")).collect(),
        "force_measured" | "force_filtered" => WRENCH
            .iter()
            .enumerate()
            .map(|(i, f)| (*f, if i < 3 { "N" } else { "N m" }))
            .collect(),
        "correction" => TWIST
            .iter()
            .enumerate()
            .map(|(i, f)| (*f, if i < 3 { "m" } else { "rad" }))
            .collect(),
        _ => vec![
            ("error_mm", "mm"),
            ("pilot_weight", "1"),
            ("force_true_norm", "N"),
        ],
    }
}

fn message(topic: &str, run: &str, s: &Sample) -> serde_json::Value {
    let mut m = json!({"timestamp": stamp(s.t), "run": run});
    let put = |m: &mut serde_json::Value, names: &[&str], v: &[f64]| {
        for (n, x) in names.iter().zip(v) {
            m[*n] = json!(x);
        }
    };
    match topic {
        "nominal" => put(&mut m, &XYZ, &s.nominal),
        "actual" => put(&mut m, &XYZ, &s.actual),
        "commanded" => put(&mut m, &XYZ, &s.commanded),
        "force_measured" => put(&mut m, &WRENCH, &s.force_measured),
        "force_filtered" => put(&mut m, &WRENCH, &s.force_filtered),
        "correction" => put(&mut m, &TWIST, &s.correction),
        _ => {
            let f = nalgebra::Vector3::from(s.force_true).norm();
            put(
                &mut m,
                &["error_mm", "pilot_weight", "force_true_norm"],
                &[s.error_mm, s.pilot_weight, f],
            );
        }
    }
    m
}

/// Writes the runs to `path`, topics `/milling/<run>/<topic>`; all runs share the
/// scenario's time axis. Returns the number of messages.
pub fn write_mcap(path: &Path, r: &MillingResult) -> Result<usize, SimError> {
    let mut log = McapLog::create(path)?;
    let mut schema_ids = Vec::new();
    for topic in TOPICS {
        let s = schema(&format!("milling {topic}"), &fields(topic));
        schema_ids.push(log.add_schema(&format!("deflect.milling.{topic}"), &s)?);
    }
    for run in &r.runs {
        let name = run.mode.label();
        let mut channels = Vec::new();
        for (topic, schema) in TOPICS.iter().zip(&schema_ids) {
            channels.push(log.add_channel(
                *schema,
                &format!("/milling/{name}/{topic}"),
                "run",
                name,
            )?);
        }
        for (seq, s) in (0u32..).zip(&run.samples) {
            for (topic, ch) in TOPICS.iter().zip(&channels) {
                log.write(*ch, seq, s.t, &message(topic, name, s))?;
            }
        }
    }
    log.finish()
}

/// Path error against time for the runs, with the cutter entry and exit marked.
pub fn plot_error(path: &Path, r: &MillingResult) -> Result<(), SimError> {
    let root = canvas(path, (1100, 620))?;
    let t_end = r.options.t_end();
    let ymax = r
        .runs
        .iter()
        .flat_map(|x| x.samples.iter().map(|s| s.error_mm))
        .fold(0.1, f64::max)
        * 1.1;
    let mut chart = new_chart(
        &root,
        CHART,
        "milling: tool-point deviation across the feed",
        0.0..t_end,
        0.0..ymax,
        ("time [s]", "path error [mm]"),
    )?;
    for t in [r.options.t_entry(), r.options.t_exit()] {
        chart
            .draw_series(LineSeries::new(
                vec![(t, 0.0), (t, ymax)],
                BLACK.mix(0.4).stroke_width(1),
            ))
            .map_err(perr)?;
    }
    let colors = [RED, BLUE, GREEN, MAGENTA];
    for (run, c) in r.runs.iter().zip(colors) {
        let m = &run.metrics;
        let label = format!(
            "{}: max {:.2} mm, RMS {:.2} mm",
            run.mode.label(),
            m.max_mm,
            m.rms_mm
        );
        labelled_line(
            &mut chart,
            run.samples.iter().map(|s| (s.t, s.error_mm)),
            c,
            2,
            label,
        )?;
    }
    legend(&mut chart, 0.8, 15)?;
    present(&root, path)?;
    Ok(())
}

/// Identified over true stiffness per virtual-joint axis (frame pairs and TCP, with +- 2 se
/// bars); axes not identifiable are left out.
pub fn plot_stiffness(path: &Path, r: &MillingResult) -> Result<(), SimError> {
    let root = canvas(path, (1100, 560))?;
    let ratio = |k: f64, t: f64| k / t;
    let spread = r
        .stiffness
        .iter()
        .flat_map(|e| [ratio(e.k_frames, e.k_true), ratio(e.k_tcp, e.k_true)])
        .filter(|v| v.is_finite())
        .fold(0.02f64, |m, v| m.max((v - 1.0).abs()))
        .min(1.0)
        * 1.3;
    let n = r.stiffness.len().max(1) as f64;
    let mut chart = new_chart(
        &root,
        CHART,
        "virtual-joint stiffness: identified / true",
        -0.5f64..(n - 0.5),
        (1.0 - spread)..(1.0 + spread),
        (
            "spring axis (chain order, see milling_summary.txt)",
            "identified / true",
        ),
    )?;
    chart
        .draw_series(LineSeries::new(
            vec![(-0.5, 1.0), (n - 0.5, 1.0)],
            BLACK.mix(0.5).stroke_width(1),
        ))
        .map_err(perr)?;
    for (dx, c, label, tcp) in [
        (-0.12, BLUE, "frame pairs", false),
        (0.12, RED, "TCP deflection (6-D)", true),
    ] {
        let pts: Vec<(f64, f64, f64)> = r
            .stiffness
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let (k, se) = if tcp {
                    (e.k_tcp, e.se_tcp)
                } else {
                    (e.k_frames, e.se_frames)
                };
                (i as f64 + dx, k / e.k_true, se / e.k_true)
            })
            .filter(|p| p.1.is_finite() && (p.1 - 1.0).abs() <= spread)
            .collect();
        chart
            .draw_series(pts.iter().map(|p| Circle::new((p.0, p.1), 4, c.filled())))
            .map_err(perr)?
            .label(label)
            .legend(move |(x, y)| Circle::new((x + 10, y), 4, c.filled()));
        chart
            .draw_series(pts.iter().filter(|p| p.2.is_finite()).map(|p| {
                PathElement::new(
                    vec![(p.0, p.1 - 2.0 * p.2), (p.0, p.1 + 2.0 * p.2)],
                    c.stroke_width(2),
                )
            }))
            .map_err(perr)?;
    }
    legend(&mut chart, 0.8, 15)?;
    present(&root, path)?;
    Ok(())
}

/// Writes `milling_summary.{txt,csv,json}`, `milling.mcap`, `milling_error.png` and
/// `milling_stiffness.png` into `out`.
pub fn write_all(out: &Path, r: &MillingResult) -> Result<(), SimError> {
    std::fs::create_dir_all(out)
        .map_err(|e| SimError::file(out, "create the output directory", e))?;
    write_summary(out, "milling_summary", &table(r), &csv(r), &json(r))?;
    write_mcap(&out.join("milling.mcap"), r)?;
    plot_error(&out.join("milling_error.png"), r)?;
    plot_stiffness(&out.join("milling_stiffness.png"), r)?;
    Ok(())
}
