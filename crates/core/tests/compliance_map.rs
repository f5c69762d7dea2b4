//! Compliance map (Paksoy et al. 2025, Eq. 9-14) against the published Tables II/III.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use deflect_core::compliance_map::{
    ComplianceMap, ComplianceMapView, FitOptions, HoldOutAxis, Interpolation, Measurement,
    OutOfGrid, QueryOptions, fit, leave_one_node_out, two_point_displacement,
};
use deflect_core::io::{map_csv, map_json};
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_core::{BuildError, LoadError, Placement, TickError};
use proptest::prelude::*;

const OC: &str = include_str!("../../../data/paksoy2025_compliance_oc.csv");
const NC: &str = include_str!("../../../data/paksoy2025_compliance_nc.csv");
const KGF: f64 = 9.80665;

/// One table row: x, y [mm], then m, n, o, p, s, u, v, w.
fn rows(text: &str) -> Vec<[f64; 10]> {
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|s| s.trim().parse().unwrap()).collect();
            [v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11]]
        })
        .collect()
}

fn paper(text: &str) -> ComplianceMap {
    map_csv::from_str(text, ForceUnit::Newton, LengthUnit::Millimetre).unwrap()
}

fn query(map: &ComplianceMap, p: [f64; 2], f: [f64; 2], o: QueryOptions) -> [f64; 2] {
    let mut out = [0.0; 2];
    map.displacement_with(p, &f, &mut out, o).unwrap();
    out
}

