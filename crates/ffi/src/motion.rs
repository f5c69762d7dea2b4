//! Jerk-limited rest-to-rest motions along planar lines and polylines (Paksoy, Dede and Kiper
//! 2025, section 3.3), sampled exactly at servo ticks.

use deflect_core::BuildError;
use deflect_core::motion::{Limits, State, Trajectory, paper_limits};
use nalgebra::Vector2;

use crate::boundary::{array, destroy, guard, handle, handle_mut, load, slice, write};
use crate::status::{
    DEFLECT_ERR_NULL, DEFLECT_ERR_WRONG_LENGTH, DeflectStatus, build_failure, build_status,
    tick_status,
};

/// The paper's correction rate \[Hz\].
pub const DEFLECT_PAPER_RATE_HZ: f64 = 2000.0;

const _: () = assert!(DEFLECT_PAPER_RATE_HZ == deflect_core::motion::DEFAULT_RATE_HZ);

/// Path limits of a motion: speed \[m/s\], acceleration \[m/s^2\], jerk \[m/s^3\], each finite
/// and > 0.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectLimits {
    /// Largest speed \[m/s\].
    pub v_max: f64,
    /// Largest acceleration \[m/s^2\].
    pub a_max: f64,
    /// Largest jerk \[m/s^3\].
    pub j_max: f64,
}

/// The state of a planar trajectory at one time.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectState2 {
    /// Time since the start \[s\].
    pub t: f64,
    /// Index of the segment being travelled.
    pub segment: usize,
    /// Path length from the start of the polyline \[m\].
    pub path_s: f64,
    /// Path speed along the current segment \[m/s\].
    pub path_v: f64,
    /// Path acceleration along the current segment \[m/s^2\].
    pub path_a: f64,
    /// Path jerk along the current segment \[m/s^3\].
    pub path_j: f64,
    /// Position (x, y) \[m\].
    pub position: [f64; 2],
    /// Velocity \[m/s\].
    pub velocity: [f64; 2],
    /// Acceleration \[m/s^2\]: what the D'Alembert force -m* a needs.
    pub acceleration: [f64; 2],
    /// Jerk \[m/s^3\].
    pub jerk: [f64; 2],
}

/// A planned jerk-limited rest-to-rest motion along a planar line or polyline. Opaque; create
/// with `deflect_trajectory2_line` or `deflect_trajectory2_polyline`, free with
/// `deflect_trajectory2_destroy`.
#[derive(Debug)]
pub struct DeflectTrajectory2 {
    trajectory: Trajectory<2>,
}

fn state2(s: &State<2>) -> DeflectState2 {
    DeflectState2 {
        t: s.t,
        segment: s.segment,
        path_s: s.path.s,
        path_v: s.path.v,
        path_a: s.path.a,
        path_j: s.path.j,
        position: [s.position.x, s.position.y],
        velocity: [s.velocity.x, s.velocity.y],
        acceleration: [s.acceleration.x, s.acceleration.y],
        jerk: [s.jerk.x, s.jerk.y],
    }
}

pub(crate) fn limits(l: &DeflectLimits) -> Result<Limits, BuildError> {
    Limits::new(l.v_max, l.a_max, l.j_max)
}

/// Limits that reproduce the paper's motions at `g_level` g (1..5): a_max = g_level * 9.81
/// m/s^2, v_max and j_max fitted to the published durations. Returns `DEFLECT_ERR_NULL` or
/// `DEFLECT_ERR_INVALID_ARGUMENT` (g level outside 1..5).
///
/// # Safety
/// `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_paper_limits(
    g_level: u8,
    out: *mut DeflectLimits,
) -> DeflectStatus {
    guard(|| {
        if out.is_null() {
            return Err(DEFLECT_ERR_NULL);
        }
        let l = paper_limits(g_level).map_err(|e| build_status(&e))?;
        let value = DeflectLimits {
            v_max: l.v_max,
            a_max: l.a_max,
            j_max: l.j_max,
        };
        // SAFETY: non-null (checked), writable by contract.
        unsafe { write(out, value) }
    })
}

/// Plans a time-optimal jerk-limited rest-to-rest motion from `start[2]` to `end[2]` \[m\].
/// Init time: allocates the handle. Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE` or
/// `DEFLECT_ERR_INVALID_ARGUMENT` (a limit not finite and > 0). On failure `*out` is NULL.
///
/// # Safety
/// `start`, `end` hold 2 doubles; `limits` is NULL or readable; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_trajectory2_line(
    start: *const f64,
    end: *const f64,
    limits: *const DeflectLimits,
    out: *mut *mut DeflectTrajectory2,
) -> DeflectStatus {
    let make = || {
        let err = |s: DeflectStatus| (s, String::new());
        // SAFETY: pointers valid (or NULL) by contract.
        let (a, b, l) = unsafe { (array::<2>(start), array::<2>(end), handle(limits)) };
        let (a, b, l) = (a.map_err(err)?, b.map_err(err)?, l.map_err(err)?);
        let lim = self::limits(l).map_err(build_failure)?;
        let trajectory =
            Trajectory::line(Vector2::from(a), Vector2::from(b), &lim).map_err(build_failure)?;
        Ok(DeflectTrajectory2 { trajectory })
    };
    // SAFETY: forwarded caller contract for `out`.
    unsafe { load(out, std::ptr::null_mut(), 0, make) }
}

