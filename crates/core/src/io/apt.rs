//! APT / CL data (`std`): the cutter-location source CAM systems write for any machine
//! (NX, CATIA, Mastercam, hyperMILL, PowerMill), read into a [`Program`] with the tool axis of
//! every point, SI.
//!
//! One statement per line, `MAJOR/arg, arg, ...` or `MAJOR` alone; a line ending in `$`
//! continues on the next; `$$` starts a comment. Words in either case.
//!
//! | statement | meaning here |
//! |---|---|
//! | `GOTO/x,y,z[,i,j,k]` | a straight move of the tool tip to `(x, y, z)`, the tool axis turning (great circle) to `(i, j, k)` (tip towards spindle; a vector within [`AXIS_NORM_TOLERANCE`] of unit length is normalised, beyond refused; without it the axis is kept) |
//! | `FROM/x,y,z[,i,j,k]` | where the tool is before the first move (without a vector here or in `TLAXIS/`, the first `GOTO`'s holds from the start) |
//! | `RAPID` | the next `GOTO` at the rapid rate |
//! | `FEDRAT/f[,MMPM\|IPM\|MMPR\|IPR]`, `FEDRAT/MMPM,f` | feed per minute in the program's unit (or the one named), or per revolution |
//! | `CIRCLE/xc,yc,zc,i,j,k,r[,...]` | the next `GOTO` is an arc about the centre, counter-clockwise about `(i, j, k)` (an axis along x, y or z; a full circle when it ends where it starts) |
//! | `SPINDL/s[,RPM][,CLW\|CCLW]`, `SPINDL/RPM,s,...`, `SPINDL/OFF`, `SPINDL/ON` | spindle speed \[rev/min\] and direction (`CLW` clockwise, `M3`'s) |
//! | `LOADTL/n[,...]` | tool `n` in the spindle; a new operation |
//! | `CUTTER/d[,r,...]` | the tool's cutter: diameter `d`, corner radius `r` (0 flat, `d / 2` ball, between bull-nose) |
//! | `TLAXIS/i,j,k` | the tool axis for the `GOTO`s that give none |
//! | `MULTAX[/ON\|OFF]` | recorded (every `GOTO` may carry a tool axis) |
//! | `UNITS/MM\|INCHES` | the length unit (default [`GcodeOptions::units`]) |
//! | `TOOL PATH/name,...` | a new operation named `name` (NX) |
//! | `FINI` | the end (what follows is not read) |
//! | `PARTNO` `PPRINT` `COOLNT` `TLDATA` `PAINT` `END-OF-PATH` `CLRSRF` `INSERT` `OPSTOP` `STOP` `SELCTL` `AUTOPS` `DISPLY` `TPRINT` | no motion |
//! | `MSYS/0,0,0,1,0,0,0,1,0` | the identity (any other frame is refused) |
//!
//! Any other statement is refused with [`LoadError::Program`] naming its line and word, as is
//! a malformed one (a missing or non-numeric value, a zero tool vector, an arc about a tilted
//! axis or whose end is off its circle, a feed move before any `FEDRAT`). At most
//! [`crate::machining::MAX_MOVES`] moves and [`super::MAX_FILE_BYTES`] of text.

use std::format;
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use nalgebra::Vector3;

use super::gcode::GcodeOptions;
use crate::error::{BuildError, LoadError};
use crate::machining::tools::ToolShape;
use crate::machining::{
    MAX_COORDINATE, MAX_FEED, MAX_MOVES, MAX_SPINDLE_RPM, MAX_TOOL_NUMBER, Motion, Move, Operation,
    Plane, Program,
};
use crate::units::LengthUnit;

mod args;
use args::{Arg, fault, numbers, parse_args, point_and_axis, word};

/// How far from unit length a tool vector may be and be normalised: 1e-3 (a vector printed
/// to 4 decimals is within 2e-4; one further off is not a tool vector but a typo).
pub const AXIS_NORM_TOLERANCE: f64 = 1.0e-3;

/// A cutter a program defines (`CUTTER/`), for the tool in the spindle when it was defined
/// (or loaded right after it, before any move).
#[derive(Debug, Clone, PartialEq)]
pub struct AptCutter {
    /// The program line of the `CUTTER/` statement.
    pub line: usize,
    /// The tool number it belongs to (0 before any `LOADTL`).
    pub tool: u32,
    /// Diameter \[m\].
    pub diameter: f64,
    /// Flat, ball or bull-nose end.
    pub shape: ToolShape,
}

