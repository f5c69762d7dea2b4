//! Robot programs out (`std`): the compensated job in the robot controller's own language,
//! for controllers without a CNC kernel, each in its vendor's documented conventions and for
//! both commands of the hybrid compensation (Hähn and Weigold 2020, sec. 2.4):
//!
//! | [`Language`] | Cartesian command ([`Command::Cartesian`]) | axis-specific ([`Command::Joints`]) |
//! |---|---|---|
//! | KUKA KRL ([`krl`]): `.src` + `.dat` | `LIN` of `E6POS` (mm, A-B-C degrees about Z, Y', X''; status `S`, turn `T`) in a declared `BASE` with a declared `TOOL`, `$VEL.CP`, `$APO.CDIS` | `PTP` of `E6AXIS` (degrees) |
//! | ABB RAPID ([`rapid`]): `.mod` | `MoveL` of `robtarget`s (mm, quaternion w-x-y-z, `confdata`), `speeddata` of the program's feeds, `zonedata` of the blending tolerance (`fine` at exact stops), `tooldata`, `wobjdata` | `MoveAbsJ` of `jointtarget`s |
//! | Universal Robots URScript ([`urscript`]): `.script` | `movel(p[x, y, z, rx, ry, rz], a, v, r)` (m, rotation vector, base frame) after `set_tcp` | `movej` to the start, `servoj` at every sample |
//! | CSV ([`csv`]): `.csv` | the kept poses (model base frame, m, quaternion) | the joints at every sample (the model's, rad or m) |
//!
//! The Cartesian forms write the commanded TCP (the rigid pose at the compensated joints) at
//! the samples a streamed decimation keeps ([`super::decimate`]): every dropped sample lies
//! within [`ProgramOptions::tolerance`] of the straight move between the kept ones and its
//! orientation within `tolerance / 0.1 m` rad of their interpolation (a point 0.1 m off the
//! flange moves by the tolerance). KRL's `PTP` and RAPID's `MoveAbsJ` are decimated in joint
//! space to [`ProgramOptions::joint_tolerance`]; `servoj` and the CSV keep every sample.
//! Every program move's last sample is kept; where the path stops there (a corner, a feed
//! change: [`crate::machining::path::PathSample::run`]) the motion ends exactly (KRL without
//! `C_DIS`, RAPID `fine`, URScript `r=0`), elsewhere it blends by the move's `G64 P`
//! tolerance, or the decimation's without one. Every motion of a new program line is
//! preceded by a comment naming it and the time (`; line 12, t = 3.456 s`), so a user finds
//! the CAM block of each motion. A dwell (`G4`) is a wait.
//!
//! The controller reads the model's joints and frames through the robot's [`Convention`]
//! (`[controller]` of its stiffness file): KRL needs a KUKA one, RAPID an ABB one, URScript a
//! UR one ([`ProgramError::NoConvention`], [`ProgramError::WrongVendor`]); the CSV needs none.
//! The workpiece frame is the program's `BASE` (KRL) and `wobjdata` (RAPID); URScript's poses
//! are in the controller's base frame. A controller reads the robot program's numbers in its
//! own precision (KRL's `REAL` has 24 bits); the files carry nanometres and nanodegrees.

pub mod csv;
pub mod krl;
pub mod rapid;
pub mod urscript;

use std::fmt::Write as _;
use std::io::Write;
use std::string::{String, ToString};
use std::vec::Vec;

use nalgebra::{Isometry3, UnitQuaternion};

use super::decimate::{Decimator, Kept};
use crate::contour::shape::distance_to_segment;
use crate::controller::{Convention, Vendor};
use crate::error::{BuildError, TickError};
use crate::machining::job::JobSample;
use crate::machining::{Motion, PathControl, Program};
use crate::vjm::{Data, Model};

/// The lever \[m\] that turns the position tolerance into the orientation one.
pub const ORIENTATION_LEVER: f64 = 0.1;
/// Longest program (module, procedure) name: KRL's 24 characters.
pub const MAX_NAME: usize = 24;
/// Largest decimation tolerance \[m\] (and \[rad\] for joints): 1 cm.
pub const MAX_TOLERANCE: f64 = 1.0e-2;

