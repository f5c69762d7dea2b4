//! The job's pass streamed: samples handed to the output files on a writer thread as they
//! come, with a progress bar on stderr.

use std::path::PathBuf;
use std::time::Instant;

use deflect_core::machining::job;
use deflect_sim::SimError;

use super::files::{JobFiles, OperationFigures};
use super::task::JobTask;
use crate::cli::JobArgs;

/// What the file writer returns: the operations' figures and the paths written.
type Written = (Vec<OperationFigures>, Vec<PathBuf>);

/// Runs the pass of a program of `duration` \[s\], streaming its samples to `files` on a
/// writer thread (two chunks in flight at most).
pub(super) fn stream_pass(
    a: &JobArgs,
    t: &JobTask,
    files: JobFiles,
    duration: f64,
) -> Result<(job::Report, Written), SimError> {
    let mut progress = Progress::new(duration);
    let run_options = job::RunOptions {
        threads: a.threads,
        ..job::RunOptions::default()
    };
    let (report, written) = std::thread::scope(|scope| {
        // Two chunks in flight at most: the writer's memory is bounded too.
        let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<job::JobSample>>(2);
        let writer = scope.spawn(move || -> Result<_, SimError> {
            let mut files = files;
            for chunk in rx {
                files.write(&chunk)?;
            }
            files.finish()
        });
        let mut sink = |chunk: &[job::JobSample]| -> Result<(), SimError> {
            if let Some(last) = chunk.last() {
                progress.at(last.path.time);
            }
            tx.send(chunk.to_vec())
                .map_err(|_| SimError::new("the file writer stopped"))
        };
        let run = job::run_streaming(&t.job, &t.program, &t.seed, &run_options, &mut sink);
        // The last sender gone, the writer's loop ends.
        drop(tx);
        let written = writer
            .join()
            .map_err(|_| SimError::new("the file writer panicked"))?;
        match (run, written) {
            (Ok(r), Ok(w)) => Ok((r, w)),
            // The writer's own error says more than the run's "writer stopped".
            (_, Err(e)) => Err(e),
            (Err(job::RunError::Job(e)), _) => {
                Err(SimError::new(format!("{}: {e}", t.program_name)))
            }
            (Err(job::RunError::Sink(e)), _) => Err(e),
        }
    })?;
    progress.done();
    Ok((report, written))
}

/// A progress bar over the program's duration \[s\] with its ETA on stderr: drawn once the
/// job has run a second, never when stderr is not a terminal or under CI.
struct Progress {
    bar: indicatif::ProgressBar,
    started: Instant,
    shown: bool,
    allowed: bool,
}

impl Progress {
    fn new(duration: f64) -> Self {
        use std::io::IsTerminal;
        let allowed = std::io::stderr().is_terminal()
            && !std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0");
        let bar = indicatif::ProgressBar::with_draw_target(
            Some((duration * 1e3).ceil().max(1.0) as u64),
            indicatif::ProgressDrawTarget::hidden(),
        );
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{msg} [{bar:40}] {percent:>3}% of the program, {elapsed_precise} (ETA {eta})",
        ) {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_message("job");
        Self {
            bar,
            started: Instant::now(),
            shown: false,
            allowed,
        }
    }

    fn at(&mut self, time: f64) {
        if self.allowed && !self.shown && self.started.elapsed().as_secs_f64() > 1.0 {
            self.shown = true;
            self.bar
                .set_draw_target(indicatif::ProgressDrawTarget::stderr());
        }
        self.bar.set_position((time * 1e3) as u64);
    }

    fn done(&self) {
        self.bar.finish_and_clear();
    }
}