/// A program read from APT: its moves and the cutters it defines.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AptProgram {
    /// The moves, tool axes and operations.
    pub program: Program,
    /// The `CUTTER/` statements, in program order.
    pub cutters: Vec<AptCutter>,
}

/// Reads an APT / CL file (see the module docs).
pub fn from_path(path: impl AsRef<Path>, options: &GcodeOptions) -> Result<AptProgram, LoadError> {
    from_str(&super::read_text_lossy(path.as_ref())?, options)
}

/// Reads APT text (see the module docs); `options.start` is where the tool is before the
/// first move unless a `FROM/` says otherwise, `options.units` the length unit until
/// `UNITS/`.
pub fn from_str(text: &str, options: &GcodeOptions) -> Result<AptProgram, LoadError> {
    super::gcode::check_start(&options.start)?;
    let mut reader = Reader::new(options);
    let mut pending = String::new();
    let mut first_line = 0;
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let code = raw.split("$$").next().unwrap_or("").trim();
        if pending.is_empty() {
            first_line = line;
        }
        if let Some(head) = code.strip_suffix('$') {
            pending.push_str(head);
            continue;
        }
        pending.push_str(code);
        let statement = core::mem::take(&mut pending);
        if statement.trim().is_empty() {
            continue;
        }
        if !reader.statement(first_line, statement.trim())? {
            break;
        }
    }
    reader.finish()
}

struct Reader {
    unit: f64,
    pos: Vector3<f64>,
    axis: Vector3<f64>,
    /// Feed: per minute \[m/s\] or per revolution \[m/rev\].
    feed: Option<Feed>,
    rapid_next: bool,
    spindle_rpm: f64,
    spindle_dir: f64,
    spindle_on: bool,
    tool: u32,
    circle: Option<(usize, Vector3<f64>, Vector3<f64>)>,
    moves: Vec<Move>,
    operations: Vec<Operation>,
    next_operation: Option<String>,
    cutters: Vec<AptCutter>,
    started: bool,
    /// Whether a `FROM`, `TLAXIS` or `GOTO` gave the axis (before that, the first `GOTO`'s
    /// vector holds from the start).
    axis_given: bool,
}

#[derive(Clone, Copy)]
enum Feed {
    PerMinute(f64),
    PerRevolution(f64),
}

impl Reader {
    fn new(options: &GcodeOptions) -> Self {
        Self {
            unit: options.units.to_metre(),
            pos: options.start,
            axis: Vector3::z(),
            feed: None,
            rapid_next: false,
            spindle_rpm: 0.0,
            spindle_dir: 1.0,
            spindle_on: false,
            tool: 0,
            circle: None,
            moves: Vec::new(),
            operations: Vec::new(),
            next_operation: None,
            cutters: Vec::new(),
            started: false,
            axis_given: false,
        }
    }

    /// Runs one statement; `false` at `FINI`.
    fn statement(&mut self, line: usize, text: &str) -> Result<bool, LoadError> {
        let (major, rest) = match text.split_once('/') {
            Some((m, r)) => (m.trim().to_ascii_uppercase(), Some(r)),
            None => (text.trim().to_ascii_uppercase(), None),
        };
        let args = match rest {
            Some(r) => parse_args(line, r)?,
            None => Vec::new(),
        };
        match major.as_str() {
            "GOTO" => self.goto(line, &args)?,
            "FROM" => self.from(line, &args)?,
            "RAPID" => self.rapid_next = true,
            "FEDRAT" => self.fedrat(line, &args)?,
            "CIRCLE" => self.circle(line, &args)?,
            "SPINDL" => self.spindl(line, &args)?,
            "LOADTL" => self.loadtl(line, &args)?,
            "CUTTER" => self.cutter(line, &args)?,
            "TLAXIS" => {
                let [i, j, k] = numbers::<3>(line, "TLAXIS/i,j,k", &args)?;
                self.axis = unit_axis(line, "TLAXIS", i, j, k)?;
                self.axis_given = true;
            }
            "UNITS" => {
                self.unit = match word(&args, 0).as_deref() {
                    Some("MM") => LengthUnit::Millimetre.to_metre(),
                    Some("INCHES" | "INCH") => LengthUnit::Inch.to_metre(),
                    _ => return fault(line, "UNITS/MM or UNITS/INCHES"),
                }
            }
            "MULTAX" => match word(&args, 0).as_deref() {
                None | Some("ON" | "OFF") => {}
                _ => return fault(line, "MULTAX, MULTAX/ON or MULTAX/OFF"),
            },
            "TOOL PATH" => {
                let name = rest.unwrap_or("").split(',').next().unwrap_or("").trim();
                self.next_operation = Some(name.to_string());
            }
            "MSYS" => {
                let v = numbers::<9>(line, "MSYS/x,y,z,i,j,k,i,j,k", &args)?;
                let identity = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
                if v.iter().zip(identity).any(|(a, b)| (a - b).abs() > 1e-9) {
                    return fault(
                        line,
                        "MSYS: the identity frame (0,0,0,1,0,0,0,1,0); a program in another \
                         machine frame is not read: have the CAM system output in the \
                         workpiece frame",
                    );
                }
            }
            "FINI" => return Ok(false),
            "PARTNO" | "PPRINT" | "COOLNT" | "TLDATA" | "PAINT" | "END-OF-PATH" | "CLRSRF"
            | "INSERT" | "OPSTOP" | "STOP" | "SELCTL" | "AUTOPS" | "DISPLY" | "TPRINT" => {}
            other => {
                return fault(
                    line,
                    format!(
                        "a statement this reader knows (GOTO, FEDRAT, RAPID, CIRCLE, SPINDL, \
                         LOADTL, CUTTER, MULTAX, UNITS, FINI, ...), got {other}"
                    ),
                );
            }
        }
        Ok(true)
    }

