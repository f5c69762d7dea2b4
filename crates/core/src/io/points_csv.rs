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
) -> Result<(usize, f64, &'static str), LoadError> {
    match (column(header, mm), column(header, m)) {
        (Some(c), None) => Ok((c, mm_scale, mm)),
        (None, Some(c)) => Ok((c, 1.0, m)),
        (Some(_), Some(_)) => Err(LoadError::UnknownColumn {
            column: std::format!("{m} (given with {mm}: one unit per quantity)"),
        }),
        (None, None) => Err(LoadError::MissingColumn { column: mm }),
    }
}

/// Reads the points from CSV text (see the module docs); `options.start` is where the tool
/// is before the first row (`options.units` is unused: the columns name their units).
pub fn from_str(text: &str, options: &GcodeOptions) -> Result<Program, LoadError> {
    super::gcode::check_start(&options.start)?;
    let (header, records) = read_csv(text)?;
    check_columns(&header, &COLUMNS)?;
    let x = either(&header, "x_mm", "x_m", 1e-3)?;
    let y = either(&header, "y_mm", "y_m", 1e-3)?;
    let z = either(&header, "z_mm", "z_m", 1e-3)?;
    let feed = either(&header, "feed_mm_min", "feed_m_s", 1e-3 / 60.0)?;
    let spindle = require(&header, "spindle_rpm")?;
    let axis_columns = match (
        column(&header, "i"),
        column(&header, "j"),
        column(&header, "k"),
    ) {
        (Some(i), Some(j), Some(k)) => Some((i, j, k)),
        (None, None, None) => None,
        (i, j, _) => {
            return Err(LoadError::MissingColumn {
                column: if i.is_none() {
                    "i"
                } else if j.is_none() {
                    "j"
                } else {
                    "k"
                },
            });
        }
    };
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
        let get = |(col, scale, name): (usize, f64, &'static str)| {
            number(rec, col, row, name).map(|v| v * scale)
        };
        let end = Vector3::new(get(x)?, get(y)?, get(z)?);
        let f = get(feed)?;
        let s = number(rec, spindle, row, "spindle_rpm")?;
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
                feed.2,
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
        let line = rec
            .position()
            .map_or(row + 2, |p| usize::try_from(p.line()).unwrap_or(usize::MAX));
        let end_axis = match axis_columns {
            None => axis,
            Some((i, j, k)) => {
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
                v / n
            }
        };
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
