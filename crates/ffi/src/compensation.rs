//! Online force-based compensation of Hähn and Weigold (sections 2.2-2.6): sensor offsets and
//! weight (Eq. 12-18), the wrench at the TCP (Eq. 19-20), filters, pilot control, the
//! virtual-joint deflection, projection (Eq. 10-11) and limits, every control cycle.

use deflect_core::compensation::{
    self, CompensatorConfig, CorrectionOutput, Data, MAX_AVERAGE_WINDOW, Model, SensorCalibration,
    sensor::POLY_TERMS,
};
use deflect_core::vjm::Vector6;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

use crate::boundary::{array, destroy, guard, handle, handle_mut, load, slice, write};
use crate::robot::{DEFLECT_MAX_DOF, DeflectSerialRobot};
use crate::status::{
    DEFLECT_ERR_INVALID_ARGUMENT, DEFLECT_ERR_NON_FINITE, DEFLECT_ERR_NULL, DeflectStatus,
    build_failure, tick_status,
};

/// Largest moving-average window of the online compensator \[cycles\].
pub const DEFLECT_MAX_AVERAGE_WINDOW: usize = 64;
/// Number of terms of the sensor's residual-offset polynomial (Eq. 17).
pub const DEFLECT_RESIDUAL_TERMS: usize = 15;
/// Compensator output: Cartesian correction values only.
pub const DEFLECT_OUTPUT_CARTESIAN: i32 = 0;
/// Compensator output: also axis-specific values `dq` through the joint Jacobian.
pub const DEFLECT_OUTPUT_JOINT: i32 = 1;
/// The online-compensation paper's control cycle \[s\] (KUKA RSI, 4 ms).
pub const DEFLECT_PAPER_CYCLE: f64 = 0.004;

const _: () = assert!(DEFLECT_MAX_AVERAGE_WINDOW == MAX_AVERAGE_WINDOW);
const _: () = assert!(DEFLECT_RESIDUAL_TERMS == POLY_TERMS);
const _: () = assert!(DEFLECT_PAPER_CYCLE == compensation::PAPER_CYCLE);

/// Sensor calibration and the fixed sensor-to-TCP transform of the online compensation
/// (Eq. 12-20), plain data. `deflect_sensor_calibration_default` fills the neutral one (no
/// offsets, no weight, no residual, TCP at the sensor).
///
/// The transform `^S T_TCP` (pose of the TCP in the sensor frame) is given as a translation
/// `sensor_to_tcp_translation[3] = (x, y, z)` \[m\] and a rotation quaternion
/// `sensor_to_tcp_rotation[4] = (w, x, y, z)` (scalar first). The quaternion must be finite
/// and not zero; it is normalised on use (a quaternion of norm exactly 1 is used as is).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeflectSensorCalibration {
    /// Internal force offset `F_SI` \[N\], sensor frame.
    pub force_offset: [f64; 3],
    /// Internal moment offset `M_SI` \[N m\], sensor frame.
    pub moment_offset: [f64; 3],
    /// Weight of everything beyond the sensor, `G` \[N\] (>= 0; gravity is `-z` of the base).
    pub weight: f64,
    /// Centre of gravity `r_G` \[m\], sensor frame.
    pub center_of_gravity: [f64; 3],
    /// Residual-offset polynomial coefficients `a_1..a_15` (Eq. 17) per sensor-frame wrench
    /// component: `residual[i][k]`, `i` in `[Fx, Fy, Fz, Mx, My, Mz]`, `k` over the terms `1,
    /// q1..q4, q1^2..q4^2, q1 q2, q1 q3, q1 q4, q2 q3, q2 q4, q3 q4` of the sensor
    /// orientation's quaternion (w >= 0). Zeros disable it.
    pub residual: [[f64; DEFLECT_RESIDUAL_TERMS]; 6],
    /// Translation of `^S T_TCP`: the TCP's position in the sensor frame \[m\].
    pub sensor_to_tcp_translation: [f64; 3],
    /// Rotation of `^S T_TCP` as a quaternion `(w, x, y, z)`, scalar first.
    pub sensor_to_tcp_rotation: [f64; 4],
}

/// Settings of the online compensation chain (`deflect_compensator_config_paper` fills the
/// paper's). Flags are 0 or 1; any other value is `DEFLECT_ERR_INVALID_ARGUMENT`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeflectCompensatorConfig {
    /// Cycle time \[s\], > 0 (0.004 in the paper, 0.0005 at 2 kHz).
    pub dt: f64,
    /// Sensor offsets, weight, residual polynomial and sensor-to-TCP transform.
    pub calibration: DeflectSensorCalibration,
    /// Low-pass cut-off \[Hz\], > 0.
    pub lowpass_cutoff_hz: f64,
    /// Moving-average window \[cycles\], 1..=`DEFLECT_MAX_AVERAGE_WINDOW`.
    pub moving_average_window: usize,
    /// 1: pilot control (blend to the estimated wrench when it differs from the measured one
    /// by more than `pilot_threshold`); 0: measured forces only.
    pub pilot_enabled: u8,
    /// Pilot-control switching threshold \[N\], >= 0 (paper: 150).
    pub pilot_threshold: f64,
    /// Pilot-control blending time \[s\], >= 0 (paper: 0.080; 0 switches in one cycle).
    pub pilot_ramp: f64,
    /// 1: project the translational correction onto the plane normal to the feed (Eq. 10-11).
    pub project_on_feed: u8,
    /// Largest translational correction \[m\], >= 0; larger ones are scaled down and reported.
    pub max_correction: f64,
    /// Largest change of the translational correction per second \[m/s\], >= 0.
    pub max_rate: f64,
    /// `DEFLECT_OUTPUT_CARTESIAN` or `DEFLECT_OUTPUT_JOINT`.
    pub output: i32,
}

