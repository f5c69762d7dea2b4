//! The reading loop: lines in order (or where the control flow sends it), each lexed, its
//! values evaluated with the parameters as they were before the line, its settings committed
//! (numbered, then named), its comment and its words run on the [`Machine`]; `%`, the
//! program end and the budgets of [`super`].

use std::collections::HashMap;
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use super::expr::{self, Scope, integer};
use super::interp::{INCH, Machine};
use super::lex::{self, Block, CommentKind, Item, Keyword, Label, Param};
use super::params::{MAX_PARAMETER, Params};
use super::stack::{Frame, Loop, Skip};
use super::words::Words;
use super::{GcodeOptions, MAX_BLOCKS, MAX_PROGRAM_LINES};
use crate::error::LoadError;
use crate::machining::{MAX_MOVES, Program};

/// The reader's state.
pub(super) struct Reader<'t> {
    pub lines: Vec<&'t str>,
    pub options: GcodeOptions,
    pub block: Block,
    pub words: Words,
    pub params: Params,
    pub m: Machine,
    /// Subroutines by name: the index of their `sub` line.
    pub subs: HashMap<String, usize>,
    /// Fanuc-style program numbers (`O100` alone): the index of their line.
    pub headers: HashMap<String, usize>,
    pub frames: Vec<Frame>,
    pub loops: Vec<Loop>,
    pub skip: Option<Skip>,
    /// Pending parameter settings of the line being run.
    numbered: Vec<(usize, f64)>,
    named: Vec<(String, f64)>,
}

/// A line's error as a [`LoadError`].
pub(super) fn at(line: usize, (column, message): (usize, String)) -> LoadError {
    if column == usize::MAX {
        return LoadError::TooLarge {
            what: std::format!("G-code program moves (at line {line})"),
            limit: MAX_MOVES,
            got: MAX_MOVES + 1,
        };
    }
    LoadError::Program {
        line,
        column,
        message,
    }
}

/// The tool's point before the first move \[m\]: finite, within
/// [`crate::machining::MAX_COORDINATE`].
pub(crate) fn check_start(start: &nalgebra::Vector3<f64>) -> Result<(), LoadError> {
    if start
        .iter()
        .all(|v| v.is_finite() && v.abs() <= crate::machining::MAX_COORDINATE)
    {
        return Ok(());
    }
    Err(LoadError::InvalidValue {
        element: "program options".to_string(),
        field: "start (m)",
        expected: std::format!("finite, within +-{} m", crate::machining::MAX_COORDINATE),
        got: std::format!("{:?}", start.as_slice()),
    })
}

/// Reads `text` (size checked by the caller).
pub(super) fn run(text: &str, options: &GcodeOptions) -> Result<Program, LoadError> {
    let start = options.start;
    check_start(&start)?;
    let mut r = Reader {
        lines: text.lines().collect(),
        options: *options,
        block: Block::default(),
        words: Words::default(),
        params: Params::new(),
        m: Machine::new(options.dialect, start, options.units.to_metre())
            .with_kinematics(options.kinematics),
        subs: HashMap::new(),
        headers: HashMap::new(),
        frames: Vec::new(),
        loops: Vec::new(),
        skip: None,
        numbered: Vec::new(),
        named: Vec::new(),
    };
    r.scan()?;
    r.main()?;
    Ok(Program {
        moves: r.m.moves,
        operations: r.m.operations,
    })
}

impl Scope for Reader<'_> {
    fn numbered(&self, index: f64) -> Result<f64, String> {
        let i = check_index(index)?;
        Ok(self.m.numbered(i, &self.params))
    }

    fn named(&self, name: &str) -> Result<f64, String> {
        if let Some(v) = self.m.predefined(name) {
            return Ok(v);
        }
        self.params
            .named(name)
            .ok_or_else(|| std::format!("#<{name}> set before it is read (it is not defined)"))
    }

    fn exists(&self, name: &str) -> bool {
        self.m.predefined(name).is_some() || self.params.named(name).is_some()
    }
}

/// A numbered parameter's index, 1..=5601.
fn check_index(index: f64) -> Result<usize, String> {
    match integer(index) {
        Some(i) if (1..=MAX_PARAMETER).contains(&i) => Ok(i as usize),
        _ => Err(std::format!(
            "a parameter number in 1..={MAX_PARAMETER} (an integer), got #{index}"
        )),
    }
}

