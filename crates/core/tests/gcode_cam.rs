//! The CAM dialect of the G-code reader against LinuxCNC's moves, transcribed from `rs274 -g`
//! runs (the canned cycles, the planes, the offsets) and against hand-derived values (feed
//! modes, units, dwells, tools, dialects, the word report, tool tables). These hold without
//! `rs274` installed; `rs274.rs` compares live.

use std::f64::consts::{PI, TAU};

use deflect_core::io::gcode::{self, Dialect, GcodeOptions, WordStatus};
use deflect_core::io::tool_table::{self, TblOptions};
use deflect_core::machining::path::{self, PathOptions};
use deflect_core::machining::tools::ToolShape;
use deflect_core::machining::{Motion, PathControl, Plane, Program};
use deflect_core::units::LengthUnit;
use nalgebra::Vector3;

fn read(text: &str) -> Program {
    gcode::from_str(text, &GcodeOptions::default()).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn read_with(text: &str, dialect: Dialect) -> Result<Program, String> {
    let o = GcodeOptions {
        dialect,
        ..GcodeOptions::default()
    };
    gcode::from_str(text, &o).map_err(|e| e.to_string())
}

/// Each move as (kind, end in mm): 'R' rapid, 'L' line, 'A' arc, 'D' dwell.
fn trace(p: &Program) -> Vec<(char, [f64; 3])> {
    p.moves
        .iter()
        .map(|m| {
            let k = match m.motion {
                Motion::Rapid => 'R',
                Motion::Linear => 'L',
                Motion::Arc { .. } => 'A',
                Motion::Dwell { .. } => 'D',
            };
            let e = m.end * 1e3;
            (k, [e.x, e.y, e.z].map(|v| (v * 1e4).round() / 1e4))
        })
        .collect()
}

#[test]
fn canned_cycles_make_linuxcncs_moves() {
    // rs274 -g, G98 G81 from Z10 (its printed moves; the zero-length ones are not stored).
    let head = "G21 G17 G90 G94 F100 S1000 M3\nG0 X0 Y0 Z10\n";
    let p = read(&format!("{head}G98 G81 X1 Y2 Z-5 R2\nX3\nM2\n"));
    assert_eq!(
        trace(&p)[1..],
        [
            ('R', [1.0, 2.0, 10.0]),
            ('R', [1.0, 2.0, 2.0]),
            ('L', [1.0, 2.0, -5.0]),
            ('R', [1.0, 2.0, 10.0]),
            ('R', [3.0, 2.0, 10.0]),
            ('R', [3.0, 2.0, 2.0]),
            ('L', [3.0, 2.0, -5.0]),
            ('R', [3.0, 2.0, 10.0]),
        ]
    );
    // G99 G83 with a modal Q and F: pecks of 2.5 mm, back to R, down to 0.254 mm above.
    let p = read(&format!("{head}G99 G83 X1 Y2 Z-3 R2 Q2.5\nX3 F200\nM2\n"));
    let t = trace(&p);
    assert_eq!(
        t[1..8],
        [
            ('R', [1.0, 2.0, 10.0]),
            ('R', [1.0, 2.0, 2.0]),
            ('L', [1.0, 2.0, -0.5]),
            ('R', [1.0, 2.0, 2.0]),
            ('R', [1.0, 2.0, -0.246]),
            ('L', [1.0, 2.0, -3.0]),
            ('R', [1.0, 2.0, 2.0]),
        ]
    );
    assert_eq!(p.moves[3].feed, 100e-3 / 60.0);
    assert_eq!(p.moves.last().unwrap().line, 4);
    assert!(t[8..].iter().all(|m| m.1[0] == 3.0));
    // G91 G98 G81 L3: R relative to the initial level, Z to R, X/Y per repeat.
    let p = read(&format!("{head}G91 G98 G81 X1 Y2 Z-7 R-8 L3\nM2\n"));
    let bottoms: Vec<[f64; 3]> = trace(&p)
        .iter()
        .filter(|m| m.0 == 'L')
        .map(|m| m.1)
        .collect();
    assert_eq!(
        bottoms,
        [[1.0, 2.0, -5.0], [2.0, 4.0, -5.0], [3.0, 6.0, -5.0]]
    );
    // G73: chip-breaking pecks of Q with a 0.254 mm retract; G82 and G89 dwell P.
    let p = read(&format!("{head}G98 G73 X1 Y2 Z-5 R2 Q2\nM2\n"));
    assert_eq!(
        trace(&p)[3..9],
        [
            ('L', [1.0, 2.0, 0.0]),
            ('R', [1.0, 2.0, 0.254]),
            ('L', [1.0, 2.0, -2.0]),
            ('R', [1.0, 2.0, -1.746]),
            ('L', [1.0, 2.0, -4.0]),
            ('R', [1.0, 2.0, -3.746]),
        ]
    );
    let p = read(&format!("{head}G99 G89 X1 Y2 Z-5 R2 P0.5\nM2\n"));
    assert_eq!(p.moves[4].motion, Motion::Dwell { seconds: 0.5 });
    assert_eq!(trace(&p)[5], ('L', [1.0, 2.0, 2.0]));
    // G88: rs274 feeds, dwells, stops for the operator's retract by hand; here the retract
    // is a rapid to the clear height (the one move LinuxCNC does not make).
    let p = read(&format!(
        "{head}G98 G88 X1 Y2 Z-5 R2 P0.5\nG80\nG91 G0 X1\nM2\n"
    ));
    let t = trace(&p);
    assert_eq!(
        t[3..],
        [
            ('L', [1.0, 2.0, -5.0]),
            ('D', [1.0, 2.0, -5.0]),
            ('R', [1.0, 2.0, 10.0]),
            ('R', [2.0, 2.0, 10.0])
        ]
    );
    // G18: the cycle drills along Y.
    let p = read("G21 G18 G90 G94 F100 S1000 M3\nG0 X10 Y10 Z0\nG98 G81 X1 Z2 Y-5 R2\nM2\n");
    assert!(trace(&p).contains(&('L', [1.0, -5.0, 2.0])));
    // Starting below R: straight up to R first; the retract is R.
    let p = read(
        "G21 G90 F100 S1000 M3
G0 X0 Y0 Z0
G98 G81 X1 Y2 Z-5 R2
M2
",
    );
    assert_eq!(trace(&p)[0], ('R', [0.0, 0.0, 2.0]));
    assert_eq!(trace(&p).last().unwrap().1, [1.0, 2.0, 2.0]);
    // After G80 an axis word has no motion mode (LinuxCNC); the fanuc dialect moves in G0,
    // from the cycle's retract plane (G99 by default: R).
    let haas = format!("{head}G81 X1 Y1 Z-1 R1\nG80\nX5 Y5\nM2\n");
    assert!(
        read_with(&haas, Dialect::LinuxCnc)
            .unwrap_err()
            .contains("line 5, column 1")
    );
    let p = read_with(&haas, Dialect::Fanuc).unwrap();
    assert_eq!(trace(&p).last().unwrap(), &('R', [5.0, 5.0, 1.0]));
    // Haas's settings, %-lines with text, nested comments: fanuc only.
    let haas = "%O1000 (FUSION)\nG187 P3 E0.05 (FINISH (SMOOTH))\nG103 P0\nG0 X1\n%\n";
    assert!(read_with(haas, Dialect::LinuxCnc).is_err());
    assert_eq!(
        trace(&read_with(haas, Dialect::Fanuc).unwrap()),
        [('R', [1.0, 0.0, 0.0])]
    );
}

#[test]
fn arcs_take_their_plane_turns_and_centre_modes() {
    // rs274: G18 G2 X2 Z0 I1 Y3 from the origin -> ARC_FEED(0,2, 0,1, -1, 3): first axis Z,
    // second X, centre (z 0, x 1), clockwise, helix to Y3.
    let p = read("G0 X0 Y0 Z0\nG18 G2 X2 Z0 I1 Y3 F100\n");
    let m = &p.moves[0];
    let Motion::Arc {
        plane,
        center,
        sweep,
    } = m.motion
    else {
        panic!()
    };
    assert_eq!(plane, Plane::Zx);
    assert_eq!(center, Vector3::new(1e-3, 0.0, 0.0));
    // From (x 0, z 0) about (x 1, z 0) to (x 2, z 0), clockwise about +y: half a turn.
    assert!((sweep + PI).abs() < 1e-15);
    assert_eq!(m.end, Vector3::new(2e-3, 3e-3, 0.0));
    // Halfway: (z, x) = (0, 0) turned by -90 deg about (0, 1) in the (z, x) plane is (-1, 1),
    // and the helix is halfway up y.
    let mid = m.point(0.5);
    assert!(
        (mid - Vector3::new(1e-3, 1.5e-3, -1e-3)).norm() < 1e-15,
        "{mid}"
    );
    // G19 G3 Y2 Z0 J1 X4 -> (y, z) about (1, 0), counter-clockwise about +x, helix to X4.
    let p = read("G19 G3 Y2 Z0 J1 X4 F100\n");
    let Motion::Arc { plane, sweep, .. } = p.moves[0].motion else {
        panic!()
    };
    assert_eq!((plane, sweep), (Plane::Yz, PI));
    // P turns: a full circle three times over.
    let p = read("G0 X1 Y0\nG2 I1 P3 Z-3 F100\n");
    let Motion::Arc { sweep, .. } = p.moves[1].motion else {
        panic!()
    };
    assert!((sweep + 3.0 * TAU).abs() < 1e-12);
    let len = ((TAU * 3.0 * 1e-3).powi(2) + 9e-6f64).sqrt();
    assert!((p.moves[1].length() - len).abs() < 1e-15);
    // Absolute centres (G90.1): I and J are the centre itself.
    let p = read("G0 X10 Y0\nG90.1 G3 X0 Y10 I0 J0 F100\n");
    let Motion::Arc { center, sweep, .. } = p.moves[1].motion else {
        panic!()
    };
    assert_eq!((center, sweep), (Vector3::zeros(), PI / 2.0));
    // LinuxCNC's spiral tolerance: 0.02 mm off the circle is an arc, 0.03 mm is not.
    read("G0 X0 Y0\nG2 X2.02 I1 F100\n");
    let e = read_with("G0 X0 Y0\nG2 X2.03 I1 F100\n", Dialect::LinuxCnc).unwrap_err();
    assert!(e.contains("on the arc's circle"), "{e}");
    // R arcs: the long way with R < 0.
    let p = read("G2 X2 R-2 F100\n");
    let Motion::Arc { center, .. } = p.moves[0].motion else {
        panic!()
    };
    assert!((center - Vector3::new(1e-3, 3f64.sqrt() * 1e-3, 0.0)).norm() < 1e-15);
    // K on a G17 arc: LinuxCNC refuses it, grbl ignores it.
    let freecad = "G2 X10 Y0 I5 J0 K0.000 F200\n";
    assert!(
        read_with(freecad, Dialect::LinuxCnc)
            .unwrap_err()
            .contains("no K word on an arc in G17")
    );
    assert_eq!(read_with(freecad, Dialect::Grbl).unwrap().moves.len(), 1);
}

#[test]
fn offsets_machine_coordinates_and_stored_points() {
    // The moves are in the machine frame: program coordinates plus the work offset.
    let p = read("G10 L2 P1 X10 Y-5 Z-20\nG0 X1 Y2 Z3\n");
    assert_eq!(trace(&p)[0].1, [11.0, -3.0, -17.0]);
    // A rotated work offset: X10 in G55 rotated 90 deg about its origin (100, 50).
    let p = read("G10 L2 P2 X100 Y50 R90\nG55 G0 X10 Y0 Z0\n");
    assert_eq!(trace(&p)[0].1, [100.0, 60.0, 0.0]);
    // G92 makes the current point (3, 4) the program's (0, 0); G92.1 undoes it.
    let p = read("G0 X3 Y4\nG92 X0 Y0\nG0 X1\nG92.1\nG0 X1\n");
    assert_eq!(
        trace(&p)[1..],
        [('R', [4.0, 4.0, 0.0]), ('R', [1.0, 4.0, 0.0])]
    );
    // G53 moves in machine coordinates whatever the offsets.
    let p = read("G10 L2 P1 X10\nG0 X0\nG53 G0 X0\n");
    assert_eq!(trace(&p)[1], ('R', [0.0, 0.0, 0.0]));
    // G28: through the intermediate point to the stored point (G28.1), on the named axes.
    let p = read("G0 X5 Y6 Z7\nG28.1\nG0 X1 Y1 Z1\nG91 G28 Z2\n");
    assert_eq!(
        trace(&p)[2..],
        [('R', [1.0, 1.0, 3.0]), ('R', [1.0, 1.0, 7.0])]
    );
    // G10 L20: the current point gets the given coordinates.
    let p = read("G0 X4 Y4\nG10 L20 P1 X0 Y0\nG0 X1\n");
    assert_eq!(trace(&p)[1].1, [5.0, 4.0, 0.0]);
}

#[test]
fn feed_modes_units_dwells_and_path_control() {
    // Inverse time: F2 on a 10 mm line is 20 mm/min.
    let p = read("G93 G1 X10 F2\n");
    assert!((p.moves[0].feed - 20e-3 / 60.0).abs() < 1e-18);
    // Per revolution: F0.05 mm at S6000 is 300 mm/min.
    let p = read("S6000 M3\nG95 G1 X10 F0.05\n");
    assert!((p.moves[0].feed - 300e-3 / 60.0).abs() < 1e-18);
    // Units anywhere: inches after mm, the position kept.
    let p = read("G21 G0 X25.4\nG20 G0 Y1\nG21 G0 Z1\n");
    assert_eq!(trace(&p)[1].1, [25.4, 25.4, 0.0]);
    assert_eq!(trace(&p)[2].1, [25.4, 25.4, 1.0]);
    // G4 P1.5: a dwell of 1.5 s in place, which the path holds.
    let p = read("G1 X10 F600\nG4 P1.5\nG1 X20\n");
    assert_eq!(p.moves[1].motion, Motion::Dwell { seconds: 1.5 });
    let without = read("G1 X10 F600\nG1 X20\n");
    let o = PathOptions::default();
    let (a, b) = (
        path::duration(&p, &o).unwrap(),
        path::duration(&without, &o).unwrap(),
    );
    // The dwell, and the stop at the end of the first line (one profile becomes two).
    assert!(a - b > 1.5 && a - b < 1.5 + 0.5, "{a} {b}");
    let samples = path::sample(&p, &o).unwrap();
    assert!(
        samples
            .iter()
            .filter(|s| s.line == 2)
            .all(|s| s.speed == 0.0 && s.position.x == 0.01)
    );
    // Path control is recorded per move.
    let p = read("G64 P0.02 Q0.01 G1 X1 F100\nG61 X2\nG61.1 X3\n");
    assert_eq!(
        p.moves.iter().map(|m| m.path_control).collect::<Vec<_>>(),
        [
            PathControl::Blend {
                tolerance: 0.02e-3,
                naive_tolerance: 0.01e-3
            },
            PathControl::ExactPath,
            PathControl::ExactStop
        ]
    );
}

#[test]
fn tools_and_the_spindle_follow_the_program() {
    let p = read(
        "T3 M6\nS9000 M3\nG1 X1 F100\nT4\nG1 X2\nM6\nM4\nG1 X3\nM5\nG1 X4\nM61 Q7\nM3\nG1 X5\n",
    );
    let tools: Vec<u32> = p.moves.iter().map(|m| m.tool).collect();
    let spindle: Vec<f64> = p.moves.iter().map(|m| m.spindle * 60.0).collect();
    // T selects, M6 changes (and stops the spindle); M61 Q sets the tool without a change.
    assert_eq!(tools, [3, 3, 4, 4, 7]);
    assert_eq!(spindle, [9000.0, 9000.0, -9000.0, 0.0, 9000.0]);
    assert_eq!(p.tools(), [3, 4, 7]);
    // Before any change, the tool the program selected: a post for manual tool changes.
    let p = read("T5\nS9000 M3\nG1 X1 F100\n");
    assert_eq!(p.moves[0].tool, 5);
    // Tool length offsets are recorded, not applied: the tip follows the program.
    let with = read("T1 M6 G43 H1\nG43.1 Z5\nG0 X1 Y1 Z1\nG49\nG0 X2\n");
    let without = read("T1 M6\nG0 X1 Y1 Z1\nG0 X2\n");
    assert_eq!(trace(&with), trace(&without));
}

#[test]
fn the_word_report_lists_every_word_with_what_the_reader_does() {
    let text =
        "%\nN10 G21 G90 T1 M6\nG43 H1 M8\nS100 M3\nG0 X1\nG1 X2 F10 (MSG, hi)\nX3\nG41 D1\n%\n";
    let words = gcode::words(text, &GcodeOptions::default()).unwrap();
    let get = |w: &str| {
        words
            .iter()
            .find(|u| u.word == w)
            .unwrap_or_else(|| panic!("{w}"))
    };
    assert_eq!((get("X").count, get("X").first_line), (3, 5));
    assert_eq!(get("G1").status, WordStatus::Honoured);
    assert_eq!(get("G43").status, WordStatus::Recorded);
    assert!(get("G43").meaning.contains("TCP carries the tool length"));
    assert_eq!(get("M8").status, WordStatus::Recorded);
    assert_eq!(get("G41").status, WordStatus::Refused);
    assert_eq!(get("D").status, WordStatus::Refused);
    assert_eq!(get("(MSG,...)").first_line, 6);
    assert_eq!((get("%").count, get("T").first_line), (2, 2));
    // The reader refuses what the report calls refused, at its first use.
    let e = gcode::from_str(text, &GcodeOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("program line 8, column 1"), "{e}");
}

#[test]
fn tool_tables_read_linuxcncs_tbl_and_the_toml_form() {
    let o = TblOptions {
        units: LengthUnit::Inch,
        flutes: 2,
        helix: 0.5,
    };
    let t = tool_table::tbl_from_str(
        "; a comment line\nT1 P1 D0.25 Z1.5 ;quarter inch\nt2 p2 x0 d0.5\n",
        &o,
    )
    .unwrap();
    let t1 = t.get(1).unwrap();
    assert_eq!(
        (t1.tool.diameter, t1.length, t1.tool.flutes),
        (0.25 * 25.4e-3, 1.5 * 25.4e-3, 2)
    );
    assert_eq!(
        (t1.name.as_str(), t1.tool.helix, t1.shape),
        ("quarter inch", 0.5, ToolShape::Flat)
    );
    assert_eq!(t.get(2).unwrap().tool.diameter, 0.5 * 25.4e-3);
    assert!(t.get(3).is_none());
    let toml = "units = \"mm\"\n[[tool]]\nnumber = 5\ndiameter = 10\nflutes = 4\nhelix_deg = 30\nshape = \"bull-nose\"\ncorner_radius = 1\nname = \"torus\"\n";
    let t = tool_table::toml_from_str(toml).unwrap();
    let t5 = t.get(5).unwrap();
    assert_eq!(
        t5.shape,
        ToolShape::BullNose {
            corner_radius: 1e-3
        }
    );
    assert!((t5.tool.helix - 30f64.to_radians()).abs() < 1e-15);
    // Faults name the line or the entry.
    for (text, needle) in [
        ("T1 P1\n", "D"),
        ("T1 D6\nT1 D8\n", "each tool number once"),
        ("T1 D6 K3\n", "T, P, D"),
        ("P1 D6\n", "tool number T"),
        ("T1 D-6\n", "diameter"),
    ] {
        let e = tool_table::tbl_from_str(text, &TblOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{text:?}: {e}");
    }
    let e = tool_table::toml_from_str(&toml.replace("corner_radius = 1", "corner_radius = 5"))
        .unwrap_err();
    assert!(e.to_string().contains("corner radius"), "{e}");
    let e = tool_table::toml_from_str(&toml.replace("\"bull-nose\"", "\"drill\"")).unwrap_err();
    assert!(
        e.to_string()
            .contains("\"flat\", \"ball\" or \"bull-nose\""),
        "{e}"
    );
}

#[test]
fn a_latin1_comment_does_not_refuse_the_program() {
    // A European post's comment in ISO-8859-1 ("Fräser"): not UTF-8, read as LinuxCNC reads
    // bytes.
    let dir = std::env::temp_dir().join(format!("deflect-latin1-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("fraeser.nc");
    std::fs::write(&f, b"(Fr\xe4ser 6 mm)\nG0 X1\nM30\n").unwrap();
    let p = gcode::from_path(&f, &GcodeOptions::default()).unwrap();
    assert_eq!(trace(&p), [('R', [1.0, 0.0, 0.0])]);
}
