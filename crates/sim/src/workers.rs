//! Parallel runs and progress bars shared by the scenario commands: the simulated runs are
//! independent and deterministic, so they are spread over worker threads and their results
//! collected in job order, whatever the thread count.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicUsize, Ordering};

use indicatif::{ProgressBar, ProgressStyle};

use crate::SimError;

/// A progress bar of `len` steps labelled `msg` on stderr; hidden when stderr is not a
/// terminal or under CI (`CI` set to anything but empty, `false` or `0`).
pub fn progress(len: usize, msg: &str) -> ProgressBar {
    let hidden = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
        || !std::io::stderr().is_terminal();
    let pb = if hidden {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(len as u64)
    };
    if let Ok(style) =
        ProgressStyle::with_template("{msg:>14} [{bar:40}] {pos}/{len} {elapsed_precise}")
    {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_message(msg.to_string());
    pb
}

/// `f` applied to every item of `items` on up to `threads` worker threads (at least one),
/// each worker taking the next unstarted item; the results in the order of `items`. An error
/// only if a worker panicked.
pub fn parallel_map<T, R, F>(items: &[T], threads: usize, f: F) -> Result<Vec<R>, SimError>
where
    T: Sync,
    R: Send,
    F: Fn(&T) -> R + Sync,
{
    let next = AtomicUsize::new(0);
    let workers = threads.clamp(1, items.len().max(1));
    let worker = || {
        let mut done = Vec::new();
        loop {
            let k = next.fetch_add(1, Ordering::SeqCst);
            let Some(item) = items.get(k) else { break };
            done.push((k, f(item)));
        }
        done
    };
    let finished: Result<Vec<Vec<(usize, R)>>, _> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..workers).map(|_| s.spawn(worker)).collect();
        handles.into_iter().map(|h| h.join()).collect()
    });
    let finished = finished.map_err(|_| SimError::new("worker thread panicked"))?;
    let mut slots: Vec<Option<R>> = items.iter().map(|_| None).collect();
    for (k, r) in finished.into_iter().flatten() {
        if let Some(slot) = slots.get_mut(k) {
            *slot = Some(r);
        }
    }
    slots
        .into_iter()
        .map(|r| r.ok_or_else(|| SimError::new("job result missing")))
        .collect()
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::parallel_map;

    #[test]
    fn results_in_item_order_for_any_thread_count() {
        let items: Vec<u64> = (0..37).collect();
        let serial = parallel_map(&items, 1, |x| x * x).unwrap();
        for threads in [0, 2, 5, 64] {
            assert_eq!(parallel_map(&items, threads, |x| x * x).unwrap(), serial);
        }
        assert!(parallel_map(&[] as &[u64], 4, |x| *x).unwrap().is_empty());
    }

    #[test]
    fn a_panicking_job_is_an_error() {
        let r = parallel_map(&[1, 2, 3], 2, |x| {
            assert!(*x != 2, "job failed");
            *x
        });
        assert!(r.is_err());
    }
}
