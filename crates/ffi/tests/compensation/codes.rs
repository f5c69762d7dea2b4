//! The compensator's inputs through the C API: quaternion normalisation, and every
//! documented error code of `create` and `step` (the state left alone).
#![allow(unsafe_code)] // reason: the tests call the extern "C" API, which is unsafe by nature.

use super::*;

#[test]
fn a_non_unit_quaternion_is_normalised_like_from_quaternion() {
    let robot = kr300_c();
    let rust = kr300_rust();
    let mut cfg = paper_config(DT);
    cfg.calibration.sensor_to_tcp_rotation = [2.0, 0.3, -0.1, 0.7];
    cfg.calibration.weight = 50.0;
    let comp = create(robot, &cfg).unwrap();
    let cal = SensorCalibration {
        weight: 50.0,
        sensor_to_tcp: Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_quaternion(Quaternion::new(2.0, 0.3, -0.1, 0.7)),
        ),
        ..SensorCalibration::default()
    };
    let rmodel =
        compensation::Model::new(rust.model.clone(), CompensatorConfig::paper(DT, cal)).unwrap();
    let mut rdata = compensation::Data::new(&rmodel);
    let mut out = DeflectCycleOutput::default();
    for k in 0..50 {
        let (q, reading, _, feed) = cycle(k);
        // SAFETY: live handles, arrays of the documented lengths.
        let s = unsafe {
            deflect_compensator_step(
                comp,
                q.as_ptr(),
                6,
                reading.as_ptr(),
                ptr::null(),
                feed.as_ptr(),
                &mut out,
            )
        };
        assert_eq!(s, DEFLECT_OK);
        let want = compensation::step(
            &rmodel,
            &mut rdata,
            &q,
            &Vector6::from(reading),
            None,
            &Vector3::from(feed),
        )
        .unwrap();
        assert_same(&out, &want, k);
    }
    // SAFETY: live handles, destroyed once.
    unsafe {
        deflect_compensator_destroy(comp);
        deflect_serial_robot_destroy(robot);
    }
}

/// A change that spoils a good configuration.
type Edit = Box<dyn Fn(&mut DeflectCompensatorConfig)>;

