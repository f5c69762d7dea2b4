//! A program's pickled state: its moves, word report, tool axes and cutters as plain values
//! (`GcodeProgram.__reduce__` and `_from_state`).

use deflect_core::io::apt::AptCutter;
use deflect_core::machining::tools::ToolShape;
use deflect_core::machining::{Motion, Move, PathControl, Plane};
use nalgebra::Vector3;
use pyo3::prelude::*;

use crate::InputError;

/// One move as pickled: line, kind (0 rapid, 1 linear, 2 arc, 3 dwell), start, end, arc
/// centre (NaN for other moves), (plane 0 xy / 1 zx / 2 yz, sweep [rad] or dwell [s]),
/// (feed, spindle, tool), (path control 0 G61 / 1 G61.1 / 2 G64, P, Q).
pub(crate) type MoveState = (
    usize,
    u8,
    [f64; 3],
    [f64; 3],
    [f64; 3],
    (u8, f64),
    (f64, f64, u32),
    (u8, f64, f64),
);

/// A word of the report: word, status, count, first line, meaning.
pub(crate) type WordState = (String, String, usize, usize, String);

/// A program as pickled: its moves and its word report.
pub(crate) type ProgramState = (
    Vec<MoveState>,
    Vec<WordState>,
    Vec<(String, usize)>,
    Vec<([f64; 3], [f64; 3])>,
    Vec<CutterState>,
);

/// A cutter as pickled: line, tool, diameter [m], corner radius [m] (0 flat, d/2 ball).
pub(crate) type CutterState = (usize, u32, f64, f64);

/// A cutter's corner radius \[m\] (0 flat, half the diameter for a ball).
pub(crate) fn corner(c: &AptCutter) -> f64 {
    match c.shape {
        ToolShape::Flat => 0.0,
        ToolShape::Ball => 0.5 * c.diameter,
        ToolShape::BullNose { corner_radius } => corner_radius,
    }
}

pub(crate) fn move_state(m: &Move) -> MoveState {
    let nan = [f64::NAN; 3];
    let (kind, center, plane, sweep) = match m.motion {
        Motion::Rapid => (0u8, nan, 0u8, 0.0),
        Motion::Linear => (1, nan, 0, 0.0),
        Motion::Arc {
            plane,
            center,
            sweep,
        } => (
            2,
            center.into(),
            match plane {
                Plane::Xy => 0,
                Plane::Zx => 1,
                Plane::Yz => 2,
            },
            sweep,
        ),
        Motion::Dwell { seconds } => (3, nan, 0, seconds),
    };
    let control = match m.path_control {
        PathControl::ExactPath => (0u8, 0.0, 0.0),
        PathControl::ExactStop => (1, 0.0, 0.0),
        PathControl::Blend {
            tolerance,
            naive_tolerance,
        } => (2, tolerance, naive_tolerance),
    };
    (
        m.line,
        kind,
        m.start.into(),
        m.end.into(),
        center,
        (plane, sweep),
        (m.feed, m.spindle, m.tool),
        control,
    )
}

pub(crate) fn from_move_state(i: usize, s: MoveState) -> PyResult<Move> {
    let (line, kind, start, end, center, (plane, sweep), (feed, spindle, tool), (control, p, q)) =
        s;
    let bad = |what: &str, got: u8, expected: &str| {
        InputError::new_err(format!(
            "pickled program, move {i}: {what} {got}; expected {expected}"
        ))
    };
    let plane = match plane {
        0 => Plane::Xy,
        1 => Plane::Zx,
        2 => Plane::Yz,
        k => return Err(bad("plane", k, "0 (xy), 1 (zx) or 2 (yz)")),
    };
    let motion = match kind {
        0 => Motion::Rapid,
        1 => Motion::Linear,
        2 => Motion::Arc {
            plane,
            center: Vector3::from(center),
            sweep,
        },
        3 => Motion::Dwell { seconds: sweep },
        k => {
            return Err(bad(
                "kind",
                k,
                "0 (rapid), 1 (linear), 2 (arc) or 3 (dwell)",
            ));
        }
    };
    let path_control = match control {
        0 => PathControl::ExactPath,
        1 => PathControl::ExactStop,
        2 => PathControl::Blend {
            tolerance: p,
            naive_tolerance: q,
        },
        k => return Err(bad("path control", k, "0 (G61), 1 (G61.1) or 2 (G64)")),
    };
    Ok(Move {
        spindle,
        tool,
        path_control,
        ..Move::new(line, motion, Vector3::from(start), Vector3::from(end), feed)
    })
}
