//! The checks of [`Program::validate`]: a program however it was made (read, built by hand,
//! unpickled) within the budgets and on one path, each move's own fields and an arc's
//! geometry.

use nalgebra::{ComplexField, Vector3};

use super::{
    ARC_TOLERANCE, AXIS_TOLERANCE, MAX_ARC_TURNS, MAX_AXIS_TURN, MAX_COORDINATE, MAX_DWELL,
    MAX_FEED, MAX_GAP, MAX_MOVES, MAX_SPINDLE_RPM, MAX_TOOL_NUMBER, Motion, Move, PathControl,
    Plane, Program,
};
use crate::error::BuildError;

impl Program {
    /// Checks a program however it was made (read, built by hand, unpickled): operations
    /// in order of their first moves, each a move of the program; at most
    /// [`MAX_MOVES`] moves, lines >= 1, points finite within [`MAX_COORDINATE`], each move
    /// starting where the one before ends (within [`MAX_GAP`]), feeds in `[0, MAX_FEED]`,
    /// spindle speeds within `MAX_SPINDLE_RPM / 60` rev/s either way, tools up to
    /// [`MAX_TOOL_NUMBER`], path control tolerances finite and >= 0, arcs with
    /// `0 < |sweep| <= 2 pi MAX_ARC_TURNS`, their centre level with the start along the
    /// normal and their end where the sweep takes the start (within [`ARC_TOLERANCE`]),
    /// dwells in place for `(0, MAX_DWELL]` s. [`BuildError::InvalidEntry`] naming the move
    /// (its index) and what is wrong.
    pub fn validate(&self) -> Result<(), BuildError> {
        if self.moves.len() > MAX_MOVES {
            return Err(BuildError::Budget {
                what: "program moves",
                budget: "MAX_MOVES",
                limit: MAX_MOVES,
                requested: self.moves.len(),
            });
        }
        let mut previous: Option<(Vector3<f64>, Vector3<f64>)> = None;
        for (i, m) in self.moves.iter().enumerate() {
            if let Some((p, a)) = previous {
                let gap = (m.start - p).norm();
                if gap > MAX_GAP {
                    return bad(
                        i,
                        gap,
                        "a start within MAX_GAP (1e-9 m) of the previous end",
                    );
                }
                let turn = (m.start_axis - a).norm();
                if turn > AXIS_TOLERANCE {
                    return bad(
                        i,
                        turn,
                        "a start axis within AXIS_TOLERANCE (1e-9) of the previous end axis",
                    );
                }
            }
            previous = Some((m.end, m.end_axis));
            check_move(i, m)?;
            check_axes(i, m)?;
        }
        let mut last: Option<usize> = None;
        for (index, o) in self.operations.iter().enumerate() {
            if o.first_move >= self.moves.len() || last.is_some_and(|l| o.first_move <= l) {
                return Err(BuildError::InvalidEntry {
                    what: "program operations (index: the operation)",
                    index,
                    value: o.first_move as f64,
                    expected: "first moves increasing, each an index of the moves",
                });
            }
            last = Some(o.first_move);
        }
        Ok(())
    }
}

/// A move's tool axes: unit within [`AXIS_TOLERANCE`], turning at most [`MAX_AXIS_TURN`].
fn check_axes(i: usize, m: &Move) -> Result<(), BuildError> {
    for a in [&m.start_axis, &m.end_axis] {
        let n = a.norm();
        if !(n.is_finite() && ComplexField::abs(n - 1.0) <= AXIS_TOLERANCE) {
            return bad(
                i,
                n,
                "a tool axis of unit length (within AXIS_TOLERANCE, 1e-9)",
            );
        }
    }
    let turn = m.axis_turn();
    if turn > MAX_AXIS_TURN {
        return bad(
            i,
            turn,
            "a tool axis turning at most MAX_AXIS_TURN (179 degrees) along one move",
        );
    }
    if matches!(m.motion, Motion::Dwell { .. }) && turn > 0.0 {
        return bad(i, turn, "a dwell with the tool axis held");
    }
    Ok(())
}

/// The error for move `index`: its `value` and what was `expected` of it.
fn bad(index: usize, value: f64, expected: &'static str) -> Result<(), BuildError> {
    Err(BuildError::InvalidEntry {
        what: "program moves (index: the move)",
        index,
        value,
        expected,
    })
}

