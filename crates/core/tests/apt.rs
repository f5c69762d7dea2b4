//! The APT / CL reader and the five-axis G-code of a declared machine: statements read by
//! hand, the same motion as APT and as `A B C` G-code on three machine layouts giving the
//! same tool poses (the machine's angles and axes computed here from the rotation matrices
//! written out, not from the reader's chain), and malformed input refused by line and word.

use std::f64::consts::PI;
use std::fmt::Write as _;

use deflect_core::LoadError;
use deflect_core::io::{apt, gcode, points_csv};
use deflect_core::machining::kinematics::{Carrier, Rotary, RotaryWord};
use deflect_core::machining::tools::ToolShape;
use deflect_core::machining::{Kinematics, Motion, Plane};
use nalgebra::{Matrix3, Vector3};

fn read(text: &str) -> apt::AptProgram {
    apt::from_str(text, &gcode::GcodeOptions::default()).unwrap()
}

fn refused(text: &str) -> (usize, String) {
    match apt::from_str(text, &gcode::GcodeOptions::default()) {
        Err(LoadError::Program { line, message, .. }) => (line, message),
        other => panic!("expected a program error, got {other:?}"),
    }
}

#[test]
fn statements_read_as_written() {
    let p = read(
        "PARTNO/TEST $$ a comment\n\
         UNITS/MM\n\
         MULTAX\n\
         LOADTL/3\n\
         CUTTER/10.0,5.0\n\
         SPINDL/RPM,12000,CLW\n\
         RAPID\n\
         GOTO/10,0,20,0,0,1\n\
         FEDRAT/MMPM,600\n\
         GOTO/10,0,0\n\
         GOTO/20,0,0,0.0,-0.5,0.8660254\n\
         GOTO/20,0,$\n\
         0,0.0,-0.5,0.866025404\n\
         CIRCLE/20,10,0,0,0,-1,10\n\
         GOTO/30,10,0\n\
         FEDRAT/0.1,MMPR\n\
         GOTO/40,10,0\n\
         FINI\n\
         GOTO/99,99,99\n",
    );
    let m = &p.program.moves;
    assert_eq!(m.len(), 6, "{m:?}");
    assert_eq!(m[0].motion, Motion::Rapid);
    assert_eq!(m[0].line, 8);
    assert_eq!(m[0].end, Vector3::new(0.01, 0.0, 0.02));
    assert_eq!(m[0].tool, 3);
    assert!((m[0].spindle - 200.0).abs() < 1e-12);
    // The first vector holds from the start; 600 mm/min is 0.01 m/s.
    assert_eq!(m[0].start_axis, Vector3::z());
    assert_eq!(m[1].feed, 0.01);
    // 0.8660254 is within the tolerance: normalised.
    let a = m[2].end_axis;
    assert!(
        (a.norm() - 1.0).abs() < 1e-15 && (a.y + 0.5 / 0.866_025_4_f64.hypot(0.5)).abs() < 1e-12
    );
    assert!((m[2].axis_turn() - 30f64.to_radians()).abs() < 1e-6);
    // The continued GOTO to the same point with the vector to more digits turns the axis in
    // place (by 2e-9 rad); the arc is clockwise about -z: from (20, 0) round to (30, 10)
    // about (20, 10) is three quarters.
    assert_eq!(m[3].start, m[3].end);
    assert!(m[3].axis_turn() < 1e-8 && m[3].axis_turn() > 0.0);
    let arc = m
        .iter()
        .find(|m| matches!(m.motion, Motion::Arc { .. }))
        .unwrap();
    match arc.motion {
        Motion::Arc {
            plane,
            center,
            sweep,
        } => {
            assert_eq!(plane, Plane::Xy);
            assert!((center - Vector3::new(0.02, 0.01, 0.0)).norm() < 1e-15);
            assert!((sweep + 1.5 * PI).abs() < 1e-12, "{sweep}");
        }
        _ => unreachable!(),
    }
    // 0.1 mm/rev at 12,000 rpm is 20 mm/s.
    assert!((m.last().unwrap().feed - 0.02).abs() < 1e-15);
    assert_eq!(p.cutters.len(), 1);
    assert_eq!(p.cutters[0].tool, 3);
    assert_eq!(p.cutters[0].shape, ToolShape::Ball);
    assert!((p.cutters[0].diameter - 0.01).abs() < 1e-15);
    p.program.validate().unwrap();
    assert!(p.program.is_multi_axis());
}