/// The controller's language.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Language {
    /// KUKA KRL (`.src` + `.dat`).
    Krl,
    /// ABB RAPID (`.mod`).
    Rapid,
    /// Universal Robots URScript (`.script`).
    UrScript,
    /// CSV of poses or joints (any controller that reads a table).
    Csv,
}

impl Language {
    /// Every language, by name.
    pub const ALL: [Self; 4] = [Self::Krl, Self::Rapid, Self::UrScript, Self::Csv];

    /// `"krl"`, `"rapid"`, `"urscript"`, `"csv"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Krl => "krl",
            Self::Rapid => "rapid",
            Self::UrScript => "urscript",
            Self::Csv => "csv",
        }
    }

    /// The language of a name ([`Self::name`]); [`ProgramError::UnknownLanguage`] naming the
    /// known ones.
    pub fn from_name(name: &str) -> Result<Self, ProgramError> {
        Self::ALL
            .into_iter()
            .find(|l| l.name() == name)
            .ok_or_else(|| ProgramError::UnknownLanguage {
                got: name.to_string(),
            })
    }

    /// The controller it runs on (`None` for CSV).
    pub fn vendor(self) -> Option<Vendor> {
        match self {
            Self::Krl => Some(Vendor::Kuka),
            Self::Rapid => Some(Vendor::Abb),
            Self::UrScript => Some(Vendor::UniversalRobots),
            Self::Csv => None,
        }
    }

    /// The main file's extension: `src`, `mod`, `script`, `csv`.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Krl => "src",
            Self::Rapid => "mod",
            Self::UrScript => "script",
            Self::Csv => "csv",
        }
    }
}

/// Which command of the compensation the program carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Command {
    /// The commanded TCP poses (the Cartesian correction).
    #[default]
    Cartesian,
    /// The compensated joints (the axis-specific correction).
    Joints,
}

impl Command {
    /// `"cartesian"` or `"joints"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Cartesian => "cartesian",
            Self::Joints => "joints",
        }
    }

    /// The command of a name ([`Self::name`]).
    pub fn from_name(name: &str) -> Result<Self, ProgramError> {
        [Self::Cartesian, Self::Joints]
            .into_iter()
            .find(|c| c.name() == name)
            .ok_or_else(|| ProgramError::UnknownCommand {
                got: name.to_string(),
            })
    }
}

/// How a robot program is written.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramOptions {
    /// The language.
    pub language: Language,
    /// The command.
    pub command: Command,
    /// The program's (module's, procedure's) name and the files' stem: a letter, then
    /// letters, digits and `_`, at most [`MAX_NAME`] characters.
    pub name: String,
    /// Cartesian decimation tolerance \[m\], in (0, [`MAX_TOLERANCE`]].
    pub tolerance: f64,
    /// Joint decimation tolerance \[rad or m\], in (0, [`MAX_TOLERANCE`]].
    pub joint_tolerance: f64,
    /// URScript's `a` of every `movel` \[m/s^2\] (`movej`'s in rad/s^2), in (0, 100].
    pub acceleration: f64,
    /// RAPID's tool load \[kg\] (`tooldata.tload.mass`, at the TCP), in (0, 1000]: the
    /// controller refuses 0; give your spindle's.
    pub tool_mass: f64,
}

impl ProgramOptions {
    /// The options of `language` and `command` with the defaults: name `deflect_job`, 1 um,
    /// 1e-6 rad, 1.2 m/s^2 (UR's default), a 1 kg tool.
    pub fn new(language: Language, command: Command) -> Self {
        Self {
            language,
            command,
            name: "deflect_job".to_string(),
            tolerance: 1.0e-6,
            joint_tolerance: 1.0e-6,
            acceleration: 1.2,
            tool_mass: 1.0,
        }
    }

