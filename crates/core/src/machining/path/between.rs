//! The points where the programmed path bends between two samples: the corners and arc chords
//! the stock is cut through, so that a sample period that spans a corner does not cut the chord.

use nalgebra::{ComplexField, Vector3};

use super::super::Program;

/// How far the stock's cut may leave the programmed path between two samples \[m\]: 1 um. An
/// arc is cut along chords whose sagitta stays below it (at the 4 ms cycle a sample's chord
/// on a 10 mm arc at 25 mm/s has 0.13 um, so none is added there).
pub const WAYPOINT_TOLERANCE: f64 = 1.0e-6;

/// Most chords one arc is cut into between two samples: past it (a kilometre arc at one
/// sample per second) its chords' sagitta exceeds [`WAYPOINT_TOLERANCE`].
pub const MAX_ARC_CHORDS: usize = 4096;

/// The points where the programmed path bends strictly between two samples at `from` and
/// `to` (each `(move index, fraction)` of [`PathSample`](super::PathSample), `from` not after `to`): every
/// move's end between them and the points that cut each arc into chords within
/// [`WAYPOINT_TOLERANCE`]. Calls `visit(point, move index, share)` in path order, `share` the
/// part of the path's length from `from` to the point (0..1), the move index that of the
/// move the segment *ending* at the point lies on; returns how many points it visited. None
/// for two samples on one straight move. Allocation-free.
pub fn between(
    program: &Program,
    from: (usize, f64),
    to: (usize, f64),
    mut visit: impl FnMut(Vector3<f64>, usize, f64),
) -> usize {
    let (m0, f0) = from;
    let (m1, f1) = to;
    if m1 < m0 || (m1 == m0 && f1 <= f0) {
        return 0;
    }
    // The stretches of moves between the samples: (move, fraction from, fraction to).
    let stretch = |m: usize| -> (f64, f64) {
        let a = if m == m0 { f0 } else { 0.0 };
        let b = if m == m1 { f1 } else { 1.0 };
        (a, b)
    };
    // Chords per stretch of an arc, so that each one's sagitta is within the tolerance.
    let chords = |mv: &super::super::Move, a: f64, b: f64| -> usize {
        match mv.motion {
            super::super::Motion::Arc { sweep, .. } => {
                let r = mv.radius().max(mv.end_radius());
                if r.is_nan() || r <= WAYPOINT_TOLERANCE {
                    return 1;
                }
                let step = 2.0 * ComplexField::acos(1.0 - WAYPOINT_TOLERANCE / r);
                let angle = ComplexField::abs(sweep) * (b - a);
                let n = ComplexField::ceil(angle / step);
                if n.is_finite() && n >= 1.0 {
                    (n as usize).min(MAX_ARC_CHORDS)
                } else {
                    1
                }
            }
            _ => 1,
        }
    };
    let moves = program.moves.get(m0..=m1).unwrap_or(&[]);
    let total: f64 = moves
        .iter()
        .zip(m0..)
        .map(|(mv, m)| {
            let (a, b) = stretch(m);
            mv.length() * (b - a)
        })
        .sum();
    let mut done = 0.0;
    let mut count = 0;
    for (mv, m) in moves.iter().zip(m0..) {
        let (a, b) = stretch(m);
        let n = chords(mv, a, b);
        let length = mv.length() * (b - a);
        for k in 1..=n {
            // The stretch's inner chord ends, and its end unless it is the sample itself.
            if k == n && m == m1 {
                break;
            }
            let f = a + (b - a) * k as f64 / n as f64;
            let share = if total > 0.0 {
                (done + length * k as f64 / n as f64) / total
            } else {
                0.0
            };
            visit(mv.point(f), m, share.clamp(0.0, 1.0));
            count += 1;
        }
        done += length;
    }
    count
}