    fn point(&self, line: usize, v: [f64; 3]) -> Result<Vector3<f64>, LoadError> {
        let p = Vector3::from(v) * self.unit;
        if let Some(x) = p.iter().find(|x| x.is_nan() || x.abs() > MAX_COORDINATE) {
            return fault(
                line,
                format!("a point within +-{MAX_COORDINATE} m, got {x} m"),
            );
        }
        Ok(p)
    }

    fn from(&mut self, line: usize, args: &[Arg]) -> Result<(), LoadError> {
        if self.started {
            return fault(line, "FROM before the first move");
        }
        let (p, axis) = point_and_axis(line, "FROM/x,y,z[,i,j,k]", args)?;
        self.pos = self.point(line, p)?;
        if let Some([i, j, k]) = axis {
            self.axis = unit_axis(line, "FROM", i, j, k)?;
            self.axis_given = true;
        }
        Ok(())
    }

    fn goto(&mut self, line: usize, args: &[Arg]) -> Result<(), LoadError> {
        let (p, axis) = point_and_axis(line, "GOTO/x,y,z[,i,j,k]", args)?;
        let end = self.point(line, p)?;
        let axis = match axis {
            Some([i, j, k]) => unit_axis(line, "GOTO", i, j, k)?,
            None => self.axis,
        };
        if !self.axis_given {
            // The tool stands at the start as the first vector holds it.
            self.axis = axis;
            self.axis_given = true;
        }
        self.started = true;
        let rapid = core::mem::take(&mut self.rapid_next);
        let circle = self.circle.take();
        let motion = match circle {
            Some((_, centre, normal)) if !rapid => self.arc(line, &centre, &normal, &end)?,
            Some(_) => return fault(line, "a GOTO at feed after CIRCLE/ (got RAPID)"),
            None if rapid => Motion::Rapid,
            None => Motion::Linear,
        };
        let (start, start_axis) = (self.pos, self.axis);
        self.pos = end;
        self.axis = axis;
        if matches!(motion, Motion::Linear | Motion::Rapid) && start == end && start_axis == axis {
            return Ok(());
        }
        let feed = if rapid { 0.0 } else { self.speed(line)? };
        if self.moves.len() >= MAX_MOVES {
            return Err(LoadError::TooLarge {
                what: format!("APT program moves (at line {line})"),
                limit: MAX_MOVES,
                got: self.moves.len() + 1,
            });
        }
        if self.operations.is_empty() || self.next_operation.is_some() {
            let name = self
                .next_operation
                .take()
                .unwrap_or_else(|| format!("T{}", self.tool));
            self.operations.push(Operation {
                name,
                first_move: self.moves.len(),
            });
        }
        self.moves.push(Move {
            spindle: if self.spindle_on {
                self.spindle_dir * self.spindle_rpm / 60.0
            } else {
                0.0
            },
            tool: self.tool,
            start_axis,
            end_axis: axis,
            ..Move::new(line, motion, start, end, feed)
        });
        Ok(())
    }