impl Reader<'_> {
    /// Finds the subroutines and Fanuc program numbers (a call may come before its `sub`).
    fn scan(&mut self) -> Result<(), LoadError> {
        let mut block = Block::default();
        for (i, raw) in self.lines.iter().enumerate() {
            if !lex::is_o_line(raw) || lex::lex(raw, self.options.dialect, &mut block).is_err() {
                continue;
            }
            let Some(o) = block.o_word.as_ref() else {
                continue;
            };
            let name = match o.label {
                Label::Name(s, e) => block.name(s, e).to_string(),
                Label::Value(n) => match expr::eval(&block, n, self).ok().and_then(integer) {
                    Some(v) => v.to_string(),
                    None => continue,
                },
            };
            let table = match o.keyword {
                Keyword::Sub => &mut self.subs,
                Keyword::Header => &mut self.headers,
                _ => continue,
            };
            if table.contains_key(&name) && o.keyword == Keyword::Sub {
                return Err(LoadError::Program {
                    line: i + 1,
                    column: o.column,
                    message: std::format!(
                        "one definition of subroutine o<{name}>, got a second one"
                    ),
                });
            }
            table.entry(name).or_insert(i);
        }
        Ok(())
    }

    fn main(&mut self) -> Result<(), LoadError> {
        let first = self.lines.iter().position(|l| !l.trim().is_empty());
        let percent = first
            .and_then(|i| self.lines.get(i))
            .is_some_and(|l| l.trim() == "%");
        let mut pc = first.map_or(0, |i| i + usize::from(percent));
        let mut runs = 0usize;
        while let Some(&raw) = self.lines.get(pc) {
            runs += 1;
            let line = pc + 1;
            if runs > MAX_BLOCKS {
                return Err(LoadError::ProgramBudget {
                    line,
                    what: "lines run or skipped (a loop that does not end?)".into(),
                    budget: "MAX_BLOCKS",
                    limit: MAX_BLOCKS,
                });
            }
            self.m.line = line;
            let here = pc;
            pc += 1;
            let trimmed = raw.trim();
            if percent && trimmed == "%" {
                // The program's end, even inside a block being skipped (an error below).
                break;
            }
            if self.skip.is_some() {
                if let Some(next) = self.skipping(raw, here)? {
                    pc = next;
                }
                continue;
            }
            if trimmed.starts_with('%') {
                if self.options.dialect.percent_anywhere() {
                    continue;
                }
                return Err(at(
                    line,
                    (
                        raw.find('%').map_or(1, |c| c + 1),
                        "'%' alone on the first line and on the line that ends the program \
                         (LinuxCNC; the fanuc and grbl dialects read '%' lines anywhere)"
                            .to_string(),
                    ),
                ));
            }
            if trimmed.starts_with(";py,") {
                continue;
            }
            lex::lex(raw, self.options.dialect, &mut self.block).map_err(|e| at(line, e))?;
            if self.block.delete && self.options.block_delete {
                continue;
            }
            if self.block.o_word.is_some() {
                pc = self.o_word(here, false).map_err(|e| at(line, e))?;
                continue;
            }
            if let Some(next) = self.run_block(here).map_err(|e| at(line, e))? {
                pc = next;
            }
            if self.m.ended.is_some() {
                break;
            }
        }
        if let Some(s) = &self.skip
            && !s.resume_after_definition_end()
        {
            return Err(LoadError::Program {
                line: s.from + 1,
                column: 1,
                message: std::format!(
                    "o<{}> {} to close this block before the end of the file",
                    s.label_text(),
                    s.until.map_or("its next O-word", Keyword::name)
                ),
            });
        }
        Ok(())
    }

    /// Evaluates a line's values, commits its settings, runs its comment and its words.
    /// Returns where to go next when the line calls or returns (M98, M99).
    fn run_block(&mut self, here: usize) -> Result<Option<usize>, (usize, String)> {
        self.words.clear();
        self.numbered.clear();
        self.named.clear();
        for k in 0..self.block.items.len() {
            if let Some(item) = self.block.items.get(k).copied() {
                self.evaluate(item)?;
            }
        }
        for &(i, v) in &self.numbered {
            self.params.set(i, v);
        }
        for (name, v) in self.named.drain(..) {
            self.params.set_named(&name, v).map_err(|e| (1, e))?;
        }
        if let Some(c) = &self.block.comment
            && c.kind == CommentKind::Abort
        {
            return Err((
                c.column,
                std::format!(
                    "a program that does not abort, got (ABORT,{})",
                    c.text.trim()
                ),
            ));
        }
        if let Some(c) = &self.block.comment
            && c.kind == CommentKind::Plain
            && self.block.items.is_empty()
            && self.block.o_word.is_none()
        {
            self.m.note_comment(&c.text);
        }
        let call = self.fanuc_call()?;
        self.m.execute(&mut self.words, &mut self.params)?;
        if self.words.m(73).is_some()
            && let Some(f) = self.frames.last_mut()
        {
            f.m73 = self.m.saved;
        }
        match call {
            Some(FanucCall::Call { target, repeats }) => Ok(Some(self.m98(here, target, repeats)?)),
            Some(FanucCall::Return) => Ok(self.m99()),
            None => Ok(None),
        }
    }
}

