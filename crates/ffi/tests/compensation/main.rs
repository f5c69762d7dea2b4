//! The online force compensation through the C API: the same cycles as deflect-core's
//! `compensation::step` bit for bit (cutter exit, pilot control, both output forms,
//! reset), the paper's defaults, and every documented error code.
#![allow(unsafe_code)] // reason: the tests call the extern "C" API, which is unsafe by nature.

use std::ffi::CString;
use std::path::Path;
use std::ptr;

use deflect::*;
use deflect_core::SerialRobot;
use deflect_core::compensation::sensor::POLY_TERMS;
use deflect_core::compensation::{
    self, CompensatorConfig, CorrectionOutput, CycleOutput, SensorCalibration,
};
use deflect_core::vjm::Vector6;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

const Q: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
const DT: f64 = 0.004;
/// A 120 degree rotation about (1, -1, 1): a quaternion of norm exactly 1.
const ROTATION: [f64; 4] = [0.5, 0.5, -0.5, 0.5];

fn repo(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
        .to_string_lossy()
        .into_owned()
}

fn c(s: &str) -> CString {
    CString::new(s).unwrap()
}

fn load_c(stiffness: &str) -> *mut DeflectSerialRobot {
    let (urdf, toml) = (c(&repo("robots/kr300/kr300_r2500.urdf")), c(stiffness));
    let mut out = ptr::null_mut();
    // SAFETY: strings are NUL-terminated, `out` is writable.
    let s = unsafe {
        deflect_serial_robot_load(
            urdf.as_ptr(),
            toml.as_ptr(),
            c"tcp".as_ptr(),
            &mut out,
            ptr::null_mut(),
            0,
        )
    };
    assert_eq!(s, DEFLECT_OK);
    out
}

fn kr300_c() -> *mut DeflectSerialRobot {
    load_c(&repo("robots/kr300/kr300_r2500_stiffness.toml"))
}

