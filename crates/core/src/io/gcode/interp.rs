//! The machine a block runs on: LinuxCNC's modal state and its order of execution within a
//! block (comment, feed mode, F, S, T, M codes by group, dwell, plane, units, cutter radius
//! and tool length compensation, coordinate system, path control, distance modes, retract
//! mode, the non-modal codes, motion, stops), each code checked as LinuxCNC checks it.
//!
//! Positions are kept as LinuxCNC keeps them, in the program frame `P` (SI here), with the
//! active work offset `G5x`, its XY rotation `R` and the axis offset `G92`; the moves are
//! the tool tip's in the machine frame, `Rot(R) (P + G92) + G5x`. Tool length offsets are
//! recorded and not applied: a robot's TCP is the tool tip.

use std::string::String;
use std::vec::Vec;

use nalgebra::{Vector2, Vector3};

use super::Dialect;
use super::fault::{Fault, fault};
use super::params::Params;
use super::words::{Words, g_name};
use crate::machining::kinematics::RotaryWord;
use crate::machining::{Motion, Move, PathControl, Plane};

mod modes;

/// Millimetres per inch.
pub(super) const INCH: f64 = 25.4e-3;

/// Feed rate modes (`G93`, `G94`, `G95`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum FeedMode {
    InverseTime,
    PerMinute,
    PerRevolution,
}

/// The modal state `M70`/`M73` save and `M72` restores.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Modal {
    units: f64,
    plane: Plane,
    absolute: bool,
    ijk_absolute: bool,
    feed_mode: FeedMode,
    feed: f64,
    motion: Option<u16>,
    retract_old_z: bool,
    path_control: PathControl,
    spindle_rpm: f64,
    spindle_dir: i8,
    mist: bool,
    flood: bool,
    system: usize,
}

/// What the canned cycles remember between blocks (LinuxCNC's `cycle_*` settings).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct CycleMemory {
    /// The initial level of the series (the drilling-axis coordinate before its first block),
    /// program frame \[m\]; `None` outside a series.
    pub initial: Option<f64>,
    /// The raw R, depth, P, Q, I, J, K words (program units; I/J/K of G87).
    pub r: Option<f64>,
    pub depth: Option<f64>,
    pub p: Option<f64>,
    pub q: Option<f64>,
    pub i: Option<f64>,
    pub j: Option<f64>,
    pub k: Option<f64>,
}

/// The interpreter's machine.
#[derive(Debug, Clone)]
pub(super) struct Machine {
    pub dialect: Dialect,
    /// Program-frame position \[m\].
    pub pos: Vector3<f64>,
    /// Active coordinate system, 1 (G54) ..= 9 (G59.3).
    pub system: usize,
    /// Active work offset \[m\] and its XY rotation \[deg\].
    pub g5x: Vector3<f64>,
    pub rotation: f64,
    /// Axis offset (G92/G52) \[m\].
    pub g92: Vector3<f64>,
    /// Metres per program unit.
    pub units: f64,
    pub plane: Plane,
    pub absolute: bool,
    pub ijk_absolute: bool,
    pub feed_mode: FeedMode,
    /// The F word as given (program units per minute, or per revolution in G95).
    pub feed: f64,
    /// Modal motion, ten times its G number; `None` after G80 and at the start.
    pub motion: Option<u16>,
    /// The last G0-G3 mode (the Fanuc dialect's motion after G80).
    pub plain_motion: Option<u16>,
    pub retract_old_z: bool,
    pub path_control: PathControl,
    pub spindle_rpm: f64,
    /// 1 clockwise, -1 counter-clockwise, 0 stopped.
    pub spindle_dir: i8,
    pub tool: u32,
    pub selected: u32,
    /// Recorded tool length offset \[m\] (not applied) and whether one is in effect.
    pub tool_offset: Vector3<f64>,
    pub mist: bool,
    pub flood: bool,
    pub feed_override: bool,
    pub speed_override: bool,
    pub cycle: CycleMemory,
    /// The last G5's P and Q (program units), for a G5 without I and J.
    pub spline_pq: Option<(f64, f64)>,
    /// M70/M73 saved states.
    pub saved: Option<Modal>,
    pub moves: Vec<Move>,
    /// The operations so far (see [`crate::machining::Program::operations`]), the name the
    /// next one takes, and whether the next move starts one.
    pub operations: Vec<crate::machining::Operation>,
    pub operation_name: Option<String>,
    pub operation_next: bool,
    /// The line of M2/M30 (or an M99 at the top level), once read.
    pub ended: Option<usize>,
    /// The physical line being run (1-based).
    pub line: usize,
    /// `#<_value>`, `#<_value_returned>`, `#<_call_level>`.
    pub value: f64,
    pub value_returned: bool,
    pub call_level: usize,
    /// The machine's rotary axes, if the program is read for one.
    pub kinematics: Option<crate::machining::Kinematics>,
    /// The rotary angles (A, B, C) \[rad\] at the current point, and where the block's words
    /// turn them (reached by the block's first move).
    pub rotary: [f64; 3],
    pub rotary_end: [f64; 3],
    /// The column of the block's first rotary word (1 without one).
    pub rotary_column: usize,
}

