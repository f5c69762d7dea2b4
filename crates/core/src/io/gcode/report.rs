//! The word report: every word a program uses, whether this reader honours it (it shapes
//! the moves), records it without motion, or refuses it, with its count and first line. Read
//! from the text alone (every line, whether it runs or not), so a program the reader refuses
//! still has its report.

use std::collections::HashMap;
use std::string::{String, ToString};
use std::vec::Vec;

use super::GcodeOptions;
use super::lex::{self, Block, CommentKind, Item, Keyword, Node};
use super::words::g_name;
use crate::error::LoadError;

/// What the reader does with a word.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum WordStatus {
    /// It shapes the moves (or the language that makes them).
    Honoured,
    /// Read, checked and kept or dropped without motion (coolant, overrides, tool lengths).
    Recorded,
    /// The reader refuses it ([`crate::LoadError::Program`] at its first use).
    Refused,
}

impl WordStatus {
    /// "honoured", "recorded" or "refused".
    pub fn name(self) -> &'static str {
        match self {
            Self::Honoured => "honoured",
            Self::Recorded => "recorded",
            Self::Refused => "refused",
        }
    }
}

/// One word of a program and what the reader does with it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WordUse {
    /// The word: "G43", "M6", "X", "#" (parameter setting), "O sub", "(MSG,...)", ...
    pub word: String,
    /// Honoured, recorded or refused.
    pub status: WordStatus,
    /// Occurrences in the text.
    pub count: usize,
    /// The first line (1-based) it is on.
    pub first_line: usize,
    /// What it means here.
    pub meaning: String,
}

/// The words of `text`, in order of first use (at most [`super::MAX_PROGRAM_LINES`] lines).
pub fn words(text: &str, options: &GcodeOptions) -> Result<Vec<WordUse>, LoadError> {
    super::super::check_size("G-code program", text)?;
    let lines = text.lines().count();
    if lines > super::MAX_PROGRAM_LINES {
        return Err(LoadError::TooLarge {
            what: "G-code program lines".into(),
            limit: super::MAX_PROGRAM_LINES,
            got: lines,
        });
    }
    let mut tally = Tally::default();
    let mut block = Block::default();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        if raw.trim().starts_with('%') {
            tally.add(
                "%".into(),
                line,
                honoured("program start and end marker (tape)"),
            );
            continue;
        }
        if let Err((_, message)) = lex::lex(raw, options.dialect, &mut block) {
            let why = (WordStatus::Refused, std::format!("expected {message}"));
            tally.add("(a line that does not read)".into(), line, why);
            continue;
        }
        if block.delete {
            let what = honoured("block delete (the line runs unless block delete is on)");
            tally.add("/".into(), line, what);
        }
        if let Some(o) = &block.o_word {
            let meaning = match o.keyword {
                Keyword::Header => "a program number: M98's target, or nothing",
                Keyword::Sub | Keyword::Endsub | Keyword::Call | Keyword::Return => "subroutine",
                _ => "control flow",
            };
            tally.add(
                std::format!("O {}", o.keyword.name()),
                line,
                honoured(meaning),
            );
        }
        for item in &block.items {
            let (word, class) = item_class(&block, item);
            tally.add(word, line, class);
        }
        if let Some(c) = &block.comment {
            let (word, class) = comment_class(c.kind);
            tally.add(word.into(), line, class);
        }
    }
    Ok(tally.words)
}

/// The words met so far, by first use.
#[derive(Default)]
struct Tally {
    words: Vec<WordUse>,
    index: HashMap<String, usize>,
}

impl Tally {
    fn add(&mut self, word: String, line: usize, (status, meaning): (WordStatus, String)) {
        if let Some(u) = self.index.get(&word).and_then(|&k| self.words.get_mut(k)) {
            u.count += 1;
            return;
        }
        self.index.insert(word.clone(), self.words.len());
        self.words.push(WordUse {
            word,
            status,
            count: 1,
            first_line: line,
            meaning,
        });
    }
}

/// A word or a parameter setting as the report names and classes it.
fn item_class(block: &Block, item: &Item) -> (String, (WordStatus, String)) {
    let &Item::Word { letter, value, .. } = item else {
        return ("#".into(), honoured("parameter setting"));
    };
    let literal = match block.nodes.get(value as usize) {
        Some(Node::Num(v)) => Some(*v),
        _ => None,
    };
    let upper = char::from(letter.to_ascii_uppercase());
    match (letter, literal) {
        (b'g', Some(v)) => {
            let code = (v * 10.0).round() as u16;
            (g_name(code), g_class(code))
        }
        (b'm', Some(v)) => {
            let code = v.round() as u16;
            (std::format!("M{code}"), m_class(code))
        }
        (b'g' | b'm', None) => (
            std::format!("{upper}[...]"),
            honoured("a code given by an expression"),
        ),
        (b'a' | b'b' | b'c', Some(v)) if v != 0.0 => (
            upper.to_string(),
            refused("rotary axis turning: not modelled"),
        ),
        _ => (upper.to_string(), letter_class(letter)),
    }
}

/// A paren comment as the report names and classes it.
fn comment_class(kind: CommentKind) -> (&'static str, (WordStatus, String)) {
    match kind {
        CommentKind::Plain => ("( )", recorded("comment")),
        CommentKind::Msg => ("(MSG,...)", recorded("operator message: no motion")),
        CommentKind::Debug => ("(DEBUG,...)", recorded("debug message: no motion")),
        CommentKind::Print => ("(PRINT,...)", recorded("printed message: no motion")),
        CommentKind::Log => ("(LOG,...)", recorded("log message: no motion")),
        CommentKind::Abort => (
            "(ABORT,...)",
            honoured("stops the reading with its text as the error"),
        ),
    }
}

