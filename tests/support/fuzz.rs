//! Fuzz harnesses of deflect's loaders, one function per cargo-fuzz target in `fuzz/`.
//!
//! The bodies live here, in the root package's support library, so that the fuzz targets
//! (nightly, `cargo fuzz run <target>`) and the stable replay test `tests/fuzz_replay.rs`
//! (every file of `fuzz/corpus/<target>/` and `fuzz/regressions/<target>/`) run the same
//! code. A harness takes arbitrary bytes and never panics unless a loader or the model it
//! loaded breaks an invariant: loading may fail with a typed error, but whatever loads must
//! answer a small query with a finite result or a typed error, never NaN with `Ok`.

use deflect_core::compliance_map::ComplianceMap;
use deflect_core::io::{drive, gcode, map_csv, map_json, stiffness, urdf};
use deflect_core::machining::Motion;
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_core::vjm::{self, Vector6};
use deflect_core::{SerialRobot, TickError, drivetrain};

/// The fuzz targets, each with its harness: the names of `fuzz/fuzz_targets/*.rs` and of
/// the directories of `fuzz/corpus/` and `fuzz/regressions/`. A harness returns whether a
/// model loaded (the replay test wants each seed corpus to load at least one).
pub const TARGETS: [(&str, Harness); 7] = [
    ("urdf_stiffness", urdf_stiffness),
    ("map_csv", map_csv),
    ("static_csv", static_csv),
    ("map_json", map_json),
    ("drive_toml", drive_toml),
    ("gcode", gcode),
    ("tool_table", tool_table),
];

/// A harness: arbitrary bytes in, whether a model loaded out.
pub type Harness = fn(&[u8]) -> bool;

/// The byte that separates the URDF text from the stiffness TOML in an `urdf_stiffness`
/// input (the first one does; neither format has a use for NUL).
pub const SEPARATOR: u8 = 0;

/// The shipped KR 300 R2500 URDF, compiled in (the drive-train target loads against it).
pub const KR300_URDF: &str = include_str!("../../robots/kr300/kr300_r2500.urdf");
/// The shipped KR 300 R2500 stiffness file.
pub const KR300_STIFFNESS: &str = include_str!("../../robots/kr300/kr300_r2500_stiffness.toml");

/// A small TCP wrench \[N, N m\] the harnesses deflect a loaded model with.
const WRENCH: [f64; 6] = [100.0, -50.0, 200.0, 1.0, 0.0, -1.0];

/// Splits an `urdf_stiffness` input at the first [`SEPARATOR`]: (URDF, stiffness TOML).
/// Without one, the whole input is the URDF and the stiffness text is empty.
pub fn split_urdf_stiffness(data: &[u8]) -> (&[u8], &[u8]) {
    match data.iter().position(|&b| b == SEPARATOR) {
        Some(i) => (
            data.get(..i).unwrap_or(&[]),
            data.get(i + 1..).unwrap_or(&[]),
        ),
        None => (data, &[]),
    }
}

