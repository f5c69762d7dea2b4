//! The program scenario's outputs ([`super::program`]): the summary table beside the paper's
//! figures, JSON, every cycle as CSV, and the MCAP log (Foxglove-viewable) by the convention of
//! [`crate::mcap_log`].

use std::fmt::Write as _;
use std::path::Path;

use super::program::{ProgramMode, ProgramResult, ProgramRun};
use crate::SimError;
use crate::mcap_log::{self, IDENTITY, Kind, Line, McapLog, RunInfo};
use crate::plot_style::{Role, color};
use plotters::style::Color as _;

/// The table: per run the path errors and the part's, beside the paper's figures; `name`
/// names the program.
pub fn table(name: &str, r: &ProgramResult) -> String {
    let mut t = String::new();
    let n = r.offline.samples.len();
    let _ = writeln!(
        t,
        "milling: {name} on the flexible {} (rapier), {n} cycles of {:.0} ms, {} runs in \
         {:.1} s wall time",
        r.robot,
        1e3 / r.offline.rate_hz,
        r.runs.len(),
        r.wall_seconds
    );
    let fmax = r
        .offline
        .samples
        .iter()
        .map(|s| s.force.norm())
        .fold(0.0, f64::max);
    let _ = writeln!(
        t,
        "largest offline force on the tool: {fmax:.0} N (paper: up to 546 N)"
    );
    let _ = writeln!(
        t,
        "run              path max  RMS    entry  exit [mm] | floors max  RMS [mm] | walls left  overcut [mm^2]"
    );
    for run in &r.runs {
        let (m, e) = (&run.metrics, &run.part_error);
        let _ = writeln!(
            t,
            "{:<15}  {:>8.3}  {:.3}  {:.3}  {:.3}     | {:>10.3}  {:.3}    | {:>10.1}  {:.1}",
            run.mode.label(),
            m.max_mm,
            m.rms_mm,
            m.entry_max_mm,
            m.exit_max_mm,
            e.floor.max * 1e3,
            e.floor.rms * 1e3,
            e.material_left * 1e6,
            e.overcut * 1e6
        );
    }
    let _ = writeln!(
        t,
        "entry, exit: the largest deviation over the first and the last tool radius of travel \
         of each of the {} cuts (tool in the material at least twice that long)",
        r.cuts.len()
    );
    let by = |mode| r.runs.iter().find(|x| x.mode == mode).map(|x| x.metrics);
    if let (Some(u), Some(c), Some(h)) = (
        by(ProgramMode::Uncompensated),
        by(ProgramMode::Cartesian),
        by(ProgramMode::Hybrid),
    ) {
        let _ = writeln!(
            t,
            "paper (Fig. 10-12): 1.4 mm uncompensated -> 0.7 mm Cartesian -> 0.3 mm with pilot \
             control at the cutter exits, \"78 % and more\"\nhere: max {:.2} mm -> {:.2} mm -> \
             {:.2} mm, at the cutter exits {:.2} mm -> {:.2} mm -> {:.2} mm; max deviation \
             reduced by {:.0} % (Cartesian) and {:.0} % (hybrid)",
            u.max_mm,
            c.max_mm,
            h.max_mm,
            u.exit_max_mm,
            c.exit_max_mm,
            h.exit_max_mm,
            100.0 * (1.0 - c.max_mm / u.max_mm),
            100.0 * (1.0 - h.max_mm / u.max_mm)
        );
        if let Some(m) = by(ProgramMode::Combined) {
            let _ = writeln!(
                t,
                "combined (hybrid with the inertial feed-forward): max {:.2} mm, at the cutter \
                 exits {:.2} mm; max deviation reduced by {:.0} %",
                m.max_mm,
                m.exit_max_mm,
                100.0 * (1.0 - m.max_mm / u.max_mm)
            );
        }
    }
    sources(&mut t, r);
    t
}

/// Where the error comes from, per program line that cuts: the offline pass's process and
/// inertial deflections at the rigid joints (largest position part) and peak acceleration, and
/// each run's largest deviation across the feed there.
fn sources(t: &mut String, r: &ProgramResult) {
    if r.lines.is_empty() {
        return;
    }
    let _ = write!(
        t,
        "by source, per cutting line: line  process  inertial [mm]  peak acc [m/s^2] |"
    );
    for run in &r.runs {
        let _ = write!(t, " {}", run.mode.label());
    }
    let _ = writeln!(t, " [mm]");
    for l in &r.lines {
        let worst = |run: &ProgramRun| {
            run.samples
                .iter()
                .filter(|s| s.line == l.line && s.depth > 0.0)
                .map(|s| s.error_mm)
                .fold(f64::NAN, f64::max)
        };
        if r.runs.first().is_none_or(|u| worst(u).is_nan()) {
            continue;
        }
        let _ = write!(
            t,
            "  {:>4}  {:>7.3}  {:>8.3}       {:>8.3}         |",
            l.line,
            l.deflection_process * 1e3,
            l.deflection_inertial * 1e3,
            l.peak_acceleration
        );
        for run in &r.runs {
            let _ = write!(t, " {:.3}", worst(run));
        }
        let _ = writeln!(t);
    }
}

