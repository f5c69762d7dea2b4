//! Compliance maps from CSV (`std`): the paper's coefficient tables (Paksoy et al. 2025,
//! Appendix A, Tables II/III) and static-test tables to fit (Eq. 10-13). File units are
//! explicit parameters and are converted to SI here.

use std::path::Path;
use std::string::ToString;
use std::vec;
use std::vec::Vec;

use crate::compliance_map::{ComplianceMap, FitOptions, MAX_AXES, Measurement, fit};
use crate::error::{BuildError, LoadError};
use crate::units::{ForceUnit, LengthUnit};

/// Coefficient columns of the paper's tables, in the order (d, f) = (0,0), (0,1), (1,0),
/// (1,1): `dx = (m Fx + n) + (o Fy + p)`, `dy = (s Fx + u) + (v Fy + w)`.
const SLOPE_COLUMNS: [&str; 4] = ["m", "o", "s", "v"];
const OFFSET_COLUMNS: [&str; 4] = ["n", "p", "u", "w"];
/// Displacement columns of a static-test CSV and whether they are lengths (else radians).
const DISP_COLUMNS: [(&str, bool); MAX_AXES] = [
    ("dx", true),
    ("dy", true),
    ("dz", true),
    ("rx", false),
    ("ry", false),
    ("rz", false),
];
const AXIS_NAMES: [&str; MAX_AXES] = ["x", "y", "z", "mx", "my", "mz"];

pub(super) fn csv_err(e: &csv::Error) -> LoadError {
    LoadError::Csv {
        line: e.position().map(|p| p.line()),
        message: e.to_string(),
    }
}

/// Refuses a header column outside `known` (a misspelt `dx` must not be dropped silently).
pub(super) fn check_columns(header: &csv::StringRecord, known: &[&str]) -> Result<(), LoadError> {
    match header
        .iter()
        .find(|h| !known.iter().any(|k| h.eq_ignore_ascii_case(k)))
    {
        Some(h) => Err(LoadError::UnknownColumn {
            column: h.to_string(),
        }),
        None => Ok(()),
    }
}

/// Columns of the paper's coefficient tables (`i, j` are the grid indices, read and unused).
const PAPER_COLUMNS: [&str; 16] = [
    "i", "j", "x_mm", "y_mm", "x_m", "y_m", "x", "y", "m", "n", "o", "p", "s", "u", "v", "w",
];
/// Columns of a static-test table.
const STATIC_COLUMNS: [&str; 10] = [
    "x",
    "y",
    "force_axis",
    "force",
    "dx",
    "dy",
    "dz",
    "rx",
    "ry",
    "rz",
];

/// Header and records of a CSV text, fields trimmed.
pub(super) fn read_csv(
    text: &str,
) -> Result<(csv::StringRecord, Vec<csv::StringRecord>), LoadError> {
    super::check_size("CSV", text)?;
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let header = rdr.headers().map_err(|e| csv_err(&e))?.clone();
    // A column given twice would be read once and the other copy dropped.
    for (k, h) in header.iter().enumerate() {
        if header.iter().take(k).any(|p| p.eq_ignore_ascii_case(h)) {
            return Err(LoadError::UnknownColumn {
                column: std::format!("{h} (a second time: each column once)"),
            });
        }
    }
    let records = rdr
        .records()
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| csv_err(&e))?;
    Ok((header, records))
}

pub(super) fn column(header: &csv::StringRecord, name: &str) -> Option<usize> {
    header.iter().position(|h| h.eq_ignore_ascii_case(name))
}

pub(super) fn require(header: &csv::StringRecord, name: &'static str) -> Result<usize, LoadError> {
    column(header, name).ok_or(LoadError::MissingColumn { column: name })
}

pub(super) fn number(
    rec: &csv::StringRecord,
    col: usize,
    row: usize,
    name: &'static str,
) -> Result<f64, LoadError> {
    let v: f64 = rec
        .get(col)
        .and_then(|s| s.parse().ok())
        .ok_or(LoadError::BadNumber { row, column: name })?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(LoadError::NonFiniteCell { row, column: name })
    }
}

