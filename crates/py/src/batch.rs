//! Row batches on every core: the rows of a batch are split into one contiguous chunk per
//! thread (scoped threads, at most [`MAX_THREADS`]), each thread with its own workspace, and
//! the first failing row in row order is reported. The per-tick core stays single-threaded
//! and allocation-free; only the batch wrapper spreads it over threads.

use deflect_core::TickError;

/// Batches of at least this many rows are split over threads (below, thread start-up costs
/// more than it saves: a thread costs ~20 us, a VJM row ~0.5 us).
pub const PARALLEL_MIN_ROWS: usize = 2048;

/// Most threads one batch uses.
pub const MAX_THREADS: usize = 8;

/// How a batch failed: a row's tick error, or a worker thread that panicked (a bug).
pub enum BatchFailure {
    Row(usize, TickError),
    Panicked,
}

/// Threads for `n` rows: one below `min_rows`, else every available core (at most
/// [`MAX_THREADS`], at most one per row).
pub fn threads_for(n: usize, min_rows: usize) -> usize {
    if n < min_rows.max(2) {
        return 1;
    }
    std::thread::available_parallelism().map_or(1, |t| t.get().min(MAX_THREADS).min(n))
}

/// Fills `out` (n rows of `width` numbers) by `row(i, workspace, out_row)` for every row
/// `i`, each thread with its own `workspace()`, on several threads from `min_rows` rows
/// ([`PARALLEL_MIN_ROWS`] for rows of a microsecond; fewer for costlier rows).
pub fn rows<W, M, F>(
    out: &mut [f64],
    width: usize,
    min_rows: usize,
    workspace: M,
    row: F,
) -> Result<(), BatchFailure>
where
    M: Fn() -> W + Sync,
    F: Fn(usize, &mut W, &mut [f64]) -> Result<(), TickError> + Sync,
{
    let width = width.max(1);
    let n = out.len() / width;
    let threads = threads_for(n, min_rows);
    let chunk_rows = n.div_ceil(threads).max(1);
    let run = |first: usize, chunk: &mut [f64]| -> Result<(), BatchFailure> {
        let mut w = workspace();
        for (k, o) in chunk.chunks_mut(width).enumerate() {
            row(first + k, &mut w, o).map_err(|e| BatchFailure::Row(first + k, e))?;
        }
        Ok(())
    };
    if threads == 1 {
        return run(0, out);
    }
    let results: Vec<Result<(), BatchFailure>> = std::thread::scope(|scope| {
        let handles: Vec<_> = out
            .chunks_mut(chunk_rows * width)
            .enumerate()
            .map(|(c, chunk)| {
                let run = &run;
                scope.spawn(move || run(c * chunk_rows, chunk))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or(Err(BatchFailure::Panicked)))
            .collect()
    });
    // Chunks are in row order: the first error is the first failing row.
    results.into_iter().collect()
}