    /// The feed \[m/s\] of a feed move.
    fn speed(&self, line: usize) -> Result<f64, LoadError> {
        let v = match self.feed {
            None => return fault(line, "a FEDRAT before the first GOTO at feed"),
            Some(Feed::PerMinute(v)) => v,
            Some(Feed::PerRevolution(f)) => {
                if !self.spindle_on || self.spindle_rpm == 0.0 {
                    return fault(line, "a turning spindle for a feed per revolution");
                }
                f * self.spindle_rpm / 60.0
            }
        };
        if !(v > 0.0 && v <= MAX_FEED) {
            return fault(line, format!("a feed in (0, {MAX_FEED}] m/s, got {v} m/s"));
        }
        Ok(v)
    }

    /// The arc of `CIRCLE/` from the current point to `end`.
    fn arc(
        &self,
        line: usize,
        centre: &Vector3<f64>,
        normal: &Vector3<f64>,
        end: &Vector3<f64>,
    ) -> Result<Motion, LoadError> {
        let (plane, sign) = match principal(normal) {
            Some(p) => p,
            None => {
                return fault(
                    line,
                    "a CIRCLE/ axis along x, y or z (an arc in a tilted plane is not read: \
                     have the CAM system output it as points)",
                );
            }
        };
        let (a, b, n) = plane.axes();
        let at = |v: &Vector3<f64>, i: usize| v.get(i).copied().unwrap_or(0.0);
        let mut c = *centre;
        if let Some(x) = c.get_mut(n) {
            *x = at(&self.pos, n);
        }
        let start_angle = (at(&self.pos, b) - at(&c, b)).atan2(at(&self.pos, a) - at(&c, a));
        let end_angle = (at(end, b) - at(&c, b)).atan2(at(end, a) - at(&c, a));
        let tau = core::f64::consts::TAU;
        // Counter-clockwise about +n for sign > 0, clockwise for sign < 0; (0, 2 pi].
        let mut sweep = (sign * (end_angle - start_angle)).rem_euclid(tau);
        if sweep < 1e-12 {
            sweep = tau;
        }
        Ok(Motion::Arc {
            plane,
            center: c,
            sweep: sign * sweep,
        })
    }

    fn fedrat(&mut self, line: usize, args: &[Arg]) -> Result<(), LoadError> {
        let mut value = None;
        let mut mode = None;
        for a in args {
            match a {
                Arg::Number(v) if value.is_none() => value = Some(*v),
                Arg::Word(w) if mode.is_none() => mode = Some(w.as_str()),
                _ => return fault(line, "FEDRAT/f[,MMPM|IPM|MMPR|IPR]"),
            }
        }
        let Some(v) = value.filter(|v| *v > 0.0) else {
            return fault(line, "FEDRAT/f with a feed > 0");
        };
        let (mm, inch) = (1e-3, 25.4e-3);
        self.feed = Some(match mode {
            None => Feed::PerMinute(v * self.unit / 60.0),
            Some("MMPM") => Feed::PerMinute(v * mm / 60.0),
            Some("IPM") => Feed::PerMinute(v * inch / 60.0),
            Some("MMPR") => Feed::PerRevolution(v * mm),
            Some("IPR") => Feed::PerRevolution(v * inch),
            Some(other) => {
                return fault(
                    line,
                    format!("FEDRAT's unit MMPM, IPM, MMPR or IPR, got {other}"),
                );
            }
        });
        Ok(())
    }

    fn circle(&mut self, line: usize, args: &[Arg]) -> Result<(), LoadError> {
        let [x, y, z, i, j, k, _r] = numbers::<7>(line, "CIRCLE/xc,yc,zc,i,j,k,r", args)?;
        let centre = self.point(line, [x, y, z])?;
        let normal = Vector3::new(i, j, k);
        if normal.norm() == 0.0 {
            return fault(line, "a CIRCLE/ axis that is not zero");
        }
        self.circle = Some((line, centre, normal.normalize()));
        Ok(())
    }

    fn spindl(&mut self, line: usize, args: &[Arg]) -> Result<(), LoadError> {
        let mut speed = None;
        for a in args {
            match a {
                Arg::Number(v) if speed.is_none() => speed = Some(*v),
                Arg::Word(w) => match w.as_str() {
                    "RPM" => {}
                    "CLW" => self.spindle_dir = 1.0,
                    "CCLW" => self.spindle_dir = -1.0,
                    "OFF" => self.spindle_on = false,
                    "ON" => self.spindle_on = true,
                    other => {
                        return fault(
                            line,
                            format!(
                                "SPINDL's words RPM, CLW, CCLW, ON or OFF (a surface speed is \
                                 not read), got {other}"
                            ),
                        );
                    }
                },
                _ => return fault(line, "SPINDL/s[,RPM][,CLW|CCLW]"),
            }
        }
        if let Some(s) = speed {
            if !(0.0..=MAX_SPINDLE_RPM).contains(&s) {
                return fault(
                    line,
                    format!("a spindle speed in 0..={MAX_SPINDLE_RPM} rpm, got {s}"),
                );
            }
            self.spindle_rpm = s;
            self.spindle_on = true;
        }
        Ok(())
    }

