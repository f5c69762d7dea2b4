//! A machining program as straight, circular and dwell moves in the workpiece frame, SI: what
//! the G-code reader ([`crate::io::gcode`]) produces and the path, the cutting-force model and
//! the material removal consume.
//!
//! The workpiece frame is the frame of the program's machine coordinates (LinuxCNC's: the
//! program's coordinates plus its work and axis offsets, `G54`-`G59.3` and `G92`, which a
//! program that never sets them leaves at zero). A robot's TCP is the tool tip, so a move's
//! points are the tool tip's, whatever tool length (`G43`) the program selects.

use alloc::string::String;
use alloc::vec::Vec;

use nalgebra::{ComplexField, Vector3};

mod validate;

/// Most moves one program holds: 500,000 (a finishing program of a large part; about 60 MB).
/// The reader refuses a longer program with [`crate::LoadError::TooLarge`].
pub const MAX_MOVES: usize = 500_000;

/// Largest coordinate, radius or offset \[m\] (1 km): a robot cell is metres.
pub const MAX_COORDINATE: f64 = 1.0e3;

/// Largest feed \[m/s\] (100 m/s = 6,000,000 mm/min).
pub const MAX_FEED: f64 = 100.0;

/// Largest spindle speed \[rpm\].
pub const MAX_SPINDLE_RPM: f64 = 1.0e6;

/// Most full turns one arc may sweep (a helix programmed with `P` turns): 1,000.
pub const MAX_ARC_TURNS: u32 = 1_000;

/// Longest dwell \[s\] (one hour; `G4 P`).
pub const MAX_DWELL: f64 = 3600.0;

/// Largest tool number (`T`): 99,999 (LinuxCNC's tool numbers are 32-bit; tables rarely pass
/// 1,000).
pub const MAX_TOOL_NUMBER: u32 = 99_999;

/// Tolerance on an arc whose end is not exactly on the circle through its start: the radii
/// at the start and the end may differ by 0.0718 mm or 0.1 % of the larger radius, whichever
/// is larger (what LinuxCNC accepts in either unit; its reader, [`crate::io::gcode`], applies
/// LinuxCNC's own rule in the program's unit: 0.028 mm or 0.0028 in, or 0.1 % up to 100 times
/// that). Such an arc is driven as LinuxCNC drives it: a spiral, its radius linear in the
/// angle. More is an error, not a silently moved centre.
pub const ARC_TOLERANCE: (f64, f64) = (7.2e-5, 1.0e-3);

/// Largest gap between a move's start and the previous move's end \[m\] that
/// [`Program::validate`] accepts (a program is one path).
pub const MAX_GAP: f64 = 1.0e-9;

/// The plane of an arc (`G17`, `G18`, `G19`) and its axes: arcs turn about the plane's normal,
/// counter-clockwise (sweep > 0) as seen from the normal's positive side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Plane {
    /// `G17`: the XY plane, about +z.
    #[default]
    Xy,
    /// `G18`: the ZX plane, about +y (first axis z, second x).
    Zx,
    /// `G19`: the YZ plane, about +x (first axis y, second z).
    Yz,
}

impl Plane {
    /// The indices (0 x, 1 y, 2 z) of the plane's first axis, its second axis and its normal,
    /// a right-handed triple: XY (x, y, z), ZX (z, x, y), YZ (y, z, x).
    pub fn axes(self) -> (usize, usize, usize) {
        match self {
            Self::Xy => (0, 1, 2),
            Self::Zx => (2, 0, 1),
            Self::Yz => (1, 2, 0),
        }
    }

    /// The G code that selects the plane.
    pub fn gcode(self) -> &'static str {
        match self {
            Self::Xy => "G17",
            Self::Zx => "G18",
            Self::Yz => "G19",
        }
    }

    /// `v`'s coordinates along the first and second axes.
    fn split(self, v: &Vector3<f64>) -> (f64, f64) {
        let (a, b, _) = self.axes();
        (
            v.get(a).copied().unwrap_or(0.0),
            v.get(b).copied().unwrap_or(0.0),
        )
    }

    /// `v` with its first and second coordinates replaced.
    fn with(self, v: &Vector3<f64>, first: f64, second: f64) -> Vector3<f64> {
        let (a, b, _) = self.axes();
        let mut out = *v;
        if let Some(x) = out.get_mut(a) {
            *x = first;
        }
        if let Some(x) = out.get_mut(b) {
            *x = second;
        }
        out
    }

    /// The coordinate along the normal.
    fn normal(self, v: &Vector3<f64>) -> f64 {
        let (_, _, n) = self.axes();
        v.get(n).copied().unwrap_or(0.0)
    }
}

