//! `run`: one motion on one configuration, uncorrected and/or corrected with the D'Alembert
//! correction (Paksoy, Dede and Kiper (2025), sec. 3.3, Eq. 5); prints its figures and writes
//! an MCAP log, a plot and the runs as JSON.

use std::path::Path;
use std::time::Instant;

use deflect_core::compliance_map::ComplianceMap;
use deflect_core::io::map_json;
use deflect_sim::pipeline::{self, RunOptions, RunResult};
use deflect_sim::robot::RobotParams;
use deflect_sim::{SimError, output, write_file};

use super::calibrate::calibrate_all;
use super::{input_file, load_error};
use crate::cli::{CliError, Correction, RunArgs};

/// What `run --map` expects.
const MAP: &str = "compliance map JSON written by `fit`";

/// Loads the map of `run --map` before any work (checked even with `--correction off`).
pub fn load_map(path: &Path) -> Result<ComplianceMap, CliError> {
    input_file("--map", path, MAP)?;
    map_json::from_path(path).map_err(|e| load_error("--map", path, MAP, e))
}

/// The `run` command; `map` is the loaded `--map`, if given.
pub fn run_one(args: &RunArgs, map: Option<ComplianceMap>, out: &Path) -> Result<(), SimError> {
    let head = args.head.head();
    let constraint = args.mechanism.constraint();
    let params = RobotParams::new(constraint, head);
    let motion = args.motion.motion();
    let map = if args.correction == Correction::Off {
        None
    } else if map.is_some() {
        map
    } else {
        calibrate_all(&[constraint], out)?.pop().map(|(_, m)| m)
    };
    let opts = RunOptions {
        mass: args.mass,
        ..Default::default()
    };
    let mut runs = Vec::new();
    for corrected in [false, true] {
        let wanted = match args.correction {
            Correction::Off => !corrected,
            Correction::On => corrected,
            Correction::Both => true,
        };
        if wanted {
            let t = Instant::now();
            let r = pipeline::run(
                &params,
                motion,
                args.g,
                map.as_ref().filter(|_| corrected),
                &opts,
            )?;
            let sim = r.samples.last().map_or(0.0, |s| s.t);
            say!(
                "{} {} {} g {}: max path dev {:.4} mm, RMS {:.4} mm, area {:.4} mm2, length dev \
                 {:.4} mm, max tracking {:.4} mm ({:.1}x real time)",
                r.config,
                motion.label(),
                r.g,
                if corrected {
                    "corrected"
                } else {
                    "uncorrected"
                },
                r.metrics.max_dev_mm,
                r.metrics.rms_dev_mm,
                r.metrics.area_mm2,
                r.metrics.length_dev_mm,
                r.metrics.max_track_mm,
                sim / t.elapsed().as_secs_f64()
            );
            runs.push(r);
        }
    }
    let refs: Vec<&RunResult> = runs.iter().collect();
    let name = format!(
        "run_{}_{}_{}_{}g",
        constraint.label().to_lowercase(),
        head.label().to_lowercase(),
        motion.label(),
        args.g
    );
    let mcap_path = out.join(format!("{name}.mcap"));
    let n = output::write_mcap(&mcap_path, &refs, runs.len() > 1)?;
    output::plot_paths(&out.join(format!("{name}.png")), &name, &refs)?;
    write_file(
        &out.join(format!("{name}.json")),
        "the runs JSON",
        serde_json::to_string_pretty(&runs)?,
    )?;
    say!("{} messages in {}", n, mcap_path.display());
    Ok(())
}
