//! Compliance map (Paksoy et al. 2025, Eq. 9-14) against the published Tables II/III, by hand
//! between nodes, and its interpolation and out-of-grid options.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use deflect_core::compliance_map::{
    ComplianceMap, Interpolation, Measurement, OutOfGrid, two_point_displacement,
};
use deflect_core::io::map_csv;
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_core::{BuildError, Placement, TickError};

mod fixtures;
use fixtures::maps::*;

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
