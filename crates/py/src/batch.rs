//! The one batch runner of the bindings: the rows of a batch are split into contiguous
//! pieces that the threads (scoped, at most [`MAX_THREADS`], the calling thread one of them)
//! take in row order as they become free, each thread with its own workspace, and the first
//! failing row in row order is reported. The per-tick core stays
//! single-threaded and allocation-free; only this wrapper spreads it over threads.
//!
//! When to split is one threshold on the work, not on the row count: a batch goes on several
//! threads once its estimated single-threaded time, rows times the row's cost
//! ([`row_cost`]), reaches [`PARALLEL_MIN_NS`].

use core::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

use numpy::ndarray::{ArrayView2, s};

use deflect_core::TickError;
use pyo3::PyErr;

use crate::InputError;
use crate::errors::tick_err_at;

/// A batch is split over threads once its estimated single-threaded time reaches 1 ms.
/// Measured on a 2-core machine like CI's (`benches/batch_threads.py`, release wheel): just
/// past the threshold two threads take 0.92 ms for the 1.35 ms of 2,000 deflections (-32 %)
/// and 0.79 ms for 0.95 ms of 20,000 map queries (-17 %); the second thread's start, join
/// and shared caches cost 0.15-0.3 ms there, so well below 1 ms of work it gains nothing.
pub const PARALLEL_MIN_NS: f64 = 1.0e6;

/// Most threads one batch uses.
pub const MAX_THREADS: usize = 8;

/// Single-threaded cost of one row \[ns\] of each kind of batch, measured on the release
/// wheel (`benches/peers.py`, `benches/batch_threads.py`): what [`PARALLEL_MIN_NS`] is
/// compared against. Estimates, rounded to the slower end; a wrong estimate only moves the
/// row count at which threads start.
pub mod row_cost {
    /// One virtual-joint pass of a 6-axis arm (forward 0.22 us, compliance 0.7 us,
    /// deflection 0.7 us, single-threaded on the KR 300): threads from 2,000 rows.
    pub const VJM: f64 = 500.0;
    /// One compliance-map or displacement-field query (30-60 ns): threads from 20,000 rows.
    pub const MAP_QUERY: f64 = 50.0;
    /// One posture sweep over a full turn of tool angles (about a millisecond): two rows
    /// already share the work.
    pub const POSTURE_SWEEP: f64 = 1.0e6;
}

/// How a batch failed: a row's tick error, or a worker thread that panicked (a bug).
#[derive(Debug)]
pub enum BatchFailure {
    Row(usize, TickError),
    Panicked,
}

impl From<BatchFailure> for PyErr {
    /// The exception the single call would raise, naming the row.
    fn from(e: BatchFailure) -> Self {
        match e {
            BatchFailure::Row(i, e) => tick_err_at(format_args!("row {i}"), e),
            BatchFailure::Panicked => {
                InputError::new_err("internal: a batch worker thread panicked")
            }
        }
    }
}

/// Threads for `n` rows of `row_ns` each: one below [`PARALLEL_MIN_NS`] of work, else every
/// available core (at most [`MAX_THREADS`], at most one per row).
pub fn threads_for(n: usize, row_ns: f64) -> usize {
    if n < 2 || (n as f64) * row_ns < PARALLEL_MIN_NS {
        return 1;
    }
    std::thread::available_parallelism().map_or(1, |t| t.get().min(MAX_THREADS).min(n))
}

/// Pieces per thread of a threaded batch: each thread takes the next piece in row order
/// when it is free, so a core busy with something else does less of the batch instead of
/// holding it up (on a shared machine the second core comes and goes; with one chunk per
/// thread the batch waited for the slower one).
pub const PIECES_PER_THREAD: usize = 8;

/// Least estimated work of one piece \[ns\]: a piece's start (a lock, the chunk function's
/// own setup) stays small beside it.
pub const PIECE_MIN_NS: f64 = 5.0e4;

