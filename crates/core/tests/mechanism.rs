//! Rigid kinematics: the paper's 2-DoF parallel robot (closed form) and a serial VJM model
//! (damped least squares) behind the `Mechanism` trait.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use approx::assert_relative_eq;
use deflect_core::mechanism::{
    DEFAULT_MIN_SIGMA, IkOptions, Mechanism, PAPER_LINK, ParallelRobot2, SerialArm,
};
use deflect_core::motion::{self, Trajectory};
use deflect_core::vjm::Model;
use deflect_core::{BuildError, ModelBuilder, TickError};
use nalgebra::{Isometry3, SMatrix, SVector, Vector2, Vector3};
use proptest::prelude::*;

/// The static-test grid of the paper (Figure 5, data README), task frame p = C - O.
fn grid() -> Vec<Vector2<f64>> {
    let mut g = Vec::new();
    for i in 1..=3 {
        for j in 1..=5 {
            g.push(Vector2::new(
                0.122_132 + 0.05 * f64::from(i),
                -0.1125 + 0.0375 * f64::from(j),
            ));
        }
    }
    g
}

/// Central finite differences of any mechanism's FK (in a workspace of its own).
fn fd_jacobian<M: Mechanism<T, J>, const T: usize, const J: usize>(
    m: &M,
    q: &SVector<f64, J>,
) -> SMatrix<f64, T, J> {
    let mut data = m.new_data();
    let h = 1e-6;
    let mut jac = SMatrix::<f64, T, J>::zeros();
    for c in 0..J {
        let mut qp = *q;
        let mut qm = *q;
        qp[c] += h;
        qm[c] -= h;
        let col =
            (m.forward(&mut data, &qp).unwrap() - m.forward(&mut data, &qm).unwrap()) / (2.0 * h);
        jac.set_column(c, &col);
    }
    jac
}

#[test]
fn grid_nodes_round_trip() {
    let r = ParallelRobot2::paper();
    for p in grid() {
        let q = r.ik(&p).unwrap();
        assert_relative_eq!(r.fk(&q).unwrap(), p, epsilon = 1e-15);
        assert_relative_eq!(r.ik(&r.fk(&q).unwrap()).unwrap(), q, epsilon = 1e-12);
        // Through the trait, too.
        assert_eq!(r.inverse(&mut (), &p, &Vector2::zeros()).unwrap(), q);
        // Working mode: elbow A on the +y side of the line O-C.
        let d = q.x - q.y;
        assert!(d > 0.0 && d < core::f64::consts::PI);
        let sd = r.singularity_distance(&mut (), &q).unwrap();
        assert!(sd >= 0.07, "sigma_min {sd} at {p}");
        assert_relative_eq!(
            r.jacobian(&mut (), &q).unwrap(),
            fd_jacobian(&r, &q),
            epsilon = 1e-9
        );
    }
}

#[test]
fn geometry_of_the_linkage() {
    let r = ParallelRobot2::paper();
    let p = Vector2::new(0.222_132, 0.0375);
    let q = r.ik(&p).unwrap();
    let [a0, a, d, b0, b, e, c] = r.points(&q);
    let l = PAPER_LINK;
    assert_relative_eq!((a - a0).norm(), l, epsilon = 1e-15);
    assert_relative_eq!((d - a).norm(), l, epsilon = 1e-15);
    assert_relative_eq!((b - b0).norm(), l, epsilon = 1e-15);
    assert_relative_eq!((e - b).norm(), l, epsilon = 1e-15);
    assert_relative_eq!((d - c).norm(), 0.09, epsilon = 1e-15);
    assert_relative_eq!((e - c).norm(), 0.09, epsilon = 1e-15);
    assert_relative_eq!(c, p, epsilon = 1e-15);
    assert_relative_eq!(d - a0, e - b0, epsilon = 1e-15);
    // Elbows out: A above the O-C line, B below.
    let cross = |u: Vector2<f64>, v: Vector2<f64>| u.x * v.y - u.y * v.x;
    assert!(cross(p, a - a0) > 0.0 && cross(p, b - b0) < 0.0);
    // p = 2 L cos(Delta/2) [cos sigma, sin sigma].
    let (sig, del) = ((q.x + q.y) / 2.0, q.x - q.y);
    assert_relative_eq!(
        p,
        Vector2::new(sig.cos(), sig.sin()) * 2.0 * l * (del / 2.0).cos(),
        epsilon = 1e-15
    );
    // Singular values sqrt(2) L cos(Delta/2), sqrt(2) L sin(Delta/2).
    let sv = r.jacobian(&mut (), &q).unwrap().singular_values();
    let expect = 2f64.sqrt() * l * (del / 2.0).cos().min((del / 2.0).sin());
    assert_relative_eq!(sv.min(), expect, epsilon = 1e-14);
    assert_relative_eq!(
        r.singularity_distance(&mut (), &q).unwrap(),
        expect,
        epsilon = 1e-14
    );
}