fn honoured(s: &str) -> (WordStatus, String) {
    (WordStatus::Honoured, s.into())
}

fn recorded(s: &str) -> (WordStatus, String) {
    (WordStatus::Recorded, s.into())
}

fn refused(s: &str) -> (WordStatus, String) {
    (WordStatus::Refused, s.into())
}

fn g_class(code: u16) -> (WordStatus, String) {
    match code {
        0 => honoured("rapid move"),
        10 => honoured("straight feed move"),
        20 | 30 => honoured("arc (clockwise G2, counter-clockwise G3) in the selected plane"),
        40 => honoured("dwell P seconds: a timed stop"),
        50 | 51 => honoured("spline (cubic G5, quadratic G5.1) as lines within 1 um"),
        100 => {
            honoured("coordinate system data (L2, L20); tool table data (L1, L10, L11) recorded")
        }
        170 | 180 | 190 => honoured("arc plane XY, ZX, YZ"),
        200 | 210 => honoured("units inch, mm"),
        280 | 300 => honoured("rapid to the stored point through the intermediate point"),
        281 | 301 => honoured("stores the current point"),
        400 => recorded("cutter radius compensation off"),
        430..=432 => recorded(
            "tool length offset: recorded, not applied (a robot's TCP carries the tool length)",
        ),
        490 => recorded("tool length offset off"),
        520 | 920 => honoured("axis offset"),
        530 => honoured("move in machine coordinates"),
        540 | 550 | 560 | 570 | 580 | 590 | 591 | 592 | 593 => honoured("work coordinate system"),
        610 | 611 | 640 => {
            recorded("path control: recorded per move (the path model stops at corners)")
        }
        730 | 740 | 810 | 820 | 830 | 840 | 850 | 860 | 870 | 890 => {
            honoured("canned cycle, expanded into LinuxCNC's moves")
        }
        880 => {
            honoured("canned cycle; the operator's retract by hand is a rapid to the clear height")
        }
        800 => honoured("cancel the motion mode"),
        900 | 910 => honoured("absolute, incremental coordinates"),
        901 | 911 => honoured("absolute, incremental arc centres"),
        921..=923 => honoured("axis offset reset, suspend, restore"),
        930 | 940 | 950 => honoured("feed: inverse time, per minute, per revolution"),
        970 => recorded("spindle in RPM"),
        980 | 990 => honoured("cycle retract to the initial level, to R"),
        330 | 331 | 760 => refused("threading: not modelled"),
        382..=385 => refused("probing: not modelled"),
        410 | 411 | 420 | 421 => {
            refused("cutter radius compensation: have the CAM write the compensated path")
        }
        70 | 700..=722 | 960 => refused("lathe mode or cycle"),
        80 => recorded("lathe radius mode (the default)"),
        1030 | 1870 => {
            recorded("Haas look-ahead, smoothness: no motion (fanuc dialect; LinuxCNC refuses it)")
        }
        52 | 53 => refused("NURBS: not modelled"),
        171 | 181 | 191 => refused("UVW planes"),
        _ => refused("a G code LinuxCNC does not know"),
    }
}

fn m_class(code: u16) -> (WordStatus, String) {
    match code {
        0 | 1 | 60 => recorded("program stop: no motion"),
        2 | 30 => honoured("program end: what follows is not read"),
        99 => honoured("return from M98 (at the top: program end)"),
        98 => honoured("call program number P, L times"),
        3 | 4 => honoured(
            "spindle on, clockwise (M3) or counter-clockwise (M4: the cutting model's direction)",
        ),
        5 => honoured("spindle off"),
        6 | 61 => honoured("tool change: the tool in the spindle, per move"),
        7..=9 => recorded("coolant"),
        19 => recorded("spindle orientation"),
        48..=53 => recorded("overrides"),
        62..=68 => recorded("digital and analog I/O"),
        70..=73 => honoured("modal state save, invalidate, restore"),
        100..=199 => refused("user M code: runs a program of the controller"),
        _ => refused("an M code LinuxCNC does not know"),
    }
}

fn letter_class(letter: u8) -> (WordStatus, String) {
    match letter {
        b'x' | b'y' | b'z' => honoured("axis"),
        b'i' | b'j' | b'k' => honoured("arc centre, spline or cycle offset"),
        b'r' => honoured("arc radius, cycle retract plane, G10 rotation"),
        b'f' => honoured("feed"),
        b's' => honoured("spindle speed"),
        b't' => honoured("tool"),
        b'p' => honoured("dwell, turns, coordinate system, tolerance, program number"),
        b'q' => honoured("peck, tolerance, tool number"),
        b'l' => honoured("repeats, G10 mode"),
        b'h' => recorded("tool length offset number"),
        b'e' => recorded("analog I/O number"),
        b'@' | b'^' => honoured("polar radius, angle"),
        b'd' => refused("cutter radius compensation number"),
        b'a' | b'b' | b'c' => recorded("rotary axis: held at 0 only (refused where it turns)"),
        b'u' | b'v' | b'w' => refused("secondary axis: not modelled"),
        b'$' => refused("spindle selection: one spindle"),
        _ => refused("a word LinuxCNC does not know"),
    }
}
