//! A fault inside a block, before the reader names its line: the column and the message.

use std::string::String;

/// A fault inside a block: the column and the message.
pub(super) type Fault = (usize, String);

pub(super) fn fault<T>(column: usize, message: impl Into<String>) -> Result<T, Fault> {
    Err((column, message.into()))
}