#[test]
fn inches_bull_noses_and_tool_paths() {
    let p = read(
        "UNITS/INCHES\nTOOL PATH/FINISH,TOOL,T2\nCUTTER/0.5,0.125\nLOADTL/2\nFEDRAT/10,IPM\n\
         GOTO/1,0,0\nGOTO/1,1,0\n",
    );
    assert_eq!(p.program.operations[0].name, "FINISH");
    assert!((p.program.moves[0].end.x - 0.0254).abs() < 1e-15);
    assert!((p.program.moves[0].feed - 10.0 * 0.0254 / 60.0).abs() < 1e-15);
    // The cutter was defined before LOADTL and before any move: it is tool 2's.
    assert_eq!(p.cutters[0].tool, 2);
    assert_eq!(
        p.cutters[0].shape,
        ToolShape::BullNose {
            corner_radius: 0.125 * 0.0254
        }
    );
    assert!(!p.program.is_multi_axis());
}

#[test]
fn malformed_apt_is_refused_by_line_and_word() {
    let cases = [
        ("FEDRAT/100\nGOTO/1,0,0\nSPLINE/1,2,3\n", 3, "SPLINE"),
        ("FEDRAT/100\nGOTO/1,0,0,0,0,0\n", 2, "not zero"),
        ("FEDRAT/100\nGOTO/1,0,0,0,0,1.01\n", 2, "unit tool vector"),
        ("GOTO/1,0,0\n", 1, "FEDRAT"),
        ("FEDRAT/100\nGOTO/1,0\n", 2, "3 or 6"),
        ("FEDRAT/100\nGOTO/1,0,x\n", 2, "numbers"),
        (
            "FEDRAT/100\nCIRCLE/0,0,0,0,0.6,0.8,1\nGOTO/1,0,0\n",
            3,
            "along x, y or z",
        ),
        (
            "FEDRAT/100\nGOTO/1,0,0\nCIRCLE/0,0,0,0,0,1,1\nGOTO/0,5,0\n",
            4,
            "ARC_TOLERANCE",
        ),
        (
            "FEDRAT/100\nGOTO/1,0,0\nCIRCLE/0,0,0,0,0,1,1\n",
            3,
            "GOTO after CIRCLE",
        ),
        ("MSYS/1,0,0,1,0,0,0,1,0\n", 1, "identity"),
        ("CUTTER/10,6\n", 1, "corner radius"),
        ("FEDRAT/1,MMPR\nGOTO/1,0,0\n", 2, "turning spindle"),
        (
            "FEDRAT/100\nGOTO/0,0,0,0,0,1\nGOTO/0,0,0,0,0,-1\n",
            3,
            "MAX_AXIS_TURN",
        ),
        ("UNITS/FEET\n", 1, "UNITS"),
        ("FEDRAT/100\nGOTO/1e9,0,0\n", 2, "1000 m"),
    ];
    for (text, line, word) in cases {
        let (l, message) = refused(text);
        assert_eq!(l, line, "{text}: {message}");
        assert!(message.contains(word), "{text}: {message}");
    }
}

/// A five-axis path: the tool tip along a tilted strip, its axis leaning 0..35 degrees and
/// swinging about the vertical.
fn path() -> Vec<(Vector3<f64>, Vector3<f64>)> {
    (0..13)
        .map(|i| {
            let t = f64::from(i) / 12.0;
            let tip = Vector3::new(0.02 + 0.06 * t, 0.01 * (3.0 * t).sin(), 0.005 + 0.01 * t);
            let (lean, swing) = (
                (5.0 + 30.0 * t).to_radians(),
                (40.0 - 100.0 * t).to_radians(),
            );
            let axis = Vector3::new(
                lean.sin() * swing.cos(),
                lean.sin() * swing.sin(),
                lean.cos(),
            );
            (tip, axis)
        })
        .collect()
}

