//! The arguments of an APT statement (`MAJOR/arg, arg, ...`): numbers and words, split,
//! read by position and checked against the statement's form, and the fault naming the
//! statement's line.

use std::format;
use std::string::String;
use std::vec::Vec;

use crate::error::LoadError;

/// A fault at `line`, column 1: the statement.
pub(super) fn fault<T>(line: usize, message: impl Into<String>) -> Result<T, LoadError> {
    Err(LoadError::Program {
        line,
        column: 1,
        message: message.into(),
    })
}

/// One argument: a number or a word (upper-cased).
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Arg {
    Number(f64),
    Word(String),
}

/// The word at `i`, if that argument is one.
pub(super) fn word(args: &[Arg], i: usize) -> Option<String> {
    match args.get(i) {
        Some(Arg::Word(w)) => Some(w.clone()),
        _ => None,
    }
}

/// The first `N` arguments, numbers (more may follow).
pub(super) fn numbers<const N: usize>(
    line: usize,
    form: &str,
    args: &[Arg],
) -> Result<[f64; N], LoadError> {
    let mut out = [0.0; N];
    for (i, o) in out.iter_mut().enumerate() {
        match args.get(i) {
            Some(Arg::Number(v)) => *o = *v,
            _ => return fault(line, format!("{form} ({N} numbers)")),
        }
    }
    Ok(out)
}

/// A point and, with 6 numbers, a tool vector (unnormalised): 3 or 6 numbers, nothing else.
pub(super) fn point_and_axis(
    line: usize,
    form: &str,
    args: &[Arg],
) -> Result<([f64; 3], Option<[f64; 3]>), LoadError> {
    match args.len() {
        3 => Ok((numbers::<3>(line, form, args)?, None)),
        6 => {
            let [x, y, z, i, j, k] = numbers::<6>(line, form, args)?;
            Ok(([x, y, z], Some([i, j, k])))
        }
        n => fault(line, format!("{form} (3 or 6 numbers), got {n} values")),
    }
}

/// Splits `a, b, c` into numbers and words.
pub(super) fn parse_args(line: usize, text: &str) -> Result<Vec<Arg>, LoadError> {
    text.split(',')
        .map(|t| t.trim())
        .filter(|t| !t.is_empty())
        .map(|t| {
            if t.starts_with(|c: char| c.is_ascii_digit() || matches!(c, '-' | '+' | '.')) {
                match t.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(Arg::Number(v)),
                    _ => fault(line, format!("a finite number, got {t}")),
                }
            } else {
                Ok(Arg::Word(t.to_ascii_uppercase()))
            }
        })
        .collect()
}
