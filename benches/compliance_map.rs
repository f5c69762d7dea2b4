//! ns per compliance-map query (Paksoy et al. Eq. 9-14): bilinear and bicubic, evenly spaced
//! (O(1) cell lookup) and uneven (binary search) grids. Each iteration is one query; the
//! positions cycle over 1024 precomputed points inside the grid.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use deflect_core::compliance_map::{ComplianceMap, Interpolation, OutOfGrid, QueryOptions};
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
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
