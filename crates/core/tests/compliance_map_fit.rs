//! Fitting a compliance map from static tests (Paksoy et al. 2025, sec. 3.1-3.2): the
//! per-node least squares recover the published tables, their standard errors cover the
//! noise, bad measurements are refused, and cross-validation compares the interpolations.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use deflect_core::compliance_map::{
    FitOptions, HoldOutAxis, Interpolation, Measurement, fit, leave_one_node_out,
};
use deflect_core::io::map_csv;
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_core::{BuildError, LoadError};

mod fixtures;
use fixtures::maps::*;

#[test]
fn fit_recovers_table_ii_without_noise() {
    let table = paper(OC);
    let mut ms = synthetic(&table, 0.0, 1);
    ms.reverse(); // order must not matter
    let fitted = fit(&ms, &FitOptions::default()).unwrap();
    assert_eq!(fitted.x(), table.x());
    assert_eq!(fitted.y(), table.y());
    for (a, b) in fitted.slopes().iter().zip(table.slopes()) {
        assert!(
            close(*a, *b, 1e-12) || (a - b).abs() < 1e-12 * 2e-6,
            "slope {a} vs {b}"
        );
    }
    for (a, b) in fitted.offsets().iter().zip(table.offsets()) {
        assert!(
            close(*a, *b, 1e-12) || (a - b).abs() < 1e-12 * 2e-5,
            "offset {a} vs {b}"
        );
    }
    let stats = fitted.fit_stats().unwrap();
    assert_eq!(stats.len(), 15);
    for s in stats {
        assert_eq!(s.samples, vec![5, 5]);
        for l in &s.lines {
            assert!(l.rms < 1e-18, "rms {}", l.rms);
            assert!(l.r_squared > 1.0 - 1e-9 || l.slope == 0.0);
        }
        // cond([F 1]) for F = 49.05..245.25 N: eigenvalues of [[132324.6375, 735.75], [735.75, 5]]
        // (numpy.linalg.cond gives 381.53126).
        let (a, b, c) = (132_324.637_5_f64, 735.75_f64, 5.0_f64);
        let lmax = 0.5 * (a + c + ((a - c).powi(2) + 4.0 * b * b).sqrt());
        let lmin = (a * c - b * b) / lmax;
        let cond = (lmax / lmin).sqrt();
        assert!(
            close(s.condition[0], cond, 1e-9),
            "{} vs {cond}",
            s.condition[0]
        );
        assert!((cond - 381.531_258_8).abs() < 1e-6, "{cond}");
    }
}

#[test]
fn fit_with_noise_is_within_standard_errors() {
    let table = paper(NC);
    let sigma = 2e-6; // 2 um, the order of a portable measuring arm
    let fitted = fit(
        &synthetic(&table, sigma, 0x9E37_79B9_7F4A_7C15),
        &FitOptions::default(),
    )
    .unwrap();
    // Least-squares standard errors for F = 49.05 k, k = 1..5: Sxx = 10 * 49.05^2, mean 147.15.
    let sxx = 10.0 * 49.05_f64.powi(2);
    let se_slope = sigma / sxx.sqrt();
    let se_offset = sigma * (0.2 + 147.15_f64.powi(2) / sxx).sqrt();
    let mut worst = 0.0_f64;
    for (a, b) in fitted.slopes().iter().zip(table.slopes()) {
        worst = worst.max((a - b).abs() / se_slope);
    }
    for (a, b) in fitted.offsets().iter().zip(table.offsets()) {
        worst = worst.max((a - b).abs() / se_offset);
    }
    println!("worst coefficient error = {worst:.2} standard errors");
    assert!(worst < 5.0 && worst > 0.5, "{worst}");
    // Mean squared residual per line has expectation sigma^2 (k - 2) / k.
    let stats = fitted.fit_stats().unwrap();
    let ms: f64 = stats
        .iter()
        .flat_map(|s| s.lines.iter())
        .map(|l| l.rms * l.rms)
        .sum::<f64>()
        / 60.0;
    let expected = sigma * sigma * 3.0 / 5.0;
    assert!(
        ms > 0.6 * expected && ms < 1.4 * expected,
        "{ms} vs {expected}"
    );
}