/// Rotates (x, y) by `deg` counter-clockwise.
pub(super) fn rotate(v: Vector2<f64>, deg: f64) -> Vector2<f64> {
    if deg == 0.0 {
        return v;
    }
    let (s, c) = deg.to_radians().sin_cos();
    Vector2::new(v.x * c - v.y * s, v.x * s + v.y * c)
}

impl Machine {
    /// A comment line standing alone: after moves it starts the next operation; the last
    /// one before a move names it.
    pub(super) fn note_comment(&mut self, text: &str) {
        let name = text.trim();
        if name.is_empty() {
            return;
        }
        if self
            .operations
            .last()
            .is_some_and(|o| o.first_move < self.moves.len())
        {
            self.operation_next = true;
        }
        self.operation_name = Some(name.chars().take(200).collect());
    }

    pub(super) fn new(dialect: Dialect, start: Vector3<f64>, units: f64) -> Self {
        Self {
            dialect,
            pos: start,
            system: 1,
            g5x: Vector3::zeros(),
            rotation: 0.0,
            g92: Vector3::zeros(),
            units,
            plane: Plane::Xy,
            absolute: true,
            ijk_absolute: false,
            feed_mode: FeedMode::PerMinute,
            feed: 0.0,
            motion: None,
            plain_motion: None,
            retract_old_z: false,
            path_control: PathControl::default(),
            spindle_rpm: 0.0,
            spindle_dir: 0,
            tool: 0,
            selected: 0,
            tool_offset: Vector3::zeros(),
            mist: false,
            flood: false,
            feed_override: true,
            speed_override: true,
            cycle: CycleMemory::default(),
            spline_pq: None,
            saved: None,
            moves: Vec::new(),
            operations: Vec::new(),
            operation_name: None,
            operation_next: false,
            ended: None,
            line: 0,
            value: 0.0,
            value_returned: false,
            call_level: 0,
            kinematics: None,
            rotary: [0.0; 3],
            rotary_end: [0.0; 3],
            rotary_column: 1,
        }
    }

    /// The machine read with `kinematics`' rotary axes.
    pub(super) fn with_kinematics(
        mut self,
        kinematics: Option<crate::machining::Kinematics>,
    ) -> Self {
        self.kinematics = kinematics;
        self
    }

    /// Reads the block's words of the kinematics' rotary axes (degrees; incremental in
    /// `G91`) into [`Self::rotary_end`]; the other rotary words were refused (or are 0).
    fn rotary_words(&mut self, w: &mut Words) {
        self.rotary_end = self.rotary;
        let Some(k) = self.kinematics else {
            for letter in [b'a', b'b', b'c'] {
                w.take(letter);
            }
            return;
        };
        for (letter, word) in [
            (b'a', RotaryWord::A),
            (b'b', RotaryWord::B),
            (b'c', RotaryWord::C),
        ] {
            let Some(v) = w.take(letter) else { continue };
            if k.rotary(word).is_none() {
                continue;
            }
            let i = word.index();
            let now = self.rotary.get(i).copied().unwrap_or(0.0);
            if let Some(slot) = self.rotary_end.get_mut(i) {
                *slot = if self.absolute {
                    v.to_radians()
                } else {
                    now + v.to_radians()
                };
            }
        }
    }

    /// The machine-frame tool tip of program-frame point `p` \[m\].
    pub(super) fn to_machine(&self, p: &Vector3<f64>) -> Vector3<f64> {
        let xy = rotate(p.xy() + self.g92.xy(), self.rotation) + self.g5x.xy();
        Vector3::new(xy.x, xy.y, p.z + self.g92.z + self.g5x.z)
    }

    /// The program-frame point of machine-frame point `m` \[m\].
    pub(super) fn to_program(&self, m: &Vector3<f64>) -> Vector3<f64> {
        let xy = rotate(m.xy() - self.g5x.xy(), -self.rotation) - self.g92.xy();
        Vector3::new(xy.x, xy.y, m.z - self.g5x.z - self.g92.z)
    }

    /// The machine's modal state (M70).
    fn modal(&self) -> Modal {
        Modal {
            units: self.units,
            plane: self.plane,
            absolute: self.absolute,
            ijk_absolute: self.ijk_absolute,
            feed_mode: self.feed_mode,
            feed: self.feed,
            motion: self.motion,
            retract_old_z: self.retract_old_z,
            path_control: self.path_control,
            spindle_rpm: self.spindle_rpm,
            spindle_dir: self.spindle_dir,
            mist: self.mist,
            flood: self.flood,
            system: self.system,
        }
    }

    /// Restores a saved modal state (M72; the automatic restore of M73 at a sub's return).
    pub(super) fn restore(&mut self, m: &Modal, params: &Params) {
        self.units = m.units;
        self.plane = m.plane;
        self.absolute = m.absolute;
        self.ijk_absolute = m.ijk_absolute;
        self.feed_mode = m.feed_mode;
        self.feed = m.feed;
        self.motion = m.motion;
        self.retract_old_z = m.retract_old_z;
        self.path_control = m.path_control;
        self.spindle_rpm = m.spindle_rpm;
        self.spindle_dir = m.spindle_dir;
        self.mist = m.mist;
        self.flood = m.flood;
        if m.system != self.system {
            self.select_system(m.system, params);
        }
    }

