//! Compliance maps over 1-4 dimensional grids: nodes reproduced exactly, the 2-D case equal to
//! the 2-D map, polynomials the interpolation must reproduce, fitting from static tests, and
//! every refusal typed.

use deflect_core::compliance_map::{
    ComplianceMap, FitOptions, GridMap, GridMeasurement, Interpolation, MAX_GRID_NODES, OutOfGrid,
    QueryOptions, fit_grid,
};
use deflect_core::{BuildError, Placement, TickError};

/// A deterministic sequence in (-1, 1) (no RNG dependency for a test of exactness).
fn noise(k: usize) -> f64 {
    let x = ((k as f64 + 1.0) * 0.618_033_988_749_894_9).fract();
    2.0 * x - 1.0
}

fn names(n: usize) -> Vec<String> {
    ["x", "y", "z", "q4"]
        .iter()
        .take(n)
        .map(|s| s.to_string())
        .collect()
}

/// Uneven axes: `n` nodes from `a` growing by 10 % per step.
fn axis(a: f64, n: usize) -> Vec<f64> {
    let mut v = vec![a];
    let mut h = 0.05;
    for _ in 1..n {
        v.push(v.last().unwrap() + h);
        h *= 1.1;
    }
    v
}

fn map_with(
    axes: Vec<Vec<f64>>,
    nf: usize,
    nd: usize,
    value: impl Fn(&[f64], usize) -> f64,
) -> GridMap {
    // Node displacements under force f are slope * F + offset: slopes from `value`, offsets
    // a fixed fraction, so that both enter.
    let dims = axes.len();
    let nodes: usize = axes.iter().map(Vec::len).product();
    let mut slopes = Vec::new();
    let mut offsets = Vec::new();
    for node in 0..nodes {
        let mut rest = node;
        let mut p = vec![0.0; dims];
        for k in (0..dims).rev() {
            p[k] = axes[k][rest % axes[k].len()];
            rest /= axes[k].len();
        }
        for d in 0..nd {
            for f in 0..nf {
                let v = value(&p, d * nf + f);
                slopes.push(v);
                offsets.push(1e-3 * v);
            }
        }
    }
    GridMap::new(axes, names(dims), nf, nd, slopes, offsets).unwrap()
}

#[test]
fn every_node_is_reproduced_exactly_in_1_to_4_dimensions() {
    for dims in 1..=4 {
        let axes: Vec<Vec<f64>> = (0..dims)
            .map(|k| axis(0.1 * k as f64, 5 - (k % 2)))
            .collect();
        let map = map_with(axes.clone(), 2, 3, |p, c| {
            noise(c + (p.iter().sum::<f64>() * 1e3) as usize) * 1e-6
        });
        let force = [120.0, -35.0];
        for method in [Interpolation::Bilinear, Interpolation::Bicubic] {
            let o = QueryOptions {
                interpolation: method,
                out_of_grid: OutOfGrid::Error,
            };
            for node in 0..map.node_count() {
                let mut rest = node;
                let mut p = vec![0.0; dims];
                for k in (0..dims).rev() {
                    p[k] = axes[k][rest % axes[k].len()];
                    rest /= axes[k].len();
                }
                let mut got = [0.0; 3];
                map.displacement_with(&p, &force, &mut got, o).unwrap();
                for (d, g) in got.iter().enumerate() {
                    let c = node * 6 + d * 2;
                    let want: f64 = (0..2)
                        .map(|f| map.slopes()[c + f] * force[f] + map.offsets()[c + f])
                        .sum();
                    if dims == 2 {
                        // The 2-D map's kernels (the 2-D grid map's fast path) add the
                        // offsets as one sum: the node's lines to the rounding of that order.
                        let size: f64 = (0..2)
                            .map(|f| {
                                (map.slopes()[c + f] * force[f]).abs() + map.offsets()[c + f].abs()
                            })
                            .sum();
                        assert!(
                            (*g - want).abs() <= 4.0 * f64::EPSILON * size,
                            "{dims}-D {method:?} node {node} axis {d}: {g} against {want}"
                        );
                    } else {
                        assert_eq!(*g, want, "{dims}-D {method:?} node {node} axis {d}");
                    }
                }
            }
        }
    }
}

