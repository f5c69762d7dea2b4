//! Arms with fewer than six joints: the pose IK and the D'Alembert corrector on the task the
//! arm controls ([`Task`]), the rotation it cannot correct reported, and the joint-limit
//! tolerance on a range that starts at the start joint.
//!
//! The chains are written out here (not from a URDF) so that which rotations each can control
//! is known by construction:
//! * a 5-axis arm with a two-axis wrist (pan, shoulder, elbow, forearm roll, wrist bend; the
//!   tool along the last link): position and tool axis, the spin about the tool free;
//! * an SO-101-like 5-axis arm (pan, three parallel pitch joints, roll): its tool cannot tilt
//!   out of the plane of the arm on its own (the pan that tilts it also moves it), so the
//!   position and the spin about the tool are controlled;
//! * a SCARA (two horizontal-plane revolutes, a vertical quill, a spin): position and spin.

use deflect_core::TickError;
use deflect_core::dalembert::serial::{self, Payload};
use deflect_core::mechanism::{
    JOINT_LIMIT_TOLERANCE, PoseIkOptions, Task, check_limits, largest_task, pose_ik,
};
use deflect_core::motion::{Limits, PoseLimits, PoseTrajectory};
use deflect_core::vjm::{self, Data, Load, Model, ModelBuilder, Vector6};
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

const K: [f64; 3] = [2.0e5, 2.0e6, 2.0e6];

fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::translation(x, y, z)
}

/// Pan, shoulder, elbow, forearm roll, wrist bend; TCP 0.1 m beyond the bend with its z
/// along the last link (x), a spring after every joint.
fn five_axis() -> Model {
    ModelBuilder::new()
        .revolute(Vector3::z())
        .and_then(|b| b.spring(K))
        .and_then(|b| b.fixed(at(0.0, 0.0, 0.4)))
        .and_then(|b| b.revolute(Vector3::y()))
        .and_then(|b| b.spring(K))
        .and_then(|b| b.fixed(at(0.5, 0.0, 0.0)))
        .and_then(|b| b.revolute(Vector3::y()))
        .and_then(|b| b.spring(K))
        .and_then(|b| b.fixed(at(0.4, 0.0, 0.0)))
        .and_then(|b| b.revolute(Vector3::x()))
        .and_then(|b| b.spring(K))
        .and_then(|b| b.fixed(at(0.1, 0.0, 0.0)))
        .and_then(|b| b.revolute(Vector3::y()))
        .and_then(|b| b.spring(K))
        .and_then(|b| {
            b.fixed(Isometry3::from_parts(
                Translation3::new(0.1, 0.0, 0.0),
                UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2),
            ))
        })
        .and_then(ModelBuilder::build)
        .unwrap()
}

/// Pan, three parallel pitch joints, roll about the tool (TCP z along the last link).
fn so101_like() -> Model {
    ModelBuilder::new()
        .revolute(Vector3::z())
        .and_then(|b| b.fixed(at(0.0, 0.0, 0.1)))
        .and_then(|b| b.revolute(Vector3::y()))
        .and_then(|b| b.fixed(at(0.11, 0.0, 0.0)))
        .and_then(|b| b.revolute(Vector3::y()))
        .and_then(|b| b.fixed(at(0.13, 0.0, 0.0)))
        .and_then(|b| b.revolute(Vector3::y()))
        .and_then(|b| {
            b.fixed(Isometry3::from_parts(
                Translation3::new(0.05, 0.0, 0.0),
                UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2),
            ))
        })
        .and_then(|b| b.revolute(Vector3::z()))
        .and_then(|b| b.fixed(at(0.0, 0.0, 0.05)))
        .and_then(ModelBuilder::build)
        .unwrap()
}

/// Shoulder and elbow about the vertical, a quill along it, a spin; TCP z pointing down.
fn scara() -> Model {
    ModelBuilder::new()
        .revolute(Vector3::z())
        .and_then(|b| b.fixed(at(0.3, 0.0, 0.2)))
        .and_then(|b| b.revolute(Vector3::z()))
        .and_then(|b| b.fixed(at(0.25, 0.0, 0.0)))
        .and_then(|b| b.prismatic(Vector3::z()))
        .and_then(|b| b.revolute(Vector3::z()))
        .and_then(|b| {
            b.fixed(Isometry3::from_parts(
                Translation3::new(0.0, 0.0, -0.1),
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
            ))
        })
        .and_then(ModelBuilder::build)
        .unwrap()
}

