//! # deflect-ffi: the C API of deflect
//!
//! An `extern "C"` wrapper around deflect-core's real-time paths, so that C and C++ servo
//! controllers can link deflect as a static (`libdeflect.a`) or shared (`libdeflect.so`)
//! library. The header `include/deflect.h` is generated from this file by cbindgen; a test
//! checks that the committed header is up to date.
//!
//! Conventions of the API:
//!
//! * Every name starts with `deflect_` / `Deflect` / `DEFLECT_`.
//! * Objects are opaque handles with an explicit `*_create`/`*_load`/`*_from_*` and
//!   `*_destroy`. Creating one allocates (init time); every per-tick function (`deflection`,
//!   `compliance`, `joint_correction`, `displacement`, `sample`, `step`) allocates nothing
//!   and runs in bounded time.
//! * Every fallible function returns a [`DeflectStatus`]: [`DEFLECT_OK`] (0) or a negative
//!   `DEFLECT_ERR_*` code. Outputs are written only on success (a failing `*_create` sets
//!   its handle output to NULL).
//! * Loaders take a caller-provided buffer `err`/`err_len` that receives the error message,
//!   NUL-terminated and truncated to fit (`err` may be NULL). [`deflect_status_message`]
//!   names any status code.
//! * No Rust panic crosses the boundary: every entry point runs under
//!   `std::panic::catch_unwind` and returns [`DEFLECT_ERR_PANIC`] instead.
//! * Units are SI: m, N, N m, rad, s, kg.
//! * Threads: a handle is not synchronised. A serial robot owns its workspace, so use it from
//!   one thread at a time; maps, trajectories and correctors are read-only after creation
//!   (except `deflect_compliance_map_set_options`) and may be read from several threads. An
//!   online compensator owns its filter states and workspace: one thread at a time, together
//!   with the robot handle it is stepped with (which it only reads).
#![allow(unsafe_code)]
// reason: a C API has to dereference the caller's raw pointers and hand out boxed handles; each unsafe block states its invariant in a SAFETY comment.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![warn(missing_docs)]

use std::ffi::{CStr, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

use deflect_core::compensation::{
    CompensationError, CompensatorConfig, CorrectionOutput, MAX_AVERAGE_WINDOW, OnlineCompensator,
    SensorCalibration, sensor::POLY_TERMS,
};
use deflect_core::compliance_map::{
    ComplianceMap, ForceUnit, Interpolation, LengthUnit, OutOfGrid, QueryError, QueryOptions,
    QueryStatus,
};
use deflect_core::dalembert::{CorrectorError, DalembertCorrector, ModelStatus};
use deflect_core::mechanism::{MechanismError, ParallelRobot2};
use deflect_core::motion::{Limits, MotionError, State, Trajectory, paper_limits};
use deflect_core::vjm::{self, Data, Vector6};
use deflect_core::{SerialRobot, TickError};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector2, Vector3};

// ---------------------------------------------------------------------------------------------
// Status codes
// ---------------------------------------------------------------------------------------------

/// Result of every fallible deflect function: `DEFLECT_OK` (0) on success, a negative
/// `DEFLECT_ERR_*` code otherwise (in the style of ruckig's `Result`).
pub type DeflectStatus = i32;

/// Success.
pub const DEFLECT_OK: DeflectStatus = 0;
/// A required pointer argument (handle, input or output array, string) is NULL.
pub const DEFLECT_ERR_NULL: DeflectStatus = -1;
/// An input holds NaN or an infinity (joints, wrench, position, force, acceleration, time,
/// path point, tolerance).
pub const DEFLECT_ERR_NON_FINITE: DeflectStatus = -2;
/// An array length argument does not match (joints vs. the robot's dof, force and output
/// lengths vs. the map's axes, too few or too many path points).
pub const DEFLECT_ERR_WRONG_LENGTH: DeflectStatus = -3;
/// A file could not be read or parsed, or its content is invalid (robot URDF/TOML,
/// compliance map CSV/JSON). The loader's `err` buffer holds the message.
pub const DEFLECT_ERR_LOAD: DeflectStatus = -4;
/// A compliance-map query fell outside the map's grid and the map's policy is
/// `DEFLECT_OUT_OF_GRID_ERROR`.
pub const DEFLECT_ERR_OUT_OF_GRID: DeflectStatus = -5;
/// The mechanism cannot reach the commanded point.
pub const DEFLECT_ERR_OUT_OF_WORKSPACE: DeflectStatus = -6;
/// The pose is singular or too close to a singularity (no unique inverse kinematics or joint
/// correction).
pub const DEFLECT_ERR_SINGULAR: DeflectStatus = -7;
/// An iterative solve did not reach its tolerance within its iteration budget.
pub const DEFLECT_ERR_NOT_CONVERGED: DeflectStatus = -8;
/// A parameter is out of its range: a unit or option code, motion limits, g level, sampling
/// rate, mass, robot geometry, tolerance, or a string that is not UTF-8.
pub const DEFLECT_ERR_INVALID_ARGUMENT: DeflectStatus = -9;
/// The compliance map's force/displacement axes do not fit the call (the D'Alembert corrector
/// of the planar robot needs a 2-force, 2-displacement map).
pub const DEFLECT_ERR_MAP_DIMENSION: DeflectStatus = -10;
/// An error this version of the C API does not classify (a newer deflect-core error kind).
pub const DEFLECT_ERR_OTHER: DeflectStatus = -98;
/// A Rust panic was caught at the boundary (a bug in deflect: please report it). Outputs are
/// unspecified; the handles involved may be destroyed safely.
pub const DEFLECT_ERR_PANIC: DeflectStatus = -99;

// ---------------------------------------------------------------------------------------------
// Codes of options and statuses
// ---------------------------------------------------------------------------------------------

/// File force unit: newton.
pub const DEFLECT_FORCE_UNIT_NEWTON: i32 = 0;
/// File force unit: kilogram-force (9.80665 N).
pub const DEFLECT_FORCE_UNIT_KGF: i32 = 1;
/// File length unit: metre.
pub const DEFLECT_LENGTH_UNIT_METRE: i32 = 0;
/// File length unit: millimetre.
pub const DEFLECT_LENGTH_UNIT_MILLIMETRE: i32 = 1;
/// Map interpolation: bilinear between the 4 nodes of the cell (the paper's Eq. 14).
pub const DEFLECT_INTERPOLATION_BILINEAR: i32 = 0;
/// Map interpolation: tensor-product cubic Hermite (C1).
pub const DEFLECT_INTERPOLATION_BICUBIC: i32 = 1;
/// Outside the map's grid: refuse with `DEFLECT_ERR_OUT_OF_GRID` (the default).
pub const DEFLECT_OUT_OF_GRID_ERROR: i32 = 0;
/// Outside the map's grid: clamp the position to the grid boundary.
pub const DEFLECT_OUT_OF_GRID_CLAMP: i32 = 1;
/// Outside the map's grid: extrapolate linearly from the boundary.
pub const DEFLECT_OUT_OF_GRID_EXTRAPOLATE: i32 = 2;
/// Query/model status: the position was inside the grid.
pub const DEFLECT_QUERY_INSIDE: i32 = 0;
/// Query/model status: the position was outside and was clamped.
pub const DEFLECT_QUERY_CLAMPED: i32 = 1;
/// Query/model status: the position was outside and was extrapolated.
pub const DEFLECT_QUERY_EXTRAPOLATED: i32 = 2;
/// Most actuated joints of a serial robot (length of `DeflectJointCorrection.dq`).
pub const DEFLECT_MAX_DOF: usize = 8;
/// The paper's tuned D'Alembert mass parameter m* [kg].
pub const DEFLECT_PAPER_MASS: f64 = 5.0;
/// The paper's correction rate [Hz].
pub const DEFLECT_PAPER_RATE_HZ: f64 = 2000.0;

