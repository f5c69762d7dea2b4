//! ns per compliance-map query (Paksoy et al. Eq. 9-14): bilinear and bicubic, evenly spaced
//! (O(1) cell lookup) and uneven (binary search) grids. Each iteration is one query; the
//! positions cycle over 1024 precomputed points inside the grid.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use deflect_core::compliance_map::{
    ComplianceMap, GridMap, Interpolation, OutOfGrid, QueryOptions,
};
use deflect_core::io::map_csv;
use deflect_core::units::{ForceUnit, LengthUnit};

fn maps() -> (ComplianceMap, ComplianceMap) {
    let path = deflect_tests::repo_path("data/paksoy2025_compliance_oc.csv");
    let oc = match map_csv::from_path(path, ForceUnit::Newton, LengthUnit::Millimetre) {
        Ok(m) => m,
        Err(e) => panic!("the shipped OC table must load: {e}"),
    };
    let uneven = match ComplianceMap::new(
        vec![0.172132, 0.2, 0.272132],
        vec![-0.075, -0.05, 0.0, 0.01, 0.075],
        2,
        2,
        oc.slopes().to_vec(),
        oc.offsets().to_vec(),
    ) {
        Ok(m) => m,
        Err(e) => panic!("{e}"),
    };
    (oc, uneven)
}

/// A hand-written 2 x 2 bilinear lookup on an evenly spaced grid: the floor a controller
/// author would write in C++ (no input checks, positions assumed inside).
struct Hand {
    x0: f64,
    y0: f64,
    inv_dx: f64,
    inv_dy: f64,
    ny: usize,
    last_i: usize,
    last_j: usize,
    /// Per node: s_xx, s_xy, s_yx, s_yy, offset sum x, offset sum y.
    node: Vec<[f64; 6]>,
}

impl Hand {
    fn new(map: &ComplianceMap) -> Self {
        let (x, y) = (map.x(), map.y());
        let (nx, ny) = (x.len(), y.len());
        let node = (0..nx * ny)
            .map(|n| {
                let s = &map.slopes()[n * 4..n * 4 + 4];
                let o = &map.offsets()[n * 4..n * 4 + 4];
                [s[0], s[1], s[2], s[3], o[0] + o[1], o[2] + o[3]]
            })
            .collect();
        Self {
            x0: x[0],
            y0: y[0],
            inv_dx: (nx - 1) as f64 / (x[nx - 1] - x[0]),
            inv_dy: (ny - 1) as f64 / (y[ny - 1] - y[0]),
            ny,
            last_i: nx - 2,
            last_j: ny - 2,
            node,
        }
    }

    #[inline(always)]
    fn query(&self, p: [f64; 2], f: [f64; 2]) -> [f64; 2] {
        let u = (p[0] - self.x0) * self.inv_dx;
        let v = (p[1] - self.y0) * self.inv_dy;
        let i = (u as usize).min(self.last_i);
        let j = (v as usize).min(self.last_j);
        let (tx, ty) = (u - i as f64, v - j as f64);
        let n = i * self.ny + j;
        let val = |c: &[f64; 6]| {
            [
                c[0] * f[0] + c[1] * f[1] + c[4],
                c[2] * f[0] + c[3] * f[1] + c[5],
            ]
        };
        let (a, b) = (val(&self.node[n]), val(&self.node[n + 1]));
        let (c, d) = (
            val(&self.node[n + self.ny]),
            val(&self.node[n + self.ny + 1]),
        );
        let w = [
            (1.0 - tx) * (1.0 - ty),
            (1.0 - tx) * ty,
            tx * (1.0 - ty),
            tx * ty,
        ];
        [
            w[0] * a[0] + w[1] * b[0] + w[2] * c[0] + w[3] * d[0],
            w[0] * a[1] + w[1] * b[1] + w[2] * c[1] + w[3] * d[1],
        ]
    }
}

