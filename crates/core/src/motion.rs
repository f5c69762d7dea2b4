//! Time-optimal, jerk-limited (7-phase, trapezoidal-acceleration) rest-to-rest motion along
//! straight lines and polylines in N-D, sampled exactly at any time: the "Desired Trajectory"
//! of section 3.3 / 4.2.3 of Paksoy et al. (`shared/papers/002_cf21300bacbb0f8b.txt`),
//! "a trapezoidal acceleration profile ... by limiting velocity, acceleration, and jerk".
//!
//! No heap, no panic: a [`Trajectory`] holds at most [`MAX_POINTS`] points in a
//! `heapless::Vec`, every input is validated once when the trajectory is planned, and
//! sampling it ([`Trajectory::sample`], [`Cursor`]) is a closed-form evaluation.
//!
//! # The 1-D profile ([`Profile`])
//! The path length `s(t)` goes from 0 to `L` at rest at both ends with `|s'| <= v_max`,
//! `|s''| <= a_max`, `|s'''| <= j_max`. The time-optimal rest-to-rest profile has seven phases
//! with jerk `+j, 0, -j, 0, -j, 0, +j` and durations `t_j, t_a, t_j, t_v, t_j, t_a, t_j`:
//!
//! 1. `v_max` and `a_max` reached: `t_j = a/j`, `t_a = v/a - a/j`, `t_v = L/v - (2 t_j + t_a)`
//!    (needs `a^2/j <= v` and `L >= v (v/a + a/j)`).
//! 2. `v_max` reached, `a_max` not (`a^2/j > v`): `t_j = sqrt(v/j)`, `t_a = 0`, peak
//!    acceleration `sqrt(v j)`.
//! 3. `v_max` not reached, `a_max` reached (`L >= 2 a^3/j^2`): `t_j = a/j`, `t_v = 0`,
//!    `t_a = (sqrt(t_j^2 + 4 L/a) - 3 t_j) / 2` (from `L = a (t_j + t_a)(2 t_j + t_a)`).
//! 4. neither reached: `t_a = t_v = 0`, `t_j = cbrt(L / (2 j))` (from `L = 2 j t_j^3`).
//!
//! The duration is `2 (2 t_j + t_a) + t_v`; whenever `v_max` is reached it equals
//! `L/v_max + t_acc` with the acceleration time `t_acc = 2 t_j + t_a`.
//! The deceleration half is evaluated as the mirror image of the acceleration half
//! (`s(t) = L - s(T - t)`), so the profile ends exactly at `L` with zero velocity and
//! acceleration.
//!
//! # Polylines
//! Each segment is its own rest-to-rest profile: the robot stops at every corner. This is
//! what the paper's triangle does (its sides are timed separately, 206..169 ms each), it keeps
//! the path exactly on the polyline (no corner blending), and the limits hold along the
//! path and, for the vector quantities, in the Euclidean norm. Segments of length at most
//! [`MIN_SEGMENT_LENGTH`] (repeated points) are skipped: they add no time and no motion.
//!
//! # Why not a crate
//! `ruckig` on crates.io (0.17) is a `cxx` binding to the C++ library (needs `std` and a C++
//! toolchain); `rsruckig` is a community port of the full Ruckig (arbitrary target states,
//! waypoints, ~8k lines) whose no-std story we have not verified to be allocation-free, and
//! which is far more than a rest-to-rest straight-line move needs. The closed form above is
//! about a hundred lines, exactly auditable against the paper, and fits the crate's
//! no-alloc/no-panic rules, so it is written here.

use core::fmt;

use nalgebra::{ComplexField, SVector};