/// Fills `out` (rows of `width` numbers) piece by piece: `chunk(rows, workspace, out_rows)`
/// gets a contiguous range of rows and their slice of `out`, each thread its own
/// `workspace()` (made once per thread); a failure names the absolute row, the first in row
/// order. On several threads from [`PARALLEL_MIN_NS`] of estimated work (`row_ns` per row),
/// the calling thread one of them, the rows in pieces that free threads take in order.
pub fn chunks<W, M, F>(
    out: &mut [f64],
    width: usize,
    row_ns: f64,
    workspace: M,
    chunk: F,
) -> Result<(), BatchFailure>
where
    M: Fn() -> W + Sync,
    F: Fn(Range<usize>, &mut W, &mut [f64]) -> Result<(), (usize, TickError)> + Sync,
{
    let width = width.max(1);
    let n = out.len() / width;
    let threads = threads_for(n, row_ns);
    let run = |first: usize, w: &mut W, o: &mut [f64]| -> Result<(), BatchFailure> {
        let rows = first..first + o.len() / width;
        chunk(rows, w, o).map_err(|(row, e)| BatchFailure::Row(row, e))
    };
    if threads == 1 {
        return run(0, &mut workspace(), out);
    }
    // Whole groups of 8 rows per piece (the four-row kernels' groups stay whole).
    let by_work = ((n as f64) * row_ns / PIECE_MIN_NS) as usize;
    let pieces = (threads * PIECES_PER_THREAD).min(by_work).max(threads);
    let piece_rows = n.div_ceil(pieces).next_multiple_of(8);
    let queue = Mutex::new(out.chunks_mut(piece_rows * width).enumerate());
    // The lowest piece that failed: the pieces after it are skipped, the ones before it
    // (all handed out already) finish, so its first failing row is the batch's.
    let failed = AtomicUsize::new(usize::MAX);
    let worker = || -> Option<(usize, BatchFailure)> {
        let mut w = workspace();
        let mut first: Option<(usize, BatchFailure)> = None;
        loop {
            let next = queue.lock().unwrap_or_else(PoisonError::into_inner).next();
            let Some((k, o)) = next else {
                return first;
            };
            if k > failed.load(Ordering::Acquire) {
                continue;
            }
            if let Err(e) = run(k * piece_rows, &mut w, o) {
                failed.fetch_min(k, Ordering::AcqRel);
                if first.as_ref().is_none_or(|(j, _)| k < *j) {
                    first = Some((k, e));
                }
            }
        }
    };
    let outcomes: Vec<Option<(usize, BatchFailure)>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (1..threads).map(|_| scope.spawn(worker)).collect();
        let mine = worker();
        core::iter::once(mine)
            .chain(handles.into_iter().map(|h| {
                h.join()
                    .unwrap_or(Some((usize::MAX, BatchFailure::Panicked)))
            }))
            .collect()
    });
    match outcomes.into_iter().flatten().min_by_key(|(k, _)| *k) {
        Some((_, e)) => Err(e),
        None => Ok(()),
    }
}

/// [`chunks`] one row at a time: `row(i, workspace, out_row)` for every row `i`.
pub fn rows<W, M, F>(
    out: &mut [f64],
    width: usize,
    row_ns: f64,
    workspace: M,
    row: F,
) -> Result<(), BatchFailure>
where
    M: Fn() -> W + Sync,
    F: Fn(usize, &mut W, &mut [f64]) -> Result<(), TickError> + Sync,
{
    let width = width.max(1);
    chunks(out, width, row_ns, workspace, |rows, w, o| {
        for (i, oi) in rows.zip(o.chunks_mut(width)) {
            row(i, w, oi).map_err(|e| (i, e))?;
        }
        Ok(())
    })
}

/// Rows per block when a batch reads an argument that is not C-contiguous (a broadcast row,
/// a strided view): such an argument is copied one block at a time into the worker's
/// buffer, so that its memory stays 4,096 rows however long the batch (a broadcast view of
/// 1e10 rows costs nothing to create and must not cost 1e10 rows to read).
pub const BLOCK_ROWS: usize = 4096;

/// Rows `rows` of `a` as one row-major slice: borrowed when `a` is C-contiguous, else copied
/// into `buf` (at most [`BLOCK_ROWS`] rows by the callers).
pub fn block<'a, 'd: 'a>(
    a: &ArrayView2<'d, f64>,
    rows: Range<usize>,
    buf: &'a mut Vec<f64>,
) -> &'a [f64] {
    let v = (*a).slice_move(s![rows, ..]);
    if let Some(contiguous) = v.to_slice() {
        return contiguous;
    }
    buf.clear();
    buf.extend(v.iter().copied());
    buf
}

/// Row `i` of `a`: in place when `a` is C-contiguous (`rows` its slice, `a.as_slice()`),
/// else copied into `buf` through the row view (a broadcast or strided argument).
pub fn row_of<'a>(
    a: &ArrayView2<'_, f64>,
    rows: Option<&'a [f64]>,
    i: usize,
    buf: &'a mut Vec<f64>,
) -> &'a [f64] {
    let width = a.ncols();
    if let Some(r) = rows.and_then(|s| s.get(width * i..width * (i + 1))) {
        return r;
    }
    buf.clear();
    buf.extend(a.row(i).iter().copied());
    buf
}

/// The blocks of at most [`BLOCK_ROWS`] rows of `rows`, in order.
pub fn blocks(rows: Range<usize>) -> impl Iterator<Item = Range<usize>> {
    let end = rows.end;
    rows.step_by(BLOCK_ROWS)
        .map(move |start| start..(start + BLOCK_ROWS).min(end))
}
