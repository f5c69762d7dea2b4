//! A tool path as a CSV of points (`std`): what robot offline-programming tools and scripts
//! export when there is no G-code. Each row is a straight move of the tool tip, in the
//! workpiece frame, from the previous row's point (the first from
//! [`super::gcode::GcodeOptions::start`]) to its own:
//!
//! | column | unit | meaning |
//! |---|---|---|
//! | `x_mm`, `y_mm`, `z_mm` (or `x_m`, `y_m`, `z_m`) | mm (m) | the point |
//! | `feed_mm_min` (or `feed_m_s`) | mm/min (m/s) | feed of the move; 0 for a rapid move |
//! | `spindle_rpm` | rev/min | spindle speed during the move (0: off) |
//! | `i`, `j`, `k` (optional, all three) | 1 | the tool axis at the point, tip towards spindle (a five-axis path; normalised within [`super::apt::AXIS_NORM_TOLERANCE`] of unit length, refused beyond); without them the axis is the workpiece's `+z` |
//!
//! Every other column is required (a point file that leaves the spindle out would leave the
//! force model guessing); an unknown column is refused. Between two rows the axis turns along
//! the great circle; the tool stands at the start as the first row holds it. Moves name their CSV line (the header is line 1) in every
//! later error. At most [`crate::machining::MAX_MOVES`] rows.

use std::path::Path;
use std::vec::Vec;

use nalgebra::Vector3;

use super::gcode::GcodeOptions;
use super::map_csv::{check_columns, column, number, read_csv, require};
use crate::error::LoadError;
use crate::machining::{MAX_MOVES, Motion, Move, Program};

const COLUMNS: [&str; 12] = [
    "x_mm",
    "y_mm",
    "z_mm",
    "x_m",
    "y_m",
    "z_m",
    "feed_mm_min",
    "feed_m_s",
    "spindle_rpm",
    "i",
    "j",
    "k",
];

/// A column in mm (scale 1e-3) or in m.
fn either(
    header: &csv::StringRecord,
    mm: &'static str,
    m: &'static str,
    mm_scale: f64,
) -> Result<Quantity, LoadError> {
    match (column(header, mm), column(header, m)) {
        (Some(c), None) => Ok((c, mm_scale, mm)),
        (None, Some(c)) => Ok((c, 1.0, m)),
        (Some(_), Some(_)) => Err(LoadError::UnknownColumn {
            column: std::format!("{m} (given with {mm}: one unit per quantity)"),
        }),
        (None, None) => Err(LoadError::MissingColumn { column: mm }),
    }
}

