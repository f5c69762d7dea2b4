//! A machining program as straight and circular moves in the workpiece frame, SI: what the
//! G-code reader ([`crate::io::gcode`]) produces and the path, the cutting-force model and
//! the material removal consume.

use alloc::vec::Vec;

use nalgebra::{ComplexField, Vector2, Vector3};

use crate::error::BuildError;

/// Most moves one program holds: 500,000 (a finishing program of a large part; about 60 MB).
/// The reader refuses a longer program with [`crate::LoadError::TooLarge`].
pub const MAX_MOVES: usize = 500_000;

/// Largest coordinate, radius or offset \[m\] (1 km): a robot cell is metres.
pub const MAX_COORDINATE: f64 = 1.0e3;

/// Largest feed \[m/s\] (100 m/s = 6,000,000 mm/min).
pub const MAX_FEED: f64 = 100.0;

/// Largest spindle speed \[rpm\].
pub const MAX_SPINDLE_RPM: f64 = 1.0e6;

/// Tolerance on an `I`/`J` arc whose end is not exactly on the circle through its start: the
/// radii may differ by 0.002 mm or 0.1 % of the radius, whichever is larger (LinuxCNC's
/// rule); more is an error, not a silently moved centre.
pub const ARC_TOLERANCE: (f64, f64) = (2.0e-6, 1.0e-3);

/// Largest gap between a move's start and the previous move's end \[m\] that
/// [`Program::validate`] accepts (a program is one path).
pub const MAX_GAP: f64 = 1.0e-9;

/// How a move goes from its start to its end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// `G0`: at the controller's rapid rate, not cutting.
    Rapid,
    /// `G1`: straight, at the programmed feed.
    Linear,
    /// `G2` / `G3` in the XY plane (`G17`): a circle about `center` (x, y) \[m\] through
    /// `sweep` \[rad\] (> 0 counter-clockwise, `G3`; < 0 clockwise, `G2`; a full turn is
    /// +-2 pi), with z linear in the angle (a helix when z changes).
    Arc {
        /// Centre (x, y) \[m\], workpiece frame.
        center: Vector2<f64>,
        /// Signed angle swept about +z \[rad\], `0 < |sweep| <= 2 pi`.
        sweep: f64,
    },
}

/// One move of a program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// The program line it comes from (1-based), for every error and report about it.
    pub line: usize,
    /// Straight, circular or rapid.
    pub motion: Motion,
    /// Start point \[m\], workpiece frame.
    pub start: Vector3<f64>,
    /// End point \[m\], workpiece frame (as programmed).
    pub end: Vector3<f64>,
    /// Programmed feed along the path \[m/s\]; 0 for a rapid move.
    pub feed: f64,
    /// Spindle speed \[rev/s\]; 0 while the spindle is off (`M5`, or before `M3`).
    pub spindle: f64,
}

impl Move {
    /// Arc radius \[m\] (from the start point; 0 for straight moves).
    pub fn radius(&self) -> f64 {
        match self.motion {
            Motion::Arc { center, .. } => (self.start.xy() - center).norm(),
            _ => 0.0,
        }
    }

    /// Path length \[m\]: the chord of a straight move, `sqrt((r sweep)^2 + dz^2)` of an arc.
    pub fn length(&self) -> f64 {
        match self.motion {
            Motion::Arc { sweep, .. } => {
                let arc = self.radius() * ComplexField::abs(sweep);
                let dz = self.end.z - self.start.z;
                ComplexField::sqrt(arc * arc + dz * dz)
            }
            _ => (self.end - self.start).norm(),
        }
    }

    /// The point at the fraction `s` in \[0, 1\] of the move \[m\] (by angle on an arc, so
    /// by length): `s <= 0` is the start, `s >= 1` the end, exactly.
    pub fn point(&self, s: f64) -> Vector3<f64> {
        // The ends exactly (an arc's rotation about its centre rounds them).
        if s <= 0.0 {
            return self.start;
        }
        if s >= 1.0 {
            return self.end;
        }
        match self.motion {
            Motion::Arc { center, sweep } => {
                let r0 = self.start.xy() - center;
                let (sin, cos) = ComplexField::sin_cos(sweep * s);
                let xy = center + Vector2::new(cos * r0.x - sin * r0.y, sin * r0.x + cos * r0.y);
                let z = self.start.z + (self.end.z - self.start.z) * s;
                Vector3::new(xy.x, xy.y, z)
            }
            _ => self.start + (self.end - self.start) * s,
        }
    }

