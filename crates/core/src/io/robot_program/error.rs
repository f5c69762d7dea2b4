//! Why a robot program could not be written.

use std::string::{String, ToString};

use super::{Language, MAX_NAME};
use crate::controller::Vendor;
use crate::error::{BuildError, TickError};

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
