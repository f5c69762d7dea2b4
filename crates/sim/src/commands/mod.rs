//! One module per command of `deflect-sim` (binary): each turns its arguments into the
//! library's options, runs the scenario, prints its table and writes its files. Shared here:
//! printing that fails instead of panicking (`say!`, `put!`), the checks of input files
//! and of the output directory before any work.

use std::fmt;
use std::path::Path;

use deflect_sim::SimError;

use crate::cli::CliError;

/// `println!` that returns an error from the enclosing function when stdout is closed or
/// fails (`deflect-sim | head -1`), instead of panicking.
macro_rules! say {
    ($($t:tt)*) => {
        $crate::commands::stdout(format_args!("{}\n", format_args!($($t)*)))?
    };
}

/// `print!` that returns an error when stdout fails; see `say!`.
macro_rules! put {
    ($($t:tt)*) => {
        $crate::commands::stdout(format_args!($($t)*))?
    };
}

pub mod atlas;
pub mod calibrate;
pub mod contour;
pub mod delta;
pub mod fit;
pub mod inputs;
pub mod job;
pub mod milling;
pub mod place;
pub mod reproduce;
pub mod run;
pub mod serial;
pub mod static_test;

/// Writes `args` to stdout; an error if stdout is closed or fails.
pub fn stdout(args: fmt::Arguments<'_>) -> Result<(), SimError> {
    use std::io::Write;
    std::io::stdout()
        .lock()
        .write_fmt(args)
        .map_err(|e| SimError::new(format!("cannot write to standard output: {e}")))
}

/// Creates the output directory `out` if missing and checks that it takes files, before any
/// work; otherwise a usage error naming `--out` and the path.
pub fn prepare_out(out: &Path) -> Result<(), CliError> {
    let usage = |what: &str| CliError::Usage(format!("--out {}: {what}", out.display()));
    if std::fs::metadata(out).is_ok_and(|m| !m.is_dir()) {
        return Err(usage(
            "exists and is not a directory (expected an output directory)",
        ));
    }
    std::fs::create_dir_all(out)
        .map_err(|e| usage(&format!("cannot create the output directory: {e}")))?;
    let probe = out.join(format!(".deflect-sim-probe-{}", std::process::id()));
    std::fs::File::create(&probe)
        .map_err(|e| usage(&format!("cannot write into the output directory: {e}")))?;
    // A probe left behind is harmless; the directory took a file.
    let _ = std::fs::remove_file(&probe);
    Ok(())
}