fn bench(c: &mut Criterion) {
    let (even, uneven) = maps();
    let points: Vec<([f64; 2], [f64; 2])> = (0..1024)
        .map(|k| {
            let t = k as f64 * 0.618_033_988_749_895;
            (
                [
                    0.172132 + 0.1 * t.fract(),
                    -0.075 + 0.15 * (t * 1.7).fract(),
                ],
                [
                    300.0 * (t * 2.3).fract() - 150.0,
                    245.25 * (t * 3.1).fract(),
                ],
            )
        })
        .collect();
    let mut group = c.benchmark_group("compliance_map");
    // What this CPU can do: the hand-written lookup of a C++ controller (uniform 2 x 2 map,
    // no checks, no out-of-grid policy), timed the same way, for same-run ratios.
    let hand = Hand::new(&even);
    let mut k = 0usize;
    group.bench_function("reference_hand/even", |b| {
        b.iter(|| {
            k = (k + 1) & 1023;
            let (p, f) = points.get(k).copied().unwrap_or_default();
            black_box(hand.query(black_box(p), black_box(f)))
        })
    });
    for (name, map) in [("even", &even), ("uneven", &uneven)] {
        for method in [Interpolation::Bilinear, Interpolation::Bicubic] {
            let options = QueryOptions {
                interpolation: method,
                out_of_grid: OutOfGrid::Error,
            };
            let mut k = 0usize;
            let mut out = [0.0; 2];
            group.bench_function(format!("{method:?}/{name}"), |b| {
                b.iter(|| {
                    k = (k + 1) & 1023;
                    let (p, f) = points.get(k).copied().unwrap_or_default();
                    let s = map.displacement_with(black_box(p), black_box(&f), &mut out, options);
                    black_box((s, out))
                })
            });
        }
    }
    // 1024 single queries back to back through the per-query API (what a loop over
    // `displacement` costs per call without the harness's per-iteration overhead).
    group.throughput(criterion::Throughput::Elements(1024));
    let bilinear = QueryOptions {
        interpolation: Interpolation::Bilinear,
        out_of_grid: OutOfGrid::Error,
    };
    group.bench_function("single_x1024/Bilinear/even", |b| {
        b.iter(|| {
            let mut acc = [0.0; 2];
            let mut out = [0.0; 2];
            for (p, f) in &points {
                if even.displacement_with(*p, f, &mut out, bilinear).is_ok() {
                    acc[0] += out[0];
                    acc[1] += out[1];
                }
            }
            black_box(acc)
        })
    });
    group.bench_function("single_x1024/reference_hand/even", |b| {
        b.iter(|| {
            let mut acc = [0.0; 2];
            for (p, f) in &points {
                let r = hand.query(*p, *f);
                acc[0] += r[0];
                acc[1] += r[1];
            }
            black_box(acc)
        })
    });
    group.throughput(criterion::Throughput::Elements(1));
    // A displacement field at a fixed load (`ComplianceMap::field`): position-only queries.
    let field = match even.field(&[-120.0, 245.25]) {
        Ok(f) => f,
        Err(e) => panic!("{e}"),
    };
    let mut k = 0usize;
    let mut fout = [0.0; 2];
    group.bench_function("field/Bilinear/even", |b| {
        b.iter(|| {
            k = (k + 1) & 1023;
            let (p, _) = points.get(k).copied().unwrap_or_default();
            let s = field.displacement(black_box(p), &mut fout);
            black_box((s, fout))
        })
    });
    // 1e5 queries in one allocation-free batch call (the path the Python binding uses).
    let n = 100_000;
    let mut pos = Vec::with_capacity(2 * n);
    let mut force = Vec::with_capacity(2 * n);
    for k in 0..n {
        let (p, f) = points.get(k % 1024).copied().unwrap_or_default();
        pos.extend_from_slice(&p);
        force.extend_from_slice(&f);
    }
    let mut out = vec![0.0; 2 * n];
    group.throughput(criterion::Throughput::Elements(n as u64));
    for method in [Interpolation::Bilinear, Interpolation::Bicubic] {
        let options = QueryOptions {
            interpolation: method,
            out_of_grid: OutOfGrid::Error,
        };
        group.bench_function(format!("batch_1e5/{method:?}/even"), |b| {
            b.iter(|| {
                black_box(even.displacement_batch(black_box(&pos), 2, &force, &mut out, options))
            })
        });
    }
    // The same batch over uniformly random points (a workspace sweep, what a Python batch
    // gets): no pattern for the branch predictor to learn.
    let mut state = 0x9E37_79B9_7F4A_7C15_u64;
    let mut uniform = move || {
        // xorshift64*: a fixed, reproducible sequence in [0, 1).
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut rpos = Vec::with_capacity(2 * n);
    for _ in 0..n {
        rpos.push(0.172132 + 0.1 * uniform());
        rpos.push(-0.075 + 0.15 * uniform());
    }
    let bilinear = QueryOptions {
        interpolation: Interpolation::Bilinear,
        out_of_grid: OutOfGrid::Error,
    };
    group.bench_function("batch_1e5/Bilinear/even_random", |b| {
        b.iter(|| {
            black_box(even.displacement_batch(black_box(&rpos), 2, &force, &mut out, bilinear))
        })
    });
    // The hand-written lookup over a whole batch, row by row.
    let hand_batch = |pos: &[f64], out: &mut [f64]| {
        for ((p, f), o) in pos
            .chunks_exact(2)
            .zip(force.chunks_exact(2))
            .zip(out.chunks_exact_mut(2))
        {
            o.copy_from_slice(&hand.query([p[0], p[1]], [f[0], f[1]]));
        }
        black_box(&*out);
    };
    group.bench_function("batch_1e5/reference_hand/even_random", |b| {
        b.iter(|| hand_batch(&rpos, &mut out))
    });
    group.bench_function("batch_1e5/reference_hand/even", |b| {
        b.iter(|| hand_batch(&pos, &mut out))
    });
    group.finish();
    grid_map(c, &even, &points);
}

/// The N-D `GridMap` on the same queries: over two axes it is the 2-D map's fast path (the
/// 2-D map's kernels); over three (the 2-D grid with a third axis of 3 nodes, the query at
/// its middle) the general tensor-product path.
fn grid_map(c: &mut Criterion, even: &ComplianceMap, points: &[([f64; 2], [f64; 2])]) {
    let planar = GridMap::from_map(even);
    let (x, y) = (even.x().to_vec(), even.y().to_vec());
    let nodes = x.len() * y.len();
    let block = even.n_force() * even.n_displacement();
    let (mut slopes, mut offsets) = (Vec::new(), Vec::new());
    for node in 0..nodes {
        let range = node * block..(node + 1) * block;
        let s = even.slopes().get(range.clone()).unwrap_or(&[]);
        let o = even.offsets().get(range).unwrap_or(&[]);
        for _ in 0..3 {
            slopes.extend_from_slice(s);
            offsets.extend_from_slice(o);
        }
    }
    let names = ["x", "y", "z"].map(String::from).to_vec();
    let spatial = match GridMap::new(
        vec![x, y, vec![0.0, 0.5, 1.0]],
        names,
        even.n_force(),
        even.n_displacement(),
        slopes,
        offsets,
    ) {
        Ok(m) => m,
        Err(e) => panic!("{e}"),
    };
    let mut group = c.benchmark_group("grid_map");
    for method in [Interpolation::Bilinear, Interpolation::Bicubic] {
        let options = QueryOptions {
            interpolation: method,
            out_of_grid: OutOfGrid::Error,
        };
        let mut k = 0usize;
        let mut out = [0.0; 2];
        group.bench_function(format!("{method:?}/2d_even"), |b| {
            b.iter(|| {
                k = (k + 1) & 1023;
                let (p, f) = points.get(k).copied().unwrap_or_default();
                let s = planar.displacement_with(black_box(&p), black_box(&f), &mut out, options);
                black_box((s, out))
            })
        });
        group.bench_function(format!("{method:?}/3d_even"), |b| {
            b.iter(|| {
                k = (k + 1) & 1023;
                let (p, f) = points.get(k).copied().unwrap_or_default();
                let q = [p[0], p[1], 0.25];
                let s = spatial.displacement_with(black_box(&q), black_box(&f), &mut out, options);
                black_box((s, out))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
