//! The compliance map's query kernels: batch, packed and plain layouts and the displacement
//! field agree with the single query bit for bit.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use deflect_core::compliance_map::{
    ComplianceMap, ComplianceMapView, Interpolation, OutOfGrid, QueryOptions,
};
use deflect_core::{BuildError, Placement, TickError};
use proptest::prelude::*;

mod fixtures;
use fixtures::maps::*;

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

/// The blocked batch of evenly spaced maps (64 rows a block): rows at every node coordinate
/// and one ulp either side (where the cell estimate `(x - x0) / step` rounds to the wrong
/// cell and the single query corrects it), rows outside and non-finite rows scattered across
/// block edges: every row the single query's bits, and a refused row reported by its index.
#[test]
fn blocked_batch_equals_single_at_rounding_edges() {
    // Nodes 0.1 apart from 0.1: x0 + k step is not exactly the stored node for every k.
    let x: Vec<f64> = (0..7).map(|k| 0.1 + 0.1 * k as f64).collect();
    let y: Vec<f64> = (0..5).map(|k| -0.3 + 0.15 * k as f64).collect();
    let nodes = x.len() * y.len();
    let coef = |k: usize| ((k as f64) * 0.7548776662466927).fract() * 1e-5 - 4e-6;
    let slopes: Vec<f64> = (0..4 * nodes).map(coef).collect();
    let offsets: Vec<f64> = (0..4 * nodes).map(|k| coef(k + 1000)).collect();
    let map = ComplianceMap::new(x.clone(), y.clone(), 2, 2, slopes, offsets).unwrap();
    let mut pos = Vec::new();
    for (a, b) in x.iter().zip(y.iter().cycle()) {
        for v in [a.next_down(), *a, a.next_up()] {
            for w in [b.next_down(), *b, b.next_up()] {
                pos.push([v, w]);
            }
        }
    }
    let n_edges = pos.len();
    for k in 0..300 {
        let t = k as f64 * 0.618_033_988_749_895;
        pos.push([0.05 + 0.75 * t.fract(), -0.35 + 0.7 * (t * 1.7).fract()]);
    }
    let n = pos.len();
    let force: Vec<f64> = (0..2 * n)
        .map(|k| 200.0 * ((k as f64) * 0.37).sin())
        .collect();
    let flat: Vec<f64> = pos.iter().flatten().copied().collect();
    for policy in [OutOfGrid::Clamp, OutOfGrid::Extrapolate] {
        let o = opts(Interpolation::Bilinear, policy);
        let mut out = vec![0.0; 2 * n];
        let summary = map
            .displacement_batch(&flat, 2, &force, &mut out, o)
            .unwrap();
        assert!(
            summary.inside > n_edges / 2 && summary.inside < n,
            "{summary:?}"
        );
        for (k, p) in pos.iter().enumerate() {
            let single = query(&map, *p, [force[2 * k], force[2 * k + 1]], o);
            assert_eq!(single[0].to_bits(), out[2 * k].to_bits(), "row {k} {p:?}");
            assert_eq!(
                single[1].to_bits(),
                out[2 * k + 1].to_bits(),
                "row {k} {p:?}"
            );
        }
    }
    // A NaN force in the second block, after rows inside and outside the grid: that row.
    let mut bad = force.clone();
    bad[2 * 100 + 1] = f64::NAN;
    let mut out = vec![0.0; 2 * n];
    let o = opts(Interpolation::Bilinear, OutOfGrid::Clamp);
    let err = map
        .displacement_batch(&flat, 2, &bad, &mut out, o)
        .unwrap_err();
    assert_eq!(
        (err.row, err.error),
        (
            100,
            TickError::NonFinite {
                what: "force",
                index: 1
            }
        )
    );
    // An infinite position in the third block.
    let mut bad = flat.clone();
    bad[2 * 150] = f64::INFINITY;
    let err = map
        .displacement_batch(&bad, 2, &force, &mut out, o)
        .unwrap_err();
    assert_eq!(err.row, 150);
    assert!(matches!(
        err.error,
        TickError::NonFinite {
            what: "position",
            index: 0
        }
    ));
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

/// The batch of evenly spaced maps for positions of stride 2 (four rows at a time in AVX2
/// lanes where the CPU has them), for each fixed shape (2 x 2, 3 x 3, 6 x 6): every row the
/// single query's bits, with axes held in registers (3 and 9 nodes) and read from memory
/// (40 nodes), rows outside the grid, non-finite rows and a last group of three rows.
#[test]
fn lane_batch_equals_single_for_every_shape() {
    for (nd, nf) in [(2, 2), (3, 3), (6, 6)] {
        for nx in [3, 9, 40] {
            let x: Vec<f64> = (0..nx)
                .map(|k| 0.15 + 0.1 / (nx - 1) as f64 * k as f64)
                .collect();
            let y: Vec<f64> = (0..5).map(|k| -0.075 + 0.0375 * k as f64).collect();
            let values = nx * y.len() * nd * nf;
            let coef = |k: usize| ((k as f64) * 0.754_877_666_246_692_7).fract() * 1e-5 - 4e-6;
            let slopes: Vec<f64> = (0..values).map(coef).collect();
            let offsets: Vec<f64> = (0..values).map(|k| coef(k + 7777)).collect();
            let map = ComplianceMap::new(x.clone(), y.clone(), nf, nd, slopes, offsets).unwrap();
            let n = 403;
            let mut pos = Vec::new();
            for k in 0..n {
                let t = k as f64 * 0.618_033_988_749_895;
                let (mut px, py) = (0.14 + 0.12 * t.fract(), -0.08 + 0.16 * (t * 1.7).fract());
                if k % 97 == 5 {
                    px = f64::NAN;
                }
                if k % 41 == 3 {
                    px = x[k % nx]; // on a node
                }
                pos.extend_from_slice(&[px, py]);
            }
            let force: Vec<f64> = (0..nf * n)
                .map(|k| 200.0 * ((k as f64) * 0.37).sin())
                .collect();
            let o = opts(Interpolation::Bilinear, OutOfGrid::Extrapolate);
            let mut out = vec![0.0; nd * n];
            let err = map
                .displacement_batch(&pos, 2, &force, &mut out, o)
                .unwrap_err();
            assert_eq!(
                (err.row, err.error),
                (
                    5,
                    TickError::NonFinite {
                        what: "position",
                        index: 0
                    }
                ),
                "{nd}x{nf}, {nx} nodes"
            );
            for k in (5..n).step_by(97) {
                pos[2 * k] = 0.2;
            }
            let summary = map
                .displacement_batch(&pos, 2, &force, &mut out, o)
                .unwrap();
            assert!(summary.inside > n / 2 && summary.inside < n, "{summary:?}");
            assert_eq!(summary.inside + summary.extrapolated, n);
            let mut single = vec![0.0; nd];
            for k in 0..n {
                let (p, f) = ([pos[2 * k], pos[2 * k + 1]], &force[nf * k..nf * (k + 1)]);
                map.displacement_with(p, f, &mut single, o).unwrap();
                for d in 0..nd {
                    assert_eq!(
                        single[d].to_bits(),
                        out[nd * k + d].to_bits(),
                        "{nd}x{nf}, {nx} nodes, row {k} axis {d}"
                    );
                }
            }
        }
    }
}

/// The owning map's single query on an evenly spaced grid (its own path, without a view) and
/// the view's path give the same bits and the same errors: at the fixed sizes and one generic
/// size, on every node and either side of it (where `x0 + k step` and the stored node differ
/// by rounding), between nodes, outside the grid under every policy, with non-finite input
/// and with a wrong force length.
#[test]
fn the_owning_maps_even_grid_query_is_the_views() {
    let x: Vec<f64> = (0..7).map(|k| 0.1 + 0.1 * k as f64).collect();
    let y: Vec<f64> = (0..5).map(|k| -0.3 + 0.15 * k as f64).collect();
    let mut points = Vec::new();
    for a in &x {
        for b in &y {
            for v in [a.next_down(), *a, a.next_up()] {
                for w in [b.next_down(), *b, b.next_up()] {
                    points.push([v, w]);
                }
            }
        }
    }
    for k in 0..200 {
        let t = k as f64 * 0.618_033_988_749_895;
        points.push([0.05 + 0.75 * t.fract(), -0.35 + 0.7 * (t * 1.7).fract()]);
    }
    points.extend([[f64::NAN, 0.0], [0.2, f64::INFINITY], [-1e300, 1e300]]);
    for (nd, nf) in [(2, 2), (3, 3), (6, 6), (3, 2)] {
        let n = x.len() * y.len() * nd * nf;
        let coef = |k: usize, s: f64| ((k as f64 * s).sin() * 1e-6) + 1e-7;
        let slopes: Vec<f64> = (0..n).map(|k| coef(k, 0.37)).collect();
        let offsets: Vec<f64> = (0..n).map(|k| coef(k, 0.71)).collect();
        let map = ComplianceMap::new(x.clone(), y.clone(), nf, nd, slopes, offsets).unwrap();
        let forces = [
            (0..nf).map(|k| 150.0 - 40.0 * k as f64).collect::<Vec<_>>(),
            (0..nf)
                .map(|k| if k == 0 { f64::NAN } else { 1.0 })
                .collect(),
            (0..nf)
                .map(|k| if k == 0 { 1e308 } else { -1e308 })
                .collect(),
            vec![1.0; nf + 1],
        ];
        let mut checked = 0;
        for f in &forces {
            for p in &points {
                for method in [Interpolation::Bilinear, Interpolation::Bicubic] {
                    for policy in [OutOfGrid::Error, OutOfGrid::Clamp, OutOfGrid::Extrapolate] {
                        let o = opts(method, policy);
                        let (mut a, mut b) = (vec![0.0; nd], vec![0.0; nd]);
                        let own = map.displacement_with(*p, f, &mut a, o);
                        let view = map.view().displacement_with(*p, f, &mut b, o);
                        assert_eq!(own, view, "{nd}x{nf} {p:?} {f:?} {o:?}");
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(&a), bits(&b), "{nd}x{nf} {p:?} {f:?} {o:?}");
                        checked += usize::from(own == Ok(Placement::Inside));
                    }
                }
            }
        }
        assert!(checked > 2 * points.len(), "{nd}x{nf}: {checked} inside");
    }
}