fn base_measurements() -> Vec<Measurement> {
    synthetic(&paper(OC), 0.0, 3)
}

fn fit_err(ms: &[Measurement]) -> BuildError {
    fit(ms, &FitOptions::default()).unwrap_err()
}

#[test]
fn fit_rejections() {
    let base = base_measurements();
    // Only one force level on axis 1 at the first node.
    let (x0, y0) = (base[0].x, base[0].y);
    let few: Vec<_> = base
        .iter()
        .copied()
        .filter(|m| !(m.x == x0 && m.y == y0 && m.force_axis == 1 && m.force > 50.0))
        .collect();
    assert_eq!(
        fit_err(&few),
        BuildError::TooFewForceLevels {
            node_x: x0,
            node_y: y0,
            force_axis: 1,
            levels: 1
        }
    );
    // A node missing.
    let missing: Vec<_> = base
        .iter()
        .copied()
        .filter(|m| !(m.x == x0 && m.y == y0))
        .collect();
    assert_eq!(fit_err(&missing), BuildError::MissingNode { x: x0, y: y0 });
    // Duplicate (node, axis, force).
    let mut dup = base.clone();
    dup.push(base[7]);
    assert_eq!(
        fit_err(&dup),
        BuildError::DuplicateMeasurement {
            row: base.len(),
            previous_row: 7
        }
    );
    // Non-finite displacement at row 4, column d1.
    let mut nan = base.clone();
    nan[4].displacement[1] = f64::NAN;
    assert_eq!(
        fit_err(&nan),
        BuildError::NonFiniteMeasurement {
            row: 4,
            column: "d1"
        }
    );
    nan[2].force = f64::INFINITY;
    assert_eq!(
        fit_err(&nan),
        BuildError::NonFiniteMeasurement {
            row: 2,
            column: "force"
        }
    );
    // Force axis out of range.
    let mut axis = base.clone();
    axis[3].force_axis = 2;
    assert_eq!(
        fit_err(&axis),
        BuildError::ForceAxisOutOfRange {
            row: 3,
            force_axis: 2,
            n_force: 2
        }
    );
    // Scattered positions: no grid.
    let scattered: Vec<_> = (0..6)
        .flat_map(|k| {
            (0..2).flat_map(move |f| {
                (1..3).map(move |l| {
                    Measurement::new(0.01 * k as f64, 0.007 * k as f64, f, l as f64, &[0.0, 0.0])
                })
            })
        })
        .collect();
    assert_eq!(
        fit_err(&scattered),
        BuildError::NotRectilinear {
            nodes: 6,
            distinct_x: 6,
            distinct_y: 6
        }
    );
    // Coordinates chaining within the tolerance into a line wider than it.
    let mut chain = base.clone();
    chain[0].x += 0.9e-6;
    chain[1].x += 1.8e-6;
    assert!(matches!(
        fit_err(&chain),
        BuildError::AmbiguousCoordinate { axis: "x", .. }
    ));
    // A single grid line.
    let line: Vec<_> = base.iter().copied().filter(|m| m.x == x0).collect();
    assert_eq!(
        fit_err(&line),
        BuildError::TooFew {
            what: "x nodes",
            needed: 2,
            got: 1
        }
    );
    // Bad dimensions.
    assert_eq!(
        fit(
            &base,
            &FitOptions {
                n_force: 7,
                ..FitOptions::default()
            }
        )
        .unwrap_err(),
        BuildError::InvalidParameter {
            what: "n_force",
            value: 7.0,
            expected: "in 1..=6"
        }
    );
    // Errors print what and where.
    let msg = fit_err(&missing).to_string();
    assert!(msg.contains("0.172132") && msg.contains("-0.075"), "{msg}");
}

