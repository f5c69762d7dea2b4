//! One line of RS274/NGC read into a [`Block`]: LinuxCNC's lexical rules (its
//! `interp_read.cc`, described in the module docs of [`super`]): spaces, tabs and CR dropped
//! and letters lower-cased outside comments, `(...)` and `;` comments (only the last paren
//! comment of a line counts), an optional `/` and `N` number, then either one O-word
//! statement or words and parameter settings whose values are numbers, `[expressions]`,
//! `#parameters` or functions. Values are parsed into an arena of [`Node`]s and evaluated
//! when the block runs (a loop runs a line many times; it is lexed each time it runs).

use std::string::{String, ToString};
use std::vec::Vec;

use super::Dialect;

mod oword;
mod value;

/// Deepest nesting of brackets, functions and unary signs in one value: 128 (LinuxCNC's
/// 253-byte lines allow about 120). Past it the line is refused, so evaluation recursion is
/// bounded.
pub const MAX_EXPRESSION_DEPTH: usize = 128;

/// A binary operator, by LinuxCNC's precedence (all left-associative).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Op {
    Pow,
    Mul,
    Div,
    Mod,
    Add,
    Sub,
    Eq,
    Ne,
    Gt,
    Ge,
    Lt,
    Le,
    And,
    Or,
    Xor,
}

impl Op {
    fn precedence(self) -> u8 {
        match self {
            Self::Pow => 6,
            Self::Mul | Self::Div | Self::Mod => 5,
            Self::Add | Self::Sub => 4,
            Self::Eq | Self::Ne | Self::Gt | Self::Ge | Self::Lt | Self::Le => 3,
            Self::And | Self::Or | Self::Xor => 2,
        }
    }
}

/// A one-argument function (angles in degrees).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Func {
    Abs,
    Acos,
    Asin,
    Cos,
    Exp,
    Fix,
    Fup,
    Round,
    Ln,
    Sin,
    Sqrt,
    Tan,
}

/// A parameter: numbered (its index is a value) or named (a range of [`Block::names`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Param {
    Numbered(u32),
    Named(u32, u32),
}

/// A node of a value's expression tree; children are indices into [`Block::nodes`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Node {
    Num(f64),
    Param(Param),
    Neg(u32),
    Bin(Op, u32, u32),
    Func(Func, u32),
    Atan(u32, u32),
    Exists(Param),
}

/// A word or a parameter setting, in the line's order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Item {
    /// A letter (lower case, or `@` `^` `$`) and its value.
    Word {
        letter: u8,
        value: u32,
        column: usize,
    },
    /// `#... = value`.
    Set {
        target: Param,
        value: u32,
        column: usize,
    },
}

/// An O-word's label.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Label {
    /// `O100`, `O[50*2]`, `O#5`: a value, named `<100>` when run.
    Value(u32),
    /// `O<name>` (lower case, no spaces).
    Name(u32, u32),
}

/// An O-word's keyword.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Keyword {
    Sub,
    Endsub,
    Call,
    Do,
    While,
    Repeat,
    If,
    Elseif,
    Else,
    Endif,
    Break,
    Continue,
    Endwhile,
    Endrepeat,
    Return,
    /// A bare `O100`: a Fanuc-style program number.
    Header,
}

impl Keyword {
    /// The keyword as written.
    pub(super) fn name(self) -> &'static str {
        match self {
            Self::Sub => "sub",
            Self::Endsub => "endsub",
            Self::Call => "call",
            Self::Do => "do",
            Self::While => "while",
            Self::Repeat => "repeat",
            Self::If => "if",
            Self::Elseif => "elseif",
            Self::Else => "else",
            Self::Endif => "endif",
            Self::Break => "break",
            Self::Continue => "continue",
            Self::Endwhile => "endwhile",
            Self::Endrepeat => "endrepeat",
            Self::Return => "return",
            Self::Header => "(program number)",
        }
    }
}

/// An O-word statement: label, keyword, its bracketed arguments (values) and column.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct OWord {
    pub label: Label,
    pub keyword: Keyword,
    pub args: Vec<u32>,
    pub column: usize,
}

/// What a paren comment asks for (`(MSG,...)`, `(DEBUG,...)`, ...); plain comments are
/// kept for the word report only.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum CommentKind {
    Plain,
    Msg,
    Debug,
    Print,
    Log,
    /// `(ABORT,...)`: the program stops with its text as the error.
    Abort,
}

/// The last paren comment of a line.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Comment {
    pub kind: CommentKind,
    /// Its text after the keyword's comma, case kept.
    pub text: String,
    pub column: usize,
}

/// One line, lexed.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct Block {
    /// The line starts with `/` (block delete).
    pub delete: bool,
    pub nodes: Vec<Node>,
    pub names: String,
    pub items: Vec<Item>,
    pub o_word: Option<OWord>,
    pub comment: Option<Comment>,
    /// The normalised text (lower case, no spaces, comments out) and each byte's column.
    text: Vec<u8>,
    cols: Vec<usize>,
    /// Column one past the line's end.
    end_column: usize,
}