/// Largest moving-average window of the online compensator [cycles].
pub const DEFLECT_MAX_AVERAGE_WINDOW: usize = 64;
/// Number of terms of the sensor's residual-offset polynomial (Eq. 17).
pub const DEFLECT_RESIDUAL_TERMS: usize = 15;
/// Compensator output: Cartesian correction values only.
pub const DEFLECT_OUTPUT_CARTESIAN: i32 = 0;
/// Compensator output: also axis-specific values `dq` through the joint Jacobian.
pub const DEFLECT_OUTPUT_JOINT: i32 = 1;
/// The online-compensation paper's control cycle [s] (KUKA RSI, 4 ms).
pub const DEFLECT_PAPER_CYCLE: f64 = 0.004;

const _: () = assert!(DEFLECT_MAX_DOF == vjm::MAX_DOF);
const _: () = assert!(DEFLECT_MAX_AVERAGE_WINDOW == MAX_AVERAGE_WINDOW);
const _: () = assert!(DEFLECT_RESIDUAL_TERMS == POLY_TERMS);
const _: () = assert!(DEFLECT_PAPER_CYCLE == deflect_core::compensation::PAPER_CYCLE);
const _: () = assert!(DEFLECT_PAPER_MASS == DalembertCorrector::PAPER_MASS);
const _: () = assert!(DEFLECT_PAPER_RATE_HZ == deflect_core::motion::DEFAULT_RATE_HZ);

// ---------------------------------------------------------------------------------------------
// Plain data exchanged by value
// ---------------------------------------------------------------------------------------------

/// Path limits of a motion: speed [m/s], acceleration [m/s^2], jerk [m/s^3], each finite
/// and > 0.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectLimits {
    /// Largest speed [m/s].
    pub v_max: f64,
    /// Largest acceleration [m/s^2].
    pub a_max: f64,
    /// Largest jerk [m/s^3].
    pub j_max: f64,
}

/// The state of a planar trajectory at one time.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectState2 {
    /// Time since the start [s].
    pub t: f64,
    /// Index of the segment being travelled.
    pub segment: usize,
    /// Path length from the start of the polyline [m].
    pub path_s: f64,
    /// Path speed along the current segment [m/s].
    pub path_v: f64,
    /// Path acceleration along the current segment [m/s^2].
    pub path_a: f64,
    /// Path jerk along the current segment [m/s^3].
    pub path_j: f64,
    /// Position (x, y) [m].
    pub position: [f64; 2],
    /// Velocity [m/s].
    pub velocity: [f64; 2],
    /// Acceleration [m/s^2]: what the D'Alembert force -m* a needs.
    pub acceleration: [f64; 2],
    /// Jerk [m/s^3].
    pub jerk: [f64; 2],
}

/// Geometry of the paper's 2-DoF planar parallel robot (Paksoy et al., section 4.1).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeflectParallelRobot2 {
    /// Length of every arm link [m] (paper: 0.150).
    pub link: f64,
    /// Distance of the base pivots from the base centre [m] (paper: 0.090).
    pub half_width: f64,
    /// Singularity threshold: smallest allowed Jacobian singular value [m/rad] (0.020).
    pub min_sigma: f64,
}

/// One corrected tick of the D'Alembert corrector of the planar robot.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectCorrectedTick2 {
    /// Desired (planned) point [m].
    pub desired: [f64; 2],
    /// Commanded point [m]: desired minus the predicted displacement.
    pub commanded: [f64; 2],
    /// Joint command (theta_A, theta_B) [rad]: inverse kinematics of `commanded`.
    pub joints: [f64; 2],
    /// D'Alembert force -m* a [N].
    pub force: [f64; 2],
    /// Predicted displacement at the commanded point [m].
    pub displacement: [f64; 2],
    /// Fixed-point iterations done (0 = the paper's one-shot update).
    pub iterations: u32,
    /// |c_k - c_(k-1)| of the last fixed-point iteration [m] (0 without iterations).
    pub fixed_point_residual: f64,
    /// Worst map status met: `DEFLECT_QUERY_INSIDE`, `_CLAMPED` or `_EXTRAPOLATED`.
    pub model_status: i32,
}

/// Result of `deflect_serial_robot_joint_correction`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectJointCorrection {
    /// Correction to add to the nominal joints [rad or m]; entries past the robot's dof are 0.
    pub dq: [f64; DEFLECT_MAX_DOF],
    /// Gauss-Newton steps taken.
    pub iterations: u32,
    /// Remaining pose error |[dp; dr]| of the deflected TCP at q + dq [m, rad].
    pub residual: f64,
    /// Smallest singular value of the joint Jacobian at the last step (NaN if no step).
    pub sigma_min: f64,
    /// 1 if `residual <= tolerance`, else 0.
    pub converged: i32,
}

// ---------------------------------------------------------------------------------------------
// Opaque handles
// ---------------------------------------------------------------------------------------------

/// A serial robot (virtual-joint model) loaded from URDF + stiffness TOML, with its own
/// per-call workspace. Opaque; create with `deflect_serial_robot_load`, free with
/// `deflect_serial_robot_destroy`. Not thread-safe: one thread at a time.
#[derive(Debug)]
pub struct DeflectSerialRobot {
    robot: SerialRobot,
    data: Data,
}

/// A compliance map (per-node force-displacement lines over an (x, y) grid). Opaque; create
/// with `deflect_compliance_map_from_paper_csv`, `_load_paper_csv`, `_from_json` or
/// `_load_json`, free with `deflect_compliance_map_destroy`.
#[derive(Debug)]
pub struct DeflectComplianceMap {
    map: ComplianceMap,
}

/// A planned jerk-limited rest-to-rest motion along a planar line or polyline. Opaque; create
/// with `deflect_trajectory2_line` or `deflect_trajectory2_polyline`, free with
/// `deflect_trajectory2_destroy`.
#[derive(Debug)]
pub struct DeflectTrajectory2 {
    trajectory: Trajectory<2>,
}

/// The D'Alembert trajectory corrector of the planar parallel robot (Paksoy et al.,
/// section 3.3): settings and robot geometry. Opaque; create with `deflect_dalembert_create`,
/// free with `deflect_dalembert_destroy`.
#[derive(Debug)]
pub struct DeflectDalembert {
    corrector: DalembertCorrector,
    robot: ParallelRobot2,
}

// ---------------------------------------------------------------------------------------------
// Helpers (not exported)
// ---------------------------------------------------------------------------------------------

/// Runs `f`, turning a panic into `DEFLECT_ERR_PANIC`. The closures only touch the caller's
/// pointers and handles; after a panic the handle is still a valid (if partly updated) object,
/// so asserting unwind safety is sound.
#[inline(always)]
fn guard(f: impl FnOnce() -> Result<(), DeflectStatus>) -> DeflectStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => DEFLECT_OK,
        Ok(Err(status)) => status,
        Err(_) => DEFLECT_ERR_PANIC,
    }
}

