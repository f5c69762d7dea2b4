//! ISO G-code programs (`std`): the subset a CAM post-processor writes for 2.5-D and 3-axis
//! milling, read into a [`Program`] of moves in the workpiece frame, SI.
//!
//! | words | meaning |
//! |---|---|
//! | `G0` `G1` `G2` `G3` | rapid, linear, clockwise and counter-clockwise arc (modal) |
//! | `G17` | arcs in the XY plane (the only plane: `G18`/`G19` are refused) |
//! | `G20` `G21` | inch, mm (before the first coordinate; a switch later is refused) |
//! | `G90` `G91` | absolute, incremental coordinates (modal) |
//! | `G40` `G49` `G54` `G80` `G94` | the cancel and default states of a CAM preamble: accepted, no effect |
//! | `X` `Y` `Z` | end point (modal per axis) |
//! | `I` `J` / `R` | arc centre offset from the start (always incremental) / radius (< 0: over 180 deg) |
//! | `F` | feed per minute (modal; required before the first `G1`/`G2`/`G3`) |
//! | `S` `M3` `M5` | spindle speed \[rpm\], on (clockwise), off |
//! | `M2` `M30` | program end (only blank lines, comments and `%` may follow) |
//! | `N` | line number (first word of a line; not checked) |
//! | `( ... )` `;` `%` | comments, tape markers |
//!
//! Anything else (another word, a second word of the same group on a line, a number that is
//! not finite or out of range, an arc whose end is not on its circle) is a
//! [`LoadError::Program`] naming the line, the column and what was expected. Without `G20`
//! or `G21` the program is read in mm (the ISO default; [`GcodeOptions::units`]). Arcs keep
//! the programmed end point; their centre comes from `I`/`J` (radius consistency within
//! [`ARC_TOLERANCE`]) or from `R`.

use std::format;
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use nalgebra::{Vector2, Vector3};

use crate::error::LoadError;
use crate::machining::{MAX_MOVES, Motion, Move, Program};
use crate::units::LengthUnit;

/// Most lines a program may have: 1,000,000 (about 20 MB of G-code, beyond
/// [`super::MAX_FILE_BYTES`] for typical lines anyway); refused before parsing.
pub const MAX_PROGRAM_LINES: usize = 1_000_000;

// The limits every program holds, whatever its source (checked again by
// `Program::validate`).
pub use crate::machining::{ARC_TOLERANCE, MAX_COORDINATE, MAX_FEED, MAX_SPINDLE_RPM};

/// Settings of the reader.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GcodeOptions {
    /// Where the tool is before the first move \[m\], workpiece frame (the first move starts
    /// there; incremental coordinates count from it). Default: the origin.
    pub start: Vector3<f64>,
    /// Length unit until the program says `G20` or `G21`. Default: mm.
    pub units: LengthUnit,
}

impl Default for GcodeOptions {
    fn default() -> Self {
        Self {
            start: Vector3::zeros(),
            units: LengthUnit::Millimetre,
        }
    }
}

/// Reads a G-code file (at most [`super::MAX_FILE_BYTES`]).
pub fn from_path(path: &Path, options: &GcodeOptions) -> Result<Program, LoadError> {
    let text = super::read_text(path)?;
    from_str(&text, options)
}

/// Reads a G-code program from its text.
pub fn from_str(text: &str, options: &GcodeOptions) -> Result<Program, LoadError> {
    super::check_size("G-code program", text)?;
    let lines = text.lines().count();
    if lines > MAX_PROGRAM_LINES {
        return Err(LoadError::TooLarge {
            what: "G-code program lines".to_string(),
            limit: MAX_PROGRAM_LINES,
            got: lines,
        });
    }
    let mut reader = Reader::new(options)?;
    let mut words = Vec::with_capacity(16);
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        words.clear();
        lex(raw, line, &mut words)?;
        if words.is_empty() {
            continue;
        }
        if let Some(end) = reader.ended {
            let (column, letter, _) = words.first().copied().unwrap_or((1, 'N', 0.0));
            return Err(error(
                line,
                column,
                format!(
                    "nothing after the program end (line {end}), got the word {letter}; only \
                     blank lines, comments and % may follow"
                ),
            ));
        }
        reader.line(line, &words)?;
    }
    Ok(Program {
        moves: reader.moves,
    })
}

