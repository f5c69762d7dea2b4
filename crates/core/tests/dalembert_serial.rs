//! The 6-D D'Alembert corrector of a serial arm on the shipped KR 300: the predicted loaded
//! pose of every command equals the desired pose to the IK tolerance, the inertial wrench
//! follows Eq. 3-5 by hand, and every failure is a status.

use approx::assert_relative_eq;
use deflect_core::dalembert::serial::{self, Payload};
use deflect_core::mechanism::{PoseIkOptions, pose_ik};
use deflect_core::motion::{Limits, PoseLimits, PoseState, PoseTrajectory};
use deflect_core::vjm::{self, Data, Vector6};
use deflect_core::{SerialRobot, TickError};
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

mod fixtures;

const Q0: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];

fn payload() -> Payload {
    Payload {
        mass: 150.0,
        com: Vector3::new(0.0, 0.0, 0.25),
        inertia: Matrix3::from_diagonal(&Vector3::new(4.0, 4.0, 2.5)),
    }
}

fn motion(robot: &SerialRobot) -> PoseTrajectory {
    let mut data = Data::new(&robot.model);
    let start = vjm::forward(&robot.model, &mut data, &Q0).unwrap();
    let end = Isometry3::from_parts(
        Translation3::from(start.translation.vector + Vector3::new(0.1, 0.3, -0.1)),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, 0.3)) * start.rotation,
    );
    let limits = PoseLimits {
        linear: Limits::new(2.0, 9.81, 200.0).unwrap(),
        angular: Limits::new(1.5, 8.0, 100.0).unwrap(),
    };
    PoseTrajectory::line(&start, &end, &limits).unwrap()
}

#[test]
fn predicted_loaded_pose_equals_the_desired_pose_at_every_tick() {
    let robot = fixtures::kr300();
    // The payload alone, as the paper's D'Alembert force: the link masses left out.
    let model = serial::Model::new(robot.model.clone(), payload())
        .unwrap()
        .with_joint_limits(&robot.joint_limits)
        .unwrap();
    assert!(!model.link_inertia(), "off by default, as in the paper");
    let mut data = serial::Data::new(&model);
    data.set_seed(&Q0);
    let traj = motion(&robot);
    let rate = 2000.0;
    let n = traj.tick_count(rate).unwrap();
    assert!(n > 300, "{n}");
    let mut check = Data::new(&robot.model);
    let (mut max_defl, mut max_iter) = (0.0f64, 0usize);
    for k in 0..n {
        let s = traj.sample(traj.tick_time(rate, k, n)).unwrap();
        let tick = serial::step(&model, &mut data, &s, None).unwrap();
        // Consistency check, not an independent one: deflect the commanded joints under the
        // tick's own wrench with the same vjm::deflection the corrector inverts. The
        // independent check is Python's (crates/py/tests/test_serial.py,
        // test_corrected_commands_land_the_loaded_arm_on_the_desired_pose: the wrench from
        // the payload's own Newton-Euler in numpy, the landing from numpy's chain).
        let d = vjm::deflection(
            &robot.model,
            &mut check,
            &tick.joints[..6],
            &tick.load,
            vjm::Load::Exact,
        )
        .unwrap();
        let loaded = check.tcp_deflected;
        let ep = (loaded.translation.vector - s.pose.translation.vector).norm();
        let er = loaded.rotation.angle_to(&s.pose.rotation);
        assert!(ep <= 1e-8 && er <= 1e-8, "tick {k}: {ep:e} m {er:e} rad");
        assert_relative_eq!(d, tick.displacement, epsilon = 1e-15);
        max_defl = max_defl.max(d.fixed_rows::<3>(0).norm());
        max_iter = max_iter.max(tick.iterations);
    }
    // 150 kg at up to ~1 g: a deflection of a tenth of a millimetre or more is corrected.
    assert!(max_defl > 5e-5, "{max_defl}");
    assert!(max_iter <= 4, "{max_iter}");
}