impl Reader<'_> {
    /// One word or setting of the line, with the parameters as they were before the line: a
    /// word's value into the words, a setting's into the pending settings.
    fn evaluate(&mut self, item: Item) -> Result<(), (usize, String)> {
        match item {
            Item::Word {
                letter,
                value,
                column,
            } => {
                let v = expr::eval(&self.block, value, self).map_err(|e| (column, e))?;
                match letter {
                    b'g' => {
                        let code = g_code(v, self.options.dialect).map_err(|e| (column, e))?;
                        self.words.g.push((code, column));
                    }
                    b'm' => {
                        let code = m_code(v).map_err(|e| (column, e))?;
                        self.words.m.push((code, column));
                    }
                    _ => self.words.set(letter, v, column),
                }
            }
            Item::Set {
                target: Param::Named(s, e),
                value,
                column,
            } => {
                let name = self.block.name(s, e).to_string();
                if self.m.predefined(&name).is_some() {
                    return Err((
                        column,
                        std::format!("a parameter that may be set, got #<{name}> (read-only)"),
                    ));
                }
                // LinuxCNC: the name exists (as 0) from its `=` on.
                if self.params.named(&name).is_none() {
                    self.params.set_named(&name, 0.0).map_err(|e| (column, e))?;
                }
                let v = expr::eval(&self.block, value, self).map_err(|e| (column, e))?;
                self.named.push((name, v));
            }
            Item::Set {
                target: Param::Numbered(i),
                value,
                column,
            } => {
                let i = expr::eval(&self.block, i, self)
                    .and_then(check_index)
                    .map_err(|e| (column, e))?;
                if (5400..=5413).contains(&i) || (5420..=5428).contains(&i) {
                    return Err((
                        column,
                        std::format!(
                            "a parameter that may be set, got #{i} (read-only: the tool and the \
                             position)"
                        ),
                    ));
                }
                let v = expr::eval(&self.block, value, self).map_err(|e| (column, e))?;
                self.numbered.push((i, v));
            }
        }
        Ok(())
    }
}

/// A G code's value as ten times its number (G91.1 -> 911): within 0.001 of a tenth,
/// 0..=99.9, one LinuxCNC knows.
fn g_code(v: f64, dialect: super::Dialect) -> Result<u16, String> {
    let tenth = (v * 10.0).round();
    // Haas's smoothness (G187) and look-ahead (G103) settings: no motion.
    if dialect.haas_settings() && (tenth == 1870.0 || tenth == 1030.0) {
        return Ok(tenth as u16);
    }
    if v < 0.0 || (v * 10.0 - tenth).abs() > 1.0e-3 || tenth > 999.0 {
        return Err(std::format!(
            "a G code (a number 0-99.9 with at most one decimal), got G{v}"
        ));
    }
    let code = tenth as u16;
    if super::words_group(code).is_none() {
        return Err(std::format!(
            "a G code LinuxCNC knows, got {}",
            super::words::g_name(code)
        ));
    }
    Ok(code)
}

/// An M code's value: an integer within 0.0001, 0..=199, one LinuxCNC knows.
fn m_code(v: f64) -> Result<u16, String> {
    match integer(v) {
        Some(m) if (0..=199).contains(&m) && super::m_group(m as u16).is_some() => Ok(m as u16),
        _ => Err(std::format!("an M code LinuxCNC knows (M0-M199), got M{v}")),
    }
}

/// An M98 call or an M99 return on the line.
enum FanucCall {
    Call { target: String, repeats: u32 },
    Return,
}

impl Reader<'_> {
    /// Takes M98's P and L (or notes M99) before the block runs.
    fn fanuc_call(&mut self) -> Result<Option<FanucCall>, (usize, String)> {
        if let Some(column) = self.words.m(98) {
            let Some(p) = self.words.take(b'p').and_then(integer) else {
                return Err((
                    column,
                    "P, the program number O to call, with M98".to_string(),
                ));
            };
            let repeats = match self.words.take(b'l') {
                None => 1,
                Some(l) => match integer(l) {
                    Some(l) if (0..=100_000).contains(&l) => l as u32,
                    _ => {
                        return Err((
                            self.words.column(b'l'),
                            std::format!("repeats L in 0..=100000 with M98, got L{l}"),
                        ));
                    }
                },
            };
            return Ok(Some(FanucCall::Call {
                target: p.to_string(),
                repeats,
            }));
        }
        if self.words.m(99).is_some() {
            return Ok(Some(FanucCall::Return));
        }
        Ok(None)
    }
}

