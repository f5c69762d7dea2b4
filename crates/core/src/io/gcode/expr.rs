//! Evaluating a value of a [`Block`]: LinuxCNC's arithmetic (its `interp_execute.cc` and
//! `interp_read.cc`): angles in degrees, `EQ`/`NE` within 0.0001, `MOD` into `[0, |b|)`,
//! `FIX` = floor, `FUP` = ceil, `ROUND` half away from zero, logical operators giving 0 or 1,
//! and a typed refusal of every domain error, NaN and infinity.

use std::string::{String, ToString};

use super::lex::{Block, Func, Node, Op, Param};

/// Where a value reads its parameters.
pub(super) trait Scope {
    /// Numbered parameter `#index` (an integer within 0.0001; LinuxCNC's 1..=5601).
    fn numbered(&self, index: f64) -> Result<f64, String>;
    /// Named parameter `#<name>` (lower case); an error when it does not exist.
    fn named(&self, name: &str) -> Result<f64, String>;
    /// Whether `#<name>` exists.
    fn exists(&self, name: &str) -> bool;
}

/// The integer a value stands for, when it is within 0.0001 of one (LinuxCNC's rule for
/// `D H L M T`, O-word numbers and parameter indices).
pub(super) fn integer(v: f64) -> Option<i64> {
    let r = v.round();
    ((v - r).abs() < 1.0e-4 && r.abs() < 1.0e15).then_some(r as i64)
}

/// Evaluates node `n` of `b`.
pub(super) fn eval(b: &Block, n: u32, s: &dyn Scope) -> Result<f64, String> {
    let v = match b.nodes.get(n as usize).copied() {
        Some(Node::Num(v)) => v,
        Some(Node::Param(p)) => param(b, p, s)?,
        Some(Node::Neg(a)) => -eval(b, a, s)?,
        Some(Node::Bin(op, l, r)) => binary(op, eval(b, l, s)?, eval(b, r, s)?)?,
        Some(Node::Func(f, a)) => func(f, eval(b, a, s)?)?,
        Some(Node::Atan(y, x)) => {
            let (y, x) = (eval(b, y, s)?, eval(b, x, s)?);
            y.atan2(x).to_degrees()
        }
        Some(Node::Exists(p)) => match p {
            Param::Named(a, e) => f64::from(u8::from(s.exists(b.name(a, e)))),
            Param::Numbered(i) => {
                let i = eval(b, i, s)?;
                f64::from(u8::from(
                    integer(i).is_some_and(|i| (1..=super::params::MAX_PARAMETER).contains(&i)),
                ))
            }
        },
        None => return Err("internal: a value refers to a missing node".to_string()),
    };
    if v.is_nan() {
        return Err("a calculation that is a number, got NaN".to_string());
    }
    if v.is_infinite() {
        return Err("a calculation that is finite, got infinity".to_string());
    }
    Ok(v)
}

/// A parameter's value.
pub(super) fn param(b: &Block, p: Param, s: &dyn Scope) -> Result<f64, String> {
    match p {
        Param::Named(a, e) => s.named(b.name(a, e)),
        Param::Numbered(i) => s.numbered(eval(b, i, s)?),
    }
}

fn binary(op: Op, a: f64, b: f64) -> Result<f64, String> {
    let truth = |t: bool| f64::from(u8::from(t));
    Ok(match op {
        Op::Pow => {
            if a < 0.0 && b.fract() != 0.0 {
                return Err(std::format!(
                    "a non-negative base for a non-integer power, got {a} ** {b}"
                ));
            }
            a.powf(b)
        }
        Op::Mul => a * b,
        Op::Div => {
            if b == 0.0 {
                return Err(std::format!("a divisor other than 0, got {a} / 0"));
            }
            a / b
        }
        Op::Mod => {
            let m = a % b;
            if m < 0.0 { m + b.abs() } else { m }
        }
        Op::Add => a + b,
        Op::Sub => a - b,
        Op::Eq => truth((a - b).abs() < 1.0e-4),
        Op::Ne => truth((a - b).abs() >= 1.0e-4),
        Op::Gt => truth(a > b),
        Op::Ge => truth(a >= b),
        Op::Lt => truth(a < b),
        Op::Le => truth(a <= b),
        Op::And => truth(a != 0.0 && b != 0.0),
        Op::Or => truth(a != 0.0 || b != 0.0),
        Op::Xor => truth((a != 0.0) != (b != 0.0)),
    })
}

fn func(f: Func, x: f64) -> Result<f64, String> {
    Ok(match f {
        Func::Abs => x.abs(),
        Func::Acos | Func::Asin => {
            if !(-1.0..=1.0).contains(&x) {
                return Err(std::format!(
                    "an argument in [-1, 1] for {}, got {x}",
                    if f == Func::Acos { "ACOS" } else { "ASIN" }
                ));
            }
            if f == Func::Acos {
                x.acos().to_degrees()
            } else {
                x.asin().to_degrees()
            }
        }
        Func::Cos => x.to_radians().cos(),
        Func::Sin => x.to_radians().sin(),
        Func::Tan => x.to_radians().tan(),
        Func::Exp => x.exp(),
        Func::Fix => x.floor(),
        Func::Fup => x.ceil(),
        Func::Round => x.round(),
        Func::Ln => {
            if x <= 0.0 {
                return Err(std::format!("an argument > 0 for LN, got {x}"));
            }
            x.ln()
        }
        Func::Sqrt => {
            if x < 0.0 {
                return Err(std::format!("an argument >= 0 for SQRT, got {x}"));
            }
            x.sqrt()
        }
    })
}