/// How a move goes from its start to its end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// `G0`: at the controller's rapid rate, not cutting.
    Rapid,
    /// `G1`: straight, at the programmed feed.
    Linear,
    /// `G2` / `G3` in `plane`: a circle about `center` through `sweep` \[rad\] about the
    /// plane's normal (> 0 counter-clockwise, `G3`; < 0 clockwise, `G2`; a full turn is
    /// +-2 pi, a helix of `P` turns up to +-2 pi [`MAX_ARC_TURNS`]), with the coordinate
    /// along the normal linear in the angle (a helix when it changes).
    Arc {
        /// The plane (`G17`, `G18`, `G19`).
        plane: Plane,
        /// Centre \[m\], workpiece frame; its coordinate along the normal is the start's.
        center: Vector3<f64>,
        /// Signed angle swept about the plane's normal \[rad\], `0 < |sweep| <= 2 pi turns`.
        sweep: f64,
    },
    /// `G4` (or a canned cycle's dwell): the tool stays at its point for `seconds` \[s\].
    Dwell {
        /// Duration \[s\], in `(0, MAX_DWELL]`.
        seconds: f64,
    },
}

/// The path control mode in effect for a move (`G61`, `G61.1`, `G64 P Q`): recorded for the
/// path model; the path of [`super::path`] stops at every corner whatever the mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathControl {
    /// `G61`: exact path (the tool follows the corners, slowing as needed).
    ExactPath,
    /// `G61.1`: exact stop at the end of each move.
    ExactStop,
    /// `G64 P Q`: blending; `tolerance` \[m\] is how far the path may leave the corner (`P`;
    /// 0: no limit, as fast as possible) and `naive_tolerance` \[m\] the collinear-move
    /// merge tolerance (`Q`; 0: none).
    Blend {
        /// `P` \[m\], >= 0.
        tolerance: f64,
        /// `Q` \[m\], >= 0.
        naive_tolerance: f64,
    },
}

impl Default for PathControl {
    /// `G64` without `P` or `Q`, LinuxCNC's state at the program start.
    fn default() -> Self {
        Self::Blend {
            tolerance: 0.0,
            naive_tolerance: 0.0,
        }
    }
}

/// One move of a program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// The program line it comes from (1-based), for every error and report about it.
    pub line: usize,
    /// Straight, circular, rapid or a dwell.
    pub motion: Motion,
    /// Start point \[m\], workpiece frame.
    pub start: Vector3<f64>,
    /// End point \[m\], workpiece frame (as programmed).
    pub end: Vector3<f64>,
    /// Programmed feed along the path \[m/s\] (inverse-time and per-revolution feeds turned
    /// into the path speed); 0 for a rapid move and a dwell.
    pub feed: f64,
    /// Spindle speed \[rev/s\]: > 0 clockwise (`M3`), < 0 counter-clockwise (`M4`), 0 off
    /// (`M5`, or before `M3`/`M4`).
    pub spindle: f64,
    /// The tool in the spindle (`T` and `M6`, or `M61 Q`); before the program's first tool
    /// change, the tool it selected with `T` (posts for manual tool changes write `T` without
    /// `M6`); 0 for none.
    pub tool: u32,
    /// The path control mode in effect.
    pub path_control: PathControl,
    /// The tool axis at the start, a unit vector from the tip towards the spindle, workpiece
    /// frame: `+z` for a 2.5-D program; a five-axis program's (APT `GOTO/x,y,z,i,j,k`, G-code
    /// `A B C` under a [`crate::machining::Kinematics`], a points CSV's `i j k`).
    pub start_axis: Vector3<f64>,
    /// The tool axis at the end (unit); between the two it turns along the great circle
    /// ([`Self::axis`]).
    pub end_axis: Vector3<f64>,
}

impl Move {
    /// A move with the spindle off, no tool and the default path control.
    pub fn new(
        line: usize,
        motion: Motion,
        start: Vector3<f64>,
        end: Vector3<f64>,
        feed: f64,
    ) -> Self {
        Self {
            line,
            motion,
            start,
            end,
            feed,
            spindle: 0.0,
            tool: 0,
            path_control: PathControl::default(),
            start_axis: Vector3::z(),
            end_axis: Vector3::z(),
        }
    }

    /// The tool axis at the fraction `s` in \[0, 1\] of the move: the great circle from
    /// [`Self::start_axis`] to [`Self::end_axis`], uniform in angle (the ends exactly). What
    /// a CAM system means between two tool vectors; a machine's rotary axes interpolated
    /// linearly leave it by a fraction of the step's turn (a step of a few degrees: a few
    /// thousandths of a degree off).
    pub fn axis(&self, s: f64) -> Vector3<f64> {
        if s <= 0.0 || self.start_axis == self.end_axis {
            return self.start_axis;
        }
        if s >= 1.0 {
            return self.end_axis;
        }
        slerp(&self.start_axis, &self.end_axis, s)
    }

