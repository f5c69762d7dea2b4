//! O-word control flow as LinuxCNC runs it: a false branch, a loop's exit and a subroutine's
//! definition are skipped up to the next O-word with the same label; `if`/`elseif`/`else`,
//! `while`, `do ... while`, `repeat`, `break`, `continue`; `call` with up to 30 arguments
//! (`#1`-`#30` saved and restored, named locals per call), `endsub`/`return` with a value;
//! Fanuc-style `M98 P L` / `M99`. Labels other than a subroutine's are local to the
//! subroutine they are in.

use std::string::{String, ToString};

use super::MAX_CALL_DEPTH;
use super::expr::{self, integer};
use super::fault::Fault;
use super::lex::{self, Keyword, Label};
use super::read::{Reader, at};
use super::stack::{Frame, Loop, Skip};
use crate::error::LoadError;

impl Reader<'_> {
    /// The label of the block's O-word: `<name>`, or a number's decimal form.
    fn label(&self) -> Result<String, Fault> {
        let Some(o) = self.block.o_word.as_ref() else {
            return Err((1, "an O-word".to_string()));
        };
        match o.label {
            Label::Name(s, e) => Ok(self.block.name(s, e).to_string()),
            Label::Value(n) => {
                let v = expr::eval(&self.block, n, self).map_err(|e| (o.column, e))?;
                integer(v)
                    .map(|v| v.to_string())
                    .ok_or_else(|| (o.column, std::format!("an integer O-word number, got O{v}")))
            }
        }
    }

    /// A control label scoped by the subroutine it is in.
    fn scoped(&self, label: &str) -> String {
        let sub = self.frames.last().map_or("", |f| f.name.as_str());
        std::format!("{sub}#{label}")
    }

    /// One line while skipping: returns where to go next when the line ends the skip.
    pub(super) fn skipping(&mut self, raw: &str, here: usize) -> Result<Option<usize>, LoadError> {
        let line = here + 1;
        if !lex::is_o_line(raw) {
            return Ok(None);
        }
        lex::lex(raw, self.options.dialect, &mut self.block).map_err(|e| at(line, e))?;
        let Some(keyword) = self.block.o_word.as_ref().map(|o| o.keyword) else {
            return Ok(None);
        };
        let label = self.label().map_err(|e| at(line, e))?;
        let Some(skip) = self.skip.clone() else {
            return Ok(None);
        };
        let name = if skip.definition {
            label.clone()
        } else {
            self.scoped(&label)
        };
        if skip.definition && keyword == Keyword::Sub && label != skip.label {
            return Err(at(
                line,
                (
                    self.block.o_word.as_ref().map_or(1, |o| o.column),
                    std::format!(
                        "o<{}> endsub before another subroutine's definition (no nested \
                         definitions), got o<{label}> sub",
                        skip.label
                    ),
                ),
            ));
        }
        if name != skip.label || skip.until.is_some_and(|k| k != keyword) {
            return Ok(None);
        }
        self.skip = None;
        if !skip.then_run {
            if skip.definition {
                // The definition's endsub sets _value as LinuxCNC reads it.
                self.m.value = 0.0;
                self.m.value_returned = false;
            }
            return Ok(Some(here + 1));
        }
        self.o_word(here, true).map(Some).map_err(|e| at(line, e))
    }

    fn skip_to(&mut self, label: String, until: Option<Keyword>, then_run: bool, from: usize) {
        self.skip = Some(Skip {
            label,
            until,
            then_run,
            definition: false,
            from,
        });
    }

    /// Runs the block's O-word (`by_skip`: reached from a false branch or a loop exit).
    /// Returns the index of the next line.
    pub(super) fn o_word(&mut self, here: usize, by_skip: bool) -> Result<usize, Fault> {
        let Some(o) = self.block.o_word.clone() else {
            return Ok(here + 1);
        };
        let label = self.label()?;
        match o.keyword {
            Keyword::Sub | Keyword::Endsub | Keyword::Return | Keyword::Call | Keyword::Header => {
                self.sub_word(&o, label, here)
            }
            Keyword::If | Keyword::Elseif | Keyword::Else | Keyword::Endif => {
                self.branch(&o, &label, here, by_skip)
            }
            Keyword::While => {
                let c = self.condition(&o)?;
                self.while_line(label, here, c)
            }
            Keyword::Break | Keyword::Continue => self.loop_exit(&o, &label, here),
            Keyword::Do | Keyword::Repeat | Keyword::Endwhile | Keyword::Endrepeat => {
                self.loop_word(&o, &label, here)
            }
        }
    }

    /// The value of an O-word's bracketed argument (0 without one).
    fn condition(&self, o: &lex::OWord) -> Result<f64, Fault> {
        match o.args.first() {
            Some(&n) => expr::eval(&self.block, n, self).map_err(|e| (o.column, e)),
            None => Ok(0.0),
        }
    }

    /// `sub` (its definition is skipped), `endsub`/`return` (back to the caller with a
    /// value), `call`, and a bare program number.
    fn sub_word(&mut self, o: &lex::OWord, label: String, here: usize) -> Result<usize, Fault> {
        match o.keyword {
            Keyword::Sub => {
                self.skip = Some(Skip {
                    label,
                    until: Some(Keyword::Endsub),
                    then_run: false,
                    definition: true,
                    from: here,
                });
                Ok(here + 1)
            }
            Keyword::Endsub | Keyword::Return => {
                if self.frames.last().is_none_or(|f| f.fanuc.is_some()) {
                    return Err((
                        o.column,
                        std::format!(
                            "o<{label}> {} inside a called subroutine (this one was not called)",
                            o.keyword.name()
                        ),
                    ));
                }
                self.m.value_returned = !o.args.is_empty();
                self.m.value = self.condition(o)?;
                Ok(self.leave())
            }
            Keyword::Call => self.call(o, label, here),
            _ => Ok(here + 1),
        }
    }

    /// `if`, `elseif`, `else`, `endif`: a false condition skips to the label's next O-word; a
    /// branch reached by running (not by a skip) means an earlier one ran: on to `endif`.
    fn branch(
        &mut self,
        o: &lex::OWord,
        label: &str,
        here: usize,
        by_skip: bool,
    ) -> Result<usize, Fault> {
        let scoped = self.scoped(label);
        let tested = o.keyword == Keyword::If || (o.keyword == Keyword::Elseif && by_skip);
        if tested {
            if self.condition(o)? == 0.0 {
                self.skip_to(scoped, None, true, here);
            }
        } else if matches!(o.keyword, Keyword::Elseif | Keyword::Else) && !by_skip {
            self.skip_to(scoped, Some(Keyword::Endif), false, here);
        }
        Ok(here + 1)
    }

    /// `do`, `repeat` (its count rounded half to even), `endwhile`, `endrepeat`.
    fn loop_word(&mut self, o: &lex::OWord, label: &str, here: usize) -> Result<usize, Fault> {
        let scoped = self.scoped(label);
        let next = here + 1;
        match o.keyword {
            Keyword::Do => {
                if self
                    .loops
                    .last()
                    .is_none_or(|l| l.label != scoped || l.line != here)
                {
                    self.loops.push(Loop {
                        label: scoped,
                        kind: Keyword::Do,
                        line: here,
                        remaining: 0,
                    });
                }
                Ok(next)
            }
            Keyword::Repeat => {
                let n = round_half_even(self.condition(o)?);
                if n <= 0 {
                    self.skip_to(scoped, Some(Keyword::Endrepeat), false, here);
                } else {
                    self.loops.push(Loop {
                        label: scoped,
                        kind: Keyword::Repeat,
                        line: here,
                        remaining: n,
                    });
                }
                Ok(next)
            }
            _ => {
                let kind = if o.keyword == Keyword::Endwhile {
                    Keyword::While
                } else {
                    Keyword::Repeat
                };
                let Some(k) = self
                    .loops
                    .iter()
                    .rposition(|l| l.label == scoped && l.kind == kind)
                else {
                    return Err((
                        o.column,
                        std::format!(
                            "o<{label}> {} before o<{label}> {}",
                            kind.name(),
                            o.keyword.name()
                        ),
                    ));
                };
                self.loops.truncate(k + 1);
                match self.loops.last_mut() {
                    // endwhile: back to the while line, which tests again.
                    Some(l) if kind == Keyword::While => Ok(l.line),
                    Some(l) if l.remaining > 1 => {
                        l.remaining -= 1;
                        Ok(l.line + 1)
                    }
                    _ => {
                        self.loops.pop();
                        Ok(next)
                    }
                }
            }
        }
    }

    /// `break` (past the loop's end) and `continue` (to its test); none in a `repeat`
    /// (LinuxCNC's rule).
    fn loop_exit(&mut self, o: &lex::OWord, label: &str, here: usize) -> Result<usize, Fault> {
        let scoped = self.scoped(label);
        let name = o.keyword.name();
        let Some(k) = self.loops.iter().rposition(|l| l.label == scoped) else {
            return Err((
                o.column,
                std::format!("o<{label}> {name} inside a while or do loop o<{label}>"),
            ));
        };
        let (kind, line) = self
            .loops
            .get(k)
            .map_or((Keyword::While, here), |l| (l.kind, l.line));
        if kind == Keyword::Repeat {
            return Err((
                o.column,
                std::format!(
                    "o<{label}> {name} inside a while or do loop (LinuxCNC has none in repeat)"
                ),
            ));
        }
        self.loops.truncate(k + 1);
        match (o.keyword, kind) {
            (Keyword::Continue, Keyword::While) => return Ok(line),
            (Keyword::Continue, _) => self.skip_to(scoped, Some(Keyword::While), true, here),
            (_, Keyword::While) => {
                self.loops.pop();
                self.skip_to(scoped, Some(Keyword::Endwhile), false, here);
            }
            _ => {
                self.loops.pop();
                self.skip_to(scoped, Some(Keyword::While), false, here);
            }
        }
        Ok(here + 1)
    }

    /// A `while` line: the head of a while loop, or the tail of a do loop.
    fn while_line(&mut self, label: String, here: usize, c: f64) -> Result<usize, Fault> {
        let scoped = self.scoped(&label);
        if let Some(top) = self.loops.last()
            && top.label == scoped
            && top.kind == Keyword::Do
        {
            let body = top.line + 1;
            if c != 0.0 {
                return Ok(body);
            }
            self.loops.pop();
            return Ok(here + 1);
        }
        if self
            .loops
            .last()
            .is_none_or(|l| l.label != scoped || l.line != here)
        {
            self.loops.push(Loop {
                label: scoped.clone(),
                kind: Keyword::While,
                line: here,
                remaining: 0,
            });
        }
        if c == 0.0 {
            self.loops.pop();
            self.skip_to(scoped, Some(Keyword::Endwhile), false, here);
        }
        Ok(here + 1)
    }

    fn call(&mut self, o: &lex::OWord, name: String, here: usize) -> Result<usize, Fault> {
        let Some(&sub) = self.subs.get(&name) else {
            return Err((
                o.column,
                std::format!(
                    "a subroutine o<{name}> defined in this program (o<{name}> sub ... o<{name}> \
                     endsub; subroutine files are not searched)"
                ),
            ));
        };
        if self.frames.len() >= MAX_CALL_DEPTH {
            return Err((
                o.column,
                std::format!("at most {MAX_CALL_DEPTH} nested subroutine calls (MAX_CALL_DEPTH)"),
            ));
        }
        let mut args = [0.0; 30];
        for (a, &n) in args.iter_mut().zip(&o.args) {
            *a = expr::eval(&self.block, n, self).map_err(|e| (o.column, e))?;
        }
        let saved = self.params.enter();
        for (k, a) in args.iter().enumerate() {
            self.params.set(k + 1, *a);
        }
        let loops = core::mem::take(&mut self.loops);
        self.frames.push(Frame {
            name,
            return_to: here + 1,
            saved: Some(saved),
            loops,
            fanuc: None,
            m73: None,
        });
        self.m.call_level = self.frames.len();
        Ok(sub + 1)
    }

    /// Returns from the innermost call: the caller's parameters, loops and line.
    fn leave(&mut self) -> usize {
        let Some(f) = self.frames.pop() else {
            return self.lines.len();
        };
        if f.fanuc.is_none() {
            self.params.leave(f.saved.as_ref());
        }
        if let Some(m) = f.m73 {
            self.m.restore(&m, &self.params);
        }
        self.loops = f.loops;
        self.m.call_level = self.frames.len();
        f.return_to
    }

    /// `M98 P<n> L<count>`: runs program number `O<n>` count times.
    pub(super) fn m98(
        &mut self,
        here: usize,
        target: String,
        repeats: u32,
    ) -> Result<usize, Fault> {
        if repeats == 0 {
            return Ok(here + 1);
        }
        let Some(&start) = self.headers.get(&target) else {
            return Err((
                self.words.column(b'p'),
                std::format!("a program number O{target} in this program for M98 P{target}"),
            ));
        };
        if self.frames.len() >= MAX_CALL_DEPTH {
            return Err((
                1,
                std::format!("at most {MAX_CALL_DEPTH} nested subroutine calls (MAX_CALL_DEPTH)"),
            ));
        }
        let loops = core::mem::take(&mut self.loops);
        self.frames.push(Frame {
            name: target,
            return_to: here + 1,
            saved: None,
            loops,
            fanuc: Some((start + 1, repeats - 1)),
            m73: None,
        });
        self.m.call_level = self.frames.len();
        Ok(start + 1)
    }

    /// `M99`: the next pass of an M98 call, its return, or the program's end at the top.
    pub(super) fn m99(&mut self) -> Option<usize> {
        match self.frames.last_mut() {
            Some(Frame {
                fanuc: Some((start, left)),
                ..
            }) if *left > 0 => {
                *left -= 1;
                Some(*start)
            }
            Some(Frame { fanuc: Some(_), .. }) => Some(self.leave()),
            _ => {
                self.m.ended = Some(self.m.line);
                None
            }
        }
    }
}

/// `repeat`'s count: rounded half to even (LinuxCNC's `nearbyint`).
fn round_half_even(v: f64) -> i64 {
    let r = v.round();
    let n = if (v - v.trunc()).abs() == 0.5 && r % 2.0 != 0.0 {
        r - v.signum()
    } else {
        r
    };
    n.clamp(-1.0e15, 1.0e15) as i64
}
