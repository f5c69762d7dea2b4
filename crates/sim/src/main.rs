//! `deflect-sim`: the project's main command. With no arguments it runs `reproduce`.
//!
//! The binary's own modules: [`cli`] (the command line) and [`commands`] (one module per
//! command); the simulation itself is the `deflect_sim` library.
//!
//! Before any work, the arguments are checked against their documented ranges, input files
//! are read and validated, and the output directory is created and probed. Errors are one
//! line on stderr, `error: ...`: exit code 2 for usage (as clap's own), 1 for failure; never a
//! panic (a panic of a dependency is caught and reported as an internal error, exit code 1).
// No input may kill the process: errors are returned, never panicked (tests may unwrap).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod cli;
mod commands;

use std::sync::Mutex;

use clap::Parser;

use cli::{Cli, CliError, Command, ReproduceArgs};

/// The first panic's message, recorded by the panic hook for the one-line report.
static PANIC: Mutex<Option<String>> = Mutex::new(None);

/// Replaces the default panic report (several lines, a backtrace hint) by a record in
/// [`PANIC`], unless `RUST_BACKTRACE` asks for the default.
fn install_panic_hook() {
    if std::env::var_os("RUST_BACKTRACE").is_some() {
        return;
    }
    std::panic::set_hook(Box::new(|info| {
        if let Ok(mut p) = PANIC.lock() {
            p.get_or_insert_with(|| info.to_string());
        }
    }));
}

/// Checks the flags, then drives the command through its spine ([`commands::Cmd`]: the
/// inputs loaded and checked, the output directory prepared, the run).
fn execute(cli: &Cli) -> Result<(), CliError> {
    let default = Command::Reproduce(ReproduceArgs::default());
    let command = cli.command.as_ref().unwrap_or(&default);
    command.check()?;
    let out = &cli.out;
    match command {
        Command::Reproduce(a) => commands::execute(a, out),
        Command::StaticTest(a) => commands::execute(a, out),
        Command::Fit(a) => commands::execute(a, out),
        Command::Run(a) => commands::execute(a, out),
        Command::Milling(a) => commands::execute(a, out),
        Command::Contour(a) => commands::execute(a, out),
        Command::Serial(a) => commands::execute(a, out),
        Command::Atlas(a) => commands::execute(a, out),
        Command::Job(a) => commands::execute(a, out),
        Command::Place(a) => commands::execute(a, out),
        Command::Delta(a) => commands::execute(a, out),
    }
}

/// `msg` on one line: line breaks (from a dependency's message) become "; ".
fn one_line(msg: &str) -> String {
    msg.split(['\n', '\r'])
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

/// clap's own outcome: help and version as clap prints them (exit 0); a usage error as the
/// one `error: ...` line of every other refusal (clap's usage block and help hint dropped, the
/// missing or wrong flags kept), exit 2.
fn clap_exit(e: &clap::Error) -> std::process::ExitCode {
    use clap::error::ErrorKind;
    use std::io::Write;
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        // Nothing more can be reported if stdout or stderr itself fails.
        let _ = e.print();
        return std::process::ExitCode::from(if e.use_stderr() { 2 } else { 0 });
    }
    let text = e.to_string();
    let body = text.split("\n\nUsage:").next().unwrap_or(&text);
    let body = body
        .split("\n\nFor more information")
        .next()
        .unwrap_or(body);
    let body = body.trim().trim_start_matches("error:").trim();
    let _ = writeln!(std::io::stderr(), "error: {}", one_line(body));
    std::process::ExitCode::from(2)
}

fn main() -> std::process::ExitCode {
    install_panic_hook();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_exit(&e),
    };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| execute(&cli)));
    let panicked = PANIC.lock().ok().and_then(|mut p| p.take());
    let error = match (result, panicked) {
        (Ok(Ok(())), None) => return std::process::ExitCode::SUCCESS,
        // A worker thread's panic comes back as an error; report the panic itself.
        (_, Some(p)) => CliError::Failure(format!("internal error (a bug): {p}")),
        (Ok(Err(e)), None) => e,
        (Err(_), None) => CliError::Failure("internal error (a bug): panic".into()),
    };
    {
        use std::io::Write;
        // Nothing more can be reported if stderr itself fails.
        let _ = writeln!(std::io::stderr(), "error: {}", one_line(error.message()));
    }
    std::process::ExitCode::from(error.code())
}