/// `Some(&[T])` of `len` elements at `ptr`, or `Err(DEFLECT_ERR_NULL)` for NULL.
///
/// # Safety
/// A non-null `ptr` must point to `len` initialised, readable `T` valid for `'a`.
#[inline(always)]
unsafe fn slice<'a, T>(ptr: *const T, len: usize) -> Result<&'a [T], DeflectStatus> {
    if ptr.is_null() {
        return Err(DEFLECT_ERR_NULL);
    }
    // SAFETY: non-null, and the caller guarantees `len` readable elements.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// Reads `N` doubles at `ptr`.
///
/// # Safety
/// A non-null `ptr` must point to `N` readable doubles.
#[inline(always)]
unsafe fn array<const N: usize>(ptr: *const f64) -> Result<[f64; N], DeflectStatus> {
    if ptr.is_null() {
        return Err(DEFLECT_ERR_NULL);
    }
    let mut out = [0.0; N];
    // SAFETY: non-null, the caller guarantees `N` readable doubles; `out` is a distinct local.
    unsafe { std::ptr::copy_nonoverlapping(ptr, out.as_mut_ptr(), N) };
    Ok(out)
}

/// A mutable slice of `len` elements at `ptr`, or `Err(DEFLECT_ERR_NULL)` for NULL.
///
/// # Safety
/// A non-null `ptr` must point to `len` writable `T` not aliased during `'a`.
#[inline(always)]
unsafe fn slice_mut<'a, T>(ptr: *mut T, len: usize) -> Result<&'a mut [T], DeflectStatus> {
    if ptr.is_null() {
        return Err(DEFLECT_ERR_NULL);
    }
    // SAFETY: non-null, and the caller guarantees `len` writable, unaliased elements.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len) })
}

/// A shared reference to the handle at `ptr`, or `Err(DEFLECT_ERR_NULL)`.
///
/// # Safety
/// A non-null `ptr` must come from this library's constructor and not be destroyed.
#[inline(always)]
unsafe fn handle<'a, T>(ptr: *const T) -> Result<&'a T, DeflectStatus> {
    // SAFETY: the caller guarantees a live handle (or NULL, handled by `as_ref`).
    unsafe { ptr.as_ref() }.ok_or(DEFLECT_ERR_NULL)
}

/// A mutable reference to the handle at `ptr`, or `Err(DEFLECT_ERR_NULL)`.
///
/// # Safety
/// A non-null `ptr` must come from this library's constructor, not be destroyed and not be in
/// use by another thread.
#[inline(always)]
unsafe fn handle_mut<'a, T>(ptr: *mut T) -> Result<&'a mut T, DeflectStatus> {
    // SAFETY: the caller guarantees a live, unshared handle (or NULL, handled by `as_mut`).
    unsafe { ptr.as_mut() }.ok_or(DEFLECT_ERR_NULL)
}

/// Writes `value` to `out`, or fails with `DEFLECT_ERR_NULL`.
///
/// # Safety
/// A non-null `out` must be valid for a write of `T`.
#[inline(always)]
unsafe fn write<T>(out: *mut T, value: T) -> Result<(), DeflectStatus> {
    if out.is_null() {
        return Err(DEFLECT_ERR_NULL);
    }
    // SAFETY: non-null and, by the caller's contract, writable; `write` drops nothing old.
    unsafe { out.write(value) };
    Ok(())
}

/// Copies `msg` into the caller's buffer, truncated at a character boundary so that it fits
/// with its terminating NUL. Does nothing for a NULL buffer or a zero length.
///
/// # Safety
/// A non-null `buf` must be writable for `len` bytes.
unsafe fn write_message(buf: *mut c_char, len: usize, msg: &str) {
    if buf.is_null() || len == 0 {
        return;
    }
    let mut n = msg.len().min(len - 1);
    while !msg.is_char_boundary(n) {
        n -= 1;
    }
    // SAFETY: `buf` holds `len` writable bytes and `n + 1 <= len`; `msg` is a distinct Rust
    // string, so the regions do not overlap.
    unsafe {
        std::ptr::copy_nonoverlapping(msg.as_ptr(), buf.cast::<u8>(), n);
        buf.add(n).write(0);
    }
}

/// Reads a NUL-terminated UTF-8 string.
///
/// # Safety
/// A non-null `ptr` must point to a NUL-terminated string valid for `'a`.
unsafe fn c_str<'a>(ptr: *const c_char, what: &str) -> Result<&'a str, (DeflectStatus, String)> {
    if ptr.is_null() {
        return Err((DEFLECT_ERR_NULL, format!("{what} is NULL")));
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    let s = unsafe { CStr::from_ptr(ptr) };
    s.to_str().map_err(|e| {
        (
            DEFLECT_ERR_INVALID_ARGUMENT,
            format!("{what} is not UTF-8: {e}"),
        )
    })
}

/// Boxes `value` into `*out`.
///
/// # Safety
/// `out` must be non-null (checked by the caller) and writable.
unsafe fn publish<T>(out: *mut *mut T, value: T) {
    // SAFETY: checked non-null by every caller before any work; writable by contract.
    unsafe { out.write(Box::into_raw(Box::new(value))) };
}

/// Frees a handle made by `publish`.
///
/// # Safety
/// `ptr` is NULL or a live handle from `publish`, not used afterwards.
unsafe fn destroy<T>(ptr: *mut T) {
    if !ptr.is_null() {
        // SAFETY: `ptr` came from `Box::into_raw` in `publish` and is freed once.
        drop(unsafe { Box::from_raw(ptr) });
    }
}

/// A loader's common frame: NULL checks, `*out = NULL` first, the message on error.
///
/// # Safety
/// `out` is NULL or writable; `err` is NULL or writable for `err_len` bytes.
unsafe fn load<T>(
    out: *mut *mut T,
    err: *mut c_char,
    err_len: usize,
    f: impl FnOnce() -> Result<T, (DeflectStatus, String)>,
) -> DeflectStatus {
    let mut message = None;
    let status = guard(|| {
        if out.is_null() {
            message = Some("the output handle pointer is NULL".to_owned());
            return Err(DEFLECT_ERR_NULL);
        }
        // SAFETY: `out` is non-null and writable by the caller's contract.
        unsafe { out.write(std::ptr::null_mut()) };
        match f() {
            Ok(value) => {
                // SAFETY: `out` checked non-null above.
                unsafe { publish(out, value) };
                Ok(())
            }
            Err((status, msg)) => {
                message = Some(msg);
                Err(status)
            }
        }
    });
    let msg = match (&message, status) {
        (Some(m), _) => m.as_str(),
        (None, DEFLECT_ERR_PANIC) => "internal error: a panic was caught (please report it)",
        (None, _) => "",
    };
    // SAFETY: `err` is NULL or writable for `err_len` bytes by the caller's contract.
    unsafe { write_message(err, err_len, msg) };
    status
}

fn tick_status(e: &TickError) -> DeflectStatus {
    match e {
        TickError::WrongLength { .. } => DEFLECT_ERR_WRONG_LENGTH,
        TickError::NonFinite { .. } => DEFLECT_ERR_NON_FINITE,
        TickError::Singular { .. } => DEFLECT_ERR_SINGULAR,
        TickError::NotConverged { .. } => DEFLECT_ERR_NOT_CONVERGED,
        _ => DEFLECT_ERR_OTHER,
    }
}

fn query_status(e: &QueryError) -> DeflectStatus {
    match e {
        QueryError::WrongLength { .. } => DEFLECT_ERR_WRONG_LENGTH,
        QueryError::NonFinite { .. } => DEFLECT_ERR_NON_FINITE,
        QueryError::OutOfGrid { .. } => DEFLECT_ERR_OUT_OF_GRID,
        _ => DEFLECT_ERR_OTHER,
    }
}

fn mechanism_status(e: &MechanismError) -> DeflectStatus {
    match e {
        MechanismError::NonFinite { .. } => DEFLECT_ERR_NON_FINITE,
        MechanismError::OutOfWorkspace { .. } => DEFLECT_ERR_OUT_OF_WORKSPACE,
        MechanismError::Singular { .. } => DEFLECT_ERR_SINGULAR,
        MechanismError::NotConverged { .. } => DEFLECT_ERR_NOT_CONVERGED,
        MechanismError::WrongDof { .. } => DEFLECT_ERR_WRONG_LENGTH,
        MechanismError::InvalidParameter { .. } => DEFLECT_ERR_INVALID_ARGUMENT,
        MechanismError::Tick { error } => tick_status(error),
        _ => DEFLECT_ERR_OTHER,
    }
}

fn motion_status(e: &MotionError) -> DeflectStatus {
    match e {
        MotionError::NonFinitePoint { .. } | MotionError::NonFiniteTime { .. } => {
            DEFLECT_ERR_NON_FINITE
        }
        MotionError::TooFewPoints { .. } | MotionError::CapacityExceeded { .. } => {
            DEFLECT_ERR_WRONG_LENGTH
        }
        MotionError::InvalidLimit { .. }
        | MotionError::InvalidLength { .. }
        | MotionError::InvalidRate { .. }
        | MotionError::UnknownGLevel { .. } => DEFLECT_ERR_INVALID_ARGUMENT,
        _ => DEFLECT_ERR_OTHER,
    }
}

fn corrector_status(e: &CorrectorError) -> DeflectStatus {
    match e {
        CorrectorError::NonFinite { .. } => DEFLECT_ERR_NON_FINITE,
        CorrectorError::Map(q) => query_status(q),
        CorrectorError::MapDimension { .. } => DEFLECT_ERR_MAP_DIMENSION,
        CorrectorError::Vjm(t) => tick_status(t),
        CorrectorError::Mechanism(m) => mechanism_status(m),
        CorrectorError::Motion(m) => motion_status(m),
        CorrectorError::InvalidMass { .. } => DEFLECT_ERR_INVALID_ARGUMENT,
        _ => DEFLECT_ERR_OTHER,
    }
}

fn query_status_code(s: QueryStatus) -> i32 {
    match s {
        QueryStatus::Inside => DEFLECT_QUERY_INSIDE,
        QueryStatus::Clamped => DEFLECT_QUERY_CLAMPED,
        QueryStatus::Extrapolated => DEFLECT_QUERY_EXTRAPOLATED,
    }
}

fn model_status_code(s: ModelStatus) -> i32 {
    match s {
        ModelStatus::Inside => DEFLECT_QUERY_INSIDE,
        ModelStatus::Clamped => DEFLECT_QUERY_CLAMPED,
        ModelStatus::Extrapolated => DEFLECT_QUERY_EXTRAPOLATED,
    }
}

fn units(force_unit: i32, length_unit: i32) -> Result<(ForceUnit, LengthUnit), (i32, String)> {
    let force = match force_unit {
        DEFLECT_FORCE_UNIT_NEWTON => ForceUnit::Newton,
        DEFLECT_FORCE_UNIT_KGF => ForceUnit::KilogramForce,
        other => {
            return Err((
                DEFLECT_ERR_INVALID_ARGUMENT,
                format!("unknown force unit code {other} (0 = N, 1 = kgf)"),
            ));
        }
    };
    let length = match length_unit {
        DEFLECT_LENGTH_UNIT_METRE => LengthUnit::Metre,
        DEFLECT_LENGTH_UNIT_MILLIMETRE => LengthUnit::Millimetre,
        other => {
            return Err((
                DEFLECT_ERR_INVALID_ARGUMENT,
                format!("unknown length unit code {other} (0 = m, 1 = mm)"),
            ));
        }
    };
    Ok((force, length))
}

fn read_file(path: &str) -> Result<String, (DeflectStatus, String)> {
    std::fs::read_to_string(path)
        .map_err(|e| (DEFLECT_ERR_LOAD, format!("cannot read {path}: {e}")))
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

fn limits(l: &DeflectLimits) -> Result<Limits, DeflectStatus> {
    Limits::new(l.v_max, l.a_max, l.j_max).map_err(|e| motion_status(&e))
}

// ---------------------------------------------------------------------------------------------
// General
// ---------------------------------------------------------------------------------------------

/// The library version, a static NUL-terminated string such as "0.1.0".
#[unsafe(no_mangle)]
pub extern "C" fn deflect_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// A static NUL-terminated English description of a status code ("ok", "null pointer", ...;
/// "unknown status" for a code this library does not define). Never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn deflect_status_message(status: DeflectStatus) -> *const c_char {
    let s: &'static str = match status {
        DEFLECT_OK => "ok\0",
        DEFLECT_ERR_NULL => "null pointer argument\0",
        DEFLECT_ERR_NON_FINITE => "input is NaN or infinite\0",
        DEFLECT_ERR_WRONG_LENGTH => "array length does not match\0",
        DEFLECT_ERR_LOAD => "file could not be loaded\0",
        DEFLECT_ERR_OUT_OF_GRID => "position outside the compliance map's grid\0",
        DEFLECT_ERR_OUT_OF_WORKSPACE => "point outside the robot's workspace\0",
        DEFLECT_ERR_SINGULAR => "singular or near-singular pose\0",
        DEFLECT_ERR_NOT_CONVERGED => "iterative solve did not converge\0",
        DEFLECT_ERR_INVALID_ARGUMENT => "invalid argument\0",
        DEFLECT_ERR_MAP_DIMENSION => "compliance map has the wrong number of axes\0",
        DEFLECT_ERR_OTHER => "unclassified error\0",
        DEFLECT_ERR_PANIC => "internal error (panic caught)\0",
        _ => "unknown status\0",
    };
    s.as_ptr().cast()
}

/// Always unwinds (panics) inside Rust and returns `DEFLECT_ERR_PANIC`: lets a C caller check
/// that panics are contained at the boundary. Prints nothing.
#[unsafe(no_mangle)]
pub extern "C" fn deflect_test_panic() -> DeflectStatus {
    guard(|| {
        std::panic::resume_unwind(Box::new("deflect_test_panic: deliberate panic"));
    })
}

// ---------------------------------------------------------------------------------------------
// Serial robot (virtual-joint model)
// ---------------------------------------------------------------------------------------------

/// Loads a serial robot from a URDF file and a stiffness TOML file (see deflect-core's
/// `robot` module for the format); the chain runs from the URDF's root link to `tip_link`.
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
        let robot = SerialRobot::from_files(urdf, stiffness, tip)
            .map_err(|e| (DEFLECT_ERR_LOAD, e.to_string()))?;
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

/// TCP deflection `out[6] = [dx, dy, dz, rx, ry, rz]` [m, rad] (base frame) at joints
/// `q[q_len]` [rad or m] under the TCP wrench `wrench[6] = [Fx, Fy, Fz, Mx, My, Mz]`
/// [N, N m] (base frame, moment about the TCP): the exact virtual-joint model (Hahn &
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
        let d = vjm::deflection(&r.robot.model, &mut r.data, q, &Vector6::from(w))
            .map_err(|e| tick_status(&e))?;
        out.copy_from_slice(d.as_slice());
        Ok(())
    })
}