#[test]
fn in_two_dimensions_it_is_the_paper_map() {
    // A 2-D grid map queries through the 2-D map's kernels: the same bits.
    let (x, y) = (axis(0.2, 6), axis(-0.1, 5));
    let n = x.len() * y.len() * 4;
    let slopes: Vec<f64> = (0..n).map(|k| 1e-6 * noise(k)).collect();
    let offsets: Vec<f64> = (0..n).map(|k| 1e-5 * noise(k + 7)).collect();
    let map2 = ComplianceMap::new(x.clone(), y.clone(), 2, 2, slopes, offsets).unwrap();
    let nd = GridMap::from_map(&map2);
    assert_eq!(nd.dims(), 2);
    assert_eq!(nd.names(), ["x", "y"]);
    for method in [Interpolation::Bilinear, Interpolation::Bicubic] {
        for policy in [OutOfGrid::Clamp, OutOfGrid::Extrapolate] {
            let o = QueryOptions {
                interpolation: method,
                out_of_grid: policy,
            };
            for k in 0..400 {
                let p = [
                    0.15 + 0.4 * (noise(3 * k) + 1.0) / 2.0,
                    -0.15 + 0.4 * (noise(3 * k + 1) + 1.0) / 2.0,
                ];
                let f = [200.0 * noise(3 * k + 2), 50.0];
                let (mut a, mut b) = ([0.0; 2], [0.0; 2]);
                let pa = map2.displacement_with(p, &f, &mut a, o).unwrap();
                let pb = nd.displacement_with(&p, &f, &mut b, o).unwrap();
                assert_eq!(pa, pb);
                for (u, v) in a.iter().zip(&b) {
                    assert_eq!(u.to_bits(), v.to_bits(), "{method:?} {policy:?} {p:?}");
                }
            }
        }
    }
}

#[test]
fn multilinear_keeps_affine_fields_and_cubic_keeps_quadratics() {
    let axes = vec![axis(0.0, 4), axis(0.3, 5), axis(-0.2, 4)];
    let affine = |p: &[f64]| 1e-6 * (2.0 + 3.0 * p[0] - 1.5 * p[1] + 0.7 * p[2]);
    let quadratic =
        |p: &[f64]| 1e-6 * (1.0 + p[0] * p[0] - 2.0 * p[1] * p[1] + 0.5 * p[2] * p[2] + p[1]);
    for (field, method) in [
        (&affine as &dyn Fn(&[f64]) -> f64, Interpolation::Bilinear),
        (&quadratic, Interpolation::Bicubic),
    ] {
        let map = map_with(axes.clone(), 1, 1, |p, _| field(p)).with_options(QueryOptions {
            interpolation: method,
            out_of_grid: OutOfGrid::Error,
        });
        for k in 0..500 {
            let p = [
                axes[0][0] + (axes[0][3] - axes[0][0]) * (noise(3 * k) + 1.0) / 2.0,
                axes[1][0] + (axes[1][4] - axes[1][0]) * (noise(3 * k + 1) + 1.0) / 2.0,
                axes[2][0] + (axes[2][3] - axes[2][0]) * (noise(3 * k + 2) + 1.0) / 2.0,
            ];
            let mut got = [0.0];
            map.displacement(&p, &[100.0], &mut got).unwrap();
            let want = field(&p) * 100.0 + 1e-3 * field(&p);
            assert!(
                (got[0] - want).abs() < 1e-17,
                "{method:?} {p:?}: {} vs {want}",
                got[0]
            );
        }
    }
}