    /// The angle the tool axis turns through along the move \[rad\].
    pub fn axis_turn(&self) -> f64 {
        angle_between(&self.start_axis, &self.end_axis)
    }

    /// Arc radius \[m\] (from the start point, in the arc's plane; 0 for other moves).
    pub fn radius(&self) -> f64 {
        match self.motion {
            Motion::Arc { plane, center, .. } => {
                let (a, b) = plane.split(&(self.start - center));
                ComplexField::sqrt(a * a + b * b)
            }
            _ => 0.0,
        }
    }

    /// Arc radius \[m\] at the end point (equal to [`Self::radius`] but for a spiral within
    /// [`ARC_TOLERANCE`]; 0 for other moves).
    pub fn end_radius(&self) -> f64 {
        match self.motion {
            Motion::Arc { plane, center, .. } => {
                let (a, b) = plane.split(&(self.end - center));
                ComplexField::sqrt(a * a + b * b)
            }
            _ => 0.0,
        }
    }

    /// Path length \[m\]: the chord of a straight move, `sqrt((r sweep)^2 + dn^2)` of an arc
    /// (`r` its mean radius, `dn` its rise along the normal), 0 for a dwell.
    pub fn length(&self) -> f64 {
        match self.motion {
            Motion::Arc { plane, sweep, .. } => {
                let arc = 0.5 * (self.radius() + self.end_radius()) * ComplexField::abs(sweep);
                let dn = plane.normal(&self.end) - plane.normal(&self.start);
                ComplexField::sqrt(arc * arc + dn * dn)
            }
            Motion::Dwell { .. } => 0.0,
            _ => (self.end - self.start).norm(),
        }
    }

    /// The point at the fraction `s` in \[0, 1\] of the move \[m\] (by angle on an arc, its
    /// radius linear in the angle as LinuxCNC drives a spiral within tolerance): `s <= 0` is
    /// the start, `s >= 1` the end, exactly.
    pub fn point(&self, s: f64) -> Vector3<f64> {
        // The ends exactly (an arc's rotation about its centre rounds them).
        if s <= 0.0 {
            return self.start;
        }
        if s >= 1.0 {
            return self.end;
        }
        match self.motion {
            Motion::Arc {
                plane,
                center,
                sweep,
            } => {
                let (c1, c2) = plane.split(&center);
                let (mut r1, mut r2) = plane.split(&(self.start - center));
                let (r0, re) = (self.radius(), self.end_radius());
                if r0 > 0.0 && re != r0 {
                    let k = (r0 + (re - r0) * s) / r0;
                    r1 *= k;
                    r2 *= k;
                }
                let (sin, cos) = ComplexField::sin_cos(sweep * s);
                let n0 = plane.normal(&self.start);
                let n = n0 + (plane.normal(&self.end) - n0) * s;
                let (_, _, k) = plane.axes();
                let mut p = plane.with(
                    &self.start,
                    c1 + cos * r1 - sin * r2,
                    c2 + sin * r1 + cos * r2,
                );
                if let Some(x) = p.get_mut(k) {
                    *x = n;
                }
                p
            }
            Motion::Dwell { .. } => self.start,
            _ => self.start + (self.end - self.start) * s,
        }
    }

    /// Unit tangent (feed direction) at the fraction `s`, workpiece frame; zero for a
    /// zero-length move and a dwell.
    pub fn tangent(&self, s: f64) -> Vector3<f64> {
        let t = match self.motion {
            Motion::Arc {
                plane,
                center,
                sweep,
            } => {
                let p = self.point(s);
                let (r1, r2) = plane.split(&(p - center));
                let r = ComplexField::sqrt(r1 * r1 + r2 * r2);
                // d/ds of the spiral: the radius' change outwards, the turn times the sweep;
                // the normal coordinate rises linearly.
                let dr = self.end_radius() - self.radius();
                let (u1, u2) = if r > 0.0 {
                    (r1 / r, r2 / r)
                } else {
                    (0.0, 0.0)
                };
                let (_, _, k) = plane.axes();
                let mut t = plane.with(
                    &Vector3::zeros(),
                    -r2 * sweep + dr * u1,
                    r1 * sweep + dr * u2,
                );
                if let Some(x) = t.get_mut(k) {
                    *x = plane.normal(&self.end) - plane.normal(&self.start);
                }
                t
            }
            Motion::Dwell { .. } => Vector3::zeros(),
            _ => self.end - self.start,
        };
        let n = t.norm();
        if n > 0.0 { t / n } else { Vector3::zeros() }
    }

