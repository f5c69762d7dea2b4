//! Outputs: summary table (text, CSV, JSON), MCAP log (JSON messages with JSON schemas, for
//! Foxglove and the Python `mcap` reader) and PNG plots.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs::File;
use std::io::BufWriter;
use std::ops::Range;
use std::path::{Path, PathBuf};

use mcap::records::MessageHeader;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use serde_json::json;

use crate::pipeline::{Motion, RunResult, Sample};
use crate::{SimError, write_file};

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
        "timestamp": stamp_schema(),
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
                "timestamp": stamp_schema(),
                "run": {"type": "string"},
                "command": {"type": "array", "items": {"type": "number"}, "description": "rad"},
                "motor": {"type": "array", "items": {"type": "number"}, "description": "rad"},
                "link": {"type": "array", "items": {"type": "number"}, "description": "rad"}
            }}),
        ),
    ]
}

/// Log time `t` \[s\] in nanoseconds.
fn nanos(t: f64) -> u64 {
    (t * 1e9).round() as u64
}

/// A message timestamp `{"sec", "nsec"}` for time `t` \[s\].
pub(crate) fn stamp(t: f64) -> serde_json::Value {
    let ns = nanos(t);
    json!({"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000})
}

/// The JSON schema of a [`stamp`].
pub(crate) fn stamp_schema() -> serde_json::Value {
    json!({"type": "object", "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}}})
}

/// An MCAP file of JSON messages with JSON schemas (zstd chunks), shared by the scenarios.
pub(crate) struct McapLog {
    w: mcap::Writer<BufWriter<File>>,
    count: usize,
    path: PathBuf,
}

impl McapLog {
    /// Creates the file at `path`.
    pub(crate) fn create(path: &Path) -> Result<Self, SimError> {
        let err = |e: &dyn std::fmt::Display| SimError::file(path, "create the MCAP log", e);
        let file = File::create(path).map_err(|e| err(&e))?;
        Ok(Self {
            w: mcap::Writer::new(BufWriter::new(file)).map_err(|e| err(&e))?,
            count: 0,
            path: path.to_path_buf(),
        })
    }

    /// An MCAP error naming the file.
    fn err(&self, e: mcap::McapError) -> SimError {
        SimError::file(&self.path, "write the MCAP log", e)
    }

    /// Adds a JSON schema named `name`; returns its id.
    pub(crate) fn add_schema(
        &mut self,
        name: &str,
        schema: &serde_json::Value,
    ) -> Result<u16, SimError> {
        self.w
            .add_schema(
                name,
                "jsonschema",
                serde_json::to_string(schema)?.as_bytes(),
            )
            .map_err(|e| self.err(e))
    }

    /// Adds a JSON channel on `topic` with one metadata entry `key: value`; returns its id.
    pub(crate) fn add_channel(
        &mut self,
        schema: u16,
        topic: &str,
        key: &str,
        value: &str,
    ) -> Result<u16, SimError> {
        let mut meta = BTreeMap::new();
        meta.insert(key.to_string(), value.to_string());
        self.w
            .add_channel(schema, topic, "json", &meta)
            .map_err(|e| self.err(e))
    }

    /// Writes `msg` on `channel` with sequence number `seq`, logged and published at `t` \[s\].
    pub(crate) fn write(
        &mut self,
        channel: u16,
        seq: u32,
        t: f64,
        msg: &serde_json::Value,
    ) -> Result<(), SimError> {
        let ns = nanos(t);
        let header = MessageHeader {
            channel_id: channel,
            sequence: seq,
            log_time: ns,
            publish_time: ns,
        };
        let data = serde_json::to_string(msg)?;
        if let Err(e) = self.w.write_to_known_channel(&header, data.as_bytes()) {
            return Err(self.err(e));
        }
        self.count += 1;
        Ok(())
    }

    /// Finishes the file; returns the number of messages written.
    pub(crate) fn finish(mut self) -> Result<usize, SimError> {
        if let Err(e) = self.w.finish() {
            return Err(self.err(e));
        }
        Ok(self.count)
    }
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
    let mut log = McapLog::create(path)?;
    let mut schema_ids = Vec::new();
    for (name, s) in schemas() {
        schema_ids.push(log.add_schema(&name, &s)?);
    }
    let mut offset = 0.0;
    for r in runs {
        let name = run_name(r);
        let mut channels = Vec::new();
        for (topic, schema) in TOPICS.iter().zip(&schema_ids) {
            let full = if prefix_topics {
                format!("/{name}/{topic}")
            } else {
                format!("/{topic}")
            };
            channels.push(log.add_channel(*schema, &full, "run", &name)?);
        }
        let mut last = 0.0;
        for (seq, s) in (0u32..).zip(&r.samples) {
            let t = offset + s.t;
            for (ch, msg) in channels.iter().zip(messages(&name, s, t)) {
                log.write(*ch, seq, t, &msg)?;
            }
            last = s.t;
        }
        offset += last + 0.1;
    }
    log.finish()
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

/// A PNG canvas of `size` pixels at `path`, filled white (font registered).
pub(crate) fn canvas(
    path: &Path,
    size: (u32, u32),
) -> Result<DrawingArea<BitMapBackend<'_>, Shift>, SimError> {
    register_font();
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(perr)?;
    Ok(root)
}

/// Writes the PNG of `root` to `path` (the file it was created on); the error names the file.
pub(crate) fn present(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    path: &Path,
) -> Result<(), SimError> {
    root.present()
        .map_err(|e| SimError::file(path, "write the PNG plot", e))
}

/// A 2-D chart of `f64` axes as the scenarios draw them.
pub(crate) type Chart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Font sizes and label areas of a chart.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ChartStyle {
    /// Caption font size.
    pub caption: u32,
    /// X and y label area sizes.
    pub label_areas: (u32, u32),
    /// Axis label font size.
    pub labels: u32,
}

/// The usual style: caption 22, label areas 45 x 70, labels 15.
pub(crate) const CHART: ChartStyle = ChartStyle {
    caption: 22,
    label_areas: (45, 70),
    labels: 15,
};

/// A chart on `area` with a caption, axis ranges `x`, `y` and axis descriptions `desc`
/// (mesh drawn).
pub(crate) fn new_chart<'a, 'b>(
    area: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    style: ChartStyle,
    caption: &str,
    x: Range<f64>,
    y: Range<f64>,
    desc: (&str, &str),
) -> Result<Chart<'a, 'b>, SimError> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", style.caption))
        .margin(12)
        .x_label_area_size(style.label_areas.0)
        .y_label_area_size(style.label_areas.1)
        .build_cartesian_2d(x, y)
        .map_err(perr)?;
    chart
        .configure_mesh()
        .x_desc(desc.0)
        .y_desc(desc.1)
        .label_style(("sans-serif", style.labels))
        .draw()
        .map_err(perr)?;
    Ok(chart)
}

/// Draws a line of `width` in color `c` with a legend entry `label`.
pub(crate) fn labelled_line(
    chart: &mut Chart<'_, '_>,
    pts: impl IntoIterator<Item = (f64, f64)>,
    c: RGBColor,
    width: u32,
    label: impl Into<String>,
) -> Result<(), SimError> {
    chart
        .draw_series(LineSeries::new(pts, c.stroke_width(width)))
        .map_err(perr)?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(width)));
    Ok(())
}

/// Draws the legend box (upper right, white at `opacity`, font size `font`).
pub(crate) fn legend<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    opacity: f64,
    font: u32,
) -> Result<(), SimError> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(opacity))
        .border_style(BLACK)
        .label_font(("sans-serif", font))
        .draw()
        .map_err(perr)
}