/// The summary as JSON.
pub fn json(name: &str, r: &ProgramResult) -> serde_json::Value {
    serde_json::json!({
        "program": name,
        "robot": r.robot,
        "cycles": r.offline.samples.len(),
        "rate_hz": r.offline.rate_hz,
        "wall_seconds": r.wall_seconds,
        "cuts": r.cuts,
        "runs": r.runs.iter().map(|run| serde_json::json!({
            "mode": run.mode.label(),
            "metrics": run.metrics,
            "floor_error_max_m": run.part_error.floor.max,
            "floor_error_rms_m": run.part_error.floor.rms,
            "material_left_m2": run.part_error.material_left,
            "overcut_m2": run.part_error.overcut,
        })).collect::<Vec<_>>(),
    })
}

/// Every run's cycles as CSV: mode, time, line, programmed and simulated tip, force, the
/// engagement (depth, first entry and last exit angle, arcs), error across the feed.
pub fn csv(r: &ProgramResult) -> String {
    let mut t = String::from(
        "run,time_s,line,x_m,y_m,z_m,actual_x_m,actual_y_m,actual_z_m,fx_n,fy_n,fz_n,depth_m,\
         entry_rad,exit_rad,arcs,error_mm\n",
    );
    for run in &r.runs {
        for s in &run.samples {
            let _ = writeln!(
                t,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                run.mode.label(),
                s.t,
                s.line,
                s.nominal[0],
                s.nominal[1],
                s.nominal[2],
                s.actual[0],
                s.actual[1],
                s.actual[2],
                s.force[0],
                s.force[1],
                s.force[2],
                s.depth,
                s.angles[0],
                s.angles[1],
                s.arcs,
                s.error_mm
            );
        }
    }
    t
}

/// Topics per run, as `/milling/<run>/<topic>`, and their message types.
pub const TOPICS: [(&str, Kind); 7] = [
    ("nominal", Kind::Point),
    ("actual", Kind::Point),
    ("process_force", Kind::Force),
    ("engagement", Kind::Engagement),
    ("error", Kind::PathError),
    ("tcp_pose", Kind::PosesInFrame),
    ("paths", Kind::SceneUpdate),
];

fn role(mode: ProgramMode) -> Role {
    match mode {
        ProgramMode::Uncompensated => Role::Uncorrected,
        ProgramMode::Offline | ProgramMode::AxisSpecific => Role::Uncalibrated,
        ProgramMode::Cartesian => Role::Corrected,
        ProgramMode::Hybrid | ProgramMode::Combined => Role::Pilot,
    }
}

fn run_info(name: &str, r: &ProgramResult, run: &ProgramRun) -> RunInfo {
    RunInfo {
        scenario: "milling".into(),
        run: run.mode.label().into(),
        robot: format!("{} as a flexible arm in rapier", r.robot),
        motion: format!(
            "{name}: {} cycles of {:.1} ms, positions in the workpiece frame",
            r.offline.samples.len(),
            1e3 / r.offline.rate_hz
        ),
        acceleration: "jerk-limited, exact stop at corners (deflect-core machining::path)".into(),
        correction: run.mode.label().replace('_', " "),
        options: serde_json::json!({"rate_hz": r.offline.rate_hz}),
    }
}

/// Writes every run to `path`: topics `/milling/<run>/<topic>` ([`TOPICS`]) from t = 0, SI
/// units, tool tips and forces in the workpiece frame, a `deflect.run` metadata record per
/// run. Returns the number of messages.
pub fn write_mcap(path: &Path, name: &str, r: &ProgramResult) -> Result<usize, SimError> {
    let mut log = McapLog::create(path)?;
    for run in &r.runs {
        let label = run.mode.label();
        let lines = [
            Line {
                id: format!("{label}/nominal"),
                points: run.samples.iter().map(|s| s.nominal).collect(),
                rgb: color(Role::Desired).rgb(),
                closed: false,
            },
            Line {
                id: format!("{label}/actual"),
                points: run.samples.iter().map(|s| s.actual).collect(),
                rgb: color(role(run.mode)).rgb(),
                closed: false,
            },
        ];
        log.write_run(
            &run_info(name, r, run),
            &TOPICS,
            &lines,
            &run.samples,
            |s| {
                let t = s.t;
                let msgs = vec![
                    mcap_log::point(label, t, s.nominal),
                    mcap_log::point(label, t, s.actual),
                    mcap_log::force(label, t, s.force),
                    mcap_log::engagement(label, t, s.depth, s.angles, s.arcs),
                    mcap_log::path_error(label, t, s.error_mm * 1e-3),
                    mcap_log::poses_in_frame(t, s.actual, IDENTITY),
                ];
                (t, msgs)
            },
        )?;
    }
    log.finish()
}