#[test]
fn static_test_csv_fit() {
    // The same synthetic tests written as a CSV in mm and kgf.
    let table = paper(OC);
    let ms = synthetic(&table, 0.0, 5);
    let mut text = String::from("x,y,force_axis,force,dx,dy\n");
    for m in &ms {
        text += &format!(
            "{},{},{},{},{},{}\n",
            m.x * 1e3,
            m.y * 1e3,
            ["x", "y"][m.force_axis],
            m.force / KGF,
            m.displacement[0] * 1e3,
            m.displacement[1] * 1e3
        );
    }
    let fitted = map_csv::fit_static_str(
        &text,
        ForceUnit::KilogramForce,
        LengthUnit::Millimetre,
        None,
        1e-6,
    )
    .unwrap();
    assert_eq!((fitted.n_force(), fitted.n_displacement()), (2, 2));
    for (a, b) in fitted.slopes().iter().zip(table.slopes()) {
        assert!((a - b).abs() < 1e-9 * 2e-6, "{a} vs {b}");
    }
    let bad = text.replacen(",x,", ",q,", 1);
    assert_eq!(
        map_csv::fit_static_str(&bad, ForceUnit::Newton, LengthUnit::Metre, None, 1e-6)
            .unwrap_err(),
        LoadError::BadNumber {
            row: 0,
            column: "force_axis"
        }
    );
}

#[test]
fn cross_validation_bilinear_vs_bicubic() {
    // Forces 49.05..245.25 N (5..25 kgf) along x, then along y.
    let mut forces = Vec::new();
    for axis in 0..2 {
        for k in 1..=5 {
            let mut f = [0.0, 0.0];
            f[axis] = 49.05 * k as f64;
            forces.extend_from_slice(&f);
        }
    }
    for (name, text) in [("OC", OC), ("NC", NC)] {
        let map = paper(text);
        let cy = leave_one_node_out(&map, &forces, HoldOutAxis::Y).unwrap();
        let cx = leave_one_node_out(&map, &forces, HoldOutAxis::X).unwrap();
        println!(
            "{name}: hold out along y ({} nodes): RMS bilinear {:.2} um, bicubic {:.2} um -> {:?}",
            cy.nodes.len(),
            cy.rms_bilinear * 1e6,
            cy.rms_bicubic * 1e6,
            cy.better()
        );
        for n in &cy.nodes {
            println!(
                "  node (i={}, j={}): bilinear {:.2} um, bicubic {:.2} um",
                n.i + 1,
                n.j + 1,
                n.rms_bilinear * 1e6,
                n.rms_bicubic * 1e6
            );
        }
        println!(
            "{name}: hold out along x ({} nodes): RMS bilinear {:.2} um, bicubic {:.2} um (2 x-nodes left: identical)",
            cx.nodes.len(),
            cx.rms_bilinear * 1e6,
            cx.rms_bicubic * 1e6
        );
        assert_eq!(cy.nodes.len(), 9);
        assert_eq!(cx.nodes.len(), 5);
        assert!(cy.rms_bilinear > 1e-6 && cy.rms_bilinear < 1e-3);
        assert!(cy.rms_bicubic > 1e-6 && cy.rms_bicubic < 1e-3);
        assert!(
            (cy.rms_bilinear - cy.rms_bicubic).abs() > 1e-9,
            "the two methods must differ"
        );
        assert!(close(cx.rms_bilinear, cx.rms_bicubic, 1e-9));
    }
    // On a smooth (quadratic in y) field the cubic must win clearly.
    let x = [0.0, 0.05, 0.1];
    let y = [-0.1, -0.05, 0.0, 0.05, 0.1];
    let smooth = field_map(&x, &y, |x, y| 1e-6 * (1.0 + x + 40.0 * y * y));
    let cv = leave_one_node_out(&smooth, &[100.0], HoldOutAxis::Y).unwrap();
    assert!(cv.rms_bicubic < 1e-3 * cv.rms_bilinear, "{cv:?}");
    assert_eq!(cv.better(), Interpolation::Bicubic);
}
