//! The `job` command's summary: the run, the tools, per operation, the ten lines of largest
//! force, where the compensated prediction leaves the program, and the totals, as text lines
//! and JSON.

use std::fmt::Write as _;

use deflect_core::machining::job::{self, Report};

use super::files::OperationFigures;
use super::task::JobTask;

/// Which tool cuts each `T` of the program, and which spindle: the summary's words.
fn tools_text(t: &JobTask) -> (String, Vec<serde_json::Value>) {
    let used = t.program.tools();
    let setup = t.job.setup();
    let mut json = Vec::new();
    let mut text = match t.job.tools() {
        Some(table) => {
            let mut parts = Vec::new();
            for n in &used {
                if let Some(spec) = table.get(*n) {
                    parts.push(format!(
                        "T{n} {:.3} mm {} {} flutes{}",
                        spec.tool.diameter * 1e3,
                        spec.shape.name(),
                        spec.tool.flutes,
                        if spec.name.is_empty() {
                            String::new()
                        } else {
                            format!(" ({})", spec.name)
                        }
                    ));
                    json.push(serde_json::json!({
                        "tool": n, "diameter_m": spec.tool.diameter, "shape": spec.shape.name(),
                        "flutes": spec.tool.flutes, "helix_rad": spec.tool.helix, "length_m": spec.length,
                    }));
                }
            }
            let ends = table
                .tools()
                .iter()
                .any(|s| s.shape != deflect_core::machining::tools::ToolShape::Flat);
            format!(
                "tools (from the tool table): {}{}",
                if parts.is_empty() {
                    "none cut".to_string()
                } else {
                    parts.join("; ")
                },
                if ends {
                    "; ball and bull-nose ends cut the z-map as ball and flat ends and feel the flat \
                     end mill's force"
                } else {
                    ""
                }
            )
        }
        None => {
            let names: Vec<String> = used
                .iter()
                .filter(|&&n| n > 0)
                .map(|n| format!("T{n}"))
                .collect();
            json.push(serde_json::json!({
                "tool": "every", "diameter_m": setup.tool.diameter, "shape": "flat",
                "flutes": setup.tool.flutes, "helix_rad": setup.tool.helix,
            }));
            format!(
                "tool: no tool table; the --diameter/--flutes tool ({:.3} mm flat, {} flutes) serves \
                 every T of the program ({})",
                setup.tool.diameter * 1e3,
                setup.tool.flutes,
                if names.is_empty() {
                    "it names none".to_string()
                } else {
                    names.join(", ")
                }
            )
        }
    };
    if let Some(hand) = setup.hand_spindle {
        let _ = write!(
            text,
            "\nspindle: hand-started at {:.0} rpm wherever the program's spindle is off",
            hand * 60.0
        );
    }
    (text, json)
}

/// The summary as text lines and JSON: the run, the tools, per operation, the ten lines of
/// largest force, where the compensated prediction leaves the program, and the totals.
/// The spin search's lines (`--spin optimize`): the predicted deflection of the optimised
/// schedule against the seed's constant spin and the best constant one; its JSON.
fn spin_text(t: &JobTask, text: &mut String) -> serde_json::Value {
    let Some((plan, wall)) = &t.spin else {
        return serde_json::Value::Null;
    };
    let mm = |c: &deflect_core::machining::spin::SpinCost| {
        format!("RMS {:.4} mm, max {:.4} mm", c.rms * 1e3, c.max * 1e3)
    };
    let spins = plan.schedule.spins();
    let (lo, hi) = spins
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
            (a.min(*s), b.max(*s))
        });
    let _ = writeln!(
        text,
        "spin about the tool axis (--spin optimize, {} stations x {} candidates, {} refused, in {wall:.2} s): predicted deflection ({}) optimised {}; the seed's constant spin {}; the best constant spin ({}) {}; the schedule within {:.1}..{:.1} degrees",
        plan.stations,
        plan.candidates.len(),
        plan.refused,
        plan.measure.name(),
        mm(&plan.optimised),
        plan.seed
            .as_ref()
            .map_or("leaves the limits or its branch".to_string(), mm),
        plan.best_constant
            .as_ref()
            .map_or("none".to_string(), |(a, _)| format!(
                "{:.1} degrees",
                a.to_degrees()
            )),
        plan.best_constant
            .as_ref()
            .map_or("-".to_string(), |(_, c)| mm(c)),
        lo.to_degrees(),
        hi.to_degrees()
    );
    let cost = |c: &deflect_core::machining::spin::SpinCost| serde_json::json!({"rms_m": c.rms, "max_m": c.max});
    serde_json::json!({
        "stations": plan.stations,
        "candidates": plan.candidates.len(),
        "refused_nodes": plan.refused,
        "measure": plan.measure.name(),
        "wall_time_s": wall,
        "optimised": cost(&plan.optimised),
        "seed_constant": plan.seed.as_ref().map(cost),
        "best_constant": plan.best_constant.as_ref().map(|(a, c)| serde_json::json!({
            "spin_rad": a, "rms_m": c.rms, "max_m": c.max,
        })),
        "min_spin_rad": lo,
        "max_spin_rad": hi,
    })
}

