//! The command line of `deflect-sim` (the built binary): every refused input exits with code 2
//! (usage) or 1 (failure) and one `error: ...` line on stderr naming the flag or file, before
//! any work (the output directory is not even created) and at once; never a panic. Each test
//! is named for the reproducer it guards. One quick successful `fit` is the only run.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_deflect-sim");

/// A refusal takes no work: well under a second; the bound leaves room for a loaded machine.
const PROMPT: Duration = Duration::from_secs(5);

/// A fresh scratch directory for one test, removed afterwards.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

fn scratch(name: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("deflect-sim-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    Scratch(d)
}

struct Outcome {
    code: i32,
    stdout: String,
    stderr: String,
    elapsed: Duration,
}

/// Runs the binary with `args` (progress bars off).
fn sim(args: &[&str]) -> Outcome {
    sim_with(args, Stdio::piped())
}

/// [`sim`] with stdout going to `stdout`.
fn sim_with(args: &[&str], stdout: Stdio) -> Outcome {
    let t = Instant::now();
    let o = Command::new(BIN)
        .args(args)
        .env("CI", "1")
        .env_remove("RUST_BACKTRACE")
        .stdout(stdout)
        .output()
        .unwrap();
    Outcome {
        code: o.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
        elapsed: t.elapsed(),
    }
}

/// Runs `args` with `--out <dir>/out` and checks the refusal: exit `code`, nothing on stdout,
/// exactly one stderr line `error: ...` containing every `needle`, promptly, the output
/// directory not created. Returns the line.
fn refused(dir: &Path, args: &[&str], code: i32, needles: &[&str]) -> String {
    let out = dir.join("out");
    let out_s = out.to_str().unwrap();
    let mut all = args.to_vec();
    if !args.contains(&"--out") {
        all.extend(["--out", out_s]);
    }
    let o = sim(&all);
    let lines: Vec<&str> = o.stderr.lines().collect();
    assert_eq!(o.code, code, "{args:?}: exit code; stderr {:?}", o.stderr);
    assert_eq!(lines.len(), 1, "{args:?}: one stderr line: {:?}", o.stderr);
    let line = lines[0];
    assert!(line.starts_with("error: "), "{args:?}: {line}");
    assert!(!line.contains("panicked"), "{args:?}: {line}");
    for n in needles {
        assert!(line.contains(n), "{args:?}: {n:?} not in {line:?}");
    }
    assert!(
        o.stdout.is_empty(),
        "{args:?}: no work, no output: {:?}",
        o.stdout
    );
    assert!(
        o.elapsed < PROMPT,
        "{args:?}: refused after {:?}",
        o.elapsed
    );
    assert!(!out.exists(), "{args:?}: the output directory was created");
    line.to_string()
}

/// A usage refusal (exit 2) of `flag value`, naming both and the `range`.
fn out_of_range(dir: &Path, args: &[&str], flag: &str, value: &str, range: &str) {
    let line = refused(dir, args, 2, &[flag, value, range]);
    assert!(
        line.contains(&format!("{flag} {value} is out of range: allowed {range}")),
        "{line}"
    );
}

mod atlas;
mod files;
mod flags;
mod job;
mod place;
mod serial;
