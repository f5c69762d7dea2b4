//! Regression tests of the third adversarial pass (inputs accepted silently, files that
//! block): each test replays its reproducer through deflect-core and asserts the typed error
//! or the right value.

use std::time::{Duration, Instant};

use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::io::{grid_csv, points_csv};
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::path::PathOptions;
use deflect_core::mechanism::{Delta, Mechanism};
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_core::{BuildError, LoadError, TickError};
use nalgebra::Vector3;

const POINTS: &str = "x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm\n10,0,0,600,10000\n";

fn with_start(start: [f64; 3]) -> GcodeOptions {
    GcodeOptions {
        start: Vector3::from(start),
        ..GcodeOptions::default()
    }
}

/// A FIFO with no writer: every file reader refuses it at once instead of blocking.
#[test]
fn a_fifo_is_refused_at_once_not_read() {
    let dir = std::env::temp_dir().join(format!("deflect-fifo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("f");
    let _ = std::fs::remove_file(&fifo);
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("mkfifo unavailable: skipped");
        return;
    }
    let t = Instant::now();
    let text = deflect_core::io::read_text_file(&fifo);
    let points = points_csv::from_path(&fifo, &GcodeOptions::default());
    let fit = grid_csv::fit_static_path(&fifo, ForceUnit::Newton, LengthUnit::Metre, None, 1e-6);
    let lossy = deflect_core::io::read_text_lossy(&fifo);
    assert!(t.elapsed() < Duration::from_secs(1));
    for e in [
        text.unwrap_err(),
        points.unwrap_err(),
        fit.unwrap_err(),
        lossy.unwrap_err(),
    ] {
        match e {
            LoadError::Io { path, message } => {
                assert!(path.ends_with("/f"), "{path}");
                assert!(message.contains("not a regular file"), "{message}");
            }
            other => panic!("{other:?}"),
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A points file's start is checked as the G-code reader checks it.
#[test]
fn a_points_file_refuses_a_start_that_is_not_finite_or_past_a_kilometre() {
    for start in [
        [f64::NAN, 0.0, 0.0],
        [0.0, f64::INFINITY, 0.0],
        [0.0, 0.0, 1e300],
        [2000.0, 0.0, 0.0],
    ] {
        let e = points_csv::from_str(POINTS, &with_start(start)).unwrap_err();
        assert!(
            matches!(
                e,
                LoadError::InvalidValue {
                    field: "start (m)",
                    ..
                }
            ),
            "{start:?}: {e:?}"
        );
    }
    // A start within the bounds: the first move's length is the distance to it.
    let p = points_csv::from_str(POINTS, &with_start([0.0, 0.0, 0.01])).unwrap();
    let m = p.moves.first().unwrap();
    assert!(((m.end - m.start).norm() - (0.01f64.powi(2) + 0.01f64.powi(2)).sqrt()).abs() < 1e-15);
}

/// A column given twice is refused, not read once with the other copy dropped.
#[test]
fn a_column_given_twice_is_refused() {
    let twice = "x_mm,x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm\n1,2,0,0,600,1000\n";
    let e = points_csv::from_str(twice, &GcodeOptions::default()).unwrap_err();
    assert!(
        matches!(&e, LoadError::UnknownColumn { column } if column.starts_with("x_mm")),
        "{e:?}"
    );
    // Static tests with two dx columns, and one axis given in two units.
    let fit = |text: &str| {
        grid_csv::fit_static_str(text, ForceUnit::Newton, LengthUnit::Metre, None, 1e-6)
            .unwrap_err()
    };
    let dx2 = "x_m,force_axis,force,dx,dx\n0,0,1,1e-6,2e-6\n";
    assert!(matches!(fit(dx2), LoadError::UnknownColumn { column } if column.starts_with("dx")),);
    let axis2 = "x_m,x_mm,force_axis,force,dx\n0,0,0,1,1e-6\n";
    assert!(
        matches!(fit(axis2), LoadError::UnknownColumn { column } if column.starts_with("x_mm")),
    );
}

/// An arc whose centre lies past `MAX_COORDINATE` is refused where it is read.
#[test]
fn an_arc_centre_past_a_kilometre_is_refused() {
    let e = gcode::from_str("G0 X900000\nG2 I900000 F100\n", &GcodeOptions::default()).unwrap_err();
    match e {
        LoadError::Program { line, message, .. } => {
            assert_eq!(line, 2);
            assert!(message.contains("arc centre"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

/// The Delta: a point above the elbows is not answered with joints whose platform is
/// elsewhere; joints past `MAX_JOINT_POSITION` are refused; lengths below a micrometre too.
#[test]
fn the_delta_refuses_what_it_cannot_mean() {
    let d = Delta::pick_and_place();
    let e = d.ik(&Vector3::new(0.0, 0.0, 0.5)).unwrap_err();
    assert!(matches!(e, TickError::InvalidArgument { .. }), "{e:?}");
    // Below the elbows, ik and fk agree (the working mode).
    let p = Vector3::new(0.05, -0.03, -0.8);
    let q = d.ik(&p).unwrap();
    assert!((d.fk(&q).unwrap() - p).norm() < 1e-12);
    for q in [1e7, 1e300] {
        let q = Vector3::new(q, 0.0, 0.0);
        assert!(matches!(
            d.fk(&q).unwrap_err(),
            TickError::InvalidArgument { .. }
        ));
        let mut data = ();
        assert!(matches!(
            d.jacobian(&mut data, &q).unwrap_err(),
            TickError::InvalidArgument { .. }
        ));
        assert!(matches!(
            d.singularity_distance(&mut data, &q).unwrap_err(),
            TickError::InvalidArgument { .. }
        ));
    }
    assert!(matches!(
        Delta::new(5e-324, 0.045, 0.35, 0.8).unwrap_err(),
        BuildError::InvalidParameter {
            what: "base_radius",
            ..
        }
    ));
    assert!(Delta::new(0.2, 0.045, 0.35, 0.8).is_ok());
}

/// A tool of 5e-324 m and coefficients of 1e200 are refused, not turned into forces.
#[test]
fn a_denormal_tool_and_absurd_coefficients_are_refused() {
    assert!(matches!(
        Tool::new(5e-324, 3, 0.0).unwrap_err(),
        BuildError::InvalidParameter {
            what: "tool diameter",
            ..
        }
    ));
    assert!(Tool::new(1e-5, 2, 0.0).is_ok());
    let c = Coefficients::AL7075_T6_CARBIDE;
    assert!(matches!(
        Coefficients::new(1e200, c.k_rc, c.k_ac, c.k_te, c.k_re, c.k_ae).unwrap_err(),
        BuildError::InvalidParameter { what: "k_tc", .. }
    ));
    assert!(matches!(
        Coefficients::new(c.k_tc, c.k_rc, c.k_ac, c.k_te, c.k_re, 1e200).unwrap_err(),
        BuildError::InvalidParameter { what: "k_ae", .. }
    ));
}

/// A sampling rate of 1e-3 Hz (two samples, errors reading 0) is refused; 1 Hz is taken.
#[test]
fn a_rate_below_one_hertz_is_refused() {
    let o = |rate_hz| PathOptions {
        rate_hz,
        ..PathOptions::default()
    };
    assert!(matches!(
        o(1e-3).validate().unwrap_err(),
        BuildError::InvalidParameter {
            what: "rate_hz",
            ..
        }
    ));
    assert!(o(1.0).validate().is_ok());
}

/// An inch program's arcs (I/J and R) are the millimetre program's scaled by 25.4: the same
/// centres, sweeps and ends.
#[test]
fn inch_arcs_are_the_millimetre_arcs() {
    let read = |text: &str| gcode::from_str(text, &GcodeOptions::default()).unwrap();
    let inch = read("G20 G90 G17\nG1 X1 Y0 F10\nG2 X2 Y1 I0 J1\nG3 X1 Y2 R1\n");
    let mm = read("G21 G90 G17\nG1 X25.4 Y0 F254\nG2 X50.8 Y25.4 I0 J25.4\nG3 X25.4 Y50.8 R25.4\n");
    assert_eq!(inch.moves.len(), mm.moves.len());
    for (i, m) in inch.moves.iter().zip(&mm.moves) {
        assert!((i.end - m.end).norm() < 1e-12, "{:?} vs {:?}", i.end, m.end);
        assert!((i.feed - m.feed).abs() < 1e-12 * m.feed.max(1e-9));
        assert!((i.length() - m.length()).abs() < 1e-12);
        match (i.motion, m.motion) {
            (
                deflect_core::machining::Motion::Arc {
                    center: ci,
                    sweep: si,
                    ..
                },
                deflect_core::machining::Motion::Arc {
                    center: cm,
                    sweep: sm,
                    ..
                },
            ) => {
                assert!((ci - cm).norm() < 1e-12 && (si - sm).abs() < 1e-12);
            }
            (a, b) => assert_eq!(a, b),
        }
    }
    // The first arc by hand: about (25.4, 25.4) mm from below the centre to its right,
    // clockwise: three quarters of a turn.
    let three_quarters = 1.5 * std::f64::consts::PI;
    match mm.moves.get(1).unwrap().motion {
        deflect_core::machining::Motion::Arc { center, sweep, .. } => {
            assert!((center - Vector3::new(0.0254, 0.0254, 0.0)).norm() < 1e-15);
            assert!((sweep + three_quarters).abs() < 1e-12, "{sweep}");
        }
        other => panic!("{other:?}"),
    }
}
