//! What every scene's output shares: the summary's three files and the reduction figure.

use std::path::Path;

use crate::{SimError, write_file};

/// Writes `<stem>.txt`, `<stem>.csv` and `<stem>.json` (pretty JSON of `json`) into `out`.
pub fn write_summary<T: serde::Serialize + ?Sized>(
    out: &Path,
    stem: &str,
    txt: &str,
    csv: &str,
    json: &T,
) -> Result<(), SimError> {
    write_file(&out.join(format!("{stem}.txt")), "the summary table", txt)?;
    write_file(&out.join(format!("{stem}.csv")), "the summary CSV", csv)?;
    write_file(
        &out.join(format!("{stem}.json")),
        "the summary JSON",
        serde_json::to_string_pretty(json)?,
    )?;
    Ok(())
}

/// Reduction in percent from `a` to `b`.
pub fn reduction(a: f64, b: f64) -> f64 {
    if a > 0.0 { 100.0 * (a - b) / a } else { 0.0 }
}
