//! The values of a line: numbers, `[expressions]` by LinuxCNC's precedence (all operators
//! left-associative), `#parameters` and functions, parsed into the block's [`Node`]s, their
//! nesting bounded by [`MAX_EXPRESSION_DEPTH`].

use std::string::String;

use super::{Func, LexError, MAX_EXPRESSION_DEPTH, Node, Op, Parser, VALUE};

impl Parser<'_> {
    fn enter(&mut self) -> Result<(), LexError> {
        self.depth += 1;
        if self.depth > MAX_EXPRESSION_DEPTH {
            return self.err(std::format!(
                "at most {MAX_EXPRESSION_DEPTH} nested brackets, functions and signs in one \
                 value (MAX_EXPRESSION_DEPTH)"
            ));
        }
        Ok(())
    }

    /// A real value: a number, `[expression]`, `#parameter`, a function, or a sign before one.
    pub(super) fn value(&mut self) -> Result<u32, LexError> {
        self.enter()?;
        let v = self.value_inner();
        self.depth -= 1;
        v
    }

    fn value_inner(&mut self) -> Result<u32, LexError> {
        match self.peek() {
            Some(b'[') => {
                self.at += 1;
                let e = self.binary(0)?;
                if self.peek() != Some(b']') {
                    return self.err(std::format!(
                        "']' closing the expression, got {}",
                        self.got()
                    ));
                }
                self.at += 1;
                Ok(e)
            }
            Some(b'#') => {
                self.at += 1;
                let p = self.param()?;
                Ok(self.push(Node::Param(p)))
            }
            Some(b'a'..=b'z') => self.function(),
            Some(s @ (b'+' | b'-')) if !matches!(self.peek_at(1), Some(c) if c.is_ascii_digit() || c == b'.') =>
            {
                self.at += 1;
                let v = self.value()?;
                Ok(if s == b'-' {
                    self.push(Node::Neg(v))
                } else {
                    v
                })
            }
            Some(c) if c.is_ascii_digit() || matches!(c, b'.' | b'+' | b'-') => self.number(),
            _ => self.err(std::format!("{VALUE}, got {}", self.got())),
        }
    }

    /// A literal: an optional sign, then digits with at most one '.' (no exponent).
    fn number(&mut self) -> Result<u32, LexError> {
        let from = self.at;
        if matches!(self.peek(), Some(b'+' | b'-')) {
            self.at += 1;
        }
        let digits = self.at;
        while matches!(self.peek(), Some(c) if c.is_ascii_digit() || c == b'.') {
            self.at += 1;
        }
        let run = self.b.text.get(digits..self.at).unwrap_or(&[]);
        let text: String = self
            .b
            .text
            .get(from..self.at)
            .unwrap_or(&[])
            .iter()
            .map(|&c| char::from(c))
            .collect();
        let ok =
            run.iter().any(u8::is_ascii_digit) && run.iter().filter(|&&c| c == b'.').count() <= 1;
        match text.parse::<f64>() {
            Ok(v) if ok && v.is_finite() => Ok(self.push(Node::Num(v))),
            _ => Err((
                self.column_of(from),
                std::format!("a number (digits with at most one '.'), got {text:?}"),
            )),
        }
    }

    /// A function: its name, then `[argument]` (`ATAN[y]/[x]`, `EXISTS[#param]`).
    fn function(&mut self) -> Result<u32, LexError> {
        let column = self.column();
        let (from, name) = self.letters();
        let func = match name.as_str() {
            "abs" => Some(Func::Abs),
            "acos" => Some(Func::Acos),
            "asin" => Some(Func::Asin),
            "cos" => Some(Func::Cos),
            "exp" => Some(Func::Exp),
            "fix" => Some(Func::Fix),
            "fup" => Some(Func::Fup),
            "round" => Some(Func::Round),
            "ln" => Some(Func::Ln),
            "sin" => Some(Func::Sin),
            "sqrt" => Some(Func::Sqrt),
            "tan" => Some(Func::Tan),
            "atan" | "exists" => None,
            _ => {
                self.at = from;
                return Err((
                    column,
                    std::format!(
                        "{VALUE} (ABS, ACOS, ASIN, ATAN, COS, EXISTS, EXP, FIX, FUP, LN, ROUND, \
                         SIN, SQRT, TAN), got {}",
                        self.got()
                    ),
                ));
            }
        };
        if self.peek() != Some(b'[') {
            return self.err(std::format!(
                "'[' after the function {}, got {}",
                name.to_ascii_uppercase(),
                self.got()
            ));
        }
        if name == "exists" {
            self.at += 1;
            if self.peek() != Some(b'#') {
                return self.err(std::format!(
                    "a #parameter in EXISTS[...], got {}",
                    self.got()
                ));
            }
            self.at += 1;
            let p = self.param()?;
            if self.peek() != Some(b']') {
                return self.err(std::format!("']' closing EXISTS[#...], got {}", self.got()));
            }
            self.at += 1;
            return Ok(self.push(Node::Exists(p)));
        }
        let arg = self.value()?;
        match func {
            Some(f) => Ok(self.push(Node::Func(f, arg))),
            None => {
                if self.peek() != Some(b'/') {
                    return self.err(std::format!(
                        "'/' after ATAN's first argument (ATAN[y]/[x]), got {}",
                        self.got()
                    ));
                }
                self.at += 1;
                if self.peek() != Some(b'[') {
                    return self.err(std::format!(
                        "'[' for ATAN's second argument (ATAN[y]/[x]), got {}",
                        self.got()
                    ));
                }
                let x = self.value()?;
                Ok(self.push(Node::Atan(arg, x)))
            }
        }
    }

    /// An operator, if one follows (`**`, `*`, `/`, `+`, `-`, `MOD`, `EQ`, `NE`, `GT`, `GE`,
    /// `LT`, `LE`, `AND`, `OR`, `XOR`), and its length.
    fn operator(&self) -> Result<Option<(Op, usize)>, LexError> {
        let rest = self.b.text.get(self.at..).unwrap_or(&[]);
        let starts = |s: &[u8]| rest.starts_with(s);
        let op = match rest.first() {
            None | Some(b']') => return Ok(None),
            Some(b'*') if starts(b"**") => (Op::Pow, 2),
            Some(b'*') => (Op::Mul, 1),
            Some(b'/') => (Op::Div, 1),
            Some(b'+') => (Op::Add, 1),
            Some(b'-') => (Op::Sub, 1),
            _ => {
                let words: [(&[u8], Op); 11] = [
                    (b"mod", Op::Mod),
                    (b"eq", Op::Eq),
                    (b"ne", Op::Ne),
                    (b"gt", Op::Gt),
                    (b"ge", Op::Ge),
                    (b"lt", Op::Lt),
                    (b"le", Op::Le),
                    (b"and", Op::And),
                    (b"or", Op::Or),
                    (b"xor", Op::Xor),
                    (b"**", Op::Pow),
                ];
                match words.iter().find(|(w, _)| starts(w)) {
                    Some(&(w, op)) => (op, w.len()),
                    None => {
                        return self.err(std::format!(
                            "an operator (** * / MOD + - EQ NE GT GE LT LE AND OR XOR) or ']', \
                             got {}",
                            self.got()
                        ));
                    }
                }
            }
        };
        Ok(Some(op))
    }

    /// Values joined by operators of precedence `min` and above, left to right.
    fn binary(&mut self, min: u8) -> Result<u32, LexError> {
        let mut lhs = self.value()?;
        while let Some((op, len)) = self.operator()? {
            if op.precedence() < min {
                break;
            }
            self.at += len;
            self.enter()?;
            let rhs = self.binary(op.precedence() + 1);
            self.depth -= 1;
            lhs = self.push(Node::Bin(op, lhs, rhs?));
        }
        Ok(lhs)
    }
}
