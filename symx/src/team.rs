//! [`Team`]: a fixed set of worker threads that run one borrowed job together with the
//! calling thread and return when all are done (an OpenMP-style parallel region).
//!
//! It exists for [`crate::Map`], whose evaluation must allocate nothing and hand work over
//! quickly: rayon's scopes box every spawned job, and its injector queue allocates a block
//! every 63 injections, so neither is allocation-free; a fresh `std::thread::scope` costs a
//! thread creation per call. Here the workers live as long as the team, the hand-over is
//! a generation counter (workers spin on it briefly after each job, then sleep on a
//! condition variable), and a job is a borrowed `&dyn Fn(usize)`: nothing is allocated
//! per run.
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long a worker polls for the next job, and the caller for the workers' end, before
/// sleeping: long enough to catch back-to-back runs and short jobs without a sleep and
/// wake-up (about 10 µs each on Linux), short enough not to burn a shared core.
const SPIN: Duration = Duration::from_micros(50);

/// Polls `done` until it holds or [`SPIN`] has passed; returns whether it holds. After a
/// short busy wait it yields between polls, so that a thread it waits for that shares its
/// core (a loaded machine) gets to run.
fn spin_until(done: impl Fn() -> bool) -> bool {
    for _ in 0..64 {
        if done() {
            return true;
        }
        std::hint::spin_loop();
    }
    let start = Instant::now();
    while start.elapsed() < SPIN {
        if done() {
            return true;
        }
        std::thread::yield_now();
    }
    done()
}

/// A job with its lifetime erased: only dereferenced between the start of
/// [`Team::run`] and the moment all workers have reported back, while the borrow lives.
#[derive(Clone, Copy)]
struct JobRef(*const (dyn Fn(usize) + Sync));

// SAFETY: the pointee is `Sync`, and `Team::run` keeps it alive while workers use it.
unsafe impl Send for JobRef {}

struct State {
    job: Option<JobRef>,
    /// Whether a worker's job panicked during the current run.
    panicked: bool,
    /// Workers that have started their loop.
    ready: usize,
    shutdown: bool,
}

struct Shared {
    state: Mutex<State>,
    /// Bumped (under the lock) for each run; workers poll it, then wait on `start`.
    generation: AtomicU64,
    /// Workers that have not yet finished the current job (decremented without the lock;
    /// the last one then takes the lock to notify `done`).
    pending: AtomicUsize,
    start: Condvar,
    done: Condvar,
    /// Serialises concurrent `run`s of one team (one job at a time).
    busy: Mutex<()>,
}

/// `workers` threads that run jobs handed over by [`Team::run`].
pub(crate) struct Team {
    shared: Arc<Shared>,
    handles: Vec<JoinHandle<()>>,
}

impl std::fmt::Debug for Team {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Team({} workers)", self.handles.len())
    }
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A poisoned lock only means a job panicked; the state itself stays consistent.
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl Team {
    /// Starts `workers` threads.
    pub fn new(workers: usize) -> std::io::Result<Team> {
        let shared = Arc::new(Shared {
            state: Mutex::new(State {
                job: None,
                panicked: false,
                ready: 0,
                shutdown: false,
            }),
            generation: AtomicU64::new(0),
            pending: AtomicUsize::new(0),
            start: Condvar::new(),
            done: Condvar::new(),
            busy: Mutex::new(()),
        });
        let mut team = Team {
            shared,
            handles: Vec::with_capacity(workers),
        };
        for index in 1..=workers {
            let shared = team.shared.clone();
            let handle = std::thread::Builder::new()
                .name(format!("symx-map-{index}"))
                .spawn(move || work(&shared, index))?;
            // On an error, dropping `team` stops the threads already started.
            team.handles.push(handle);
        }
        // Wait for the workers to be running, so that nothing of their start-up (which
        // allocates) happens during a later run.
        let mut s = lock(&team.shared.state);
        while s.ready < workers {
            s = team.shared.done.wait(s).unwrap_or_else(|e| e.into_inner());
        }
        drop(s);
        Ok(team)
    }

    /// Runs `job(0)` on the calling thread and `job(i)` on worker `i` (`1..=workers`),
    /// and returns when all have finished. Panics if a job panicked.
    pub fn run(&self, job: &(dyn Fn(usize) + Sync)) {
        let _busy = lock(&self.shared.busy);
        // SAFETY: erases the borrow's lifetime; `Wait` below does not let this function
        // return or unwind before every worker is done with the job.
        let erased: *const (dyn Fn(usize) + Sync + 'static) =
            unsafe { std::mem::transmute(job as *const (dyn Fn(usize) + Sync + '_)) };
        {
            let mut s = lock(&self.shared.state);
            s.job = Some(JobRef(erased));
            self.shared
                .pending
                .store(self.handles.len(), Ordering::Relaxed);
            s.panicked = false;
            self.shared.generation.fetch_add(1, Ordering::Release);
        }
        self.shared.start.notify_all();
        let wait = Wait(&self.shared);
        job(0);
        drop(wait);
        if lock(&self.shared.state).panicked {
            panic!("a symx map worker panicked");
        }
    }
}

/// Waits (also when the caller's own part unwinds) until all workers are done.
struct Wait<'a>(&'a Shared);

impl Drop for Wait<'_> {
    fn drop(&mut self) {
        let finished = || self.0.pending.load(Ordering::Acquire) == 0;
        spin_until(finished);
        let mut s = lock(&self.0.state);
        while !finished() {
            s = self.0.done.wait(s).unwrap_or_else(|e| e.into_inner());
        }
        s.job = None;
    }
}

impl Drop for Team {
    fn drop(&mut self) {
        lock(&self.shared.state).shutdown = true;
        self.shared.generation.fetch_add(1, Ordering::Release);
        self.shared.start.notify_all();
        for h in self.handles.drain(..) {
            let _ = h.join();
        }
    }
}

/// The loop of worker `index`: wait for a new generation, run the job, report.
fn work(shared: &Shared, index: usize) {
    let mut seen = 0u64;
    lock(&shared.state).ready += 1;
    shared.done.notify_all();
    loop {
        spin_until(|| shared.generation.load(Ordering::Acquire) != seen);
        let job = {
            let mut s = lock(&shared.state);
            while shared.generation.load(Ordering::Acquire) == seen && !s.shutdown {
                s = shared.start.wait(s).unwrap_or_else(|e| e.into_inner());
            }
            if s.shutdown {
                return;
            }
            seen = shared.generation.load(Ordering::Acquire);
            s.job
        };
        let Some(JobRef(f)) = job else {
            continue; // (not reached: a new generation without shutdown carries a job)
        };
        // SAFETY: `Team::run` keeps the job alive until `pending` reaches 0 below.
        let ok = catch_unwind(AssertUnwindSafe(|| unsafe { (*f)(index) })).is_ok();
        if !ok {
            lock(&shared.state).panicked = true;
        }
        if shared.pending.fetch_sub(1, Ordering::AcqRel) == 1 {
            // Under the lock, so that a caller between its check and its wait is not missed.
            let _s = lock(&shared.state);
            shared.done.notify_all();
        }
    }
}