#[test]
fn paper_motions_are_inside_the_workspace() {
    let r = ParallelRobot2::paper();
    let lim = motion::paper_limits(5).unwrap();
    let x0 = 0.122_132;
    let mut paths: Vec<Vec<Vector2<f64>>> = vec![
        // 100 mm along x at y = 0.
        vec![Vector2::new(x0 + 0.05, 0.0), Vector2::new(x0 + 0.15, 0.0)],
        // Triangle inside the grid.
        vec![
            Vector2::new(x0 + 0.05, -0.075),
            Vector2::new(x0 + 0.15, 0.0),
            Vector2::new(x0 + 0.05, 0.075),
            Vector2::new(x0 + 0.05, -0.075),
        ],
    ];
    // 150 mm along y, on every grid column.
    for i in 1..=3 {
        let x = x0 + 0.05 * f64::from(i);
        paths.push(vec![Vector2::new(x, -0.075), Vector2::new(x, 0.075)]);
    }
    for path in paths {
        let tr = Trajectory::polyline(&path, &lim).unwrap();
        let mut q_prev = r.ik(&path[0]).unwrap();
        for s in tr.ticks(2000.0).unwrap() {
            let q = r.ik(&s.position).unwrap();
            assert_relative_eq!(r.fk(&q).unwrap(), s.position, epsilon = 1e-15);
            // Joint motion is continuous at 2 kHz (no branch flips).
            assert!((q - q_prev).norm() < 0.01);
            q_prev = q;
        }
    }
}