    /// The moves' spindle \[rev/s\], signed by direction.
    pub(super) fn spindle(&self) -> f64 {
        f64::from(self.spindle_dir) * self.spindle_rpm / 60.0
    }

    /// Runs a block (see the module docs for the order). `params` for the offset and home
    /// parameters.
    pub(super) fn execute(&mut self, w: &mut Words, params: &mut Params) -> Result<(), Fault> {
        super::words::check_groups(w)?;
        self.refuse_unsupported(w)?;
        let rotary_column = [b'a', b'b', b'c']
            .into_iter()
            .find(|&l| w.has(l))
            .map_or(1, |l| w.column(l));
        self.rotary_column = rotary_column;
        self.modes_before_motion(w, params)?;
        // After the distance mode of this block, before its motion.
        self.rotary_words(w);
        let consumed = self.non_modal(w, params)?;
        self.motion(w, consumed, params)?;
        if self.rotary_end != self.rotary {
            // A turn of the rotaries alone: a reorientation in place, at the rapid rate.
            if self.motion != Some(0) {
                return fault(
                    rotary_column,
                    "a turn of the rotary axes alone in G0 (in G1 it has no path speed: give \
                     the X Y Z of the move with it)",
                );
            }
            self.emit(Motion::Rapid, self.pos, 0.0, rotary_column)?;
        }
        self.stops(w);
        if let Some((letter, column)) = w.unused() {
            return fault(column, super::words::unused_message(letter, w));
        }
        Ok(())
    }

    /// Refuses what has no meaning on a robot or is not modelled, by name.
    fn refuse_unsupported(&self, w: &mut Words) -> Result<(), Fault> {
        for &(g, column) in &w.g {
            let why = match g {
                330 | 331 | 760 => "threading (G33, G33.1, G76) is not modelled",
                382..=385 => "probing (G38.2-G38.5) needs a probe; it is not modelled",
                410 | 411 | 420 | 421 => {
                    "cutter radius compensation (G41, G42) is not modelled: have the CAM \
                     system write the compensated tool path"
                }
                70 => "lathe diameter mode (G7) is a lathe's",
                700 | 710 | 711 | 712 | 720 | 721 | 722 => "lathe cycles (G70-G72) are a lathe's",
                960 => "constant surface speed (G96) is a lathe's",
                171 | 181 | 191 => "the UVW planes (G17.1, G18.1, G19.1) need UVW axes",
                52 | 53 => "NURBS (G5.2, G5.3) are not modelled",
                _ => continue,
            };
            return fault(column, std::format!("{}: {why}", g_name(g)));
        }
        for (letter, what) in [
            (b'a', "A"),
            (b'b', "B"),
            (b'c', "C"),
            (b'u', "U"),
            (b'v', "V"),
            (b'w', "W"),
        ] {
            // A rotary axis held at 0 (a post for a machine with a rotary table that this
            // program does not turn) moves nothing; one that turns is refused, but the
            // rotaries of the kinematics the program is read for.
            let declared = self.kinematics.is_some_and(|k| {
                let word = match letter {
                    b'a' => Some(RotaryWord::A),
                    b'b' => Some(RotaryWord::B),
                    b'c' => Some(RotaryWord::C),
                    _ => None,
                };
                word.is_some_and(|r| k.rotary(r).is_some())
            });
            let held =
                declared || matches!(letter, b'a' | b'b' | b'c') && w.peek(letter) == Some(0.0);
            if w.has(letter) && !held {
                return fault(
                    w.column(letter),
                    std::format!(
                        "{what}: rotary and secondary axes (A, B, C, U, V, W) are not modelled \
                         without a machine kinematics declaring them; a 3-axis program moves \
                         X, Y and Z (A, B, C may only stay at 0)"
                    ),
                );
            }
        }
        if w.has(b'$') {
            return fault(
                w.column(b'$'),
                "$ (spindle selection): the robot has one spindle",
            );
        }
        if let Some(&(m, column)) = w.m.iter().find(|m| (100..=199).contains(&m.0)) {
            return fault(
                column,
                std::format!(
                    "M{m}: user M codes (M100-M199) run programs of the controller; none is \
                     available"
                ),
            );
        }
        Ok(())
    }

    /// `M2`, `M30`: the program ends at this line.
    fn stops(&mut self, w: &Words) {
        if w.m(2).is_some() || w.m(30).is_some() {
            self.ended = Some(self.line);
        }
    }
}

impl Machine {
    /// The tool offset in effect is recorded only; whether one is set (`#<_tool_offset>`).
    pub(super) fn has_tool_offset(&self) -> bool {
        self.tool_offset != Vector3::zeros()
    }

    /// A description of the unit, for messages.
    pub(super) fn unit_name(&self) -> &'static str {
        if self.units == INCH { "in" } else { "mm" }
    }
}
