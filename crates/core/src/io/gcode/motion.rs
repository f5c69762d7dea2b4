//! The moves a block makes: straight moves (`G0`, `G1`, `G53`), splines (`G5`, `G5.1`, as
//! lines within 1 um), dwells (`G4`) and the return to a stored point (`G28`, `G30`), the feed
//! of each in the program's feed mode; arcs are [`super::arc`]'s.

use std::string::ToString;

use nalgebra::{Vector2, Vector3};

use super::fault::{Fault, fault};
use super::interp::{FeedMode, Machine};
use super::params::Params;
use super::words::{Words, g_name};
use crate::LoadError;
use crate::machining::{MAX_COORDINATE, MAX_DWELL, MAX_FEED, MAX_MOVES, Motion, Move, Plane};

/// Largest distance \[m\] of a spline's chords from the spline (`G5`, `G5.1` become lines).
pub const SPLINE_TOLERANCE: f64 = 1.0e-6;
/// Most chords one spline becomes.
pub const MAX_SPLINE_CHORDS: usize = 1_000;

/// Words that make a motion run.
const AXES: &[u8] = b"xyz@^";

/// Whether a motion code is a canned cycle.
pub(super) fn is_cycle(code: u16) -> bool {
    code == 730 || code == 740 || (810..=890).contains(&code)
}

impl Machine {
    /// Step 26: the motion of the line (its own group-1 code, or the modal one when axis
    /// words are given), `G53` applied.
    pub(super) fn motion(
        &mut self,
        w: &mut Words,
        consumed: bool,
        params: &Params,
    ) -> Result<(), Fault> {
        let explicit =
            w.g.iter()
                .find(|g| super::words_group(g.0) == Some(1))
                .copied();
        let Some(code) = self.motion_code(w, explicit, consumed)? else {
            return Ok(());
        };
        let column = explicit.map_or_else(|| w.first_of(AXES).unwrap_or(1), |e| e.1);
        self.check_g53(w, code)?;
        if !is_cycle(code) {
            self.cycle.initial = None;
        }
        if code != 50 {
            self.spline_pq = None;
        }
        self.run_motion(w, code, column)?;
        if code != 50 && code != 51 {
            self.motion = Some(code);
        }
        if code <= 30 {
            self.plain_motion = Some(code);
        }
        let _ = params;
        Ok(())
    }

    /// The motion code the line runs: its own group-1 code (`explicit`, with its column), or
    /// the modal one when axis words (or an arc's centre words) are given; `None` when it runs
    /// none (`G80` cancels the motion mode here).
    fn motion_code(
        &mut self,
        w: &Words,
        explicit: Option<(u16, usize)>,
        consumed: bool,
    ) -> Result<Option<u16>, Fault> {
        let has_axes = !consumed && w.any_unused(AXES);
        match explicit {
            Some((800, column)) => {
                if has_axes {
                    return fault(
                        w.first_of(AXES).unwrap_or(column),
                        "no axis words with G80 (it cancels the motion mode)",
                    );
                }
                self.motion = None;
                self.cycle.initial = None;
                Ok(None)
            }
            Some((code, column)) => {
                if is_cycle(code) && !has_axes {
                    return fault(
                        column,
                        std::format!("{}: a cycle needs axis words", g_name(code)),
                    );
                }
                Ok(Some(code))
            }
            None => {
                let arc_words =
                    matches!(self.motion, Some(20 | 30)) && w.first_of(b"ijk").is_some();
                if consumed || !(has_axes || arc_words) {
                    if let Some(column) = w.g(530) {
                        return fault(column, "G53 needs axis words and G0 or G1");
                    }
                    return Ok(None);
                }
                match self.motion.or(if self.dialect.motion_after_g80() {
                    self.plain_motion
                } else {
                    None
                }) {
                    Some(code) => Ok(Some(code)),
                    None => fault(
                        w.first_of(AXES).unwrap_or(1),
                        "axis words with no motion mode to use them (the line needs G0, G1, \
                         G2, G3 or a cycle: G80 and the program start leave none; the fanuc \
                         dialect moves in the last G0-G3 mode instead)",
                    ),
                }
            }
        }
    }

    /// `G53` (machine coordinates) with the line's motion `code`: only with `G0` or `G1`, and
    /// not in incremental distance mode.
    fn check_g53(&self, w: &Words, code: u16) -> Result<(), Fault> {
        if let Some(g53) = w.g(530) {
            if !matches!(code, 0 | 10) {
                return fault(g53, "G53 moves with G0 or G1 only");
            }
            if w.g(910).is_some() || (!self.absolute && w.g(900).is_none()) {
                return fault(
                    g53,
                    "G53 takes machine coordinates: not with G91 (incremental)",
                );
            }
        }
        Ok(())
    }