/// Writes `<stem>.txt`, `<stem>.csv` and `<stem>.json` (pretty JSON of `json`) into `out`.
pub fn write_summary<T: serde::Serialize + ?Sized>(
    out: &Path,
    stem: &str,
    txt: &str,
    csv: &str,
    json: &T,
) -> Result<(), SimError> {
    write_file(&out.join(format!("{stem}.txt")), "the summary table", txt)?;
    write_file(&out.join(format!("{stem}.csv")), "the summary CSV", csv)?;
    write_file(
        &out.join(format!("{stem}.json")),
        "the summary JSON",
        serde_json::to_string_pretty(json)?,
    )?;
    Ok(())
}

/// Path plot of runs of one motion: deviation across the path (mm, magnified) against the
/// position along it, one curve per run.
pub fn plot_paths(path: &Path, title: &str, runs: &[&RunResult]) -> Result<(), SimError> {
    let root = canvas(path, (1000, 620))?;
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
    let mut chart = new_chart(
        &root,
        CHART,
        title,
        umin - 2.0..umax + 2.0,
        -vmax * 1.1..vmax * 1.1,
        ("along the first segment [mm]", "across [mm]"),
    )?;
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
        labelled_line(&mut chart, series, c, width, label)?;
    }
    legend(&mut chart, 0.8, 15)?;
    present(&root, path)?;
    Ok(())
}

/// Max path deviation (or tracking error for the x-line) against acceleration, per
/// configuration, uncorrected (dashed-looking thin) and corrected (thick).
pub fn plot_error_vs_g(path: &Path, motion: Motion, runs: &[RunResult]) -> Result<(), SimError> {
    let root = canvas(path, (1000, 620))?;
    let sel: Vec<&RunResult> = runs.iter().filter(|r| r.motion == motion).collect();
    let metric = |r: &RunResult| r.metrics.max_dev_mm;
    let ymax = sel.iter().map(|r| metric(r)).fold(0.01, f64::max) * 1.1;
    let mut chart = new_chart(
        &root,
        CHART,
        &format!("{}: max path deviation vs acceleration", motion.label()),
        0.8f64..5.2f64,
        0.0..ymax,
        ("peak acceleration [g]", "max deviation [mm]"),
    )?;
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
            labelled_line(&mut chart, pts.clone(), c, width, label)?;
            chart
                .draw_series(pts.iter().map(|p| Circle::new(*p, 4, c.filled())))
                .map_err(perr)?;
        }
    }
    legend(&mut chart, 0.8, 14)?;
    present(&root, path)?;
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A scratch directory holding a file `a_file`: paths under it cannot be created.
    fn blocked(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("deflect-sim-out-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("a_file"), "").unwrap();
        d
    }

    #[test]
    fn write_errors_name_the_file_and_what_it_is() {
        let d = blocked("write");
        let under = d.join("a_file");
        let e = write_summary(&under, "summary", "t", "c", &1).unwrap_err();
        let p = under.join("summary.txt");
        assert!(
            e.0.starts_with(&format!("cannot write the summary table {}: ", p.display())),
            "{e}"
        );
        let m = d.join("a_file/log.mcap");
        let e = McapLog::create(&m).err().unwrap();
        assert!(
            e.0.starts_with(&format!("cannot create the MCAP log {}: ", m.display())),
            "{e}"
        );
        // A PNG is written on `present`.
        let png = d.join("a_file/plot.png");
        let root = canvas(&png, (10, 10)).unwrap();
        let e = present(&root, &png).unwrap_err();
        assert!(
            e.0.starts_with(&format!("cannot write the PNG plot {}: ", png.display())),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&d);
    }
}