fn opts(interpolation: Interpolation, out_of_grid: OutOfGrid) -> QueryOptions {
    QueryOptions {
        interpolation,
        out_of_grid,
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-18
}

#[test]
fn nodes_reproduce_table_lines() {
    for text in [OC, NC] {
        let map = paper(text);
        assert_eq!((map.x().len(), map.y().len()), (3, 5));
        for r in rows(text) {
            let [x, y, m, n, o, p, s, u, v, w] = r;
            for (fx, fy) in [(0.0, 0.0), (49.05, 0.0), (0.0, 245.25), (-120.0, 80.0)] {
                let dx = ((m * fx + n) + (o * fy + p)) * 1e-3;
                let dy = ((s * fx + u) + (v * fy + w)) * 1e-3;
                for method in [Interpolation::Bilinear, Interpolation::Bicubic] {
                    let d = query(
                        &map,
                        [x * 1e-3, y * 1e-3],
                        [fx, fy],
                        opts(method, OutOfGrid::Error),
                    );
                    assert!(
                        close(d[0], dx, 1e-12),
                        "{method:?} node ({x},{y}): {} vs {dx}",
                        d[0]
                    );
                    assert!(
                        close(d[1], dy, 1e-12),
                        "{method:?} node ({x},{y}): {} vs {dy}",
                        d[1]
                    );
                }
            }
        }
    }
}

#[test]
fn between_nodes_is_eq14_by_hand() {
    // OC, cell (i, j) = (1, 1)..(2, 2): x1 = 172.132, x2 = 222.132, y1 = -75, y2 = -37.5 mm.
    // P = (192.132, -60) mm, Fx = 100 N, Fy = 50 N. Node dx = (m Fx + n) + (o Fy + p) [mm]:
    //   dx11 = 0.1344 - 0.013608 - 0.07295 + 0.006259 =  0.054101
    //   dx12 = 0.0244 - 0.009737 - 0.0264  - 0.006226 = -0.017963
    //   dx21 = 0.0166 - 0.001331 - 0.04695 - 0.009154 = -0.040835
    //   dx22 = -0.0043 - 0.004694 - 0.02045 + 0.000947 = -0.028497
    // Eq. 14 with x2 - x = 30, x - x1 = 20, y2 - y = 22.5, y - y1 = 15, (x2-x1)(y2-y1) = 1875:
    //   dx_P = (30 (22.5 dx11 + 15 dx12) + 20 (22.5 dx21 + 15 dx22)) / 1875
    //        = (30 * 0.9478275 + 20 * (-1.3462425)) / 1875 = 1.509975 / 1875 = 0.00080532 mm
    // Likewise dy11 = 0.030991, dy12 = -0.025867, dy21 = -0.028834, dy22 = -0.071333 give
    //   dy_P = (30 (0.6972975 - 0.388005) + 20 (-0.648765 - 1.069995)) / 1875 = -0.01338476 mm
    let map = paper(OC);
    let d = query(
        &map,
        [192.132e-3, -60e-3],
        [100.0, 50.0],
        opts(Interpolation::Bilinear, OutOfGrid::Error),
    );
    assert!(close(d[0], 0.00080532e-3, 1e-9), "{}", d[0]);
    assert!(close(d[1], -0.01338476e-3, 1e-9), "{}", d[1]);
    // Bicubic differs between nodes (it uses the 4 x 4 neighbourhood) but stays close.
    let c = query(
        &map,
        [192.132e-3, -60e-3],
        [100.0, 50.0],
        opts(Interpolation::Bicubic, OutOfGrid::Error),
    );
    assert!((c[0] - d[0]).abs() > 1e-12 && (c[0] - d[0]).abs() < 0.05e-3);
}

#[test]
fn force_unit_and_length_unit_are_explicit() {
    let n = paper(OC);
    let kgf = map_csv::from_str(OC, ForceUnit::KilogramForce, LengthUnit::Millimetre).unwrap();
    // Table II, node (1,1): m = 1.344e-3 mm per unit force.
    assert!(close(n.slope(0, 0, 0, 0).unwrap(), 1.344e-6, 1e-12));
    assert!(close(kgf.slope(0, 0, 0, 0).unwrap(), 1.344e-6 / KGF, 1e-12));
    assert!(close(n.offset(0, 0, 1, 1).unwrap(), 13.977e-6, 1e-12));
    let m = map_csv::from_str(OC, ForceUnit::Newton, LengthUnit::Metre).unwrap();
    assert!(close(m.slope(0, 0, 0, 0).unwrap(), 1.344e-3, 1e-12));
    assert!(
        close(m.x()[0], 172.132e-3, 1e-12),
        "x_mm columns are mm whatever length_unit"
    );
}

/// Synthetic static tests from a map: forces 49.05 k N (k = 1..5) along each axis, each
/// reading = the loaded axis' line (Eq. 10), plus seeded Gaussian noise of `sigma` [m].
fn synthetic(map: &ComplianceMap, sigma: f64, seed: u64) -> Vec<Measurement> {
    let mut state = seed;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut gauss = move || {
        let (a, b) = (uniform(), uniform());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    };
    let mut out = Vec::new();
    for (i, x) in map.x().iter().enumerate() {
        for (j, y) in map.y().iter().enumerate() {
            for f in 0..2 {
                for k in 1..=5 {
                    let force = 49.05 * k as f64;
                    let d: Vec<f64> = (0..2)
                        .map(|d| {
                            map.slope(i, j, d, f).unwrap() * force
                                + map.offset(i, j, d, f).unwrap()
                                + sigma * gauss()
                        })
                        .collect();
                    out.push(Measurement::new(*x, *y, f, force, &d));
                }
            }
        }
    }
    out
}

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
fn loader_and_view_rejections() {
    let mut lines: Vec<&str> = OC.lines().collect();
    let dup_row = lines[3];
    lines.push(dup_row);
    let text = lines.join("\n");
    let load = |t: &str| map_csv::from_str(t, ForceUnit::Newton, LengthUnit::Millimetre);
    assert_eq!(
        load(&text).unwrap_err(),
        LoadError::Build(BuildError::DuplicateNode {
            row: 15,
            previous_row: 2
        })
    );
    let short: String = OC.lines().take(15).collect::<Vec<_>>().join("\n");
    assert!(matches!(
        load(&short).unwrap_err(),
        LoadError::Build(BuildError::MissingNode { .. })
    ));
    let bad = OC.replacen("1.344e-3", "abc", 1);
    assert_eq!(
        load(&bad).unwrap_err(),
        LoadError::BadNumber {
            row: 0,
            column: "m"
        }
    );
    let inf = OC.replacen("1.344e-3", "inf", 1);
    assert_eq!(
        load(&inf).unwrap_err(),
        LoadError::NonFiniteCell {
            row: 0,
            column: "m"
        }
    );
    // A misspelt column is named as unknown (it used to be dropped silently and reported
    // only as the missing column it should have been).
    let misspelt = OC.replacen(",w\n", ",ww\n", 1);
    assert_eq!(
        load(&misspelt).unwrap_err(),
        LoadError::UnknownColumn {
            column: "ww".to_string()
        }
    );
    // Without the last column (`w`) in the header and in every row.
    let nocol: String = OC
        .lines()
        .map(|l| match l.rsplit_once(',') {
            Some((head, _)) if !l.starts_with('#') => format!("{head}\n"),
            _ => format!("{l}\n"),
        })
        .collect();
    assert_eq!(
        load(&nocol).unwrap_err(),
        LoadError::MissingColumn { column: "w" }
    );
    let ragged = format!("{OC}1,1,2\n");
    assert!(matches!(
        load(&ragged).unwrap_err(),
        LoadError::Csv { line: Some(17), .. }
    ));

    let x = [0.0, 1.0, 1.0];
    let y = [0.0, 1.0];
    let c = [0.0; 6];
    assert_eq!(
        ComplianceMapView::new(&x, &y, 1, 1, &c, &c).unwrap_err(),
        BuildError::NotIncreasing {
            what: "x",
            index: 2
        }
    );
    assert_eq!(
        ComplianceMapView::new(&[0.0, 1.0], &y, 1, 1, &c, &c).unwrap_err(),
        BuildError::WrongLength {
            what: "slopes",
            expected: 4,
            got: 6
        }
    );
    assert_eq!(
        ComplianceMapView::new(&[0.0], &y, 1, 1, &c, &c).unwrap_err(),
        BuildError::TooFew {
            what: "x nodes",
            needed: 2,
            got: 1
        }
    );

    let map = paper(OC);
    let mut out = [0.0; 2];
    let p = [0.2, 0.0];
    assert_eq!(
        map.displacement([f64::NAN, 0.0], &[1.0, 1.0], &mut out),
        Err(TickError::NonFinite {
            what: "position",
            index: 0
        })
    );
    assert_eq!(
        map.displacement(p, &[1.0, f64::INFINITY], &mut out),
        Err(TickError::NonFinite {
            what: "force",
            index: 1
        })
    );
    assert_eq!(
        map.displacement(p, &[1.0], &mut out),
        Err(TickError::WrongLength {
            what: "force",
            expected: 2,
            got: 1
        })
    );
    assert_eq!(
        map.displacement(p, &[1.0, 1.0], &mut [0.0; 3]),
        Err(TickError::WrongLength {
            what: "out",
            expected: 2,
            got: 3
        })
    );

    let json = map_json::to_string(&map).unwrap();
    let v2 = json.replacen("\"format_version\": 1", "\"format_version\": 2", 1);
    assert_eq!(
        map_json::from_str(&v2).unwrap_err(),
        LoadError::UnsupportedVersion { found: 2 }
    );
    let mm = json.replacen("\"position\": \"m\"", "\"position\": \"mm\"", 1);
    assert!(matches!(
        map_json::from_str(&mm).unwrap_err(),
        LoadError::UnexpectedUnits {
            quantity: "position",
            ..
        }
    ));
    assert!(matches!(
        map_json::from_str("{\"format_version\": 1}").unwrap_err(),
        LoadError::Json { .. }
    ));
}

#[test]
fn out_of_grid_policies() {
    let map = paper(OC);
    let (x, y) = (map.x().to_vec(), map.y().to_vec());
    let f = [150.0, -80.0];
    let outside = [x[2] + 0.01, y[1]];
    let mut out = [0.0; 2];
    match map.displacement_with(
        outside,
        &f,
        &mut out,
        opts(Interpolation::Bilinear, OutOfGrid::Error),
    ) {
        Err(TickError::OutOfGrid {
            axis: 0,
            value,
            min,
            max,
        }) => {
            assert_eq!((value, min, max), (outside[0], x[0], x[2]));
        }
        other => panic!("{other:?}"),
    }
    for method in [Interpolation::Bilinear, Interpolation::Bicubic] {
        let st = map.displacement_with(outside, &f, &mut out, opts(method, OutOfGrid::Clamp));
        assert_eq!(st, Ok(Placement::Clamped));
        assert_eq!(
            out,
            query(&map, [x[2], y[1]], f, opts(method, OutOfGrid::Error))
        );
        let inside =
            map.displacement_with([x[1], y[1]], &f, &mut out, opts(method, OutOfGrid::Clamp));
        assert_eq!(inside, Ok(Placement::Inside));
    }
    // Bilinear extrapolation continues the boundary cell's line: along y = y_1 the values
    // at x_1, x_2 extend linearly by 0.01 / 0.05 of their difference.
    let a = query(
        &map,
        [x[1], y[1]],
        f,
        opts(Interpolation::Bilinear, OutOfGrid::Error),
    );
    let b = query(
        &map,
        [x[2], y[1]],
        f,
        opts(Interpolation::Bilinear, OutOfGrid::Error),
    );
    let st = map.displacement_with(
        outside,
        &f,
        &mut out,
        opts(Interpolation::Bilinear, OutOfGrid::Extrapolate),
    );
    assert_eq!(st, Ok(Placement::Extrapolated));
    for k in 0..2 {
        assert!(
            close(out[k], b[k] + 0.2 * (b[k] - a[k]), 1e-9),
            "{} vs {}",
            out[k],
            b[k] + 0.2 * (b[k] - a[k])
        );
    }
    // Bicubic extrapolation is C1: one-sided difference quotients match across the boundary.
    let h = 1e-7;
    let o = opts(Interpolation::Bicubic, OutOfGrid::Extrapolate);
    let (yq, xb) = (-0.05, x[2]);
    let vin = query(&map, [xb - h, yq], f, o);
    let v0 = query(&map, [xb, yq], f, o);
    let vout = query(&map, [xb + h, yq], f, o);
    for k in 0..2 {
        let (din, dout) = ((v0[k] - vin[k]) / h, (vout[k] - v0[k]) / h);
        assert!(
            (din - dout).abs() < 1e-4 * din.abs().max(1e-6),
            "{din} vs {dout}"
        );
    }
    // Below and left of the grid at once.
    let st = map.displacement_with([0.0, -1.0], &f, &mut out, o);
    assert_eq!(st, Ok(Placement::Extrapolated));
    assert!(out.iter().all(|v| v.is_finite()));
}

/// A map whose slope field is `g(x, y)` on the given axes (1 force, 1 displacement).
fn field_map(x: &[f64], y: &[f64], g: impl Fn(f64, f64) -> f64) -> ComplianceMap {
    let mut slopes = Vec::new();
    for xi in x {
        for yj in y {
            slopes.push(g(*xi, *yj));
        }
    }
    let offsets = vec![0.0; slopes.len()];
    ComplianceMap::new(x.to_vec(), y.to_vec(), 1, 1, slopes, offsets).unwrap()
}

#[test]
fn bicubic_reproduces_biquadratics_on_uneven_grids_and_bilinear_bilinears() {
    let x = [0.0, 0.1, 0.25, 0.3, 0.5];
    let y = [-0.2, -0.05, 0.0, 0.2];
    let q = |x: f64, y: f64| 1.0 + 2.0 * x - 3.0 * y + 4.0 * x * x * y * y - x * y + 0.5 * y * y;
    let l = |x: f64, y: f64| 1.0 + 2.0 * x - 3.0 * y + 5.0 * x * y;
    let mq = field_map(&x, &y, q);
    let ml = field_map(&x, &y, l);
    let mut out = [0.0];
    for k in 0..200 {
        let (px, py) = (
            0.5 * (k as f64 * 0.618_033_988).fract(),
            -0.2 + 0.4 * (k as f64 * 0.414_213_56).fract(),
        );
        mq.displacement_with(
            [px, py],
            &[1.0],
            &mut out,
            opts(Interpolation::Bicubic, OutOfGrid::Error),
        )
        .unwrap();
        assert!(
            (out[0] - q(px, py)).abs() < 1e-12,
            "bicubic at ({px}, {py}): {} vs {}",
            out[0],
            q(px, py)
        );
        ml.displacement_with(
            [px, py],
            &[1.0],
            &mut out,
            opts(Interpolation::Bilinear, OutOfGrid::Error),
        )
        .unwrap();
        assert!((out[0] - l(px, py)).abs() < 1e-12);
    }
    // Bilinear does not reproduce the quadratic between nodes.
    mq.displacement_with(
        [0.05, -0.1],
        &[1.0],
        &mut out,
        opts(Interpolation::Bilinear, OutOfGrid::Error),
    )
    .unwrap();
    assert!((out[0] - q(0.05, -0.1)).abs() > 1e-4);
}

#[test]
fn six_by_six_map() {
    // 6 force axes, 6 displacement axes on a 2 x 3 grid; slope (d, f) = 1e-6 (1 + d + 10 f + i + j).
    let (x, y) = (vec![0.0, 1.0], vec![0.0, 0.5, 1.0]);
    let mut slopes = Vec::new();
    let mut offsets = Vec::new();
    for i in 0..2 {
        for j in 0..3 {
            for d in 0..6 {
                for f in 0..6 {
                    slopes.push(1e-6 * (1 + d + 10 * f + i + j) as f64);
                    offsets.push(1e-7 * f as f64);
                }
            }
        }
    }
    let map = ComplianceMap::new(x, y, 6, 6, slopes, offsets).unwrap();
    let force = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    let mut out = [0.0; 6];
    // At (0.5, 0.25): i + j interpolates to 0.5 + 0.5 (bilinear of a bilinear field).
    map.displacement([0.5, 0.25], &force, &mut out).unwrap();
    for (d, o) in out.iter().enumerate() {
        let want: f64 = (0..6)
            .map(|f| 1e-6 * (1.0 + d as f64 + 10.0 * f as f64 + 1.0) * force[f] + 1e-7 * f as f64)
            .sum();
        assert!(close(*o, want, 1e-12), "{o} vs {want}");
    }
    assert!(
        ComplianceMap::new(
            vec![0.0, 1.0],
            vec![0.0, 1.0],
            7,
            1,
            vec![0.0; 28],
            vec![0.0; 28]
        )
        .is_err()
    );
}

#[test]
fn two_point_extrapolation_is_rigid_body() {
    // Rigid small motion: delta(p) = t + theta x (p - c). P_u = (0, 0, 0.1), P_l = 0,
    // W = (0, 0, -0.0025): L = 0.1 m, e = 2.5 mm.
    let (t, th, c) = ([1e-5, -2e-5, 3e-6], [2e-4, -1e-4, 5e-5], [0.02, -0.01, 0.3]);
    let delta = |p: [f64; 3]| {
        let r = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        [
            t[0] + th[1] * r[2] - th[2] * r[1],
            t[1] + th[2] * r[0] - th[0] * r[2],
            t[2] + th[0] * r[1] - th[1] * r[0],
        ]
    };
    let (u, l, w) = (
        delta([0.0, 0.0, 0.1]),
        delta([0.0; 3]),
        delta([0.0, 0.0, -0.0025]),
    );
    let mut out = [0.0; 3];
    two_point_displacement(&u, &l, 0.1, 0.0025, &mut out).unwrap();
    for k in 0..3 {
        assert!((out[k] - w[k]).abs() < 1e-18, "{k}: {} vs {}", out[k], w[k]);
    }
    // e = -L gives P_u back.
    two_point_displacement(&u, &l, 0.1, -0.1, &mut out).unwrap();
    assert!((out[0] - u[0]).abs() < 1e-18);
    let m = Measurement::from_two_point(0.1, 0.2, 1, 49.05, &u[..2], &l[..2], 0.1, 0.0025).unwrap();
    assert!((m.displacement[1] - w[1]).abs() < 1e-18 && m.displacement[2] == 0.0);
    assert_eq!(
        two_point_displacement(&u, &l, 0.0, 0.0025, &mut out),
        Err(BuildError::BadTwoPoint { spacing: 0.0 })
    );
}

#[test]
fn json_round_trip_is_exact() {
    let table = paper(OC);
    let mut fitted = fit(&synthetic(&table, 1.7e-6, 42), &FitOptions::default()).unwrap();
    fitted.set_options(opts(Interpolation::Bicubic, OutOfGrid::Clamp));
    for map in [table, fitted] {
        let json = map_json::to_string(&map).unwrap();
        assert!(json.contains("\"format_version\": 1"));
        let back = map_json::from_str(&json).unwrap();
        assert_eq!(back, map);
        for (a, b) in back.slopes().iter().zip(map.slopes()) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
    }
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

fn even_and_uneven() -> Vec<ComplianceMap> {
    let oc = paper(OC);
    let uneven_x = vec![0.17, 0.2, 0.27];
    let uneven_y = vec![-0.075, -0.05, 0.0, 0.01, 0.075];
    let uneven = ComplianceMap::new(
        uneven_x,
        uneven_y,
        2,
        2,
        oc.slopes().to_vec(),
        oc.offsets().to_vec(),
    )
    .unwrap();
    vec![oc, uneven]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn bilinear_stays_within_the_cell_corner_values(
        which in 0usize..2, tx in 0.0f64..=1.0, ty in 0.0f64..=1.0,
        fx in -300.0f64..300.0, fy in -300.0f64..300.0,
    ) {
        let map = &even_and_uneven()[which];
        let (x, y) = (map.x(), map.y());
        let px = x[0] + tx * (x[x.len() - 1] - x[0]);
        let py = y[0] + ty * (y[y.len() - 1] - y[0]);
        let i = x.partition_point(|v| *v <= px).clamp(1, x.len() - 1) - 1;
        let j = y.partition_point(|v| *v <= py).clamp(1, y.len() - 1) - 1;
        let d = query(map, [px, py], [fx, fy], opts(Interpolation::Bilinear, OutOfGrid::Error));
        for k in 0..2 {
            let corners: Vec<f64> = [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
                .iter()
                .map(|(a, b)| {
                    let mut o = [0.0; 2];
                    map.node_displacement(*a, *b, &[fx, fy], &mut o).unwrap();
                    o[k]
                })
                .collect();
            let lo = corners.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = corners.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let eps = 1e-12 * hi.abs().max(lo.abs()).max(1e-9);
            prop_assert!(d[k] >= lo - eps && d[k] <= hi + eps, "{} not in [{lo}, {hi}]", d[k]);
        }
    }

    #[test]
    fn displacement_is_affine_in_force(
        which in 0usize..2, bicubic in proptest::bool::ANY, tx in -0.2f64..1.2, ty in -0.2f64..1.2,
        f1 in proptest::array::uniform2(-300.0f64..300.0), f2 in proptest::array::uniform2(-300.0f64..300.0),
        a in -2.0f64..2.0,
    ) {
        let map = &even_and_uneven()[which];
        let (x, y) = (map.x(), map.y());
        let p = [x[0] + tx * (x[x.len() - 1] - x[0]), y[0] + ty * (y[y.len() - 1] - y[0])];
        let method = if bicubic { Interpolation::Bicubic } else { Interpolation::Bilinear };
        let o = opts(method, OutOfGrid::Extrapolate);
        let d1 = query(map, p, f1, o);
        let d2 = query(map, p, f2, o);
        let mix = [a * f1[0] + (1.0 - a) * f2[0], a * f1[1] + (1.0 - a) * f2[1]];
        let dm = query(map, p, mix, o);
        for k in 0..2 {
            let want = a * d1[k] + (1.0 - a) * d2[k];
            prop_assert!((dm[k] - want).abs() <= 1e-9 * (d1[k].abs() + d2[k].abs()).max(1e-9) * 4.0,
                "{} vs {want}", dm[k]);
        }
    }
}

#[test]
fn batch_equals_single_bit_for_bit() {
    for map in even_and_uneven() {
        let n = 500;
        let mut pos = Vec::new();
        let mut force = Vec::new();
        for k in 0..n {
            let t = k as f64 * 0.618_033_988_749_895;
            // stride 3: x, y, z (ignored); some rows outside the grid, some exactly on nodes.
            let (x, y) = if k % 50 == 0 {
                (map.x()[k % 3], map.y()[k % 5])
            } else {
                (0.16 + 0.13 * t.fract(), -0.085 + 0.17 * (t * 1.7).fract())
            };
            pos.extend_from_slice(&[x, y, 9.0]);
            force.extend_from_slice(&[
                300.0 * (t * 2.3).fract() - 150.0,
                245.25 * (t * 3.1).fract(),
            ]);
        }
        for method in [Interpolation::Bilinear, Interpolation::Bicubic] {
            for policy in [OutOfGrid::Clamp, OutOfGrid::Extrapolate] {
                let o = opts(method, policy);
                let mut out = vec![0.0; 2 * n];
                let summary = map
                    .displacement_batch(&pos, 3, &force, &mut out, o)
                    .unwrap();
                assert_eq!(summary.inside + summary.clamped + summary.extrapolated, n);
                assert!(summary.inside > 300 && summary.inside < n, "{summary:?}");
                for k in 0..n {
                    let single = query(
                        &map,
                        [pos[3 * k], pos[3 * k + 1]],
                        [force[2 * k], force[2 * k + 1]],
                        o,
                    );
                    assert_eq!(single[0].to_bits(), out[2 * k].to_bits(), "row {k} {o:?}");
                    assert_eq!(
                        single[1].to_bits(),
                        out[2 * k + 1].to_bits(),
                        "row {k} {o:?}"
                    );
                }
            }
            // With the Error policy the first row outside the grid is reported.
            let mut out = vec![0.0; 2 * n];
            let err = map
                .displacement_batch(&pos, 3, &force, &mut out, opts(method, OutOfGrid::Error))
                .unwrap_err();
            let first_out = (0..n)
                .find(|k| {
                    let (x, y) = (pos[3 * k], pos[3 * k + 1]);
                    x < map.x()[0] || x > map.x()[2] || y < map.y()[0] || y > map.y()[4]
                })
                .unwrap();
            assert_eq!(err.row, first_out);
            assert!(matches!(err.error, TickError::OutOfGrid { .. }));
        }
        let mut out = vec![0.0; 4];
        let mut bad = pos[..6].to_vec();
        bad[4] = f64::NAN;
        let err = map
            .displacement_batch(&bad, 3, &force[..4], &mut out, QueryOptions::default())
            .unwrap_err();
        assert_eq!(
            (err.row, err.error),
            (
                1,
                TickError::NonFinite {
                    what: "position",
                    index: 1
                }
            )
        );
        assert!(
            map.displacement_batch(&pos[..5], 3, &force[..4], &mut out, QueryOptions::default())
                .is_err()
        );
    }
}

/// The owning map's packed coefficient layout (slopes, then offset sums, node by node) and a
/// borrowed view over the plain tables give the same bits, for the fixed-size kernels (2 x 2,
/// 3 x 3, 6 x 6) and the generic one (3 x 2), every interpolation and out-of-grid policy,
/// single queries and batches; and both equal Eq. 9-10 summed by hand at the nodes.
#[test]
fn packed_and_plain_layouts_agree_bit_for_bit() {
    let x = vec![0.0, 0.1, 0.25, 0.3];
    let y = vec![-0.2, -0.1, 0.0, 0.1, 0.2];
    for (nd, nf) in [(2, 2), (3, 3), (6, 6), (3, 2), (1, 4)] {
        let n = x.len() * y.len() * nd * nf;
        let coef = |k: usize, s: f64| ((k as f64 * s).sin() * 1e-6) + 1e-7;
        let slopes: Vec<f64> = (0..n).map(|k| coef(k, 0.37)).collect();
        let offsets: Vec<f64> = (0..n).map(|k| coef(k, 1.91) * 1e-3).collect();
        let map = ComplianceMap::new(
            x.clone(),
            y.clone(),
            nf,
            nd,
            slopes.clone(),
            offsets.clone(),
        )
        .unwrap();
        let plain = ComplianceMapView::new(&x, &y, nf, nd, &slopes, &offsets).unwrap();
        let packed = map.view();
        let force: Vec<f64> = (0..nf).map(|f| 100.0 * (f as f64 + 1.0) - 150.0).collect();
        // Nodes: Eq. 9-10 by hand.
        for (i, xi) in x.iter().enumerate() {
            for (j, yj) in y.iter().enumerate() {
                let mut out = vec![0.0; nd];
                packed.displacement([*xi, *yj], &force, &mut out).unwrap();
                for (d, o) in out.iter().enumerate() {
                    let want: f64 = (0..nf)
                        .map(|f| map.slope(i, j, d, f).unwrap() * force[f])
                        .sum::<f64>()
                        + (0..nf)
                            .map(|f| map.offset(i, j, d, f).unwrap())
                            .sum::<f64>();
                    assert!(
                        (o - want).abs() <= 1e-15 * want.abs().max(1e-12),
                        "{nd}x{nf}"
                    );
                }
            }
        }
        let points: Vec<[f64; 2]> = (0..200)
            .map(|k| {
                let t = k as f64 * 0.618_033_988_749_895;
                [-0.05 + 0.4 * t.fract(), -0.25 + 0.5 * (t * 1.7).fract()]
            })
            .chain([[0.1, 0.0], [0.3, 0.2], [0.0, -0.2], [0.25, -0.1]])
            .collect();
        for interpolation in [Interpolation::Bilinear, Interpolation::Bicubic] {
            for out_of_grid in [OutOfGrid::Error, OutOfGrid::Clamp, OutOfGrid::Extrapolate] {
                let o = opts(interpolation, out_of_grid);
                let flat_p: Vec<f64> = points.iter().flatten().copied().collect();
                let flat_f: Vec<f64> = points.iter().flat_map(|_| force.clone()).collect();
                for p in &points {
                    let (mut a, mut b) = (vec![0.0; nd], vec![0.0; nd]);
                    let ra = packed.displacement_with(*p, &force, &mut a, o);
                    let rb = plain.displacement_with(*p, &force, &mut b, o);
                    assert_eq!(ra, rb);
                    if ra.is_ok() {
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(&a), bits(&b), "{nd}x{nf} {p:?} {o:?}");
                    }
                }
                if out_of_grid != OutOfGrid::Error {
                    let (mut a, mut b) =
                        (vec![0.0; nd * points.len()], vec![0.0; nd * points.len()]);
                    packed
                        .displacement_batch(&flat_p, 2, &flat_f, &mut a, o)
                        .unwrap();
                    plain
                        .displacement_batch(&flat_p, 2, &flat_f, &mut b, o)
                        .unwrap();
                    for (k, p) in points.iter().enumerate() {
                        let mut s = vec![0.0; nd];
                        packed.displacement_with(*p, &force, &mut s, o).unwrap();
                        for d in 0..nd {
                            assert_eq!(a[k * nd + d].to_bits(), s[d].to_bits());
                            assert_eq!(b[k * nd + d].to_bits(), s[d].to_bits());
                        }
                    }
                }
            }
        }
    }
}

/// A displacement field at a fixed load gives the map's displacement under that load (the
/// same node values blended the same way), inside and out, single and batched; bad loads
/// are refused at build.
#[test]
fn displacement_field_equals_the_map_at_its_load() {
    let map = paper(OC);
    let force = [-120.0, 245.25];
    let field = map.field(&force).unwrap();
    assert_eq!(field.force(), &force);
    assert_eq!(field.n_displacement(), 2);
    for interpolation in [Interpolation::Bilinear, Interpolation::Bicubic] {
        for out_of_grid in [OutOfGrid::Error, OutOfGrid::Clamp, OutOfGrid::Extrapolate] {
            let o = opts(interpolation, out_of_grid);
            let mut flat = Vec::new();
            for k in 0..300 {
                let t = k as f64 * 0.618_033_988_749_895;
                let p = [0.15 + 0.15 * t.fract(), -0.09 + 0.18 * (t * 1.3).fract()];
                flat.extend_from_slice(&p);
                let (mut a, mut b) = ([0.0; 2], [0.0; 2]);
                let ra = field.displacement_with(p, &mut a, o);
                let rb = map.displacement_with(p, &force, &mut b, o);
                assert_eq!(ra, rb, "{p:?} {o:?}");
                if ra.is_ok() {
                    assert_eq!(a, b, "{p:?} {o:?}");
                }
            }
            if out_of_grid != OutOfGrid::Error {
                let mut out = vec![0.0; flat.len()];
                field.displacement_batch(&flat, 2, &mut out, o).unwrap();
                for (p, d) in flat.chunks(2).zip(out.chunks(2)) {
                    let mut b = [0.0; 2];
                    map.displacement_with([p[0], p[1]], &force, &mut b, o)
                        .unwrap();
                    assert_eq!(d, b);
                }
            }
        }
    }
    assert!(matches!(
        map.field(&[1.0]),
        Err(BuildError::WrongLength {
            what: "force",
            expected: 2,
            got: 1
        })
    ));
    assert!(matches!(
        map.field(&[1.0, f64::NAN]),
        Err(BuildError::NonFinite {
            what: "force",
            index: 1
        })
    ));
    let mut out = [0.0; 2];
    assert!(matches!(
        field.displacement([0.5, 0.0], &mut out),
        Err(TickError::OutOfGrid { axis: 0, .. })
    ));
}
