//! The words of one block, evaluated: G and M codes with their columns, and one value per
//! letter, each marked when the block's execution uses it (a word nothing uses is refused, as
//! LinuxCNC refuses "K word with no G2, G3 ... to use it").

use std::string::String;
use std::vec::Vec;

use super::fault::{Fault, fault};

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

/// The G and M codes of a block grouped as LinuxCNC groups them: one per group (G80 may
/// join another motion code and is then dropped; M7 and M8 share group 8 but LinuxCNC
/// refuses them together too), at most 4 M codes.
pub(super) fn check_groups(w: &mut Words) -> Result<(), Fault> {
    let has_other_motion =
        w.g.iter()
            .any(|g| super::words_group(g.0) == Some(1) && g.0 != 800);
    if has_other_motion {
        w.g.retain(|g| g.0 != 800);
    }
    for (i, &(a, ca)) in w.g.iter().enumerate() {
        let ga = super::words_group(a);
        if let Some(&(b, _)) =
            w.g.iter()
                .skip(i + 1)
                .find(|&&(b, _)| super::words_group(b) == ga)
        {
            return fault(
                ca,
                std::format!(
                    "one G code of each modal group per line, got {} and {}",
                    g_name(a),
                    g_name(b)
                ),
            );
        }
    }
    if w.m.len() > 4 {
        return fault(w.m.get(4).map_or(1, |m| m.1), "at most 4 M codes on a line");
    }
    for (i, &(a, ca)) in w.m.iter().enumerate() {
        let ga = super::m_group(a);
        if let Some(&(b, _)) =
            w.m.iter()
                .skip(i + 1)
                .find(|&&(b, _)| super::m_group(b) == ga)
        {
            return fault(
                ca,
                std::format!("one M code of each modal group per line, got M{a} and M{b}"),
            );
        }
    }
    Ok(())
}

/// Why a word nothing used is on the line.
pub(super) fn unused_message(letter: char, w: &Words) -> String {
    let motion = w.g.iter().find(|g| super::words_group(g.0) == Some(1));
    let users = match letter {
        'X' | 'Y' | 'Z' | '@' | '^' => {
            return std::format!(
                "{letter}: axis words with no motion mode to use them (G0, G1, G2, G3 or a \
                 cycle; after G80 or at the start, the line needs one)"
            );
        }
        'I' | 'J' | 'K' => "G2, G3, G5, G5.1 or G87",
        'R' => "G2, G3, a canned cycle or G10 L2",
        'P' => "G2, G3, G4, G5, G10, G64, G82, G86, G88, G89, M50-M53, M62-M66 or M98",
        'Q' => "G5, G10, G64, G73, G83, M61, M66-M68 or M19",
        'L' => "G10, a canned cycle or M98",
        'H' => "G43 or G43.2",
        'D' => "G41 or G42 (not modelled)",
        'E' => "M66, M67 or M68",
        _ => "any code",
    };
    let context = motion.map_or(String::new(), |m| {
        std::format!(" (this line's is {})", g_name(m.0))
    });
    std::format!("{letter}: a word nothing on the line uses; only {users} use it{context}")
}
