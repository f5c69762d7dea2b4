//! Loading and viewing compliance maps: every malformed file or table is a typed error, and
//! JSON round-trips exactly.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use deflect_core::compliance_map::{ComplianceMapView, FitOptions, Interpolation, OutOfGrid, fit};
use deflect_core::io::{map_csv, map_json};
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_core::{BuildError, LoadError, TickError};

mod fixtures;
use fixtures::maps::*;

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
    let v3 = json.replacen("\"format_version\": 1", "\"format_version\": 3", 1);
    assert_eq!(
        map_json::from_str(&v3).unwrap_err(),
        LoadError::UnsupportedVersion { found: 3 }
    );
    // A version-1 body labelled 2 is read as a grid map and refused for its missing axes.
    let v2 = json.replacen("\"format_version\": 1", "\"format_version\": 2", 1);
    assert!(matches!(
        map_json::from_str(&v2).unwrap_err(),
        LoadError::Json { .. }
    ));
    // The 2-D map as a version-2 grid map reads back as the same map, and the grid reader
    // reads version 1 as the same grid.
    let grid = deflect_core::compliance_map::GridMap::from_map(&map);
    let text = map_json::grid_to_string(&grid).unwrap();
    assert!(text.contains("\"format_version\": 2") && text.contains("\"name\": \"y\""));
    let back = map_json::from_str(&text).unwrap();
    assert_eq!(back.slopes(), map.slopes());
    assert_eq!(back.offsets(), map.offsets());
    assert_eq!(back.x(), map.x());
    assert_eq!(map_json::grid_from_str(&json).unwrap(), grid);
    assert_eq!(map_json::grid_from_str(&text).unwrap(), grid);
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