fn apt_text(path: &[(Vector3<f64>, Vector3<f64>)]) -> String {
    let mut s = String::from("UNITS/MM\nMULTAX\nFEDRAT/MMPM,1200\n");
    for (p, a) in path {
        let p = p * 1e3;
        writeln!(
            s,
            "GOTO/{:.12},{:.12},{:.12},{:.15},{:.15},{:.15}",
            p.x, p.y, p.z, a.x, a.y, a.z
        )
        .unwrap();
    }
    s
}

fn rx(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}
fn rz(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

fn rotary(
    word: RotaryWord,
    carrier: Carrier,
    direction: Vector3<f64>,
    point: Vector3<f64>,
) -> Rotary {
    Rotary {
        word,
        carrier,
        direction,
        point,
        limits: (-2.0 * PI, 2.0 * PI),
    }
}

/// The G-code of the path on a machine, from the machine angles and linear axes computed
/// for each pose by `machine`.
/// The machine's linear axes and two rotary angles for a tool pose (tip, axis).
type Machine<'a> = dyn Fn(&Vector3<f64>, &Vector3<f64>) -> (Vector3<f64>, f64, f64) + 'a;

fn gcode_text(
    path: &[(Vector3<f64>, Vector3<f64>)],
    letters: (&str, &str),
    machine: &Machine<'_>,
) -> String {
    let mut s = String::from("G21 G90 G94 F1200\n");
    for (tip, axis) in path {
        let (xyz, r1, r2) = machine(tip, axis);
        let x = xyz * 1e3;
        writeln!(
            s,
            "G1 X{:.12} Y{:.12} Z{:.12} {}{:.12} {}{:.12}",
            x.x,
            x.y,
            x.z,
            letters.0,
            r1.to_degrees(),
            letters.1,
            r2.to_degrees()
        )
        .unwrap();
    }
    s
}

fn same_poses(a: &deflect_core::machining::Program, b: &deflect_core::machining::Program) {
    assert_eq!(a.moves.len(), b.moves.len());
    for (m, n) in a.moves.iter().zip(&b.moves) {
        assert!(
            (m.end - n.end).norm() < 1e-9,
            "line {}: {} vs {}",
            m.line,
            m.end,
            n.end
        );
        assert!(
            (m.end_axis - n.end_axis).norm() < 1e-9,
            "line {}: {} vs {}",
            m.line,
            m.end_axis,
            n.end_axis
        );
    }
}

#[test]
fn apt_and_abc_gcode_give_the_same_tool_poses_on_three_machines() {
    let path = path();
    let reference = read(&apt_text(&path)).program;
    let c1 = Vector3::new(0.0, 0.0, 0.05);
    let c2 = Vector3::new(0.003, -0.002, 0.0);
    // Table-table, no TCP: a trunnion A (about +x through c1) carrying a table C (about +z
    // through c2). p_machine = Rx(a) (Rz(c) (p - c2) + c2 - c1) + c1; the tool stays +z, so
    // the axis in the workpiece is Rz(-c) Rx(-a) z = (sin a sin c, sin a cos c, cos a).
    let table_table = Kinematics::new(
        [
            rotary(RotaryWord::A, Carrier::Table, Vector3::x(), c1),
            rotary(RotaryWord::C, Carrier::Table, Vector3::z(), c2),
        ],
        false,
    )
    .unwrap();
    let tt = |tip: &Vector3<f64>, v: &Vector3<f64>| {
        let (a, c) = (v.z.acos(), v.x.atan2(v.y));
        (rx(a) * (rz(c) * (tip - c2) + c2 - c1) + c1, a, c)
    };
    // Head-table with TCP: B on the head (about +y), C on the table (about +z): the axis is
    // Rz(-c) Ry(b) z = (sin b cos c, -sin b sin c, cos b); X Y Z are the tip.
    let head_table = Kinematics::new(
        [
            rotary(RotaryWord::B, Carrier::Head, Vector3::y(), Vector3::zeros()),
            rotary(
                RotaryWord::C,
                Carrier::Table,
                Vector3::z(),
                Vector3::zeros(),
            ),
        ],
        true,
    )
    .unwrap();
    let ht = |tip: &Vector3<f64>, v: &Vector3<f64>| (*tip, v.z.acos(), (-v.y).atan2(v.x));
    // Head-head, no TCP: C (about +z) carrying A (about +x), both through the pivot 0.15 m
    // above the tip: the axis Rz(c) Rx(a) z = (sin a sin c, -sin a cos c, cos a), the tip
    // at xyz + P - R P.
    let pivot = Vector3::new(0.0, 0.0, 0.15);
    let head_head = Kinematics::new(
        [
            rotary(RotaryWord::C, Carrier::Head, Vector3::z(), pivot),
            rotary(RotaryWord::A, Carrier::Head, Vector3::x(), pivot),
        ],
        false,
    )
    .unwrap();
    let hh = |tip: &Vector3<f64>, v: &Vector3<f64>| {
        let (a, c) = (v.z.acos(), v.x.atan2(-v.y));
        let r = rz(c) * rx(a);
        (tip - pivot + r * pivot, c, a)
    };
    for (k, letters, machine) in [
        (table_table, ("A", "C"), &tt as &Machine<'_>),
        (head_table, ("B", "C"), &ht),
        (head_head, ("C", "A"), &hh),
    ] {
        let text = gcode_text(&path, letters, machine);
        let options = gcode::GcodeOptions {
            kinematics: Some(k),
            ..Default::default()
        };
        let program = gcode::from_str(&text, &options).unwrap();
        program.validate().unwrap();
        // The G-code's first move starts at the origin with the axis of the angles at 0.
        same_poses(&reference, &program);
    }
}

#[test]
fn rotary_words_need_the_machine_and_its_travel() {
    let k = Kinematics::new(
        [
            Rotary {
                limits: (-0.5, 0.5),
                ..rotary(
                    RotaryWord::A,
                    Carrier::Table,
                    Vector3::x(),
                    Vector3::zeros(),
                )
            },
            rotary(
                RotaryWord::C,
                Carrier::Table,
                Vector3::z(),
                Vector3::zeros(),
            ),
        ],
        true,
    )
    .unwrap();
    let with = gcode::GcodeOptions {
        kinematics: Some(k),
        ..Default::default()
    };
    let err = |text: &str, o: &gcode::GcodeOptions| match gcode::from_str(text, o) {
        Err(LoadError::Program {
            line,
            column,
            message,
        }) => (line, column, message),
        other => panic!("{text}: expected a program error, got {other:?}"),
    };
    // Without a kinematics A turns nothing the reader knows.
    let (line, _, m) = err("G1 X1 A10 F100\n", &gcode::GcodeOptions::default());
    assert_eq!(line, 1);
    assert!(m.contains("kinematics"), "{m}");
    // Past the A axis' travel (0.5 rad = 28.6 degrees): named, with the angle.
    let (line, column, m) = err("G1 X1 F100\nG1 X2 A30\n", &with);
    assert_eq!((line, column), (2, 7), "{m}");
    assert!(m.contains("A angle"), "{m}");
    // A word the machine lacks (B), a turn on an arc, a turn alone at feed.
    let (_, _, m) = err("G1 X1 B10 F100\n", &with);
    assert!(m.contains("B"), "{m}");
    let (_, _, m) = err("G1 X1 F100\nG2 X2 I0.5 C10\n", &with);
    assert!(m.contains("arc"), "{m}");
    let (_, _, m) = err("G1 X1 F100\nC10\n", &with);
    assert!(m.contains("alone"), "{m}");
    // A turn alone at G0 is a reorientation in place; G91 turns by increments.
    // With A at 0 the tool axis is +z whatever C is: a turn of C alone moves nothing.
    let p = gcode::from_str("G0 X1 C10\nC20\n", &with).unwrap();
    assert_eq!(p.moves.len(), 1);
    // With A at 10 degrees C swings the axis about z: 10 degrees of C turn it by
    // 2 asin(sin(10) sin(5)) = 0.8704 degrees.
    let p = gcode::from_str("G0 X1 A10 C10\nC20\nG91 C-5\n", &with).unwrap();
    assert_eq!(p.moves.len(), 3);
    assert_eq!(p.moves[1].start, p.moves[1].end);
    let want = 2.0 * (10f64.to_radians().sin() * 5f64.to_radians().sin()).asin();
    assert!(
        (p.moves[1].axis_turn() - want).abs() < 1e-12,
        "{}",
        p.moves[1].axis_turn()
    );
    let p = gcode::from_str("G0 A10\nG91 A5\n", &with).unwrap();
    assert!((p.moves[1].axis_turn() - 5f64.to_radians()).abs() < 1e-12);
    // Bad machines: the same word twice, a zero direction, limits reversed.
    let bad = [
        [rotary(
            RotaryWord::A,
            Carrier::Table,
            Vector3::x(),
            Vector3::zeros(),
        ); 2],
        [
            rotary(
                RotaryWord::A,
                Carrier::Table,
                Vector3::zeros(),
                Vector3::zeros(),
            ),
            rotary(
                RotaryWord::C,
                Carrier::Table,
                Vector3::z(),
                Vector3::zeros(),
            ),
        ],
        [
            Rotary {
                limits: (1.0, -1.0),
                ..rotary(
                    RotaryWord::A,
                    Carrier::Table,
                    Vector3::x(),
                    Vector3::zeros(),
                )
            },
            rotary(
                RotaryWord::C,
                Carrier::Table,
                Vector3::z(),
                Vector3::zeros(),
            ),
        ],
    ];
    for r in bad {
        assert!(Kinematics::new(r, true).is_err(), "{r:?}");
    }
}

#[test]
fn points_csv_takes_tool_vectors() {
    let text = "x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm,i,j,k\n\
                10,0,0,600,10000,0,0,1\n\
                20,0,0,600,10000,0.5,0,0.8660254\n";
    let p = points_csv::from_str(text, &gcode::GcodeOptions::default()).unwrap();
    assert_eq!(p.moves[0].start_axis, Vector3::z());
    assert!((p.moves[1].axis_turn() - PI / 6.0).abs() < 1e-6);
    let half = p.moves[1].axis(0.5);
    assert!(
        (half - Vector3::new(15f64.to_radians().sin(), 0.0, 15f64.to_radians().cos())).norm()
            < 1e-6
    );
    let bad = "x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm,i,j,k\n10,0,0,600,10000,0,0,2\n";
    let e = points_csv::from_str(bad, &gcode::GcodeOptions::default()).unwrap_err();
    assert!(e.to_string().contains("unit tool vector"), "{e}");
    let missing = "x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm,i,j\n10,0,0,600,10000,0,0\n";
    assert!(points_csv::from_str(missing, &gcode::GcodeOptions::default()).is_err());
}

#[test]
fn the_path_samples_the_tool_axis_along_the_great_circle() {
    use deflect_core::machining::path;
    let p = read("FEDRAT/600\nGOTO/10,0,0,0,0,1\nGOTO/20,0,0,0,0.1736482,0.9848078\n").program;
    let samples: Vec<_> = path::Sampler::new(&p, &path::PathOptions::default())
        .unwrap()
        .collect();
    // The axis turns 10 degrees about -x along the great circle with the tip's fraction.
    let last = p.moves.len() - 1;
    assert!(samples.iter().filter(|s| s.move_index == last).count() > 10);
    for s in samples.iter().filter(|s| s.move_index == last) {
        let angle = 10f64.to_radians() * s.fraction;
        let expected = Vector3::new(0.0, angle.sin(), angle.cos());
        assert!((s.axis - expected).norm() < 1e-6, "{:?}", s.axis);
    }
    assert!((samples.last().unwrap().axis.y - 0.1736482).abs() < 1e-6);
    // Along +z the same reader's program samples +z.
    let flat = read("FEDRAT/600\nGOTO/10,0,0,0,0,1\nGOTO/20,0,0\n").program;
    let t = path::duration(&flat, &path::PathOptions::default()).unwrap();
    assert!(t > 1.0, "{t}");
}
