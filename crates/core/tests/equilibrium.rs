//! Static equilibrium (moments in the deflected pose) against hand-derived solutions, its
//! relation to the paper's model, and its errors.

use deflect_core::vjm::{self, Data, EquilibriumOptions, Vector6};
use deflect_core::{ModelBuilder, TickError};
use nalgebra::{Isometry3, Vector3};

mod fixtures;

/// A 1 m link about z with one spring at the joint, soft (k [N m/rad]) about z.
fn one_link(k: f64) -> vjm::Model {
    ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .spring([f64::INFINITY, f64::INFINITY, k])
        .unwrap()
        .fixed(Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap()
}

/// Root of `k theta = f l cos(theta)` on [0, f l / k] by bisection.
fn hand_angle(k: f64, f: f64, l: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, f * l / k);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if k * mid - f * l * mid.cos() > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn one_link_under_a_transverse_force_matches_the_hand_solution() {
    // The tip force stays along +y while the link turns: the moment arm shrinks to
    // l cos(theta), so k theta = F l cos(theta) (the paper takes F l, the undeformed arm).
    let (k, f) = (1.0e4, 1000.0);
    let model = one_link(k);
    let mut data = Data::new(&model);
    let w = Vector6::new(0.0, f, 0.0, 0.0, 0.0, 0.0);
    let eq = vjm::equilibrium(
        &model,
        &mut data,
        &[0.0],
        &w,
        &EquilibriumOptions::default(),
    )
    .unwrap();
    let theta = hand_angle(k, f, 1.0);
    assert!((theta - 0.099_505).abs() < 1e-5, "{theta}");
    let expected = [theta.cos() - 1.0, theta.sin(), 0.0, 0.0, 0.0, theta];
    for (i, e) in expected.iter().enumerate() {
        assert!(
            (eq.deflection[i] - e).abs() < 1e-13,
            "{i}: {} vs {e}",
            eq.deflection[i]
        );
    }
    assert!(eq.residual < 1e-14, "{}", eq.residual);
    assert!((1..=6).contains(&eq.iterations), "{}", eq.iterations);
    assert!((data.spring_angles[0].z - theta).abs() < 1e-14);
    // The paper's model: theta = F l / k = 0.1 rad exactly.
    let paper = vjm::deflection(&model, &mut data, &[0.0], &w, vjm::Load::Exact).unwrap();
    assert!((paper[5] - 0.1).abs() < 1e-15);
    assert!((paper[1] - 0.1f64.sin()).abs() < 1e-15);
}

#[test]
fn a_pure_moment_gives_the_papers_angle() {
    // A moment about the spring's own (fixed) axis has no lever arm to change.
    let model = one_link(2.0e4);
    let mut data = Data::new(&model);
    let w = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 50.0);
    let eq = vjm::equilibrium(
        &model,
        &mut data,
        &[0.3],
        &w,
        &EquilibriumOptions::default(),
    )
    .unwrap();
    let paper = vjm::deflection(&model, &mut data, &[0.3], &w, vjm::Load::Exact).unwrap();
    assert!((eq.deflection[5] - 50.0 / 2.0e4).abs() < 1e-15);
    assert!((eq.deflection - paper).amax() < 1e-15);
}

#[test]
fn zero_load_is_zero_deflection() {
    let model = one_link(1.0e4);
    let mut data = Data::new(&model);
    let eq = vjm::equilibrium(
        &model,
        &mut data,
        &[1.0],
        &Vector6::zeros(),
        &EquilibriumOptions::default(),
    )
    .unwrap();
    assert_eq!(eq.deflection, Vector6::zeros());
    assert_eq!(eq.iterations, 1);
}

fn six_axis() -> vjm::Model {
    fixtures::six_r(fixtures::Link::Spring([3.0e5, 2.0e5, 1.0e5]))
        .build()
        .unwrap()
}

#[test]
fn the_difference_from_the_paper_is_second_order_in_the_load() {
    let model = six_axis();
    let mut data = Data::new(&model);
    let q = [0.1, -0.4, 0.9, 0.2, 0.6, -0.3];
    let w = Vector6::new(300.0, -200.0, -500.0, 10.0, 0.0, -5.0);
    let gap = |s: f64, data: &mut Data| {
        let eq =
            vjm::equilibrium(&model, data, &q, &(w * s), &EquilibriumOptions::default()).unwrap();
        let paper = vjm::deflection(&model, data, &q, &(w * s), vjm::Load::Exact).unwrap();
        ((eq.deflection - paper).norm(), paper.norm())
    };
    let (g1, d1) = gap(0.25, &mut data);
    let (g2, _) = gap(0.5, &mut data);
    let (g4, _) = gap(1.0, &mut data);
    // Relative gap of the order of the deflection's angular size, and quadratic.
    assert!(g1 / d1 > 1e-4 && g1 / d1 < 1e-1, "{g1} {d1}");
    assert!((g2 / g1 - 4.0).abs() < 0.1, "{}", g2 / g1);
    assert!((g4 / g2 - 4.0).abs() < 0.1, "{}", g4 / g2);
}

#[test]
fn bad_inputs_are_typed_errors() {
    let model = six_axis();
    let mut data = Data::new(&model);
    let q = [0.0; 6];
    let w = Vector6::new(0.0, 0.0, -100.0, 0.0, 0.0, 0.0);
    let opts = |max_iterations, tolerance| EquilibriumOptions {
        max_iterations,
        tolerance,
    };
    for o in [opts(0, 1e-12), opts(65, 1e-12), opts(5, 0.0), opts(5, -1.0)] {
        assert!(matches!(
            vjm::equilibrium(&model, &mut data, &q, &w, &o),
            Err(TickError::InvalidArgument { .. })
        ));
    }
    assert!(matches!(
        vjm::equilibrium(&model, &mut data, &q, &w, &opts(5, f64::NAN)),
        Err(TickError::InvalidArgument { .. })
    ));
    let mut bad = w;
    bad[2] = f64::NAN;
    assert!(matches!(
        vjm::equilibrium(&model, &mut data, &q, &bad, &EquilibriumOptions::default()),
        Err(TickError::NonFinite { .. })
    ));
    assert!(matches!(
        vjm::equilibrium(
            &model,
            &mut data,
            &q[..5],
            &w,
            &EquilibriumOptions::default()
        ),
        Err(TickError::WrongLength { .. })
    ));
    // Past the small-angle budget: refused, not iterated.
    assert!(matches!(
        vjm::equilibrium(
            &model,
            &mut data,
            &q,
            &(w * 1e6),
            &EquilibriumOptions::default()
        ),
        Err(TickError::InvalidArgument { .. })
    ));
    // One iteration is not enough for a loaded arm at 1e-15 rad.
    assert!(matches!(
        vjm::equilibrium(&model, &mut data, &q, &(w * 100.0), &opts(1, 1e-15)),
        Err(TickError::NotConverged { iterations: 1, .. })
    ));
}
