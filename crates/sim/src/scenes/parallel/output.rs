//! Outputs of `reproduce` and `run`: summary table (text, CSV, JSON), MCAP log (the
//! convention of [`crate::mcap_log`]) and PNG plots (the style of [`crate::plot_style`]).

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;
use serde_json::json;

use crate::SimError;
use crate::mcap_log::{self, IDENTITY, Kind, Line, McapLog, RunInfo, poses_in_frame, scene_update};
use crate::plot_style::{
    CHART, Entry, Role, Swatch, canvas, color, config_role, config_words, draw_legend, figure,
    line, new_chart, padded_range, perr, present,
};
use crate::scenes::parallel::run::{Motion, RunResult};
pub use crate::summary::write_summary;

/// Topics written for each run, as `/<scenario>/<run>/<topic>` (`crates/sim/README.md`).
pub const TOPICS: [&str; 7] = [
    "desired",
    "commanded",
    "actual",
    "dalembert_force",
    "joints",
    "tcp_pose",
    "paths",
];

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

/// A motion in words with its size: "y-line (150 mm along y)".
pub fn motion_words(m: Motion) -> &'static str {
    match m {
        Motion::XLine => "x-line (100 mm along x at y = 0)",
        Motion::YLine => "y-line (150 mm along y at x = 222.132 mm)",
        Motion::Triangle => "triangle (legs of 63.6 mm, baseline along y at x = 197.132 mm)",
    }
}

/// What a run was, for its `deflect.run` metadata record.
fn run_info(scenario: &str, r: &RunResult) -> RunInfo {
    RunInfo {
        scenario: scenario.to_string(),
        run: run_name(r),
        robot: format!(
            "2-DoF planar parallel robot of Paksoy, Dede and Kiper (2025) in rapier: {}",
            config_words(&r.config)
        ),
        motion: motion_words(r.motion).to_string(),
        acceleration: format!(
            "{} g peak ({:.2} m/s^2), the paper's durations",
            r.g,
            f64::from(r.g) * deflect_core::units::STANDARD_GRAVITY
        ),
        correction: if r.corrected {
            format!(
                "D'Alembert correction (m* = {} kg, compliance map fitted from the simulated static tests)",
                r.mass
            )
        } else {
            "none".to_string()
        },
        options: json!({"config": r.config, "motion": r.motion.label(), "g": r.g,
                        "corrected": r.corrected, "mass_kg": r.mass}),
    }
}

/// Writes `runs` of `scenario` ("reproduce", "run") into one MCAP file following the
/// convention of [`crate::mcap_log`]: topics `/<scenario>/<run>/<topic>` ([`TOPICS`]), every
/// run from t = 0, a `deflect.run` metadata record per run. Planar points carry the tool
/// point's height at rest as `z`. Returns the number of messages.
pub fn write_mcap(path: &Path, scenario: &str, runs: &[&RunResult]) -> Result<usize, SimError> {
    let mut log = McapLog::create(path)?;
    for r in runs {
        let info = run_info(scenario, r);
        log.run_metadata(&info)?;
        let prefix = info.prefix();
        let name = info.run.as_str();
        let kinds = [
            Kind::Point,
            Kind::Point,
            Kind::Point,
            Kind::Force,
            Kind::JointState,
            Kind::PosesInFrame,
            Kind::SceneUpdate,
        ];
        let mut ch = [0u16; 7];
        for ((c, topic), kind) in ch.iter_mut().zip(TOPICS).zip(kinds) {
            *c = log.channel(&prefix, topic, kind)?;
        }
        let z0 = r.samples.first().map_or(0.0, |s| s.actual[2]);
        let plane = |p: &[f64; 2]| [p[0], p[1], z0];
        let lines = [
            Line {
                id: format!("{name}/desired"),
                points: r.samples.iter().map(|s| plane(&s.desired)).collect(),
                rgb: color(Role::Desired).rgb(),
                closed: false,
            },
            Line {
                id: format!("{name}/actual"),
                points: r.samples.iter().map(|s| s.actual).collect(),
                rgb: color(config_role(&r.config)).rgb(),
                closed: false,
            },
        ];
        log.write(ch[6], 0.0, &scene_update(0.0, &lines))?;
        for s in &r.samples {
            let t = s.t;
            let msgs = [
                mcap_log::point(name, t, plane(&s.desired)),
                mcap_log::point(name, t, plane(&s.commanded)),
                mcap_log::point(name, t, s.actual),
                mcap_log::force(name, t, [s.force[0], s.force[1], 0.0]),
                mcap_log::joints(name, t, &s.q_cmd, &s.q_motor, &s.q_link),
                poses_in_frame(t, s.actual, IDENTITY),
            ];
            for (c, m) in ch.iter().zip(&msgs) {
                log.write(*c, t, m)?;
            }
        }
    }
    log.finish()
}