    /// Runs motion `code` (ten times its G number): a straight move (to machine coordinates
    /// with `G53`), an arc, a spline or a canned cycle.
    fn run_motion(&mut self, w: &mut Words, code: u16, column: usize) -> Result<(), Fault> {
        match code {
            0 | 10 => {
                let end = if w.g(530).is_some() {
                    self.machine_target(w)?
                } else {
                    self.target(w)?
                };
                let motion = if code == 0 {
                    Motion::Rapid
                } else {
                    Motion::Linear
                };
                self.straight(motion, end, w, column)
            }
            20 | 30 => self.arc(w, code == 20, column),
            50 | 51 => self.spline(w, code == 50, column),
            _ if is_cycle(code) => self.cycle(w, code, column),
            _ => fault(
                column,
                std::format!("{}: not a motion this reader runs", g_name(code)),
            ),
        }
    }

    /// The end point of the axis words (and `@` `^` polar words, G17 only), program frame.
    pub(super) fn target(&mut self, w: &mut Words) -> Result<Vector3<f64>, Fault> {
        let mut p = self.pos;
        if w.has(b'@') || w.has(b'^') {
            let column = w.first_of(b"@^").unwrap_or(1);
            if self.plane != Plane::Xy {
                return fault(
                    column,
                    "polar coordinates (@, ^) in G17 (the XY plane) only",
                );
            }
            if w.has(b'x') || w.has(b'y') {
                return fault(
                    column,
                    "either polar coordinates (@, ^) or X and Y, not both",
                );
            }
            let (r0, a0) = (p.xy().norm(), p.y.atan2(p.x).to_degrees());
            let at_origin = p.x == 0.0 && p.y == 0.0;
            let radius = w.take(b'@').map(|r| r * self.units);
            let angle = w.take(b'^');
            if at_origin && (angle.is_none() || !self.absolute) {
                return fault(
                    column,
                    "a polar angle (^) from the origin, where the angle is undefined",
                );
            }
            let (r, a) = if self.absolute {
                (radius.unwrap_or(r0), angle.unwrap_or(a0))
            } else {
                (r0 + radius.unwrap_or(0.0), a0 + angle.unwrap_or(0.0))
            };
            let (s, c) = a.to_radians().sin_cos();
            p.x = r * c;
            p.y = r * s;
        }
        for (k, l) in [b'x', b'y', b'z'].into_iter().enumerate() {
            if let (Some(v), Some(e)) = (w.take(l), p.get_mut(k)) {
                *e = if self.absolute {
                    v * self.units
                } else {
                    *e + v * self.units
                };
            }
        }
        Ok(p)
    }

    /// The end point of `G53`'s machine coordinates, program frame (axes without words stay).
    fn machine_target(&mut self, w: &mut Words) -> Result<Vector3<f64>, Fault> {
        if w.has(b'@') || w.has(b'^') {
            return fault(
                w.first_of(b"@^").unwrap_or(1),
                "no polar coordinates with G53",
            );
        }
        let mut m = self.to_machine(&self.pos);
        for (k, l) in [b'x', b'y', b'z'].into_iter().enumerate() {
            if let (Some(v), Some(e)) = (w.take(l), m.get_mut(k)) {
                *e = v * self.units;
            }
        }
        Ok(self.to_program(&m))
    }

    /// The feed \[m/s\] of a feed move `length` \[m\] long in the current feed mode.
    pub(super) fn speed(&self, w: &Words, length: f64, column: usize) -> Result<f64, Fault> {
        let per_minute = match self.feed_mode {
            FeedMode::PerMinute => {
                if self.feed <= 0.0 {
                    return fault(column, "a feed rate F > 0 before a feed move (G1, G2, G3)");
                }
                self.feed
            }
            FeedMode::InverseTime => {
                let Some(f) = w.peek(b'f') else {
                    return fault(column, "F on every feed move in inverse time (G93)");
                };
                (length / self.units * f).max(0.1)
            }
            FeedMode::PerRevolution => {
                if self.feed <= 0.0 {
                    return fault(
                        column,
                        "a feed per revolution F > 0 before a feed move (G95)",
                    );
                }
                if self.spindle_rpm <= 0.0 {
                    return fault(
                        column,
                        "a spindle speed S > 0 for a feed per revolution (G95)",
                    );
                }
                self.feed * self.spindle_rpm
            }
        };
        let v = per_minute * self.units / 60.0;
        if v.is_nan() || v > MAX_FEED {
            return fault(
                w.first_of(b"f").unwrap_or(column),
                std::format!("a feed of at most {MAX_FEED} m/s, got {v} m/s"),
            );
        }
        Ok(v)
    }