#[test]
fn create_refuses_invalid_configs_with_the_documented_codes() {
    let robot = kr300_c();
    let good = paper_config(DT);
    let cases: Vec<(&str, DeflectStatus, Edit)> = vec![
        (
            "dt 0",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.dt = 0.0),
        ),
        (
            "dt < 0",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.dt = -DT),
        ),
        (
            "dt NaN",
            DEFLECT_ERR_NON_FINITE,
            Box::new(|c| c.dt = f64::NAN),
        ),
        (
            "cut-off 0",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.lowpass_cutoff_hz = 0.0),
        ),
        (
            "cut-off inf",
            DEFLECT_ERR_NON_FINITE,
            Box::new(|c| c.lowpass_cutoff_hz = f64::INFINITY),
        ),
        (
            "window 0",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.moving_average_window = 0),
        ),
        (
            "window too long",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.moving_average_window = DEFLECT_MAX_AVERAGE_WINDOW + 1),
        ),
        (
            "pilot flag 2",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.pilot_enabled = 2),
        ),
        (
            "threshold < 0",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.pilot_threshold = -1.0),
        ),
        (
            "ramp < 0",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.pilot_ramp = -0.08),
        ),
        (
            "ramp NaN",
            DEFLECT_ERR_NON_FINITE,
            Box::new(|c| c.pilot_ramp = f64::NAN),
        ),
        (
            "projection flag 7",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.project_on_feed = 7),
        ),
        (
            "max correction < 0",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.max_correction = -1e-3),
        ),
        (
            "max rate NaN",
            DEFLECT_ERR_NON_FINITE,
            Box::new(|c| c.max_rate = f64::NAN),
        ),
        (
            "max rate < 0",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.max_rate = -1.0),
        ),
        (
            "output code",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.output = 2),
        ),
        (
            "weight < 0",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.calibration.weight = -1.0),
        ),
        (
            "zero quaternion",
            DEFLECT_ERR_INVALID_ARGUMENT,
            Box::new(|c| c.calibration.sensor_to_tcp_rotation = [0.0; 4]),
        ),
        (
            "NaN residual",
            DEFLECT_ERR_NON_FINITE,
            Box::new(|c| c.calibration.residual[3][14] = f64::NAN),
        ),
        (
            "infinite offset",
            DEFLECT_ERR_NON_FINITE,
            Box::new(|c| c.calibration.force_offset[1] = f64::NEG_INFINITY),
        ),
    ];
    for (what, code, edit) in &cases {
        let mut cfg = good;
        edit(&mut cfg);
        assert_eq!(create(robot, &cfg).err(), Some(*code), "{what}");
    }
    // Pilot settings are not checked while pilot control is off.
    let mut off = good;
    off.pilot_enabled = 0;
    off.pilot_threshold = -1.0;
    let comp = create(robot, &off).unwrap();
    // NULL arguments.
    assert_eq!(create(ptr::null(), &good).err(), Some(DEFLECT_ERR_NULL));
    // SAFETY: NULL pointers are part of the contract; `out` is writable.
    unsafe {
        let mut out = ptr::null_mut();
        assert_eq!(
            deflect_compensator_create(robot, ptr::null(), &mut out),
            DEFLECT_ERR_NULL
        );
        assert!(out.is_null());
        assert_eq!(
            deflect_compensator_create(robot, &good, ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_compensator_config_paper(DT, ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_sensor_calibration_default(ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_compensator_delay(ptr::null(), ptr::null_mut(), ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_compensator_delay(comp, ptr::null_mut(), ptr::null_mut()),
            DEFLECT_OK
        );
        assert_eq!(deflect_compensator_reset(ptr::null_mut()), DEFLECT_ERR_NULL);
        deflect_compensator_destroy(ptr::null_mut());
        deflect_compensator_destroy(comp);
        deflect_serial_robot_destroy(robot);
    }
}

#[test]
fn step_returns_the_documented_codes_and_leaves_the_state_alone() {
    let robot = kr300_c();
    let rust = kr300_rust();
    let mut cfg = paper_config(DT);
    cfg.output = DEFLECT_OUTPUT_JOINT;
    let comp = create(robot, &cfg).unwrap();
    let mut rcfg = CompensatorConfig::paper(DT, SensorCalibration::default());
    rcfg.output = CorrectionOutput::Joint;
    let rmodel = compensation::Model::new(rust.model.clone(), rcfg).unwrap();
    let mut rdata = compensation::Data::new(&rmodel);
    let (q, reading, est, feed) = cycle(3);
    let nan6 = [0.0, 0.0, f64::NAN, 0.0, 0.0, 0.0];
    let nan3 = [0.0, f64::INFINITY, 0.0];
    let mut q_nan = q;
    q_nan[2] = f64::NAN;
    let mut out = DeflectCycleOutput::default();
    // SAFETY: live handles or NULL, arrays of the documented lengths.
    let step = |comp: *mut DeflectCompensator,
                q: *const f64,
                q_len: usize,
                reading: *const f64,
                est: *const f64,
                feed: *const f64,
                out: *mut DeflectCycleOutput| unsafe {
        deflect_compensator_step(comp, q, q_len, reading, est, feed, out)
    };
    let (qp, rp, ep, fp) = (q.as_ptr(), reading.as_ptr(), est.as_ptr(), feed.as_ptr());
    let o: *mut DeflectCycleOutput = &mut out;
    let cases: [(&str, DeflectStatus, DeflectStatus); 11] = [
        (
            "NULL compensator",
            DEFLECT_ERR_NULL,
            step(ptr::null_mut(), qp, 6, rp, ep, fp, o),
        ),
        (
            "NULL q",
            DEFLECT_ERR_NULL,
            step(comp, ptr::null(), 6, rp, ep, fp, o),
        ),
        (
            "NULL reading",
            DEFLECT_ERR_NULL,
            step(comp, qp, 6, ptr::null(), ep, fp, o),
        ),
        (
            "NULL feed",
            DEFLECT_ERR_NULL,
            step(comp, qp, 6, rp, ep, ptr::null(), o),
        ),
        (
            "NULL out",
            DEFLECT_ERR_NULL,
            step(comp, qp, 6, rp, ep, fp, ptr::null_mut()),
        ),
        (
            "q_len 5",
            DEFLECT_ERR_WRONG_LENGTH,
            step(comp, qp, 5, rp, ep, fp, o),
        ),
        (
            "q_len 7",
            DEFLECT_ERR_WRONG_LENGTH,
            step(comp, qp, 7, rp, ep, fp, o),
        ),
        (
            "NaN q",
            DEFLECT_ERR_NON_FINITE,
            step(comp, q_nan.as_ptr(), 6, rp, ep, fp, o),
        ),
        (
            "NaN reading",
            DEFLECT_ERR_NON_FINITE,
            step(comp, qp, 6, nan6.as_ptr(), ep, fp, o),
        ),
        (
            "NaN estimate",
            DEFLECT_ERR_NON_FINITE,
            step(comp, qp, 6, rp, nan6.as_ptr(), fp, o),
        ),
        (
            "infinite feed",
            DEFLECT_ERR_NON_FINITE,
            step(comp, qp, 6, rp, ep, nan3.as_ptr(), o),
        ),
    ];
    for (what, want, got) in cases {
        assert_eq!(got, want, "{what}");
    }
    assert_eq!(
        out,
        DeflectCycleOutput::default(),
        "failed steps write no output"
    );

    // The compensator owns its robot's chain: it keeps working after the robot handle is
    // destroyed, even when a robot with other springs then takes the freed memory.
    // SAFETY: live handle, destroyed once and not used afterwards.
    unsafe { deflect_serial_robot_destroy(robot) };
    let dir = std::env::temp_dir().join(format!("deflect-ffi-comp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let toml = dir.join("one_spring.toml");
    std::fs::write(
        &toml,
        "[[virtual_joint]]\nlink = \"link_1\"\nk = [1.2e7, 1.2e7, 7.5e6]\n",
    )
    .unwrap();
    let other = load_c(&toml.to_string_lossy());
    let (mut dof, mut springs) = (0, 0);
    // SAFETY: live handle, writable outputs.
    assert_eq!(
        unsafe { deflect_serial_robot_dof(other, &mut dof, &mut springs) },
        DEFLECT_OK
    );
    assert_eq!((dof, springs), (6, 1));
    std::fs::remove_dir_all(&dir).unwrap();

    // None of the refused calls moved the filters: the next good steps equal a fresh Rust
    // compensator's (of the KR 300 the compensator was made for, whose handle is gone).
    for k in 0..30 {
        let (q, reading, est, feed) = cycle(k);
        assert_eq!(
            step(
                comp,
                q.as_ptr(),
                6,
                reading.as_ptr(),
                est.as_ptr(),
                feed.as_ptr(),
                o
            ),
            DEFLECT_OK
        );
        let want = compensation::step(
            &rmodel,
            &mut rdata,
            &q,
            &Vector6::from(reading),
            Some(&Vector6::from(est)),
            &Vector3::from(feed),
        )
        .unwrap();
        assert_same(&out, &want, k);
    }
    // SAFETY: live handles, destroyed once.
    unsafe {
        deflect_compensator_destroy(comp);
        deflect_serial_robot_destroy(other);
    }
}
