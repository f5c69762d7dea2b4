//! deflect's G-code reader against LinuxCNC's interpreter, live: `rs274 -t TOOLS -g FILE`
//! prints the canonical moves of a program (in the program frame, in its units, 4 decimals);
//! deflect's moves (machine frame, SI) must be the same moves in the same order: kind, end
//! point, arc centre, plane, turns and direction, dwell time and feed, to the precision
//! `rs274` prints.
//!
//! Programs: the real CAM programs of `../shared/machining/real/` (not ours to commit: read
//! where they are; `DEFLECT_SHARED` overrides the folder) and LinuxCNC's mill samples in
//! `/usr/share/linuxcnc/ncfiles/`. Every program `rs274` runs to its end must read here with
//! the same moves, or be refused by name for what item 3 of the reader's docs refuses
//! (cutter compensation, probing, threading, lathe, rotary axes). The tool table holds
//! tools 1-99, every length zero (a robot's TCP carries the tool length).
//!
//! Without `rs274` (Debian's `linuxcnc-uspace`) the comparison prints that it was skipped.

use std::path::{Path, PathBuf};
use std::process::Command;

use deflect_core::LoadError;
use deflect_core::io::gcode::{self, Dialect, GcodeOptions};
use deflect_core::machining::{Motion, Move, Plane};

/// One canonical move of rs274, in the machine frame \[m\] (its program-frame numbers taken
/// through the offsets it announced), with its feed \[m/s\] and the unit it printed in.
#[derive(Debug, Clone, PartialEq)]
enum Canon {
    Rapid {
        end: [f64; 3],
        unit: f64,
        slack: f64,
    },
    Feed {
        end: [f64; 3],
        feed: f64,
        unit: f64,
        slack: f64,
    },
    Arc {
        end: [f64; 3],
        plane: Plane,
        center: [f64; 2],
        rotation: i64,
        feed: f64,
        unit: f64,
        slack: f64,
    },
    Dwell(f64),
    Spline,
}

/// What rs274 printed: the moves and, when it stopped on an error, the message and the text
/// of the offending line.
struct Run {
    moves: Vec<Canon>,
    error: Option<(String, String)>,
}

fn rs274() -> Option<PathBuf> {
    let out = Command::new("sh")
        .args(["-c", "command -v rs274"])
        .output()
        .ok()?;
    let path = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (!path.is_empty()).then(|| PathBuf::from(path))
}

/// A private HOME (rs274 keeps its tool table in `$HOME/.tool.mmap`) with a table of tools
/// 1-99, lengths zero.
fn workdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("deflect-rs274-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let table: String = (1..=99)
        .map(|t| format!("T{t} P{t} D{:.3} Z0 ;tool {t}\n", 0.1 * f64::from(t)))
        .collect();
    std::fs::write(dir.join("tools.tbl"), table).unwrap();
    dir
}

fn numbers(args: &str) -> Vec<f64> {
    args.split([',', ' '])
        .filter(|s| !s.is_empty())
        .filter_map(|s| s.parse().ok())
        .collect()
}

