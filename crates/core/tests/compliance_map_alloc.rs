//! `displacement` allocates nothing: a counting global allocator over 1e4 queries. Its own
//! test binary with a single test, so nothing else allocates while it counts.
#![allow(unsafe_code)] // reason: a GlobalAlloc impl is unsafe by definition; it only forwards to System
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use deflect_core::compliance_map::{
    ComplianceMap, ForceUnit, Interpolation, LengthUnit, OutOfGrid, QueryOptions,
};

mod common;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

#[test]
fn displacement_allocates_nothing() {
    common::watch_this_thread();
    common::assert_counter_works();
    let text = include_str!("../../../data/paksoy2025_compliance_oc.csv");
    let oc =
        ComplianceMap::from_paper_csv(text, ForceUnit::Newton, LengthUnit::Millimetre).unwrap();
    // An unevenly spaced copy exercises the binary-search lookup.
    let uneven = ComplianceMap::new(
        vec![0.17, 0.2, 0.27],
        vec![-0.075, -0.05, 0.0, 0.01, 0.075],
        2,
        2,
        oc.slopes().to_vec(),
        oc.offsets().to_vec(),
    )
    .unwrap();
    let maps = [&oc, &uneven];
    let options = [
        (Interpolation::Bilinear, OutOfGrid::Error),
        (Interpolation::Bicubic, OutOfGrid::Error),
        (Interpolation::Bilinear, OutOfGrid::Clamp),
        (Interpolation::Bicubic, OutOfGrid::Extrapolate),
    ]
    .map(|(interpolation, out_of_grid)| QueryOptions {
        interpolation,
        out_of_grid,
    });
    let prepared: (Vec<f64>, Vec<f64>, Vec<f64>) = (
        (0..1000)
            .flat_map(|k| [0.18 + 0.00009 * k as f64, -0.07 + 0.00014 * k as f64])
            .collect(),
        (0..2000).map(|k| (k % 7) as f64 * 30.0).collect(),
        vec![0.0; 2000],
    );
    let mut out = [0.0; 2];
    let (mut ok, mut refused, mut checksum) = (0usize, 0usize, 0.0);
    let before = common::allocations();
    for k in 0..10_000 {
        let t = k as f64 * 0.618_033_988_749_895;
        // Mostly inside, some outside the grid (x 0.15..0.29 m, y -0.09..0.09 m).
        let p = [0.15 + 0.14 * t.fract(), -0.09 + 0.18 * (t * 1.7).fract()];
        let f = [
            300.0 * (t * 2.3).fract() - 150.0,
            245.25 * (t * 3.1).fract(),
        ];
        let map = maps[k % 2];
        match map.displacement_with(p, &f, &mut out, options[k % 4]) {
            Ok(_) => {
                ok += 1;
                checksum += out[0] + out[1];
            }
            Err(_) => refused += 1,
        }
    }
    // The batch path, into buffers allocated before counting started.
    let (pos, force, mut batch_out) = prepared;
    let batch = oc.displacement_batch(&pos, 2, &force, &mut batch_out, QueryOptions::default());
    let after = common::allocations();
    assert_eq!(batch.map(|s| s.inside), Ok(1000));
    assert_eq!(
        after - before,
        0,
        "displacement allocated {} times",
        after - before
    );
    assert_eq!(ok + refused, 10_000);
    assert!(ok > 7_000 && refused > 100, "ok {ok}, refused {refused}");
    assert!(checksum.is_finite() && checksum != 0.0);
}
