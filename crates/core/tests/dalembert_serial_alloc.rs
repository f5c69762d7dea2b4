//! The serial-arm corrector's ticks allocate nothing: pose sampling, inertial wrench, exact
//! and linearized loaded-pose IK over 3000 ticks (three passes) under a counting global allocator (one test
//! function only).

use deflect_core::dalembert::serial::{self, Payload};
use deflect_core::motion::{Limits, PoseLimits, PoseTrajectory};
use deflect_core::vjm::Deflection;
use deflect_core::vjm::{self, Data, Vector6};
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

mod common;
mod fixtures;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

const Q0: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];

#[test]
fn serial_corrector_ticks_do_not_allocate() {
    let robot = fixtures::kr300();
    let start = vjm::forward(&robot.model, &mut Data::new(&robot.model), &Q0).unwrap();
    let end = Isometry3::from_parts(
        Translation3::from(start.translation.vector + Vector3::new(0.1, 0.3, -0.1)),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, 0.3)) * start.rotation,
    );
    let limits = PoseLimits {
        linear: Limits::new(2.0, 9.81, 200.0).unwrap(),
        angular: Limits::new(1.5, 8.0, 100.0).unwrap(),
    };
    let motion = PoseTrajectory::line(&start, &end, &limits).unwrap();
    let payload = Payload {
        mass: 150.0,
        com: Vector3::new(0.0, 0.0, 0.25),
        inertia: Matrix3::from_diagonal(&Vector3::new(4.0, 4.0, 2.5)),
    };
    let exact = serial::Model::new(robot.model.clone(), payload)
        .unwrap()
        .with_joint_limits(&robot.joint_limits)
        .unwrap();
    let linear = exact.clone().with_deflection(Deflection::Linearized);
    let (mut de, mut dl) = (serial::Data::new(&exact), serial::Data::new(&linear));
    de.set_seed(&Q0);
    dl.set_seed(&Q0);
    let process = Vector6::new(0.0, 0.0, -300.0, 0.0, 0.0, 0.0);
    let n = motion.tick_count(2000.0).unwrap();

    common::watch_this_thread();
    common::assert_counter_works();
    let before = common::allocations();
    let (mut ticks, mut sink) = (0usize, 0.0);
    while ticks < 3_000 {
        for k in 0..n {
            // Forth and back, so the warm start follows a continuous path.
            let k = if (ticks / n).is_multiple_of(2) {
                k
            } else {
                n - 1 - k
            };
            let s = motion.sample(motion.tick_time(2000.0, k, n)).unwrap();
            let a = serial::step(&exact, &mut de, &s, None).unwrap();
            let b = serial::step(&linear, &mut dl, &s, Some(&process)).unwrap();
            sink += a.joints[1] + b.joints[1];
            ticks += 1;
        }
    }
    // Failures allocate nothing either.
    let mut bad = motion.sample(0.0).unwrap();
    bad.acceleration.x = f64::NAN;
    assert!(serial::step(&exact, &mut de, &bad, None).is_err());
    assert_eq!(common::allocations() - before, 0, "serial ticks allocated");
    assert!(sink.is_finite() && ticks >= 3_000);
}