/// Re-plans `trajectory` in place as `deflect_trajectory2_line(start, end, limits)` would
/// plan it (the same result bit for bit), for a controller that plans move after move into
/// one handle: no allocation, the limits validated once (ruckig's `calculate(input,
/// trajectory)` habit). Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE` or
/// `DEFLECT_ERR_INVALID_ARGUMENT`; on failure the trajectory is unchanged.
///
/// # Safety
/// `trajectory` is NULL or a live handle not used elsewhere during the call; `start`, `end`
/// hold 2 doubles; `limits` is NULL or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_trajectory2_replan_line(
    trajectory: *mut DeflectTrajectory2,
    start: *const f64,
    end: *const f64,
    limits: *const DeflectLimits,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid (or NULL) by contract.
        let (tr, a, b, l) = unsafe {
            (
                handle_mut(trajectory)?,
                array::<2>(start)?,
                array::<2>(end)?,
                handle(limits)?,
            )
        };
        let lim = Limits {
            v_max: l.v_max,
            a_max: l.a_max,
            j_max: l.j_max,
        };
        tr.trajectory
            .replan_line(Vector2::from(a), Vector2::from(b), &lim)
            .map_err(|e| build_status(&e))
    })
}

/// Plans rest-to-rest motions through `n_points` points (2..32) given as `points[2 *
/// n_points] = x0, y0, x1, y1, ...` \[m\], stopping at each. Returns `DEFLECT_ERR_NULL`,
/// `DEFLECT_ERR_WRONG_LENGTH` (too few or too many points), `DEFLECT_ERR_NON_FINITE` or
/// `DEFLECT_ERR_INVALID_ARGUMENT`. On failure `*out` is NULL.
///
/// # Safety
/// `points` holds `2 * n_points` doubles; `limits` is NULL or readable; `out` is NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_trajectory2_polyline(
    points: *const f64,
    n_points: usize,
    limits: *const DeflectLimits,
    out: *mut *mut DeflectTrajectory2,
) -> DeflectStatus {
    let make = || {
        let err = |s: DeflectStatus| (s, String::new());
        let n = n_points
            .checked_mul(2)
            .ok_or(err(DEFLECT_ERR_WRONG_LENGTH))?;
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (p, l) = unsafe { (slice(points, n), handle(limits)) };
        let (p, l) = (p.map_err(err)?, l.map_err(err)?);
        let lim = self::limits(l).map_err(build_failure)?;
        let pts: Vec<Vector2<f64>> = p.chunks_exact(2).map(Vector2::from_column_slice).collect();
        let trajectory = Trajectory::polyline(&pts, &lim).map_err(build_failure)?;
        Ok(DeflectTrajectory2 { trajectory })
    };
    // SAFETY: forwarded caller contract for `out`.
    unsafe { load(out, std::ptr::null_mut(), 0, make) }
}

/// Frees a trajectory handle. NULL is a no-op.
///
/// # Safety
/// `trajectory` is NULL or a live handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_trajectory2_destroy(trajectory: *mut DeflectTrajectory2) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(trajectory) };
        Ok(())
    });
}

/// Writes the motion's total duration \[s\] to `*duration`.
///
/// # Safety
/// `trajectory` is NULL or a live handle; `duration` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_trajectory2_duration(
    trajectory: *const DeflectTrajectory2,
    duration: *mut f64,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL; `duration` NULL or writable, by contract.
        unsafe { write(duration, handle(trajectory)?.trajectory.duration()) }
    })
}

/// Number of servo ticks at `rate_hz` \[Hz\]: tick `k` (0 <= k < count) is at time
/// `deflect_trajectory2_tick_time(k)`, the last one exactly at the end point; `count =
/// ceil(duration * rate_hz) + 1`. Returns `DEFLECT_ERR_NULL` or
/// `DEFLECT_ERR_INVALID_ARGUMENT` (rate not finite and > 0).
///
/// # Safety
/// `trajectory` is NULL or a live handle; `count` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_trajectory2_tick_count(
    trajectory: *const DeflectTrajectory2,
    rate_hz: f64,
    count: *mut usize,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let t = unsafe { handle(trajectory) }?;
        let n = t
            .trajectory
            .ticks(rate_hz)
            .map_err(|e| tick_status(&e))?
            .remaining();
        // SAFETY: NULL or writable by contract.
        unsafe { write(count, n) }
    })
}

/// Time \[s\] of tick `k` at `rate_hz`, exactly as deflect's own tick cursor computes it:
/// `k / rate_hz` (no accumulated drift), and the duration itself for the last tick
/// (`k >= count - 1`). Returns `DEFLECT_ERR_NULL` or `DEFLECT_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `trajectory` is NULL or a live handle; `t` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_trajectory2_tick_time(
    trajectory: *const DeflectTrajectory2,
    rate_hz: f64,
    k: usize,
    t: *mut f64,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let tr = unsafe { handle(trajectory) }?;
        let last = tr
            .trajectory
            .ticks(rate_hz)
            .map_err(|e| tick_status(&e))?
            .remaining()
            .saturating_sub(1);
        let duration = tr.trajectory.duration();
        let time = if k >= last {
            duration
        } else {
            (k as f64 / rate_hz).min(duration)
        };
        // SAFETY: NULL or writable by contract.
        unsafe { write(t, time) }
    })
}

/// The exact state at time `t` \[s\] (the start at rest before 0, the end at rest from the
/// duration on). Per tick: no allocation, closed form. Returns `DEFLECT_ERR_NULL` or
/// `DEFLECT_ERR_NON_FINITE` (NaN or infinite `t`).
///
/// # Safety
/// `trajectory` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_trajectory2_sample(
    trajectory: *const DeflectTrajectory2,
    t: f64,
    out: *mut DeflectState2,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let tr = unsafe { handle(trajectory) }?;
        if out.is_null() {
            return Err(DEFLECT_ERR_NULL);
        }
        let s = tr.trajectory.sample(t).map_err(|e| tick_status(&e))?;
        // SAFETY: non-null (checked), writable by contract.
        unsafe { write(out, state2(&s)) }
    })
}