/// Joins a URDF and a stiffness text into one `urdf_stiffness` input (for seed corpora).
pub fn join_urdf_stiffness(urdf: &str, stiffness: &str) -> Vec<u8> {
    let mut v = Vec::with_capacity(urdf.len() + stiffness.len() + 1);
    v.extend_from_slice(urdf.as_bytes());
    v.push(SEPARATOR);
    v.extend_from_slice(stiffness.as_bytes());
    v
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Target `urdf_stiffness`: URDF and stiffness TOML (split at the first NUL byte), the
/// chain from the URDF's root (and from its first link) to its last link; when the robot
/// loads, a drive train from the same stiffness text (a combined file may carry `[[joint]]`
/// entries) and a few per-tick calls on both.
pub fn urdf_stiffness(data: &[u8]) -> bool {
    let (u, s) = split_urdf_stiffness(data);
    let (urdf_text, stiffness_text) = (String::from_utf8_lossy(u), String::from_utf8_lossy(s));
    let specs = stiffness::from_str(&stiffness_text);
    if let Ok(specs) = &specs {
        assert!(
            !specs.is_empty(),
            "a stiffness file loads with no virtual joint"
        );
    }
    let Ok(parsed) = urdf::parse(&urdf_text) else {
        return false;
    };
    let (Some(first), Some(last)) = (parsed.links.first(), parsed.links.last()) else {
        return false;
    };
    let mut loaded = false;
    // The whole loader (texts in, chain from the URDF's root) ...
    if let Ok(robot) = urdf::from_str(&urdf_text, &stiffness_text, None, &last.name) {
        check_robot(&robot, &urdf_text, &stiffness_text);
        loaded = true;
    }
    // ... and its assembly step with an explicit base link (the URDF parsed once).
    let assembled = specs
        .as_ref()
        .ok()
        .and_then(|specs| urdf::assemble(&parsed, specs, Some(&first.name), &last.name).ok());
    if let Some(robot) = assembled {
        check_robot(&robot, &urdf_text, &stiffness_text);
        loaded = true;
    }
    loaded
}

/// Invariants of a loaded robot, and a deflection at the zero joints (clamped to the
/// limits); then its drive train from `drive_toml`, when that loads.
fn check_robot(robot: &SerialRobot, urdf_text: &str, drive_toml: &str) {
    let dof = robot.model.dof();
    assert_eq!(robot.joint_names.len(), dof, "one name per joint");
    assert_eq!(robot.joint_limits.len(), dof, "one limit pair per joint");
    assert_eq!(
        robot.spring_names.len(),
        robot.model.spring_count(),
        "one name per virtual joint"
    );
    assert!(
        robot.joint_limits.iter().all(|(lo, hi)| lo < hi),
        "a loaded joint has limits lower < upper: {:?}",
        robot.joint_limits
    );
    let q: Vec<f64> = robot
        .joint_limits
        .iter()
        .map(|&(lo, hi)| 0.0f64.clamp(lo, hi))
        .collect();
    let wrench = Vector6::from(WRENCH);
    let mut data = vjm::Data::new(&robot.model);
    if let Ok(tcp) = vjm::forward(&robot.model, &mut data, &q) {
        assert!(
            all_finite(tcp.translation.vector.as_slice())
                && all_finite(tcp.rotation.coords.as_slice()),
            "forward kinematics Ok with a non-finite pose: {tcp:?}"
        );
    }
    if let Ok(d) = vjm::deflection(&robot.model, &mut data, &q, &wrench, vjm::Load::Exact) {
        assert!(all_finite(d.as_slice()), "deflection Ok with {d:?}");
    }
    if let Ok(c) = vjm::compliance(&robot.model, &mut data, &q) {
        assert!(all_finite(c.as_slice()), "compliance Ok with {c:?}");
    }
    if let Ok(model) = drive::from_str(robot, urdf_text, drive_toml) {
        check_drive(&model, robot, &q);
    }
}

/// Invariants of a loaded drive train of `robot`, and its torques at `q`.
fn check_drive(model: &drivetrain::Model, robot: &SerialRobot, q: &[f64]) {
    assert_eq!(model.dof(), robot.model.dof(), "drive train and robot dof");
    assert!(
        model.stiffness().iter().all(|k| k.is_normal() && *k > 0.0),
        "drive stiffness {:?}",
        model.stiffness()
    );
    assert!(
        model.backlash().iter().all(|b| b.is_finite() && *b >= 0.0),
        "drive backlash {:?}",
        model.backlash()
    );
    let wrench = Vector6::from(WRENCH);
    let mut data = drivetrain::Data::new(model);
    if let Ok(g) = drivetrain::gravity_torques(model, &mut data, q) {
        assert!(all_finite(&g), "gravity torques Ok with {g:?}");
    }
    if let Ok(c) = drivetrain::step(model, &mut data, q, &wrench) {
        assert!(
            all_finite(&c.q) && all_finite(&c.torque),
            "corrected joints Ok with {c:?}"
        );
    }
    if let Ok(tcp) = drivetrain::compensated_forward(model, &mut data, q, &wrench) {
        assert!(
            all_finite(tcp.translation.vector.as_slice()),
            "compensated forward Ok with {tcp:?}"
        );
    }
}

/// Target `map_csv`: a paper coefficient table, read in N and mm and in kgf and m.
pub fn map_csv(data: &[u8]) -> bool {
    let text = String::from_utf8_lossy(data);
    let mut loaded = false;
    for (force, length) in [
        (ForceUnit::Newton, LengthUnit::Millimetre),
        (ForceUnit::KilogramForce, LengthUnit::Metre),
    ] {
        if let Ok(map) = map_csv::from_str(&text, force, length) {
            assert_eq!(
                (map.n_force(), map.n_displacement()),
                (2, 2),
                "a paper table loads as a 2 x 2 map"
            );
            check_map(&map);
            loaded = true;
        }
    }
    loaded
}

/// Target `static_csv`: a static-test table fitted in N and mm (force axes from the table,
/// 1 um tolerance) and in kgf and m (a force-axis count and a tolerance, valid or not,
/// chosen by the input's length).
pub fn static_csv(data: &[u8]) -> bool {
    let text = String::from_utf8_lossy(data);
    let mut loaded = false;
    const TOLERANCES: [f64; 7] = [1e-6, 0.0, 1e-3, f64::NAN, -1.0, f64::INFINITY, 0.5];
    let n = data.len();
    let tolerance = TOLERANCES
        .get(n % TOLERANCES.len())
        .copied()
        .unwrap_or(1e-6);
    for (force, length, n_force, tolerance) in [
        (ForceUnit::Newton, LengthUnit::Millimetre, None, 1e-6),
        (
            ForceUnit::KilogramForce,
            LengthUnit::Metre,
            Some(n % 8),
            tolerance,
        ),
    ] {
        if let Ok(map) = map_csv::fit_static_str(&text, force, length, n_force, tolerance) {
            if let Some(nf) = n_force {
                assert_eq!(map.n_force(), nf, "the fit has the force axes asked for");
            }
            let nodes = map.x().len() * map.y().len();
            assert!(
                map.fit_stats().is_some_and(|f| f.len() == nodes),
                "a fitted map has statistics for each of its {nodes} nodes"
            );
            check_map(&map);
            loaded = true;
        }
    }
    loaded
}

/// Target `map_json`: a JSON map.
pub fn map_json(data: &[u8]) -> bool {
    let text = String::from_utf8_lossy(data);
    match map_json::from_str(&text) {
        Ok(map) => {
            check_map(&map);
            true
        }
        Err(_) => false,
    }
}

/// Invariants of a loaded map: a consistent, strictly increasing finite grid; queries at the
/// first node and at the grid's centre (inside the grid) give a finite displacement or a
/// typed error other than out-of-grid; the JSON round trip restores the map exactly.
pub fn check_map(map: &ComplianceMap) {
    let (nf, nd) = (map.n_force(), map.n_displacement());
    let (x, y) = (map.x(), map.y());
    assert!(nf >= 1 && nd >= 1, "map axes {nf} x {nd}");
    assert!(!x.is_empty() && !y.is_empty(), "an empty grid loaded");
    for axis in [x, y] {
        assert!(all_finite(axis), "grid nodes {axis:?}");
        assert!(
            axis.windows(2).all(|w| matches!(w, [a, b] if a < b)),
            "grid nodes not strictly increasing: {axis:?}"
        );
    }
    let len = x.len() * y.len() * nf * nd;
    assert_eq!(
        map.slopes().len(),
        len,
        "slopes for every node and axis pair"
    );
    assert_eq!(
        map.offsets().len(),
        len,
        "offsets for every node and axis pair"
    );
    if let (Some(fit), nodes) = (map.fit_stats(), x.len() * y.len()) {
        assert_eq!(fit.len(), nodes, "fit statistics for every node");
    }

    let force: Vec<f64> = (0..nf).map(|f| 10.0 + 5.0 * f as f64).collect();
    let mut out = vec![0.0; nd];
    let (x0, y0) = (x.first().copied(), y.first().copied());
    let (x1, y1) = (x.last().copied(), y.last().copied());
    let (Some(x0), Some(y0), Some(x1), Some(y1)) = (x0, y0, x1, y1) else {
        return;
    };
    // Halves first, so that the midpoint of two finite nodes is finite (clamped: halving a
    // subnormal rounds).
    let centre = [
        (x0 / 2.0 + x1 / 2.0).clamp(x0, x1),
        (y0 / 2.0 + y1 / 2.0).clamp(y0, y1),
    ];
    for position in [[x0, y0], centre] {
        match map.displacement(position, &force, &mut out) {
            Ok(_) => assert!(
                all_finite(&out),
                "query at {position:?} (inside the grid) Ok with {out:?}"
            ),
            Err(TickError::OutOfGrid { .. }) => {
                panic!("query at {position:?} is inside the grid, refused as outside")
            }
            Err(_) => {}
        }
    }

    // Saved as JSON, a map is restored bit for bit (floats in shortest round-trip form).
    if let Ok(json) = map_json::to_string(map) {
        match map_json::from_str(&json) {
            Ok(back) => assert!(back == *map, "the JSON round trip changed the map:\n{json}"),
            Err(e) => panic!("a map saved as JSON does not load again: {e}\n{json}"),
        }
    }
}

/// Target `drive_toml`: a drive-train TOML, parsed alone and loaded against the shipped
/// KR 300 R2500 robot (masses from its URDF).
pub fn drive_toml(data: &[u8]) -> bool {
    let text = String::from_utf8_lossy(data);
    // `from_str` parses the (shipped, valid) URDF and then this text: where the text does
    // not parse it fails the same way, so only a text that parses is loaded (the URDF parse
    // dominates the cost of an input).
    let Ok(specs) = drive::parse(&text) else {
        return false;
    };
    let robot = kr300_robot();
    let loaded = drive::from_str(robot, KR300_URDF, &text);
    if let Ok(model) = &loaded {
        assert_eq!(
            specs.len(),
            robot.joint_names.len(),
            "one [[joint]] entry per actuated joint"
        );
        let q = crate::KR300_MILLING_POSE;
        check_drive(model, robot, &q);
    }
    loaded.is_ok()
}

/// The shipped KR 300 R2500 robot, loaded once from the compiled-in texts.
pub fn kr300_robot() -> &'static SerialRobot {
    static ROBOT: std::sync::OnceLock<SerialRobot> = std::sync::OnceLock::new();
    ROBOT.get_or_init(
        || match urdf::from_str(KR300_URDF, KR300_STIFFNESS, None, "tcp") {
            Ok(r) => r,
            Err(e) => panic!("the shipped KR 300 model must load: {e}"),
        },
    )
}