#[test]
fn out_of_workspace_and_singular_points_are_errors() {
    let r = ParallelRobot2::paper();
    assert_eq!(
        r.ik(&Vector2::new(0.31, 0.0)),
        Err(TickError::OutOfWorkspace {
            distance: 0.31,
            reach: 0.3
        })
    );
    assert!(matches!(
        r.ik(&Vector2::new(0.0, -0.4)),
        Err(TickError::OutOfWorkspace { .. })
    ));
    // Full stretch and the base centre.
    for p in [
        Vector2::new(0.3, 0.0),
        Vector2::new(0.2995, 0.0),
        Vector2::new(0.0, 0.0),
        Vector2::new(0.001, 0.0),
    ] {
        match r.ik(&p) {
            Err(TickError::Singular { sigma_min, .. }) => assert!(sigma_min < DEFAULT_MIN_SIGMA),
            other => panic!("{p}: {other:?}"),
        }
    }
    assert_eq!(
        r.ik(&Vector2::new(0.0, 0.0)),
        Err(TickError::Singular {
            what: "task Jacobian",
            sigma_min: 0.0
        })
    );
    // At a stretched pose the Jacobian is rank deficient.
    let stretched = Vector2::new(0.4, 0.4);
    assert!(r.singularity_distance(&mut (), &stretched).unwrap() < 1e-12);
    assert!(matches!(
        r.ik(&Vector2::new(f64::NAN, 0.0)),
        Err(TickError::NonFinite {
            what: "x",
            index: 0
        })
    ));
    assert!(matches!(
        r.fk(&Vector2::new(0.0, f64::INFINITY)),
        Err(TickError::NonFinite {
            what: "q",
            index: 1
        })
    ));
    assert!(matches!(
        ParallelRobot2::new(0.15, 0.09, 0.0),
        Err(BuildError::InvalidParameter {
            what: "min_sigma",
            ..
        })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn parallel_round_trips(sigma in -1.5f64..1.5, delta in 0.2f64..2.9) {
        let r = ParallelRobot2::paper();
        let q = Vector2::new(sigma + delta / 2.0, sigma - delta / 2.0);
        let p = r.fk(&q).unwrap();
        let qi = r.ik(&p).unwrap();
        prop_assert!((qi - q).norm() < 1e-10, "{q} -> {p} -> {qi}");
        prop_assert!((r.fk(&qi).unwrap() - p).norm() < 1e-15);
        let jfd = fd_jacobian(&r, &q);
        prop_assert!((r.jacobian(&mut (), &q).unwrap() - jfd).norm() < 1e-9);
    }

    #[test]
    fn parallel_random_points(x in 0.0f64..0.3, y in -0.3f64..0.3) {
        let r = ParallelRobot2::paper();
        let p = Vector2::new(x, y);
        match r.ik(&p) {
            Ok(q) => {
                prop_assert!((r.fk(&q).unwrap() - p).norm() < 1e-15);
                prop_assert!(r.singularity_distance(&mut (), &q).unwrap() >= DEFAULT_MIN_SIGMA * (1.0 - 1e-12));
            }
            Err(TickError::OutOfWorkspace { reach, .. }) => prop_assert!(p.norm() > reach),
            Err(TickError::Singular { sigma_min, .. }) => prop_assert!(sigma_min < DEFAULT_MIN_SIGMA),
            Err(e) => prop_assert!(false, "{e}"),
        }
    }
}

/// A 3R arm: base yaw, shoulder pitch, elbow pitch (0.4 m column, 0.5 m + 0.4 m links).
fn arm3() -> Model {
    ModelBuilder::new()
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
        .fixed(Isometry3::translation(0.4, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap()
}

/// A 6R arm: the 3R arm plus a roll-pitch-roll wrist and a 0.1 m tool.
fn arm6() -> Model {
    ModelBuilder::new()
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
        .unwrap()
}

#[test]
fn serial_3r_ik_recovers_joints() {
    let model = arm3();
    let arm = SerialArm::<3>::new(model.clone(), IkOptions::default()).unwrap();
    let mut data = arm.new_data();
    let q = SVector::<f64, 3>::new(0.3, -0.4, 0.8);
    let x = arm.forward(&mut data, &q).unwrap();
    let seed = q + SVector::<f64, 3>::new(0.1, -0.15, 0.2);
    let qi = arm.inverse(&mut data, &x, &seed).unwrap();
    assert_relative_eq!(qi, q, epsilon = 1e-8);
    assert!((arm.forward(&mut data, &qi).unwrap() - x).norm() <= 1e-9);
    assert_relative_eq!(
        arm.jacobian(&mut data, &q).unwrap(),
        fd_jacobian(&arm, &q),
        epsilon = 1e-8
    );
    assert!(arm.singularity_distance(&mut data, &q).unwrap() > 0.01);
    // Tick-by-tick along a line: seeded with the previous solution, it tracks.
    let tr = Trajectory::line(
        x,
        x + Vector3::new(-0.1, 0.15, 0.05),
        &motion::paper_limits(1).unwrap(),
    )
    .unwrap();
    let mut qk = q;
    for s in tr.ticks(2000.0).unwrap() {
        qk = arm.inverse(&mut data, &s.position, &qk).unwrap();
        assert!((arm.forward(&mut data, &qk).unwrap() - s.position).norm() <= 1e-9);
    }
}

#[test]
fn serial_6r_ik_converges_and_reports_failures() {
    let model = arm6();
    let arm = SerialArm::<6>::new(model.clone(), IkOptions::default()).unwrap();
    let mut data = arm.new_data();
    let q = SVector::<f64, 6>::from_column_slice(&[0.2, -0.3, 0.9, 0.4, -0.6, 0.3]);
    let x = arm.forward(&mut data, &q).unwrap();
    let seed = q.add_scalar(0.1);
    let qi = arm.inverse(&mut data, &x, &seed).unwrap();
    assert!((arm.forward(&mut data, &qi).unwrap() - x).norm() <= 1e-9);
    assert_relative_eq!(
        arm.jacobian(&mut data, &q).unwrap(),
        fd_jacobian(&arm, &q),
        epsilon = 1e-8
    );
    // Far out of reach: the arm stretches, then fails with a typed error.
    let far = Vector3::new(3.0, 0.0, 0.4);
    match arm.inverse(&mut data, &far, &q) {
        Err(TickError::NotConverged {
            iterations,
            residual,
        }) => {
            assert_eq!(iterations, IkOptions::default().max_iterations);
            assert!(residual > 1.0);
        }
        Err(TickError::Singular { sigma_min, .. }) => assert!(sigma_min < 1e-4),
        other => panic!("{other:?}"),
    }
    // Too few iterations: NotConverged.
    let short = SerialArm::<6>::new(
        model.clone(),
        IkOptions {
            max_iterations: 1,
            ..IkOptions::default()
        },
    )
    .unwrap();
    assert!(matches!(
        short.inverse(&mut data, &(x + Vector3::new(0.05, 0.05, 0.0)), &q),
        Err(TickError::NotConverged { iterations: 1, .. })
    ));
    assert!(matches!(
        arm.inverse(&mut data, &Vector3::new(f64::NAN, 0.0, 0.0), &q),
        Err(TickError::NonFinite { what: "x", .. })
    ));
    assert_eq!(
        SerialArm::<3>::new(model, IkOptions::default()).err(),
        Some(BuildError::DofMismatch {
            what: "SerialArm<J>",
            expected: 6,
            got: 3
        })
    );
}