/// Most points of a polyline (so at most `MAX_POINTS - 1` segments). The paper's longest
/// path, the triangle, has 4; 32 leaves room for a polygonal contour without costing much
/// memory (a 3-D trajectory is about 4 kB).
pub const MAX_POINTS: usize = 32;
/// Most segments of a [`Trajectory`].
pub const MAX_SEGMENTS: usize = MAX_POINTS - 1;
/// Update rate of the paper's trajectory correction (section 4.2.3) [Hz].
pub const DEFAULT_RATE_HZ: f64 = 2000.0;
/// Segments at most this long [m] are skipped when a polyline is planned.
pub const MIN_SEGMENT_LENGTH: f64 = 1.0e-12;
/// Gravity used to turn the paper's "1..5 g" into accelerations [m/s^2] (the paper converts
/// 5 kgf to 49.05 N, i.e. uses 9.81).
pub const PAPER_G: f64 = 9.81;
/// Length of the paper's x-axis motion [m].
pub const PAPER_X_LENGTH: f64 = 0.100;
/// Length of the paper's y-axis motion [m].
pub const PAPER_Y_LENGTH: f64 = 0.150;
/// Published x-motion durations at 1..5 g [s] (section 5.1, "approximately").
pub const PAPER_X_DURATIONS: [f64; 5] = [0.288, 0.272, 0.262, 0.255, 0.253];
/// Published y-motion durations at 1..5 g [s].
pub const PAPER_Y_DURATIONS: [f64; 5] = [0.408, 0.391, 0.382, 0.377, 0.375];
/// Published acceleration (= deceleration) times at 1..5 g [s], both motions.
pub const PAPER_ACCEL_TIMES: [f64; 5] = [0.056, 0.037, 0.026, 0.021, 0.018];

/// Why a motion could not be planned or sampled.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum MotionError {
    /// A limit is zero, negative, NaN or infinite.
    InvalidLimit {
        /// "v_max", "a_max" or "j_max".
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A 1-D profile length is negative or not finite [m].
    InvalidLength {
        /// The offending value.
        length: f64,
    },
    /// A path point holds NaN or an infinity.
    NonFinitePoint {
        /// Index of the point.
        index: usize,
        /// Coordinate index within the point.
        axis: usize,
    },
    /// A polyline needs at least two points.
    TooFewPoints {
        /// Points received.
        got: usize,
    },
    /// More points than [`MAX_POINTS`].
    CapacityExceeded {
        /// [`MAX_POINTS`].
        capacity: usize,
        /// Points received.
        got: usize,
    },
    /// A sampling rate is zero, negative or not finite [Hz].
    InvalidRate {
        /// The offending value.
        rate_hz: f64,
    },
    /// A sampling time is NaN or infinite.
    NonFiniteTime {
        /// The offending value.
        t: f64,
    },
    /// [`paper_limits`] knows 1..=5 g only.
    UnknownGLevel {
        /// The level asked for.
        g_level: u8,
    },
}

impl fmt::Display for MotionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidLimit { what, value } => {
                write!(f, "{what} is {value}; it must be finite and > 0")
            }
            Self::InvalidLength { length } => {
                write!(f, "profile length {length} m must be finite and >= 0")
            }
            Self::NonFinitePoint { index, axis } => {
                write!(f, "point {index}, coordinate {axis} is not finite")
            }
            Self::TooFewPoints { got } => {
                write!(f, "a path needs at least 2 points, got {got}")
            }
            Self::CapacityExceeded { capacity, got } => {
                write!(f, "{got} points exceed the capacity of {capacity}")
            }
            Self::InvalidRate { rate_hz } => {
                write!(f, "rate {rate_hz} Hz must be finite and > 0")
            }
            Self::NonFiniteTime { t } => write!(f, "time {t} s is not finite"),
            Self::UnknownGLevel { g_level } => {
                write!(f, "the paper's motions exist for 1..=5 g, not {g_level} g")
            }
        }
    }
}

impl core::error::Error for MotionError {}

/// Path limits: speed [m/s], acceleration [m/s^2] and jerk [m/s^3] along the path (and, for a
/// straight segment, the Euclidean norm of the vector quantities).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Largest speed [m/s].
    pub v_max: f64,
    /// Largest acceleration [m/s^2].
    pub a_max: f64,
    /// Largest jerk [m/s^3].
    pub j_max: f64,
}

impl Limits {
    /// Validated limits: each must be finite and > 0.
    pub fn new(v_max: f64, a_max: f64, j_max: f64) -> Result<Self, MotionError> {
        let l = Self {
            v_max,
            a_max,
            j_max,
        };
        l.validate()?;
        Ok(l)
    }

    /// Checks that every limit is finite and > 0 (the planners call this too, since the
    /// fields are public).
    pub fn validate(&self) -> Result<(), MotionError> {
        for (what, value) in [
            ("v_max", self.v_max),
            ("a_max", self.a_max),
            ("j_max", self.j_max),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(MotionError::InvalidLimit { what, value });
            }
        }
        Ok(())
    }
}