/// One move's own checks (see [`Program::validate`]).
fn check_move(i: usize, m: &Move) -> Result<(), BuildError> {
    if m.line == 0 {
        return bad(i, 0.0, "a program line >= 1");
    }
    if let Some(v) = m
        .start
        .iter()
        .chain(m.end.iter())
        .find(|v| !(v.is_finite() && v.abs() <= MAX_COORDINATE))
    {
        return bad(
            i,
            *v,
            "start and end finite, within +-MAX_COORDINATE (1000 m)",
        );
    }
    if !(0.0..=MAX_FEED).contains(&m.feed) {
        return bad(i, m.feed, "a feed in [0, MAX_FEED] m/s");
    }
    if m.spindle.is_nan() || m.spindle.abs() > MAX_SPINDLE_RPM / 60.0 {
        return bad(
            i,
            m.spindle,
            "a spindle speed within +-MAX_SPINDLE_RPM / 60 rev/s",
        );
    }
    if m.tool > MAX_TOOL_NUMBER {
        return bad(i, f64::from(m.tool), "a tool number in 0..=MAX_TOOL_NUMBER");
    }
    if let PathControl::Blend {
        tolerance,
        naive_tolerance,
    } = m.path_control
        && !(tolerance.is_finite()
            && tolerance >= 0.0
            && naive_tolerance.is_finite()
            && naive_tolerance >= 0.0)
    {
        return bad(
            i,
            tolerance + naive_tolerance,
            "G64 tolerances finite and >= 0 m",
        );
    }
    match m.motion {
        Motion::Rapid if m.feed != 0.0 => bad(i, m.feed, "a feed of 0 on a rapid move"),
        Motion::Dwell { seconds } => {
            if !(seconds > 0.0 && seconds <= MAX_DWELL) {
                return bad(i, seconds, "a dwell in (0, MAX_DWELL] s");
            }
            if m.start != m.end || m.feed != 0.0 {
                return bad(
                    i,
                    (m.end - m.start).norm(),
                    "a dwell in place with a feed of 0",
                );
            }
            Ok(())
        }
        Motion::Arc {
            plane,
            center,
            sweep,
        } => check_arc(i, m, plane, &center, sweep),
        _ => Ok(()),
    }
}

/// An arc's own checks (see [`Program::validate`]): its centre, sweep, radii and end.
fn check_arc(
    i: usize,
    m: &Move,
    plane: Plane,
    center: &Vector3<f64>,
    sweep: f64,
) -> Result<(), BuildError> {
    if !(center
        .iter()
        .all(|v| v.is_finite() && v.abs() <= MAX_COORDINATE))
    {
        return bad(i, center.sum(), "an arc centre finite, within 1000 m");
    }
    let rise = ComplexField::abs(plane.normal(center) - plane.normal(&m.start));
    if rise > MAX_GAP {
        return bad(
            i,
            rise,
            "an arc centre level with the start along the plane's normal",
        );
    }
    let most = core::f64::consts::TAU * f64::from(MAX_ARC_TURNS);
    if !(sweep.is_finite() && sweep != 0.0 && ComplexField::abs(sweep) <= most) {
        return bad(
            i,
            sweep,
            "an arc sweep with 0 < |sweep| <= 2 pi MAX_ARC_TURNS",
        );
    }
    let (r0, re) = (m.radius(), m.end_radius());
    if !(r0 > 0.0 && re > 0.0) {
        return bad(
            i,
            r0.min(re),
            "an arc of radius > 0 at its start and its end",
        );
    }
    let spiral = ComplexField::abs(re - r0);
    if spiral > ARC_TOLERANCE.0.max(ARC_TOLERANCE.1 * r0.max(re)) {
        return bad(
            i,
            spiral,
            "an arc end as far from the centre as the start (within ARC_TOLERANCE)",
        );
    }
    // The end's direction from the centre is where the sweep turns the start's.
    let (sin, cos) = ComplexField::sin_cos(sweep);
    let (c1, c2) = plane.split(center);
    let (r1, r2) = plane.split(&(m.start - center));
    let (e1, e2) = plane.split(&m.end);
    let k = re / r0;
    let miss = ComplexField::sqrt(
        (c1 + (cos * r1 - sin * r2) * k - e1).powi(2)
            + (c2 + (sin * r1 + cos * r2) * k - e2).powi(2),
    );
    if miss > MAX_GAP + 1.0e-12 * re * (1.0 + ComplexField::abs(sweep)) {
        return bad(
            i,
            miss,
            "an arc end where the sweep takes the start (within ARC_TOLERANCE)",
        );
    }
    Ok(())
}