/// The 6x6 Cartesian compliance of the linearized model at joints `q[q_len]`, written
/// row-major to `out[36]`: `out[6 * i + j] = C[i][j]` with rows and columns ordered
/// `[dx, dy, dz, rx, ry, rz]` x `[Fx, Fy, Fz, Mx, My, Mz]` [m/N, m/(N m), rad/N, rad/(N m)],
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
        if !tolerance.is_finite() {
            return Err(DEFLECT_ERR_NON_FINITE);
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

// ---------------------------------------------------------------------------------------------
// Compliance map
// ---------------------------------------------------------------------------------------------

/// Loads a compliance map from CSV text in the layout of the paper's coefficient tables
/// (Paksoy et al., Tables II/III: columns `x_mm, y_mm` (or `x_m, y_m`, or `x, y` in
/// `length_unit`) and `m, n, o, p, s, u, v, w`). `force_unit` is `DEFLECT_FORCE_UNIT_*` (the
/// unit the lines were fitted in), `length_unit` is `DEFLECT_LENGTH_UNIT_*` (unit of the
/// displacements). Converted to SI. Init time: allocates. On failure `*out` is NULL and `err`
/// receives the message.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_INVALID_ARGUMENT` (unit code, not UTF-8) or
/// `DEFLECT_ERR_LOAD`.
///
/// # Safety
/// `text` is NULL or NUL-terminated; `out` is NULL or writable; `err` is NULL or writable for
/// `err_len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_from_paper_csv(
    text: *const c_char,
    force_unit: i32,
    length_unit: i32,
    out: *mut *mut DeflectComplianceMap,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    let make = || {
        // SAFETY: NULL or NUL-terminated by contract.
        let text = unsafe { c_str(text, "text") }?;
        let (f, l) = units(force_unit, length_unit)?;
        let map = ComplianceMap::from_paper_csv(text, f, l)
            .map_err(|e| (DEFLECT_ERR_LOAD, e.to_string()))?;
        Ok(DeflectComplianceMap { map })
    };
    // SAFETY: forwarded caller contract.
    unsafe { load(out, err, err_len, make) }
}