    /// Checks every option ([`ProgramError::Option`] naming it).
    pub fn validate(&self) -> Result<(), ProgramError> {
        let ok_name = self.name.len() <= MAX_NAME
            && self
                .name
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic())
            && self
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !ok_name {
            return Err(ProgramError::Name {
                got: self.name.clone(),
            });
        }
        let check = |what, v: f64, ok: bool, expected| {
            crate::error::param(what, v, ok, expected).map_err(ProgramError::Option)
        };
        check(
            "tolerance (m)",
            self.tolerance,
            self.tolerance > 0.0 && self.tolerance <= MAX_TOLERANCE,
            "in (0, 0.01] m",
        )?;
        check(
            "joint tolerance (rad or m)",
            self.joint_tolerance,
            self.joint_tolerance > 0.0 && self.joint_tolerance <= MAX_TOLERANCE,
            "in (0, 0.01] rad",
        )?;
        check(
            "acceleration (m/s^2)",
            self.acceleration,
            self.acceleration > 0.0 && self.acceleration <= 100.0,
            "in (0, 100] m/s^2",
        )?;
        check(
            "tool mass (kg)",
            self.tool_mass,
            self.tool_mass > 0.0 && self.tool_mass <= 1000.0,
            "in (0, 1000] kg",
        )?;
        Ok(())
    }
}

/// Why a robot program could not be written.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ProgramError {
    /// A language deflect does not write.
    UnknownLanguage {
        /// The name given.
        got: String,
    },
    /// A command other than `cartesian` and `joints`.
    UnknownCommand {
        /// The name given.
        got: String,
    },
    /// A program name a controller does not take.
    Name {
        /// The name given.
        got: String,
    },
    /// An option out of its range.
    Option(BuildError),
    /// The robot has no controller convention (`[controller]` in its stiffness file).
    NoConvention {
        /// The robot.
        robot: String,
        /// The language asked for.
        language: Language,
    },
    /// The robot's convention is another vendor's.
    WrongVendor {
        /// The robot.
        robot: String,
        /// The language asked for.
        language: Language,
        /// The vendor of the robot's convention.
        got: Vendor,
    },
    /// A sample's configuration words could not be computed.
    Sample {
        /// Its program line.
        line: usize,
        /// Its time \[s\].
        time: f64,
        /// Why.
        error: TickError,
    },
    /// Writing failed.
    Io {
        /// The writer's message.
        message: String,
    },
}

impl core::fmt::Display for ProgramError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::UnknownLanguage { got } => write!(
                f,
                "robot program kind {got:?}: expected \"krl\", \"rapid\", \"urscript\" or \"csv\""
            ),
            Self::UnknownCommand { got } => write!(
                f,
                "robot program command {got:?}: expected \"cartesian\" or \"joints\""
            ),
            Self::Name { got } => write!(
                f,
                "robot program name {got:?}: expected a letter, then letters, digits or '_', at \
                 most {MAX_NAME} characters"
            ),
            Self::Option(e) => write!(f, "robot program: {e}"),
            Self::NoConvention { robot, language } => write!(
                f,
                "{robot} has no controller convention: a {} program needs a [controller] table \
                 with vendor = \"{}\" in its stiffness file (joint_sign, joint_offset, flange)",
                language.name(),
                language.vendor().map_or("", Vendor::name)
            ),
            Self::WrongVendor {
                robot,
                language,
                got,
            } => write!(
                f,
                "{robot}'s controller convention is {}'s ({}): it runs no {} program",
                got.name(),
                got.language(),
                language.name()
            ),
            Self::Sample { line, time, error } => {
                write!(f, "line {line}, t = {time:.3} s: {error}")
            }
            Self::Io { message } => write!(f, "writing the robot program: {message}"),
        }
    }
}

impl std::error::Error for ProgramError {}

impl From<std::io::Error> for ProgramError {
    fn from(e: std::io::Error) -> Self {
        Self::Io {
            message: e.to_string(),
        }
    }
}

/// What a program is written for: the arm, its controller, the job around the samples.
#[derive(Debug, Clone, Copy)]
pub struct Target<'a> {
    /// The arm (its forward kinematics gives the configuration words).
    pub model: &'a Model,
    /// Its controller's convention, if its file has one.
    pub convention: Option<&'a Convention>,
    /// The robot's name, for errors.
    pub robot: &'a str,
    /// The workpiece frame in the model's base frame (the job's placement).
    pub placement: Isometry3<f64>,
    /// The program the samples were run on (feeds, blending, dwells).
    pub program: &'a Program,
    /// Sampling rate \[Hz\].
    pub rate_hz: f64,
    /// Speed of rapid moves \[m/s\].
    pub rapid_speed: f64,
}

/// One file of a program: its name and text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ProgramFile {
    /// File name (`deflect_job.src`).
    pub name: String,
    /// Its text.
    pub text: String,
}

