//! The 6-D D'Alembert corrector for serial arms (deflect-core's `dalembert::serial`): the
//! payload's inertial wrench (Paksoy, Dede and Kiper 2025, Eq. 3-5, with the moment part)
//! through the virtual-joint deflection (Hähn and Weigold 2020, Eq. 2-9) to the joints at
//! which the loaded arm reaches the desired pose, every servo tick.

use deflect_core::dalembert::serial::{self, Payload};
use deflect_core::mechanism::{PoseIkOptions, Task};
use deflect_core::motion::PoseState;
use deflect_core::vjm::Deflection;
use deflect_core::vjm::Vector6;
use nalgebra::{Matrix3, Vector3};

use crate::boundary::{array, destroy, guard, handle, handle_mut, load, slice, write};
use crate::pose_motion::{DeflectPoseState, pose_of, row_major};
use crate::robot::{DEFLECT_MAX_DOF, DeflectSerialRobot};
use crate::status::{
    DEFLECT_ERR_INVALID_ARGUMENT, DEFLECT_ERR_NON_FINITE, DEFLECT_ERR_NULL,
    DEFLECT_ERR_WRONG_LENGTH, DeflectStatus, build_failure, tick_status,
};

/// Invert the paper's exact virtual-joint deflection (Eq. 2-9).
pub const DEFLECT_SERIAL_EXACT: i32 = 0;
/// Invert the linearized deflection `C(q) w`.
pub const DEFLECT_SERIAL_LINEARIZED: i32 = 1;

/// IK task: the full pose (6 rows; at least 6 joints). The default with 6 or more joints.
pub const DEFLECT_TASK_POSE: i32 = 0;
/// IK task: position and tool axis (5 rows; the spin about the TCP's z is free). The default
/// with 5 joints.
pub const DEFLECT_TASK_POSITION_AND_AXIS: i32 = 1;
/// IK task: position and the spin about the tool axis (4 rows; a SCARA).
pub const DEFLECT_TASK_POSITION_AND_SPIN: i32 = 2;
/// IK task: position only (3 rows). The default with 3 or 4 joints.
pub const DEFLECT_TASK_POSITION: i32 = 3;

/// Payload and tool beyond the TCP.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectPayload {
    /// Mass \[kg\], finite and >= 0.
    pub mass: f64,
    /// Centre of mass in the TCP frame \[m\].
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass, TCP frame, row-major 3 x 3 \[kg m^2\]:
    /// symmetric, positive semi-definite (all zeros for a point mass).
    pub inertia: [f64; 9],
}

/// One corrected tick of a serial arm.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectSerialTick {
    /// Commanded rigid TCP pose, row-major 4 x 4: where the joints put the unloaded TCP.
    pub commanded: [f64; 16],
    /// Joint command \[rad or m\]; entries past the robot's dof are 0.
    pub joints: [f64; DEFLECT_MAX_DOF],
    /// Wrench cancelled, D'Alembert plus process `[F; M]` \[N, N m\], base frame at the TCP.
    pub wrench: [f64; 6],
    /// Predicted TCP deflection at the command `[dp; dr]` \[m, rad\].
    pub deflection: [f64; 6],
    /// Pose IK iterations done (0 when the warm start already met the tolerance).
    pub iterations: u32,
    /// Position error left \[m\].
    pub position_error: f64,
    /// Orientation error left \[rad\].
    pub orientation_error: f64,
    /// Estimated smallest singular value of the task's joint Jacobian at the command.
    pub sigma_min: f64,
    /// Rotation left about the axes the task leaves free \[rad\] (0 for the full pose):
    /// what an arm with fewer joints cannot correct.
    pub free_rotation: f64,
}

/// The serial-arm D'Alembert corrector: the robot's chain and URDF joint limits, the payload,
/// the deflection model and the last ticks' joints (the warm start). Opaque; create with
/// `deflect_serial_dalembert_create`, free with `deflect_serial_dalembert_destroy`. Not
/// thread-safe: one thread at a time.
#[derive(Debug)]
pub struct DeflectSerialDalembert {
    model: serial::Model,
    data: serial::Data,
}

fn seed_of(q: &[f64], dof: usize) -> Result<&[f64], DeflectStatus> {
    if q.len() != dof {
        return Err(DEFLECT_ERR_WRONG_LENGTH);
    }
    if q.iter().any(|v| !v.is_finite()) {
        return Err(DEFLECT_ERR_NON_FINITE);
    }
    Ok(q)
}

