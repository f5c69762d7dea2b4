//! Serial robots: the virtual-joint model of Hähn and Weigold (forward compliance, Eq. 1-9;
//! Cartesian and axis-specific correction, section 2.2).

use std::ffi::c_char;

use deflect_core::SerialRobot;
use deflect_core::vjm::{self, Data, Vector6};

use crate::boundary::{
    array, c_str, destroy, guard, handle, handle_mut, load, slice, slice_mut, write,
};
use crate::status::{DEFLECT_ERR_NULL, DeflectStatus, load_failure, tick_status};

/// Most actuated joints of a serial robot (length of `DeflectJointCorrection.dq`).
pub const DEFLECT_MAX_DOF: usize = 8;

const _: () = assert!(DEFLECT_MAX_DOF == vjm::MAX_DOF);

/// Result of `deflect_serial_robot_joint_correction`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectJointCorrection {
    /// Correction to add to the nominal joints \[rad or m\]; entries past the robot's dof are 0.
    pub dq: [f64; DEFLECT_MAX_DOF],
    /// Gauss-Newton steps taken.
    pub iterations: u32,
    /// Remaining pose error |\[dp; dr\]| of the deflected TCP at q + dq \[m, rad\].
    pub residual: f64,
    /// Smallest singular value of the joint Jacobian at the last step (NaN if no step).
    pub sigma_min: f64,
    /// 1 if `residual <= tolerance`, else 0.
    pub converged: i32,
}

/// A serial robot (virtual-joint model) loaded from URDF + stiffness TOML, with its own
/// per-call workspace. Opaque; create with `deflect_serial_robot_load`, free with
/// `deflect_serial_robot_destroy`. Not thread-safe: one thread at a time.
#[derive(Debug)]
pub struct DeflectSerialRobot {
    pub(crate) robot: SerialRobot,
    data: Data,
}

/// Loads a serial robot from a URDF file and a stiffness TOML file (see deflect-core's
/// `io::urdf` and `io::stiffness` modules for the formats); the chain runs from the URDF's root link to `tip_link`.
/// Init time: allocates. On success `*out` is a new handle; on failure `*out` is NULL and
/// `err` (if not NULL) receives the message, NUL-terminated, truncated to `err_len` bytes.
///
/// Returns `DEFLECT_ERR_NULL` (a NULL string or `out`), `DEFLECT_ERR_INVALID_ARGUMENT`
/// (a string that is not UTF-8) or `DEFLECT_ERR_LOAD` (unreadable or invalid files).
///
/// # Safety
/// The strings are NULL or NUL-terminated; `out` is NULL or writable; `err` is NULL or
/// writable for `err_len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_robot_load(
    urdf_path: *const c_char,
    stiffness_path: *const c_char,
    tip_link: *const c_char,
    out: *mut *mut DeflectSerialRobot,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    let make = || {
        // SAFETY: the strings are NULL or NUL-terminated by contract.
        let (urdf, stiffness, tip) = unsafe {
            (
                c_str(urdf_path, "urdf_path")?,
                c_str(stiffness_path, "stiffness_path")?,
                c_str(tip_link, "tip_link")?,
            )
        };
        let robot = SerialRobot::from_path(urdf, stiffness, tip).map_err(load_failure)?;
        let data = Data::new(&robot.model);
        Ok(DeflectSerialRobot { robot, data })
    };
    // SAFETY: forwarded caller contract for `out`, `err`, `err_len`.
    unsafe { load(out, err, err_len, make) }
}

/// Frees a robot handle. NULL is a no-op.
///
/// # Safety
/// `robot` is NULL or a live handle from `deflect_serial_robot_load`, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_robot_destroy(robot: *mut DeflectSerialRobot) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(robot) };
        Ok(())
    });
}