pub(crate) fn summary(
    t: &JobTask,
    r: &Report,
    ops: &[OperationFigures],
    wall: f64,
    threads: usize,
) -> (String, serde_json::Value) {
    let (pu, pc) = (r.path_error(false), r.path_error(true));
    let (su, sc) = (
        r.surface_error(&r.uncompensated),
        r.surface_error(&r.compensated),
    );
    let sm = &r.summary;
    let duration = sm.duration();
    let fmax = sm.max_force();
    let cell = t.job.setup().stock.cell;
    let mut text = header_text(t, r, wall, threads);
    let (tools, tools_json) = tools_text(t);
    let _ = writeln!(text, "{tools}");
    if let Some(c) = r.rapid_contact {
        let _ = writeln!(
            text,
            "rapids in the stock: the deepest {:.3} mm at line {} (t = {:.2} s), within --rapid-skim \
             {:.3} mm",
            c.depth * 1e3,
            c.line,
            c.time,
            t.job.setup().rapid_skim * 1e3
        );
    }
    let _ = writeln!(text, "largest force on the tool: {fmax:.1} N");
    let spin_json = spin_text(t, &mut text);
    operations_text(ops, &mut text);
    let lines = r.line_forces();
    let mut top: Vec<_> = lines.iter().filter(|l| l.max > 0.0).collect();
    top.sort_by(|a, b| b.max.total_cmp(&a.max));
    top.truncate(10);
    top_lines_text(&top, &mut text);
    let mut off: Vec<_> = lines.iter().filter(|l| l.deviation.is_some()).collect();
    off.sort_by(|a, b| b.error_compensated.total_cmp(&a.error_compensated));
    let tol = job::PREDICTION_TOLERANCE;
    deviating_text(&off, r, pc.max, &mut text);
    let _ = writeln!(text);
    for (label, p, s) in [("uncompensated", pu, su), ("compensated", pc, sc)] {
        let _ = writeln!(
            text,
            "{label:<13}  path error max {:.4} mm, RMS {:.4} mm; part floors max {:.4} mm, \
             RMS {:.4} mm; walls {:.1} mm^2 left, {:.1} mm^2 overcut",
            p.max * 1e3,
            p.rms * 1e3,
            s.floor.max * 1e3,
            s.floor.rms * 1e3,
            s.material_left * 1e6,
            s.overcut * 1e6
        );
    }
    let json = serde_json::json!({
        "program": t.program_name,
        "robot": t.robot_name,
        "samples": sm.samples(),
        "rate_hz": r.rate_hz,
        "duration_s": duration,
        "wall_time_s": wall,
        "threads": threads,
        "cell_m": cell,
        "cell_updates": r.cell_updates,
        "plunge_samples": r.plunge_samples,
        "max_force_n": fmax,
        "tools": tools_json,
        "rapid_contact": r.rapid_contact.map(|c| serde_json::json!({
            "line": c.line, "time_s": c.time, "depth_m": c.depth,
        })),
        "hand_spindle_rpm": t.job.setup().hand_spindle.map(|v| v * 60.0),
        "spin": spin_json,
        "operations": ops.iter().map(|o| serde_json::json!({
            "name": o.name, "line": o.line, "tool": o.tool, "samples": o.samples,
            "start_s": o.start, "end_s": o.end, "max_force_n": o.max_force,
            "mean_force_n": o.sum_force / o.samples.max(1) as f64,
            "path_error_uncompensated_m": o.error_uncompensated,
            "path_error_compensated_m": o.error_compensated,
            "deviating_samples": o.deviating,
        })).collect::<Vec<_>>(),
        "top_lines": top.iter().map(|l| line_json(l)).collect::<Vec<_>>(),
        "deviating_lines": off.iter().map(|l| line_json(l)).collect::<Vec<_>>(),
        "prediction_tolerance_m": tol,
        "coupling_residual_max_m": sm.max_residual(),
        "uncompensated": stats_json(pu, su),
        "compensated": stats_json(pc, sc),
    });
    (text, json)
}

/// The summary's first line: the program, the arm, the samples and the pass's speed.
fn header_text(t: &JobTask, r: &Report, wall: f64, threads: usize) -> String {
    let sm = &r.summary;
    let duration = sm.duration();
    let cell = t.job.setup().stock.cell;
    let mut text = String::new();
    let _ = writeln!(
        text,
        "job: {} on {}: {} samples at {} Hz over {duration:.2} s of program, in {wall:.2} s \
         on {threads} thread{} ({:.0} samples/s, {:.0} z-map cell updates/s); z-map cells of \
         {:.3} mm; {} plunge samples (no side force)",
        t.program_name,
        t.robot_name,
        sm.samples(),
        r.rate_hz,
        if threads == 1 { "" } else { "s" },
        sm.samples() as f64 / wall.max(1e-9),
        r.cell_updates as f64 / wall.max(1e-9),
        cell * 1e3,
        r.plunge_samples
    );
    text
}

