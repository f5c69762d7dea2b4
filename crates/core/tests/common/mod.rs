//! A counting global allocator for the allocation tests. Each `*_alloc.rs` test binary
//! installs it with
//! `#[global_allocator] static GLOBAL: common::Counting = common::Counting;`
//! and calls [`watch_this_thread`] first: only allocations made by the test's own thread
//! count, so the test harness's threads (output capture, progress) cannot disturb it.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    // `const` initialiser and no destructor: reading it never allocates.
    static WATCHED: Cell<bool> = const { Cell::new(false) };
}

/// Counts the allocations of the calling thread from now on.
pub fn watch_this_thread() {
    WATCHED.with(|w| w.set(true));
}

fn count() {
    if WATCHED.with(Cell::get) {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
    }
}

/// Forwards to the system allocator and counts allocations and reallocations.
pub struct Counting;

// SAFETY: forwards every call unchanged to the system allocator; only counts.
#[allow(unsafe_code)] // reason: a global allocator is an unsafe trait by definition
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Allocations so far by watched threads.
pub fn allocations() -> usize {
    ALLOCATIONS.load(Ordering::SeqCst)
}

/// Proves the counter sees this thread's allocations (so a zero count means something).
pub fn assert_counter_works() {
    let before = allocations();
    let v: Vec<u8> = std::hint::black_box(Vec::with_capacity(64));
    drop(v);
    assert!(
        allocations() > before,
        "the counting allocator missed an allocation"
    );
}