/// A lexical error: column and message.
pub(super) type LexError = (usize, String);

impl Block {
    /// Empties the block, keeping its buffers.
    pub(super) fn clear(&mut self) {
        self.delete = false;
        self.nodes.clear();
        self.names.clear();
        self.items.clear();
        self.o_word = None;
        self.comment = None;
        self.text.clear();
        self.cols.clear();
        self.end_column = 1;
    }

    /// A named parameter's or label's name.
    pub(super) fn name(&self, start: u32, end: u32) -> &str {
        self.names.get(start as usize..end as usize).unwrap_or("")
    }

    /// The words' letters with their columns (for the word report).
    pub(super) fn words(&self) -> impl Iterator<Item = (u8, u32, usize)> + '_ {
        self.items.iter().filter_map(|i| match *i {
            Item::Word {
                letter,
                value,
                column,
            } => Some((letter, value, column)),
            Item::Set { .. } => None,
        })
    }
}

/// Lexes `raw` into `block` (cleared first). A line is read whole: its errors come before
/// any of it runs, as in LinuxCNC.
pub(super) fn lex(raw: &str, dialect: Dialect, block: &mut Block) -> Result<(), LexError> {
    block.clear();
    normalise(raw, dialect, block)?;
    let mut p = Parser {
        b: block,
        at: 0,
        depth: 0,
    };
    p.line()
}

/// Whether a raw line is an O-word line (after an optional `/` and `N` number), read without
/// lexing it: what the reader checks while it skips lines.
pub(super) fn is_o_line(raw: &str) -> bool {
    let mut bytes = raw
        .bytes()
        .filter(|b| !matches!(b, b' ' | b'\t' | b'\r'))
        .peekable();
    if bytes.peek() == Some(&b'/') {
        bytes.next();
    }
    if matches!(bytes.peek(), Some(b'n' | b'N')) {
        bytes.next();
        while matches!(bytes.peek(), Some(b) if b.is_ascii_digit() || *b == b'.') {
            bytes.next();
        }
    }
    matches!(bytes.peek(), Some(b'o' | b'O'))
}

/// Drops spaces, tabs and CR outside comments, lower-cases, takes out the comments (the last
/// paren comment kept) and stops at `;`.
fn normalise(raw: &str, dialect: Dialect, b: &mut Block) -> Result<(), LexError> {
    let bytes = raw.as_bytes();
    b.end_column = bytes.len() + 1;
    let mut i = 0;
    while let Some(&c) = bytes.get(i) {
        let column = i + 1;
        match c {
            0 => break,
            b' ' | b'\t' | b'\r' => i += 1,
            b';' => break,
            b'(' => {
                let close = comment_end(bytes, i, dialect)?;
                let inner = raw.get(i + 1..close).unwrap_or("");
                b.comment = Some(classify_comment(inner, column));
                i = close + 1;
            }
            _ => {
                b.text.push(c.to_ascii_lowercase());
                b.cols.push(column);
                i += 1;
            }
        }
    }
    Ok(())
}

/// The index of the `)` closing the comment opened at `open`. LinuxCNC refuses a `(` inside
/// a comment; the Fanuc dialect nests them.
fn comment_end(bytes: &[u8], open: usize, dialect: Dialect) -> Result<usize, LexError> {
    let mut depth = 0usize;
    for (k, &c) in bytes.iter().enumerate().skip(open) {
        match c {
            b'(' if depth > 0 && !dialect.nested_comments() => {
                return Err((
                    k + 1,
                    "no '(' inside a comment (nested comments are refused by LinuxCNC; the \
                     fanuc dialect reads them)"
                        .to_string(),
                ));
            }
            b'(' => depth += 1,
            b')' => {
                depth -= 1;
                if depth == 0 {
                    return Ok(k);
                }
            }
            0 => break,
            _ => {}
        }
    }
    Err((open + 1, "a ')' closing this comment".to_string()))
}

fn classify_comment(inner: &str, column: usize) -> Comment {
    let trimmed = inner.trim_start();
    for (key, kind) in [
        ("msg,", CommentKind::Msg),
        ("debug,", CommentKind::Debug),
        ("print,", CommentKind::Print),
        ("log,", CommentKind::Log),
        ("abort,", CommentKind::Abort),
    ] {
        if let Some(head) = trimmed.get(..key.len())
            && head.eq_ignore_ascii_case(key)
        {
            return Comment {
                kind,
                text: trimmed.get(key.len()..).unwrap_or("").to_string(),
                column,
            };
        }
    }
    Comment {
        kind: CommentKind::Plain,
        text: trimmed.to_string(),
        column,
    }
}

/// What may start a value, for messages.
const VALUE: &str = "a number, a [bracketed expression], a #parameter or a function";