/// Limits that reproduce the paper's motions at `g_level` g (1..=5): `a_max = g_level * 9.81`,
/// and `v_max`, `j_max` fitted to the published durations and acceleration times
/// ([`PAPER_X_DURATIONS`], [`PAPER_Y_DURATIONS`], [`PAPER_ACCEL_TIMES`]):
///
/// * with `v_max` reached, a motion of length `L` lasts `L / v_max + t_acc`, so `1 / v_max` is
///   the least-squares fit of `(T_x - t_acc, T_y - t_acc)` against `(L_x, L_y)` = (0.1, 0.15) m;
/// * `j_max` then makes the acceleration time equal the published `t_acc`: if
///   `t_acc <= 2 v/a` (acceleration limit reached) `j = a / (t_acc - v/a)`, otherwise
///   `j = 4 v / t_acc^2` (the profile peaks below `a_max`; this is the case at 5 g, where
///   the 18 ms acceleration time lets the profile peak at 4.78 g).
///
/// The result is v_max = 0.4276, 0.4243, 0.4221, 0.4232, 0.4218 m/s and j_max = 791, 1276,
/// 2524, 3841, 5208 m/s^3 for 1..5 g; durations then agree with the paper to within 2.3 ms.
pub fn paper_limits(g_level: u8) -> Result<Limits, MotionError> {
    let k = usize::from(g_level)
        .checked_sub(1)
        .ok_or(MotionError::UnknownGLevel { g_level })?;
    let (Some(&tx), Some(&ty), Some(&ta)) = (
        PAPER_X_DURATIONS.get(k),
        PAPER_Y_DURATIONS.get(k),
        PAPER_ACCEL_TIMES.get(k),
    ) else {
        return Err(MotionError::UnknownGLevel { g_level });
    };
    let a = f64::from(g_level) * PAPER_G;
    let (lx, ly) = (PAPER_X_LENGTH, PAPER_Y_LENGTH);
    let inv_v = (lx * (tx - ta) + ly * (ty - ta)) / (lx * lx + ly * ly);
    let v = 1.0 / inv_v;
    let j = if ta <= 2.0 * v / a {
        a / (ta - v / a)
    } else {
        4.0 * v / (ta * ta)
    };
    Limits::new(v, a, j)
}

/// Position, velocity, acceleration and jerk along a path (scalars) [m, m/s, m/s^2, m/s^3].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PathState {
    /// Path length covered [m].
    pub s: f64,
    /// Path speed [m/s].
    pub v: f64,
    /// Path acceleration [m/s^2].
    pub a: f64,
    /// Path jerk [m/s^3].
    pub j: f64,
}

/// A time-optimal jerk-limited rest-to-rest 1-D profile from 0 to `length` (see the module
/// docs for the closed form).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    length: f64,
    jerk: f64,
    t_j: f64,
    t_a: f64,
    t_v: f64,
    // State at the end of phases 1, 2, 3 (end of the acceleration half).
    s1: f64,
    v1: f64,
    s2: f64,
    v2: f64,
    s3: f64,
    v3: f64,
}

impl Profile {
    /// The profile over `length` [m] (finite, >= 0; 0 gives a zero-duration profile).
    pub fn new(length: f64, limits: &Limits) -> Result<Self, MotionError> {
        limits.validate()?;
        if !(length.is_finite() && length >= 0.0) {
            return Err(MotionError::InvalidLength { length });
        }
        let (v, a, j) = (limits.v_max, limits.a_max, limits.j_max);
        // Acceleration half that reaches v_max (cases 1 and 2).
        let (mut t_j, mut t_a) = if a * a / j <= v {
            (a / j, v / a - a / j)
        } else {
            (ComplexField::sqrt(v / j), 0.0)
        };
        let a_peak = j * t_j;
        // Distance of the acceleration and deceleration halves together.
        let d_v = a_peak * (t_j + t_a) * (2.0 * t_j + t_a);
        if length < d_v {
            if length >= 2.0 * a * a * a / (j * j) {
                // Case 3.
                t_j = a / j;
                t_a = 0.5 * (ComplexField::sqrt(t_j * t_j + 4.0 * length / a) - 3.0 * t_j);
            } else {
                // Case 4.
                t_j = ComplexField::cbrt(length / (2.0 * j));
                t_a = 0.0;
            }
        }
        t_a = t_a.max(0.0);
        let ap = j * t_j;
        let s1 = j * t_j * t_j * t_j / 6.0;
        let v1 = 0.5 * j * t_j * t_j;
        let s2 = s1 + v1 * t_a + 0.5 * ap * t_a * t_a;
        let v2 = v1 + ap * t_a;
        let s3 = s2 + v2 * t_j + 0.5 * ap * t_j * t_j - j * t_j * t_j * t_j / 6.0;
        let v3 = v2 + ap * t_j - 0.5 * j * t_j * t_j;
        let t_v = if v3 > 0.0 {
            ((length - 2.0 * s3) / v3).max(0.0)
        } else {
            0.0
        };
        Ok(Self {
            length,
            jerk: j,
            t_j,
            t_a,
            t_v,
            s1,
            v1,
            s2,
            v2,
            s3,
            v3,
        })
    }