    /// A straight move to `end` (program frame).
    pub(super) fn straight(
        &mut self,
        motion: Motion,
        end: Vector3<f64>,
        w: &Words,
        column: usize,
    ) -> Result<(), Fault> {
        let feed = if motion == Motion::Rapid {
            0.0
        } else {
            self.speed(w, (end - self.pos).norm(), column)?
        };
        self.emit(motion, end, feed, column)
    }

    /// Appends a move from the current point to `end` (program frame) and moves there; a
    /// straight move that goes nowhere is not stored.
    pub(super) fn emit(
        &mut self,
        motion: Motion,
        end: Vector3<f64>,
        feed: f64,
        column: usize,
    ) -> Result<(), Fault> {
        let (start, stop) = (self.to_machine(&self.pos), self.to_machine(&end));
        if let Some(v) = stop
            .iter()
            .find(|v| !(v.is_finite() && v.abs() <= MAX_COORDINATE))
        {
            return fault(
                column,
                std::format!("an end point within +-{MAX_COORDINATE} m, got {v} m"),
            );
        }
        let turning = self.rotary_end != self.rotary;
        if turning && !matches!(motion, Motion::Rapid | Motion::Linear) {
            return fault(
                column,
                "rotary axes turning on a straight move (G0, G1) only, not on an arc, a \
                 dwell or in a canned cycle",
            );
        }
        let (start, stop, start_axis, end_axis) = self.posed(start, stop)?;
        self.pos = end;
        self.rotary = self.rotary_end;
        if matches!(motion, Motion::Rapid | Motion::Linear)
            && start == stop
            && start_axis == end_axis
        {
            return Ok(());
        }
        let motion = self.machine_motion(motion, column)?;
        if self.moves.len() >= MAX_MOVES {
            // The column says "the moves budget" to the reading loop (a LoadError::TooLarge).
            return Err((
                usize::MAX,
                LoadError::TooLarge {
                    what: std::format!("G-code program moves (at line {})", self.line),
                    limit: MAX_MOVES,
                    got: self.moves.len() + 1,
                }
                .to_string(),
            ));
        }
        self.start_operation();
        self.moves.push(Move {
            spindle: self.spindle(),
            // Before the first tool change, the tool the program selected (posts for manual
            // tool changes write T without M6: the operator puts that tool in).
            tool: if self.tool == 0 {
                self.selected
            } else {
                self.tool
            },
            path_control: self.path_control,
            start_axis,
            end_axis,
            ..Move::new(self.line, motion, start, stop, feed)
        });
        Ok(())
    }

    /// `motion` in the machine frame: an arc's centre moved there (refused when rotary axes
    /// stand turned without tool centre point control); other motions as they are.
    fn machine_motion(&self, motion: Motion, column: usize) -> Result<Motion, Fault> {
        Ok(match motion {
            Motion::Arc {
                plane,
                center,
                sweep,
            } => {
                if self.kinematics.is_some_and(|k| !k.tcp()) && self.rotary != [0.0; 3] {
                    return fault(
                        column,
                        "an arc with the rotary axes at 0 (without tool centre point \
                         control a turned table or head makes it no circle in the \
                         workpiece: have the post write lines)",
                    );
                }
                Motion::Arc {
                    plane,
                    center: self.to_machine(&center),
                    sweep,
                }
            }
            m => m,
        })
    }

    /// Starts an operation at the next move when there is none yet or one is due (a tool
    /// change, a comment after moves), named by the last comment or else by the tool.
    fn start_operation(&mut self) {
        if self.operations.is_empty() || self.operation_next {
            let tool = if self.tool == 0 {
                self.selected
            } else {
                self.tool
            };
            let name = self
                .operation_name
                .take()
                .unwrap_or_else(|| std::format!("T{tool}"));
            self.operations.push(crate::machining::Operation {
                name,
                first_move: self.moves.len(),
            });
            self.operation_next = false;
        }
    }

    /// The move's start and end tips and axes in the workpiece frame: the machine points as
    /// they are without kinematics, else the kinematics' poses at the rotary angles before and
    /// after the block's words.
    #[allow(clippy::type_complexity)] // reason: the two poses of one move, used once
    fn posed(
        &self,
        start: Vector3<f64>,
        stop: Vector3<f64>,
    ) -> Result<(Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>), Fault> {
        let column = self.rotary_column;
        let Some(k) = self.kinematics else {
            return Ok((start, stop, Vector3::z(), Vector3::z()));
        };
        let pose = |p: &Vector3<f64>, angles: &[f64; 3]| {
            k.pose(p, angles).map_err(|e| {
                (
                    column,
                    std::format!("rotary angles the machine reaches: {e}"),
                )
            })
        };
        let a = pose(&start, &self.rotary)?;
        let b = pose(&stop, &self.rotary_end)?;
        Ok((a.tip, b.tip, a.axis, b.axis))
    }

