//! Outputs of the milling scenario: summary table (text, CSV, JSON), MCAP log and PNG plots.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;
use serde_json::json;

use super::{MillingOptions, MillingResult, Mode, Sample};
use crate::SimError;
use crate::mcap_log::{self, IDENTITY, Kind, Line, McapLog, RunInfo};
use crate::plot_style::{
    CHART, Entry, Role, Swatch, canvas, color, draw_legend, figure, line, new_chart, padded_range,
    present,
};
use crate::summary::write_summary;

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
    stiffness_table(r, &mut s);
    sensor_table(r, &mut s);
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

/// The stiffness identification's rows: each spring axis's true and identified stiffness
/// \[kN m/rad\] from frame pairs and from the TCP.
fn stiffness_table(r: &MillingResult, s: &mut String) {
    let o = &r.options;
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
}

/// The sensor identification's rows: force and moment offsets, weight and centre of gravity,
/// true and identified.
fn sensor_table(r: &MillingResult, s: &mut String) {
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
    s.push_str(
        "\nspring,axis,label,k_true_N_m_per_rad,k_frames_N_m_per_rad,se_frames_N_m_per_rad,\
         k_tcp_N_m_per_rad,se_tcp_N_m_per_rad\n",
    );
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

/// The run's mode as a plot role (its colour in every figure).
fn role(mode: Mode) -> Role {
    match mode {
        Mode::Uncompensated => Role::Uncorrected,
        Mode::Cartesian => Role::Corrected,
        Mode::Pilot => Role::Pilot,
        Mode::Uncalibrated => Role::Uncalibrated,
    }
}

/// The compensation of `mode` in words.
fn mode_words(mode: Mode, o: &MillingOptions) -> String {
    match mode {
        Mode::Uncompensated => "none".to_string(),
        Mode::Cartesian => "online Cartesian compensation (Hähn and Weigold 2020) from the \
                            measured forces, pilot control off"
            .to_string(),
        Mode::Pilot => format!(
            "online Cartesian compensation with pilot control ({:.0} N, {:.0} ms) from an offline \
             force estimate leading by {:.0} ms, {:+.0} % off",
            o.pilot.0,
            o.pilot.1 * 1e3,
            o.estimate_lead * 1e3,
            o.estimate_error * 100.0
        ),
        Mode::Uncalibrated => "online Cartesian compensation without sensor calibration \
                               (offsets and tool weight taken for process force)"
            .to_string(),
    }
}

fn run_info(r: &MillingResult, mode: Mode) -> RunInfo {
    let o = &r.options;
    RunInfo {
        scenario: "milling".into(),
        run: mode.label().into(),
        robot: "KUKA KR 300 R2500 (robots/ URDF and stiffness file) as a flexible arm in rapier: \
                6 servo joints, 10 virtual joints"
            .into(),
        motion: format!(
            "groove along +x of the base at {:.1} mm/s with the tool's orientation held: {:.2} s \
             standstill, {:.2} s approach, {:.2} s cut, {:.2} s run-out; process force \
             [{:.0}, {:.0}, {:.0}] N at the TCP while cutting",
            o.feed * 1e3,
            o.settle,
            o.approach,
            o.cut,
            o.runout,
            o.force[0],
            o.force[1],
            o.force[2]
        ),
        acceleration: format!(
            "(1 - cos) ramp to the feed in {:.2} s, peak {:.3} m/s^2",
            o.ramp,
            core::f64::consts::FRAC_PI_2 * o.feed / o.ramp.max(1e-9)
        ),
        correction: mode_words(mode, o),
        options: serde_json::to_value(o).unwrap_or_default(),
    }
}

/// Topics per run, as `/milling/<run>/<topic>`, and their message types.
pub const TOPICS: [(&str, Kind); 11] = [
    ("nominal", Kind::Point),
    ("actual", Kind::Point),
    ("commanded", Kind::Point),
    ("force_measured", Kind::Wrench),
    ("force_filtered", Kind::Wrench),
    ("process_force", Kind::Force),
    ("correction", Kind::Displacement),
    ("error", Kind::PathError),
    ("pilot", Kind::PilotControl),
    ("tcp_pose", Kind::PosesInFrame),
    ("paths", Kind::SceneUpdate),
];

fn messages(run: &str, s: &Sample) -> [serde_json::Value; 10] {
    let t = s.t;
    [
        mcap_log::point(run, t, s.nominal),
        mcap_log::point(run, t, s.actual),
        mcap_log::point(run, t, s.commanded),
        mcap_log::wrench(run, t, &s.force_measured),
        mcap_log::wrench(run, t, &s.force_filtered),
        mcap_log::force(run, t, s.force_true),
        mcap_log::displacement(run, t, &s.correction),
        mcap_log::path_error(run, t, s.error_mm * 1e-3),
        mcap_log::pilot(run, t, s.pilot_weight),
        mcap_log::poses_in_frame(t, s.actual, IDENTITY),
    ]
}

/// Writes the runs to `path` by the convention of [`crate::mcap_log`]: topics
/// `/milling/<run>/<topic>` ([`TOPICS`]), every run from t = 0, SI units (the path error in
/// m), a `deflect.run` metadata record per run. Returns the number of messages.
pub fn write_mcap(path: &Path, r: &MillingResult) -> Result<usize, SimError> {
    let mut log = McapLog::create(path)?;
    for run in &r.runs {
        let name = run.mode.label();
        let lines = [
            Line {
                id: format!("{name}/nominal"),
                points: run.samples.iter().map(|s| s.nominal).collect(),
                rgb: color(Role::Desired).rgb(),
                closed: false,
            },
            Line {
                id: format!("{name}/actual"),
                points: run.samples.iter().map(|s| s.actual).collect(),
                rgb: color(role(run.mode)).rgb(),
                closed: false,
            },
        ];
        log.write_run(&run_info(r, run.mode), &TOPICS, &lines, &run.samples, |s| {
            (s.t, messages(name, s).to_vec())
        })?;
    }
    log.finish()
}

/// Path error against time for the runs, with the cutter entry and exit marked.
pub fn plot_error(path: &Path, r: &MillingResult) -> Result<(), SimError> {
    let root = canvas(path, (1250, 620))?;
    let o = &r.options;
    let mut entries: Vec<Entry> = r
        .runs
        .iter()
        .map(|run| {
            let m = &run.metrics;
            Entry::new(
                format!(
                    "{}: max {:.2} mm, RMS {:.2} mm",
                    run.mode.label(),
                    m.max_mm,
                    m.rms_mm
                ),
                role(run.mode),
                Swatch::Line(2),
            )
        })
        .collect();
    entries.push(Entry::new(
        "cutter entry and exit",
        Role::Guide,
        Swatch::Dashed(1),
    ));
    let title = format!(
        "KR 300 R2500 milling a groove at {:.0} mm/s, {:.0} N process force: path error across \
         the feed, uncompensated and compensated",
        o.feed * 1e3,
        nalgebra::Vector3::from(o.force).norm()
    );
    let (plot, legend) = figure(&root, &title, CHART.caption, &entries)?;
    let x = padded_range(
        r.runs.iter().flat_map(|x| x.samples.iter().map(|s| s.t)),
        0.01,
        0.01,
    );
    let ymax = r
        .runs
        .iter()
        .flat_map(|x| x.samples.iter().map(|s| s.error_mm))
        .fold(0.1, f64::max)
        * 1.06;
    let mut chart = new_chart(
        &plot,
        CHART,
        x,
        0.0..ymax,
        (
            "time since the run's start [s]",
            "path error across the feed [mm]",
        ),
    )?;
    for t in [o.t_entry(), o.t_exit()] {
        line(
            &mut chart,
            vec![(t, 0.0), (t, ymax)],
            color(Role::Guide),
            1,
            true,
        )?;
    }
    for run in &r.runs {
        let pts = run.samples.iter().map(|s| (s.t, s.error_mm)).collect();
        line(&mut chart, pts, color(role(run.mode)), 2, false)?;
    }
    draw_legend(&legend, &entries)?;
    present(&root, path)?;
    Ok(())
}

/// The 95 % confidence factor of a normal estimate: identified value +- 1.96 standard errors.
pub const CI95: f64 = 1.96;

/// One panel of [`plot_stiffness`]: identified / true per axis with 95 % confidence bars
/// (capped; a bar beyond the axis ends in an arrow), unidentifiable axes as crosses at 1.
fn stiffness_panel(
    area: &crate::plot_style::Area<'_>,
    caption: &str,
    pts: &[(f64, f64, f64)],
    n: f64,
    role: Role,
) -> Result<(), SimError> {
    let area = area
        .titled(caption, ("sans-serif", 16))
        .map_err(crate::plot_style::perr)?;
    let ok: Vec<&(f64, f64, f64)> = pts.iter().filter(|p| p.1.is_finite()).collect();
    let half = |p: &(f64, f64, f64)| if p.2.is_finite() { CI95 * p.2 } else { 0.0 };
    // Every estimate and bar, but bars 100x the value would hide the estimates: the axis
    // stops at 3 times the estimates' spread about 1 (then arrows mark the longer bars).
    let spread = ok.iter().map(|p| (p.1 - 1.0).abs()).fold(0.005, f64::max);
    let reach = ok
        .iter()
        .map(|p| (p.1 - 1.0).abs() + half(p))
        .fold(spread, f64::max)
        .min(3.0 * spread + 0.02);
    let y = (1.0 - 1.08 * reach)..(1.0 + 1.08 * reach);
    let mut chart = new_chart(
        &area,
        CHART,
        -0.5..(n - 0.5),
        y.clone(),
        (
            "spring axis (chain order, see milling_summary.txt)",
            "identified / true [1]",
        ),
    )?;
    let c = color(role);
    line(
        &mut chart,
        vec![(-0.5, 1.0), (n - 0.5, 1.0)],
        color(Role::Guide),
        1,
        false,
    )?;
    let perr = crate::plot_style::perr;
    for p in &ok {
        let (lo, hi) = (p.1 - half(p), p.1 + half(p));
        let (a, b) = (lo.max(y.start), hi.min(y.end));
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(p.0, a), (p.0, b)],
                c.stroke_width(2),
            )))
            .map_err(perr)?;
        for (v, clipped, up) in [(a, lo < y.start, false), (b, hi > y.end, true)] {
            if clipped {
                let d = 0.03 * (y.end - y.start);
                let base = if up { v - d } else { v + d };
                chart
                    .draw_series(std::iter::once(Polygon::new(
                        vec![(p.0 - 0.2, base), (p.0 + 0.2, base), (p.0, v)],
                        c.filled(),
                    )))
                    .map_err(perr)?;
            } else {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(p.0 - 0.2, v), (p.0 + 0.2, v)],
                        c.stroke_width(2),
                    )))
                    .map_err(perr)?;
            }
        }
    }
    chart
        .draw_series(
            ok.iter()
                .map(|p| Circle::new((p.0, p.1.clamp(y.start, y.end)), 4, c.filled())),
        )
        .map_err(perr)?;
    chart
        .draw_series(
            pts.iter()
                .filter(|p| !p.1.is_finite())
                .map(|p| Cross::new((p.0, 1.0), 5, color(Role::Guide).stroke_width(2))),
        )
        .map_err(perr)?;
    Ok(())
}