    /// Path length [m].
    pub fn length(&self) -> f64 {
        self.length
    }
    /// Duration of each of the four constant-jerk phases [s].
    pub fn t_j(&self) -> f64 {
        self.t_j
    }
    /// Duration of each of the two constant-acceleration phases [s].
    pub fn t_a(&self) -> f64 {
        self.t_a
    }
    /// Duration of the constant-velocity phase [s].
    pub fn t_v(&self) -> f64 {
        self.t_v
    }
    /// Acceleration (= deceleration) time `2 t_j + t_a` [s].
    pub fn accel_time(&self) -> f64 {
        2.0 * self.t_j + self.t_a
    }
    /// Total duration `2 (2 t_j + t_a) + t_v` [s].
    pub fn duration(&self) -> f64 {
        2.0 * self.accel_time() + self.t_v
    }
    /// Peak speed [m/s] (`v_max` unless the path is too short).
    pub fn v_peak(&self) -> f64 {
        self.v3
    }
    /// Peak acceleration [m/s^2] (`a_max` unless the path or `v_max` is too small).
    pub fn a_peak(&self) -> f64 {
        self.jerk * self.t_j
    }
    /// Phase durations `[t_j, t_a, t_j, t_v, t_j, t_a, t_j]` [s].
    pub fn phase_durations(&self) -> [f64; 7] {
        let (tj, ta) = (self.t_j, self.t_a);
        [tj, ta, tj, self.t_v, tj, ta, tj]
    }

    /// The state at `t` [s], clamped to rest at 0 before the start and at `length` after the
    /// end (NaN counts as before the start; [`Trajectory::sample`] rejects it).
    pub fn sample(&self, t: f64) -> PathState {
        let total = self.duration();
        // `!(t > 0)` also catches NaN.
        if t.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return PathState::default();
        }
        if t >= total {
            return PathState {
                s: self.length,
                ..PathState::default()
            };
        }
        if t <= 0.5 * total {
            self.first_half(t)
        } else {
            let m = self.first_half(total - t);
            PathState {
                s: self.length - m.s,
                v: m.v,
                a: -m.a,
                j: m.j,
            }
        }
    }

    /// Acceleration half and cruise, integrated forward from rest.
    fn first_half(&self, t: f64) -> PathState {
        let (j, tj, ta) = (self.jerk, self.t_j, self.t_a);
        let ap = j * tj;
        if t < tj {
            PathState {
                s: j * t * t * t / 6.0,
                v: 0.5 * j * t * t,
                a: j * t,
                j,
            }
        } else if t < tj + ta {
            let d = t - tj;
            PathState {
                s: self.s1 + self.v1 * d + 0.5 * ap * d * d,
                v: self.v1 + ap * d,
                a: ap,
                j: 0.0,
            }
        } else if t < 2.0 * tj + ta {
            let d = t - tj - ta;
            PathState {
                s: self.s2 + self.v2 * d + 0.5 * ap * d * d - j * d * d * d / 6.0,
                v: self.v2 + ap * d - 0.5 * j * d * d,
                a: ap - j * d,
                j: -j,
            }
        } else {
            let d = t - (2.0 * tj + ta);
            PathState {
                s: self.s3 + self.v3 * d,
                v: self.v3,
                a: 0.0,
                j: 0.0,
            }
        }
    }
}

/// The state of an N-D trajectory at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State<const N: usize> {
    /// Time since the start [s].
    pub t: f64,
    /// Index of the segment being travelled (the last one once the motion is over).
    pub segment: usize,
    /// Path length from the start of the whole polyline, speed, acceleration and jerk along
    /// the current segment.
    pub path: PathState,
    /// Position [m].
    pub position: SVector<f64, N>,
    /// Velocity [m/s].
    pub velocity: SVector<f64, N>,
    /// Acceleration [m/s^2]: what the D'Alembert force `-m a` needs.
    pub acceleration: SVector<f64, N>,
    /// Jerk [m/s^3].
    pub jerk: SVector<f64, N>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Segment<const N: usize> {
    start: SVector<f64, N>,
    direction: SVector<f64, N>,
    profile: Profile,
    /// Start time [s] and path length before the segment [m].
    t0: f64,
    s0: f64,
}

