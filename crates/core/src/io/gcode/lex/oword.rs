//! An O-word statement: `O` and its label (`O100`, `O[expr]`, `O<name>`), its keyword (`sub`,
//! `call`, `if`, `while`, ...; none for a Fanuc-style program number) and the bracketed
//! values the keyword takes, alone on its line but for a comment.

use std::string::ToString;
use std::vec::Vec;

use super::{Keyword, Label, LexError, OWord, Parser};

impl Parser<'_> {
    /// The line's O-word statement (the `o` at the cursor), into [`super::Block::o_word`].
    pub(super) fn o_word(&mut self) -> Result<(), LexError> {
        let column = self.column();
        self.at += 1;
        let label = if self.peek() == Some(b'<') {
            self.at += 1;
            let (s, e) = self.name()?;
            Label::Name(s, e)
        } else {
            Label::Value(self.value()?)
        };
        let keyword = self.o_keyword()?;
        let args = self.o_args(keyword)?;
        if self.peek().is_some() {
            return self.err(std::format!(
                "nothing after the O-word '{}' but a comment, got {}",
                keyword.name(),
                self.got()
            ));
        }
        self.b.o_word = Some(OWord {
            label,
            keyword,
            args,
            column,
        });
        Ok(())
    }

    /// The keyword after the label: the run of letters there ([`Keyword::Header`] when
    /// there are none).
    fn o_keyword(&mut self) -> Result<Keyword, LexError> {
        let (from, word) = self.letters();
        Ok(match word.as_str() {
            "sub" => Keyword::Sub,
            "endsub" => Keyword::Endsub,
            "call" => Keyword::Call,
            "do" => Keyword::Do,
            "while" => Keyword::While,
            "repeat" => Keyword::Repeat,
            "if" => Keyword::If,
            "elseif" => Keyword::Elseif,
            "else" => Keyword::Else,
            "endif" => Keyword::Endif,
            "break" => Keyword::Break,
            "continue" => Keyword::Continue,
            "endwhile" => Keyword::Endwhile,
            "endrepeat" => Keyword::Endrepeat,
            "return" => Keyword::Return,
            "" => Keyword::Header,
            other => {
                return Err((
                    self.column_of(from),
                    std::format!(
                        "an O-word keyword (sub, endsub, call, return, if, elseif, else, \
                         endif, while, endwhile, do, repeat, endrepeat, break, continue), got \
                         {other:?}"
                    ),
                ));
            }
        })
    }

    /// The keyword's bracketed values (indices of their nodes): the condition of `if`,
    /// `elseif`, `while` and `repeat` (required), up to 30 arguments of `call`, the optional
    /// value of `endsub` and `return`.
    fn o_args(&mut self, keyword: Keyword) -> Result<Vec<u32>, LexError> {
        let mut args = Vec::new();
        match keyword {
            Keyword::If | Keyword::Elseif | Keyword::While | Keyword::Repeat => {
                if self.peek() != Some(b'[') {
                    return self.err(std::format!(
                        "a [condition] after '{}', got {}",
                        keyword.name(),
                        self.got()
                    ));
                }
                args.push(self.value()?);
            }
            Keyword::Call => {
                while self.peek() == Some(b'[') {
                    if args.len() >= 30 {
                        return self
                            .err("at most 30 arguments to a subroutine (#1-#30)".to_string());
                    }
                    args.push(self.value()?);
                }
            }
            Keyword::Endsub | Keyword::Return if self.peek() == Some(b'[') => {
                args.push(self.value()?);
            }
            _ => {}
        }
        Ok(args)
    }
}