/// Identified over true stiffness per virtual-joint axis, frame pairs (top) and 6-D TCP
/// deflections (bottom), each with its 95 % confidence interval (+- 1.96 standard errors of
/// the least-squares identification, from its residuals).
pub fn plot_stiffness(path: &Path, r: &MillingResult) -> Result<(), SimError> {
    let root = canvas(path, (1250, 820))?;
    let entries = [
        Entry::new(
            "frame pairs: identified / true",
            Role::FramePairs,
            Swatch::Marker,
        ),
        Entry::new(
            "TCP 6-D: identified / true",
            Role::TcpDeflection,
            Swatch::Marker,
        ),
        Entry::new(
            "95 % confidence interval (+- 1.96 se)",
            Role::Guide,
            Swatch::Bar,
        ),
        Entry::new("interval beyond the axis", Role::Guide, Swatch::Arrow),
        Entry::new(
            "not identifiable from the loads",
            Role::Guide,
            Swatch::Cross,
        ),
        Entry::new("true value (ratio 1)", Role::Guide, Swatch::Dashed(1)),
    ];
    let poses = r.options.id_poses.clamp(1, 3);
    let title = format!(
        "KR 300 R2500: virtual-joint stiffness identified from static loads ({:.0} N, {poses} \
         pose{}) over the true value",
        r.options.id_load,
        if poses == 1 { "" } else { "s" }
    );
    let (plot, legend) = figure(&root, &title, CHART.caption, &entries)?;
    let n = r.stiffness.len().max(1) as f64;
    let pts = |tcp: bool| -> Vec<(f64, f64, f64)> {
        r.stiffness
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let (k, se) = if tcp {
                    (e.k_tcp, e.se_tcp)
                } else {
                    (e.k_frames, e.se_frames)
                };
                (i as f64, k / e.k_true, se / e.k_true)
            })
            .collect()
    };
    let (_, ph) = plot.dim_in_pixel();
    let (top, bottom) = plot.split_vertically(ph / 2);
    stiffness_panel(
        &top,
        "frame-pair rotations across each virtual joint (used by the compensator)",
        &pts(false),
        n,
        Role::FramePairs,
    )?;
    stiffness_panel(
        &bottom,
        "6-D TCP deflections only (springs in series are hard to tell apart)",
        &pts(true),
        n,
        Role::TcpDeflection,
    )?;
    draw_legend(&legend, &entries)?;
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
