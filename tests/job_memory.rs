//! A streamed machining job's memory does not grow with its samples: the same program run
//! at a quarter of its feed (four times the samples, the same moves and stock) peaks at the
//! same allocation, which is the three z-maps, the program's plan and one chunk of samples.
//! A counting allocator (this test binary's own) measures the peak and counts the
//! allocations, which do not grow with the samples either (nothing allocated per sample);
//! one thread, so nothing else allocates meanwhile.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use deflect_core::machining::job::{self, Job, JobSample, RunOptions};
use deflect_tests::{JOB_SEED, job_setup, kr300, programs, read_mm};
use nalgebra::Vector2;

struct Counting;

static NOW: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
static COUNT: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards every call unchanged to the system allocator; only counts.
#[allow(unsafe_code)] // reason: a global allocator is an unsafe trait by definition
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded to the system allocator with the caller's layout.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            COUNT.fetch_add(1, Ordering::SeqCst);
            let now = NOW.fetch_add(layout.size(), Ordering::SeqCst) + layout.size();
            PEAK.fetch_max(now, Ordering::SeqCst);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` was allocated by `alloc` above with this layout.
        unsafe { System.dealloc(ptr, layout) };
        NOW.fetch_sub(layout.size(), Ordering::SeqCst);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The peak allocation above what was allocated before, the allocations, and the samples,
/// of a streamed run.
fn run(job: &Job, feed_scale: f64) -> (usize, usize, usize) {
    let text = programs::sloped_zigzag(4, 6.0, 0.5, 2.0, 0.01)
        .replace("F508", &format!("F{:.1}", 508.0 * feed_scale));
    let program = read_mm(&text);
    let options = RunOptions {
        chunk: 256,
        threads: 1,
    };
    let mut count = 0usize;
    let mut sink = |c: &[JobSample]| -> Result<(), std::convert::Infallible> {
        count += c.len();
        Ok(())
    };
    let base = NOW.load(Ordering::SeqCst);
    PEAK.store(base, Ordering::SeqCst);
    let allocations = COUNT.load(Ordering::SeqCst);
    let r = job::run_streaming(job, &program, &JOB_SEED, &options, &mut sink).unwrap();
    let peak = PEAK.load(Ordering::SeqCst) - base;
    let allocations = COUNT.load(Ordering::SeqCst) - allocations;
    assert!(r.path_error(true).max < 1e-6);
    drop(r);
    (peak, allocations, count)
}

#[test]
fn a_streamed_job_peaks_at_the_same_memory_for_four_times_the_samples() {
    let robot = kr300();
    let setup = job_setup(
        Vector2::new(-0.01, -0.01),
        Vector2::new(0.016, 0.012),
        5.0e-4,
    );
    let job = Job::new(robot.model.clone(), &robot.joint_limits, setup).unwrap();
    let (peak, allocations, n) = run(&job, 1.0);
    let (peak4, allocations4, n4) = run(&job, 0.25);
    assert!(n4 > 3 * n, "{n} {n4}");
    // Nothing is allocated per sample (nor per chunk): the same allocations for four times
    // the samples, give or take the summary's per-line map.
    assert!(
        allocations4 <= allocations + 8,
        "{n} samples: {allocations} allocations; {n4} samples: {allocations4}"
    );
    // The same peak within a few kilobytes (allocator rounding, the plan's equal size).
    assert!(
        peak4 <= peak + 4096,
        "{n} samples: {peak} B; {n4} samples: {peak4} B"
    );
    // What it is: three z-maps (52 x 44 cells), a chunk of samples in three stages and the
    // sink's, the tools' probes and weights, the plan.
    let cells = 52 * 44 * 8 * 3;
    let chunk = 256 * (std::mem::size_of::<JobSample>() + 2 * 400 + 600);
    assert!(peak < cells + chunk + 256 * 1024, "{peak} B");
}