#[test]
fn a_3d_map_fitted_from_static_tests_returns_its_lines() {
    let axes = vec![axis(0.0, 3), axis(0.1, 4), axis(0.5, 3)];
    let truth = map_with(axes.clone(), 2, 3, |p, c| {
        1e-6 * (1.0 + p[0] + 2.0 * p[1] * p[2] + c as f64)
    });
    let mut readings = Vec::new();
    for node in 0..truth.node_count() {
        let mut rest = node;
        let mut p = [0.0; 3];
        for k in (0..3).rev() {
            p[k] = axes[k][rest % axes[k].len()];
            rest /= axes[k].len();
        }
        for f in 0..2 {
            for level in [-300.0, -100.0, 100.0, 300.0] {
                let mut force = [0.0; 2];
                force[f] = level;
                let mut d = [0.0; 3];
                truth.displacement(&p, &force, &mut d).unwrap();
                // The other force axis's offset is in the reading: remove it as the paper's
                // per-axis lines (Eq. 10) hold each axis's own intercept.
                for (dd, di) in d.iter_mut().enumerate() {
                    let c = node * 6 + dd * 2 + (1 - f);
                    *di -= truth.offsets()[c];
                }
                // Positions as measured: within 1e-7 m of the node.
                let jitter = [1e-8 * noise(node), -2e-8, 3e-8];
                let q: Vec<f64> = p.iter().zip(jitter).map(|(a, b)| a + b).collect();
                readings.push(GridMeasurement::new(&q, f, level, &d));
            }
        }
    }
    let options = FitOptions {
        n_force: 2,
        n_displacement: 3,
        ..FitOptions::default()
    };
    let fitted = fit_grid(names(3), &readings, &options).unwrap();
    assert_eq!(fitted.dims(), 3);
    for (a, b) in fitted.slopes().iter().zip(truth.slopes()) {
        assert!((a - b).abs() < 1e-12 * b.abs(), "{a} {b}");
    }
    for (a, b) in fitted.offsets().iter().zip(truth.offsets()) {
        // Offsets are the intercepts of lines through readings 1e5 times larger: to rounding
        // of those readings.
        assert!((a - b).abs() < 1e-16, "{a} {b}");
    }
    // A node without readings is named.
    let missing: Vec<GridMeasurement> = readings
        .iter()
        .copied()
        .filter(|m| !(m.point[0] < 0.01 && m.point[1] < 0.11 && m.point[2] < 0.51))
        .collect();
    match fit_grid(names(3), &missing, &options) {
        Err(e @ BuildError::MissingGridNode { dims: 3, .. }) => {
            assert!(e.to_string().contains("has no data"), "{e}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn refusals_are_typed() {
    let ok = |axes: Vec<Vec<f64>>, names: Vec<String>| {
        let n: usize = axes.iter().map(Vec::len).product();
        GridMap::new(axes, names, 1, 1, vec![0.0; n], vec![0.0; n])
    };
    assert!(matches!(
        ok(vec![], vec![]),
        Err(BuildError::InvalidParameter {
            what: "grid dimensions",
            ..
        })
    ));
    assert!(matches!(
        ok(vec![vec![0.0, 1.0]; 5], names(4)),
        Err(BuildError::InvalidParameter { .. })
    ));
    assert!(matches!(
        ok(vec![vec![0.0, 1.0]; 2], vec!["x".into(), "x".into()]),
        Err(BuildError::InvalidEntry { index: 1, .. })
    ));
    assert!(matches!(
        ok(vec![vec![0.0, 1.0], vec![0.0]], names(2)),
        Err(BuildError::TooFew {
            what: "axis 1 nodes",
            ..
        })
    ));
    assert!(matches!(
        ok(vec![vec![0.0, 1.0], vec![0.0, 0.0]], names(2)),
        Err(BuildError::NotIncreasing { what: "axis 1", .. })
    ));
    let big: Vec<f64> = (0..40).map(f64::from).collect();
    assert!(matches!(
        ok(vec![big.clone(), big.clone(), big.clone(), big], names(4)),
        Err(BuildError::Budget {
            limit: MAX_GRID_NODES,
            requested: 2_560_000,
            ..
        })
    ));
    let map = ok(
        vec![vec![0.0, 1.0], vec![0.0, 2.0], vec![0.0, 3.0]],
        names(3),
    )
    .unwrap();
    let mut out = [0.0];
    assert!(matches!(
        map.displacement(&[0.5, 1.0, 9.0], &[1.0], &mut out),
        Err(TickError::OutOfGrid { axis: 2, .. })
    ));
    assert!(matches!(
        map.displacement(&[0.5, 1.0], &[1.0], &mut out),
        Err(TickError::WrongLength { what: "point", .. })
    ));
    assert!(matches!(
        map.displacement(&[0.5, f64::NAN, 1.0], &[1.0], &mut out),
        Err(TickError::NonFinite { .. })
    ));
    let clamped = map
        .displacement_with(
            &[0.5, 1.0, 9.0],
            &[1.0],
            &mut out,
            QueryOptions {
                interpolation: Interpolation::Bilinear,
                out_of_grid: OutOfGrid::Clamp,
            },
        )
        .unwrap();
    assert_eq!(clamped, Placement::Clamped);
    // A batch names its first bad row.
    let mut outs = [0.0; 3];
    let e = map
        .displacement_batch(
            &[0.5, 1.0, 1.0, 0.5, 1.0, 7.0, 0.1, 0.1, 0.1],
            &[1.0],
            &mut outs,
        )
        .unwrap_err();
    assert_eq!(e.row, 1);
}

#[test]
fn a_3d_map_round_trips_through_json_version_2_bit_for_bit() {
    use deflect_core::io::map_json;
    let axes = vec![axis(0.0, 3), axis(0.1, 4), axis(0.5, 3)];
    let map = map_with(axes, 2, 3, |p, c| {
        1e-6 * noise(c + (p[2] * 1e4) as usize) / 3.0
    })
    .with_options(QueryOptions {
        interpolation: Interpolation::Bicubic,
        out_of_grid: OutOfGrid::Clamp,
    });
    let text = map_json::grid_to_string(&map).unwrap();
    assert!(text.contains("\"format_version\": 2"));
    assert_eq!(map_json::grid_from_str(&text).unwrap(), map);
    // A 3-D grid is not a 2-D compliance map.
    assert!(map_json::from_str(&text).is_err());
}

#[test]
fn a_csv_of_static_tests_names_its_grid_axes_and_converts_units() {
    use deflect_core::error::LoadError;
    use deflect_core::io::grid_csv;
    use deflect_core::units::{ForceUnit, LengthUnit};
    // A serial arm's compliance over its elbow angles q2, q3 (degrees), displacements in mm,
    // forces in N: dx = (1e-3 mm/N * (1 + q2 [rad])) F, dy = 2e-3 mm/N F + 0.01 mm.
    let mut text = String::from("q2_deg, q3_deg, force_axis, force, dx, dy\n");
    for q2 in [10.0, 20.0, 40.0] {
        for q3 in [-30.0, 0.0] {
            for f in [-100.0, 100.0] {
                let s = 1e-3 * (1.0 + f64::to_radians(q2));
                text += &format!("{q2}, {q3}, x, {f}, {}, {}\n", s * f, 2e-3 * f + 0.01);
            }
        }
    }
    let map =
        grid_csv::fit_static_str(&text, ForceUnit::Newton, LengthUnit::Millimetre, None, 1e-9)
            .unwrap();
    assert_eq!(map.names(), ["q2", "q3"]);
    assert!((map.axes()[0][1] - 20f64.to_radians()).abs() < 1e-15);
    let mut d = [0.0; 2];
    map.displacement(&[30f64.to_radians(), -15f64.to_radians()], &[50.0], &mut d)
        .unwrap();
    // Linear in q2 between its nodes: exact multilinear; SI out.
    let want = 1e-6 * (1.0 + 30f64.to_radians()) * 50.0;
    assert!((d[0] - want).abs() < 1e-18, "{d:?}");
    assert!((d[1] - (2e-6 * 50.0 + 1e-5)).abs() < 1e-18, "{d:?}");
    // Refusals name the column or the row.
    let bad = text.replacen("q3_deg", "q3", 1);
    assert_eq!(
        grid_csv::fit_static_str(&bad, ForceUnit::Newton, LengthUnit::Metre, None, 1e-9)
            .unwrap_err(),
        LoadError::UnknownColumn {
            column: "q3".into()
        }
    );
    let bad = text.replacen("10, -30, x, -100", "10, -30, x, oops", 1);
    assert!(matches!(
        grid_csv::fit_static_str(&bad, ForceUnit::Newton, LengthUnit::Metre, None, 1e-9)
            .unwrap_err(),
        LoadError::BadNumber {
            row: 0,
            column: "force"
        }
    ));
}

#[test]
fn the_tick_shape_serves_the_grid_map() {
    use deflect_core::compliance_map::{self, Data};
    // 2 x 2 x 2 nodes, one force and one displacement axis; compliance affine in the
    // coordinates, 1e-6 (1 + x + y + z) m/N, which trilinear interpolation reproduces: at
    // (0.5, 1, 2) it is 4.5e-6 m/N, so 100 N give 4.5e-4 m.
    let axes = vec![vec![0.0, 1.0], vec![0.0, 2.0], vec![0.0, 4.0]];
    let mut slopes = Vec::new();
    for x in [0.0, 1.0] {
        for y in [0.0, 2.0] {
            for z in [0.0, 4.0] {
                slopes.push(1e-6 * (1.0 + x + y + z));
            }
        }
    }
    let grid = GridMap::new(axes, names(3), 1, 1, slopes, vec![0.0; 8]).unwrap();
    let mut data = Data::new(&grid);
    assert!(data.check(&grid));
    let placement = compliance_map::step_grid(&grid, &mut data, &[0.5, 1.0, 2.0], &[100.0]);
    assert_eq!(placement, Ok(Placement::Inside));
    assert_eq!(data.placement, Placement::Inside);
    assert_eq!(data.displacement().len(), 1);
    assert!(
        (data.displacement()[0] - 4.5e-4).abs() < 1e-18,
        "{:?}",
        data.displacement()
    );
    // The tick shape is the grid's own query, bit for bit.
    let mut direct = [0.0];
    grid.displacement(&[0.5, 1.0, 2.0], &[100.0], &mut direct)
        .unwrap();
    assert_eq!(data.displacement()[0].to_bits(), direct[0].to_bits());
    // Wrong input is typed, and the workspace keeps its last answer.
    assert!(matches!(
        compliance_map::step_grid(&grid, &mut data, &[0.5, 1.0], &[100.0]),
        Err(TickError::WrongLength {
            what: "point",
            expected: 3,
            got: 2
        })
    ));
    assert!(matches!(
        compliance_map::step_grid(&grid, &mut data, &[0.5, 1.0, 4.5], &[100.0]),
        Err(TickError::OutOfGrid { axis: 2, .. })
    ));
    assert_eq!(data.displacement()[0].to_bits(), direct[0].to_bits());
    // A workspace made for a map of other axis counts is refused.
    let map2 = ComplianceMap::new(
        vec![0.0, 1.0],
        vec![0.0, 1.0],
        2,
        2,
        vec![0.0; 16],
        vec![0.0; 16],
    )
    .unwrap();
    let mut other = Data::new(&map2);
    assert!(!other.check(&grid));
    assert!(matches!(
        compliance_map::step_grid(&grid, &mut other, &[0.5, 1.0, 2.0], &[100.0]),
        Err(TickError::ModelMismatch {
            what: "map axes",
            ..
        })
    ));
}