impl Machine {
    /// A numbered parameter's value: the live tool and position ones from the machine.
    pub(super) fn numbered(&self, i: usize, params: &Params) -> f64 {
        let p = |k: usize| self.pos.get(k).copied().unwrap_or(0.0) / self.units;
        match i {
            5400 => f64::from(self.tool),
            5401..=5409 => self.tool_offset.get(i - 5401).copied().unwrap_or(0.0) * 1e3,
            5410..=5413 => 0.0,
            5420..=5422 => p(i - 5420),
            5423..=5428 => 0.0,
            _ => params.get(i),
        }
    }

    /// The predefined read-only named parameters (`#<_x>`, `#<_metric>`, ...), by name.
    pub(super) fn predefined(&self, name: &str) -> Option<f64> {
        let b = |t: bool| f64::from(u8::from(t));
        let p = |k: usize| self.pos.get(k).copied().unwrap_or(0.0) / self.units;
        let abs = |k: usize| self.to_machine(&self.pos).get(k).copied().unwrap_or(0.0) / self.units;
        let systems = [
            540.0, 550.0, 560.0, 570.0, 580.0, 590.0, 591.0, 592.0, 593.0,
        ];
        Some(match name {
            "_vmajor" => 2.9,
            "_vminor" => 0.0,
            "_metric_machine" => 1.0,
            "_line" => self.line as f64,
            "_motion_mode" => self.motion.map_or(800.0, f64::from),
            "_plane" => match self.plane {
                crate::machining::Plane::Xy => 170.0,
                crate::machining::Plane::Zx => 180.0,
                crate::machining::Plane::Yz => 190.0,
            },
            "_ccomp" => 400.0,
            "_metric" => b(self.units != INCH),
            "_imperial" => b(self.units == INCH),
            "_absolute" => b(self.absolute),
            "_incremental" => b(!self.absolute),
            "_inverse_time" => b(self.feed_mode == super::interp::FeedMode::InverseTime),
            "_units_per_minute" => b(self.feed_mode == super::interp::FeedMode::PerMinute),
            "_units_per_rev" => b(self.feed_mode == super::interp::FeedMode::PerRevolution),
            "_coord_system" => systems
                .get(self.system.saturating_sub(1))
                .copied()
                .unwrap_or(540.0),
            "_tool_offset" => b(self.has_tool_offset()),
            "_retract_r_plane" => b(!self.retract_old_z),
            "_retract_old_z" => b(self.retract_old_z),
            "_spindle_rpm_mode" => 1.0,
            "_spindle_css_mode" => 0.0,
            "_ijk_absolute_mode" => b(self.ijk_absolute),
            "_lathe_diameter_mode" => 0.0,
            "_lathe_radius_mode" => 1.0,
            "_spindle_on" => b(self.spindle_dir != 0),
            "_spindle_cw" => b(self.spindle_dir > 0),
            "_mist" => b(self.mist),
            "_flood" => b(self.flood),
            "_speed_override" => b(self.speed_override),
            "_feed_override" => b(self.feed_override),
            "_adaptive_feed" => 0.0,
            "_feed_hold" => 1.0,
            "_feed" => self.feed,
            "_rpm" => self.spindle_rpm,
            "_current_tool" => f64::from(self.tool),
            "_current_pocket" => f64::from(self.tool),
            "_selected_tool" => f64::from(self.selected),
            "_selected_pocket" => f64::from(self.selected),
            "_x" => p(0),
            "_y" => p(1),
            "_z" => p(2),
            "_a" | "_b" | "_c" | "_u" | "_v" | "_w" => 0.0,
            "_abs_x" => abs(0),
            "_abs_y" => abs(1),
            "_abs_z" => abs(2),
            "_abs_a" | "_abs_b" | "_abs_c" => 0.0,
            "_value" => self.value,
            "_value_returned" => b(self.value_returned),
            "_task" => 0.0,
            "_call_level" => self.call_level as f64,
            "_remap_level" => 0.0,
            _ => return None,
        })
    }
}

/// Reads a G-code file (at most [`crate::io::MAX_FILE_BYTES`]; bytes that are not UTF-8 become
/// U+FFFD, [`crate::io::read_text_lossy`]).
pub fn from_path(path: &Path, options: &GcodeOptions) -> Result<Program, LoadError> {
    let text = crate::io::read_text_lossy(path)?;
    from_str(&text, options)
}

/// Reads a G-code program from its text.
pub fn from_str(text: &str, options: &GcodeOptions) -> Result<Program, LoadError> {
    crate::io::check_size("G-code program", text)?;
    let lines = text.lines().count();
    if lines > MAX_PROGRAM_LINES {
        return Err(LoadError::TooLarge {
            what: "G-code program lines".into(),
            limit: MAX_PROGRAM_LINES,
            got: lines,
        });
    }
    run(text, options)
}
