//! Tier 1 for files (`std`): a robot description, map or table file could not be loaded.

use core::fmt;
use std::string::String;

use super::BuildError;
use super::build::axis_name;

/// A robot description, map or table file could not be loaded. Every variant names the file
/// element at fault; [`LoadError::Build`] wraps the values' own error.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum LoadError {
    /// A file could not be read.
    Io {
        /// The file.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// A file could not be written.
    Write {
        /// The file.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// A file exceeds a documented size or nesting budget (checked before parsing).
    TooLarge {
        /// What was measured ("URDF size", "XML nesting depth", ...).
        what: String,
        /// The limit.
        limit: usize,
        /// The value found.
        got: usize,
    },
    /// urdf-rs rejected the URDF text, or its XML structure is not a single `<robot>`.
    UrdfParse {
        /// The parser's message.
        message: String,
    },
    /// A TOML file (stiffness, drive train) is malformed: syntax, unknown field, wrong type.
    StiffnessParse {
        /// The TOML parser's message, with line and column.
        message: String,
    },
    /// Two links, joints or entries share a name.
    DuplicateName {
        /// "link", "joint", "drive-train entry".
        kind: &'static str,
        /// The repeated name.
        name: String,
    },
    /// A link name that the URDF does not define.
    UnknownLink {
        /// The name.
        link: String,
        /// Where it was used (a joint name, "tip_link", "base_link", "stiffness file").
        referenced_by: String,
    },
    /// A joint name that the chain does not have.
    UnknownJoint {
        /// The name.
        joint: String,
        /// Where it was used.
        referenced_by: String,
    },
    /// The tip link is not a descendant of the base link.
    TipNotReachable {
        /// Requested tip.
        tip: String,
        /// Base link.
        base: String,
    },
    /// The joints form a cycle, or a link has two parent joints.
    NotATree {
        /// The link where the walk from the tip met it.
        link: String,
    },
    /// A joint or virtual-joint origin holds NaN or an infinity.
    NonFiniteOrigin {
        /// The joint (or "virtual_joint #n on link L").
        element: String,
    },
    /// A revolute or prismatic joint axis is zero or not finite.
    ZeroAxis {
        /// The joint.
        joint: String,
    },
    /// A joint limit with `lower >= upper` or NaN (a revolute or prismatic joint without
    /// `<limit>` reads as lower = upper = 0).
    InvalidLimit {
        /// The joint.
        joint: String,
        /// Lower limit.
        lower: f64,
        /// Upper limit.
        upper: f64,
    },
    /// A joint type the serial model does not support on the base-to-tip path.
    UnsupportedJoint {
        /// The joint.
        joint: String,
        /// Its type or feature ("floating", "planar", "spherical", "mimic").
        kind: String,
    },
    /// A virtual joint names a link that is not on the base-to-tip chain.
    LinkNotInChain {
        /// The link.
        link: String,
    },
    /// A stiffness is zero, negative, sub-normal or NaN (`inf` = rigid is fine).
    NonPositiveStiffness {
        /// The element ("virtual_joint #0 on link 'l'", "joint 'a1'").
        element: String,
        /// 0, 1, 2 for x, y, z.
        axis: usize,
        /// The value \[N m / rad\].
        value: f64,
    },
    /// A value of a file entry is out of range or missing.
    InvalidValue {
        /// The element ("joint 'a1'", "virtual_joint #2").
        element: String,
        /// The field.
        field: &'static str,
        /// What was expected, in words.
        expected: String,
        /// What was found.
        got: String,
    },
    /// A G-code program line is malformed or uses what the reader does not support.
    Program {
        /// 1-based line.
        line: usize,
        /// 1-based column (byte) of the word at fault.
        column: usize,
        /// What was expected, and what was found.
        message: String,
    },
    /// A G-code program ran past a documented budget of the reader (lines run, call depth).
    ProgramBudget {
        /// 1-based line where the budget ran out.
        line: usize,
        /// What was counted.
        what: String,
        /// The budget's name ("MAX_BLOCKS").
        budget: &'static str,
        /// Its value.
        limit: usize,
    },
    /// The CSV reader failed (malformed record, wrong field count).
    Csv {
        /// 1-based line, when known.
        line: Option<u64>,
        /// The reader's message.
        message: String,
    },
    /// A required column is absent from a CSV header.
    MissingColumn {
        /// Column name.
        column: &'static str,
    },
    /// A CSV header names a column the format does not have.
    UnknownColumn {
        /// Column name as written.
        column: String,
    },
    /// A CSV field is not a number (or not a valid force axis).
    BadNumber {
        /// Record index (0-based, header not counted).
        row: usize,
        /// Column name.
        column: &'static str,
    },
    /// A CSV value is NaN or infinite.
    NonFiniteCell {
        /// Record index (0-based, header not counted).
        row: usize,
        /// Column name.
        column: &'static str,
    },
    /// An unknown unit name.
    UnknownUnit {
        /// "force" or "length".
        quantity: &'static str,
        /// The name given.
        unit: String,
    },
    /// The JSON text is malformed or misses fields.
    Json {
        /// The parser's message.
        message: String,
    },
    /// A JSON map of another format version.
    UnsupportedVersion {
        /// The version found.
        found: u64,
    },
    /// A JSON map records units other than SI.
    UnexpectedUnits {
        /// Which quantity.
        quantity: &'static str,
        /// The unit recorded.
        found: String,
    },
    /// The values read are not a valid model (capacity, stiffness, grid, fit).
    Build(BuildError),
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, message } => write!(f, "cannot read {path}: {message}"),
            Self::Write { path, message } => write!(f, "cannot write {path}: {message}"),
            Self::TooLarge { what, limit, got } => {
                write!(f, "{what} is {got}; the loader accepts at most {limit}")
            }
            Self::UrdfParse { message } => write!(f, "invalid URDF: {message}"),
            Self::StiffnessParse { message } => write!(f, "invalid stiffness file: {message}"),
            Self::DuplicateName { kind, name } => write!(f, "duplicate {kind} name '{name}'"),
            Self::UnknownLink {
                link,
                referenced_by,
            } => write!(f, "unknown link '{link}' (referenced by {referenced_by})"),
            Self::UnknownJoint {
                joint,
                referenced_by,
            } => write!(f, "unknown joint '{joint}' (referenced by {referenced_by})"),
            Self::TipNotReachable { tip, base } => write!(
                f,
                "tip link '{tip}' is not reachable from base link '{base}'"
            ),
            Self::NotATree { link } => write!(
                f,
                "the joints around link '{link}' form a cycle or give it two parents"
            ),
            Self::NonFiniteOrigin { element } => {
                write!(f, "{element}: origin is not finite (NaN or inf)")
            }
            Self::ZeroAxis { joint } => write!(f, "joint '{joint}': axis is zero or not finite"),
            Self::InvalidLimit {
                joint,
                lower,
                upper,
            } => write!(
                f,
                "joint '{joint}': invalid limits lower={lower} upper={upper} (a revolute or \
                 prismatic joint needs <limit> with lower < upper)"
            ),
            Self::UnsupportedJoint { joint, kind } => {
                write!(f, "joint '{joint}': {kind} joints are not supported")
            }
            Self::LinkNotInChain { link } => write!(
                f,
                "virtual joint on link '{link}', which is not on the base-to-tip chain"
            ),
            Self::NonPositiveStiffness {
                element,
                axis,
                value,
            } => write!(
                f,
                "{element}: stiffness about {} is {value:?}; it must be a normal number > 0 \
                 (inf = rigid)",
                axis_name(*axis)
            ),
            Self::InvalidValue {
                element,
                field,
                expected,
                got,
            } => write!(f, "{element}: {field} is {got}; expected {expected}"),
            Self::Program {
                line,
                column,
                message,
            } => write!(
                f,
                "program line {line}, column {column}: expected {message}"
            ),
            Self::ProgramBudget {
                line,
                what,
                budget,
                limit,
            } => write!(
                f,
                "program line {line}: {what}: more than {budget} = {limit}"
            ),
            Self::Csv { line, message } => match line {
                Some(l) => write!(f, "CSV line {l}: {message}"),
                None => write!(f, "CSV: {message}"),
            },
            Self::MissingColumn { column } => write!(f, "missing column {column:?}"),
            Self::UnknownColumn { column } => write!(f, "unknown column {column:?}"),
            Self::BadNumber { row, column } => {
                write!(f, "row {row}, column {column}: not a valid number")
            }
            Self::NonFiniteCell { row, column } => {
                write!(f, "row {row}, column {column}: value is not finite")
            }
            Self::UnknownUnit { quantity, unit } => write!(f, "unknown {quantity} unit {unit:?}"),
            Self::Json { message } => write!(f, "JSON: {message}"),
            Self::UnsupportedVersion { found } => write!(
                f,
                "compliance map format_version {found} is not supported (expected 1 or 2)"
            ),
            Self::UnexpectedUnits { quantity, found } => {
                write!(f, "JSON map records {quantity} in {found:?}; expected SI")
            }
            Self::Build(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for LoadError {}

impl From<BuildError> for LoadError {
    fn from(e: BuildError) -> Self {
        Self::Build(e)
    }
}