/// `deflect_compliance_map_from_paper_csv` on the contents of the file at `path`.
///
/// # Safety
/// As `deflect_compliance_map_from_paper_csv`, with `path` for `text`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_load_paper_csv(
    path: *const c_char,
    force_unit: i32,
    length_unit: i32,
    out: *mut *mut DeflectComplianceMap,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    let make = || {
        // SAFETY: NULL or NUL-terminated by contract.
        let path = unsafe { c_str(path, "path") }?;
        let (f, l) = units(force_unit, length_unit)?;
        let text = read_file(path)?;
        let map = ComplianceMap::from_paper_csv(&text, f, l)
            .map_err(|e| (DEFLECT_ERR_LOAD, format!("{path}: {e}")))?;
        Ok(DeflectComplianceMap { map })
    };
    // SAFETY: forwarded caller contract.
    unsafe { load(out, err, err_len, make) }
}

/// Loads a compliance map from deflect's versioned JSON text (`format_version` 1, SI units,
/// any number of force and displacement axes, with its query options). Init time: allocates.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_INVALID_ARGUMENT` (not UTF-8) or
/// `DEFLECT_ERR_LOAD`.
///
/// # Safety
/// `text` is NULL or NUL-terminated; `out` is NULL or writable; `err` is NULL or writable for
/// `err_len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_from_json(
    text: *const c_char,
    out: *mut *mut DeflectComplianceMap,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    let make = || {
        // SAFETY: NULL or NUL-terminated by contract.
        let text = unsafe { c_str(text, "text") }?;
        let map = ComplianceMap::from_json(text).map_err(|e| (DEFLECT_ERR_LOAD, e.to_string()))?;
        Ok(DeflectComplianceMap { map })
    };
    // SAFETY: forwarded caller contract.
    unsafe { load(out, err, err_len, make) }
}

/// `deflect_compliance_map_from_json` on the contents of the file at `path`.
///
/// # Safety
/// As `deflect_compliance_map_from_json`, with `path` for `text`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_load_json(
    path: *const c_char,
    out: *mut *mut DeflectComplianceMap,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    let make = || {
        // SAFETY: NULL or NUL-terminated by contract.
        let path = unsafe { c_str(path, "path") }?;
        let text = read_file(path)?;
        let map = ComplianceMap::from_json(&text)
            .map_err(|e| (DEFLECT_ERR_LOAD, format!("{path}: {e}")))?;
        Ok(DeflectComplianceMap { map })
    };
    // SAFETY: forwarded caller contract.
    unsafe { load(out, err, err_len, make) }
}

/// Frees a map handle. NULL is a no-op.
///
/// # Safety
/// `map` is NULL or a live handle, not used afterwards (and by no corrector call in flight).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_destroy(map: *mut DeflectComplianceMap) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(map) };
        Ok(())
    });
}

/// Sets the map's query options: `interpolation` is `DEFLECT_INTERPOLATION_*`, `out_of_grid`
/// is `DEFLECT_OUT_OF_GRID_*`. A map loaded from CSV starts bilinear with
/// `DEFLECT_OUT_OF_GRID_ERROR`. Returns `DEFLECT_ERR_NULL` or `DEFLECT_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `map` is NULL or a live handle not read by another thread meanwhile.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_set_options(
    map: *mut DeflectComplianceMap,
    interpolation: i32,
    out_of_grid: i32,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let m = unsafe { handle_mut(map) }?;
        let interpolation = match interpolation {
            DEFLECT_INTERPOLATION_BILINEAR => Interpolation::Bilinear,
            DEFLECT_INTERPOLATION_BICUBIC => Interpolation::Bicubic,
            _ => return Err(DEFLECT_ERR_INVALID_ARGUMENT),
        };
        let out_of_grid = match out_of_grid {
            DEFLECT_OUT_OF_GRID_ERROR => OutOfGrid::Error,
            DEFLECT_OUT_OF_GRID_CLAMP => OutOfGrid::Clamp,
            DEFLECT_OUT_OF_GRID_EXTRAPOLATE => OutOfGrid::Extrapolate,
            _ => return Err(DEFLECT_ERR_INVALID_ARGUMENT),
        };
        m.map.set_options(QueryOptions {
            interpolation,
            out_of_grid,
        });
        Ok(())
    })
}

/// Writes the map's number of force axes to `*n_force` and of displacement axes to
/// `*n_displacement` (either may be NULL). The paper's tables give 2 and 2.
///
/// # Safety
/// `map` is NULL or a live handle; the outputs are NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_axes(
    map: *const DeflectComplianceMap,
    n_force: *mut usize,
    n_displacement: *mut usize,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let m = unsafe { handle(map) }?;
        if !n_force.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(n_force, m.map.n_force()) }?;
        }
        if !n_displacement.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(n_displacement, m.map.n_displacement()) }?;
        }
        Ok(())
    })
}

/// Displacement `out[out_len]` [m | rad] at `position[2] = (x, y)` [m] under
/// `force[force_len]` [N | N m], with the map's options (Eq. 9-10 at nodes, Eq. 14 between
/// them). `force_len` must equal the map's force axes and `out_len` its displacement axes.
/// `status` (may be NULL) receives `DEFLECT_QUERY_INSIDE`, `_CLAMPED` or `_EXTRAPOLATED`.
/// Per tick: no allocation.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_WRONG_LENGTH`, `DEFLECT_ERR_NON_FINITE` or
/// `DEFLECT_ERR_OUT_OF_GRID`.
///
/// # Safety
/// `map` is NULL or a live handle; `position` holds 2 doubles, `force` `force_len`, `out`
/// `out_len` writable doubles; `status` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_displacement(
    map: *const DeflectComplianceMap,
    position: *const f64,
    force: *const f64,
    force_len: usize,
    out: *mut f64,
    out_len: usize,
    status: *mut i32,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (m, p, f, o) = unsafe {
            (
                handle(map)?,
                array::<2>(position)?,
                slice(force, force_len)?,
                slice_mut(out, out_len)?,
            )
        };
        let s = m.map.displacement(p, f, o).map_err(|e| query_status(&e))?;
        if !status.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(status, query_status_code(s)) }?;
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------------
// Motion planning
// ---------------------------------------------------------------------------------------------

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
        let l = paper_limits(g_level).map_err(|e| motion_status(&e))?;
        let value = DeflectLimits {
            v_max: l.v_max,
            a_max: l.a_max,
            j_max: l.j_max,
        };
        // SAFETY: non-null (checked), writable by contract.
        unsafe { write(out, value) }
    })
}

/// Plans a time-optimal jerk-limited rest-to-rest motion from `start[2]` to `end[2]` [m].
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
        let lim = self::limits(l).map_err(err)?;
        let trajectory = Trajectory::line(Vector2::from(a), Vector2::from(b), &lim)
            .map_err(|e| err(motion_status(&e)))?;
        Ok(DeflectTrajectory2 { trajectory })
    };
    // SAFETY: forwarded caller contract for `out`.
    unsafe { load(out, std::ptr::null_mut(), 0, make) }
}

/// Plans rest-to-rest motions through `n_points` points (2..32) given as `points[2 *
/// n_points] = x0, y0, x1, y1, ...` [m], stopping at each. Returns `DEFLECT_ERR_NULL`,
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
        let lim = self::limits(l).map_err(err)?;
        let pts: Vec<Vector2<f64>> = p.chunks_exact(2).map(Vector2::from_column_slice).collect();
        let trajectory = Trajectory::polyline(&pts, &lim).map_err(|e| err(motion_status(&e)))?;
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

/// Writes the motion's total duration [s] to `*duration`.
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

/// Number of servo ticks at `rate_hz` [Hz]: tick `k` (0 <= k < count) is at time
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
            .map_err(|e| motion_status(&e))?
            .remaining();
        // SAFETY: NULL or writable by contract.
        unsafe { write(count, n) }
    })
}