/// What the per-language writers share: the target, the options, the workspace for the
/// configuration words, and what the output has set so far.
#[derive(Debug)]
pub(crate) struct Context<'a> {
    pub target: Target<'a>,
    pub options: ProgramOptions,
    pub data: Data,
    /// The program line of the last comment.
    pub line: usize,
    /// The last speed written \[m/s\] (NaN: none yet).
    pub speed: f64,
    /// The last blending tolerance written \[m\] (NaN: none yet).
    pub blend: f64,
    /// The dwell move last waited for.
    pub dwelt: usize,
    /// Motions written.
    pub motions: usize,
}

impl Context<'_> {
    /// The convention (checked present by [`RobotProgram::new`] for the vendors' languages).
    pub fn convention(&self) -> Convention {
        self.target.convention.copied().unwrap_or_else(|| {
            // CSV only: it reads the model as it is (never reached for the others).
            Convention {
                vendor: Vendor::UniversalRobots,
                sign: [1.0; crate::vjm::MAX_DOF],
                offset: [0.0; crate::vjm::MAX_DOF],
                revolute: [true; crate::vjm::MAX_DOF],
                dof: self.target.model.dof(),
                base: Isometry3::identity(),
                tool: Isometry3::identity(),
            }
        })
    }

    /// The model's joints of a sample (compensated) \[rad or m\].
    pub fn joints<'s>(&self, s: &'s JobSample) -> &'s [f64] {
        s.q_commanded.get(..self.target.model.dof()).unwrap_or(&[])
    }

    /// The configuration words' inputs: the model, the workspace, the sample's joints.
    pub fn arm<'s>(&mut self, s: &'s JobSample) -> (&Model, &mut Data, &'s [f64]) {
        let dof = self.target.model.dof();
        (
            self.target.model,
            &mut self.data,
            s.q_commanded.get(..dof).unwrap_or(&[]),
        )
    }

    /// The comment of a new program line, with `prefix` (`;`, `!`, `#`).
    pub fn line_comment(&mut self, out: &mut String, indent: &str, prefix: &str, s: &JobSample) {
        if s.path.line != self.line {
            self.line = s.path.line;
            let _ = writeln!(
                out,
                "{indent}{prefix} line {}, t = {:.3} s",
                s.path.line, s.path.time
            );
        }
    }

    /// The dwell of a sample's move, `Some(seconds)` once per dwell (the motion is skipped).
    pub fn dwell(&mut self, s: &JobSample) -> Option<Option<f64>> {
        let mv = self.target.program.moves.get(s.path.move_index)?;
        let Motion::Dwell { seconds } = mv.motion else {
            return None;
        };
        if self.dwelt == s.path.move_index {
            return Some(None);
        }
        self.dwelt = s.path.move_index;
        Some(Some(seconds))
    }

    /// The programmed speed of a sample's move \[m/s\]: its feed, or the rapid speed.
    pub fn speed_of(&self, s: &JobSample) -> f64 {
        match self.target.program.moves.get(s.path.move_index) {
            Some(m) if m.is_feed() && m.feed > 0.0 => m.feed,
            _ => self.target.rapid_speed,
        }
    }

    /// How far the motion may blend past a kept sample \[m\]: 0 at an exact stop, else the
    /// move's `G64 P` tolerance, or the decimation's.
    pub fn blend_of(&self, k: &Kept) -> f64 {
        if k.stop {
            return 0.0;
        }
        match self
            .target
            .program
            .moves
            .get(k.sample.path.move_index)
            .map(|m| m.path_control)
        {
            Some(PathControl::Blend { tolerance, .. }) if tolerance > 0.0 => tolerance,
            _ => self.options.tolerance,
        }
    }

    /// A sample's error for the program.
    pub fn at(s: &JobSample, error: TickError) -> ProgramError {
        ProgramError::Sample {
            line: s.path.line,
            time: s.path.time,
            error,
        }
    }
}

/// The pose a Cartesian program writes for a sample: the commanded TCP, workpiece frame.
fn pose(s: &JobSample) -> Isometry3<f64> {
    s.commanded
}