const Q5: [f64; 5] = [0.3, -0.4, 0.9, 0.2, -0.6];

#[test]
fn each_arm_gets_the_largest_task_it_controls() {
    let cases: [(Model, &[f64], Task); 3] = [
        (five_axis(), &Q5, Task::POSITION_AND_AXIS),
        (
            so101_like(),
            &[0.2, -0.5, 0.8, 0.4, 0.1],
            Task::POSITION_AND_SPIN,
        ),
        (scara(), &[0.4, 1.1, 0.05, 0.3], Task::POSITION_AND_SPIN),
    ];
    for (model, q, want) in cases {
        let mut data = Data::new(&model);
        assert_eq!(largest_task(&model, &mut data, q).unwrap(), want);
    }
    assert_eq!(Task::for_dof(6), Task::POSE);
    assert_eq!(Task::for_dof(5), Task::POSITION_AND_AXIS);
    assert_eq!(Task::for_dof(4), Task::POSITION);
    assert_eq!(
        [
            Task::POSE,
            Task::POSITION_AND_AXIS,
            Task::POSITION_AND_SPIN,
            Task::POSITION
        ]
        .map(|t| t.rank()),
        [6, 5, 4, 3]
    );
}

#[test]
fn five_axes_reach_position_and_tool_axis_and_report_the_spin() {
    let model = five_axis();
    let mut data = Data::new(&model);
    let reached = vjm::forward(&model, &mut data, &Q5).unwrap();
    // The target asks for a spin of 0.3 rad about the tool axis more than the arm can give.
    let spin = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.3);
    let target = Isometry3::from_parts(reached.translation, reached.rotation * spin);
    let seed = [0.35, -0.45, 0.95, 0.1, -0.5];
    let options = PoseIkOptions {
        task: Task::POSITION_AND_AXIS,
        ..PoseIkOptions::default()
    };
    let sol = pose_ik(
        &model,
        &mut data,
        &target,
        &seed,
        &Vector6::zeros(),
        Load::Rigid,
        &options,
    )
    .unwrap();
    let got = vjm::forward(&model, &mut data, &sol.q[..5]).unwrap();
    let axis = |p: &Isometry3<f64>| p.rotation * Vector3::z();
    assert!((got.translation.vector - target.translation.vector).norm() <= 1e-8);
    assert!(axis(&got).angle(&axis(&target)) <= 1e-8, "{sol:?}");
    assert!(sol.position_error <= 1e-8 && sol.orientation_error <= 1e-8);
    // The spin it could not give is what is left, all of it about the tool axis.
    assert!(
        (sol.free_rotation - 0.3).abs() < 1e-7,
        "{}",
        sol.free_rotation
    );
    assert!((got.rotation.angle_to(&target.rotation) - sol.free_rotation).abs() < 1e-9);
    // The full pose cannot be asked of five joints.
    let full = pose_ik(
        &model,
        &mut data,
        &target,
        &seed,
        &Vector6::zeros(),
        Load::Rigid,
        &PoseIkOptions::default(),
    );
    assert!(
        matches!(
            full,
            Err(TickError::Singular { .. } | TickError::NotConverged { .. })
        ),
        "{full:?}"
    );
}

