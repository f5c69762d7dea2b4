//! RS274/NGC G-code programs (`std`), read as LinuxCNC's interpreter reads them, into a
//! [`Program`](crate::machining::Program) of moves in the workpiece frame, SI: what a CAM post-processor writes for a
//! mill, and the NGC language of parametric programs.
//!
//! The reference is LinuxCNC's RS274/NGC interpreter (the descendant of NIST's RS274NGC;
//! `rs274 -g FILE` prints its canonical moves): where it accepts a program, the moves here are
//! its moves (kind, end point, arc centre and plane, feed), and where it refuses one, this
//! reader refuses it with a [`LoadError::Program`](crate::error::LoadError::Program) naming the line, the column and the word.
//!
//! | words | meaning here |
//! |---|---|
//! | `G0` `G1` `G2` `G3` `G5` `G5.1` | rapid, line, arcs in `G17`/`G18`/`G19` (`I J K` or `R`, `P` turns, helices), cubic and quadratic splines (lines within 1 um) |
//! | `G73` `G74` `G81`-`G89` `G80` `G98` `G99` | canned cycles expanded into LinuxCNC's moves (`R`, `Q`, `P`, `L`, `G91`; `G88`'s retract by the operator's hand is a rapid) |
//! | `G4` | dwell `P` seconds: a timed stop |
//! | `G17` `G18` `G19` `G90.1` `G91.1` | arc plane, absolute / incremental arc centres |
//! | `G20` `G21` `G90` `G91` `G93` `G94` `G95` | units anywhere, distance modes, feed per minute, inverse time, per revolution (turned into path speed) |
//! | `G54`-`G59.3` `G10 L2/L20` `G92` `G92.1`-`G92.3` `G52` `G53` `G28` `G30` `G28.1` `G30.1` | work and axis offsets, machine coordinates, the stored points, in the program's machine frame |
//! | `T` `M6` `M61 Q` | the tool in the spindle, per move |
//! | `M3` `M4` `M5` `S` | spindle clockwise, counter-clockwise (the cutting model's direction), off, speed |
//! | `G43 H` `G43.1` `G43.2` `G49` | tool length offsets: recorded, not applied (a robot's TCP carries the tool length) |
//! | `G61` `G61.1` `G64 P Q` | path control: recorded per move ([`crate::machining::PathControl`]) |
//! | `A` `B` `C` | with [`GcodeOptions::kinematics`]: the rotary axes it declares (degrees), turned into the tool tip and axis of each move; a turn with `G0`/`G1` (alone only at `G0`), not on an arc or in a cycle; an angle past the axis' limits refused |
//! | `M0` `M1` `M60` `M7`-`M9` `M19` `M48`-`M53` `M62`-`M68` `M70`-`M73` `G40` `G97` | stops, coolant, orientation, overrides, I/O, modal state save and restore: no motion |
//! | `M2` `M30` `M99` `%` | program end (what follows is not read) |
//! | `#1`-`#5601` `#<name>` `#<_global>` `[...]` `O` words `M98` | parameters, expressions, subroutines and control flow (see below) |
//! | `N`, `/`, `(...)`, `;`, `(MSG,...)` `(DEBUG,...)` `(PRINT,...)` `(ABORT,...)` | line numbers, block delete, comments |
//!
//! Refused by name: cutter radius compensation (`G41`, `G42`), probing (`G38.x`), threading
//! (`G33`, `G76`), lathe modes and cycles (`G7`, `G70`-`G72`, `G96`), NURBS (`G5.2`), rotary
//! axes (`A B C`) but those of [`GcodeOptions::kinematics`], secondary axes (`U V W`), user M codes
//! (`M100`-`M199`); and every word LinuxCNC refuses, with its reason.
//!
//! # The frame
//! Moves are in the program's machine frame: the program's coordinates plus the work offset
//! of the active coordinate system (`G54`-`G59.3`, with its XY rotation) and the axis offset
//! (`G92`, `G52`). A program that never sets them (the usual CAM output: the offsets live in
//! the controller) has its moves in its own coordinates. `G53`, `G28` and `G30` move in that
//! frame; the stored points of `G28`/`G30` are the origin until `G28.1`/`G30.1` set them.
//! Tool length offsets are recorded and not applied: the moves are LinuxCNC's with every
//! tool length zero.
//!
//! # The language
//! LinuxCNC's NGC: spaces ignored, letters in either case, numbers without exponents;
//! numbered parameters (`#1`-`#30` local to a call), named locals and `_` globals, settings
//! taking effect after the line is read; expressions with `**`, `* / MOD`, `+ -`, `EQ NE GT
//! GE LT LE`, `AND OR XOR` and `ABS ACOS ASIN ATAN[y]/[x] COS EXISTS EXP FIX FUP LN ROUND SIN
//! SQRT TAN` (degrees); `O` subroutines (`sub`, `endsub`, `call` with up to 30 arguments,
//! `return`, values in `#<_value>`), Fanuc-style `M98 P L` / `M99`, and `if`/`elseif`/`else`,
//! `while`, `do`, `repeat`, `break`, `continue`. Subroutines are looked for in the program,
//! not in files. Budgets: [`MAX_CALL_DEPTH`], [`MAX_BLOCKS`] (a loop that never ends is a
//! budget error), [`MAX_EXPRESSION_DEPTH`], [`MAX_NAMED_PARAMETERS`].
//!
//! # Dialects
//! Some programs LinuxCNC refuses run on the control their post targets; [`Dialect`] reads
//! them as that control does. Where this reader is more lenient than LinuxCNC by default: a
//! program may end without `M2`, `M30` or `%` (LinuxCNC refuses one that does), and lines may
//! be longer than LinuxCNC's 252 characters.