    /// A dwell of `seconds` (`G4 P`, a cycle's `P`).
    pub(super) fn dwell(&mut self, seconds: f64, column: usize) -> Result<(), Fault> {
        if !(0.0..=MAX_DWELL).contains(&seconds) {
            return fault(
                column,
                std::format!("a dwell time P in [0, {MAX_DWELL}] s, got P{seconds}"),
            );
        }
        if seconds > 0.0 {
            self.emit(Motion::Dwell { seconds }, self.pos, 0.0, column)?;
        }
        Ok(())
    }

    /// `G28`/`G30`: a rapid to the intermediate point of the axis words, then to the stored
    /// point (parameters `base..base + 3`, machine frame, mm) on the axes named, in the
    /// program frame (all three without axis words).
    pub(super) fn home(
        &mut self,
        w: &mut Words,
        params: &Params,
        base: usize,
        column: usize,
    ) -> Result<(), Fault> {
        let named: [bool; 3] = [w.has(b'x'), w.has(b'y'), w.has(b'z')];
        let any = named.iter().any(|&b| b) || w.has(b'@') || w.has(b'^');
        let mid = self.target(w)?;
        self.emit(Motion::Rapid, mid, 0.0, column)?;
        // The stored point in the program frame; the axes named go there, in that frame.
        let stored =
            Vector3::new(params.get(base), params.get(base + 1), params.get(base + 2)) * 1e-3;
        let home = self.to_program(&stored);
        let mut end = mid;
        for (k, &given) in named.iter().enumerate() {
            if (given || !any)
                && let (Some(e), Some(h)) = (end.get_mut(k), home.get(k))
            {
                *e = *h;
            }
        }
        self.emit(Motion::Rapid, end, 0.0, column)
    }

    /// `G5` (cubic, `I J P Q`) and `G5.1` (quadratic, `I J`) B-splines in the XY plane, as
    /// chords within [`SPLINE_TOLERANCE`].
    fn spline(&mut self, w: &mut Words, cubic: bool, column: usize) -> Result<(), Fault> {
        let name = if cubic { "G5" } else { "G5.1" };
        if self.plane != Plane::Xy {
            return fault(
                column,
                std::format!("{name}: splines in G17 (the XY plane) only"),
            );
        }
        if w.has(b'z') {
            return fault(
                w.column(b'z'),
                std::format!("{name}: a spline moves X and Y only"),
            );
        }
        let start = self.pos;
        let (i, j) = (w.take(b'i'), w.take(b'j'));
        let end = self.target(w)?;
        let u = self.units;
        let (s, e) = (start.xy(), end.xy());
        let points: [Vector2<f64>; 4] = if cubic {
            let (Some(p), Some(q)) = (w.take(b'p'), w.take(b'q')) else {
                return fault(
                    column,
                    "G5 needs both P and Q (the second control point's offset from the end)",
                );
            };
            let first = match (i, j, self.spline_pq) {
                (Some(i), Some(j), _) => Vector2::new(i, j),
                (None, None, Some((pp, qq))) => Vector2::new(-pp, -qq),
                _ => {
                    return fault(
                        column,
                        "G5 needs I and J (the first control point's offset from the start), except \
                         right after another G5",
                    );
                }
            };
            self.spline_pq = Some((p, q));
            [s, s + first * u, e + Vector2::new(p, q) * u, e]
        } else {
            let (Some(i), Some(j)) = (i, j) else {
                return fault(
                    column,
                    "G5.1 needs both I and J (the control point's offset from the start)",
                );
            };
            let c = s + Vector2::new(i, j) * u;
            // A quadratic as a cubic: the same curve.
            [s, s + (c - s) * (2.0 / 3.0), e + (c - e) * (2.0 / 3.0), e]
        };
        let [p0, p1, p2, p3] = points;
        let point = |t: f64| {
            let m = 1.0 - t;
            p0 * (m * m * m) + p1 * (3.0 * m * m * t) + p2 * (3.0 * m * t * t) + p3 * (t * t * t)
        };
        // Chord error <= max|B''| dt^2 / 8 for uniform steps dt.
        let curvature = ((p0 - p1 * 2.0 + p2).norm()).max((p1 - p2 * 2.0 + p3).norm()) * 6.0;
        let chords = ((curvature / (8.0 * SPLINE_TOLERANCE)).sqrt().ceil() as usize)
            .clamp(1, MAX_SPLINE_CHORDS);
        let length: f64 = (0..chords)
            .map(|k| {
                (point((k + 1) as f64 / chords as f64) - point(k as f64 / chords as f64)).norm()
            })
            .sum();
        let feed = self.speed(w, length, column)?;
        for k in 1..=chords {
            let p = if k == chords {
                e
            } else {
                point(k as f64 / chords as f64)
            };
            self.emit(
                Motion::Linear,
                Vector3::new(p.x, p.y, start.z),
                feed,
                column,
            )?;
        }
        Ok(())
    }
}