struct Parser<'a> {
    b: &'a mut Block,
    at: usize,
    depth: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<u8> {
        self.b.text.get(self.at).copied()
    }

    fn peek_at(&self, k: usize) -> Option<u8> {
        self.b.text.get(self.at + k).copied()
    }

    fn column(&self) -> usize {
        self.b
            .cols
            .get(self.at)
            .copied()
            .unwrap_or(self.b.end_column)
    }

    fn column_of(&self, at: usize) -> usize {
        self.b.cols.get(at).copied().unwrap_or(self.b.end_column)
    }

    fn err<T>(&self, message: String) -> Result<T, LexError> {
        Err((self.column(), message))
    }

    /// What follows, for messages: up to 12 bytes of the normalised text.
    fn got(&self) -> String {
        match self.b.text.get(self.at..) {
            Some(rest) if !rest.is_empty() => {
                let s: String = rest.iter().take(12).map(|&c| char::from(c)).collect();
                std::format!("{s:?}")
            }
            _ => "the end of the line".to_string(),
        }
    }

    fn push(&mut self, n: Node) -> u32 {
        self.b.nodes.push(n);
        (self.b.nodes.len() - 1) as u32
    }

    /// The normalised line: an optional `/` (block delete) and line number, then one O-word
    /// statement or the words and parameter settings, in order.
    fn line(&mut self) -> Result<(), LexError> {
        if self.peek() == Some(b'/') {
            self.b.delete = true;
            self.at += 1;
        }
        self.line_number()?;
        if self.peek() == Some(b'o') {
            return self.o_word();
        }
        while let Some(c) = self.peek() {
            let column = self.column();
            match c {
                b'#' => self.setting(column)?,
                b'a'..=b'z' | b'@' | b'^' | b'$' if c != b'n' && c != b'o' => {
                    self.at += 1;
                    if c != b'g'
                        && c != b'm'
                        && let Some(prev) = self.b.words().find(|w| w.0 == c).map(|w| w.2)
                    {
                        return Err((
                            column,
                            std::format!(
                                "one {} word per line (also at column {prev})",
                                char::from(c.to_ascii_uppercase())
                            ),
                        ));
                    }
                    let value = self.value()?;
                    self.b.items.push(Item::Word {
                        letter: c,
                        value,
                        column,
                    });
                }
                b'n' => {
                    return self.err("N (a line number) only at the start of the line".to_string());
                }
                b'o' => {
                    return self.err("an O-word only at the start of the line, alone".to_string());
                }
                _ => {
                    return self.err(std::format!(
                        "a word (a letter and a value), a #parameter setting or a comment, \
                         got {}",
                        self.got()
                    ));
                }
            }
        }
        Ok(())
    }

    /// An optional `N` line number at the start: digits, then an optional `.` and digits.
    fn line_number(&mut self) -> Result<(), LexError> {
        if self.peek() == Some(b'n') {
            self.at += 1;
            let from = self.at;
            while matches!(self.peek(), Some(c) if c.is_ascii_digit()) {
                self.at += 1;
            }
            if self.at == from {
                return self.err(std::format!(
                    "digits after N (a line number), got {}",
                    self.got()
                ));
            }
            if self.peek() == Some(b'.') {
                self.at += 1;
                let frac = self.at;
                while matches!(self.peek(), Some(c) if c.is_ascii_digit()) {
                    self.at += 1;
                }
                if self.at == frac {
                    return self.err("digits after the '.' of a line number".to_string());
                }
            }
        }
        Ok(())
    }

    /// A parameter setting `#n=value` (the `#` at the cursor), at `column`.
    fn setting(&mut self, column: usize) -> Result<(), LexError> {
        self.at += 1;
        let target = self.param()?;
        if self.peek() != Some(b'=') {
            return self.err(std::format!(
                "'=' after the parameter (a parameter setting #n=value), got {}",
                self.got()
            ));
        }
        self.at += 1;
        let value = self.value()?;
        self.b.items.push(Item::Set {
            target,
            value,
            column,
        });
        Ok(())
    }

    /// The run of letters from here (a keyword, a function's name) and where it starts.
    fn letters(&mut self) -> (usize, String) {
        let from = self.at;
        while matches!(self.peek(), Some(b'a'..=b'z')) {
            self.at += 1;
        }
        let run = self.b.text.get(from..self.at).unwrap_or(&[]);
        (from, run.iter().map(|&c| char::from(c)).collect())
    }

    /// A name up to `>` (the `<` consumed); lower case, no spaces (normalised).
    fn name(&mut self) -> Result<(u32, u32), LexError> {
        let from = self.at;
        while let Some(c) = self.peek() {
            if c == b'>' {
                let start = self.b.names.len() as u32;
                for &c in self.b.text.get(from..self.at).unwrap_or(&[]) {
                    self.b.names.push(char::from(c));
                }
                self.at += 1;
                return Ok((start, self.b.names.len() as u32));
            }
            self.at += 1;
        }
        Err((
            self.column_of(from.saturating_sub(1)),
            "a '>' closing the name <...>".to_string(),
        ))
    }

    /// A parameter after its `#`: `<name>` or a value (its index).
    fn param(&mut self) -> Result<Param, LexError> {
        if self.peek() == Some(b'<') {
            self.at += 1;
            let (s, e) = self.name()?;
            return Ok(Param::Named(s, e));
        }
        Ok(Param::Numbered(self.value()?))
    }
}