mod arc;
mod cycles;
mod expr;
mod fault;
mod flow;
mod interp;
mod lex;
mod motion;
mod offsets;
mod params;
mod read;
pub(crate) use read::check_start;
pub use read::{from_path, from_str};
pub mod report;
mod stack;
mod words;

use nalgebra::Vector3;

use crate::units::LengthUnit;

pub use cycles::PECK_CLEARANCE;
pub use lex::MAX_EXPRESSION_DEPTH;
pub use motion::{MAX_SPLINE_CHORDS, SPLINE_TOLERANCE};
pub use params::{MAX_NAMED_PARAMETERS, MAX_PARAMETER};
pub use report::{WordStatus, WordUse, words};

// The limits every program holds, whatever its source (checked again by
// `Program::validate`).
pub use crate::machining::{ARC_TOLERANCE, MAX_COORDINATE, MAX_FEED, MAX_SPINDLE_RPM};

/// Most lines a program may have: 1,000,000 (about 20 MB of G-code, beyond
/// [`super::MAX_FILE_BYTES`] for typical lines anyway); refused before parsing.
pub const MAX_PROGRAM_LINES: usize = 1_000_000;

/// Most nested subroutine calls (LinuxCNC's: a tenth level is refused).
pub const MAX_CALL_DEPTH: usize = 9;

/// Most lines one reading runs or skips: 5,000,000 (five times the longest program, about
/// 1 s of reading; a loop that never ends, or one that runs a billion times, is refused
/// with [`LoadError::ProgramBudget`](crate::error::LoadError::ProgramBudget)).
pub const MAX_BLOCKS: usize = 5_000_000;

/// The control a program is read for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Dialect {
    /// LinuxCNC's RS274/NGC, word for word.
    #[default]
    LinuxCnc,
    /// grbl: an arc's centre word along the plane's normal (FreeCAD's grbl post writes
    /// `K0.000` on every `G17` arc) is ignored, as grbl ignores it.
    Grbl,
    /// Fanuc-style controls (Fanuc, Haas, Mach3): axis words after `G80` with no motion code
    /// move in the last `G0`-`G3` mode; `%` lines are tape markers wherever they are, and text
    /// after a `%` (`%O1000`) is a comment; comments may nest; Haas's smoothness and
    /// look-ahead settings (`G187 P E`, `G103 P`) are read without motion.
    Fanuc,
}

