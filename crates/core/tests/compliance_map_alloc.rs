//! `displacement` and the tick-shape `compliance_map::step` and `step_grid` allocate nothing: a counting
//! global allocator over 1e4 queries of each. Its own test binary with a single test, so
//! nothing else allocates while it counts.
#![allow(unsafe_code)] // reason: a GlobalAlloc impl is unsafe by definition; it only forwards to System
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use deflect_core::compliance_map::{
    self, ComplianceMap, ComplianceMapView, GridMap, Interpolation, OutOfGrid, QueryOptions,
};
use deflect_core::io::map_csv;
use deflect_core::units::{ForceUnit, LengthUnit};

mod common;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

#[test]
fn displacement_allocates_nothing() {
    common::watch_this_thread();
    common::assert_counter_works();
    let text = include_str!("../../../data/paksoy2025_compliance_oc.csv");
    let oc = map_csv::from_str(text, ForceUnit::Newton, LengthUnit::Millimetre).unwrap();
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
    // The tick shape: one view per (map, options) and a `Data::new(&view)` for each, made
    // before counting starts.
    let views: Vec<ComplianceMapView<'_>> = (0..8)
        .map(|v| maps[v % 2].view().with_options(options[v / 2]))
        .collect();
    let mut datas: Vec<compliance_map::Data> =
        views.iter().map(compliance_map::Data::new).collect();
    assert!(views.iter().zip(&datas).all(|(v, d)| d.check(v)));
    // The N-D grid map in the same tick shape.
    let grid = GridMap::from_map(&oc);
    let mut grid_data = compliance_map::Data::new(&grid);
    let (mut grid_ok, mut grid_checksum) = (0usize, 0.0);
    let mut out = [0.0; 2];
    let mut direct = [0.0; 2];
    let (mut ok, mut refused, mut checksum) = (0usize, 0usize, 0.0);
    let (mut query_ok, mut query_refused) = (0usize, 0usize);
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
        if compliance_map::step_grid(&grid, &mut grid_data, &p, &f).is_ok() {
            grid_ok += 1;
            grid_checksum += grid_data.displacement()[0];
        }
        // `query` on a view with the same options gives what `view.displacement` gives,
        // bit for bit, placement and errors included.
        let v = (k % 2) + 2 * (k % 4);
        let (view, data) = (&views[v], &mut datas[v]);
        let queried = compliance_map::step(view, data, p, &f);
        let displaced = view.displacement(p, &f, &mut direct);
        assert_eq!(queried, displaced);
        match queried {
            Ok(placement) => {
                query_ok += 1;
                assert_eq!(data.placement, placement);
                assert_eq!(data.displacement().len(), 2);
                assert_eq!(data.displacement()[0].to_bits(), direct[0].to_bits());
                assert_eq!(data.displacement()[1].to_bits(), direct[1].to_bits());
                assert_eq!(data.displacement()[0].to_bits(), out[0].to_bits());
                assert_eq!(data.displacement()[1].to_bits(), out[1].to_bits());
            }
            Err(_) => query_refused += 1,
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
    assert_eq!((query_ok, query_refused), (ok, refused));
    assert!(ok > 7_000 && refused > 100, "ok {ok}, refused {refused}");
    assert!(checksum.is_finite() && checksum != 0.0);
    assert!(grid_ok > 1_000 && grid_checksum.is_finite() && grid_checksum != 0.0);
}