/// Creates a corrector for `robot` (3..=`DEFLECT_MAX_DOF` joints; its chain and URDF joint
/// limits are copied in; the IK task the joints control: the pose with 6 or more, position
/// and tool axis with 5, position with 3 or 4, see `deflect_serial_dalembert_set_task`)
/// carrying `payload`, inverting `model` (`DEFLECT_SERIAL_EXACT` or
/// `DEFLECT_SERIAL_LINEARIZED`), warm-started from `seed[seed_len]` (the joints the motion
/// starts from; `seed_len` must be the dof). Pose IK: 20 iterations, 1e-8 m and 1e-8 rad.
/// Init time: allocates the handle. On failure `*out` is NULL.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_WRONG_LENGTH` (seed length, or fewer than 3
/// joints), `DEFLECT_ERR_NON_FINITE`, `DEFLECT_ERR_INVALID_ARGUMENT` (negative mass,
/// asymmetric inertia, unknown model) or `DEFLECT_ERR_SINGULAR` (inertia not positive
/// semi-definite).
///
/// # Safety
/// `robot` is NULL or a live handle; `payload` NULL or readable; `seed` holds `seed_len`
/// doubles; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_dalembert_create(
    robot: *const DeflectSerialRobot,
    payload: *const DeflectPayload,
    model: i32,
    seed: *const f64,
    seed_len: usize,
    out: *mut *mut DeflectSerialDalembert,
) -> DeflectStatus {
    let make = || {
        let err = |s: DeflectStatus| (s, String::new());
        // SAFETY: NULL or live/readable by contract.
        let (r, p, q) = unsafe { (handle(robot), handle(payload), slice(seed, seed_len)) };
        let (r, p, q) = (r.map_err(err)?, p.map_err(err)?, q.map_err(err)?);
        let deflection = match model {
            DEFLECT_SERIAL_EXACT => Deflection::Exact,
            DEFLECT_SERIAL_LINEARIZED => Deflection::Linearized,
            _ => return Err(err(DEFLECT_ERR_INVALID_ARGUMENT)),
        };
        let payload = Payload {
            mass: p.mass,
            com: Vector3::from(p.com),
            inertia: Matrix3::from_row_slice(&p.inertia),
        };
        let chain = r.robot.model.clone();
        let q = seed_of(q, chain.dof()).map_err(err)?;
        let model = serial::Model::new(chain, payload)
            .and_then(|m| m.with_joint_limits(&r.robot.joint_limits))
            .map(|m| m.with_deflection(deflection))
            .map_err(build_failure)?;
        let mut data = serial::Data::new(&model);
        data.set_seed(q);
        Ok(DeflectSerialDalembert { model, data })
    };
    // SAFETY: forwarded caller contract for `out`.
    unsafe { load(out, std::ptr::null_mut(), 0, make) }
}

/// Frees a corrector. NULL is a no-op.
///
/// # Safety
/// `corrector` is NULL or a live handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_dalembert_destroy(corrector: *mut DeflectSerialDalembert) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(corrector) };
        Ok(())
    });
}

/// Sets which loads the corrector cancels besides the payload's inertial wrench: with
/// `link_inertia` nonzero, the links' own inertial loads (every URDF `<inertial>`, from the
/// joint rates of the motion; off by default, as in the paper), and `gravity[3]` \[m/s^2\],
/// base frame (NULL: zero, the default), whose weights then load the springs too. Init time
/// (rebuilds the model; allocates); the warm start is kept. Returns `DEFLECT_ERR_NULL` or
/// `DEFLECT_ERR_NON_FINITE` (gravity).
///
/// # Safety
/// `corrector` is NULL or a live handle not used by another thread; `gravity` is NULL or
/// holds 3 doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_dalembert_set_loads(
    corrector: *mut DeflectSerialDalembert,
    link_inertia: i32,
    gravity: *const f64,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: NULL or a live handle by contract.
        let c = unsafe { handle_mut(corrector)? };
        let g = if gravity.is_null() {
            Vector3::zeros()
        } else {
            // SAFETY: `gravity` holds 3 doubles by contract.
            Vector3::from_column_slice(unsafe { slice(gravity, 3)? })
        };
        if g.iter().any(|v| !v.is_finite()) {
            return Err(DEFLECT_ERR_NON_FINITE);
        }
        let model = c
            .model
            .clone()
            .with_link_inertia(link_inertia != 0)
            .with_gravity(g)
            .map_err(|_| DEFLECT_ERR_NON_FINITE)?;
        c.model = model;
        Ok(())
    })
}

