//! The serial-arm corrector and pose motions through the C API: forward kinematics against
//! deflect-core, a status code for every bad input, and a corrected tick that lands the
//! loaded arm on the desired pose.
#![allow(unsafe_code)] // reason: the tests call the extern "C" API, which is unsafe by nature.

use std::ffi::{CString, c_char};
use std::path::Path;
use std::ptr;

use deflect::*;

const Q0: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];

fn repo(rel: &str) -> CString {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel);
    CString::new(p.to_string_lossy().as_bytes()).unwrap()
}

fn kr300() -> *mut DeflectSerialRobot {
    let (urdf, toml) = (
        repo("robots/kr300/kr300_r2500.urdf"),
        repo("robots/kr300/kr300_r2500_stiffness.toml"),
    );
    let mut out = ptr::null_mut();
    let mut err = [0 as c_char; 256];
    // SAFETY: NUL-terminated strings, writable outputs of the stated sizes.
    let s = unsafe {
        deflect_serial_robot_load(
            urdf.as_ptr(),
            toml.as_ptr(),
            c"tcp".as_ptr(),
            &mut out,
            err.as_mut_ptr(),
            err.len(),
        )
    };
    assert_eq!(s, DEFLECT_OK);
    out
}

fn payload() -> DeflectPayload {
    DeflectPayload {
        mass: 150.0,
        com: [0.0, 0.0, 0.25],
        inertia: [4.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 2.5],
    }
}

fn create(
    robot: *mut DeflectSerialRobot,
    p: &DeflectPayload,
    model: i32,
    seed: &[f64],
) -> DeflectStatus {
    let mut out = ptr::null_mut();
    // SAFETY: live handle, readable inputs, writable output.
    let s = unsafe {
        deflect_serial_dalembert_create(robot, p, model, seed.as_ptr(), seed.len(), &mut out)
    };
    if s != DEFLECT_OK {
        assert!(out.is_null(), "a failed create leaves NULL");
    }
    // SAFETY: NULL or a live handle.
    unsafe { deflect_serial_dalembert_destroy(out) };
    s
}