/// Time [s] of tick `k` at `rate_hz`, exactly as deflect's own tick cursor computes it:
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
            .map_err(|e| motion_status(&e))?
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

/// The exact state at time `t` [s] (the start at rest before 0, the end at rest from the
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
        let s = tr.trajectory.sample(t).map_err(|e| motion_status(&e))?;
        // SAFETY: non-null (checked), writable by contract.
        unsafe { write(out, state2(&s)) }
    })
}

// ---------------------------------------------------------------------------------------------
// D'Alembert corrector of the planar parallel robot
// ---------------------------------------------------------------------------------------------

/// Writes the geometry of the paper's robot (L = 0.150 m, pivots 0.090 m from the centre,
/// singularity threshold 0.020 m/rad) to `*out`.
///
/// # Safety
/// `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_parallel_robot2_paper(
    out: *mut DeflectParallelRobot2,
) -> DeflectStatus {
    guard(|| {
        let r = ParallelRobot2::paper();
        let value = DeflectParallelRobot2 {
            link: r.link(),
            half_width: r.half_width(),
            min_sigma: r.min_sigma(),
        };
        // SAFETY: NULL or writable by contract.
        unsafe { write(out, value) }
    })
}

/// Creates a D'Alembert corrector (Paksoy et al., section 3.3) for the planar parallel robot
/// `robot` (NULL = the paper's robot) with mass parameter `mass` m* [kg] (finite, >= 0; the
/// paper's is `DEFLECT_PAPER_MASS`). With `fixed_point_iterations = 0` each step is the
/// paper's one-shot update; otherwise the command is iterated `c = x_d - d(c, F)` at most that
/// often, stopping once successive commands differ by at most `tolerance` [m] (finite, >= 0).
/// Init time: allocates the handle. On failure `*out` is NULL.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE` or `DEFLECT_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `robot` is NULL or readable; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_dalembert_create(
    robot: *const DeflectParallelRobot2,
    mass: f64,
    fixed_point_iterations: u32,
    tolerance: f64,
    out: *mut *mut DeflectDalembert,
) -> DeflectStatus {
    let make = || {
        let err = |s: DeflectStatus| (s, String::new());
        // SAFETY: NULL or readable by contract.
        let robot = match unsafe { robot.as_ref() } {
            None => ParallelRobot2::paper(),
            Some(r) => ParallelRobot2::new(r.link, r.half_width, r.min_sigma)
                .map_err(|e| err(mechanism_status(&e)))?,
        };
        if !mass.is_finite() || !tolerance.is_finite() {
            return Err(err(DEFLECT_ERR_NON_FINITE));
        }
        if tolerance < 0.0 {
            return Err(err(DEFLECT_ERR_INVALID_ARGUMENT));
        }
        let corrector = DalembertCorrector::new(mass)
            .map_err(|e| err(corrector_status(&e)))?
            .with_fixed_point(fixed_point_iterations as usize, tolerance);
        Ok(DeflectDalembert { corrector, robot })
    };
    // SAFETY: forwarded caller contract for `out`.
    unsafe { load(out, std::ptr::null_mut(), 0, make) }
}

/// Frees a corrector handle. NULL is a no-op.
///
/// # Safety
/// `corrector` is NULL or a live handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_dalembert_destroy(corrector: *mut DeflectDalembert) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(corrector) };
        Ok(())
    });
}

/// One corrector tick: desired point `desired[2]` [m] with planned acceleration
/// `acceleration[2]` [m/s^2] (from `deflect_trajectory2_sample`), `seed[2]` the previous
/// tick's joints (ignored by the closed-form IK). The D'Alembert force `-m* a` (Eq. 5), the
/// map's displacement at the desired (or fixed-point) point, the command `desired -
/// displacement` and its inverse kinematics go to `*out`. The map must have 2 force and 2
/// displacement axes; its options decide what happens outside its grid. Per tick: no
/// allocation, bounded time.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE`, `DEFLECT_ERR_MAP_DIMENSION`,
/// `DEFLECT_ERR_OUT_OF_GRID`, `DEFLECT_ERR_OUT_OF_WORKSPACE` or `DEFLECT_ERR_SINGULAR`.
///
/// # Safety
/// `corrector` and `map` are NULL or live handles (the map not modified meanwhile);
/// `desired`, `acceleration`, `seed` hold 2 doubles; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_dalembert_step(
    corrector: *const DeflectDalembert,
    map: *const DeflectComplianceMap,
    desired: *const f64,
    acceleration: *const f64,
    seed: *const f64,
    out: *mut DeflectCorrectedTick2,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (c, m, x, a, q) = unsafe {
            (
                handle(corrector)?,
                handle(map)?,
                array::<2>(desired)?,
                array::<2>(acceleration)?,
                array::<2>(seed)?,
            )
        };
        if out.is_null() {
            return Err(DEFLECT_ERR_NULL);
        }
        let t = c
            .corrector
            .step(
                &c.robot,
                &m.map.view(),
                &Vector2::from(x),
                &Vector2::from(a),
                &Vector2::from(q),
            )
            .map_err(|e| corrector_status(&e))?;
        let v = |v: Vector2<f64>| [v.x, v.y];
        let tick = DeflectCorrectedTick2 {
            desired: v(t.desired),
            commanded: v(t.commanded),
            joints: v(t.joints),
            force: v(t.force),
            displacement: v(t.displacement),
            iterations: u32::try_from(t.iterations).unwrap_or(u32::MAX),
            fixed_point_residual: t.fixed_point_residual,
            model_status: model_status_code(t.model_status),
        };
        // SAFETY: non-null (checked), writable by contract.
        unsafe { write(out, tick) }
    })
}

// ---------------------------------------------------------------------------------------------
// Online force compensation (Hähn & Weigold, sections 2.2-2.6)
// ---------------------------------------------------------------------------------------------

/// Sensor calibration and the fixed sensor-to-TCP transform of the online compensation
/// (Eq. 12-20), plain data. `deflect_sensor_calibration_default` fills the neutral one (no
/// offsets, no weight, no residual, TCP at the sensor).
///
/// The transform `^S T_TCP` (pose of the TCP in the sensor frame) is given as a translation
/// `sensor_to_tcp_translation[3] = (x, y, z)` [m] and a rotation quaternion
/// `sensor_to_tcp_rotation[4] = (w, x, y, z)` (scalar first). The quaternion must be finite
/// and not zero; it is normalised on use (a quaternion of norm exactly 1 is used as is).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeflectSensorCalibration {
    /// Internal force offset `F_SI` [N], sensor frame.
    pub force_offset: [f64; 3],
    /// Internal moment offset `M_SI` [N m], sensor frame.
    pub moment_offset: [f64; 3],
    /// Weight of everything beyond the sensor, `G` [N] (>= 0; gravity is `-z` of the base).
    pub weight: f64,
    /// Centre of gravity `r_G` [m], sensor frame.
    pub center_of_gravity: [f64; 3],
    /// Residual-offset polynomial coefficients `a_1..a_15` (Eq. 17) per sensor-frame wrench
    /// component: `residual[i][k]`, `i` in `[Fx, Fy, Fz, Mx, My, Mz]`, `k` over the terms `1,
    /// q1..q4, q1^2..q4^2, q1 q2, q1 q3, q1 q4, q2 q3, q2 q4, q3 q4` of the sensor
    /// orientation's quaternion (w >= 0). Zeros disable it.
    pub residual: [[f64; DEFLECT_RESIDUAL_TERMS]; 6],
    /// Translation of `^S T_TCP`: the TCP's position in the sensor frame [m].
    pub sensor_to_tcp_translation: [f64; 3],
    /// Rotation of `^S T_TCP` as a quaternion `(w, x, y, z)`, scalar first.
    pub sensor_to_tcp_rotation: [f64; 4],
}