/// Sets the IK task (`DEFLECT_TASK_*`): what the corrector makes the loaded TCP reach, the
/// rest reported in the tick's `free_rotation`. Init time (rebuilds the model); the warm
/// start is kept. Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_INVALID_ARGUMENT` (unknown task)
/// or `DEFLECT_ERR_WRONG_LENGTH` (more task rows than the robot has joints).
///
/// # Safety
/// `corrector` is NULL or a live handle not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_dalembert_set_task(
    corrector: *mut DeflectSerialDalembert,
    task: i32,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: NULL or a live handle by contract.
        let c = unsafe { handle_mut(corrector)? };
        let task = match task {
            DEFLECT_TASK_POSE => Task::POSE,
            DEFLECT_TASK_POSITION_AND_AXIS => Task::POSITION_AND_AXIS,
            DEFLECT_TASK_POSITION_AND_SPIN => Task::POSITION_AND_SPIN,
            DEFLECT_TASK_POSITION => Task::POSITION,
            _ => return Err(DEFLECT_ERR_INVALID_ARGUMENT),
        };
        let ik = PoseIkOptions {
            task,
            ..*c.model.ik_options()
        };
        c.model = c
            .model
            .clone()
            .with_ik_options(ik)
            .map_err(|_| DEFLECT_ERR_WRONG_LENGTH)?;
        Ok(())
    })
}

/// Restarts the warm start from joints `q[q_len]` (`q_len` = dof): call it before a motion
/// that does not continue the last one. Returns `DEFLECT_ERR_NULL`,
/// `DEFLECT_ERR_WRONG_LENGTH` or `DEFLECT_ERR_NON_FINITE`.
///
/// # Safety
/// `corrector` is NULL or a live handle not used by another thread; `q` holds `q_len`
/// doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_dalembert_reset(
    corrector: *mut DeflectSerialDalembert,
    q: *const f64,
    q_len: usize,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (c, q) = unsafe { (handle_mut(corrector)?, slice(q, q_len)?) };
        let q = seed_of(q, c.model.chain().dof())?;
        c.data.set_seed(q);
        Ok(())
    })
}

/// One tick: the desired pose state `*desired` (from `deflect_pose_motion_sample`, or the
/// caller's own; base frame) and an optional process wrench `process[6]` \[N, N m\] at the TCP
/// (NULL: none). Writes the joint command and its diagnostics to `*out`. Per tick: no
/// allocation, bounded iterations.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE`, `DEFLECT_ERR_INVALID_ARGUMENT` (a
/// pose that is not a rigid transform, or a load outside the small-deflection model),
/// `DEFLECT_ERR_NOT_CONVERGED`, `DEFLECT_ERR_SINGULAR`, `DEFLECT_ERR_JOINT_LIMIT` or
/// `DEFLECT_ERR_NON_FINITE_OUTPUT`.
///
/// # Safety
/// `corrector` is NULL or a live handle not used by another thread; `desired` is NULL or
/// readable; `process` is NULL or holds 6 doubles; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_serial_dalembert_step(
    corrector: *mut DeflectSerialDalembert,
    desired: *const DeflectPoseState,
    process: *const f64,
    out: *mut DeflectSerialTick,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid (or NULL) by contract.
        let (c, d) = unsafe { (handle_mut(corrector)?, handle(desired)?) };
        let process = if process.is_null() {
            None
        } else {
            // SAFETY: non-null, 6 doubles by contract.
            Some(Vector6::from(unsafe { array::<6>(process) }?))
        };
        if out.is_null() {
            return Err(DEFLECT_ERR_NULL);
        }
        let state = PoseState {
            t: d.t,
            pose: pose_of(&d.pose)?,
            velocity: Vector3::from(d.velocity),
            acceleration: Vector3::from(d.acceleration),
            angular_velocity: Vector3::from(d.angular_velocity),
            angular_acceleration: Vector3::from(d.angular_acceleration),
        };
        let t = serial::step(&c.model, &mut c.data, &state, process.as_ref())
            .map_err(|e| tick_status(&e))?;
        let tick = DeflectSerialTick {
            commanded: row_major(&t.commanded),
            joints: t.joints,
            wrench: t.load.into(),
            deflection: t.displacement.into(),
            iterations: u32::try_from(t.iterations).unwrap_or(u32::MAX),
            position_error: t.diagnostics.position_error,
            orientation_error: t.diagnostics.orientation_error,
            sigma_min: t.diagnostics.sigma_min,
            free_rotation: t.diagnostics.free_rotation,
        };
        // SAFETY: non-null (checked), writable by contract.
        unsafe { write(out, tick) }
    })
}
