//! `fit`: a compliance map (Paksoy, Dede and Kiper (2025), sec. 3.1-3.2, Eq. 10-13) from a
//! static-test CSV read by deflect-core's loader, or from fresh simulated static tests, with
//! its held-out prediction error.

use std::io::Read as _;
use std::path::Path;

use deflect_core::compliance_map::ComplianceMap;
use deflect_core::io::{map_csv, map_json};
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_sim::scenes::parallel::params::{Head, RobotParams};
use deflect_sim::scenes::parallel::run::{self, StaticOptions};
use deflect_sim::{SimError, write_file};

use super::Cmd;
use super::calibrate_all;
use super::inputs::{input_file, load_error};
use crate::cli::{CliError, FitArgs};

/// What `fit --input` expects.
const INPUT: &str = "static-test CSV written by `static-test` (columns x_mm, y_mm, force_axis, \
                     force_N, dx_mm, dy_mm; or the older x, y, force_axis, force, dx, dy in mm, N)";

/// Largest static-test CSV read \[bytes\] (deflect-core's loader budget).
const MAX_CSV: u64 = 16 << 20;

/// The header of a static-test CSV with units in the column names (`x_mm`, `force_N`, ...)
/// rewritten to the loader's bare names, with the length unit; `None` for the older header
/// without units (mm, N) or anything else (left to the loader's checks).
pub fn unit_header(header: &str) -> Option<(String, LengthUnit)> {
    let cols: Vec<String> = header
        .split(',')
        .map(|c| c.trim().to_ascii_lowercase())
        .collect();
    let unit = match cols.first().map(String::as_str) {
        Some("x_mm") => ("_mm", LengthUnit::Millimetre),
        Some("x_m") => ("_m", LengthUnit::Metre),
        _ => return None,
    };
    let bare: Vec<String> = cols
        .iter()
        .map(|c| {
            let stem = c
                .strip_suffix(unit.0)
                .filter(|s| ["x", "y", "dx", "dy", "dz"].contains(s));
            let stem = stem.or_else(|| c.strip_suffix("_rad").filter(|s| s.starts_with('r')));
            let stem = stem.or_else(|| c.strip_suffix("_n").filter(|s| *s == "force"));
            stem.unwrap_or(c).to_string()
        })
        .collect();
    Some((bare.join(","), unit.1))
}

/// Reads and fits the CSV of `fit --input` before any work: the map, or a usage error (no
/// such regular file) or a failure (content) naming the file.
pub fn load_input(path: &Path) -> Result<ComplianceMap, CliError> {
    input_file("--input", path, INPUT)?;
    fit_csv(path).map_err(|e| load_error("--input", path, INPUT, e))
}

/// The map fitted from the static-test CSV at `path` (header with units, [`unit_header`],
/// or the older one in mm and N), with the scenario's options.
pub fn fit_csv(path: &Path) -> Result<ComplianceMap, deflect_core::LoadError> {
    use std::io::BufRead;
    let io = |e: std::io::Error| deflect_core::LoadError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let mut first = String::new();
    std::io::BufReader::new(std::fs::File::open(path).map_err(io)?)
        .take(4096)
        .read_line(&mut first)
        .map_err(io)?;
    let map = match unit_header(first.trim_end()) {
        None => map_csv::fit_static_path(
            path,
            ForceUnit::Newton,
            LengthUnit::Millimetre,
            Some(2),
            1e-6,
        )?,
        Some((header, unit)) => {
            let len = std::fs::metadata(path).map_err(io)?.len();
            if len > MAX_CSV {
                return Err(deflect_core::LoadError::TooLarge {
                    what: "CSV size".into(),
                    limit: MAX_CSV as usize,
                    got: usize::try_from(len).unwrap_or(usize::MAX),
                });
            }
            let text = std::fs::read_to_string(path).map_err(io)?;
            let body = text.split_once('\n').map_or("", |(_, b)| b);
            map_csv::fit_static_str(
                &format!("{header}\n{body}"),
                ForceUnit::Newton,
                unit,
                Some(2),
                1e-6,
            )?
        }
    };
    Ok(map.with_options(run::map_options()))
}

/// The `fit` command: the map of `mech` fitted from `--input` (`input`, loaded by
/// [`load_input`]) or from fresh static tests, written to `out`.
fn run(a: &FitArgs, input: Option<ComplianceMap>, out: &Path) -> Result<(), SimError> {
    let constraint = a.mechanism.constraint();
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
            let ho = run::held_out(
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

impl Cmd for FitArgs {
    type Input = Option<ComplianceMap>;

    fn load(&self) -> Result<Option<ComplianceMap>, CliError> {
        self.input.as_deref().map(load_input).transpose()
    }

    fn run(&self, input: Option<ComplianceMap>, out: &Path) -> Result<(), SimError> {
        run(self, input, out)
    }
}
