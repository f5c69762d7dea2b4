//! The reader's control-flow state: the calls, the loops and the skip in progress.

use std::string::String;
use std::vec::Vec;

use super::interp::Modal;
use super::lex::Keyword;

/// A call in progress.
#[derive(Debug, Clone)]
pub(super) struct Frame {
    /// The subroutine's name (labels inside it are scoped by it).
    pub(super) name: String,
    /// Where to go on return.
    pub(super) return_to: usize,
    /// The caller's `#1`-`#30` (O-word calls; M98 shares them).
    pub(super) saved: Option<[f64; 30]>,
    /// The caller's loops.
    pub(super) loops: Vec<Loop>,
    /// M98: the line after the program number, and the passes left.
    pub(super) fanuc: Option<(usize, u32)>,
    /// The modal state M73 saved in this call, restored on return.
    pub(super) m73: Option<Modal>,
}

/// A loop in progress.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Loop {
    pub(super) label: String,
    pub(super) kind: Keyword,
    /// The index of its `while`, `do` or `repeat` line.
    pub(super) line: usize,
    pub(super) remaining: i64,
}

/// Lines being skipped up to an O-word with `label` (and keyword `until`, if given).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Skip {
    pub(super) label: String,
    pub(super) until: Option<Keyword>,
    /// Run the line found (a branch reached from a false condition), or go on after it.
    pub(super) then_run: bool,
    /// Skipping a subroutine's definition.
    pub(super) definition: bool,
    /// The line the skip started at (index).
    pub(super) from: usize,
}

impl Skip {
    /// The label as written, for messages.
    pub(super) fn label_text(&self) -> &str {
        self.label.rsplit('#').next().unwrap_or(&self.label)
    }

    /// Whether running off the end of the file while skipping is fine (never: an open
    /// definition or block is an error).
    pub(super) fn resume_after_definition_end(&self) -> bool {
        false
    }
}