/// A trunnion `A` carrying a rotary table `C`, without tool centre point control: the
/// machine the fuzzed programs' `A` and `C` words turn.
fn table_table() -> deflect_core::machining::Kinematics {
    use deflect_core::machining::kinematics::{Carrier, Rotary, RotaryWord};
    let rotary = |word, direction: [f64; 3], point: [f64; 3], limits| Rotary {
        word,
        carrier: Carrier::Table,
        direction: nalgebra::Vector3::from(direction),
        point: nalgebra::Vector3::from(point),
        limits,
    };
    deflect_core::machining::Kinematics::new(
        [
            rotary(RotaryWord::A, [1.0, 0.0, 0.0], [0.0, 0.0, 0.1], (-2.0, 2.0)),
            rotary(
                RotaryWord::C,
                [0.0, 0.0, 1.0],
                [0.01, 0.0, 0.0],
                (-600.0, 600.0),
            ),
        ],
        false,
    )
    .unwrap_or_else(|_| unreachable!("a valid machine"))
}

/// Target `gcode`: a G-code program read in mm from the origin (LinuxCNC's dialect) and in
/// inch from an offset start (the fanuc dialect, block delete on), and for a table-table
/// machine turning its `A` and `C`; its word report alongside.
/// Whatever reads is a continuous path of finite moves: each starts where the one before
/// ended, arcs have a radius > 0 and a sweep within their turns, dwells stay in place,
/// `point(0)` and `point(1)` are the ends, feeds are finite (0 for rapids and dwells, > 0
/// otherwise), and `Program::validate` agrees. No input panics, hangs or runs past a budget
/// (the reader's budgets are errors).
pub fn gcode(data: &[u8]) -> bool {
    let text = String::from_utf8_lossy(data);
    let mut loaded = false;
    for options in [
        gcode::GcodeOptions::default(),
        gcode::GcodeOptions {
            start: nalgebra::Vector3::new(0.1, -0.2, 0.3),
            units: LengthUnit::Inch,
            dialect: gcode::Dialect::Fanuc,
            block_delete: true,
            kinematics: None,
        },
        gcode::GcodeOptions {
            kinematics: Some(table_table()),
            ..gcode::GcodeOptions::default()
        },
    ] {
        if let Ok(words) = gcode::words(&text, &options) {
            assert!(words.iter().all(|w| w.count >= 1 && w.first_line >= 1));
        }
        let Ok(program) = gcode::from_str(&text, &options) else {
            continue;
        };
        let mut at = options.start;
        for m in &program.moves {
            assert!(
                (m.start - at).norm() <= 1e-9,
                "line {}: a move starts where the last ended",
                m.line
            );
            at = m.end;
            let finite = |v: &nalgebra::Vector3<f64>| v.iter().all(|x| x.is_finite());
            assert!(finite(&m.end) && m.length().is_finite(), "line {}", m.line);
            assert!(
                m.feed.is_finite() && m.spindle.is_finite(),
                "line {}",
                m.line
            );
            match m.motion {
                Motion::Rapid => assert_eq!(m.feed, 0.0),
                Motion::Dwell { seconds } => {
                    assert!(
                        seconds > 0.0 && m.feed == 0.0 && m.start == m.end,
                        "line {}",
                        m.line
                    )
                }
                Motion::Linear => assert!(m.feed > 0.0),
                Motion::Arc { sweep, .. } => {
                    assert!(m.feed > 0.0 && m.radius() > 0.0, "line {}", m.line);
                    let most =
                        std::f64::consts::TAU * f64::from(deflect_core::machining::MAX_ARC_TURNS);
                    assert!(
                        sweep != 0.0 && sweep.abs() <= most,
                        "line {}: sweep {sweep}",
                        m.line
                    );
                }
            }
            assert_eq!(m.point(0.0), m.start, "line {}", m.line);
            assert_eq!(m.point(1.0), m.end, "line {}", m.line);
            assert!(
                finite(&m.point(0.5)) && finite(&m.tangent(0.5)),
                "line {}",
                m.line
            );
        }
        // Whatever the reader accepts, the program's own check accepts.
        if let Err(e) = program.validate() {
            panic!("the reader's program fails Program::validate: {e}");
        }
        loaded |= !program.moves.is_empty();
    }
    loaded
}

