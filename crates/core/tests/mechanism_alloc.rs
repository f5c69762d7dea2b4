//! The mechanisms' per-tick paths (inverse, forward, Jacobian) allocate nothing: a counting
//! global allocator watches the paper's parallel robot and a serial arm (workspace made
//! before counting). One test function only.

use deflect_core::mechanism::{IkOptions, Mechanism, ParallelRobot2, SerialArm};
use deflect_core::{ModelBuilder, TickError};
use nalgebra::{Isometry3, SVector, Vector2, Vector3};

mod common;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

#[test]
fn mechanism_calls_do_not_allocate() {
    common::watch_this_thread();
    common::assert_counter_works();
    let robot = ParallelRobot2::paper();
    // A 6R arm: base yaw, shoulder and elbow pitch, roll-pitch-roll wrist, 0.1 m tool.
    let model = ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .fixed(Isometry3::translation(0.0, 0.0, 0.4))
        .unwrap()
        .revolute(Vector3::y())
        .unwrap()
        .fixed(Isometry3::translation(0.5, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::y())
        .unwrap()
        .fixed(Isometry3::translation(0.3, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::x())
        .unwrap()
        .fixed(Isometry3::translation(0.1, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::y())
        .unwrap()
        .revolute(Vector3::x())
        .unwrap()
        .fixed(Isometry3::translation(0.1, 0.0, 0.05))
        .unwrap()
        .build()
        .unwrap();
    let arm = SerialArm::<6>::new(model, IkOptions::default()).unwrap();
    let mut data = arm.new_data();
    let q0 = SVector::<f64, 6>::from_column_slice(&[0.2, -0.3, 0.9, 0.4, -0.6, 0.3]);
    let mut seed = q0;
    let mut sink = 0.0;
    let mut worst_parallel: f64 = 0.0;
    let mut worst_serial: f64 = 0.0;
    let mut serial_ticks = 0;

    let before = common::allocations();
    for k in 0..10_000 {
        let s = k as f64 * 1e-4;
        // Parallel robot: a point sweeping the paper's grid, IK -> FK round trip.
        let p = Vector2::new(0.2 + 0.05 * s.sin(), 0.08 * (3.0 * s).cos());
        let q = robot.inverse(&mut (), &p, &Vector2::zeros()).unwrap();
        let back = robot.forward(&mut (), &q).unwrap();
        worst_parallel = worst_parallel.max((back - p).norm());
        sink += robot.jacobian(&mut (), &q).unwrap()[(0, 0)];
        sink += robot.singularity_distance(&mut (), &q).unwrap();
        // Serial arm every 5th tick: FK of a moving joint target, IK seeded by the last
        // solution, FK of the solution.
        if k % 5 == 0 {
            let mut target = q0;
            target[0] += 0.3 * s.sin();
            target[2] -= 0.2 * s;
            let x = arm.forward(&mut data, &target).unwrap();
            seed = arm.inverse(&mut data, &x, &seed).unwrap();
            worst_serial = worst_serial.max((arm.forward(&mut data, &seed).unwrap() - x).norm());
            sink += arm.jacobian(&mut data, &seed).unwrap()[(2, 1)];
            serial_ticks += 1;
        }
        // Error paths allocate nothing either.
        if k % 100 == 0 {
            let bad = robot.inverse(&mut (), &Vector2::new(0.31, 0.0), &Vector2::zeros());
            assert!(matches!(bad, Err(TickError::OutOfWorkspace { .. })));
            let bad = arm.inverse(&mut data, &Vector3::new(f64::NAN, 0.0, 0.0), &seed);
            assert!(matches!(bad, Err(TickError::NonFinite { what: "x", .. })));
        }
    }
    let after = common::allocations();
    assert_eq!(after - before, 0, "allocations on the mechanism paths");

    // Real answers: both IKs round-trip.
    assert!(sink.is_finite());
    assert_eq!(serial_ticks, 2000);
    assert!(
        worst_parallel < 1e-15,
        "parallel round trip {worst_parallel} m"
    );
    assert!(worst_serial <= 1e-9, "serial round trip {worst_serial} m");
    // The serial arm moved: its last solution is far from where it started.
    assert!((seed - q0).norm() > 0.1);
}