#[test]
fn the_corrector_lands_the_loaded_five_axis_tool_on_position_and_axis() {
    let model = five_axis();
    let payload = Payload {
        mass: 20.0,
        com: Vector3::new(0.0, 0.0, 0.08),
        inertia: Matrix3::from_diagonal_element(0.05),
    };
    let corrector = serial::Model::new(model.clone(), payload).unwrap();
    assert_eq!(corrector.ik_options().task, Task::POSITION_AND_AXIS);
    // Six rows are refused on five joints, naming the count.
    let pose = PoseIkOptions::default();
    assert!(matches!(
        corrector.clone().with_ik_options(pose),
        Err(deflect_core::BuildError::DofMismatch {
            expected: 6,
            got: 5,
            ..
        })
    ));
    let mut data = serial::Data::new(&corrector);
    data.set_seed(&Q5);
    let mut d = Data::new(&model);
    let start = vjm::forward(&model, &mut d, &Q5).unwrap();
    let end = Isometry3::from_parts(
        Translation3::from(start.translation.vector + Vector3::new(-0.12, 0.1, 0.05)),
        start.rotation,
    );
    let limits = PoseLimits {
        linear: Limits::new(2.0, 30.0, 600.0).unwrap(),
        angular: Limits::new(1.5, 8.0, 100.0).unwrap(),
    };
    let traj = PoseTrajectory::line(&start, &end, &limits).unwrap();
    let rate = 1000.0;
    let n = traj.tick_count(rate).unwrap();
    let (mut worst_defl, mut worst_free) = (0.0f64, 0.0f64);
    for k in 0..n {
        let s = traj.sample(traj.tick_time(rate, k, n)).unwrap();
        let tick = serial::step(&corrector, &mut data, &s, None)
            .unwrap_or_else(|e| panic!("tick {k} of {n}: {e:?}"));
        // Independent of the IK: deflect the command under the tick's wrench.
        let defl =
            vjm::deflection(&model, &mut d, &tick.joints[..5], &tick.load, Load::Exact).unwrap();
        let loaded = d.tcp_deflected;
        let ep = (loaded.translation.vector - s.pose.translation.vector).norm();
        let axis_err = (loaded.rotation * Vector3::z()).angle(&(s.pose.rotation * Vector3::z()));
        assert!(
            ep <= 1e-8 && axis_err <= 1e-8,
            "tick {k}: {ep:e} m {axis_err:e} rad"
        );
        // The spin left is the loaded pose's whole orientation error.
        let total = loaded.rotation.angle_to(&s.pose.rotation);
        assert!((tick.diagnostics.free_rotation - total).abs() < 1e-9);
        worst_defl = worst_defl.max(defl.fixed_rows::<3>(0).norm());
        worst_free = worst_free.max(total);
    }
    // 20 kg at 3 g bends this arm by tens of micrometres, all of it corrected in position and
    // tool axis. The desired orientation is held along the line, but five joints cannot hold
    // the spin while the pan turns: a tenth of a radian or more of it is reported, not refused.
    assert!(worst_defl > 1e-5, "{worst_defl}");
    assert!(worst_free > 0.05, "{worst_free}");
}

#[test]
fn a_start_on_a_limit_is_inside_by_the_documented_tolerance() {
    // The Unitree Z1's elbow: range [0, 2.967] and the start pose on its lower end; the IK's
    // rounding puts the first command 1.59e-9 rad below it.
    let limits = [(0.0, 2.967)];
    assert!(check_limits(&[-1.59e-9], &limits, JOINT_LIMIT_TOLERANCE).is_ok());
    assert!(
        check_limits(
            &[-2.0 * JOINT_LIMIT_TOLERANCE],
            &limits,
            JOINT_LIMIT_TOLERANCE
        )
        .is_err()
    );
    // The corrector holding a 4-axis SCARA at a pose with the quill at the bottom of its
    // [0, 0.2] m stroke: the first tick at rest stays within the tolerance and is accepted.
    let model = scara();
    let q0 = [0.4, 1.1, 0.0, 0.3];
    let corrector = serial::Model::new(model.clone(), Payload::point(2.0, Vector3::zeros()))
        .unwrap()
        .with_joint_limits(&[(-2.5, 2.5), (-2.5, 2.5), (0.0, 0.2), (-3.0, 3.0)])
        .unwrap();
    let corrector = corrector
        .clone()
        .with_ik_options(PoseIkOptions {
            task: Task::POSITION_AND_SPIN,
            ..*corrector.ik_options()
        })
        .unwrap();
    assert_eq!(corrector.limit_tolerance(), JOINT_LIMIT_TOLERANCE);
    let mut data = serial::Data::new(&corrector);
    data.set_seed(&q0);
    let start = vjm::forward(&model, &mut Data::new(&model), &q0).unwrap();
    let s = deflect_core::motion::PoseState::at_rest(0.0, start);
    let tick = serial::step(&corrector, &mut data, &s, None).unwrap();
    assert!(
        tick.joints[2].abs() <= JOINT_LIMIT_TOLERANCE,
        "{:?}",
        tick.joints
    );
    // Compared exactly, a command a rounding below the stroke would be refused; a tolerance
    // must be finite and non-negative.
    assert!(corrector.clone().with_limit_tolerance(-1.0).is_err());
    assert!(corrector.clone().with_limit_tolerance(f64::NAN).is_err());
}