fn kr300_rust() -> SerialRobot {
    SerialRobot::from_path(
        repo("robots/kr300/kr300_r2500.urdf"),
        repo("robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    )
    .unwrap()
}

/// A non-trivial calibration, as C data and as the Rust value it stands for.
fn calibration() -> (DeflectSensorCalibration, SensorCalibration) {
    let mut residual = [[0.0; POLY_TERMS]; 6];
    residual[0][1] = 2.0;
    residual[0][12] = 0.5;
    residual[2][5] = -1.5;
    residual[5][0] = 0.1;
    let rust = SensorCalibration {
        force_offset: Vector3::new(3.0, -2.0, 5.0),
        moment_offset: Vector3::new(0.2, 0.1, -0.3),
        weight: 180.0,
        center_of_gravity: Vector3::new(0.01, -0.02, 0.15),
        residual,
        sensor_to_tcp: Isometry3::from_parts(
            Translation3::new(0.0, 0.05, 0.4),
            UnitQuaternion::new_unchecked(Quaternion::new(
                ROTATION[0],
                ROTATION[1],
                ROTATION[2],
                ROTATION[3],
            )),
        ),
    };
    let mut cal = DeflectSensorCalibration {
        force_offset: [0.0; 3],
        moment_offset: [0.0; 3],
        weight: 0.0,
        center_of_gravity: [0.0; 3],
        residual: [[0.0; DEFLECT_RESIDUAL_TERMS]; 6],
        sensor_to_tcp_translation: [0.0; 3],
        sensor_to_tcp_rotation: [0.0; 4],
    };
    // SAFETY: `cal` is writable.
    assert_eq!(
        unsafe { deflect_sensor_calibration_default(&mut cal) },
        DEFLECT_OK
    );
    assert_eq!(cal.sensor_to_tcp_rotation, [1.0, 0.0, 0.0, 0.0]);
    assert_eq!(cal.weight, 0.0);
    cal.force_offset = [3.0, -2.0, 5.0];
    cal.moment_offset = [0.2, 0.1, -0.3];
    cal.weight = 180.0;
    cal.center_of_gravity = [0.01, -0.02, 0.15];
    cal.residual = residual;
    cal.sensor_to_tcp_translation = [0.0, 0.05, 0.4];
    cal.sensor_to_tcp_rotation = ROTATION;
    (cal, rust)
}

fn paper_config(dt: f64) -> DeflectCompensatorConfig {
    let mut cfg = std::mem::MaybeUninit::<DeflectCompensatorConfig>::uninit();
    // SAFETY: `cfg` is writable; the call fills every field on success.
    unsafe {
        assert_eq!(
            deflect_compensator_config_paper(dt, cfg.as_mut_ptr()),
            DEFLECT_OK
        );
        cfg.assume_init()
    }
}

fn create(
    robot: *const DeflectSerialRobot,
    cfg: &DeflectCompensatorConfig,
) -> Result<*mut DeflectCompensator, DeflectStatus> {
    // Not NULL: a failing create must overwrite it.
    let mut out = ptr::NonNull::<DeflectCompensator>::dangling().as_ptr();
    // SAFETY: live robot handle (or NULL), readable config, writable `out`.
    let s = unsafe { deflect_compensator_create(robot, cfg, &mut out) };
    if s == DEFLECT_OK {
        assert!(!out.is_null());
        Ok(out)
    } else {
        assert!(out.is_null(), "a failed create sets *out to NULL");
        Err(s)
    }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn assert_same(c: &DeflectCycleOutput, r: &CycleOutput, k: usize) {
    assert_eq!(
        bits(&c.wrench),
        bits(r.wrench.as_slice()),
        "wrench, cycle {k}"
    );
    assert_eq!(
        bits(&c.measured_wrench),
        bits(r.measured_wrench.as_slice()),
        "measured wrench, cycle {k}"
    );
    assert_eq!(
        bits(&c.deflection),
        bits(r.deflection.as_slice()),
        "deflection, cycle {k}"
    );
    assert_eq!(
        bits(&c.correction),
        bits(r.correction.as_slice()),
        "correction, cycle {k}"
    );
    assert_eq!(bits(&c.dq), bits(&r.dq), "dq, cycle {k}");
    assert_eq!(
        c.pilot_weight.to_bits(),
        r.pilot_weight.to_bits(),
        "cycle {k}"
    );
    assert_eq!(c.projected, u8::from(r.projected), "projected, cycle {k}");
    assert_eq!(c.size_limited, u8::from(r.size_limited), "cycle {k}");
    assert_eq!(c.rate_limited, u8::from(r.rate_limited), "cycle {k}");
}

/// Cycle `k` of a milling pass along base y with the cutter leaving the part at cycle 200:
/// joints, raw sensor reading, offline estimate (which knows the exit 20 cycles early) and
/// feed velocity.
fn cycle(k: usize) -> ([f64; 6], [f64; 6], [f64; 6], [f64; 3]) {
    let t = k as f64;
    let mut q = Q;
    q[0] = 2e-4 * t;
    q[4] += 1e-4 * t;
    let cutting = k < 200;
    let noise = (0.7 * t).sin();
    let f = if cutting { 600.0 } else { 0.0 };
    let reading = [
        3.0 + 0.4 * f + 8.0 * noise,
        -2.0 - 0.8 * f + 5.0 * noise,
        -180.0 + 5.0 + 0.3 * f,
        0.2 + 0.02 * f,
        0.1 - 0.01 * f * noise,
        -0.3,
    ];
    let estimated = if k < 180 {
        [-400.0, 450.0, -150.0, 0.0, 0.0, 0.0]
    } else {
        [0.0; 6]
    };
    let feed = if k < 320 { [0.0, 0.025, 0.0] } else { [0.0; 3] };
    (q, reading, estimated, feed)
}

fn run_against_rust(output: i32, with_estimate_from: usize) {
    let robot = kr300_c();
    let rust = kr300_rust();
    let (cal_c, cal_r) = calibration();
    let mut cfg = paper_config(DT);
    cfg.calibration = cal_c;
    cfg.max_rate = 0.2;
    cfg.output = output;
    let comp = create(robot, &cfg).unwrap();
    let mut rcfg = CompensatorConfig::paper(DT, cal_r);
    rcfg.max_rate = 0.2;
    rcfg.output = if output == DEFLECT_OUTPUT_JOINT {
        CorrectionOutput::Joint
    } else {
        CorrectionOutput::Cartesian
    };
    let rmodel = compensation::Model::new(rust.model.clone(), rcfg).unwrap();
    let mut rdata = compensation::Data::new(&rmodel);

    let (mut samples, mut seconds) = (0.0, 0.0);
    // SAFETY: live handle, writable outputs.
    let s = unsafe { deflect_compensator_delay(comp, &mut samples, &mut seconds) };
    assert_eq!(s, DEFLECT_OK);
    assert_eq!(samples.to_bits(), rmodel.delay_samples().to_bits());
    assert_eq!(seconds.to_bits(), rmodel.delay_seconds().to_bits());

    let (mut max_weight, mut limited, mut projected) = (0.0f64, 0, 0);
    let mut out = DeflectCycleOutput::default();
    for k in 0..400 {
        if k == 350 {
            // SAFETY: live handle.
            assert_eq!(unsafe { deflect_compensator_reset(comp) }, DEFLECT_OK);
            rdata.reset();
        }
        let (q, reading, estimated, feed) = cycle(k);
        let est = (k >= with_estimate_from).then_some(estimated);
        let est_ptr = est.as_ref().map_or(ptr::null(), |e| e.as_ptr());
        // SAFETY: live handles, arrays of the documented lengths.
        let s = unsafe {
            deflect_compensator_step(
                comp,
                q.as_ptr(),
                q.len(),
                reading.as_ptr(),
                est_ptr,
                feed.as_ptr(),
                &mut out,
            )
        };
        assert_eq!(s, DEFLECT_OK, "cycle {k}");
        let want = compensation::step(
            &rmodel,
            &mut rdata,
            &q,
            &Vector6::from(reading),
            est.map(Vector6::from).as_ref(),
            &Vector3::from(feed),
        )
        .unwrap();
        assert_same(&out, &want, k);
        max_weight = max_weight.max(out.pilot_weight);
        limited += usize::from(out.rate_limited) + usize::from(out.size_limited);
        projected += usize::from(out.projected);
        if output == DEFLECT_OUTPUT_CARTESIAN {
            assert_eq!(out.dq, [0.0; DEFLECT_MAX_DOF]);
        }
    }
    // The run exercised what it claims to: pilot control, limits, projection, joint output.
    if with_estimate_from < 400 {
        assert_eq!(max_weight, 1.0, "pilot control took over");
    } else {
        assert_eq!(max_weight, 0.0);
    }
    assert!(limited > 0, "a limit acted");
    assert!(
        projected > 0 && projected < 400,
        "projection on, then standing still"
    );
    if output == DEFLECT_OUTPUT_JOINT {
        assert!(out.dq[..6].iter().any(|d| *d != 0.0));
        assert_eq!(out.dq[6..], [0.0; DEFLECT_MAX_DOF - 6]);
    }
    // SAFETY: live handles, destroyed once.
    unsafe {
        deflect_compensator_destroy(comp);
        deflect_serial_robot_destroy(robot);
    }
}

#[test]
fn step_equals_the_rust_compensator_bit_for_bit_cartesian_with_pilot() {
    run_against_rust(DEFLECT_OUTPUT_CARTESIAN, 0);
}

#[test]
fn step_equals_the_rust_compensator_bit_for_bit_joint_with_late_estimate() {
    run_against_rust(DEFLECT_OUTPUT_JOINT, 60);
}

#[test]
fn step_equals_the_rust_compensator_bit_for_bit_without_estimate() {
    run_against_rust(DEFLECT_OUTPUT_CARTESIAN, usize::MAX);
}

#[test]
fn paper_config_and_default_calibration_match_the_rust_ones() {
    let cfg = paper_config(0.0005);
    let want = CompensatorConfig::paper(0.0005, SensorCalibration::default());
    assert_eq!(cfg.dt, want.dt);
    assert_eq!(cfg.lowpass_cutoff_hz, want.lowpass_cutoff_hz);
    assert_eq!(cfg.moving_average_window, want.moving_average_window);
    assert_eq!(cfg.pilot_enabled, 1);
    assert_eq!(Some((cfg.pilot_threshold, cfg.pilot_ramp)), want.pilot);
    assert_eq!(cfg.project_on_feed, u8::from(want.project_on_feed));
    assert_eq!(cfg.max_correction, want.max_correction);
    assert_eq!(cfg.max_rate, want.max_rate);
    assert_eq!(cfg.output, DEFLECT_OUTPUT_CARTESIAN);
    let mut cal = calibration().0;
    // SAFETY: writable.
    assert_eq!(
        unsafe { deflect_sensor_calibration_default(&mut cal) },
        DEFLECT_OK
    );
    assert_eq!(cfg.calibration, cal);
    assert_eq!(cal.residual, [[0.0; DEFLECT_RESIDUAL_TERMS]; 6]);
    assert_eq!(cal.sensor_to_tcp_translation, [0.0; 3]);
    assert_eq!(DEFLECT_PAPER_CYCLE, 0.004);
    assert_eq!(DEFLECT_MAX_AVERAGE_WINDOW, 64);
}

mod codes;