/// Target `tool_table`: the bytes as a LinuxCNC tool table (mm and inch), as a TOML tool
/// table and as a tool-points CSV. Whatever loads is sane: every tool passes its own check
/// (number, diameter within the tool's bounds, flutes, helix, a corner radius within the
/// radius), the table is sorted by number without repeats, a point program is a continuous
/// chain of finite moves within `MAX_COORDINATE`. No input panics or hangs.
pub fn tool_table(data: &[u8]) -> bool {
    use deflect_core::io::{points_csv, tool_table as tt};
    let text = String::from_utf8_lossy(data);
    let mut loaded = false;
    let mut check = |t: deflect_core::machining::tools::ToolTable| {
        let tools = t.tools();
        for spec in tools {
            assert!(spec.validate().is_ok(), "{spec:?}");
            assert!(spec.cutter().radius().is_finite() && spec.cutter().radius() > 0.0);
        }
        assert!(tools.windows(2).all(|w| w[0].number < w[1].number));
        loaded = true;
    };
    for units in [LengthUnit::Millimetre, LengthUnit::Inch] {
        let o = tt::TblOptions {
            units,
            ..tt::TblOptions::default()
        };
        if let Ok(t) = tt::tbl_from_str(&text, &o) {
            check(t);
        }
    }
    if let Ok(t) = tt::toml_from_str(&text) {
        check(t);
    }
    if let Ok(p) = points_csv::from_str(&text, &gcode::GcodeOptions::default()) {
        let mut at = nalgebra::Vector3::zeros();
        for m in &p.moves {
            assert!((m.start - at).norm() == 0.0, "row {}", m.line);
            assert!(
                m.end
                    .iter()
                    .all(|v| v.abs() <= deflect_core::machining::MAX_COORDINATE),
                "row {}",
                m.line
            );
            assert!(m.feed.is_finite() && m.feed >= 0.0 && m.spindle.is_finite());
            at = m.end;
        }
        assert!(p.validate().is_ok());
        loaded = true;
    }
    loaded
}
