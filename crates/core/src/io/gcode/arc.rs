//! Arcs (`G2`, `G3`) in the selected plane as LinuxCNC makes them (its `interp_arc.cc`):
//! the centre from `I J K` (incremental, or absolute with `G90.1`) or from `R` (negative: the
//! long way), the off-plane centre word refused (ignored by the grbl dialect), `P` turns, a
//! helix along the normal, and LinuxCNC's tolerances on the radius, in the program's unit.

use nalgebra::{Vector2, Vector3};

use super::fault::{Fault, fault};
use super::interp::{INCH, Machine};
use super::words::Words;
use crate::machining::{MAX_ARC_TURNS, MAX_COORDINATE, Motion, Plane};

/// LinuxCNC's radius tolerances of arcs \[m\], in the program's unit: the zero-radius and
/// `R` reach tolerance (0.00005 in, 0.00127 mm) and the spiral tolerance of a centre arc
/// (`2 x 0.001 sqrt 2` in, `2 x 0.01 sqrt 2` mm).
fn tolerances(units: f64) -> (f64, f64) {
    let root2 = core::f64::consts::SQRT_2;
    if units == INCH {
        (0.00005 * INCH, 2.0 * 0.001 * root2 * INCH)
    } else {
        (0.00127e-3, 2.0 * 0.01 * root2 * 1.0e-3)
    }
}

/// A letter as the message writes it.
fn upper(l: u8) -> char {
    char::from(l.to_ascii_uppercase())
}

/// An arc's ends in its plane (first and second axes) \[m\].
struct Ends {
    start: Vector2<f64>,
    end: Vector2<f64>,
}

impl Machine {
    /// `G2`/`G3` in the selected plane.
    pub(super) fn arc(
        &mut self,
        w: &mut Words,
        clockwise: bool,
        column: usize,
    ) -> Result<(), Fault> {
        let plane = self.plane;
        if plane != Plane::Xy && self.rotation != 0.0 {
            return fault(
                column,
                "G18/G19 arcs in a rotated coordinate system (G10 L2 R) are not modelled",
            );
        }
        let (first, second, off) = centre_letters(plane);
        self.off_plane_word(w, off, (first, second))?;
        let radius_word = centre_form(w, (first, second), column)?;
        let turns = turns(w)?;
        let (a, b, n) = plane.axes();
        let in_plane = ends_in_plane(w, (a, b));
        let start = self.pos;
        let end_column = w.first_of(b"xyz@^").unwrap_or(column);
        let end = self.target(w)?;
        let get = |v: &Vector3<f64>, k: usize| v.get(k).copied().unwrap_or(0.0);
        let ends = Ends {
            start: Vector2::new(get(&start, a), get(&start, b)),
            end: Vector2::new(get(&end, a), get(&end, b)),
        };
        let centre = match radius_word {
            Some(r) => self.r_word_centre(w, &ends, r, clockwise, in_plane, column)?,
            None => self.centre_words(w, &ends, (first, second), column)?,
        };
        let r1 = self.check_radii(&ends, &centre, radius_word.is_none(), (column, end_column))?;
        let sweep = turned_sweep(&ends, &centre, clockwise, turns);
        let length = (r1 * sweep.abs()).hypot(get(&end, n) - get(&start, n));
        let feed = self.speed(w, length, column)?;
        let c = self.centre_point(start, &centre, (a, b), column)?;
        let motion = Motion::Arc {
            plane,
            center: c,
            sweep,
        };
        self.emit(motion, end, feed, column)
    }

    /// The centre of an `R` arc, its `R` word taken: refused without an end point in the
    /// plane (`in_plane`), else [`Self::radius_centre`] \[m\].
    fn r_word_centre(
        &self,
        w: &mut Words,
        ends: &Ends,
        r: f64,
        clockwise: bool,
        in_plane: bool,
        column: usize,
    ) -> Result<Vector2<f64>, Fault> {
        if !in_plane {
            return fault(
                column,
                std::format!(
                    "an R arc needs an end point in its plane ({})",
                    self.plane.gcode()
                ),
            );
        }
        let r_column = w.column(b'r');
        w.take(b'r');
        self.radius_centre(ends, r, clockwise, (column, r_column))
    }