/// A rest-to-rest jerk-limited motion along a line or polyline in N-D (N = 2, 3 in practice),
/// stopping at every corner. Plan it once, sample it at any time.
///
/// ```
/// use deflect_core::motion::{Limits, Trajectory};
/// use nalgebra::Vector2;
/// let lim = Limits::new(1.0, 10.0, 1000.0)?;
/// let traj = Trajectory::line(Vector2::new(0.0, 0.0), Vector2::new(0.1, 0.0), &lim)?;
/// let end = traj.sample(traj.duration())?;
/// assert_eq!(end.position, Vector2::new(0.1, 0.0));
/// let ticks = traj.ticks(2000.0)?.count();
/// assert_eq!(ticks, 1 + (traj.duration() * 2000.0).ceil() as usize);
/// # Ok::<(), deflect_core::motion::MotionError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory<const N: usize> {
    segments: heapless::Vec<Segment<N>, MAX_SEGMENTS>,
    start: SVector<f64, N>,
    end: SVector<f64, N>,
    limits: Limits,
    duration: f64,
    path_length: f64,
}

impl<const N: usize> Trajectory<N> {
    /// A straight rest-to-rest move from `start` to `end` (equal points give a zero-duration
    /// trajectory).
    pub fn line(
        start: SVector<f64, N>,
        end: SVector<f64, N>,
        limits: &Limits,
    ) -> Result<Self, MotionError> {
        Self::polyline(&[start, end], limits)
    }

    /// Rest-to-rest moves through `points` (2..=[`MAX_POINTS`]), stopping at each one;
    /// segments of length <= [`MIN_SEGMENT_LENGTH`] are skipped.
    pub fn polyline(points: &[SVector<f64, N>], limits: &Limits) -> Result<Self, MotionError> {
        limits.validate()?;
        if points.len() < 2 {
            return Err(MotionError::TooFewPoints { got: points.len() });
        }
        if points.len() > MAX_POINTS {
            return Err(MotionError::CapacityExceeded {
                capacity: MAX_POINTS,
                got: points.len(),
            });
        }
        for (index, p) in points.iter().enumerate() {
            if let Some(axis) = p.iter().position(|c| !c.is_finite()) {
                return Err(MotionError::NonFinitePoint { index, axis });
            }
        }
        let (Some(&start), Some(&end)) = (points.first(), points.last()) else {
            return Err(MotionError::TooFewPoints { got: points.len() });
        };
        let mut segments = heapless::Vec::new();
        let (mut prev, mut t0, mut s0) = (start, 0.0, 0.0);
        for &p in points.iter().skip(1) {
            let d = p - prev;
            let length = d.norm();
            if length <= MIN_SEGMENT_LENGTH {
                continue;
            }
            let profile = Profile::new(length, limits)?;
            let seg = Segment {
                start: prev,
                direction: d / length,
                profile,
                t0,
                s0,
            };
            segments
                .push(seg)
                .map_err(|_| MotionError::CapacityExceeded {
                    capacity: MAX_POINTS,
                    got: points.len(),
                })?;
            t0 += profile.duration();
            s0 += length;
            prev = p;
        }
        Ok(Self {
            segments,
            start,
            end,
            limits: *limits,
            duration: t0,
            path_length: s0,
        })
    }

    /// Total duration [s].
    pub fn duration(&self) -> f64 {
        self.duration
    }
    /// Total path length [m].
    pub fn path_length(&self) -> f64 {
        self.path_length
    }
    /// First point.
    pub fn start(&self) -> SVector<f64, N> {
        self.start
    }
    /// Last point (reached exactly at [`Self::duration`]).
    pub fn end(&self) -> SVector<f64, N> {
        self.end
    }
    /// The limits it was planned with.
    pub fn limits(&self) -> Limits {
        self.limits
    }
    /// Number of (non-skipped) segments.
    pub fn segment_count(&self) -> usize {
        self.segments.len()
    }
    /// The 1-D profile of segment `i`, and its start time [s].
    pub fn segment_profile(&self, i: usize) -> Option<(&Profile, f64)> {
        self.segments.get(i).map(|s| (&s.profile, s.t0))
    }