/// A word: its column (1-based), its letter (upper case) and its number.
type Word = (usize, char, f64);

fn error(line: usize, column: usize, message: String) -> LoadError {
    LoadError::Program {
        line,
        column,
        message,
    }
}

/// The words of one line, comments dropped.
fn lex(raw: &str, line: usize, words: &mut Vec<Word>) -> Result<(), LoadError> {
    let bytes = raw.as_bytes();
    let trimmed = raw.trim();
    if trimmed == "%" {
        return Ok(());
    }
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        let column = i + 1;
        match b {
            b' ' | b'\t' | b'\r' => i += 1,
            b'(' => match bytes
                .get(i..)
                .and_then(|r| r.iter().position(|&c| c == b')'))
            {
                Some(close) => i += close + 1,
                None => {
                    return Err(error(
                        line,
                        column,
                        "a ')' closing this comment".to_string(),
                    ));
                }
            },
            b';' => break,
            b if b.is_ascii_alphabetic() => {
                let letter = char::from(b.to_ascii_uppercase());
                i += 1;
                while matches!(bytes.get(i), Some(b' ' | b'\t')) {
                    i += 1;
                }
                let start = i;
                if matches!(bytes.get(i), Some(b'+' | b'-')) {
                    i += 1;
                }
                let digits_from = i;
                while matches!(bytes.get(i), Some(c) if c.is_ascii_digit() || *c == b'.') {
                    i += 1;
                }
                let text = raw.get(start..i).unwrap_or("");
                let digits = raw.get(digits_from..i).unwrap_or("");
                let value = if digits.bytes().any(|c| c.is_ascii_digit())
                    && digits.bytes().filter(|&c| c == b'.').count() <= 1
                {
                    text.parse::<f64>().ok()
                } else {
                    None
                };
                let Some(value) = value else {
                    let got = raw.get(start..).and_then(|r| r.split_whitespace().next());
                    return Err(error(
                        line,
                        start + 1,
                        format!(
                            "a number after {letter} (digits with at most one '.'), got {}",
                            got.map_or("the end of the line".to_string(), |g| format!("{g:?}"))
                        ),
                    ));
                };
                if !value.is_finite() {
                    return Err(error(
                        line,
                        start + 1,
                        format!("a finite number after {letter}, got {text}"),
                    ));
                }
                words.push((column, letter, value));
            }
            b'%' => {
                return Err(error(line, column, "'%' alone on its line".to_string()));
            }
            _ => {
                let got = raw.get(i..).and_then(|r| r.chars().next()).unwrap_or(' ');
                return Err(error(
                    line,
                    column,
                    format!("a word (a letter and a number), a comment or ';', got {got:?}"),
                ));
            }
        }
    }
    Ok(())
}

/// The modal state of a program being read.
struct Reader {
    units: f64,
    /// Whether a length has been read (units may not change after that).
    lengths_seen: bool,
    absolute: bool,
    motion: Option<u8>,
    feed: Option<f64>,
    spindle_rpm: f64,
    spindle_on: bool,
    position: Vector3<f64>,
    ended: Option<usize>,
    moves: Vec<Move>,
}

impl Reader {
    fn new(options: &GcodeOptions) -> Result<Self, LoadError> {
        if !options
            .start
            .iter()
            .all(|v| v.is_finite() && v.abs() <= MAX_COORDINATE)
        {
            return Err(LoadError::InvalidValue {
                element: "G-code options".to_string(),
                field: "start (m)",
                expected: format!("finite, within +-{MAX_COORDINATE} m"),
                got: format!("{:?}", options.start.as_slice()),
            });
        }
        Ok(Self {
            units: options.units.to_metre(),
            lengths_seen: false,
            absolute: true,
            motion: None,
            feed: None,
            spindle_rpm: 0.0,
            spindle_on: false,
            position: options.start,
            ended: None,
            moves: Vec::new(),
        })
    }