    /// The program-frame centre of the arc: `start` with its plane coordinates (`a`, `b`)
    /// replaced by the in-plane `centre` \[m\], refused when its machine-frame point is
    /// beyond [`MAX_COORDINATE`].
    fn centre_point(
        &self,
        start: Vector3<f64>,
        centre: &Vector2<f64>,
        (a, b): (usize, usize),
        column: usize,
    ) -> Result<Vector3<f64>, Fault> {
        let mut c = start;
        if let Some(x) = c.get_mut(a) {
            *x = centre.x;
        }
        if let Some(x) = c.get_mut(b) {
            *x = centre.y;
        }
        if let Some(v) = self
            .to_machine(&c)
            .iter()
            .find(|v| v.is_nan() || v.abs() > MAX_COORDINATE)
        {
            return fault(
                column,
                std::format!("an arc centre within +-{MAX_COORDINATE} m, got {v} m"),
            );
        }
        Ok(c)
    }

    /// The centre word along the plane's normal: LinuxCNC refuses it, grbl ignores it.
    fn off_plane_word(
        &self,
        w: &mut Words,
        off: u8,
        (first, second): (u8, u8),
    ) -> Result<(), Fault> {
        if !w.has(off) {
            return Ok(());
        }
        if self.dialect.ignores_off_plane_offset() {
            w.take(off);
            return Ok(());
        }
        fault(
            w.column(off),
            std::format!(
                "{o}: no {o} word on an arc in {} (the plane's centre words are {} and {}; grbl \
                 ignores it: the grbl dialect reads it so)",
                self.plane.gcode(),
                upper(first),
                upper(second),
                o = upper(off),
            ),
        )
    }

    /// The centre of an `R` arc: on the chord's right (`G2`, R > 0; `G3`, R < 0) or left.
    fn radius_centre(
        &self,
        ends: &Ends,
        r: f64,
        clockwise: bool,
        (column, r_column): (usize, usize),
    ) -> Result<Vector2<f64>, Fault> {
        let (zero_tol, _) = tolerances(self.units);
        if ends.start == ends.end {
            return fault(
                column,
                "an R arc needs an end point other than its start (a full circle needs I, J, K)",
            );
        }
        let r = r * self.units;
        let chord = ends.end - ends.start;
        let half = chord.norm() / 2.0;
        if half - r.abs() > zero_tol {
            return fault(
                r_column,
                std::format!(
                    "an arc radius R at least half the chord ({:.4} {}), got {:.4}",
                    half / self.units,
                    self.unit_name(),
                    r.abs() / self.units
                ),
            );
        }
        let u = chord / chord.norm();
        let right = (clockwise && r > 0.0) || (!clockwise && r < 0.0);
        let side = if right {
            Vector2::new(u.y, -u.x)
        } else {
            Vector2::new(-u.y, u.x)
        };
        let ratio = half / r.abs();
        let d = if ratio > 1.0 - 1.0e-12 {
            0.0
        } else {
            r.abs() * ratio.asin().cos()
        };
        Ok((ends.start + ends.end) / 2.0 + side * d)
    }

    /// The centre of an `I J K` arc: from the start (`G91.1`) or absolute (`G90.1`, both
    /// words needed).
    fn centre_words(
        &self,
        w: &mut Words,
        ends: &Ends,
        (first, second): (u8, u8),
        column: usize,
    ) -> Result<Vector2<f64>, Fault> {
        let (c1, c2) = (w.take(first), w.take(second));
        if !self.ijk_absolute {
            return Ok(ends.start + Vector2::new(c1.unwrap_or(0.0), c2.unwrap_or(0.0)) * self.units);
        }
        match (c1, c2) {
            (Some(c1), Some(c2)) => Ok(Vector2::new(c1, c2) * self.units),
            _ => fault(
                column,
                std::format!(
                    "both centre words {} and {} in absolute arc centre mode (G90.1)",
                    upper(first),
                    upper(second)
                ),
            ),
        }
    }