/// Settings of the online compensation chain (`deflect_compensator_config_paper` fills the
/// paper's). Flags are 0 or 1; any other value is `DEFLECT_ERR_INVALID_ARGUMENT`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeflectCompensatorConfig {
    /// Cycle time [s], > 0 (0.004 in the paper, 0.0005 at 2 kHz).
    pub dt: f64,
    /// Sensor offsets, weight, residual polynomial and sensor-to-TCP transform.
    pub calibration: DeflectSensorCalibration,
    /// Low-pass cut-off [Hz], > 0.
    pub lowpass_cutoff_hz: f64,
    /// Moving-average window [cycles], 1..=`DEFLECT_MAX_AVERAGE_WINDOW`.
    pub moving_average_window: usize,
    /// 1: pilot control (blend to the estimated wrench when it differs from the measured one
    /// by more than `pilot_threshold`); 0: measured forces only.
    pub pilot_enabled: u8,
    /// Pilot-control switching threshold [N], >= 0 (paper: 150).
    pub pilot_threshold: f64,
    /// Pilot-control blending time [s], >= 0 (paper: 0.080; 0 switches in one cycle).
    pub pilot_ramp: f64,
    /// 1: project the translational correction onto the plane normal to the feed (Eq. 10-11).
    pub project_on_feed: u8,
    /// Largest translational correction [m], >= 0; larger ones are scaled down and reported.
    pub max_correction: f64,
    /// Largest change of the translational correction per second [m/s], >= 0.
    pub max_rate: f64,
    /// `DEFLECT_OUTPUT_CARTESIAN` or `DEFLECT_OUTPUT_JOINT`.
    pub output: i32,
}

/// What one compensation cycle produced (`deflect_compensator_step`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectCycleOutput {
    /// The wrench fed to the model `[Fx, Fy, Fz, Mx, My, Mz]` [N, N m]: TCP, base frame,
    /// filtered (and piloted).
    pub wrench: [f64; 6],
    /// The wrench before pilot control (filtered measurement) [N, N m].
    pub measured_wrench: [f64; 6],
    /// Model deflection `[dx, dy, dz, rx, ry, rz]` [m, rad] under `wrench` (Eq. 9).
    pub deflection: [f64; 6],
    /// Correction to add to the commanded pose `[dx, dy, dz, rx, ry, rz]` [m, rad], base
    /// frame, after projection and limits.
    pub correction: [f64; 6],
    /// Axis-specific correction [rad or m]; zeros unless the output is `DEFLECT_OUTPUT_JOINT`,
    /// entries past the robot's dof are 0.
    pub dq: [f64; DEFLECT_MAX_DOF],
    /// Weight of the estimated wrench in the blend (0 = measured only .. 1 = estimated only).
    pub pilot_weight: f64,
    /// 1 if the feed direction was removed (0 when standing still or projection is off).
    pub projected: u8,
    /// 1 if the size limit acted this cycle.
    pub size_limited: u8,
    /// 1 if the rate limit acted this cycle.
    pub rate_limited: u8,
}

/// The online force-compensation chain of one serial robot with its filter, pilot and
/// rate-limiter states and its own workspace. Opaque; create with `deflect_compensator_create`,
/// free with `deflect_compensator_destroy`. Not thread-safe: one thread at a time.
#[derive(Debug)]
pub struct DeflectCompensator {
    compensator: OnlineCompensator,
    dof: usize,
    springs: usize,
}

fn flag(v: u8) -> Result<bool, DeflectStatus> {
    match v {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(DEFLECT_ERR_INVALID_ARGUMENT),
    }
}

fn all_finite<'a>(values: impl IntoIterator<Item = &'a f64>) -> Result<(), DeflectStatus> {
    if values.into_iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(DEFLECT_ERR_NON_FINITE)
    }
}

fn sensor_calibration(c: &DeflectSensorCalibration) -> Result<SensorCalibration, DeflectStatus> {
    all_finite(
        c.force_offset
            .iter()
            .chain(&c.moment_offset)
            .chain(std::iter::once(&c.weight))
            .chain(&c.center_of_gravity)
            .chain(c.residual.iter().flatten())
            .chain(&c.sensor_to_tcp_translation)
            .chain(&c.sensor_to_tcp_rotation),
    )?;
    if c.weight < 0.0 {
        return Err(DEFLECT_ERR_INVALID_ARGUMENT);
    }
    let [w, x, y, z] = c.sensor_to_tcp_rotation;
    let q = Quaternion::new(w, x, y, z);
    let norm = q.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(DEFLECT_ERR_INVALID_ARGUMENT);
    }
    // Same as a Rust caller's `UnitQuaternion::from_quaternion`: `q / |q|`.
    let rotation = UnitQuaternion::from_quaternion(q);
    Ok(SensorCalibration {
        force_offset: Vector3::from(c.force_offset),
        moment_offset: Vector3::from(c.moment_offset),
        weight: c.weight,
        center_of_gravity: Vector3::from(c.center_of_gravity),
        residual: c.residual,
        sensor_to_tcp: Isometry3::from_parts(
            Translation3::from(Vector3::from(c.sensor_to_tcp_translation)),
            rotation,
        ),
    })
}

fn calibration_c(c: &SensorCalibration) -> DeflectSensorCalibration {
    let v = |v: Vector3<f64>| [v.x, v.y, v.z];
    let r = c.sensor_to_tcp.rotation.quaternion();
    DeflectSensorCalibration {
        force_offset: v(c.force_offset),
        moment_offset: v(c.moment_offset),
        weight: c.weight,
        center_of_gravity: v(c.center_of_gravity),
        residual: c.residual,
        sensor_to_tcp_translation: v(c.sensor_to_tcp.translation.vector),
        sensor_to_tcp_rotation: [r.w, r.i, r.j, r.k],
    }
}

/// Converts a C configuration: non-finite values are `DEFLECT_ERR_NON_FINITE`, values out of
/// range `DEFLECT_ERR_INVALID_ARGUMENT`.
fn compensator_config(c: &DeflectCompensatorConfig) -> Result<CompensatorConfig, DeflectStatus> {
    all_finite(&[
        c.dt,
        c.lowpass_cutoff_hz,
        c.pilot_threshold,
        c.pilot_ramp,
        c.max_correction,
        c.max_rate,
    ])?;
    let calibration = sensor_calibration(&c.calibration)?;
    let pilot = flag(c.pilot_enabled)?.then_some((c.pilot_threshold, c.pilot_ramp));
    let output = match c.output {
        DEFLECT_OUTPUT_CARTESIAN => CorrectionOutput::Cartesian,
        DEFLECT_OUTPUT_JOINT => CorrectionOutput::Joint,
        _ => return Err(DEFLECT_ERR_INVALID_ARGUMENT),
    };
    Ok(CompensatorConfig {
        dt: c.dt,
        calibration,
        lowpass_cutoff_hz: c.lowpass_cutoff_hz,
        moving_average_window: c.moving_average_window,
        pilot,
        project_on_feed: flag(c.project_on_feed)?,
        max_correction: c.max_correction,
        max_rate: c.max_rate,
        output,
    })
}

fn compensation_status(e: &CompensationError) -> DeflectStatus {
    match e {
        CompensationError::InvalidParameter { .. } => DEFLECT_ERR_INVALID_ARGUMENT,
        _ => DEFLECT_ERR_OTHER,
    }
}

/// Writes the neutral calibration to `*out`: no offsets, no weight, no residual, TCP at the
/// sensor (translation 0, rotation (1, 0, 0, 0)).
///
/// # Safety
/// `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_sensor_calibration_default(
    out: *mut DeflectSensorCalibration,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: NULL or writable by contract.
        unsafe { write(out, calibration_c(&SensorCalibration::default())) }
    })
}