    fn line(&mut self, line: usize, words: &[Word]) -> Result<(), LoadError> {
        let mut axes: [Option<(usize, f64)>; 8] = [None; 8];
        let mut motion: Option<(usize, u8)> = None;
        // G17 is the only plane: its slot only catches a second plane word on the line.
        let mut plane = None;
        let mut units = None;
        let mut distance = None;
        let mut m_word: Option<(usize, u8)> = None;
        for (k, &(column, letter, value)) in words.iter().enumerate() {
            let err = |m: String| Err(error(line, column, m));
            let whole =
                |v: f64| (v.fract() == 0.0 && (0.0..1000.0).contains(&v)).then_some(v as u16);
            match letter {
                'N' => {
                    if k != 0 {
                        return err("N (the line number) as the first word of the line".into());
                    }
                    if value.fract() != 0.0 || value < 0.0 {
                        return err(format!("a line number N >= 0 (an integer), got N{value}"));
                    }
                }
                'G' => {
                    let Some(g) = whole(value) else {
                        return err(format!("a G code of the supported set, got G{value}"));
                    };
                    let slot = match g {
                        0..=3 => &mut motion,
                        17 => &mut plane,
                        20 | 21 => &mut units,
                        90 | 91 => &mut distance,
                        40 | 49 | 54 | 80 | 94 => continue,
                        18 | 19 => {
                            return err(format!(
                                "G17 (arcs in the XY plane, the only plane supported), got G{g}"
                            ));
                        }
                        _ => {
                            return err(format!(
                                "a supported G code (G0-G3, G17, G20/G21, G90/G91, or G40, G49, \
                                 G54, G80, G94), got G{g}"
                            ));
                        }
                    };
                    if let Some((c, other)) = *slot {
                        return err(format!(
                            "one G code of its group per line, got G{other} (column {c}) and G{g}"
                        ));
                    }
                    *slot = Some((column, g as u8));
                }
                'M' => {
                    let m = match whole(value) {
                        Some(m @ (2 | 3 | 5 | 30)) => m as u8,
                        _ => {
                            return err(format!(
                                "a supported M code (M3 spindle on, M5 off, M2/M30 end), got \
                                 M{value}"
                            ));
                        }
                    };
                    if let Some((c, other)) = m_word {
                        return err(format!(
                            "one M code per line, got M{other} (column {c}) and M{m}"
                        ));
                    }
                    m_word = Some((column, m));
                }
                'X' | 'Y' | 'Z' | 'I' | 'J' | 'R' | 'F' | 'S' => {
                    let slot = match letter {
                        'X' => 0,
                        'Y' => 1,
                        'Z' => 2,
                        'I' => 3,
                        'J' => 4,
                        'R' => 5,
                        'F' => 6,
                        _ => 7,
                    };
                    if let Some(s) = axes.get_mut(slot) {
                        if let Some((c, _)) = *s {
                            return err(format!("{letter} once per line (also at column {c})"));
                        }
                        *s = Some((column, value));
                    }
                }
                _ => {
                    return err(format!(
                        "a supported word (N, G, M, X, Y, Z, I, J, R, F, S), got {letter}"
                    ));
                }
            }
        }
        let [x, y, z, i, j, r, f, s] = axes;
        if let Some((column, g)) = units {
            let unit = if g == 20 {
                LengthUnit::Inch.to_metre()
            } else {
                LengthUnit::Millimetre.to_metre()
            };
            if self.lengths_seen && unit != self.units {
                return Err(error(
                    line,
                    column,
                    format!(
                        "one unit for the whole program: G{g} after lengths in {}",
                        if self.units == 1.0e-3 {
                            "mm (G21)"
                        } else {
                            "inch (G20)"
                        }
                    ),
                ));
            }
            self.units = unit;
        }
        if let Some((_, g)) = distance {
            self.absolute = g == 90;
        }
        if let Some((column, rpm)) = s {
            if !(0.0..=MAX_SPINDLE_RPM).contains(&rpm) {
                return Err(error(
                    line,
                    column,
                    format!("a spindle speed S in [0, {MAX_SPINDLE_RPM}] rpm, got S{rpm}"),
                ));
            }
            self.spindle_rpm = rpm;
        }
        if let Some((column, feed)) = f {
            let v = feed * self.units / 60.0;
            if !(feed > 0.0 && v <= MAX_FEED) {
                return Err(error(
                    line,
                    column,
                    format!("a feed F > 0 and at most {MAX_FEED} m/s, got F{feed}"),
                ));
            }
            self.lengths_seen = true;
            self.feed = Some(v);
        }
        match m_word {
            Some((_, 3)) => self.spindle_on = true,
            Some((_, 5)) => self.spindle_on = false,
            Some((_, _)) => self.ended = Some(line),
            None => {}
        }
        if let Some((_, g)) = motion {
            self.motion = Some(g);
        }
        let has_xyz = x.is_some() || y.is_some() || z.is_some();
        let has_arc = i.is_some() || j.is_some() || r.is_some();
        if !has_xyz && !has_arc {
            return Ok(());
        }
        let column = [x, y, z, i, j, r]
            .iter()
            .flatten()
            .map(|(c, _)| *c)
            .min()
            .unwrap_or(1);
        let Some(mode) = self.motion else {
            return Err(error(
                line,
                column,
                "a motion mode (G0, G1, G2 or G3) before the first coordinates".to_string(),
            ));
        };
        let length = |(c, v): (usize, f64), what: &str| -> Result<f64, LoadError> {
            let m = v * self.units;
            if m.abs() > MAX_COORDINATE {
                return Err(error(
                    line,
                    c,
                    format!("{what} within +-{MAX_COORDINATE} m, got {v} ({m} m)"),
                ));
            }
            Ok(m)
        };
        let mut end = self.position;
        for (k, (word, name)) in [(x, "X"), (y, "Y"), (z, "Z")].into_iter().enumerate() {
            if let (Some(w), Some(e)) = (word, end.get_mut(k)) {
                let v = length(w, name)?;
                *e = if self.absolute { v } else { *e + v };
                if e.abs() > MAX_COORDINATE {
                    return Err(error(
                        line,
                        w.0,
                        format!("an end point within +-{MAX_COORDINATE} m, got {e} m"),
                    ));
                }
            }
        }
        self.lengths_seen = true;
        let start = self.position;
        let feed = match mode {
            0 => 0.0,
            _ => self.feed.ok_or_else(|| {
                error(
                    line,
                    column,
                    "a feed rate F before the first feed move (G1, G2, G3)".to_string(),
                )
            })?,
        };
        let motion = if mode <= 1 {
            if has_arc {
                let c = [i, j, r]
                    .iter()
                    .flatten()
                    .map(|(c, _)| *c)
                    .min()
                    .unwrap_or(1);
                return Err(error(
                    line,
                    c,
                    format!("I, J and R only on arcs (G2, G3), this is G{mode}"),
                ));
            }
            if end == start {
                // Nothing moves: no move is stored (a repeated position is common CAM output).
                return Ok(());
            }
            if mode == 0 {
                Motion::Rapid
            } else {
                Motion::Linear
            }
        } else {
            let clockwise = mode == 2;
            let centre = match (i.or(j), r) {
                (Some(_), Some((c, _))) => {
                    return Err(error(
                        line,
                        c,
                        "either I/J or R on an arc, not both".to_string(),
                    ));
                }
                (None, None) => {
                    return Err(error(
                        line,
                        column,
                        format!("the arc's centre: I and J, or R (G{mode})"),
                    ));
                }
                (Some(_), None) => {
                    let oi = i.map_or(Ok(0.0), |w| length(w, "I"))?;
                    let oj = j.map_or(Ok(0.0), |w| length(w, "J"))?;
                    start.xy() + Vector2::new(oi, oj)
                }
                (None, Some(rw)) => {
                    let radius = length(rw, "R")?;
                    centre_from_radius(&start.xy(), &end.xy(), radius, clockwise)
                        .map_err(|m| error(line, rw.0, m))?
                }
            };
            let r0 = (start.xy() - centre).norm();
            let r1 = (end.xy() - centre).norm();
            let allowed = ARC_TOLERANCE.0.max(ARC_TOLERANCE.1 * r0);
            if r0 < 1.0e-9 {
                return Err(error(line, column, "an arc of radius > 0".to_string()));
            }
            if (r0 - r1).abs() > allowed {
                return Err(error(
                    line,
                    column,
                    format!(
                        "an end point on the arc's circle: the radius is {r0:.6} m at the start \
                         and {r1:.6} m at the end (difference {:.3e} m, tolerance {allowed:.1e} m)",
                        (r0 - r1).abs()
                    ),
                ));
            }
            let sweep = sweep(&start.xy(), &end.xy(), &centre, clockwise);
            Motion::Arc {
                center: centre,
                sweep,
            }
        };
        if self.moves.len() >= MAX_MOVES {
            return Err(LoadError::TooLarge {
                what: format!("G-code program moves (at line {line})"),
                limit: MAX_MOVES,
                got: self.moves.len() + 1,
            });
        }
        self.moves.push(Move {
            line,
            motion,
            start,
            end,
            feed,
            spindle: if self.spindle_on {
                self.spindle_rpm / 60.0
            } else {
                0.0
            },
        });
        self.position = end;
        Ok(())
    }
}

