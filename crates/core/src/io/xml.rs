//! A structural pre-check of XML text, run before a recursive parser sees it: element
//! nesting depth and the root element. Comments, processing instructions, CDATA sections,
//! declarations and quoted attribute values are skipped as XML defines them.

use std::format;
use std::string::{String, ToString};

use crate::error::LoadError;

fn parse_error(message: String) -> LoadError {
    LoadError::UrdfParse { message }
}

/// Checks that `text` has exactly one root element, named `root`, and no element nested
/// deeper than `max_depth`. Linear in the text, no allocation beyond error messages.
pub(crate) fn check_structure(text: &str, root: &str, max_depth: usize) -> Result<(), LoadError> {
    let bytes = text.as_bytes();
    let mut i = 0usize;
    let mut depth = 0usize;
    let mut roots = 0usize;
    let find = |from: usize, pat: &[u8]| -> Option<usize> {
        bytes
            .get(from..)?
            .windows(pat.len())
            .position(|w| w == pat)
            .map(|p| p + from)
    };
    while let Some(rel) = bytes
        .get(i..)
        .and_then(|b| b.iter().position(|&c| c == b'<'))
    {
        let start = i + rel;
        let rest = bytes.get(start..).unwrap_or(&[]);
        // Skip constructs that are not elements.
        let skip_to = if rest.starts_with(b"<!--") {
            find(start + 4, b"-->").map(|e| e + 3)
        } else if rest.starts_with(b"<![CDATA[") {
            find(start + 9, b"]]>").map(|e| e + 3)
        } else if rest.starts_with(b"<?") {
            find(start + 2, b"?>").map(|e| e + 2)
        } else if rest.starts_with(b"<!") {
            find(start + 2, b">").map(|e| e + 1)
        } else {
            None
        };
        if rest.starts_with(b"<!") || rest.starts_with(b"<?") {
            match skip_to {
                Some(e) => {
                    i = e;
                    continue;
                }
                None => return Err(parse_error("unterminated comment or declaration".into())),
            }
        }
        // An element tag: find its end, honouring quoted attribute values.
        let mut j = start + 1;
        let mut quote: Option<u8> = None;
        let end = loop {
            match (bytes.get(j), quote) {
                (None, _) => return Err(parse_error("unterminated tag".into())),
                (Some(&c), Some(q)) if c == q => quote = None,
                (Some(_), Some(_)) => {}
                (Some(&c), None) if c == b'"' || c == b'\'' => quote = Some(c),
                (Some(&b'>'), None) => break j,
                (Some(_), None) => {}
            }
            j += 1;
        };
        let tag = bytes.get(start + 1..end).unwrap_or(&[]);
        if tag.first() == Some(&b'/') {
            depth = depth.checked_sub(1).ok_or_else(|| {
                parse_error(format!(
                    "closing tag without an opening one at byte {start}"
                ))
            })?;
        } else if tag.last() == Some(&b'/') {
            // Self-closing: a root element that is empty still counts as a root.
            if depth == 0 {
                roots += 1;
                check_root(tag, root, roots)?;
            }
        } else {
            if depth == 0 {
                roots += 1;
                check_root(tag, root, roots)?;
            }
            depth += 1;
            if depth > max_depth {
                return Err(LoadError::TooLarge {
                    what: "XML nesting depth".to_string(),
                    limit: max_depth,
                    got: depth,
                });
            }
        }
        i = end + 1;
    }
    match roots {
        0 => Err(parse_error(format!("no <{root}> root element"))),
        _ => Ok(()),
    }
}

fn check_root(tag: &[u8], root: &str, roots: usize) -> Result<(), LoadError> {
    if roots > 1 {
        return Err(parse_error(format!(
            "more than one root element (a second one after the <{root}>)"
        )));
    }
    let name_end = tag
        .iter()
        .position(|c| c.is_ascii_whitespace() || *c == b'/')
        .unwrap_or(tag.len());
    let name = String::from_utf8_lossy(tag.get(..name_end).unwrap_or(&[]));
    if name != root {
        return Err(parse_error(format!(
            "the root element is <{name}>, expected <{root}>"
        )));
    }
    Ok(())
}
