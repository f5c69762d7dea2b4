//! The G-code reader against hand-derived programs: SI coordinates, feeds and spindle speeds,
//! arc centres and sweeps from I/J and from R, modal state, and every fault a typed error
//! naming line and column.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use deflect_core::LoadError;
use deflect_core::io::gcode::{self, GcodeOptions, MAX_PROGRAM_LINES};
use deflect_core::machining::{Motion, Plane, Program};
use deflect_core::units::LengthUnit;
use nalgebra::{Vector2, Vector3};

fn read(text: &str) -> Program {
    gcode::from_str(text, &GcodeOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The error of `text`: (line, column, message).
fn fault(text: &str) -> (usize, usize, String) {
    match gcode::from_str(text, &GcodeOptions::default()) {
        Err(LoadError::Program {
            line,
            column,
            message,
        }) => (line, column, message),
        other => panic!("expected a program error for {text:?}, got {other:?}"),
    }
}

fn close(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol
}

#[test]
fn a_program_reads_into_si_moves_with_its_modal_state() {
    let p = read(
        "%\n(groove)\nN10 G21 G90 G17\nN20 G0 X10 Y0 Z5\nN30 G1 Z-2 F600 S13000 M3\n\
         N40 X50 ; modal G1 and F\nN50 G0 Z5\nN60 M5\nN70 G0 X0\nN80 M30\n%\n",
    );
    let lines: Vec<usize> = p.moves.iter().map(|m| m.line).collect();
    assert_eq!(lines, [4, 5, 6, 7, 9]);
    let m = &p.moves;
    assert_eq!(m[0].motion, Motion::Rapid);
    assert_eq!(m[0].start, Vector3::zeros());
    assert_eq!(m[0].end, Vector3::new(0.01, 0.0, 0.005));
    assert_eq!((m[0].feed, m[0].spindle), (0.0, 0.0));
    // F600 mm/min = 0.01 m/s; S13000 rpm = 216.67 rev/s, on from line 5 (M3 on the line).
    assert_eq!(m[1].motion, Motion::Linear);
    assert_eq!(m[1].end, Vector3::new(0.01, 0.0, -0.002));
    assert_eq!(m[1].feed, 600.0 * 1e-3 / 60.0);
    assert_eq!(m[1].spindle, 13000.0 / 60.0);
    assert_eq!(m[2].end, Vector3::new(0.05, 0.0, -0.002));
    assert_eq!(m[2].feed, m[1].feed, "F is modal");
    assert!((m[2].length() - 0.04).abs() < 1e-15);
    assert_eq!(m[4].spindle, 0.0, "M5 on line 8 turns the spindle off");
    assert!((p.cutting_length() - (0.007 + 0.04)).abs() < 1e-15);
}

#[test]
fn incremental_coordinates_inches_and_a_start_offset() {
    let p = read("G91 G1 X10 F100\nX10 Y-5\nG90 X0\n");
    assert!(close(
        &p.moves[1].end,
        &Vector3::new(0.02, -0.005, 0.0),
        1e-15
    ));
    assert_eq!(p.moves[2].end, Vector3::new(0.0, -0.005, 0.0));
    let o = GcodeOptions {
        start: Vector3::new(1.0, 2.0, 3.0),
        units: LengthUnit::Inch,
        ..GcodeOptions::default()
    };
    let p = gcode::from_str("G1 X1 F10\nG91 Z-1\n", &o).unwrap();
    assert_eq!(p.moves[0].start, Vector3::new(1.0, 2.0, 3.0));
    assert_eq!(p.moves[0].end, Vector3::new(0.0254, 2.0, 3.0));
    assert!((p.moves[0].feed - 10.0 * 0.0254 / 60.0).abs() < 1e-18);
    assert!(close(
        &p.moves[1].end,
        &Vector3::new(0.0254, 2.0, 3.0 - 0.0254),
        1e-15
    ));
    // G21 overrides the option's unit before any length.
    let p = gcode::from_str("G21 G1 X1 F10\n", &o).unwrap();
    assert_eq!(p.moves[0].end.x, 1e-3);
    // A repeated position moves nothing and stores no move.
    assert_eq!(read("G1 X1 F10\nX1\nG0 X1 Y0\n").moves.len(), 1);
}

#[test]
fn arcs_from_ij_have_their_centre_and_sweep() {
    // From (50, 0) about (50, 10) clockwise to (60, 10): bottom, left, top, right = 270 deg.
    let p = read("G0 X50 Y0\nG2 X60 Y10 I0 J10 F100\n");
    let Motion::Arc {
        plane,
        center,
        sweep,
    } = p.moves[1].motion
    else {
        panic!("an arc");
    };
    assert_eq!(plane, Plane::Xy);
    assert_eq!(center, Vector3::new(0.05, 0.01, 0.0));
    assert!((sweep + 1.5 * PI).abs() < 1e-15, "{sweep}");
    assert!((p.moves[1].radius() - 0.01).abs() < 1e-17);
    assert!((p.moves[1].length() - 0.01 * 1.5 * PI).abs() < 1e-15);
    // Its quarter points: left of the centre at a third of the sweep.
    assert!(close(
        &p.moves[1].point(1.0 / 3.0),
        &Vector3::new(0.04, 0.01, 0.0),
        1e-15
    ));
    // The same end counter-clockwise: 90 deg.
    let p = read("G0 X50 Y0\nG3 X60 Y10 I0 J10 F100\n");
    let Motion::Arc { sweep, .. } = p.moves[1].motion else {
        panic!("an arc");
    };
    assert!((sweep - FRAC_PI_2).abs() < 1e-15);
    // A helix: z linear in the angle.
    let p = read("G0 X10 Y0\nG3 X10 Y0 I-10 J0 Z-4 F100\n");
    assert!(close(
        &p.moves[1].point(0.5),
        &Vector3::new(-0.01, 0.0, -0.002),
        1e-15
    ));
    let l = (0.02 * PI * 0.02 * PI + 0.004 * 0.004_f64).sqrt();
    assert!((p.moves[1].length() - l).abs() < 1e-15);
}

#[test]
fn a_full_circle_returns_to_its_start() {
    let p = read("G0 X10 Y5 Z-1\nG2 X10 Y5 I7.5 J-2.5 F100\n");
    let m = &p.moves[1];
    let Motion::Arc { sweep, .. } = m.motion else {
        panic!("an arc");
    };
    assert_eq!(sweep, -TAU);
    assert_eq!(m.end, m.start);
    // Along the circle (radius sqrt(7.5^2 + 2.5^2) mm) and back at the start at s -> 1.
    let r = (7.5f64.hypot(2.5)) * 1e-3;
    for s in [0.1, 0.25, 0.5, 0.9] {
        let d = (m.point(s).xy() - Vector2::new(0.0175, 0.0025)).norm();
        assert!((d - r).abs() < 1e-15, "s = {s}: {d}");
    }
    assert!(close(&m.point(1.0 - f64::EPSILON), &m.start, 1e-9));
    assert!((m.length() - TAU * r).abs() < 1e-15);
}

#[test]
fn arcs_from_r_take_the_short_or_the_long_way() {
    // (0, 0) to (10, 10) counter-clockwise with R10: centre (0, 10), 90 deg; R-10: centre
    // (10, 0), 270 deg.
    for (r, centre, sweep) in [
        ("R10", Vector3::new(0.0, 0.01, 0.0), FRAC_PI_2),
        ("R-10", Vector3::new(0.01, 0.0, 0.0), 1.5 * PI),
    ] {
        let p = read(&format!("G3 X10 Y10 {r} F100\n"));
        let Motion::Arc {
            center, sweep: s, ..
        } = p.moves[0].motion
        else {
            panic!("an arc");
        };
        assert!((center - centre).norm() < 1e-15, "{r}: {center}");
        assert!((s - sweep).abs() < 1e-12, "{r}: {s}");
    }
    // Clockwise the sides swap: R10 centre (10, 0), -90 deg.
    let p = read("G2 X10 Y10 R10 F100\n");
    let Motion::Arc { center, sweep, .. } = p.moves[0].motion else {
        panic!("an arc");
    };
    assert!((center - Vector3::new(0.01, 0.0, 0.0)).norm() < 1e-15);
    assert!((sweep + FRAC_PI_2).abs() < 1e-12);
}

#[test]
fn every_fault_names_its_line_and_column() {
    // (program, line, column, words of the message)
    let cases: [(&str, usize, usize, &str); 24] = [
        ("G1 X F100\n", 1, 6, "got \"f100\""),
        (
            "G0 X0 Y0\nG2 X10 Y0 I4 J0 F100\n",
            2,
            4,
            "on the arc's circle",
        ),
        (&format!("G1 X{} F100\n", "9".repeat(400)), 1, 5, "a number"),
        ("G1 X10\n", 1, 1, "feed rate F > 0"),
        ("X10\n", 1, 1, "no motion mode"),
        ("G1 G0 X1\n", 1, 1, "one G code of each modal group"),
        ("G1 X1 F100 (unclosed\n", 1, 12, "closing this comment"),
        ("G1 X1 I2 F100\n", 1, 7, "nothing on the line uses"),
        ("G2 X10 I5 R5 F100\n", 1, 11, "not both"),
        ("G2 X10 F100\n", 1, 1, "centre"),
        ("G2 X30 R10 F100\n", 1, 8, "at least half the chord"),
        ("G2 X0 Y0 R10 F100\n", 1, 1, "a full circle needs I, J, K"),
        ("G0 N10 X1\n", 1, 4, "only at the start"),
        ("G1 X1.2.3 F100\n", 1, 5, "at most one '.'"),
        ("G1 X1 F-5\n", 1, 7, "F >= 0"),
        ("G41 G1 X1 F100\n", 1, 1, "cutter radius compensation"),
        ("G38.2 Z-1 F100\n", 1, 1, "probing"),
        ("G0 X1 A90\n", 1, 7, "rotary"),
        (
            "G17 G2 X1 I0.5 K0 F100\n",
            1,
            16,
            "no K word on an arc in G17",
        ),
        ("M101\n", 1, 1, "user M codes"),
        ("G12 X1\n", 1, 1, "a G code LinuxCNC knows"),
        ("G0 X1 (a (b) c)\n", 1, 10, "nested comments"),
        ("G0 X1\n%\n", 2, 1, "'%' alone on the first line"),
        ("#1=[1/0]\n", 1, 1, "a divisor other than 0"),
    ];
    let mut wrong = Vec::new();
    for (text, line, column, needle) in cases {
        let (l, c, m) = fault(text);
        if (l, c) != (line, column) || !m.contains(needle) {
            wrong.push(format!(
                "{text:?}: got ({l}, {c}) {m:?}; expected ({line}, {column}) with {needle:?}"
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // The message reads as one line naming line and column.
    let e = gcode::from_str("G0 X1\nG1 X10 D1 F100\n", &GcodeOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "program line 2, column 8: expected D: a word nothing on the line uses; only G41 or G42 \
         (not modelled) use it (this line's is G1)"
    );
    // Out of range: 2 km.
    let (_, _, m) = fault("G1 X2000000 F100\n");
    assert!(m.contains("within +-1000 m"), "{m}");
    // Non-ASCII, a stray character.
    assert_eq!(fault("G1 X1 F100 é\n").1, 12);
    assert_eq!(fault("G1 X1 F100 =5\n").1, 12);
}

#[test]
fn budgets_are_typed_errors() {
    let long = "G0 X1\n".repeat(MAX_PROGRAM_LINES + 1);
    assert!(matches!(
        gcode::from_str(&long, &GcodeOptions::default()),
        Err(LoadError::TooLarge { limit, .. }) if limit == MAX_PROGRAM_LINES
    ));
    let bad_start = GcodeOptions {
        start: Vector3::new(f64::NAN, 0.0, 0.0),
        ..GcodeOptions::default()
    };
    assert!(matches!(
        gcode::from_str("G0 X1\n", &bad_start),
        Err(LoadError::InvalidValue { .. })
    ));
}