/// What one compensation cycle produced (`deflect_compensator_step`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectCycleOutput {
    /// The wrench fed to the model `[Fx, Fy, Fz, Mx, My, Mz]` \[N, N m\]: TCP, base frame,
    /// filtered (and piloted).
    pub wrench: [f64; 6],
    /// The wrench before pilot control (filtered measurement) \[N, N m\].
    pub measured_wrench: [f64; 6],
    /// Model deflection `[dx, dy, dz, rx, ry, rz]` \[m, rad\] under `wrench` (Eq. 9).
    pub deflection: [f64; 6],
    /// Correction to add to the commanded pose `[dx, dy, dz, rx, ry, rz]` \[m, rad\], base
    /// frame, after projection and limits.
    pub correction: [f64; 6],
    /// Axis-specific correction \[rad or m\]; zeros unless the output is `DEFLECT_OUTPUT_JOINT`,
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

/// The online force-compensation chain of one serial robot: its model (the robot's chain and
/// the validated settings) and its state (filters, pilot control, rate limiter, workspace).
/// Opaque; create with `deflect_compensator_create`, free with `deflect_compensator_destroy`.
/// Not thread-safe: one thread at a time.
#[derive(Debug)]
pub struct DeflectCompensator {
    model: Model,
    data: Data,
}

fn flag(v: u8) -> Result<bool, DeflectStatus> {
    match v {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(DEFLECT_ERR_INVALID_ARGUMENT),
    }
}

/// Converts a C calibration. Only the quaternion is checked here (C gives a raw one, which
/// is normalised); every value is validated by deflect-core when the model is built.
fn sensor_calibration(c: &DeflectSensorCalibration) -> Result<SensorCalibration, DeflectStatus> {
    let [w, x, y, z] = c.sensor_to_tcp_rotation;
    let q = Quaternion::new(w, x, y, z);
    let norm = q.norm();
    if !norm.is_finite() {
        return Err(DEFLECT_ERR_NON_FINITE);
    }
    if norm == 0.0 {
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

/// Converts a C configuration (flags and codes); the values are validated by deflect-core.
fn compensator_config(c: &DeflectCompensatorConfig) -> Result<CompensatorConfig, DeflectStatus> {
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

/// Writes the paper's chain at cycle time `dt` \[s\] to `*out`: the neutral calibration (set
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

/// Creates the online compensation chain for `robot` with settings `*config`. The handle holds
/// the robot's chain with the settings and its own filter states and workspace; the robot
/// handle may be destroyed afterwards. Init time: allocates. On failure `*out` is NULL.
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
        let model = Model::new(r.robot.model.clone(), config).map_err(build_failure)?;
        let data = Data::new(&model);
        Ok(DeflectCompensator { model, data })
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
            unsafe { write(samples, c.model.delay_samples()) }?;
        }
        if !seconds.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(seconds, c.model.delay_seconds()) }?;
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
        unsafe { handle_mut(compensator) }?.data.reset();
        Ok(())
    })
}

/// One control cycle of the online compensation: joints `q[q_len]` \[rad or m\], the raw sensor
/// reading `reading[6] = [Fx, Fy, Fz, Mx, My, Mz]` \[N, N m\] (sensor frame), the offline
/// estimate `estimated[6]` of the TCP wrench (base frame; NULL if the program provides none,
/// which also skips pilot control) and the feed velocity `feed_velocity[3]` \[m/s\] (base
/// frame). The sensor reading is compensated (Eq. 18) and carried to the TCP (Eq. 19-20),
/// low-pass filtered and averaged, piloted, turned into a deflection (Eq. 9), and the opposite
/// correction projected (Eq. 10-11), limited and written to `*out`. Per cycle: no allocation,
/// bounded time.
///
/// Returns `DEFLECT_ERR_NULL` (handle, `q`, `reading`, `feed_velocity` or `out`; nothing is
/// changed then), `DEFLECT_ERR_NON_FINITE`, `DEFLECT_ERR_WRONG_LENGTH` (`q_len` is not the
/// robot's dof) or `DEFLECT_ERR_SINGULAR` (joint output at a singular pose). Invalid inputs
/// are refused before any state changes, except a singular pose with joint output, which is
/// met after the filter states have advanced.
///
/// # Safety
/// `compensator` is NULL or a live handle not used by another thread; `q` holds `q_len`
/// doubles, `reading` 6, `estimated` 6 (or is NULL), `feed_velocity` 3; `out` is NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compensator_step(
    compensator: *mut DeflectCompensator,
    q: *const f64,
    q_len: usize,
    reading: *const f64,
    estimated: *const f64,
    feed_velocity: *const f64,
    out: *mut DeflectCycleOutput,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (c, q, reading, feed) = unsafe {
            (
                handle_mut(compensator)?,
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
        let o = compensation::step(
            &c.model,
            &mut c.data,
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
