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
//! (cutter compensation, probing, threading, lathe, rotary axes, G88). The tool table holds
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
        rotated: bool,
    },
    Feed {
        end: [f64; 3],
        feed: f64,
        unit: f64,
        rotated: bool,
    },
    Arc {
        end: [f64; 3],
        plane: Plane,
        center: [f64; 2],
        rotation: i64,
        feed: f64,
        unit: f64,
        rotated: bool,
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
            "SET_G5X_OFFSET" => g5x = [v[1], v[2], v[3]],
            "SET_G92_OFFSET" => g92 = [v[0], v[1], v[2]],
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
                rotated: rot != 0.0,
            }),
            "STRAIGHT_FEED" => moves.push(Canon::Feed {
                end: machine([v[0], v[1], v[2]], unit),
                feed: feed(rate, unit),
                unit,
                rotated: rot != 0.0,
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
                    rotated: rot != 0.0,
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
    let mut k = 0usize;
    let ours = significant(moves);
    let close = |a: &[f64], b: &[f64], tol: f64| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol);
    let mut compared = 0;
    for (i, c) in canon.iter().enumerate() {
        let tol =
            |unit: f64, rotated: bool| 0.5e-4 * unit * if rotated { 1.5 } else { 1.0 } + 1e-12;
        match c {
            Canon::Rapid { end, unit, .. } | Canon::Feed { end, unit, .. } => {
                let null = (0..3).all(|j| (end[j] - prev[j]).abs() <= 1e-4 * unit);
                prev = *end;
                if null {
                    // A move rs274 prints to where the tool already is (to 4 decimals).
                    if ours.get(k).is_some_and(|m| {
                        matches!(m.motion, Motion::Rapid | Motion::Linear)
                            && close(m.end.as_slice(), end, 2e-4 * unit)
                            && (m.end - m.start).amax() <= 2e-4 * unit
                    }) {
                        k += 1;
                    }
                    continue;
                }
            }
            Canon::Arc { end, .. } => prev = *end,
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
            (Canon::Rapid { end, unit, rotated }, Motion::Rapid) => {
                if !close(m.end.as_slice(), end, tol(*unit, *rotated)) {
                    return mismatch("end");
                }
            }
            (
                Canon::Feed {
                    end,
                    feed,
                    unit,
                    rotated,
                },
                Motion::Linear,
            ) => {
                if !close(m.end.as_slice(), end, tol(*unit, *rotated)) {
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
                    rotated,
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
                if !close(m.end.as_slice(), end, tol(*unit, *rotated)) {
                    return mismatch("end");
                }
                if !close(&[mc[a], mc[b]], center, tol(*unit, *rotated)) {
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
const ASIDE: [&str; 7] = [
    "cutter radius compensation",
    "probing",
    "threading",
    "lathe",
    "rotary and secondary axes",
    "G88",
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