/// CSV of all runs' metrics.
pub fn summary_csv(runs: &[RunResult]) -> String {
    let mut s = String::from(
        "config,motion,peak_acceleration_g,corrected,mass_kg,length_dev_mm,area_mm2,max_dev_mm,rms_dev_mm,max_track_mm,rms_track_mm\n",
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

/// Deviation \[m\] of `p` across the polyline `pts`: its signed distance from the line of
/// the nearest segment, positive to the left of the direction of travel (overshoot beyond a
/// segment's end along it does not count, as in the paper's path deviation).
pub fn polyline_distance(pts: &[nalgebra::Vector2<f64>], p: &nalgebra::Vector2<f64>) -> f64 {
    let mut best = (f64::INFINITY, 0.0);
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let d = b - a;
        let len2 = d.norm_squared().max(f64::MIN_POSITIVE);
        let u = ((p - a).dot(&d) / len2).clamp(0.0, 1.0);
        let dist = (p - (a + d * u)).norm();
        if dist < best.0 {
            let across = (d.x * (p.y - a.y) - d.y * (p.x - a.x)) / len2.sqrt();
            best = (dist, across);
        }
    }
    best.1
}

/// The legend entry and line style of a parallel-robot run: the configuration's colour,
/// dashed thin uncorrected, solid thick corrected.
fn run_style(r: &RunResult, with_g: bool) -> (Entry, u32, bool) {
    let g = if with_g {
        format!(" {} g", r.g)
    } else {
        String::new()
    };
    let label = format!(
        "{}{g}, {}",
        config_words(&r.config),
        if r.corrected {
            "corrected"
        } else {
            "uncorrected"
        }
    );
    let swatch = if r.corrected {
        Swatch::Line(3)
    } else {
        Swatch::Dashed(2)
    };
    let width = if r.corrected { 3 } else { 2 };
    (
        Entry::new(label, config_role(&r.config), swatch),
        width,
        !r.corrected,
    )
}

/// Whether the runs are uncorrected, corrected or both, in words.
fn correction_words<'a>(runs: impl IntoIterator<Item = &'a RunResult>) -> &'static str {
    let (mut off, mut on) = (false, false);
    for r in runs {
        off |= !r.corrected;
        on |= r.corrected;
    }
    match (off, on) {
        (true, true) => "with and without correction",
        (false, true) => "with correction",
        _ => "without correction",
    }
}

/// The title of a path plot: robot (when one), motion, acceleration and correction in words,
/// e.g. "NC robot, lower head: triangle at 5 g, with and without correction".
pub fn paths_title(runs: &[&RunResult]) -> String {
    let Some(first) = runs.first() else {
        return String::new();
    };
    let one_config = runs.iter().all(|r| r.config == first.config);
    let robot = if one_config {
        config_words(&first.config)
    } else {
        "OC and NC robots, upper and lower heads".to_string()
    };
    format!(
        "{robot}: {} at {} g, {}; deviation across the path",
        first.motion.label(),
        first.g,
        correction_words(runs.iter().copied())
    )
}