/// A position column: `<axis>_mm` (always mm), `<axis>_m` (always m) or `<axis>` (in
/// `length`). Returns the column and its scale to metres.
fn position_column(
    header: &csv::StringRecord,
    names: [&'static str; 3],
    length: LengthUnit,
) -> Result<(usize, f64, &'static str), LoadError> {
    let [mm, m, bare] = names;
    if let Some(c) = column(header, mm) {
        Ok((c, 1e-3, mm))
    } else if let Some(c) = column(header, m) {
        Ok((c, 1.0, m))
    } else {
        Ok((require(header, bare)?, length.to_metre(), bare))
    }
}

/// Loads a coefficient table in the layout of the paper's Tables II/III (Appendix A):
/// columns `x_mm, y_mm` (or `x_m, y_m`, or `x, y` in `length_unit`) and
/// `m, n, o, p, s, u, v, w` with `dx = (m Fx + n) + (o Fy + p)`,
/// `dy = (s Fx + u) + (v Fy + w)` (other columns such as `i, j` are ignored).
///
/// `length_unit` is the unit of the displacements (and offsets); `force_unit` that of the
/// force the lines were fitted in (the paper does not say; its forces were 5..25 kgf).
/// Conversion to SI: `slope [m/N] = c * length / force`, `offset [m] = c * length`. Rows
/// may come in any order; every node of the grid must appear exactly once. `#` starts a
/// comment line. The result is a 2-force, 2-displacement map.
pub fn from_str(
    text: &str,
    force_unit: ForceUnit,
    length_unit: LengthUnit,
) -> Result<ComplianceMap, LoadError> {
    let (header, records) = read_csv(text)?;
    check_columns(&header, &PAPER_COLUMNS)?;
    let (cx, sx, nx_name) = position_column(&header, ["x_mm", "x_m", "x"], length_unit)?;
    let (cy, sy, ny_name) = position_column(&header, ["y_mm", "y_m", "y"], length_unit)?;
    let slope_cols = SLOPE_COLUMNS.map(|c| require(&header, c));
    let offset_cols = OFFSET_COLUMNS.map(|c| require(&header, c));
    let mut rows: Vec<(f64, f64, [f64; 4], [f64; 4])> = Vec::with_capacity(records.len());
    let length = length_unit.to_metre();
    let slope_scale = length / force_unit.to_newton();
    for (row, rec) in records.iter().enumerate() {
        let x = number(rec, cx, row, nx_name)? * sx;
        let y = number(rec, cy, row, ny_name)? * sy;
        let mut s = [0.0; 4];
        let mut o = [0.0; 4];
        for k in 0..4 {
            let (Some(sc), Some(oc), Some(sn), Some(on)) = (
                slope_cols.get(k),
                offset_cols.get(k),
                SLOPE_COLUMNS.get(k),
                OFFSET_COLUMNS.get(k),
            ) else {
                continue;
            };
            let (sc, oc) = (sc.clone()?, oc.clone()?);
            if let Some(v) = s.get_mut(k) {
                *v = number(rec, sc, row, sn)? * slope_scale;
            }
            if let Some(v) = o.get_mut(k) {
                *v = number(rec, oc, row, on)? * length;
            }
        }
        rows.push((x, y, s, o));
    }
    // Group coordinates into grid lines (1 nm tolerance: the table's digits are exact).
    let xs: Vec<f64> = rows.iter().map(|r| r.0).collect();
    let ys: Vec<f64> = rows.iter().map(|r| r.1).collect();
    let ms: Vec<Measurement> = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| Measurement::new(*x, *y, 0, 0.0, &[]))
        .collect();
    let (gx, gy, node_of) = crate::compliance_map::grid_of(&ms, 1e-9)?;
    let ny = gy.len();
    let mut first_row = vec![None; gx.len() * ny];
    let mut slopes = vec![0.0; gx.len() * ny * 4];
    let mut offsets = vec![0.0; gx.len() * ny * 4];
    for (row, ((_, _, s, o), node)) in rows.iter().zip(&node_of).enumerate() {
        match first_row.get_mut(*node) {
            Some(Some(previous_row)) => {
                return Err(LoadError::Build(BuildError::DuplicateNode {
                    row,
                    previous_row: *previous_row,
                }));
            }
            Some(slot) => *slot = Some(row),
            None => {}
        }
        if let Some(dst) = slopes.get_mut(node * 4..node * 4 + 4) {
            dst.copy_from_slice(s);
        }
        if let Some(dst) = offsets.get_mut(node * 4..node * 4 + 4) {
            dst.copy_from_slice(o);
        }
    }
    Ok(ComplianceMap::new(gx, gy, 2, 2, slopes, offsets)?)
}