/// Centre of the arc of radius `|radius|` from `a` to `b` (`radius < 0`: the arc over 180
/// degrees), clockwise or not.
fn centre_from_radius(
    a: &Vector2<f64>,
    b: &Vector2<f64>,
    radius: f64,
    clockwise: bool,
) -> Result<Vector2<f64>, String> {
    let chord = b - a;
    let d = chord.norm();
    let r = radius.abs();
    if d < 1.0e-12 {
        return Err("an R arc with distinct start and end (a full circle needs I/J)".to_string());
    }
    if r == 0.0 || d > 2.0 * r * (1.0 + 1.0e-9) {
        return Err(format!(
            "a radius R at least half the chord ({:.6} m), got {r:.6} m",
            d / 2.0
        ));
    }
    let h = (r * r - d * d / 4.0).max(0.0).sqrt();
    let u = chord / d;
    let left = Vector2::new(-u.y, u.x);
    // Counter-clockwise short arcs have their centre left of the chord, clockwise ones right;
    // a negative R takes the long arc, the other side.
    let side = if clockwise { -1.0 } else { 1.0 } * radius.signum();
    Ok(a + chord / 2.0 + left * (side * h))
}

/// Signed sweep about +z from `a` to `b` around `c` (> 0 counter-clockwise); equal points
/// make a full turn.
fn sweep(a: &Vector2<f64>, b: &Vector2<f64>, c: &Vector2<f64>, clockwise: bool) -> f64 {
    let tau = core::f64::consts::TAU;
    let (ra, rb) = (a - c, b - c);
    let angle = |v: Vector2<f64>| v.y.atan2(v.x);
    let mut ccw = (angle(rb) - angle(ra)).rem_euclid(tau);
    if clockwise {
        let mut cw = (tau - ccw).rem_euclid(tau);
        if a == b || cw == 0.0 {
            cw = tau;
        }
        return -cw;
    }
    if a == b || ccw == 0.0 {
        ccw = tau;
    }
    ccw
}