#[test]
fn forward_and_pose_motion_agree_with_the_core() {
    let robot = kr300();
    let mut t = [0.0; 16];
    // SAFETY: live handle, arrays of the documented lengths.
    assert_eq!(
        unsafe { deflect_serial_robot_forward(robot, Q0.as_ptr(), 6, t.as_mut_ptr()) },
        DEFLECT_OK
    );
    let core = deflect_core::SerialRobot::from_path(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/kr300/kr300_r2500.urdf"),
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    )
    .unwrap();
    let mut data = deflect_core::vjm::Data::new(&core.model);
    let want = deflect_core::vjm::forward(&core.model, &mut data, &Q0)
        .unwrap()
        .to_homogeneous();
    for r in 0..4 {
        for c in 0..4 {
            assert_eq!(t[4 * r + c], want[(r, c)], "({r}, {c})");
        }
    }
    // SAFETY: as above; a wrong length and a NaN joint are statuses.
    unsafe {
        assert_eq!(
            deflect_serial_robot_forward(robot, Q0.as_ptr(), 5, t.as_mut_ptr()),
            DEFLECT_ERR_WRONG_LENGTH
        );
        let nan = [f64::NAN; 6];
        assert_eq!(
            deflect_serial_robot_forward(robot, nan.as_ptr(), 6, t.as_mut_ptr()),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_serial_robot_forward(robot, Q0.as_ptr(), 6, ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
    }
    let mut end = t;
    end[3] += 0.2;
    let lin = DeflectLimits {
        v_max: 1.0,
        a_max: 10.0,
        j_max: 100.0,
    };
    let ang = DeflectLimits {
        v_max: 1.0,
        a_max: 10.0,
        j_max: 100.0,
    };
    let mut m = ptr::null_mut();
    // SAFETY: arrays of 16, readable limits, writable output.
    unsafe {
        assert_eq!(
            deflect_pose_motion_line(t.as_ptr(), end.as_ptr(), &lin, &ang, &mut m),
            DEFLECT_OK
        );
        let (mut duration, mut ticks) = (0.0, 0usize);
        assert_eq!(
            deflect_pose_motion_info(m, 2000.0, &mut duration, &mut ticks),
            DEFLECT_OK
        );
        let one = deflect_core::motion::Profile::new(
            0.2,
            &deflect_core::motion::Limits::new(1.0, 10.0, 100.0).unwrap(),
        )
        .unwrap();
        assert!((duration - one.duration()).abs() < 1e-12, "{duration}");
        assert_eq!(ticks, 1 + (duration * 2000.0 - 1e-9).ceil() as usize);
        let mut s = DeflectPoseState::default();
        assert_eq!(deflect_pose_motion_sample(m, duration, &mut s), DEFLECT_OK);
        assert_eq!(s.pose[3], end[3]);
        assert_eq!(
            deflect_pose_motion_sample(m, f64::NAN, &mut s),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_pose_motion_info(m, 0.0, &mut duration, &mut ticks),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            deflect_pose_motion_info(m, 1e300, &mut duration, &mut ticks),
            DEFLECT_ERR_BUDGET
        );
        deflect_pose_motion_destroy(m);
        // Not a rigid transform, a bad limit, NULLs.
        let mut bad = end;
        bad[0] = 2.0;
        let mut m2 = ptr::null_mut();
        assert_eq!(
            deflect_pose_motion_line(t.as_ptr(), bad.as_ptr(), &lin, &ang, &mut m2),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert!(m2.is_null());
        let zero = DeflectLimits { v_max: 0.0, ..lin };
        assert_eq!(
            deflect_pose_motion_line(t.as_ptr(), end.as_ptr(), &lin, &zero, &mut m2),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            deflect_pose_motion_line(t.as_ptr(), ptr::null(), &lin, &ang, &mut m2),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_pose_motion_line(t.as_ptr(), end.as_ptr(), &lin, &ang, ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
        deflect_serial_robot_destroy(robot);
    }
}

#[test]
fn every_bad_input_is_a_status() {
    let robot = kr300();
    let p = payload();
    assert_eq!(create(robot, &p, DEFLECT_SERIAL_EXACT, &Q0), DEFLECT_OK);
    assert_eq!(
        create(robot, &p, DEFLECT_SERIAL_LINEARIZED, &Q0),
        DEFLECT_OK
    );
    assert_eq!(create(robot, &p, 7, &Q0), DEFLECT_ERR_INVALID_ARGUMENT);
    assert_eq!(
        create(robot, &p, DEFLECT_SERIAL_EXACT, &Q0[..5]),
        DEFLECT_ERR_WRONG_LENGTH
    );
    assert_eq!(
        create(robot, &p, DEFLECT_SERIAL_EXACT, &[f64::NAN; 6]),
        DEFLECT_ERR_NON_FINITE
    );
    assert_eq!(
        create(robot, &DeflectPayload { mass: -1.0, ..p }, 0, &Q0),
        DEFLECT_ERR_INVALID_ARGUMENT
    );
    assert_eq!(
        create(
            robot,
            &DeflectPayload {
                mass: f64::NAN,
                ..p
            },
            0,
            &Q0
        ),
        DEFLECT_ERR_NON_FINITE
    );
    let mut asym = p;
    asym.inertia[1] = 1.0;
    assert_eq!(create(robot, &asym, 0, &Q0), DEFLECT_ERR_INVALID_ARGUMENT);
    let mut indefinite = p;
    indefinite.inertia[0] = -4.0;
    assert_eq!(create(robot, &indefinite, 0, &Q0), DEFLECT_ERR_SINGULAR);
    // SAFETY: NULL handles are statuses.
    unsafe {
        let mut out = ptr::null_mut();
        assert_eq!(
            deflect_serial_dalembert_create(ptr::null(), &p, 0, Q0.as_ptr(), 6, &mut out),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_serial_dalembert_create(robot, ptr::null(), 0, Q0.as_ptr(), 6, &mut out),
            DEFLECT_ERR_NULL
        );
    }

    let mut c = ptr::null_mut();
    let mut t = [0.0; 16];
    // SAFETY: live handles, arrays of the documented lengths, writable outputs.
    unsafe {
        assert_eq!(
            deflect_serial_dalembert_create(robot, &p, 0, Q0.as_ptr(), 6, &mut c),
            DEFLECT_OK
        );
        assert_eq!(
            deflect_serial_robot_forward(robot, Q0.as_ptr(), 6, t.as_mut_ptr()),
            DEFLECT_OK
        );
        let mut state = DeflectPoseState {
            pose: t,
            ..DeflectPoseState::default()
        };
        state.acceleration = [3.0, -2.0, 5.0];
        let mut tick = DeflectSerialTick::default();
        assert_eq!(
            deflect_serial_dalembert_step(c, &state, ptr::null(), &mut tick),
            DEFLECT_OK
        );
        // The loaded arm at the command lands on the desired pose: its deflection under the
        // tick's wrench is the difference between desired and commanded.
        let mut d = [0.0; 6];
        assert_eq!(
            deflect_serial_robot_deflection(
                robot,
                tick.joints.as_ptr(),
                6,
                tick.wrench.as_ptr(),
                d.as_mut_ptr()
            ),
            DEFLECT_OK
        );
        for (i, at) in [3, 7, 11].into_iter().enumerate() {
            assert!((tick.commanded[at] + d[i] - t[at]).abs() < 1e-8, "axis {i}");
        }
        assert!((tick.wrench[0] + 150.0 * 3.0).abs() < 1e-9);
        let process = [0.0, 0.0, -500.0, 0.0, 0.0, 0.0];
        assert_eq!(
            deflect_serial_dalembert_step(c, &state, process.as_ptr(), &mut tick),
            DEFLECT_OK
        );
        assert!((tick.wrench[2] - (-150.0 * 5.0 - 500.0)).abs() < 1e-9);
        // Bad inputs.
        let mut bad = state;
        bad.angular_velocity[1] = f64::INFINITY;
        assert_eq!(
            deflect_serial_dalembert_step(c, &bad, ptr::null(), &mut tick),
            DEFLECT_ERR_NON_FINITE
        );
        let mut bad = state;
        bad.pose[15] = 2.0;
        assert_eq!(
            deflect_serial_dalembert_step(c, &bad, ptr::null(), &mut tick),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        let nan_w = [f64::NAN; 6];
        assert_eq!(
            deflect_serial_dalembert_step(c, &state, nan_w.as_ptr(), &mut tick),
            DEFLECT_ERR_NON_FINITE
        );
        let mut far = state;
        far.pose[3] = 10.0;
        let s = deflect_serial_dalembert_step(c, &far, ptr::null(), &mut tick);
        assert!(
            s == DEFLECT_ERR_NOT_CONVERGED
                || s == DEFLECT_ERR_SINGULAR
                || s == DEFLECT_ERR_JOINT_LIMIT,
            "{s}"
        );
        assert_eq!(
            deflect_serial_dalembert_step(c, &state, ptr::null(), ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_serial_dalembert_step(c, ptr::null(), ptr::null(), &mut tick),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_serial_dalembert_reset(c, Q0.as_ptr(), 5),
            DEFLECT_ERR_WRONG_LENGTH
        );
        assert_eq!(
            deflect_serial_dalembert_reset(c, Q0.as_ptr(), 6),
            DEFLECT_OK
        );
        // Joint limits (the URDF's, a2 <= 0.3491 rad): a pose that needs a2 = 0.4 rad.
        let mut q = Q0;
        q[1] = 0.4;
        let mut beyond = DeflectPoseState::default();
        assert_eq!(
            deflect_serial_robot_forward(robot, q.as_ptr(), 6, beyond.pose.as_mut_ptr()),
            DEFLECT_OK
        );
        assert_eq!(deflect_serial_dalembert_reset(c, q.as_ptr(), 6), DEFLECT_OK);
        assert_eq!(
            deflect_serial_dalembert_step(c, &beyond, ptr::null(), &mut tick),
            DEFLECT_ERR_JOINT_LIMIT
        );
        deflect_serial_dalembert_destroy(c);
        deflect_serial_robot_destroy(robot);
    }
}

#[test]
fn link_inertia_and_gravity_match_the_core() {
    use deflect_core::dalembert::serial;
    use deflect_core::motion::{Limits, PoseLimits, PoseTrajectory};
    let robot = kr300();
    let p = payload();
    let core_robot = deflect_core::SerialRobot::from_path(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/kr300/kr300_r2500.urdf"),
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    )
    .unwrap();
    let start = deflect_core::vjm::forward(
        &core_robot.model,
        &mut deflect_core::vjm::Data::new(&core_robot.model),
        &Q0,
    )
    .unwrap();
    let mut end = start;
    end.translation.vector += nalgebra::Vector3::new(0.3, 0.2, -0.1);
    let limits = PoseLimits {
        linear: Limits::new(2.0, 9.81, 200.0).unwrap(),
        angular: Limits::new(1.5, 8.0, 100.0).unwrap(),
    };
    let traj = PoseTrajectory::line(&start, &end, &limits).unwrap();
    let gravity = [0.0, 0.0, -9.81];
    let core_model = serial::Model::new(
        core_robot.model.clone(),
        serial::Payload {
            mass: p.mass,
            com: p.com.into(),
            inertia: nalgebra::Matrix3::from_row_slice(&p.inertia),
        },
    )
    .unwrap()
    .with_joint_limits(&core_robot.joint_limits)
    .unwrap()
    .with_link_inertia(true)
    .with_gravity(gravity.into())
    .unwrap();
    let mut core_data = serial::Data::new(&core_model);
    core_data.set_seed(&Q0);
    let mut c = ptr::null_mut();
    // SAFETY: live handles, readable inputs, writable outputs.
    unsafe {
        assert_eq!(
            deflect_serial_dalembert_create(
                robot,
                &p,
                DEFLECT_SERIAL_EXACT,
                Q0.as_ptr(),
                6,
                &mut c
            ),
            DEFLECT_OK
        );
        let nan = [0.0, f64::NAN, 0.0];
        assert_eq!(
            deflect_serial_dalembert_set_loads(c, 1, nan.as_ptr()),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_serial_dalembert_set_loads(ptr::null_mut(), 1, ptr::null()),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_serial_dalembert_set_loads(c, 1, gravity.as_ptr()),
            DEFLECT_OK
        );
        let mut worst_gap = 0.0f64;
        for k in (0..traj.tick_count(2000.0).unwrap()).step_by(10) {
            let s = traj
                .sample(traj.tick_time(2000.0, k, traj.tick_count(2000.0).unwrap()))
                .unwrap();
            let want = serial::step(&core_model, &mut core_data, &s, None).unwrap();
            let state = DeflectPoseState {
                t: s.t,
                pose: {
                    let m: [[f64; 4]; 4] = s.pose.to_homogeneous().transpose().into();
                    let mut out = [0.0; 16];
                    for (o, v) in out.iter_mut().zip(m.iter().flatten()) {
                        *o = *v;
                    }
                    out
                },
                velocity: s.velocity.into(),
                acceleration: s.acceleration.into(),
                angular_velocity: s.angular_velocity.into(),
                angular_acceleration: s.angular_acceleration.into(),
            };
            let mut tick = DeflectSerialTick::default();
            assert_eq!(
                deflect_serial_dalembert_step(c, &state, ptr::null(), &mut tick),
                DEFLECT_OK
            );
            for (a, b) in tick.joints.iter().zip(&want.joints) {
                worst_gap = worst_gap.max((a - b).abs());
            }
        }
        // The same core computation behind the handle, to rounding (the pose goes through a
        // row-major matrix and back).
        assert!(worst_gap < 1e-12, "{worst_gap:e}");
        deflect_serial_dalembert_destroy(c);
        deflect_serial_robot_destroy(robot);
    }
}

#[test]
fn an_arm_with_fewer_joints_corrects_its_task_and_reports_the_rest() {
    use deflect_core::dalembert::serial;
    let (urdf, toml) = (
        repo("robots/scara/scara4.urdf"),
        repo("robots/scara/scara4_stiffness.toml"),
    );
    let mut robot = ptr::null_mut();
    let mut err = [0 as c_char; 256];
    let q0 = [0.4, -1.1, 0.08, 0.3];
    let p = DeflectPayload {
        mass: 1.5,
        com: [0.0, 0.0, 0.03],
        inertia: [0.0; 9],
    };
    // SAFETY: NUL-terminated strings, live handles, readable inputs, writable outputs.
    unsafe {
        assert_eq!(
            deflect_serial_robot_load(
                urdf.as_ptr(),
                toml.as_ptr(),
                c"tcp".as_ptr(),
                &mut robot,
                err.as_mut_ptr(),
                err.len(),
            ),
            DEFLECT_OK
        );
        let mut c = ptr::null_mut();
        assert_eq!(
            deflect_serial_dalembert_create(
                robot,
                &p,
                DEFLECT_SERIAL_EXACT,
                q0.as_ptr(),
                4,
                &mut c
            ),
            DEFLECT_OK,
            "a 4-axis SCARA is accepted"
        );
        assert_eq!(
            deflect_serial_dalembert_set_task(c, DEFLECT_TASK_POSE),
            DEFLECT_ERR_WRONG_LENGTH
        );
        assert_eq!(
            deflect_serial_dalembert_set_task(c, 42),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            deflect_serial_dalembert_set_task(ptr::null_mut(), DEFLECT_TASK_POSITION),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_serial_dalembert_set_task(c, DEFLECT_TASK_POSITION_AND_SPIN),
            DEFLECT_OK
        );
        // The core corrector of the same arm and task, tick for tick.
        let core_robot = deflect_core::SerialRobot::from_path(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/scara/scara4.urdf"),
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/scara/scara4_stiffness.toml"),
            "tcp",
        )
        .unwrap();
        let base = serial::Model::new(
            core_robot.model.clone(),
            serial::Payload::point(1.5, nalgebra::Vector3::new(0.0, 0.0, 0.03)),
        )
        .unwrap()
        .with_joint_limits(&core_robot.joint_limits)
        .unwrap();
        let core_model = base
            .clone()
            .with_ik_options(deflect_core::mechanism::PoseIkOptions {
                task: deflect_core::mechanism::Task::POSITION_AND_SPIN,
                ..*base.ik_options()
            })
            .unwrap();
        let mut core_data = serial::Data::new(&core_model);
        core_data.set_seed(&q0);
        let start = deflect_core::vjm::forward(
            &core_robot.model,
            &mut deflect_core::vjm::Data::new(&core_robot.model),
            &q0,
        )
        .unwrap();
        let mut s = deflect_core::motion::PoseState::at_rest(0.0, start);
        s.acceleration = nalgebra::Vector3::new(30.0, -20.0, 0.0);
        let want = serial::step(&core_model, &mut core_data, &s, None).unwrap();
        let m: [[f64; 4]; 4] = s.pose.to_homogeneous().transpose().into();
        let mut pose = [0.0; 16];
        for (o, v) in pose.iter_mut().zip(m.iter().flatten()) {
            *o = *v;
        }
        let state = DeflectPoseState {
            t: 0.0,
            pose,
            velocity: [0.0; 3],
            acceleration: [30.0, -20.0, 0.0],
            angular_velocity: [0.0; 3],
            angular_acceleration: [0.0; 3],
        };
        let mut tick = DeflectSerialTick::default();
        assert_eq!(
            deflect_serial_dalembert_step(c, &state, ptr::null(), &mut tick),
            DEFLECT_OK
        );
        for (a, b) in tick.joints.iter().zip(&want.joints) {
            assert!((a - b).abs() < 1e-12, "{:?} {:?}", tick.joints, want.joints);
        }
        // 1.5 kg at 3.6 g sideways: the quill and arms bend; the command differs from the
        // start by the correction, and the tool's tilt (which a SCARA cannot correct) is
        // reported.
        assert!((tick.joints[0] - q0[0]).abs() > 1e-6);
        assert_eq!(tick.free_rotation, want.diagnostics.free_rotation);
        assert!(tick.free_rotation > 1e-6, "{}", tick.free_rotation);
        deflect_serial_dalembert_destroy(c);
        deflect_serial_robot_destroy(robot);
    }
}
