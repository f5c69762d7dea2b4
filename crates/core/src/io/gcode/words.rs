//! The words of one block, evaluated: G and M codes with their columns, and one value per
//! letter, each marked when the block's execution uses it (a word nothing uses is refused, as
//! LinuxCNC refuses "K word with no G2, G3 ... to use it").

use std::string::String;
use std::vec::Vec;

/// Letters `a`-`z`, then `@` (polar radius), `^` (polar angle), `$` (spindle).
const SLOTS: usize = 29;

fn slot(letter: u8) -> Option<usize> {
    match letter {
        b'a'..=b'z' => Some(usize::from(letter - b'a')),
        b'@' => Some(26),
        b'^' => Some(27),
        b'$' => Some(28),
        _ => None,
    }
}

/// A block's evaluated words.
#[derive(Debug, Clone, Default)]
pub(super) struct Words {
    /// G codes as ten times their number (G91.1 -> 911), with columns.
    pub g: Vec<(u16, usize)>,
    /// M codes with columns.
    pub m: Vec<(u16, usize)>,
    values: [Option<(f64, usize)>; SLOTS],
    used: u32,
}

impl Words {
    pub(super) fn clear(&mut self) {
        self.g.clear();
        self.m.clear();
        self.values = [None; SLOTS];
        self.used = 0;
    }

    /// Stores a letter's value (the lexer allows each letter once).
    pub(super) fn set(&mut self, letter: u8, value: f64, column: usize) {
        if let Some(v) = slot(letter).and_then(|s| self.values.get_mut(s)) {
            *v = Some((value, column));
        }
    }

    /// A letter's value, marking it used.
    pub(super) fn take(&mut self, letter: u8) -> Option<f64> {
        let s = slot(letter)?;
        let v = self.values.get(s).copied().flatten()?;
        self.used |= 1 << s;
        Some(v.0)
    }

    /// A letter's value without marking it.
    pub(super) fn peek(&self, letter: u8) -> Option<f64> {
        slot(letter).and_then(|s| self.values.get(s).copied().flatten().map(|v| v.0))
    }

    /// Whether the letter is on the line.
    pub(super) fn has(&self, letter: u8) -> bool {
        self.peek(letter).is_some()
    }

    /// The column of a letter's word (or of the line start).
    pub(super) fn column(&self, letter: u8) -> usize {
        slot(letter)
            .and_then(|s| self.values.get(s).copied().flatten())
            .map_or(1, |v| v.1)
    }

    /// Whether a G code (ten times its number) is on the line, and its column.
    pub(super) fn g(&self, code: u16) -> Option<usize> {
        self.g.iter().find(|g| g.0 == code).map(|g| g.1)
    }

    /// Whether an M code is on the line, and its column.
    pub(super) fn m(&self, code: u16) -> Option<usize> {
        self.m.iter().find(|m| m.0 == code).map(|m| m.1)
    }

    /// The first word on the line that nothing used: its letter and column.
    pub(super) fn unused(&self) -> Option<(char, usize)> {
        let mut best: Option<(char, usize)> = None;
        for (s, v) in self.values.iter().enumerate() {
            if let Some((_, column)) = v
                && self.used & (1 << s) == 0
            {
                let letter = match s {
                    26 => '@',
                    27 => '^',
                    28 => '$',
                    _ => char::from(b'A' + s as u8),
                };
                if best.is_none_or(|b| *column < b.1) {
                    best = Some((letter, *column));
                }
            }
        }
        best
    }

    /// Whether any of `letters` is on the line and not used yet.
    pub(super) fn any_unused(&self, letters: &[u8]) -> bool {
        letters.iter().any(|&l| {
            slot(l).is_some_and(|s| {
                self.values.get(s).copied().flatten().is_some() && self.used & (1 << s) == 0
            })
        })
    }

    /// The column of the first of `letters` on the line.
    pub(super) fn first_of(&self, letters: &[u8]) -> Option<usize> {
        letters
            .iter()
            .filter(|&&l| self.has(l))
            .map(|&l| self.column(l))
            .min()
    }
}

/// G code `code` (ten times the number) as written: 911 -> "G91.1".
pub(super) fn g_name(code: u16) -> String {
    if code.is_multiple_of(10) {
        std::format!("G{}", code / 10)
    } else {
        std::format!("G{}.{}", code / 10, code % 10)
    }
}