/// A quantity's column: its index, the scale of its values to SI and its name.
type Quantity = (usize, f64, &'static str);

/// Where a points CSV keeps each quantity.
struct Columns {
    /// The point (scaled to m).
    x: Quantity,
    y: Quantity,
    z: Quantity,
    /// The feed (scaled to m/s).
    feed: Quantity,
    /// `spindle_rpm` \[rev/min\].
    spindle: usize,
    /// `i`, `j`, `k`, the tool axis, when given.
    axis: Option<(usize, usize, usize)>,
}

/// The columns of `header` (every one checked known, the required ones present).
fn columns(header: &csv::StringRecord) -> Result<Columns, LoadError> {
    check_columns(header, &COLUMNS)?;
    let x = either(header, "x_mm", "x_m", 1e-3)?;
    let y = either(header, "y_mm", "y_m", 1e-3)?;
    let z = either(header, "z_mm", "z_m", 1e-3)?;
    let feed = either(header, "feed_mm_min", "feed_m_s", 1e-3 / 60.0)?;
    let spindle = require(header, "spindle_rpm")?;
    let axis = axis_columns(header)?;
    Ok(Columns {
        x,
        y,
        z,
        feed,
        spindle,
        axis,
    })
}

/// The tool axis columns `i`, `j`, `k`: all three or none (the first missing one named).
fn axis_columns(header: &csv::StringRecord) -> Result<Option<(usize, usize, usize)>, LoadError> {
    match (
        column(header, "i"),
        column(header, "j"),
        column(header, "k"),
    ) {
        (Some(i), Some(j), Some(k)) => Ok(Some((i, j, k))),
        (None, None, None) => Ok(None),
        (i, j, _) => Err(LoadError::MissingColumn {
            column: if i.is_none() {
                "i"
            } else if j.is_none() {
                "j"
            } else {
                "k"
            },
        }),
    }
}

/// A row's values within the limits every program holds: the point `end` \[m\], the feed
/// `f` \[m/s\] (of column `feed_name`) and the spindle speed `s` \[rev/min\].
fn check_row(
    row: usize,
    end: &Vector3<f64>,
    (f, feed_name): (f64, &'static str),
    s: f64,
) -> Result<(), LoadError> {
    let (c, fm, sm) = (
        super::gcode::MAX_COORDINATE,
        super::gcode::MAX_FEED,
        super::gcode::MAX_SPINDLE_RPM,
    );
    for (ok, field, expected, got) in [
        (
            end.iter().all(|v| v.abs() <= c),
            "x, y, z",
            std::format!("within +-{c} m"),
            std::format!("({}, {}, {}) m", end.x, end.y, end.z),
        ),
        (
            (0.0..=fm).contains(&f),
            feed_name,
            std::format!("0..={fm} m/s"),
            std::format!("{f} m/s"),
        ),
        (
            (0.0..=sm).contains(&s),
            "spindle_rpm",
            std::format!("0..={sm} rpm"),
            std::format!("{s} rpm"),
        ),
    ] {
        if !ok {
            return Err(LoadError::InvalidValue {
                element: std::format!("points row {row}"),
                field,
                expected,
                got,
            });
        }
    }
    Ok(())
}

/// The tool axis at a row: its `i`, `j`, `k` normalised (within
/// [`super::apt::AXIS_NORM_TOLERANCE`] of unit length), or `axis`, the previous one, without
/// those columns.
fn row_axis(
    rec: &csv::StringRecord,
    row: usize,
    columns: Option<(usize, usize, usize)>,
    axis: Vector3<f64>,
) -> Result<Vector3<f64>, LoadError> {
    let Some((i, j, k)) = columns else {
        return Ok(axis);
    };
    let v = Vector3::new(
        number(rec, i, row, "i")?,
        number(rec, j, row, "j")?,
        number(rec, k, row, "k")?,
    );
    let n = v.norm();
    if n == 0.0 || (n - 1.0).abs() > super::apt::AXIS_NORM_TOLERANCE {
        return Err(LoadError::InvalidValue {
            element: std::format!("points row {row}"),
            field: "i, j, k",
            expected: "a unit tool vector (within AXIS_NORM_TOLERANCE, 1e-3)".into(),
            got: std::format!("({}, {}, {}), length {n}", v.x, v.y, v.z),
        });
    }
    Ok(v / n)
}

/// Reads the points from CSV text (see the module docs); `options.start` is where the tool
/// is before the first row (`options.units` is unused: the columns name their units).
pub fn from_str(text: &str, options: &GcodeOptions) -> Result<Program, LoadError> {
    super::gcode::check_start(&options.start)?;
    let (header, records) = read_csv(text)?;
    let cols = columns(&header)?;
    if records.len() > MAX_MOVES {
        return Err(LoadError::TooLarge {
            what: "points (rows)".into(),
            limit: MAX_MOVES,
            got: records.len(),
        });
    }
    let mut moves = Vec::with_capacity(records.len());
    let mut at = options.start;
    let mut axis = Vector3::z();
    for (row, rec) in records.iter().enumerate() {
        let get = |(col, scale, name): Quantity| number(rec, col, row, name).map(|v| v * scale);
        let end = Vector3::new(get(cols.x)?, get(cols.y)?, get(cols.z)?);
        let f = get(cols.feed)?;
        let s = number(rec, cols.spindle, row, "spindle_rpm")?;
        check_row(row, &end, (f, cols.feed.2), s)?;
        let line = rec
            .position()
            .map_or(row + 2, |p| usize::try_from(p.line()).unwrap_or(usize::MAX));
        let end_axis = row_axis(rec, row, cols.axis, axis)?;
        let motion = if f > 0.0 {
            Motion::Linear
        } else {
            Motion::Rapid
        };
        moves.push(Move {
            spindle: s / 60.0,
            // The tool stands at the start as the first row holds it.
            start_axis: if row == 0 { end_axis } else { axis },
            end_axis,
            ..Move::new(line, motion, at, end, f)
        });
        at = end;
        axis = end_axis;
    }
    Ok(Program {
        moves,
        operations: Vec::new(),
    })
}

/// Reads a points CSV file (at most [`super::MAX_FILE_BYTES`]).
pub fn from_path(path: impl AsRef<Path>, options: &GcodeOptions) -> Result<Program, LoadError> {
    from_str(&super::read_text(path.as_ref())?, options)
}
