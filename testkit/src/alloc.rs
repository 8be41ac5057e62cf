//! Counting global allocators, for tests that a span of code allocates nothing (or less).
//!
//! A `#[global_allocator]` must be declared in the test binary itself; this module gives
//! the types and their counters:
//!
//! ```ignore
//! use testkit::alloc::Counting;
//!
//! #[global_allocator]
//! static GLOBAL: Counting = Counting;
//!
//! let (_, count) = Counting::during(|| map.eval(&inputs, &mut outputs, &mut work));
//! assert_eq!(count, 0);
//! ```
//!
//! [`Counting`] counts on every thread of the process (a parallel evaluation's workers
//! included), so its binary must run without libtest's harness (`harness = false`: the
//! harness's main thread allocates while a test runs). [`ThreadCounting`] counts only on
//! the thread that opened the span, so it works under the harness.
//!
//! Each `during` first checks that its type is the global allocator (an allocation
//! inside the span must be counted) and panics otherwise: a test whose allocator was
//! never installed would count zero and could not fail.
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Counts allocations and reallocations on every thread while a [`Counting::during`] span
/// is open; delegates to the system allocator.
pub struct Counting;

static ACTIVE: AtomicBool = AtomicBool::new(false);
static COUNT: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded unchanged to `System`; counting touches only atomics.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if ACTIVE.load(Ordering::SeqCst) {
            COUNT.fetch_add(1, Ordering::SeqCst);
        }
        System.alloc(layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if ACTIVE.load(Ordering::SeqCst) {
            COUNT.fetch_add(1, Ordering::SeqCst);
        }
        System.realloc(ptr, layout, new_size)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

impl Counting {
    /// Runs `f` and returns its result with the number of allocations (and reallocations)
    /// made on any thread meanwhile. Panics if [`Counting`] is not the global allocator.
    pub fn during<T>(f: impl FnOnce() -> T) -> (T, usize) {
        let span = |f: &mut dyn FnMut()| {
            COUNT.store(0, Ordering::SeqCst);
            ACTIVE.store(true, Ordering::SeqCst);
            f();
            ACTIVE.store(false, Ordering::SeqCst);
            COUNT.load(Ordering::SeqCst)
        };
        let probe = span(&mut || drop(std::hint::black_box(vec![1u8; 10])));
        assert!(
            probe > 0,
            "testkit::alloc::Counting is not the #[global_allocator]"
        );
        let mut f = Some(f);
        let mut out = None;
        let count = span(&mut || out = f.take().map(|f| f()));
        (out.expect("the span ran"), count)
    }
}

/// Counts allocations and reallocations on the thread of an open [`ThreadCounting::during`]
/// span only; delegates to the system allocator.
pub struct ThreadCounting;

thread_local! {
    static THREAD_ACTIVE: Cell<bool> = const { Cell::new(false) };
    static THREAD_COUNT: Cell<usize> = const { Cell::new(0) };
}

fn count_on_this_thread() {
    if THREAD_ACTIVE.with(Cell::get) {
        THREAD_COUNT.with(|c| c.set(c.get() + 1));
    }
}

// SAFETY: every call is forwarded unchanged to `System`; counting touches only
// const-initialised thread-locals (no allocation, no destructor).
unsafe impl GlobalAlloc for ThreadCounting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_on_this_thread();
        System.alloc(layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_on_this_thread();
        System.realloc(ptr, layout, new_size)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

impl ThreadCounting {
    /// Runs `f` and returns its result with the number of allocations (and reallocations)
    /// this thread made meanwhile. Panics if [`ThreadCounting`] is not the global
    /// allocator.
    pub fn during<T>(f: impl FnOnce() -> T) -> (T, usize) {
        let span = |f: &mut dyn FnMut()| {
            THREAD_COUNT.with(|c| c.set(0));
            THREAD_ACTIVE.with(|a| a.set(true));
            f();
            THREAD_ACTIVE.with(|a| a.set(false));
            THREAD_COUNT.with(Cell::get)
        };
        let probe = span(&mut || drop(std::hint::black_box(vec![1u8; 10])));
        assert!(
            probe > 0,
            "testkit::alloc::ThreadCounting is not the #[global_allocator]"
        );
        let mut f = Some(f);
        let mut out = None;
        let count = span(&mut || out = f.take().map(|f| f()));
        (out.expect("the span ran"), count)
    }
}