    /// Unit tangent (feed direction) at the fraction `s`, workpiece frame; zero for a
    /// zero-length move.
    pub fn tangent(&self, s: f64) -> Vector3<f64> {
        let t = match self.motion {
            Motion::Arc { center, sweep } => {
                let p = self.point(s);
                let r = p.xy() - center;
                // d/d(angle) of the circle, times the sign of the sweep; z rises linearly.
                let dxy = Vector2::new(-r.y, r.x) * sweep;
                Vector3::new(dxy.x, dxy.y, self.end.z - self.start.z)
            }
            _ => self.end - self.start,
        };
        let n = t.norm();
        if n > 0.0 { t / n } else { Vector3::zeros() }
    }
}

/// A program: its moves in order, each from the end of the one before.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Program {
    /// The moves, in program order.
    pub moves: Vec<Move>,
}

impl Program {
    /// Checks a program however it was made (read, built by hand, unpickled): at most
    /// [`MAX_MOVES`] moves, lines >= 1, points finite within [`MAX_COORDINATE`], each move
    /// starting where the one before ends (within [`MAX_GAP`]), feeds in `[0, MAX_FEED]`,
    /// spindle speeds in `[0, MAX_SPINDLE_RPM / 60]` rev/s, arcs with `0 < |sweep| <= 2 pi`
    /// whose end lies where the sweep takes the start (within [`ARC_TOLERANCE`]).
    /// [`BuildError::InvalidEntry`] naming the move (its index) and what is wrong.
    pub fn validate(&self) -> Result<(), BuildError> {
        if self.moves.len() > MAX_MOVES {
            return Err(BuildError::Budget {
                what: "program moves",
                budget: "MAX_MOVES",
                limit: MAX_MOVES,
                requested: self.moves.len(),
            });
        }
        let bad = |index: usize, value: f64, expected: &'static str| {
            Err(BuildError::InvalidEntry {
                what: "program moves (index: the move)",
                index,
                value,
                expected,
            })
        };
        let mut previous: Option<Vector3<f64>> = None;
        for (i, m) in self.moves.iter().enumerate() {
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
            if let Some(p) = previous {
                let gap = (m.start - p).norm();
                if gap > MAX_GAP {
                    return bad(
                        i,
                        gap,
                        "a start within MAX_GAP (1e-9 m) of the previous end",
                    );
                }
            }
            previous = Some(m.end);
            if !(0.0..=MAX_FEED).contains(&m.feed) {
                return bad(i, m.feed, "a feed in [0, MAX_FEED] m/s");
            }
            if !(0.0..=MAX_SPINDLE_RPM / 60.0).contains(&m.spindle) {
                return bad(
                    i,
                    m.spindle,
                    "a spindle speed in [0, MAX_SPINDLE_RPM / 60] rev/s",
                );
            }
            if let Motion::Arc { center, sweep } = m.motion {
                if !(center
                    .iter()
                    .all(|v| v.is_finite() && v.abs() <= MAX_COORDINATE))
                {
                    return bad(
                        i,
                        center.x + center.y,
                        "an arc centre finite, within 1000 m",
                    );
                }
                let tau = core::f64::consts::TAU;
                if !(sweep.is_finite() && sweep != 0.0 && ComplexField::abs(sweep) <= tau) {
                    return bad(i, sweep, "an arc sweep with 0 < |sweep| <= 2 pi");
                }
                let r = m.radius();
                let (sin, cos) = ComplexField::sin_cos(sweep);
                let r0 = m.start.xy() - center;
                let swept = center + Vector2::new(cos * r0.x - sin * r0.y, sin * r0.x + cos * r0.y);
                let miss = (swept - m.end.xy()).norm();
                if miss > ARC_TOLERANCE.0.max(ARC_TOLERANCE.1 * r) {
                    return bad(
                        i,
                        miss,
                        "an arc end where the sweep takes the start (within ARC_TOLERANCE)",
                    );
                }
            }
        }
        Ok(())
    }

    /// Total path length \[m\] of the feed moves (rapids excluded).
    pub fn cutting_length(&self) -> f64 {
        self.moves
            .iter()
            .filter(|m| m.motion != Motion::Rapid)
            .map(Move::length)
            .sum()
    }
}
