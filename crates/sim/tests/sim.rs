//! Short scenarios (seconds in debug builds): static compliance against J K^-1 J^T, the
//! correction reducing the path deviation, the serial arm, determinism.

use deflect_sim::scenes::parallel::params::{Constraint, Head, RobotParams, linear_compliance};
use deflect_sim::scenes::parallel::run::{
    self, Motion, RunOptions, StaticOptions, grid_node, linear_map, static_test_node,
};
use nalgebra::Vector2;

#[path = "common/serial_arm.rs"]
mod serial_arm;
use serial_arm::SerialArmSim;

#[test]
fn static_compliance_matches_j_kinv_jt() {
    let opts = StaticOptions::default();
    for (constraint, nodes) in [
        (Constraint::Oc, vec![grid_node(2, 3)]),
        (
            Constraint::Nc,
            vec![grid_node(1, 1), grid_node(3, 5), grid_node(2, 2)],
        ),
    ] {
        let params = RobotParams::new(constraint, Head::Upper);
        for node in nodes {
            for axis in 0..2 {
                // 10 N: the small-load limit the linearized model describes.
                let r = static_test_node(&params, &node, axis, &[10.0], &opts).unwrap();
                let mut f = Vector2::zeros();
                f[axis] = 10.0;
                let lin = linear_compliance(&params, &node).unwrap() * f;
                let d = Vector2::new(r[0].d[0], r[0].d[1]);
                let rel = (d - lin).norm() / lin.norm();
                assert!(
                    rel < 1e-3,
                    "{constraint:?} {node:?} axis {axis}: {d:?} vs {lin:?} ({rel:.2e})"
                );
            }
        }
    }
}

#[test]
fn correction_reduces_path_deviation_at_5g() {
    for (constraint, head) in [(Constraint::Nc, Head::Lower), (Constraint::Oc, Head::Upper)] {
        let params = RobotParams::new(constraint, head);
        let map = linear_map(&params).unwrap();
        let opts = RunOptions {
            tail: 0.0,
            ..Default::default()
        };
        let plain = run::run(&params, Motion::YLine, 5, None, &opts).unwrap();
        let corr = run::run(&params, Motion::YLine, 5, Some(&map), &opts).unwrap();
        let (a, b) = (&plain.metrics, &corr.metrics);
        assert!(a.max_dev_mm > 0.05, "{a:?}");
        assert!(b.max_dev_mm < 0.5 * a.max_dev_mm, "{a:?} -> {b:?}");
        assert!(b.area_mm2 < 0.5 * a.area_mm2, "{a:?} -> {b:?}");
        assert!(b.max_track_mm < 0.6 * a.max_track_mm, "{a:?} -> {b:?}");
    }
}

#[test]
fn serial_arm_static_compliance_matches_j_kinv_jt() {
    let q = [0.3, 0.9];
    let mut arm = SerialArmSim::new(&[0.4, 0.3], &[3.0, 2.0], &[2.0e4, 1.0e4], &q).unwrap();
    let f = Vector2::new(2.0, -1.0); // small load: the linear limit
    let p0 = arm.tip();
    for _ in 0..2000 {
        arm.step(&q, &f);
    }
    let d = arm.tip() - p0;
    let lin = arm.linear_compliance() * f;
    let rel = (d - lin).norm() / lin.norm();
    assert!(rel < 1e-3, "{d:?} vs {lin:?} ({rel:.2e})");
}

#[test]
fn runs_are_deterministic() {
    let params = RobotParams::new(Constraint::Nc, Head::Upper);
    let opts = RunOptions {
        tail: 0.0,
        ..Default::default()
    };
    let a = run::run(&params, Motion::XLine, 5, None, &opts).unwrap();
    let b = run::run(&params, Motion::XLine, 5, None, &opts).unwrap();
    assert_eq!(a.samples, b.samples);
    assert_eq!(a.metrics, b.metrics);
}