/// Runs rs274 on `file` and reads its output.
fn run_rs274(rs274: &Path, dir: &Path, file: &Path) -> Run {
    let out = Command::new(rs274)
        .env("HOME", dir)
        .current_dir(dir)
        .arg("-t")
        .arg(dir.join("tools.tbl"))
        .arg("-g")
        .arg(file)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let (mut unit, mut rate, mut per_rev, mut speed) = (1.0e-3, 0.0, false, 0.0);
    let (mut g5x, mut g92, mut rot) = ([0.0; 3], [0.0; 3], 0.0f64);
    // The offsets are printed to 4 decimals of the unit in force then: their rounding [m].
    let (mut g5x_res, mut g92_res) = (0.0f64, 0.0f64);
    let mut plane = Plane::Xy;
    let mut moves = Vec::new();
    for line in stdout.lines() {
        // "   12 N..... NAME(args)"
        let Some(call) = line.split_whitespace().nth(2) else {
            continue;
        };
        let rest = &line[line.find(call).unwrap()..];
        let (name, args) = match rest.find('(') {
            Some(k) => (&rest[..k], rest[k + 1..].trim_end_matches(')')),
            None => (rest, ""),
        };
        let v = numbers(args);
        let machine = |p: [f64; 3], unit: f64| {
            let (s, c) = rot.to_radians().sin_cos();
            let (x, y) = (p[0] + g92[0], p[1] + g92[1]);
            [
                (x * c - y * s + g5x[0]) * unit,
                (x * s + y * c + g5x[1]) * unit,
                (p[2] + g92[2] + g5x[2]) * unit,
            ]
        };
        let feed = |rate: f64, unit: f64| {
            if per_rev {
                rate * speed * unit / 60.0
            } else {
                rate * unit / 60.0
            }
        };
        match name {
            "USE_LENGTH_UNITS" => {
                let new = if args.contains("INCHES") {
                    25.4e-3
                } else {
                    1.0e-3
                };
                // rs274 converts the offsets it holds; so do we.
                let k = unit / new;
                for o in g5x.iter_mut().chain(g92.iter_mut()) {
                    *o *= k;
                }
                unit = new;
            }
            "SET_G5X_OFFSET" => {
                g5x = [v[1], v[2], v[3]];
                g5x_res = if g5x.iter().any(|x| *x != 0.0) {
                    0.5e-4 * unit
                } else {
                    0.0
                };
            }
            "SET_G92_OFFSET" => {
                g92 = [v[0], v[1], v[2]];
                g92_res = if g92.iter().any(|x| *x != 0.0) {
                    0.5e-4 * unit
                } else {
                    0.0
                };
            }
            "SET_XY_ROTATION" => rot = v[0],
            "SET_FEED_RATE" => rate = v[0],
            "SET_FEED_MODE" => per_rev = v.get(1) == Some(&1.0),
            "SET_SPINDLE_SPEED" => speed = v[1],
            "SELECT_PLANE" => {
                plane = if args.contains("XZ") {
                    Plane::Zx
                } else if args.contains("YZ") {
                    Plane::Yz
                } else {
                    Plane::Xy
                }
            }
            "STRAIGHT_TRAVERSE" => moves.push(Canon::Rapid {
                end: machine([v[0], v[1], v[2]], unit),
                unit,
                slack: (g5x_res + g92_res) * if rot != 0.0 { 1.5 } else { 1.0 }
                    + if rot != 0.0 { 0.25e-4 * unit } else { 0.0 },
            }),
            "STRAIGHT_FEED" => moves.push(Canon::Feed {
                end: machine([v[0], v[1], v[2]], unit),
                feed: feed(rate, unit),
                unit,
                slack: (g5x_res + g92_res) * if rot != 0.0 { 1.5 } else { 1.0 }
                    + if rot != 0.0 { 0.25e-4 * unit } else { 0.0 },
            }),
            "ARC_FEED" => {
                // first_end, second_end, first_centre, second_centre, rotation, axis_end
                let (a, b, n) = plane.axes();
                let mut end = [0.0; 3];
                end[a] = v[0];
                end[b] = v[1];
                end[n] = v[5];
                let mut c = [0.0; 3];
                c[a] = v[2];
                c[b] = v[3];
                c[n] = v[5];
                let cm = machine(c, unit);
                moves.push(Canon::Arc {
                    end: machine(end, unit),
                    plane,
                    center: [cm[a], cm[b]],
                    rotation: v[4] as i64,
                    feed: feed(rate, unit),
                    unit,
                    slack: (g5x_res + g92_res) * if rot != 0.0 { 1.5 } else { 1.0 }
                        + if rot != 0.0 { 0.25e-4 * unit } else { 0.0 },
                });
            }
            "DWELL" => moves.push(Canon::Dwell(v[0])),
            "NURBS_FEED" => moves.push(Canon::Spline),
            _ => {}
        }
    }
    let error = (!out.status.success()).then(|| {
        let mut l = stderr.lines().filter(|l| *l != "executing");
        (
            l.next().unwrap_or("").to_string(),
            l.next().unwrap_or("").trim().to_string(),
        )
    });
    Run { moves, error }
}

