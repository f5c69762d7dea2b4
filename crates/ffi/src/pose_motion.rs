//! 6-D rest-to-rest pose motions: the TCP on a straight line and its orientation turned about
//! one fixed axis by a jerk-limited angle, synchronised (deflect-core's `PoseTrajectory`),
//! sampled exactly at servo ticks with angular velocity and acceleration.

use deflect_core::motion::{PoseLimits, PoseState, PoseTrajectory};
use deflect_core::vjm::pose_from_matrix;
use nalgebra::{Isometry3, Matrix4};

use crate::boundary::{array, destroy, guard, handle, load, write};
use crate::motion::{DeflectLimits, limits};
use crate::status::{DEFLECT_ERR_NULL, DeflectStatus, build_failure, tick_status};

/// The state of a pose motion at one time, base frame.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectPoseState {
    /// Time since the start \[s\].
    pub t: f64,
    /// TCP pose, a 4 x 4 homogeneous matrix in row-major order (translation in elements 3,
    /// 7, 11) \[m\].
    pub pose: [f64; 16],
    /// TCP velocity \[m/s\].
    pub velocity: [f64; 3],
    /// TCP acceleration \[m/s^2\].
    pub acceleration: [f64; 3],
    /// Angular velocity \[rad/s\].
    pub angular_velocity: [f64; 3],
    /// Angular acceleration \[rad/s^2\].
    pub angular_acceleration: [f64; 3],
}

/// A planned pose motion. Opaque; create with `deflect_pose_motion_line`, free with
/// `deflect_pose_motion_destroy`. Read-only after creation.
#[derive(Debug)]
pub struct DeflectPoseMotion {
    motion: PoseTrajectory,
}

/// A row-major 4 x 4 matrix as a checked rigid transform.
pub(crate) fn pose_of(m: &[f64; 16]) -> Result<Isometry3<f64>, DeflectStatus> {
    pose_from_matrix(&Matrix4::from_row_slice(m)).map_err(|e| tick_status(&e))
}

/// `iso` as a row-major 4 x 4 matrix.
pub(crate) fn row_major(iso: &Isometry3<f64>) -> [f64; 16] {
    // nalgebra stores columns: the transpose's storage is the row-major order.
    let m: [[f64; 4]; 4] = iso.to_homogeneous().transpose().into();
    let mut out = [0.0; 16];
    for (d, s) in out.iter_mut().zip(m.iter().flatten()) {
        *d = *s;
    }
    out
}

/// `s` in the C layout.
pub(crate) fn pose_state_of(s: &PoseState) -> DeflectPoseState {
    let v = |x: &nalgebra::Vector3<f64>| [x.x, x.y, x.z];
    DeflectPoseState {
        t: s.t,
        pose: row_major(&s.pose),
        velocity: v(&s.velocity),
        acceleration: v(&s.acceleration),
        angular_velocity: v(&s.angular_velocity),
        angular_acceleration: v(&s.angular_acceleration),
    }
}

/// Plans a time-optimal jerk-limited rest-to-rest pose motion from `start[16]` to `end[16]`
/// (row-major 4 x 4 rigid transforms, base frame): the position along the straight line under
/// `linear` (\[m/s, m/s^2, m/s^3\]), the orientation about one fixed axis under `angular`
/// (\[rad/s, rad/s^2, rad/s^3\]), on one profile. Init time: allocates the handle. On failure
/// `*out` is NULL.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE` or `DEFLECT_ERR_INVALID_ARGUMENT` (a
/// limit not finite and > 0, or a matrix that is not a rigid transform).
///
/// # Safety
/// `start`, `end` hold 16 doubles; `linear`, `angular` are NULL or readable; `out` is NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_pose_motion_line(
    start: *const f64,
    end: *const f64,
    linear: *const DeflectLimits,
    angular: *const DeflectLimits,
    out: *mut *mut DeflectPoseMotion,
) -> DeflectStatus {
    let make = || {
        let err = |s: DeflectStatus| (s, String::new());
        // SAFETY: pointers valid (or NULL) by contract.
        let (a, b, l, r) = unsafe {
            (
                array::<16>(start),
                array::<16>(end),
                handle(linear),
                handle(angular),
            )
        };
        let (a, b) = (pose_of(&a.map_err(err)?), pose_of(&b.map_err(err)?));
        let (a, b) = (a.map_err(err)?, b.map_err(err)?);
        let lim = PoseLimits {
            linear: limits(l.map_err(err)?).map_err(build_failure)?,
            angular: limits(r.map_err(err)?).map_err(build_failure)?,
        };
        let motion = PoseTrajectory::line(&a, &b, &lim).map_err(build_failure)?;
        Ok(DeflectPoseMotion { motion })
    };
    // SAFETY: forwarded caller contract for `out`.
    unsafe { load(out, std::ptr::null_mut(), 0, make) }
}

/// Frees a pose motion. NULL is a no-op.
///
/// # Safety
/// `motion` is NULL or a live handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_pose_motion_destroy(motion: *mut DeflectPoseMotion) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(motion) };
        Ok(())
    });
}

/// Writes the duration \[s\] to `*duration` and the number of ticks at `rate_hz` (tick `k` at
/// `k / rate_hz`, the last exactly at the duration) to `*ticks` (either may be NULL).
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_INVALID_ARGUMENT` (a rate not finite and > 0) or
/// `DEFLECT_ERR_BUDGET` (more than 2^40 ticks).
///
/// # Safety
/// `motion` is NULL or a live handle; the outputs are NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_pose_motion_info(
    motion: *const DeflectPoseMotion,
    rate_hz: f64,
    duration: *mut f64,
    ticks: *mut usize,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let m = unsafe { handle(motion) }?;
        let n = m.motion.tick_count(rate_hz).map_err(|e| tick_status(&e))?;
        if !duration.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(duration, m.motion.duration()) }?;
        }
        if !ticks.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(ticks, n) }?;
        }
        Ok(())
    })
}

/// The exact state at `t` \[s\] (at rest before 0 and from the duration on) into `*out`.
/// Per tick: no allocation. Returns `DEFLECT_ERR_NULL` or `DEFLECT_ERR_NON_FINITE`.
///
/// # Safety
/// `motion` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_pose_motion_sample(
    motion: *const DeflectPoseMotion,
    t: f64,
    out: *mut DeflectPoseState,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let m = unsafe { handle(motion) }?;
        if out.is_null() {
            return Err(DEFLECT_ERR_NULL);
        }
        let s = m.motion.sample(t).map_err(|e| tick_status(&e))?;
        // SAFETY: non-null (checked), writable by contract.
        unsafe { write(out, pose_state_of(&s)) }
    })
}