/// Writes the paper's chain at cycle time `dt` [s] to `*out`: the neutral calibration (set
/// `out->calibration` afterwards), 10 Hz low-pass, 5-cycle moving average, pilot control
/// 150 N / 80 ms, projection on, 3 mm and 50 mm/s limits, Cartesian output. `dt` is checked
/// by `deflect_compensator_create`, not here.
///
/// # Safety
/// `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compensator_config_paper(
    dt: f64,
    out: *mut DeflectCompensatorConfig,
) -> DeflectStatus {
    guard(|| {
        let c = CompensatorConfig::paper(dt, SensorCalibration::default());
        let (pilot_enabled, (pilot_threshold, pilot_ramp)) = match c.pilot {
            Some(p) => (1, p),
            None => (0, (0.0, 0.0)),
        };
        let value = DeflectCompensatorConfig {
            dt: c.dt,
            calibration: calibration_c(&c.calibration),
            lowpass_cutoff_hz: c.lowpass_cutoff_hz,
            moving_average_window: c.moving_average_window,
            pilot_enabled,
            pilot_threshold,
            pilot_ramp,
            project_on_feed: u8::from(c.project_on_feed),
            max_correction: c.max_correction,
            max_rate: c.max_rate,
            output: match c.output {
                CorrectionOutput::Joint => DEFLECT_OUTPUT_JOINT,
                CorrectionOutput::Cartesian => DEFLECT_OUTPUT_CARTESIAN,
            },
        };
        // SAFETY: NULL or writable by contract.
        unsafe { write(out, value) }
    })
}

/// Creates the online compensation chain for `robot` with settings `*config`. The handle keeps
/// its own filter states and workspace (it only reads the robot's model); every
/// `deflect_compensator_step` must be given this same robot. Init time: allocates. On failure
/// `*out` is NULL.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE` (a non-finite setting or calibration
/// value) or `DEFLECT_ERR_INVALID_ARGUMENT` (dt or cut-off not > 0, window outside
/// 1..=`DEFLECT_MAX_AVERAGE_WINDOW`, negative threshold, ramp, limit or weight, a zero
/// quaternion, a flag other than 0/1, an unknown output code).
///
/// # Safety
/// `robot` is NULL or a live handle; `config` is NULL or readable; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compensator_create(
    robot: *const DeflectSerialRobot,
    config: *const DeflectCompensatorConfig,
    out: *mut *mut DeflectCompensator,
) -> DeflectStatus {
    let make = || {
        let err = |s: DeflectStatus| (s, String::new());
        // SAFETY: NULL or live/readable by contract.
        let (r, c) = unsafe { (handle(robot), handle(config)) };
        let (r, c) = (r.map_err(err)?, c.map_err(err)?);
        let config = compensator_config(c).map_err(err)?;
        let model = &r.robot.model;
        let compensator =
            OnlineCompensator::new(model, config).map_err(|e| err(compensation_status(&e)))?;
        Ok(DeflectCompensator {
            compensator,
            dof: model.dof(),
            springs: model.spring_count(),
        })
    };
    // SAFETY: forwarded caller contract for `out`.
    unsafe { load(out, std::ptr::null_mut(), 0, make) }
}

/// Frees a compensator handle. NULL is a no-op.
///
/// # Safety
/// `compensator` is NULL or a live handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compensator_destroy(compensator: *mut DeflectCompensator) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(compensator) };
        Ok(())
    });
}

/// Low-frequency delay of the filter chain (low-pass plus moving average): `*samples` in
/// cycles and `*seconds` in s (either output may be NULL).
///
/// # Safety
/// `compensator` is NULL or a live handle; the outputs are NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compensator_delay(
    compensator: *const DeflectCompensator,
    samples: *mut f64,
    seconds: *mut f64,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let c = unsafe { handle(compensator) }?;
        if !samples.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(samples, c.compensator.delay_samples()) }?;
        }
        if !seconds.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(seconds, c.compensator.delay_seconds()) }?;
        }
        Ok(())
    })
}

/// Clears the filter, pilot-control and rate-limiter states (as after create). No allocation.
///
/// # Safety
/// `compensator` is NULL or a live handle not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compensator_reset(
    compensator: *mut DeflectCompensator,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        unsafe { handle_mut(compensator) }?.compensator.reset();
        Ok(())
    })
}

/// One control cycle of the online compensation: joints `q[q_len]` [rad or m], the raw sensor
/// reading `reading[6] = [Fx, Fy, Fz, Mx, My, Mz]` [N, N m] (sensor frame), the offline
/// estimate `estimated[6]` of the TCP wrench (base frame; NULL if the program provides none,
/// which also skips pilot control) and the feed velocity `feed_velocity[3]` [m/s] (base
/// frame). The sensor reading is compensated (Eq. 18) and carried to the TCP (Eq. 19-20),
/// low-pass filtered and averaged, piloted, turned into a deflection (Eq. 9), and the opposite
/// correction projected (Eq. 10-11), limited and written to `*out`. Per cycle: no allocation,
/// bounded time.
///
/// Returns `DEFLECT_ERR_NULL` (handles, `q`, `reading`, `feed_velocity` or `out`; nothing is
/// changed then), `DEFLECT_ERR_NON_FINITE`, `DEFLECT_ERR_WRONG_LENGTH` (`q_len` is not the
/// robot's dof), `DEFLECT_ERR_INVALID_ARGUMENT` (`robot` has another dof or spring count than
/// the robot the compensator was created for) or `DEFLECT_ERR_SINGULAR` (joint output
/// at a singular pose). Invalid inputs are refused before any state changes, except a
/// singular pose with joint output, which is met after the filter states have advanced.
///
/// # Safety
/// `compensator` is NULL or a live handle not used by another thread; `robot` is NULL or a
/// live handle (only read, not used by another thread meanwhile); `q` holds `q_len`
/// doubles, `reading` 6, `estimated` 6 (or is NULL), `feed_velocity` 3; `out` is NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compensator_step(
    compensator: *mut DeflectCompensator,
    robot: *const DeflectSerialRobot,
    q: *const f64,
    q_len: usize,
    reading: *const f64,
    estimated: *const f64,
    feed_velocity: *const f64,
    out: *mut DeflectCycleOutput,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (c, r, q, reading, feed) = unsafe {
            (
                handle_mut(compensator)?,
                handle(robot)?,
                slice(q, q_len)?,
                array::<6>(reading)?,
                array::<3>(feed_velocity)?,
            )
        };
        let estimated = if estimated.is_null() {
            None
        } else {
            // SAFETY: non-null, 6 readable doubles by contract.
            Some(Vector6::from(unsafe { array::<6>(estimated) }?))
        };
        if out.is_null() {
            return Err(DEFLECT_ERR_NULL);
        }
        let model = &r.robot.model;
        if model.dof() != c.dof || model.spring_count() != c.springs {
            return Err(DEFLECT_ERR_INVALID_ARGUMENT);
        }
        let o = c
            .compensator
            .step(
                model,
                q,
                &Vector6::from(reading),
                estimated.as_ref(),
                &Vector3::from(feed),
            )
            .map_err(|e| tick_status(&e))?;
        let value = DeflectCycleOutput {
            wrench: o.wrench.into(),
            measured_wrench: o.measured_wrench.into(),
            deflection: o.deflection.into(),
            correction: o.correction.into(),
            dq: o.dq,
            pilot_weight: o.pilot_weight,
            projected: u8::from(o.projected),
            size_limited: u8::from(o.size_limited),
            rate_limited: u8::from(o.rate_limited),
        };
        // SAFETY: non-null (checked), writable by contract.
        unsafe { write(out, value) }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Codes no current entry point can provoke are still mapped as documented.
    #[test]
    fn unreachable_codes_are_mapped() {
        let nc = TickError::NotConverged {
            iterations: 3,
            residual: 1.0,
        };
        assert_eq!(tick_status(&nc), DEFLECT_ERR_NOT_CONVERGED);
        assert_eq!(
            corrector_status(&CorrectorError::Mechanism(MechanismError::from(nc))),
            DEFLECT_ERR_NOT_CONVERGED
        );
        assert_eq!(
            mechanism_status(&MechanismError::WrongDof {
                expected: 6,
                got: 5
            }),
            DEFLECT_ERR_WRONG_LENGTH
        );
        assert_eq!(
            corrector_status(&CorrectorError::Vjm(TickError::Singular { sigma_min: 0.0 })),
            DEFLECT_ERR_SINGULAR
        );
    }
}
