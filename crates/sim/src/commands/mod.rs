//! One module per command of `deflect-sim` (binary): each turns its arguments into the
//! library's options, runs the scenario, prints its table and writes its files. Shared here:
//! printing that fails instead of panicking (`say!`, `put!`), the checks of input files
//! and of the output directory before any work.

use std::fmt;
use std::path::Path;

use deflect_core::compliance_map::ComplianceMap;
use deflect_sim::SimError;
use deflect_sim::scenes::parallel::calibrate;
use deflect_sim::scenes::parallel::params::Constraint;

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

/// One command's spine: [`Cmd::load`] reads and checks every input before any work, the
/// output directory is then created and probed (when the command writes into it), and
/// [`Cmd::run`] runs the scenario, prints its table and writes its files. Every command
/// implements it on its flags and [`execute`] drives it, after the flags' ranges are checked
/// ([`crate::cli::Command::check`]).
pub trait Cmd {
    /// What the command reads and checks before any work.
    type Input;
    /// Reads and checks the inputs: a usage error naming the flag, or a failure naming the
    /// file.
    fn load(&self) -> Result<Self::Input, CliError>;
    /// Whether the run writes into `--out` (`job --explain` only prints).
    fn writes(&self, _input: &Self::Input) -> bool {
        true
    }
    /// Runs the command on its checked inputs, writing into `out`.
    fn run(&self, input: Self::Input, out: &Path) -> Result<(), SimError>;
}

/// `load`, then the output directory, then `run` ([`Cmd`]).
pub fn execute<C: Cmd>(command: &C, out: &Path) -> Result<(), CliError> {
    let input = command.load()?;
    if command.writes(&input) {
        prepare_out(out)?;
    }
    command.run(input, out).map_err(CliError::from)
}

/// Writes `args` to stdout; an error if stdout is closed or fails.
pub fn stdout(args: fmt::Arguments<'_>) -> Result<(), SimError> {
    use std::io::Write;
    std::io::stdout()
        .lock()
        .write_fmt(args)
        .map_err(|e| SimError::new(format!("cannot write to standard output: {e}")))
}

/// The parallel robot's calibration ([`calibrate::calibrate_all`]) for `constraints`, its
/// summaries printed in order: the maps.
pub fn calibrate_all(
    constraints: &[Constraint],
    out: &Path,
) -> Result<Vec<(Constraint, ComplianceMap)>, SimError> {
    let mut maps = Vec::new();
    for (c, map, text) in calibrate::calibrate_all(constraints, out)? {
        say!("{text}");
        maps.push((c, map));
    }
    Ok(maps)
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