    /// LinuxCNC's radius checks: neither radius below the zero-radius tolerance, and for a
    /// centre arc the two radii within the spiral tolerance. Returns the start's radius.
    fn check_radii(
        &self,
        ends: &Ends,
        centre: &Vector2<f64>,
        spiral: bool,
        (column, end_column): (usize, usize),
    ) -> Result<f64, Fault> {
        let (zero_tol, spiral_tol) = tolerances(self.units);
        let (r1, r2) = ((ends.start - centre).norm(), (ends.end - centre).norm());
        if r1 < zero_tol || r2 < zero_tol {
            return fault(
                column,
                "an arc of radius > 0 (its centre is at its start or its end)",
            );
        }
        let err = (r1 - r2).abs();
        if spiral && (err > 100.0 * spiral_tol || (err / r1.max(r2) > 0.001 && err > spiral_tol)) {
            return fault(
                end_column,
                std::format!(
                    "an end point on the arc's circle: the radius is {:.4} {u} at the start and \
                     {:.4} {u} at the end (LinuxCNC's tolerance: {:.4} {u}, or 0.1 % up to {:.2} {u})",
                    r1 / self.units,
                    r2 / self.units,
                    spiral_tol / self.units,
                    100.0 * spiral_tol / self.units,
                    u = self.unit_name()
                ),
            );
        }
        Ok(r1)
    }
}

/// `P`, the number of turns of an arc: an integer in `1..=MAX_ARC_TURNS`, 1 without it.
fn turns(w: &mut Words) -> Result<u32, Fault> {
    let Some(p) = w.take(b'p') else {
        return Ok(1);
    };
    match super::expr::integer(p) {
        Some(t) if (1..=i64::from(MAX_ARC_TURNS)).contains(&t) => Ok(t as u32),
        _ => fault(
            w.column(b'p'),
            std::format!(
                "a number of turns P in 1..={MAX_ARC_TURNS} (an integer) on an arc, got P{p}"
            ),
        ),
    }
}

/// The centre words of the plane's first and second axes, and the one of its normal.
fn centre_letters(plane: Plane) -> (u8, u8, u8) {
    match plane {
        Plane::Xy => (b'i', b'j', b'k'),
        Plane::Zx => (b'k', b'i', b'j'),
        Plane::Yz => (b'j', b'k', b'i'),
    }
}

/// How the arc gives its centre: the `R` word (returned, program units) or the centre words
/// `first`, `second` (`None`); refused with both or neither.
fn centre_form(w: &Words, (first, second): (u8, u8), column: usize) -> Result<Option<f64>, Fault> {
    let radius_word = w.peek(b'r');
    match (w.has(first) || w.has(second), radius_word.is_some()) {
        (true, true) => fault(
            w.column(b'r'),
            "either a centre (I, J, K) or a radius R on an arc, not both",
        ),
        (false, false) => fault(
            column,
            "an arc needs its centre (I, J, K in its plane) or its radius R",
        ),
        _ => Ok(radius_word),
    }
}

/// Whether the block gives an end point in the plane of axes `a`, `b` (an axis word of
/// either, or a polar word), as an `R` arc needs.
fn ends_in_plane(w: &Words, (a, b): (usize, usize)) -> bool {
    [b'x', b'y', b'z']
        .iter()
        .enumerate()
        .any(|(k, l)| (k == a || k == b) && w.has(*l))
        || w.has(b'@')
        || w.has(b'^')
}

/// The arc's signed sweep \[rad\] with its `turns`: [`sweep`] plus a full turn for each turn
/// past the first, in the arc's direction.
fn turned_sweep(ends: &Ends, centre: &Vector2<f64>, clockwise: bool, turns: u32) -> f64 {
    let extra = f64::from(turns - 1) * core::f64::consts::TAU;
    let base = sweep(&ends.start, &ends.end, centre, clockwise);
    if clockwise {
        base - extra
    } else {
        base + extra
    }
}

/// Signed sweep about the plane's normal from `a` to `b` around `c` (> 0 counter-clockwise);
/// equal ends make a full turn.
pub(super) fn sweep(a: &Vector2<f64>, b: &Vector2<f64>, c: &Vector2<f64>, clockwise: bool) -> f64 {
    let tau = core::f64::consts::TAU;
    let (ra, rb) = (a - c, b - c);
    let angle = |v: Vector2<f64>| v.y.atan2(v.x);
    let ccw = (angle(rb) - angle(ra)).rem_euclid(tau);
    if clockwise {
        let cw = (tau - ccw).rem_euclid(tau);
        return -(if a == b || cw == 0.0 { tau } else { cw });
    }
    if a == b || ccw == 0.0 { tau } else { ccw }
}