    /// The path's curvature vector `dT/ds` at the fraction `s` \[1/m\], workpiece frame: the
    /// normal acceleration of a tool at speed `v` there is `v^2` times it (towards an arc's
    /// centre, `1 / r` long on a circle); zero on a straight move and a dwell. A second-order
    /// difference of [`Self::tangent`] over 1e-5 of the move (central, one-sided at the ends):
    /// the tangent is smooth along an arc, so the difference is exact to about 1e-9 relative.
    pub fn curvature(&self, s: f64) -> Vector3<f64> {
        let length = self.length();
        if !matches!(self.motion, Motion::Arc { .. }) || length <= 0.0 {
            return Vector3::zeros();
        }
        const H: f64 = 1.0e-5;
        let s = s.clamp(0.0, 1.0);
        let d = if s < H {
            self.tangent(s) * -3.0 + self.tangent(s + H) * 4.0 - self.tangent(s + 2.0 * H)
        } else if s > 1.0 - H {
            self.tangent(s) * 3.0 - self.tangent(s - H) * 4.0 + self.tangent(s - 2.0 * H)
        } else {
            self.tangent(s + H) - self.tangent(s - H)
        };
        d / (2.0 * H * length)
    }

    /// Whether the move cuts at a feed (`G1`-`G3`): not a rapid, not a dwell.
    pub fn is_feed(&self) -> bool {
        matches!(self.motion, Motion::Linear | Motion::Arc { .. })
    }
}

/// A program: its moves in order, each from the end of the one before.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Program {
    /// The moves, in program order.
    pub moves: Vec<Move>,
    /// The operations the program's moves fall into, in order of their first move (empty:
    /// one operation). What a CAM system calls a toolpath: the G-code reader starts one at
    /// each tool change and at each comment line standing alone between moves (the CAM's
    /// operation name: `(2D Pocket1)`, `( Profile1 )`), named by the last such comment.
    pub operations: Vec<Operation>,
}

/// A stretch of a program's moves: one operation of the CAM system.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Operation {
    /// The name: the comment that started it, trimmed, or `T<n>` after a tool change without
    /// one.
    pub name: String,
    /// Index of its first move in [`Program::moves`].
    pub first_move: usize,
}

impl Program {
    /// Total path length \[m\] of the feed moves (rapids and dwells excluded).
    pub fn cutting_length(&self) -> f64 {
        self.moves
            .iter()
            .filter(|m| m.is_feed())
            .map(Move::length)
            .sum()
    }

    /// The index in [`Self::operations`] of the operation move `index` belongs to (0 when
    /// the program has none listed).
    pub fn operation_of(&self, index: usize) -> usize {
        self.operations
            .partition_point(|o| o.first_move <= index)
            .saturating_sub(1)
    }

    /// Whether any move's tool axis leaves the workpiece's `+z` (a five-axis program).
    pub fn is_multi_axis(&self) -> bool {
        self.moves
            .iter()
            .any(|m| m.start_axis != Vector3::z() || m.end_axis != Vector3::z())
    }

    /// The tool numbers the program's moves use, ascending, each once.
    pub fn tools(&self) -> Vec<u32> {
        let mut t: Vec<u32> = self.moves.iter().map(|m| m.tool).collect();
        t.sort_unstable();
        t.dedup();
        t
    }
}

/// How far from unit length a move's tool axis may be (\[1\]), and how far a move's start
/// axis may be from the previous end axis: 1e-9 (the readers normalise what they read).
pub const AXIS_TOLERANCE: f64 = 1.0e-9;

/// Largest turn of the tool axis along one move \[rad\]: 179 degrees (the great circle
/// between opposite vectors has no direction; CAM programs turn by a few degrees per point).
pub const MAX_AXIS_TURN: f64 = 179.0 * core::f64::consts::PI / 180.0;

/// The angle between two unit vectors \[rad\], accurate near 0 and pi (`atan2` of the cross
/// and dot products).
pub(crate) fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    nalgebra::RealField::atan2(a.cross(b).norm(), a.dot(b))
}

/// The great circle from unit `a` to unit `b` at the fraction `s` of the angle.
pub(crate) fn slerp(a: &Vector3<f64>, b: &Vector3<f64>, s: f64) -> Vector3<f64> {
    let theta = angle_between(a, b);
    if theta < 1.0e-12 {
        return (a + (b - a) * s).normalize();
    }
    let sin = ComplexField::sin(theta);
    (a * ComplexField::sin((1.0 - s) * theta) + b * ComplexField::sin(s * theta)) / sin
}
