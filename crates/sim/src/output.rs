//! Outputs: summary table (text, CSV, JSON), MCAP log (JSON messages with JSON schemas, for
//! Foxglove and the Python `mcap` reader) and PNG plots.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use mcap::records::MessageHeader;
use plotters::prelude::*;
use serde_json::json;

use crate::SimError;
use crate::pipeline::{Motion, RunResult, Sample};

/// Topics written for each run (prefixed by the run's name in multi-run logs).
pub const TOPICS: [&str; 5] = [
    "desired",
    "commanded",
    "actual",
    "dalembert_force",
    "joints",
];

fn point_schema(title: &str, unit: &str, z: bool) -> serde_json::Value {
    let mut props = json!({
        "timestamp": {"type": "object", "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}}},
        "run": {"type": "string"},
        "x": {"type": "number", "description": unit},
        "y": {"type": "number", "description": unit},
    });
    if z {
        props["z"] = json!({"type": "number", "description": unit});
    }
    json!({"title": title, "type": "object", "properties": props})
}

fn schemas() -> [(String, serde_json::Value); 5] {
    [
        (
            "deflect.DesiredPoint".into(),
            point_schema("desired tool point", "m", false),
        ),
        (
            "deflect.CommandedPoint".into(),
            point_schema("commanded tool point", "m", false),
        ),
        (
            "deflect.ActualPoint".into(),
            point_schema("actual tool point", "m", true),
        ),
        (
            "deflect.DalembertForce".into(),
            point_schema("D'Alembert force -m* a", "N", false),
        ),
        (
            "deflect.Joints".into(),
            json!({"title": "joint angles", "type": "object", "properties": {
                "timestamp": {"type": "object", "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}}},
                "run": {"type": "string"},
                "command": {"type": "array", "items": {"type": "number"}, "description": "rad"},
                "motor": {"type": "array", "items": {"type": "number"}, "description": "rad"},
                "link": {"type": "array", "items": {"type": "number"}, "description": "rad"}
            }}),
        ),
    ]
}

fn stamp(t: f64) -> serde_json::Value {
    let ns = (t * 1e9).round() as u64;
    json!({"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000})
}

fn messages(run: &str, s: &Sample, t: f64) -> [serde_json::Value; 5] {
    let ts = stamp(t);
    [
        json!({"timestamp": ts, "run": run, "x": s.desired[0], "y": s.desired[1]}),
        json!({"timestamp": ts, "run": run, "x": s.commanded[0], "y": s.commanded[1]}),
        json!({"timestamp": ts, "run": run, "x": s.actual[0], "y": s.actual[1], "z": s.actual[2]}),
        json!({"timestamp": ts, "run": run, "x": s.force[0], "y": s.force[1]}),
        json!({"timestamp": ts, "run": run, "command": s.q_cmd, "motor": s.q_motor, "link": s.q_link}),
    ]
}

/// A run's name for topics and files: "oc_gu_y-line_5g_corr".
pub fn run_name(r: &RunResult) -> String {
    format!(
        "{}_{}_{}g_{}",
        r.config.replace(' ', "_").to_lowercase(),
        r.motion.label(),
        r.g,
        if r.corrected { "corr" } else { "plain" }
    )
}

/// Writes `runs` into one MCAP file (zstd chunks). With `prefix_topics`, each run gets its own
/// topics `/<run>/<topic>`; otherwise the topics are `/<topic>` (single-run logs). Runs follow
/// each other in log time.
pub fn write_mcap(
    path: &Path,
    runs: &[&RunResult],
    prefix_topics: bool,
) -> Result<usize, SimError> {
    let mut w = mcap::Writer::new(BufWriter::new(File::create(path)?))?;
    let mut schema_ids = Vec::new();
    for (name, s) in schemas() {
        schema_ids.push(w.add_schema(
            &name,
            "jsonschema",
            serde_json::to_string(&s)?.as_bytes(),
        )?);
    }
    let mut offset = 0.0;
    let mut count = 0;
    for r in runs {
        let name = run_name(r);
        let mut channels = Vec::new();
        for (topic, schema) in TOPICS.iter().zip(&schema_ids) {
            let full = if prefix_topics {
                format!("/{name}/{topic}")
            } else {
                format!("/{topic}")
            };
            let mut meta = BTreeMap::new();
            meta.insert("run".to_string(), name.clone());
            channels.push(w.add_channel(*schema, &full, "json", &meta)?);
        }
        let mut last = 0.0;
        for (seq, s) in (0u32..).zip(&r.samples) {
            let t = offset + s.t;
            let ns = (t * 1e9).round() as u64;
            for (ch, msg) in channels.iter().zip(messages(&name, s, t)) {
                let header = MessageHeader {
                    channel_id: *ch,
                    sequence: seq,
                    log_time: ns,
                    publish_time: ns,
                };
                w.write_to_known_channel(&header, serde_json::to_string(&msg)?.as_bytes())?;
                count += 1;
            }
            last = s.t;
        }
        offset += last + 0.1;
    }
    w.finish()?;
    Ok(count)
}

/// CSV of all runs' metrics.
pub fn summary_csv(runs: &[RunResult]) -> String {
    let mut s = String::from(
        "config,motion,g,corrected,mass_kg,length_dev_mm,area_mm2,max_dev_mm,rms_dev_mm,max_track_mm,rms_track_mm\n",
    );
    for r in runs {
        let m = &r.metrics;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
            r.config,
            r.motion.label(),
            r.g,
            r.corrected,
            r.mass,
            m.length_dev_mm,
            m.area_mm2,
            m.max_dev_mm,
            m.rms_dev_mm,
            m.max_track_mm,
            m.rms_track_mm
        );
    }
    s
}

const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the embedded font for plotters (once).
pub(crate) fn register_font() {
    use std::sync::Once;
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// A plotting error as a [`SimError`].
pub(crate) fn perr<E: std::fmt::Display>(e: E) -> SimError {
    SimError::new(format!("plot: {e}"))
}

/// Path plot of runs of one motion: deviation across the path (mm, magnified) against the
/// position along it, one curve per run.
pub fn plot_paths(path: &Path, title: &str, runs: &[&RunResult]) -> Result<(), SimError> {
    register_font();
    let root = BitMapBackend::new(path, (1000, 620)).into_drawing_area();
    root.fill(&WHITE).map_err(perr)?;
    let Some(first) = runs.first() else {
        return Ok(());
    };
    let pts = first.motion.points();
    let (a, b) = (pts[0], pts[1]);
    let dir = (b - a).normalize();
    let along_across = |s: &Sample| {
        let r = nalgebra::Vector2::new(s.actual[0], s.actual[1]) - a;
        (r.dot(&dir) * 1e3, (-r.x * dir.y + r.y * dir.x) * 1e3)
    };
    let seg0 = |s: &&Sample| s.segment == 0;
    let mut vmax: f64 = 0.05;
    let mut umin: f64 = 0.0;
    let mut umax: f64 = (b - a).norm() * 1e3;
    for r in runs {
        for s in r.samples.iter().filter(seg0) {
            let (u, v) = along_across(s);
            vmax = vmax.max(v.abs());
            umin = umin.min(u);
            umax = umax.max(u);
        }
    }
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(umin - 2.0..umax + 2.0, -vmax * 1.1..vmax * 1.1)
        .map_err(perr)?;
    chart
        .configure_mesh()
        .x_desc("along the first segment [mm]")
        .y_desc("across [mm]")
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(perr)?;
    let colors = [RED, BLUE, GREEN, MAGENTA, CYAN, BLACK];
    let mut configs: Vec<&str> = Vec::new();
    for r in runs {
        if !configs.contains(&r.config.as_str()) {
            configs.push(&r.config);
        }
    }
    for r in runs {
        let k = configs.iter().position(|c| *c == r.config).unwrap_or(0);
        let c = colors[k % colors.len()];
        let width = if r.corrected { 3 } else { 1 };
        let series: Vec<(f64, f64)> = r.samples.iter().filter(seg0).map(along_across).collect();
        let label = format!(
            "{} {}g {}",
            r.config,
            r.g,
            if r.corrected {
                "corrected"
            } else {
                "uncorrected"
            }
        );
        chart
            .draw_series(LineSeries::new(series, c.stroke_width(width)))
            .map_err(perr)?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(width))
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()
        .map_err(perr)?;
    root.present().map_err(perr)?;
    Ok(())
}

/// Max path deviation (or tracking error for the x-line) against acceleration, per
/// configuration, uncorrected (dashed-looking thin) and corrected (thick).
pub fn plot_error_vs_g(path: &Path, motion: Motion, runs: &[RunResult]) -> Result<(), SimError> {
    register_font();
    let root = BitMapBackend::new(path, (1000, 620)).into_drawing_area();
    root.fill(&WHITE).map_err(perr)?;
    let sel: Vec<&RunResult> = runs.iter().filter(|r| r.motion == motion).collect();
    let metric = |r: &RunResult| r.metrics.max_dev_mm;
    let ymax = sel.iter().map(|r| metric(r)).fold(0.01, f64::max) * 1.1;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{}: max path deviation vs acceleration", motion.label()),
            ("sans-serif", 22),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(0.8f64..5.2f64, 0.0..ymax)
        .map_err(perr)?;
    chart
        .configure_mesh()
        .x_desc("peak acceleration [g]")
        .y_desc("max deviation [mm]")
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(perr)?;
    let mut configs: Vec<String> = sel.iter().map(|r| r.config.clone()).collect();
    configs.dedup();
    configs.sort();
    configs.dedup();
    let colors = [RED, BLUE, GREEN, MAGENTA];
    for (k, cfg) in configs.iter().enumerate() {
        let c = colors[k % colors.len()];
        for corrected in [false, true] {
            let mut pts: Vec<(f64, f64)> = sel
                .iter()
                .filter(|r| &r.config == cfg && r.corrected == corrected)
                .map(|r| (f64::from(r.g), metric(r)))
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let width = if corrected { 3 } else { 1 };
            let label = format!(
                "{cfg} {}",
                if corrected {
                    "corrected"
                } else {
                    "uncorrected"
                }
            );
            chart
                .draw_series(LineSeries::new(pts.clone(), c.stroke_width(width)))
                .map_err(perr)?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(width))
                });
            chart
                .draw_series(pts.iter().map(|p| Circle::new(*p, 4, c.filled())))
                .map_err(perr)?;
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(perr)?;
    root.present().map_err(perr)?;
    Ok(())
}