/// Whether the straight motion from `a` to `b` holds `x`: the TCP within `tolerance` of the
/// chord and its orientation within `tolerance / ORIENTATION_LEVER` of the interpolated one.
fn pose_holds(tolerance: f64, a: &JobSample, b: &JobSample, x: &JobSample) -> bool {
    let (pa, pb, px) = (pose(a), pose(b), pose(x));
    let (ta, tb, tx) = (
        pa.translation.vector,
        pb.translation.vector,
        px.translation.vector,
    );
    if distance_to_segment(&tx, &ta, &tb) > tolerance {
        return false;
    }
    let length = (tb - ta).norm();
    let t = if length > 0.0 {
        ((tx - ta).dot(&(tb - ta)) / (length * length)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let between: UnitQuaternion<f64> = pa.rotation.slerp(&pb.rotation, t);
    between.angle_to(&px.rotation) <= tolerance / ORIENTATION_LEVER
}

/// Whether the joint motion from `a` to `b` (linear in time) holds `x` within `tolerance`.
fn joints_hold(tolerance: f64, dof: usize, a: &JobSample, b: &JobSample, x: &JobSample) -> bool {
    let span = b.path.time - a.path.time;
    let t = if span > 0.0 {
        ((x.path.time - a.path.time) / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a.q_commanded
        .iter()
        .zip(&b.q_commanded)
        .zip(&x.q_commanded)
        .take(dof)
        .all(|((qa, qb), qx)| (qa + (qb - qa) * t - qx).abs() <= tolerance)
}

/// Writes `text` to `out` once it holds 64 KiB, and clears it.
fn spill<W: Write>(out: &mut W, text: &mut String) -> std::io::Result<()> {
    if text.len() > 1 << 16 {
        out.write_all(text.as_bytes())?;
        text.clear();
    }
    Ok(())
}

/// A robot program written as the samples come: [`Self::push`] each chunk in time order,
/// then [`Self::finish`]; the main file streams to the writer, its companion (KRL's `.dat`,
/// fixed by the target) is [`Self::companion`]. Memory: one window of the decimation.
#[derive(Debug)]
pub struct RobotProgram<'a, W: Write> {
    out: W,
    cx: Context<'a>,
    decimator: Decimator,
    started: bool,
    text: String,
}

impl<'a, W: Write> RobotProgram<'a, W> {
    /// A writer of `options`' program for `target` to `out`; checks the options and that the
    /// robot's convention is the language's vendor's.
    pub fn new(out: W, target: Target<'a>, options: &ProgramOptions) -> Result<Self, ProgramError> {
        options.validate()?;
        if let Some(vendor) = options.language.vendor() {
            match target.convention {
                None => {
                    return Err(ProgramError::NoConvention {
                        robot: target.robot.to_string(),
                        language: options.language,
                    });
                }
                Some(c) if c.vendor != vendor => {
                    return Err(ProgramError::WrongVendor {
                        robot: target.robot.to_string(),
                        language: options.language,
                        got: c.vendor,
                    });
                }
                Some(_) => {}
            }
        }
        Ok(Self {
            out,
            cx: Context {
                target,
                options: options.clone(),
                data: Data::new(target.model),
                line: usize::MAX,
                speed: f64::NAN,
                blend: f64::NAN,
                dwelt: usize::MAX,
                motions: 0,
            },
            decimator: Decimator::default(),
            started: false,
            text: String::new(),
        })
    }

    /// The main file's name (`deflect_job.src`).
    pub fn file_name(&self) -> String {
        std::format!(
            "{}.{}",
            self.cx.options.name,
            self.cx.options.language.extension()
        )
    }

    /// The companion file (KRL's `.dat`: the frames), known before any sample.
    pub fn companion(&self) -> Option<ProgramFile> {
        match self.cx.options.language {
            Language::Krl => Some(ProgramFile {
                name: std::format!("{}.dat", self.cx.options.name),
                text: krl::dat(&self.cx),
            }),
            _ => None,
        }
    }

    /// Whether the command keeps every sample (URScript's `servoj`, the joints CSV).
    fn every_sample(&self) -> bool {
        self.cx.options.command == Command::Joints
            && matches!(self.cx.options.language, Language::UrScript | Language::Csv)
    }

    /// The next samples, in time order.
    pub fn push(&mut self, chunk: &[JobSample]) -> Result<(), ProgramError> {
        let language = self.cx.options.language;
        let command = self.cx.options.command;
        for s in chunk {
            if !self.started {
                self.started = true;
                header(language, command, &mut self.text, &mut self.cx, s)?;
            }
            if self.every_sample() {
                let k = Kept {
                    sample: *s,
                    stop: false,
                };
                motion(language, command, &mut self.text, &mut self.cx, &k)?;
            } else {
                let (tol, jtol, dof) = (
                    self.cx.options.tolerance,
                    self.cx.options.joint_tolerance,
                    self.cx.target.model.dof(),
                );
                let holds = |a: &JobSample, b: &JobSample, x: &JobSample| match command {
                    Command::Cartesian => pose_holds(tol, a, b, x),
                    Command::Joints => joints_hold(jtol, dof, a, b, x),
                };
                let mut failed = None;
                let (cx, text) = (&mut self.cx, &mut self.text);
                self.decimator.push(s, &holds, &mut |k: &Kept| {
                    if failed.is_none()
                        && let Err(e) = motion(language, command, text, cx, k)
                    {
                        failed = Some(e);
                    }
                });
                if let Some(e) = failed {
                    return Err(e);
                }
            }
            spill(&mut self.out, &mut self.text)?;
        }
        Ok(())
    }

    /// Writes the last motion and the program's end; hands back the output.
    pub fn finish(mut self) -> Result<W, ProgramError> {
        let language = self.cx.options.language;
        let command = self.cx.options.command;
        if !self.every_sample() {
            let (tol, jtol, dof) = (
                self.cx.options.tolerance,
                self.cx.options.joint_tolerance,
                self.cx.target.model.dof(),
            );
            let holds = |a: &JobSample, b: &JobSample, x: &JobSample| match command {
                Command::Cartesian => pose_holds(tol, a, b, x),
                Command::Joints => joints_hold(jtol, dof, a, b, x),
            };
            let mut failed = None;
            let (cx, text) = (&mut self.cx, &mut self.text);
            self.decimator.finish(&holds, &mut |k: &Kept| {
                if failed.is_none()
                    && let Err(e) = motion(language, command, text, cx, k)
                {
                    failed = Some(e);
                }
            });
            if let Some(e) = failed {
                return Err(e);
            }
        }
        footer(language, &mut self.text, &self.cx);
        self.out.write_all(self.text.as_bytes())?;
        self.out.flush()?;
        Ok(self.out)
    }
}

fn header(
    language: Language,
    command: Command,
    out: &mut String,
    cx: &mut Context<'_>,
    first: &JobSample,
) -> Result<(), ProgramError> {
    match language {
        Language::Krl => krl::header(out, cx, command, first),
        Language::Rapid => rapid::header(out, cx, command, first),
        Language::UrScript => urscript::header(out, cx, command, first),
        Language::Csv => {
            csv::header(out, cx, command);
            Ok(())
        }
    }
}

fn motion(
    language: Language,
    command: Command,
    out: &mut String,
    cx: &mut Context<'_>,
    k: &Kept,
) -> Result<(), ProgramError> {
    cx.motions += 1;
    match language {
        Language::Krl => krl::motion(out, cx, command, k),
        Language::Rapid => rapid::motion(out, cx, command, k),
        Language::UrScript => urscript::motion(out, cx, command, k),
        Language::Csv => {
            csv::motion(out, cx, command, k);
            Ok(())
        }
    }
}

fn footer(language: Language, out: &mut String, cx: &Context<'_>) {
    match language {
        Language::Krl => krl::footer(out),
        Language::Rapid => rapid::footer(out),
        Language::UrScript => urscript::footer(out, cx),
        Language::Csv => {}
    }
}

/// The whole program of `samples` in memory: its main file, then its companion.
pub fn write(
    target: Target<'_>,
    samples: &[JobSample],
    options: &ProgramOptions,
) -> Result<Vec<ProgramFile>, ProgramError> {
    let mut w = RobotProgram::new(Vec::new(), target, options)?;
    let name = w.file_name();
    let companion = w.companion();
    w.push(samples)?;
    let bytes = w.finish()?;
    let mut files = std::vec![ProgramFile {
        name,
        text: String::from_utf8(bytes).unwrap_or_default(),
    }];
    files.extend(companion);
    Ok(files)
}