/// deflect's moves with rs274's null straight moves taken out on both sides.
fn significant(moves: &[Move]) -> Vec<Move> {
    moves
        .iter()
        .filter(|m| match m.motion {
            Motion::Rapid | Motion::Linear => (m.end - m.start).amax() >= 0.5e-7,
            _ => true,
        })
        .copied()
        .collect()
}

/// The first difference between rs274's moves and deflect's, if any.
fn compare(canon: &[Canon], moves: &[Move], prefix: bool) -> Result<usize, String> {
    let mut prev = [0.0f64; 3];
    let mut prev_res = 0.0f64;
    let mut k = 0usize;
    let ours = significant(moves);
    let close = |a: &[f64], b: &[f64], tol: f64| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol);
    let mut compared = 0;
    for (i, c) in canon.iter().enumerate() {
        let tol = |unit: f64, slack: f64| 0.5e-4 * unit + slack + 1e-12;
        match c {
            Canon::Rapid {
                end, unit, slack, ..
            }
            | Canon::Feed {
                end, unit, slack, ..
            } => {
                // Both points as printed, each to 4 decimals of its unit, offsets included.
                let res = 0.5e-4 * unit + slack;
                let null = (0..3).all(|j| (end[j] - prev[j]).abs() <= res + prev_res + 1e-12);
                prev = *end;
                prev_res = res;
                if null {
                    // A move rs274 prints to where the tool already is (to 4 decimals).
                    if ours.get(k).is_some_and(|m| {
                        matches!(m.motion, Motion::Rapid | Motion::Linear)
                            && close(m.end.as_slice(), end, 4.0 * res)
                            && (m.end - m.start).amax() <= 4.0 * res
                    }) {
                        k += 1;
                    }
                    continue;
                }
            }
            Canon::Arc {
                end, unit, slack, ..
            } => {
                prev = *end;
                prev_res = 0.5e-4 * unit + slack;
            }
            Canon::Dwell(t) if *t <= 0.0 => continue,
            _ => {}
        }
        let Some(m) = ours.get(k) else {
            return Err(format!(
                "rs274 move {i} {c:?}: deflect has no more moves ({k})"
            ));
        };
        let mismatch = |what: &str| {
            Err(format!(
                "rs274 move {i} {c:?} vs deflect move {k} {m:?}: {what}"
            ))
        };
        match (c, m.motion) {
            (Canon::Rapid { end, unit, slack }, Motion::Rapid) => {
                if !close(m.end.as_slice(), end, tol(*unit, *slack)) {
                    return mismatch("end");
                }
            }
            (
                Canon::Feed {
                    end,
                    feed,
                    unit,
                    slack,
                },
                Motion::Linear,
            ) => {
                if !close(m.end.as_slice(), end, tol(*unit, *slack)) {
                    return mismatch("end");
                }
                if (m.feed - feed).abs() > 0.5e-4 * unit / 60.0 + 1e-9 * feed {
                    return mismatch("feed");
                }
            }
            (
                Canon::Arc {
                    end,
                    plane,
                    center,
                    rotation,
                    feed,
                    unit,
                    slack,
                },
                Motion::Arc {
                    plane: p,
                    center: mc,
                    sweep,
                },
            ) => {
                let (a, b, _) = plane.axes();
                let turns = (sweep.abs() / std::f64::consts::TAU - 1e-9).ceil() as i64;
                if *plane != p {
                    return mismatch("plane");
                }
                if !close(m.end.as_slice(), end, tol(*unit, *slack)) {
                    return mismatch("end");
                }
                if !close(&[mc[a], mc[b]], center, tol(*unit, *slack)) {
                    return mismatch("centre");
                }
                if turns * sweep.signum() as i64 != *rotation {
                    return mismatch("direction or turns");
                }
                if (m.feed - feed).abs() > 0.5e-4 * unit / 60.0 + 1e-9 * feed {
                    return mismatch("feed");
                }
            }
            (Canon::Dwell(t), Motion::Dwell { seconds }) => {
                if (seconds - t).abs() > 0.5e-4 {
                    return mismatch("dwell");
                }
            }
            (Canon::Spline, Motion::Linear) => {
                // A spline is lines here: all of the line's chords.
                let line = m.line;
                while ours
                    .get(k + 1)
                    .is_some_and(|n| n.line == line && n.motion == Motion::Linear)
                {
                    k += 1;
                }
                prev = ours.get(k).map_or(prev, |n| n.end.into());
            }
            _ => return mismatch("kind"),
        }
        k += 1;
        compared += 1;
    }
    if k < ours.len() && !prefix {
        return Err(format!(
            "deflect has {} moves more than rs274 (the first: {:?})",
            ours.len() - k,
            ours.get(k)
        ));
    }
    Ok(compared)
}

