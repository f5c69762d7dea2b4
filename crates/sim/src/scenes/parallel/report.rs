//! Text tables in the layout of the paper's Figures 10, 12 and 14, and the reduction the
//! correction brings at 5 g.

use std::fmt::Write as _;

use crate::scenes::parallel::run::{Motion, RunResult};
pub use crate::summary::reduction;

fn find<'a>(
    runs: &'a [RunResult],
    config: &str,
    motion: Motion,
    g: u8,
    corrected: bool,
) -> Option<&'a RunResult> {
    runs.iter()
        .find(|r| r.config == config && r.motion == motion && r.g == g && r.corrected == corrected)
}

fn configs(runs: &[RunResult]) -> Vec<String> {
    let mut c: Vec<String> = Vec::new();
    for r in runs {
        if !c.contains(&r.config) {
            c.push(r.config.clone());
        }
    }
    c
}

fn g_levels(runs: &[RunResult]) -> Vec<u8> {
    let mut g: Vec<u8> = runs.iter().map(|r| r.g).collect();
    g.sort_unstable();
    g.dedup();
    g
}

/// The per-motion tables and the 5 g reduction table.
pub fn tables(runs: &[RunResult]) -> String {
    let mut s = String::new();
    let gs = g_levels(runs);
    let gmax = gs.last().copied().unwrap_or(5);
    for (motion, fig) in [
        (Motion::YLine, "Fig. 10 (y-axis motion, 150 mm)"),
        (Motion::XLine, "Fig. 12 (x-axis motion, 100 mm)"),
        (Motion::Triangle, "Fig. 14 (combined motion, legs only)"),
    ] {
        if !runs.iter().any(|r| r.motion == motion) {
            continue;
        }
        let _ = writeln!(s, "\n{fig}");
        let mut head = format!("{:<16}", "configuration");
        if motion != Motion::Triangle {
            for g in &gs {
                let _ = write!(head, " dL@{g}g[mm]");
            }
        }
        let _ = write!(
            head,
            " | mean area[mm2] | max dev@{gmax}g[mm] rms dev@{gmax}g[mm] max track@{gmax}g[mm]"
        );
        let _ = writeln!(s, "{head}");
        for cfg in configs(runs) {
            for corrected in [false, true] {
                let mut line = format!(
                    "{:<16}",
                    format!("{cfg} {}", if corrected { "(+)" } else { "(-)" })
                );
                let mut areas = Vec::new();
                for g in &gs {
                    if let Some(r) = find(runs, &cfg, motion, *g, corrected) {
                        if motion != Motion::Triangle {
                            let _ = write!(line, " {:>10.4}", r.metrics.length_dev_mm);
                        }
                        areas.push(r.metrics.area_mm2);
                    } else if motion != Motion::Triangle {
                        let _ = write!(line, " {:>10}", "-");
                    }
                }
                let mean = areas.iter().sum::<f64>() / areas.len().max(1) as f64;
                let _ = write!(line, " | {mean:>14.4} |");
                if let Some(r) = find(runs, &cfg, motion, gmax, corrected) {
                    let _ = write!(
                        line,
                        " {:>16.4} {:>16.4} {:>18.4}",
                        r.metrics.max_dev_mm, r.metrics.rms_dev_mm, r.metrics.max_track_mm
                    );
                }
                let _ = writeln!(s, "{line}");
            }
        }
    }
    let _ = writeln!(
        s,
        "\nCorrection at {gmax} g: (-) uncorrected -> (+) corrected, reduction in %"
    );
    let _ = writeln!(
        s,
        "{:<10} {:<9} | {:>22} | {:>22} | {:>22} | {:>22}",
        "config",
        "motion",
        "max path dev [mm]",
        "rms path dev [mm]",
        "area [mm2]",
        "max tracking [mm]"
    );
    for cfg in configs(runs) {
        for motion in [Motion::XLine, Motion::YLine, Motion::Triangle] {
            let (Some(a), Some(b)) = (
                find(runs, &cfg, motion, gmax, false),
                find(runs, &cfg, motion, gmax, true),
            ) else {
                continue;
            };
            let (ma, mb) = (&a.metrics, &b.metrics);
            // Below 1 um (the OC x-line, symmetric) a percentage means nothing.
            let cell = |x: f64, y: f64| {
                if x < 1e-3 {
                    format!("{x:.4}->{y:.4}   n/a")
                } else {
                    format!("{x:.4}->{y:.4} {:>5.1}%", reduction(x, y))
                }
            };
            let _ = writeln!(
                s,
                "{:<10} {:<9} | {:>22} | {:>22} | {:>22} | {:>22}",
                cfg,
                motion.label(),
                cell(ma.max_dev_mm, mb.max_dev_mm),
                cell(ma.rms_dev_mm, mb.rms_dev_mm),
                cell(ma.area_mm2, mb.area_mm2),
                cell(ma.max_track_mm, mb.max_track_mm)
            );
        }
    }
    s
}