/// Writes the robot's number of actuated joints (the length of `q`) to `*dof` and its number
/// of virtual joints to `*springs` (either output may be NULL).
///
/// # Safety
/// `robot` is NULL or a live handle; the outputs are NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_robot_dof(
    robot: *const DeflectSerialRobot,
    dof: *mut usize,
    springs: *mut usize,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let r = unsafe { handle(robot) }?;
        if !dof.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(dof, r.robot.model.dof()) }?;
        }
        if !springs.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(springs, r.robot.model.spring_count()) }?;
        }
        Ok(())
    })
}

/// Rigid TCP pose at joints `q[q_len]` \[rad or m\], written to `out[16]` as a row-major 4 x 4
/// homogeneous matrix (translation in elements 3, 7, 11) \[m\]. Per tick: no allocation.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_WRONG_LENGTH` or `DEFLECT_ERR_NON_FINITE`.
///
/// # Safety
/// `robot` is NULL or a live handle not used by another thread; `q` holds `q_len` doubles,
/// `out` 16 writable doubles (or NULL).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_robot_forward(
    robot: *mut DeflectSerialRobot,
    q: *const f64,
    q_len: usize,
    out: *mut f64,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (r, q, out) = unsafe { (handle_mut(robot)?, slice(q, q_len)?, slice_mut(out, 16)?) };
        let t = vjm::forward(&r.robot.model, &mut r.data, q).map_err(|e| tick_status(&e))?;
        for (d, s) in out.iter_mut().zip(crate::pose_motion::row_major(&t)) {
            *d = s;
        }
        Ok(())
    })
}

/// TCP deflection `out[6] = [dx, dy, dz, rx, ry, rz]` \[m, rad\] (base frame) at joints
/// `q[q_len]` \[rad or m\] under the TCP wrench `wrench[6] = [Fx, Fy, Fz, Mx, My, Mz]`
/// \[N, N m\] (base frame, moment about the TCP): the exact virtual-joint model (Hahn &
/// Weigold, Eq. 2-9). Per tick: no allocation.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_WRONG_LENGTH` (`q_len` is not the robot's dof)
/// or `DEFLECT_ERR_NON_FINITE`.
///
/// # Safety
/// `robot` is NULL or a live handle not used by another thread; `q` holds `q_len` doubles,
/// `wrench` 6 and `out` 6 writable doubles (or NULL).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_robot_deflection(
    robot: *mut DeflectSerialRobot,
    q: *const f64,
    q_len: usize,
    wrench: *const f64,
    out: *mut f64,
) -> DeflectStatus {
    // SAFETY: forwarded under this function's contract.
    unsafe {
        loaded_tcp(robot, q, q_len, wrench, out, |m, d, q, w| {
            vjm::deflection(m, d, q, w, vjm::Load::Exact)
        })
    }
}

/// Linearized TCP deflection `out[6] = C(q) wrench` \[m, rad\] (base frame) at joints
/// `q[q_len]` \[rad or m\] under the TCP wrench `wrench[6]` \[N, N m\] (base frame, moment
/// about the TCP): the first-order term of `deflect_serial_robot_deflection`, in one pass
/// without forming the compliance (`deflect_core::vjm::linear_deflection`). Per tick: no
/// allocation.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_WRONG_LENGTH`, `DEFLECT_ERR_NON_FINITE`, or
/// `DEFLECT_ERR_INVALID_ARGUMENT` for a load that turns a spring past the small-deflection
/// model's 0.5 rad.
///
/// # Safety
/// `robot` is NULL or a live handle not used by another thread; `q` holds `q_len` doubles,
/// `wrench` 6 and `out` 6 writable doubles (or NULL).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_robot_linear_deflection(
    robot: *mut DeflectSerialRobot,
    q: *const f64,
    q_len: usize,
    wrench: *const f64,
    out: *mut f64,
) -> DeflectStatus {
    // SAFETY: forwarded under this function's contract.
    unsafe { loaded_tcp(robot, q, q_len, wrench, out, vjm::linear_deflection) }
}