/// The refusals item 3 of the reader's docs allows for a program rs274 runs.
const ASIDE: [&str; 6] = [
    "cutter radius compensation",
    "probing",
    "threading",
    "lathe",
    "rotary and secondary axes",
    "$ (spindle selection)",
];

fn shared() -> PathBuf {
    std::env::var_os("DEFLECT_SHARED").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared"),
        PathBuf::from,
    )
}

fn programs(dir: &Path, ext: &[&str]) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.extension()
                        .is_some_and(|e| ext.iter().any(|x| e.eq_ignore_ascii_case(x)))
                })
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Reads `file` with deflect and compares it with rs274's run. Returns what happened.
fn check(rs274: &Path, dir: &Path, file: &Path) -> Result<String, String> {
    let name = file.file_name().unwrap().to_string_lossy().to_string();
    let text = String::from_utf8_lossy(&std::fs::read(file).unwrap()).to_string();
    let run = run_rs274(rs274, dir, file);
    let ours = gcode::from_str(&text, &GcodeOptions::default());
    match (&run.error, ours) {
        (None, Ok(p)) => compare(&run.moves, &p.moves, false)
            .map(|n| format!("{name}: {n} moves equal"))
            .map_err(|e| format!("{name}: {e}")),
        (None, Err(e)) => {
            let s = e.to_string();
            if ASIDE.iter().any(|a| s.contains(a)) {
                Ok(format!("{name}: aside, refused by name: {s}"))
            } else {
                Err(format!("{name}: rs274 runs it, deflect refuses: {s}"))
            }
        }
        (Some((msg, text_line)), Ok(p)) => {
            // Where rs274 stops, deflect must too (the lenient end of file aside).
            if msg.starts_with("File ended with no percent sign") {
                compare(&run.moves, &p.moves, false)
                    .map(|n| format!("{name}: {n} moves equal (rs274: {msg})"))
                    .map_err(|e| format!("{name}: {e}"))
            } else {
                Err(format!(
                    "{name}: rs274 refuses ({msg}: {text_line}), deflect reads it"
                ))
            }
        }
        (Some((msg, text_line)), Err(e)) => {
            let line = match &e {
                LoadError::Program { line, .. } => *line,
                _ => 0,
            };
            let ours_text = text.lines().nth(line.wrapping_sub(1)).unwrap_or("").trim();
            if ours_text == text_line {
                Ok(format!("{name}: both refuse line {line} ({msg} / {e})"))
            } else {
                Ok(format!(
                    "{name}: both refuse, at different lines: rs274 {text_line:?} ({msg}), deflect {ours_text:?} ({e})"
                ))
            }
        }
    }
}