    fn loadtl(&mut self, line: usize, args: &[Arg]) -> Result<(), LoadError> {
        let Some(Arg::Number(n)) = args.first() else {
            return fault(line, "LOADTL/n");
        };
        if !(n.fract() == 0.0 && *n >= 1.0 && *n <= f64::from(MAX_TOOL_NUMBER)) {
            return fault(
                line,
                format!("a tool number in 1..={MAX_TOOL_NUMBER}, got {n}"),
            );
        }
        let n = *n as u32;
        // A cutter defined since the last move belongs to the tool loaded now.
        let moves = self.moves.len();
        let last_line = self.moves.last().map_or(0, |m| m.line);
        if let Some(c) = self.cutters.last_mut()
            && (moves == 0 || c.line > last_line)
        {
            c.tool = n;
        }
        self.tool = n;
        if self.next_operation.is_none() {
            self.next_operation = Some(format!("T{n}"));
        }
        Ok(())
    }

    fn cutter(&mut self, line: usize, args: &[Arg]) -> Result<(), LoadError> {
        let v: Vec<f64> = args
            .iter()
            .map_while(|a| match a {
                Arg::Number(v) => Some(*v),
                Arg::Word(_) => None,
            })
            .collect();
        let Some(&d) = v.first() else {
            return fault(line, "CUTTER/d[,r,...] with the diameter");
        };
        let r = v.get(1).copied().unwrap_or(0.0);
        let (d, r) = (d * self.unit, r * self.unit);
        let tol = 1e-9;
        let shape = if !(crate::machining::cutting::MIN_TOOL_DIAMETER..=1.0).contains(&d) {
            return fault(line, format!("a cutter diameter in [1e-5, 1] m, got {d} m"));
        } else if r.abs() <= tol {
            ToolShape::Flat
        } else if (r - 0.5 * d).abs() <= tol {
            ToolShape::Ball
        } else if r > 0.0 && r < 0.5 * d {
            ToolShape::BullNose { corner_radius: r }
        } else {
            return fault(
                line,
                format!("a corner radius in [0, d/2] (d = {d} m), got {r} m"),
            );
        };
        self.cutters.push(AptCutter {
            line,
            tool: self.tool,
            diameter: d,
            shape,
        });
        Ok(())
    }

    fn finish(self) -> Result<AptProgram, LoadError> {
        if let Some((line, ..)) = self.circle {
            return fault(line, "a GOTO after CIRCLE/ (the arc's end)");
        }
        let program = Program {
            moves: self.moves,
            operations: self.operations,
        };
        if let Err(e) = program.validate() {
            let line = match &e {
                BuildError::InvalidEntry { index, .. } => {
                    program.moves.get(*index).map_or(1, |m| m.line)
                }
                _ => 1,
            };
            return fault(line, e.to_string());
        }
        Ok(AptProgram {
            program,
            cutters: self.cutters,
        })
    }
}

/// The plane whose normal `n` is along (`+1`) or against (`-1`), within 1e-9.
fn principal(n: &Vector3<f64>) -> Option<(Plane, f64)> {
    [(Plane::Yz, 0), (Plane::Zx, 1), (Plane::Xy, 2)]
        .into_iter()
        .find_map(|(plane, k)| {
            let v = n.get(k).copied().unwrap_or(0.0);
            ((v.abs() - 1.0).abs() <= 1e-9).then_some((plane, v.signum()))
        })
}

/// A tool vector, normalised (within [`AXIS_NORM_TOLERANCE`] of unit length).
fn unit_axis(line: usize, what: &str, i: f64, j: f64, k: f64) -> Result<Vector3<f64>, LoadError> {
    let v = Vector3::new(i, j, k);
    let n = v.norm();
    if n == 0.0 {
        return fault(
            line,
            format!("{what}: a tool vector (i, j, k) that is not zero"),
        );
    }
    if (n - 1.0).abs() > AXIS_NORM_TOLERANCE || n.is_nan() {
        return fault(
            line,
            format!(
                "{what}: a unit tool vector (within AXIS_NORM_TOLERANCE, 1e-3), got length {n}"
            ),
        );
    }
    Ok(v / n)
}