/// Path plot of runs of one motion: the tool point's deviation across the desired path
/// ([`polyline_distance`], all legs) against time over the whole run, one curve per run;
/// dashed grey lines where a new leg is commanded.
pub fn plot_paths(path: &Path, runs: &[&RunResult]) -> Result<(), SimError> {
    let root = canvas(path, (1200, 620))?;
    let Some(first) = runs.first() else {
        return Ok(());
    };
    let pts = first.motion.points();
    let series: Vec<Vec<(f64, f64)>> = runs
        .iter()
        .map(|r| {
            r.samples
                .iter()
                .map(|s| {
                    let p = nalgebra::Vector2::new(s.actual[0], s.actual[1]);
                    (s.t, polyline_distance(&pts, &p) * 1e3)
                })
                .collect()
        })
        .collect();
    let styles: Vec<(Entry, u32, bool)> = runs.iter().map(|r| run_style(r, false)).collect();
    let mut entries: Vec<Entry> = styles.iter().map(|s| s.0.clone()).collect();
    entries.push(Entry::new(
        "new leg commanded",
        Role::Guide,
        Swatch::Dashed(1),
    ));
    let (plot, legend) = figure(&root, &paths_title(runs), CHART.caption, &entries)?;
    let x = padded_range(series.iter().flatten().map(|p| p.0), 0.01, 0.01);
    let y = padded_range(
        series.iter().flatten().map(|p| p.1).chain([0.0]),
        0.06,
        0.01,
    );
    let mut chart = new_chart(
        &plot,
        CHART,
        x,
        y.clone(),
        (
            "time since the motion start [s]",
            "deviation across the path, + left of travel [mm]",
        ),
    )?;
    let legs: Vec<f64> = first
        .samples
        .windows(2)
        .filter(|w| w[1].segment != w[0].segment)
        .map(|w| w[1].t)
        .collect();
    for t in legs {
        line(
            &mut chart,
            vec![(t, y.start), (t, y.end)],
            color(Role::Guide),
            1,
            true,
        )?;
    }
    for (s, (e, width, dashed)) in series.into_iter().zip(&styles) {
        line(&mut chart, s, e.color, *width, *dashed)?;
    }
    draw_legend(&legend, &entries)?;
    present(&root, path)?;
    Ok(())
}

/// Max path deviation against acceleration, per configuration (its colour), uncorrected
/// (dashed) and corrected (solid).
pub fn plot_error_vs_g(path: &Path, motion: Motion, runs: &[RunResult]) -> Result<(), SimError> {
    let root = canvas(path, (1200, 620))?;
    let sel: Vec<&RunResult> = runs.iter().filter(|r| r.motion == motion).collect();
    let metric = |r: &RunResult| r.metrics.max_dev_mm;
    let mut configs: Vec<String> = sel.iter().map(|r| r.config.clone()).collect();
    configs.sort();
    configs.dedup();
    let mut curves = Vec::new();
    for cfg in &configs {
        for corrected in [false, true] {
            let mut pts: Vec<(f64, f64)> = sel
                .iter()
                .filter(|r| &r.config == cfg && r.corrected == corrected)
                .map(|r| (f64::from(r.g), metric(r)))
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            if let Some(r) = sel
                .iter()
                .find(|r| &r.config == cfg && r.corrected == corrected)
            {
                curves.push((run_style(r, false), pts));
            }
        }
    }
    let entries: Vec<Entry> = curves.iter().map(|c| c.0.0.clone()).collect();
    let title = format!(
        "{}: max path deviation against peak acceleration, OC and NC robots, {}",
        motion.label(),
        correction_words(sel.iter().copied())
    );
    let (plot, legend) = figure(&root, &title, CHART.caption, &entries)?;
    let x = padded_range(
        curves.iter().flat_map(|c| c.1.iter().map(|p| p.0)),
        0.06,
        1.0,
    );
    let ymax = curves
        .iter()
        .flat_map(|c| c.1.iter().map(|p| p.1))
        .fold(0.01, f64::max);
    let mut chart = new_chart(
        &plot,
        CHART,
        x,
        0.0..ymax * 1.08,
        ("peak acceleration [g]", "max path deviation [mm]"),
    )?;
    for ((e, width, dashed), pts) in &curves {
        line(&mut chart, pts.clone(), e.color, *width, *dashed)?;
        let c = e.color;
        chart
            .draw_series(pts.iter().map(|p| Circle::new(*p, 4, c.filled())))
            .map_err(perr)?;
    }
    draw_legend(&legend, &entries)?;
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
    fn distance_from_the_path_is_signed_and_covers_every_leg() {
        use nalgebra::Vector2;
        let tri = Motion::Triangle.points();
        // On a vertex, on the second leg, left and right of the first leg.
        assert!(polyline_distance(&tri, &tri[1]).abs() < 1e-15);
        let mid = (tri[1] + tri[2]) * 0.5;
        assert!(polyline_distance(&tri, &mid).abs() < 1e-15);
        let line = [Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0)];
        assert_eq!(polyline_distance(&line, &Vector2::new(0.5, 0.25)), 0.25);
        assert_eq!(polyline_distance(&line, &Vector2::new(0.5, -0.25)), -0.25);
        // Overshoot along the line beyond its end is not a deviation across it.
        assert_eq!(polyline_distance(&line, &Vector2::new(1.5, 0.125)), 0.125);
        assert_eq!(config_words("NC GL"), "NC robot, lower head");
        assert_eq!(
            motion_words(Motion::XLine),
            "x-line (100 mm along x at y = 0)"
        );
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