/// The displacement columns present, in the order `dx, dy, dz, rx, ry, rz`, with whether each
/// is a length (else radians); at least one.
pub(super) fn displacement_columns(
    header: &csv::StringRecord,
) -> Result<Vec<(usize, &'static str, bool)>, LoadError> {
    let disp: Vec<(usize, &'static str, bool)> = DISP_COLUMNS
        .iter()
        .filter_map(|(name, is_len)| column(header, name).map(|c| (c, *name, *is_len)))
        .collect();
    if disp.is_empty() {
        return Err(LoadError::MissingColumn { column: "dx" });
    }
    Ok(disp)
}

/// A row's loaded force axis (`0..6` or `x, y, z, mx, my, mz`) and force level in SI (`newton`
/// per file unit; moments also `length` per file unit), from columns `(axis, force)`.
pub(super) fn force_of(
    rec: &csv::StringRecord,
    (ca, cf): (usize, usize),
    row: usize,
    newton: f64,
    length: f64,
) -> Result<(usize, f64), LoadError> {
    let text = rec.get(ca).unwrap_or("");
    let axis = text
        .parse::<usize>()
        .ok()
        .or_else(|| AXIS_NAMES.iter().position(|n| n.eq_ignore_ascii_case(text)))
        .filter(|a| *a < MAX_AXES)
        .ok_or(LoadError::BadNumber {
            row,
            column: "force_axis",
        })?;
    let scale = if axis >= 3 { newton * length } else { newton };
    Ok((axis, number(rec, cf, row, "force")? * scale))
}

/// A row's displacements in SI from the `columns` of [`displacement_columns`].
pub(super) fn displacements(
    rec: &csv::StringRecord,
    columns: &[(usize, &'static str, bool)],
    row: usize,
    length: f64,
) -> Result<[f64; MAX_AXES], LoadError> {
    let mut d = [0.0; MAX_AXES];
    for (slot, (c, name, is_len)) in d.iter_mut().zip(columns) {
        *slot = number(rec, *c, row, name)? * if *is_len { length } else { 1.0 };
    }
    Ok(d)
}

/// Fits a map (Eq. 10-13, see [`fit()`]) from a CSV of static tests, one reading a row:
///
/// * `x`, `y`: node position (`length_unit`);
/// * `force_axis`: `0..n_force` or `x, y, z, mx, my, mz`;
/// * `force`: force level (`force_unit`) (moments: `force_unit * length_unit`);
/// * displacement columns, those present in the order `dx, dy, dz` (`length_unit`),
///   `rx, ry, rz` \[rad\]: they define the displacement axes.
///
/// `n_force` defaults to the highest force axis + 1 (at least 1). `position_tolerance` \[m\]
/// groups coordinates into grid lines.
pub fn fit_static_str(
    text: &str,
    force_unit: ForceUnit,
    length_unit: LengthUnit,
    n_force: Option<usize>,
    position_tolerance: f64,
) -> Result<ComplianceMap, LoadError> {
    let (header, records) = read_csv(text)?;
    check_columns(&header, &STATIC_COLUMNS)?;
    let (cx, cy) = (require(&header, "x")?, require(&header, "y")?);
    let (ca, cf) = (require(&header, "force_axis")?, require(&header, "force")?);
    let disp = displacement_columns(&header)?;
    let length = length_unit.to_metre();
    let newton = force_unit.to_newton();
    let mut ms = Vec::with_capacity(records.len());
    for (row, rec) in records.iter().enumerate() {
        let (force_axis, force) = force_of(rec, (ca, cf), row, newton, length)?;
        let d = displacements(rec, &disp, row, length)?;
        ms.push(Measurement {
            x: number(rec, cx, row, "x")? * length,
            y: number(rec, cy, row, "y")? * length,
            force_axis,
            force,
            displacement: d,
        });
    }
    let n_force = n_force.unwrap_or_else(|| ms.iter().map(|m| m.force_axis + 1).max().unwrap_or(1));
    Ok(fit(
        &ms,
        &FitOptions {
            n_force,
            n_displacement: disp.len(),
            position_tolerance,
        },
    )?)
}

/// [`from_str`] on the text of the file at `path`.
pub fn from_path(
    path: impl AsRef<Path>,
    force_unit: ForceUnit,
    length_unit: LengthUnit,
) -> Result<ComplianceMap, LoadError> {
    from_str(&super::read_text(path.as_ref())?, force_unit, length_unit)
}

/// [`fit_static_str`] on the text of the file at `path`.
pub fn fit_static_path(
    path: impl AsRef<Path>,
    force_unit: ForceUnit,
    length_unit: LengthUnit,
    n_force: Option<usize>,
    position_tolerance: f64,
) -> Result<ComplianceMap, LoadError> {
    fit_static_str(
        &super::read_text(path.as_ref())?,
        force_unit,
        length_unit,
        n_force,
        position_tolerance,
    )
}
