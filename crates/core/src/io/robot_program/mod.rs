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
//! the samples a streamed decimation keeps (the one the compensated G-code shares): every dropped sample lies
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

mod context;
pub mod csv;
mod error;
pub mod krl;
pub mod rapid;
pub mod urscript;
mod writer;

pub(crate) use context::{Context, join, pose};
pub use error::ProgramError;
pub use writer::RobotProgram;

use std::string::{String, ToString};
use std::vec::Vec;

use nalgebra::Isometry3;

use crate::controller::{Convention, Vendor};
use crate::machining::Program;
use crate::machining::job::JobSample;
use crate::vjm::Model;

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