impl Dialect {
    /// Parses "linuxcnc", "grbl" or "fanuc" (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "linuxcnc" => Some(Self::LinuxCnc),
            "grbl" => Some(Self::Grbl),
            "fanuc" => Some(Self::Fanuc),
            _ => None,
        }
    }

    /// Its name as [`Self::parse`] reads it.
    pub fn name(self) -> &'static str {
        match self {
            Self::LinuxCnc => "linuxcnc",
            Self::Grbl => "grbl",
            Self::Fanuc => "fanuc",
        }
    }

    pub(crate) fn nested_comments(self) -> bool {
        self == Self::Fanuc
    }

    pub(crate) fn ignores_off_plane_offset(self) -> bool {
        self == Self::Grbl
    }

    pub(crate) fn motion_after_g80(self) -> bool {
        self == Self::Fanuc
    }

    pub(crate) fn percent_anywhere(self) -> bool {
        self != Self::LinuxCnc
    }

    pub(crate) fn haas_settings(self) -> bool {
        self == Self::Fanuc
    }
}

/// Settings of the reader.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GcodeOptions {
    /// Where the tool is before the first move \[m\], workpiece frame (the first move starts
    /// there; incremental coordinates count from it). Default: the origin.
    pub start: Vector3<f64>,
    /// Length unit until the program says `G20` or `G21`. Default: mm (LinuxCNC's).
    pub units: LengthUnit,
    /// The control the program is written for. Default: LinuxCNC.
    pub dialect: Dialect,
    /// The block delete switch: when on, lines starting with `/` are skipped. Default: off
    /// (LinuxCNC's), they run.
    pub block_delete: bool,
    /// A five-axis machine's rotary axes: its `A B C` words (degrees, `G90`/`G91` like the
    /// linear axes) turn the tool axis of the moves ([`crate::machining::Kinematics`]).
    /// Default: none (a 3-axis program: `A B C` may only stay at 0).
    pub kinematics: Option<crate::machining::Kinematics>,
}

impl Default for GcodeOptions {
    fn default() -> Self {
        Self {
            start: Vector3::zeros(),
            units: LengthUnit::Millimetre,
            dialect: Dialect::LinuxCnc,
            block_delete: false,
            kinematics: None,
        }
    }
}

/// The modal group of a G code (ten times its number), as LinuxCNC groups them; `None` for
/// a code LinuxCNC does not know.
pub(crate) fn words_group(code: u16) -> Option<u8> {
    Some(match code {
        40 | 53 | 100 | 280 | 281 | 300 | 301 | 520 | 530 | 920 => 0,
        0
        | 10
        | 20
        | 30
        | 50
        | 51
        | 52
        | 330
        | 331
        | 382..=385
        | 700
        | 710
        | 711
        | 712
        | 720
        | 721
        | 722
        | 730
        | 740
        | 760
        | 800
        | 810
        | 820
        | 830
        | 840
        | 850
        | 860
        | 870
        | 880
        | 890 => 1,
        170 | 171 | 180 | 181 | 190 | 191 => 2,
        900 | 910 => 3,
        901 | 911 => 4,
        930 | 940 | 950 => 5,
        200 | 210 => 6,
        400 | 410 | 411 | 420 | 421 => 7,
        430 | 431 | 432 | 490 => 8,
        980 | 990 => 10,
        540 | 550 | 560 | 570 | 580 | 590 | 591 | 592 | 593 => 12,
        610 | 611 | 640 => 13,
        960 | 970 => 14,
        70 | 80 => 15,
        921..=923 => 16,
        1030 | 1870 => 17,
        _ => return None,
    })
}

/// The modal group of an M code, as LinuxCNC groups them; `None` for one it does not know.
pub(crate) fn m_group(code: u16) -> Option<u8> {
    Some(match code {
        0 | 1 | 2 | 30 | 60 | 99 => 4,
        62..=68 => 5,
        6 | 61 => 6,
        3 | 4 | 5 | 19 | 70..=73 => 7,
        7..=9 => 8,
        48..=53 => 9,
        98 | 100..=199 => 10,
        _ => return None,
    })
}
