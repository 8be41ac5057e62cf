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

/// Allocations of one warm re-solve of a closed loop: with the solver's kept workspace,
/// by a fresh solver doing the same re-solve, and whether the kept one did more work than
/// any re-solve before it (so its vectors may grow).
#[derive(Clone, Copy, Debug)]
pub struct ReSolveCount {
    /// Allocations with the kept workspace.
    pub kept: usize,
    /// Allocations of a fresh solver doing the same re-solve.
    pub fresh: usize,
    /// The kept solver did more work than in any earlier re-solve.
    pub grew: bool,
}

/// Checks the allocation counts of a closed loop's warm re-solves (`counts[k]` is step
/// k + 1): every re-solve allocates less with the kept workspace than a fresh solver;
/// from the second re-solve on, one that did no more work than an earlier one allocates
/// nothing; at least half of them are such steady-state re-solves (else the test would
/// prove little). Prints a one-line summary under `label`; panics naming the step otherwise.
pub fn check_warm_re_solves(label: &str, counts: &[ReSolveCount]) {
    let mut zero_steps = 0;
    for (k, c) in counts.iter().enumerate() {
        let step = k + 1;
        assert!(
            c.kept < c.fresh,
            "{label} step {step}: {} allocations with the kept workspace, {} without",
            c.kept,
            c.fresh
        );
        if step >= 2 && !c.grew {
            assert_eq!(
                c.kept, 0,
                "{label} step {step}: allocations in a warm re-solve"
            );
            zero_steps += 1;
        }
    }
    assert!(
        zero_steps >= counts.len().div_ceil(2),
        "{label}: only {zero_steps} steady-state re-solves: {counts:?}"
    );
    let median = |mut v: Vec<usize>| {
        v.sort_unstable();
        v[v.len() / 2]
    };
    println!(
        "{label}: {} closed-loop steps bit-identical to a fresh solver's; allocations per \
         warm re-solve (median): {} kept ({zero_steps} re-solves with 0), {} fresh",
        counts.len(),
        median(counts.iter().map(|c| c.kept).collect()),
        median(counts.iter().map(|c| c.fresh).collect()),
    );
}