/// The table of the program's operations: time, force and path error max \[mm\].
fn operations_text(ops: &[OperationFigures], text: &mut String) {
    let _ = writeln!(
        text,
        "\noperations ({}): path error max [mm] uncompensated -> compensated",
        ops.len()
    );
    let _ = writeln!(
        text,
        "{:<32} {:>6} {:>5} {:>10} {:>9} {:>9} {:>14} {:>12}",
        "operation",
        "line",
        "tool",
        "time [s]",
        "max |F|",
        "mean |F|",
        "uncompensated",
        "compensated"
    );
    let name_width = 32;
    for o in ops {
        let name = deflect_sim::scenes::milling::part_map::shorten(&o.name, 32 * 9, 16);
        let name: String = name.chars().take(name_width).collect();
        let _ = writeln!(
            text,
            "{name:<32} {:>6} {:>5} {:>10.1} {:>9.1} {:>9.1} {:>14.4} {:>12.6}",
            o.line,
            format!("T{}", o.tool),
            o.end - o.start,
            o.max_force,
            o.sum_force / o.samples.max(1) as f64,
            o.error_uncompensated * 1e3,
            o.error_compensated * 1e3
        );
    }
}

/// The table of the ten program lines of largest force.
fn top_lines_text(top: &[&job::LineSummary], text: &mut String) {
    let _ = writeln!(text, "\nthe ten program lines of largest force");
    let _ = writeln!(
        text,
        "{:>6}  {:>7}  {:>12}  {:>11}  {:>22}",
        "line", "samples", "mean |F| [N]", "max |F| [N]", "path error max [mm] u/c"
    );
    for l in top {
        let _ = writeln!(
            text,
            "{:>6}  {:>7}  {:>12.1}  {:>11.1}  {:>11.4} / {:.6}",
            l.line,
            l.samples,
            l.mean.norm(),
            l.max,
            l.error_uncompensated * 1e3,
            l.error_compensated * 1e3
        );
    }
}

/// Whether the compensated prediction stays within the tolerance on every line (its largest
/// path error `pc_max` \[m\]), else the worst lines and why.
fn deviating_text(off: &[&job::LineSummary], r: &Report, pc_max: f64, text: &mut String) {
    let sm = &r.summary;
    let tol = job::PREDICTION_TOLERANCE;
    if off.is_empty() {
        let _ = writeln!(
            text,
            "\nthe compensated prediction stays within {:.0} um of the program on every line \
             (largest {:.2e} mm; coupling residual at most {:.1e} m)",
            tol * 1e6,
            pc_max * 1e3,
            sm.max_residual()[1]
        );
    } else {
        let _ = writeln!(
            text,
            "\nthe compensated prediction leaves the program by more than {:.0} um on {} lines \
             ({} samples); the worst:",
            tol * 1e6,
            off.len(),
            sm.deviating_samples()
        );
        for l in off.iter().take(10) {
            let why = match l.deviation {
                Some(job::Deviation::Coupling) => {
                    "the force-deflection coupling does not converge (the force changes faster \
                     with the tool's position than the arm holds it; a finer --cell may help)"
                }
                _ => {
                    "the compensated tool meets a stock an earlier deviation left (beyond the \
                     offline compensation)"
                }
            };
            let _ = writeln!(
                text,
                "  line {}: {:.4} mm, residual {:.1e} m: {why}",
                l.line,
                l.error_compensated * 1e3,
                l.residual
            );
        }
    }
}

/// A prediction's path and part errors, as JSON \[m, m^2\].
fn stats_json(p: job::ErrorStats, s: job::SurfaceError) -> serde_json::Value {
    serde_json::json!({
        "path_error_max_m": p.max, "path_error_rms_m": p.rms,
        "floor_error_max_m": s.floor.max, "floor_error_rms_m": s.floor.rms,
        "material_left_m2": s.material_left, "overcut_m2": s.overcut,
    })
}

/// A program line's figures, as JSON \[N, m\].
fn line_json(l: &job::LineSummary) -> serde_json::Value {
    serde_json::json!({
        "line": l.line, "samples": l.samples,
        "mean_force_n": [l.mean.x, l.mean.y, l.mean.z], "max_force_n": l.max,
        "path_error_uncompensated_m": l.error_uncompensated,
        "path_error_compensated_m": l.error_compensated,
        "coupling_residual_m": l.residual,
        "deviation": l.deviation.map(job::Deviation::name),
    })
}
