//! Static tests on an N-D grid from CSV (`std`), fitted into a
//! [`crate::compliance_map::GridMap`] (Eq. 10-13 per node): the grid's axes are named
//! by their columns.
//!
//! One reading a row. Columns:
//!
//! * one to four grid-axis columns `<name>_<unit>` with unit `m`, `mm` (positions) or `rad`,
//!   `deg` (joint angles), in grid-axis order: `x_mm, y_mm, z_mm` for a Delta's workspace,
//!   `q2_deg, q3_deg` for a serial arm's elbow; the axis is named `<name>` (`x`, `q2`);
//! * `force_axis`: `0..n_force` or `x, y, z, mx, my, mz`;
//! * `force`: force level (`force_unit`; moments `force_unit * length_unit`);
//! * displacement columns, those present in the order `dx, dy, dz` (`length_unit`),
//!   `rx, ry, rz` \[rad\]: they define the displacement axes.
//!
//! Every other column is refused by name, so a misspelt one is not dropped. Converted to SI.

use std::string::{String, ToString};
use std::vec::Vec;

use super::map_csv::{displacement_columns, displacements, force_of, number, read_csv, require};
use crate::compliance_map::{FitOptions, GridMap, GridMeasurement, MAX_GRID_DIMS, fit_grid};
use crate::error::LoadError;
use crate::units::{ForceUnit, LengthUnit};

/// The fixed (non-axis) columns.
const FIXED: [&str; 8] = ["force_axis", "force", "dx", "dy", "dz", "rx", "ry", "rz"];
/// Grid-axis column units and their scale to SI.
const UNITS: [(&str, f64); 4] = [
    ("_mm", 1e-3),
    ("_m", 1.0),
    ("_deg", core::f64::consts::PI / 180.0),
    ("_rad", 1.0),
];

/// A grid-axis column `<name>_<unit>`: its name and scale to SI.
fn axis_column(header: &str) -> Option<(String, f64)> {
    let lower = header.to_ascii_lowercase();
    UNITS.iter().find_map(|(suffix, scale)| {
        lower
            .strip_suffix(suffix)
            .filter(|name| !name.is_empty())
            .and_then(|_| header.get(..header.len() - suffix.len()))
            .map(|name| (name.to_string(), *scale))
    })
}

/// Fits a grid map from the static-test CSV `text` (see the module docs). `n_force` defaults
/// to the highest force axis + 1; `position_tolerance` (SI, per axis) groups coordinates into
/// grid lines.
pub fn fit_static_str(
    text: &str,
    force_unit: ForceUnit,
    length_unit: LengthUnit,
    n_force: Option<usize>,
    position_tolerance: f64,
) -> Result<GridMap, LoadError> {
    let (header, records) = read_csv(text)?;
    let mut axes: Vec<(usize, String, f64)> = Vec::new();
    for (c, h) in header.iter().enumerate() {
        if FIXED.iter().any(|k| h.eq_ignore_ascii_case(k)) {
            continue;
        }
        match axis_column(h) {
            // `x_mm` and `x_m` are one axis given twice.
            Some((name, _)) if axes.iter().any(|a| a.1.eq_ignore_ascii_case(&name)) => {
                return Err(LoadError::UnknownColumn {
                    column: std::format!("{h} (grid axis {name} a second time)"),
                });
            }
            Some((name, scale)) => axes.push((c, name, scale)),
            None => {
                return Err(LoadError::UnknownColumn {
                    column: h.to_string(),
                });
            }
        }
    }
    if axes.is_empty() {
        return Err(LoadError::MissingColumn {
            column: "a grid axis <name>_<m|mm|rad|deg>",
        });
    }
    if axes.len() > MAX_GRID_DIMS {
        return Err(LoadError::UnknownColumn {
            column: axes
                .get(MAX_GRID_DIMS)
                .map_or(String::new(), |a| a.1.clone())
                + " (a fifth grid axis; at most 4)",
        });
    }
    let (ca, cf) = (require(&header, "force_axis")?, require(&header, "force")?);
    let disp = displacement_columns(&header)?;
    let length = length_unit.to_metre();
    let newton = force_unit.to_newton();
    const AXIS: [&str; MAX_GRID_DIMS] =
        ["grid axis 0", "grid axis 1", "grid axis 2", "grid axis 3"];
    let mut readings = Vec::with_capacity(records.len());
    for (row, rec) in records.iter().enumerate() {
        let (force_axis, force) = force_of(rec, (ca, cf), row, newton, length)?;
        let mut point = [0.0; MAX_GRID_DIMS];
        for (slot, ((c, _, scale), what)) in point.iter_mut().zip(axes.iter().zip(AXIS)) {
            *slot = number(rec, *c, row, what)? * scale;
        }
        let d = displacements(rec, &disp, row, length)?;
        readings.push(GridMeasurement {
            point,
            force_axis,
            force,
            displacement: d,
        });
    }
    let n_force =
        n_force.unwrap_or_else(|| readings.iter().map(|m| m.force_axis + 1).max().unwrap_or(1));
    let names = axes.into_iter().map(|a| a.1).collect();
    Ok(fit_grid(
        names,
        &readings,
        &FitOptions {
            n_force,
            n_displacement: disp.len(),
            position_tolerance,
        },
    )?)
}

/// [`fit_static_str`] on the text of the file at `path`.
pub fn fit_static_path(
    path: impl AsRef<std::path::Path>,
    force_unit: ForceUnit,
    length_unit: LengthUnit,
    n_force: Option<usize>,
    position_tolerance: f64,
) -> Result<GridMap, LoadError> {
    fit_static_str(
        &super::read_text(path.as_ref())?,
        force_unit,
        length_unit,
        n_force,
        position_tolerance,
    )
}