    /// The exact state at `t` [s]; before 0 it is the start at rest, from [`Self::duration`]
    /// on the end at rest (exactly the last point).
    pub fn sample(&self, t: f64) -> Result<State<N>, MotionError> {
        if !t.is_finite() {
            return Err(MotionError::NonFiniteTime { t });
        }
        Ok(self.sample_from(t, 0).0)
    }

    /// Samples at `t` searching segments from `hint` on; returns the segment found.
    fn sample_from(&self, t: f64, hint: usize) -> (State<N>, usize) {
        let rest = |position, segment, s| State {
            t,
            segment,
            path: PathState {
                s,
                ..PathState::default()
            },
            position,
            velocity: SVector::zeros(),
            acceleration: SVector::zeros(),
            jerk: SVector::zeros(),
        };
        let last = self.segments.len().saturating_sub(1);
        if t >= self.duration {
            return (rest(self.end, last, self.path_length), last);
        }
        if t <= 0.0 {
            return (rest(self.start, 0, 0.0), 0);
        }
        // Cursors move forward, so start at the hint and fall back to a full scan.
        let start = if self.segments.get(hint).is_some_and(|s| s.t0 <= t) {
            hint
        } else {
            0
        };
        let mut index = start;
        for (i, seg) in self.segments.iter().enumerate().skip(start) {
            if seg.t0 <= t {
                index = i;
            } else {
                break;
            }
        }
        let Some(seg) = self.segments.get(index) else {
            return (rest(self.end, last, self.path_length), last);
        };
        let p = seg.profile.sample(t - seg.t0);
        let state = State {
            t,
            segment: index,
            path: PathState {
                s: seg.s0 + p.s,
                ..p
            },
            position: seg.start + seg.direction * p.s,
            velocity: seg.direction * p.v,
            acceleration: seg.direction * p.a,
            jerk: seg.direction * p.j,
        };
        (state, index)
    }

    /// A cursor over ticks at `rate_hz` ([`DEFAULT_RATE_HZ`] in the paper): tick `k` is at
    /// `t = k / rate_hz`, computed from `k` (no drift), and a last tick lands exactly on
    /// [`Self::duration`] (the end point), so there are `ceil(duration * rate) + 1` ticks.
    pub fn ticks(&self, rate_hz: f64) -> Result<Cursor<'_, N>, MotionError> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(MotionError::InvalidRate { rate_hz });
        }
        // Tolerate rounding so that a duration of exactly k ticks gives k + 1 ticks.
        let ticks = ComplexField::ceil(self.duration * rate_hz - 1.0e-9).max(0.0);
        Ok(Cursor {
            trajectory: self,
            rate_hz,
            next: 0,
            last: ticks as usize,
            hint: 0,
            done: false,
        })
    }
}

/// Steps through a [`Trajectory`] tick by tick ([`Trajectory::ticks`]); an [`Iterator`] of
/// [`State`]s that a 2 kHz loop can also drive one [`Cursor::step`] at a time.
#[derive(Debug, Clone)]
pub struct Cursor<'a, const N: usize> {
    trajectory: &'a Trajectory<N>,
    rate_hz: f64,
    next: usize,
    last: usize,
    hint: usize,
    done: bool,
}

impl<const N: usize> Cursor<'_, N> {
    /// The next tick's state, or `None` after the final tick (at the end point).
    pub fn step(&mut self) -> Option<State<N>> {
        if self.done {
            return None;
        }
        let k = self.next;
        let t = if k >= self.last {
            self.done = true;
            self.trajectory.duration
        } else {
            (k as f64 / self.rate_hz).min(self.trajectory.duration)
        };
        self.next = k.saturating_add(1);
        let (state, seg) = self.trajectory.sample_from(t, self.hint);
        self.hint = seg;
        Some(state)
    }
    /// Ticks already returned.
    pub fn ticks_done(&self) -> usize {
        self.next
    }
    /// `true` once the final tick has been returned.
    pub fn is_finished(&self) -> bool {
        self.done
    }
    /// Ticks left, including the final one.
    pub fn remaining(&self) -> usize {
        if self.done {
            0
        } else {
            self.last.saturating_sub(self.next).saturating_add(1)
        }
    }
}

impl<const N: usize> Iterator for Cursor<'_, N> {
    type Item = State<N>;
    fn next(&mut self) -> Option<State<N>> {
        self.step()
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.remaining();
        (n, Some(n))
    }
}

impl<const N: usize> ExactSizeIterator for Cursor<'_, N> {}