#[test]
fn real_cam_programs_read_move_for_move_as_linuxcnc_reads_them() {
    let Some(rs274) = rs274() else {
        println!("rs274 (Debian's linuxcnc-uspace) not found: the LinuxCNC comparison was skipped");
        return;
    };
    let real = shared().join("machining/real");
    let files = programs(&real, &["nc", "ngc", "tap", "gcode", "txt", "cnc"]);
    if files.is_empty() {
        println!(
            "{}: no programs; the real-program comparison was skipped",
            real.display()
        );
        return;
    }
    let dir = workdir("real");
    let mut failures = Vec::new();
    for f in &files {
        let text = String::from_utf8_lossy(&std::fs::read(f).unwrap()).to_string();
        let run = run_rs274(&rs274, &dir, f);
        match check(&rs274, &dir, f) {
            Ok(s) => println!("{s}"),
            Err(e) => failures.push(e),
        }
        // A program rs274 refuses (FreeCAD's grbl post: K0.000 on G17 arcs) is refused here
        // too, and its dialect reads it: the moves before rs274's refusal are rs274's.
        if let Some((msg, _)) = &run.error
            && !msg.starts_with("File ended")
        {
            let grbl = GcodeOptions {
                dialect: Dialect::Grbl,
                ..GcodeOptions::default()
            };
            match gcode::from_str(&text, &grbl) {
                Ok(p) => match compare(&run.moves, &p.moves, true) {
                    Ok(n) => println!(
                        "  grbl dialect: reads it, its first {n} moves equal rs274's before its refusal"
                    ),
                    Err(e) => failures.push(format!("{}: grbl dialect: {e}", f.display())),
                },
                Err(e) => failures.push(format!("{}: grbl dialect refuses: {e}", f.display())),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn linuxcnc_sample_programs_read_move_for_move() {
    let Some(rs274) = rs274() else {
        println!("rs274 (Debian's linuxcnc-uspace) not found: the LinuxCNC comparison was skipped");
        return;
    };
    let samples = Path::new("/usr/share/linuxcnc/ncfiles");
    let files = programs(samples, &["ngc"]);
    let dir = workdir("samples");
    let mut failures = Vec::new();
    for f in &files {
        match check(&rs274, &dir, f) {
            Ok(s) => println!("{s}"),
            Err(e) => failures.push(e),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_feature_reads_move_for_move() {
    // The fixtures exercise every word of the reader's docs: cycles, planes, offsets, feed
    // modes, the language, splines, tools. rs274 runs each to its end.
    let Some(rs274) = rs274() else {
        println!("rs274 (Debian's linuxcnc-uspace) not found: the LinuxCNC comparison was skipped");
        return;
    };
    let dir = workdir("fixtures");
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/gcode");
    let files = programs(&fixtures, &["ngc"]);
    assert!(files.len() >= 7, "{}", fixtures.display());
    let mut failures = Vec::new();
    for f in &files {
        let run = run_rs274(&rs274, &dir, f);
        if let Some((msg, line)) = &run.error {
            failures.push(format!("{}: rs274 refuses {line:?}: {msg}", f.display()));
            continue;
        }
        match check(&rs274, &dir, f) {
            Ok(s) => println!("{s}"),
            Err(e) => failures.push(e),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A small deterministic generator (xorshift64*), so the random programs are the same in
/// every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.below(items.len() as u64) as usize]
    }
}

/// A number as a program writes it (fixed point, no exponent).
fn num(v: f64) -> String {
    format!("{v:.4}")
}

/// A random program: moves in either distance mode and unit, arcs in the three planes (by
/// centre, radius and turns, written incrementally so they are valid wherever the tool is),
/// canned cycles, dwells, work and axis offsets, machine coordinates, the stored points, feed
/// modes, path control and parameters.
fn random_program(rng: &mut Rng) -> String {
    let mut p = String::from("G21 G17 G90 G94 F300 S5000 M3\nG0 X0 Y0 Z5\n");
    let mut inch = false;
    let mut inverse = false;
    p.push_str("G28.1\nG0 X3 Y-2 Z8\nG30.1\n");
    for _ in 0..30 {
        let s = if inch { 1.0 / 25.4 } else { 1.0 };
        let f = if inverse {
            format!(" F{}", num(rng.uniform(0.5, 20.0)))
        } else {
            String::new()
        };
        match rng.below(14) {
            0 | 1 => {
                let g = rng.pick(&["G0", "G1"]);
                let mut l = format!("G90 {g}");
                for a in ["X", "Y", "Z"] {
                    if rng.below(3) > 0 {
                        l += &format!(" {a}{}", num(rng.uniform(-40.0, 40.0) * s));
                    }
                }
                if g == "G1" {
                    l += &f;
                }
                p += &format!("{l}\n");
            }
            2 => {
                p += &format!(
                    "G91 G1 X{} Y[{} + #1]{f}\nG90\n",
                    num(rng.uniform(-9.0, 9.0) * s),
                    num(rng.uniform(-9.0, 9.0) * s)
                )
            }
            3 | 4 => {
                // An arc by its centre: the end is the start turned about the centre.
                let (plane, w) = *[
                    ("G17", ["X", "Y", "I", "J", "Z"]),
                    ("G18", ["Z", "X", "K", "I", "Y"]),
                    ("G19", ["Y", "Z", "J", "K", "X"]),
                ]
                .get(rng.below(3) as usize)
                .unwrap();
                let (ci, cj) = (rng.uniform(-10.0, 10.0) * s, rng.uniform(-10.0, 10.0) * s);
                let th = rng.uniform(-6.0, 6.0);
                let (sn, cs) = th.sin_cos();
                // start at the origin of the offsets: end = c - R(th) c
                let (ex, ey) = (ci - (cs * ci - sn * cj), cj - (sn * ci + cs * cj));
                let dir = if th > 0.0 { "G3" } else { "G2" };
                let turns = if rng.below(4) == 0 {
                    format!(" P{}", 1 + rng.below(3))
                } else {
                    String::new()
                };
                let helix = if rng.below(2) == 0 {
                    format!(" {}{}", w[4], num(rng.uniform(-3.0, 3.0) * s))
                } else {
                    String::new()
                };
                p += &format!(
                    "{plane} G91 {dir} {}{} {}{} {}{} {}{}{helix}{turns}{f}\nG90 G17\n",
                    w[0],
                    num(ex),
                    w[1],
                    num(ey),
                    w[2],
                    num(ci),
                    w[3],
                    num(cj)
                );
            }
            5 => {
                // An arc by its radius.
                let (dx, dy) = (rng.uniform(-10.0, 10.0) * s, rng.uniform(-10.0, 10.0) * s);
                let r = (dx.hypot(dy) / 2.0)
                    * rng.uniform(1.01, 3.0)
                    * if rng.below(2) == 0 { -1.0 } else { 1.0 };
                let dir = rng.pick(&["G2", "G3"]);
                p += &format!("G91 {dir} X{} Y{} R{}{f}\nG90\n", num(dx), num(dy), num(r));
            }
            6 if !inverse => {
                let c = rng.pick(&[
                    "G81", "G82 P0.3", "G83 Q1.1", "G73 Q0.7", "G85", "G89 P0.2", "G86 P0.1",
                ]);
                let rm = rng.pick(&["G98", "G99"]);
                let (z, r) = (rng.uniform(-8.0, -1.0) * s, rng.uniform(0.5, 4.0) * s);
                p += &format!(
                    "{rm} {c} X{} Y{} Z{} R{}\nX{}\nG80\n",
                    num(rng.uniform(-30.0, 30.0) * s),
                    num(rng.uniform(-30.0, 30.0) * s),
                    num(z),
                    num(r),
                    num(rng.uniform(-30.0, 30.0) * s)
                );
            }
            7 => p += &format!("G4 P{}\n", num(rng.uniform(0.0, 2.0))),
            8 => {
                let n = 1 + rng.below(9);
                let rot = if rng.below(3) == 0 {
                    format!(" R{}", num(rng.uniform(-90.0, 90.0)))
                } else {
                    String::new()
                };
                // (A new rotation with G92 set moves LinuxCNC's tool without a move; the reader
                // keeps the tool where it is: the generator clears G92 first.)
                p += &format!(
                    "G92.1\nG10 L2 P{n} X{} Y{} Z{}{rot}\n{}\n",
                    num(rng.uniform(-20.0, 20.0) * s),
                    num(rng.uniform(-20.0, 20.0) * s),
                    num(rng.uniform(-5.0, 5.0) * s),
                    rng.pick(&[
                        "G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3"
                    ])
                );
            }
            9 => {
                p += &format!(
                    "{}\n",
                    rng.pick(&[
                        "G92 X0 Y0",
                        "G92.1",
                        "G92.2",
                        "G92.3",
                        "G52 X2 Y-3",
                        "G10 L20 P0 X1 Y1 Z1"
                    ])
                )
            }
            10 if !inverse => {
                p += &format!(
                    "{}\n",
                    rng.pick(&[
                        "G28",
                        "G28 G91 Z2\nG90",
                        "G30 X1",
                        "G53 G0 Z10",
                        "G53 G1 X5 Y5",
                        "G28 X1 Y1"
                    ])
                )
            }
            11 => {
                inch = !inch;
                p += if inch { "G20\n" } else { "G21\n" };
            }
            12 => {
                inverse = !inverse;
                p += if inverse { "G93\n" } else { "G94 F350\n" };
            }
            _ => {
                p += &format!(
                    "#1 = [{} * SIN[{}]]\n{}\n",
                    num(rng.uniform(-3.0, 3.0)),
                    num(rng.uniform(0.0, 360.0)),
                    rng.pick(&[
                        "G64 P0.01",
                        "G61",
                        "G64",
                        "G61.1",
                        "G95 F0.02\nG1 X1\nG94 F300"
                    ])
                )
            }
        }
    }
    p + "M2\n"
}

#[test]
fn random_programs_read_move_for_move() {
    let Some(rs274) = rs274() else {
        println!("rs274 (Debian's linuxcnc-uspace) not found: the LinuxCNC comparison was skipped");
        return;
    };
    let dir = workdir("random");
    // DEFLECT_RS274_RANDOM="count,seed" runs more (a longer hunt by hand).
    let (count, seed) = std::env::var("DEFLECT_RS274_RANDOM")
        .ok()
        .and_then(|v| {
            let (c, s) = v.split_once(',')?;
            Some((c.parse().ok()?, s.parse().ok()?))
        })
        .unwrap_or((150usize, 0x9e37_79b9_7f4a_7c15u64));
    let mut rng = Rng(seed);
    let (mut equal, mut refused) = (0, 0);
    let mut failures = Vec::new();
    for k in 0..count {
        let text = random_program(&mut rng);
        let file = dir.join(format!("random_{k}.ngc"));
        std::fs::write(&file, &text).unwrap();
        match check(&rs274, &dir, &file) {
            Ok(s) if s.contains("both refuse") => refused += 1,
            Ok(_) => equal += 1,
            // A documented refusal: a G18/G19 arc is not in a principal plane of the machine
            // frame once the work offset turns the XY plane (G10 L2 R).
            Err(e) if e.contains("rotated coordinate system") => refused += 1,
            Err(e) => failures.push(format!("{e}\n--- program:\n{text}")),
        }
    }
    println!("{equal} random programs with equal moves, {refused} refused by both");
    assert!(
        failures.is_empty(),
        "{}",
        failures.first().map_or("", |s| s.as_str())
    );
    assert!(
        equal * 3 >= count * 2,
        "only {equal} of {count} random programs ran in rs274"
    );
}