#[test]
fn with_the_links_inertia_the_loaded_pose_still_lands_on_the_desired_pose() {
    let robot = fixtures::kr300();
    assert_eq!(robot.model.mass_count(), 6);
    let model = serial::Model::new(robot.model.clone(), payload())
        .unwrap()
        .with_joint_limits(&robot.joint_limits)
        .unwrap()
        .with_link_inertia(true);
    assert!(model.link_inertia());
    let payload_only = model.clone().with_link_inertia(false);
    let (mut data, mut data0) = (serial::Data::new(&model), serial::Data::new(&payload_only));
    data.set_seed(&Q0);
    data0.set_seed(&Q0);
    let traj = motion(&robot);
    let n = traj.tick_count(2000.0).unwrap();
    let mut check = Data::new(&robot.model);
    let (mut largest_gap, mut worst) = (0.0f64, 0.0f64);
    for k in 0..n {
        let s = traj.sample(traj.tick_time(2000.0, k, n)).unwrap();
        let tick = serial::step(&model, &mut data, &s, None).unwrap();
        let q = &tick.joints[..6];
        // Joint rates and accelerations at the command by another route (LU solves of the
        // rigid Jacobian there; the corrector uses damped least squares at its warm start),
        // on deflect's own Jacobian.
        vjm::joint_jacobian(&robot.model, &mut check, q).unwrap();
        let lu = check.jacobian.fixed_columns::<6>(0).into_owned().lu();
        let (v, w) = (s.velocity, s.angular_velocity);
        let qd = lu
            .solve(&Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z))
            .unwrap();
        let bias = vjm::tcp_acceleration_bias(&robot.model, &mut check, q, qd.as_slice()).unwrap();
        let (a, al) = (s.acceleration, s.angular_acceleration);
        let qdd = lu
            .solve(&(Vector6::new(a.x, a.y, a.z, al.x, al.y, al.z) - bias))
            .unwrap();
        let motion = vjm::ArmMotion {
            qd: qd.as_slice(),
            qdd: qdd.as_slice(),
            gravity: Vector3::zeros(),
        };
        vjm::deflection(
            &robot.model,
            &mut check,
            q,
            &tick.load,
            vjm::Load::ExactWithArm(motion),
        )
        .unwrap();
        let loaded = check.tcp_deflected;
        let ep = (loaded.translation.vector - s.pose.translation.vector).norm();
        let er = loaded.rotation.angle_to(&s.pose.rotation);
        // The IK tolerance (1e-8) plus rounding: the corrector's joint rates are those at the
        // solution (refreshed when the warm start was off).
        assert!(ep <= 2e-8 && er <= 2e-8, "tick {k}: {ep:e} m {er:e} rad");
        worst = worst.max(ep);
        // The arm's own inertia moves the command well beyond the payload-only one.
        let t0 = serial::step(&payload_only, &mut data0, &s, None).unwrap();
        largest_gap = largest_gap
            .max((tick.commanded.translation.vector - t0.commanded.translation.vector).norm());
    }
    assert!(largest_gap > 1e-3, "{largest_gap}");
    assert!(worst < 2e-8);
}

#[test]
fn inertial_wrench_by_hand() {
    // A point mass 2 m ahead of the TCP along x, TCP frame = base frame: spinning about z at
    // omega with no angular acceleration pulls it outward, F = m omega^2 r along +x; a linear
    // acceleration a gives F = -m a.
    let p = Payload::point(3.0, Vector3::new(2.0, 0.0, 0.0));
    let mut s = PoseState::at_rest(0.0, Isometry3::identity());
    s.angular_velocity = Vector3::new(0.0, 0.0, 0.5);
    s.acceleration = Vector3::new(0.0, 0.0, -1.0);
    let w = p.inertial_wrench(&s);
    assert_relative_eq!(w[0], 3.0 * 0.25 * 2.0, epsilon = 1e-12);
    assert_relative_eq!(w[2], 3.0, epsilon = 1e-12);
    // Moment about the TCP: r x F = (2,0,0) x (1.5, 0, 3) = (0, -6, 0).
    assert_relative_eq!(w[4], -6.0, epsilon = 1e-12);
    // A spinning inertia with angular acceleration: M = -I alpha.
    let p = Payload {
        mass: 0.0,
        com: Vector3::zeros(),
        inertia: Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0)),
    };
    let mut s = PoseState::at_rest(0.0, Isometry3::identity());
    s.angular_acceleration = Vector3::new(0.0, 0.0, 4.0);
    assert_relative_eq!(p.inertial_wrench(&s)[5], -12.0, epsilon = 1e-12);
}

#[test]
fn failures_are_statuses() {
    let robot = fixtures::kr300();
    let tight: Vec<(f64, f64)> = Q0.iter().map(|q| (q - 1e-6, q + 1e-6)).collect();
    let model = serial::Model::new(robot.model.clone(), payload())
        .unwrap()
        .with_joint_limits(&tight)
        .unwrap();
    let mut data = serial::Data::new(&model);
    data.set_seed(&Q0);
    let traj = motion(&robot);
    let s = traj.sample(0.1).unwrap();
    assert!(matches!(
        serial::step(&model, &mut data, &s, None),
        Err(TickError::JointLimit { .. })
    ));
    let free = serial::Model::new(robot.model.clone(), payload()).unwrap();
    let mut data = serial::Data::new(&free);
    data.set_seed(&Q0);
    let mut far = s;
    far.pose.translation.vector += Vector3::new(10.0, 0.0, 0.0);
    assert!(matches!(
        serial::step(&free, &mut data, &far, None),
        Err(TickError::NotConverged { .. })
    ));
    let mut nan = s;
    nan.acceleration.x = f64::NAN;
    assert!(matches!(
        serial::step(&free, &mut data, &nan, None),
        Err(TickError::NonFinite {
            what: "acceleration",
            ..
        })
    ));
    assert!(matches!(
        serial::step(&free, &mut data, &s, Some(&Vector6::repeat(f64::INFINITY))),
        Err(TickError::NonFinite { .. })
    ));
    // Fewer than 6 joints cannot be corrected in 6-D; a bad payload is refused.
    assert!(
        serial::Model::new(robot.model.clone(), Payload::point(-1.0, Vector3::zeros())).is_err()
    );
}

#[test]
fn rigid_pose_ik_round_trips() {
    let robot = fixtures::kr300();
    let mut data = Data::new(&robot.model);
    let target = vjm::forward(&robot.model, &mut data, &Q0).unwrap();
    let seed = [0.05, -0.85, 1.35, 0.05, 1.0, -0.05];
    let sol = pose_ik(
        &robot.model,
        &mut data,
        &target,
        &seed,
        &Vector6::zeros(),
        vjm::Load::Rigid,
        &PoseIkOptions::default(),
    )
    .unwrap();
    for (a, b) in sol.q.iter().zip(&Q0) {
        assert!((a - b).abs() < 1e-7, "{sol:?}");
    }
}