/// A loaded-TCP call shared by the deflections: the handle and arrays decoded and checked,
/// `f`'s six numbers into `out`, its error as a status.
///
/// # Safety
/// As the callers': `robot` NULL or a live handle not used by another thread, `q` holding
/// `q_len` doubles, `wrench` 6 and `out` 6 writable doubles (or NULL).
unsafe fn loaded_tcp(
    robot: *mut DeflectSerialRobot,
    q: *const f64,
    q_len: usize,
    wrench: *const f64,
    out: *mut f64,
    f: impl FnOnce(&vjm::Model, &mut Data, &[f64], &Vector6) -> Result<Vector6, deflect_core::TickError>,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (r, q, w, out) = unsafe {
            (
                handle_mut(robot)?,
                slice(q, q_len)?,
                array::<6>(wrench)?,
                slice_mut(out, 6)?,
            )
        };
        let d =
            f(&r.robot.model, &mut r.data, q, &Vector6::from(w)).map_err(|e| tick_status(&e))?;
        out.copy_from_slice(d.as_slice());
        Ok(())
    })
}

/// The 6x6 Cartesian compliance of the linearized model at joints `q[q_len]`, written
/// row-major to `out[36]`: `out[6 * i + j] = C[i][j]` with rows and columns ordered
/// `[dx, dy, dz, rx, ry, rz]` x `[Fx, Fy, Fz, Mx, My, Mz]` \[m/N, m/(N m), rad/N, rad/(N m)\],
/// so `deflection ~= C wrench`. Per tick: no allocation.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_WRONG_LENGTH` or `DEFLECT_ERR_NON_FINITE`.
///
/// # Safety
/// `robot` is NULL or a live handle not used by another thread; `q` holds `q_len` doubles,
/// `out` 36 writable doubles (or NULL).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_robot_compliance(
    robot: *mut DeflectSerialRobot,
    q: *const f64,
    q_len: usize,
    out: *mut f64,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (r, q, out) = unsafe { (handle_mut(robot)?, slice(q, q_len)?, slice_mut(out, 36)?) };
        let c = vjm::compliance(&r.robot.model, &mut r.data, q).map_err(|e| tick_status(&e))?;
        // nalgebra stores column-major: the transpose's storage is C's rows.
        out.copy_from_slice(c.transpose().as_slice());
        Ok(())
    })
}

/// Axis-specific correction: the `dq` such that the robot commanded to `q + dq` and loaded by
/// `wrench[6]` puts its deflected TCP on the rigid TCP of `q[q_len]`. Gauss-Newton through an
/// SVD, at most `max_iterations` steps (1 = the paper's first-order `dq = -J^+ Delta`),
/// stopping at `residual <= tolerance`. Per tick: no allocation, bounded time.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_WRONG_LENGTH`, `DEFLECT_ERR_NON_FINITE`
/// (inputs or tolerance) or `DEFLECT_ERR_SINGULAR`. Not converging is not an error:
/// `out->converged` says it.
///
/// # Safety
/// `robot` is NULL or a live handle not used by another thread; `q` holds `q_len` doubles,
/// `wrench` 6; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_robot_joint_correction(
    robot: *mut DeflectSerialRobot,
    q: *const f64,
    q_len: usize,
    wrench: *const f64,
    max_iterations: u32,
    tolerance: f64,
    out: *mut DeflectJointCorrection,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (r, q, w) = unsafe { (handle_mut(robot)?, slice(q, q_len)?, array::<6>(wrench)?) };
        if out.is_null() {
            return Err(DEFLECT_ERR_NULL);
        }
        let c = vjm::joint_correction(
            &r.robot.model,
            &mut r.data,
            q,
            &Vector6::from(w),
            max_iterations as usize,
            tolerance,
        )
        .map_err(|e| tick_status(&e))?;
        let result = DeflectJointCorrection {
            dq: c.dq,
            iterations: u32::try_from(c.iterations).unwrap_or(u32::MAX),
            residual: c.residual,
            sigma_min: c.sigma_min,
            converged: i32::from(c.converged),
        };
        // SAFETY: non-null (checked) and writable by contract.
        unsafe { write(out, result) }
    })
}
