//! `fit`: a compliance map (Paksoy, Dede and Kiper (2025), sec. 3.1-3.2, Eq. 10-13) from a
//! static-test CSV read by deflect-core's loader, or from fresh simulated static tests, with
//! its held-out prediction error.

use std::path::Path;

use deflect_core::compliance_map::ComplianceMap;
use deflect_core::io::{map_csv, map_json};
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_sim::pipeline::{self, StaticOptions};
use deflect_sim::robot::{Head, RobotParams};
use deflect_sim::{SimError, write_file};

use super::calibrate::calibrate_all;
use super::{input_file, load_error};
use crate::cli::{CliError, Mech};

/// What `fit --input` expects.
const INPUT: &str =
    "static-test CSV written by `static-test` (columns x, y, force_axis, force, dx, dy)";

/// Reads and fits the CSV of `fit --input` before any work: the map, or a usage error (no
/// such regular file) or a failure (content) naming the file.
pub fn load_input(path: &Path) -> Result<ComplianceMap, CliError> {
    input_file("--input", path, INPUT)?;
    fit_csv(path).map_err(|e| load_error("--input", path, INPUT, e))
}

/// The map fitted from the static-test CSV at `path` (mm, N), with the scenario's options.
pub fn fit_csv(path: &Path) -> Result<ComplianceMap, deflect_core::LoadError> {
    map_csv::fit_static_path(
        path,
        ForceUnit::Newton,
        LengthUnit::Millimetre,
        Some(2),
        1e-6,
    )
    .map(|m| m.with_options(pipeline::map_options()))
}

/// The `fit` command: the map of `mech` fitted from `--input` (`input`, loaded by
/// [`load_input`]) or from fresh static tests, written to `out`.
pub fn fit_cmd(mech: Mech, input: Option<ComplianceMap>, out: &Path) -> Result<(), SimError> {
    let constraint = mech.constraint();
    let map = match input {
        None => calibrate_all(&[constraint], out)?
            .pop()
            .map(|(_, m)| m)
            .ok_or_else(|| SimError::new("no map"))?,
        Some(map) => {
            let tag = constraint.label().to_lowercase();
            write_file(
                &out.join(format!("compliance_map_{tag}.json")),
                "the compliance map JSON",
                map_json::to_string(&map)?,
            )?;
            let ho = pipeline::held_out(
                &RobotParams::new(constraint, Head::Upper),
                &map,
                &StaticOptions::default(),
            )?;
            say!(
                "{}: held-out RMS {:.4} mm (cell centres), leave-one-line-out RMS y {:.4} mm",
                constraint.label(),
                ho.centre_rms * 1e3,
                ho.loo_rms_y * 1e3
            );
            map
        }
    };
    say!(
        "map: {} x {} nodes, written to {}",
        map.x().len(),
        map.y().len(),
        out.display()
    );
    Ok(())
}
