//! Time-optimal, jerk-limited (7-phase, trapezoidal-acceleration) rest-to-rest motion along
//! straight lines and polylines in N-D, sampled exactly at any time: the "Desired Trajectory"
//! of section 3.3 / 4.2.3 of Paksoy, Dede and Kiper (2025),
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

mod pose;
mod profile;
#[cfg(feature = "alloc")]
mod sampled;
mod trajectory;

pub use pose::{PoseLimits, PoseState, PoseTrajectory};
pub use profile::{PathState, PreparedLimits, Profile};
#[cfg(feature = "alloc")]
pub use sampled::SampledTrajectory;
pub use trajectory::{AxisLimits, Cursor, Data, State, Trajectory, step};

/// The immutable model of the tick shape: a planned trajectory; [`Data`] is its sampling state
/// and [`step`] the tick.
pub type Model<const N: usize> = Trajectory<N>;

use crate::error::{BuildError, TickError, param};

/// Most points of a polyline (so at most `MAX_POINTS - 1` segments). The paper's longest
/// path, the triangle, has 4; 32 leaves room for a polygonal contour without costing much
/// memory (a 3-D trajectory is about 4 kB).
pub const MAX_POINTS: usize = 32;
/// Most segments of a [`Trajectory`].
pub const MAX_SEGMENTS: usize = MAX_POINTS - 1;
/// Update rate of the paper's trajectory correction (section 4.2.3) \[Hz\].
pub const DEFAULT_RATE_HZ: f64 = 2000.0;
/// Most ticks a [`Cursor`] may step through: 2^40, 17 years at 2 kHz. A cursor costs no
/// memory, but a count past this comes from limits or rates far outside any machine (e.g.
/// `v_max = 1e-300` m/s), so [`Trajectory::ticks`] refuses it with
/// [`crate::TickError::Budget`].
pub const MAX_TICKS: u64 = 1 << 40;
/// Most samples a call that stores every tick may produce (the bindings' `plan_*`,
/// [`crate::dalembert::parallel::correct`]): 2^22 = 4 194 304, 35 min at 2 kHz, about 440 MB for a
/// 3-D trajectory's time, position, velocity, acceleration and jerk. See
/// [`Trajectory::sample_count`].
pub const MAX_SAMPLES: usize = 1 << 22;
/// Segments at most this long \[m\] are skipped when a polyline is planned.
pub const MIN_SEGMENT_LENGTH: f64 = 1.0e-12;
/// Longest planned motion (segment or pose move) \[s\]: 1e6 s, 11.6 days. Limits of 1e-300
/// plan a finite but absurd 3e299 s; past this the planner refuses them as it refuses
/// sub-normal limits, rather than return a motion no controller will run.
pub const MAX_DURATION: f64 = 1.0e6;
/// Gravity used to turn the paper's "1..5 g" into accelerations \[m/s^2\] (the paper converts
/// 5 kgf to 49.05 N, i.e. uses 9.81).
pub const PAPER_G: f64 = 9.81;
/// Length of the paper's x-axis motion \[m\].
pub const PAPER_X_LENGTH: f64 = 0.100;
/// Length of the paper's y-axis motion \[m\].
pub const PAPER_Y_LENGTH: f64 = 0.150;
/// Published x-motion durations at 1..5 g \[s\] (section 5.1, "approximately").
pub const PAPER_X_DURATIONS: [f64; 5] = [0.288, 0.272, 0.262, 0.255, 0.253];
/// Published y-motion durations at 1..5 g \[s\].
pub const PAPER_Y_DURATIONS: [f64; 5] = [0.408, 0.391, 0.382, 0.377, 0.375];
/// Published acceleration (= deceleration) times at 1..5 g \[s\], both motions.
pub const PAPER_ACCEL_TIMES: [f64; 5] = [0.056, 0.037, 0.026, 0.021, 0.018];

/// Path limits: speed \[m/s\], acceleration \[m/s^2\] and jerk \[m/s^3\] along the path (and, for a
/// straight segment, the Euclidean norm of the vector quantities).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Largest speed \[m/s\].
    pub v_max: f64,
    /// Largest acceleration \[m/s^2\].
    pub a_max: f64,
    /// Largest jerk \[m/s^3\].
    pub j_max: f64,
}

impl Limits {
    /// Validated limits: each must be finite and > 0.
    pub fn new(v_max: f64, a_max: f64, j_max: f64) -> Result<Self, BuildError> {
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
    pub fn validate(&self) -> Result<(), BuildError> {
        for (what, value) in [
            ("v_max", self.v_max),
            ("a_max", self.a_max),
            ("j_max", self.j_max),
        ] {
            // Sub-normal limits underflow the closed form (the profile would not reach its
            // length): they are refused with the others.
            param(
                what,
                value,
                value.is_normal() && value > 0.0,
                "finite and > 0 (not sub-normal)",
            )?;
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
pub fn paper_limits(g_level: u8) -> Result<Limits, BuildError> {
    let k = usize::from(g_level)
        .checked_sub(1)
        .ok_or(BuildError::UnknownGLevel { g_level })?;
    let (Some(&tx), Some(&ty), Some(&ta)) = (
        PAPER_X_DURATIONS.get(k),
        PAPER_Y_DURATIONS.get(k),
        PAPER_ACCEL_TIMES.get(k),
    ) else {
        return Err(BuildError::UnknownGLevel { g_level });
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

/// Ticks of a motion of `duration` \[s\] at `rate_hz`: tick `k` at `k / rate_hz`, the last
/// exactly at the duration, so `ceil(duration * rate) + 1` (rounding of 1e-9 tick tolerated,
/// so that a duration of exactly `k` ticks gives `k + 1`). [`TickError::InvalidArgument`] for
/// a rate that is not finite, normal and > 0, [`TickError::Budget`] past [`MAX_TICKS`].
pub(crate) fn tick_count(duration: f64, rate_hz: f64) -> Result<usize, TickError> {
    counted(duration, rate_hz, "ticks", "MAX_TICKS", MAX_TICKS as f64)
}

/// [`tick_count`] for a call that stores every tick: [`TickError::Budget`] past
/// [`MAX_SAMPLES`], checked on the count itself so that such a call names this one budget
/// however far past it the request is (not [`MAX_TICKS`] for the farthest).
pub(crate) fn sample_count(duration: f64, rate_hz: f64) -> Result<usize, TickError> {
    counted(
        duration,
        rate_hz,
        "samples",
        "MAX_SAMPLES",
        MAX_SAMPLES as f64,
    )
}

fn counted(
    duration: f64,
    rate_hz: f64,
    what: &'static str,
    budget: &'static str,
    limit: f64,
) -> Result<usize, TickError> {
    // Sub-normal rates are refused like sub-normal limits: 5e-324 Hz is one tick per
    // 6e315 years, a typo, not a rate.
    if !(rate_hz.is_normal() && rate_hz > 0.0) {
        return Err(TickError::InvalidArgument {
            what: "rate_hz",
            value: rate_hz,
        });
    }
    let intervals = nalgebra::ComplexField::ceil(duration * rate_hz - 1.0e-9).max(0.0);
    let count = intervals + 1.0;
    if count.is_nan() || count > limit {
        return Err(TickError::Budget {
            what,
            budget,
            limit,
            requested: count,
        });
    }
    // Exact: at most 2^40 < 2^53, and usize holds it on 64-bit targets; a 32-bit target
    // saturates, which the sample budget and the cursor's own bound catch.
    Ok(usize::try_from(count as u64).unwrap_or(usize::MAX))
}
