//! [`Map`]: one compiled [`Function`] evaluated at many points (CasADi's `map`), serially
//! or split over threads.
use crate::error::SymxError;
use crate::function::{output_pointers, Function};
use crate::team::Team;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// `n` evaluations of a function, each input and output holding the `n` points one after
/// the other (the layout of [`Function::eval_batch`]).
///
/// With [`Map::parallel`]`(t)`, the calling thread and `t − 1` worker threads owned by the
/// map (started once, by `parallel`) share the points: thread `i` owns the `i`-th of `t`
/// contiguous ranges (the same at every call, so its data stays in its core's cache) and
/// evaluates it block by block; a thread done with its range takes the remaining blocks
/// of the others, so a thread slowed down by other work on the machine does less. Each
/// thread has its own part of the work vector, padded so that no two threads write the
/// same cache line. Every point is computed by the same
/// tape on the same numbers, so the results are bit-identical whatever the number of
/// threads. After [`Map::parallel`], [`Map::eval`] allocates nothing.
///
/// ```
/// use symx::{Function, Matrix};
/// let x = Matrix::sym_vec("x", 2);
/// let f = Function::new(&[&x], &[&[x[0] * x[1], x[0] + x[1]]]).unwrap();
/// let map = f.map(3).parallel(2).unwrap();
/// let xs = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
/// let mut ys = [0.0; 6];
/// let mut work = vec![0.0; map.work_size()];
/// map.eval(&[&xs], &mut [&mut ys], &mut work).unwrap();
/// assert_eq!(ys, [2.0, 3.0, 12.0, 7.0, 30.0, 11.0]);
/// ```
#[derive(Clone, Debug)]
pub struct Map {
    function: Function,
    n: usize,
    threads: usize,
    team: Option<Arc<Team>>,
    /// Per range, the first point not yet taken (reset by each parallel evaluation, which
    /// holds the lock throughout).
    next: Arc<Mutex<Vec<Padded>>>,
}

/// A counter alone on its cache lines (threads update different ranges' counters).
#[repr(align(128))]
#[derive(Debug, Default)]
struct Padded(AtomicUsize);

/// Gap (in numbers) between two threads' parts of the work vector: 128 bytes, the span of
/// the adjacent-line prefetcher, so threads never share or prefetch each other's lines.
const PAD: usize = 16;

/// Blocks each thread's range is cut into (the unit taken by a thread done early).
const BLOCKS_PER_RANGE: usize = 8;

/// Raw base pointers shared by the threads of one [`Map::eval`]; each thread writes only
/// its own points and its own part of the work vector through them.
struct Shared {
    outputs: *const *mut [f64],
    work: *mut f64,
}

// SAFETY: see `Shared`: accesses through the pointers are disjoint between threads, and
// `Team::run` returns only when all threads are done.
unsafe impl Sync for Shared {}

impl Function {
    /// `n` evaluations of this function (serial; see [`Map::parallel`]).
    pub fn map(&self, n: usize) -> Map {
        Map {
            function: self.clone(),
            n,
            threads: 1,
            team: None,
            next: Arc::default(),
        }
    }
}

impl Map {
    /// Splits the points over `threads` threads: the caller and `threads − 1` workers
    /// started here and kept by the map (1 or 0: serial; never more threads than points);
    /// `Err` if the operating system refuses the threads.
    pub fn parallel(mut self, threads: usize) -> Result<Map, SymxError> {
        self.threads = threads.clamp(1, self.n.max(1));
        self.team = if self.threads > 1 {
            let team = Team::new(self.threads - 1).map_err(|e| SymxError::Threads {
                message: e.to_string(),
            })?;
            self.next = Arc::new(Mutex::new(
                (0..self.threads).map(|_| Padded::default()).collect(),
            ));
            Some(Arc::new(team))
        } else {
            None
        };
        Ok(self)
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The function evaluated at each point.
    pub fn function(&self) -> &Function {
        &self.function
    }

    /// Number of threads evaluating (the caller included).
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Distance between two threads' parts of the work vector.
    fn stride(&self) -> usize {
        let w = self.function.work_size();
        if self.threads == 1 {
            w
        } else {
            w.next_multiple_of(8) + PAD
        }
    }

    /// Length of the work vector [`Map::eval`] needs: one function work vector per thread
    /// (padded when there are several).
    pub fn work_size(&self) -> usize {
        self.threads * self.stride()
    }

    /// Evaluates at all points: input `k` has `len() · input_sizes()[k]` numbers, and so
    /// does each output for its size; `work` at least [`Map::work_size`].
    pub fn eval(
        &self,
        inputs: &[&[f64]],
        outputs: &mut [&mut [f64]],
        work: &mut [f64],
    ) -> Result<(), SymxError> {
        let f = &self.function;
        if work.len() < self.work_size() {
            return Err(SymxError::Length {
                what: "work vector",
                index: 0,
                expected: self.work_size(),
                got: work.len(),
            });
        }
        let team = match &self.team {
            Some(team) => team,
            None => return f.eval_batch(inputs, outputs, work, self.n),
        };
        f.check_batch(inputs, outputs, work, self.n)?;
        let (n, t) = (self.n, self.threads);
        let range = |r: usize| (r * n / t, (r + 1) * n / t);
        let block = n.div_ceil(t * BLOCKS_PER_RANGE).max(1);
        let next = self.next.lock().unwrap_or_else(|e| e.into_inner());
        for (r, c) in next.iter().enumerate() {
            c.0.store(range(r).0, Ordering::Relaxed);
        }
        let shared = Shared {
            outputs: output_pointers(outputs),
            work: work.as_mut_ptr(),
        };
        let stride = self.stride();
        let job = |thread: usize| {
            let shared = &shared;
            // SAFETY: thread `thread` alone uses this part of the work vector.
            let w = unsafe { shared.work.add(thread * stride) };
            // Its own range first, then what is left of the others'.
            for r in (thread..t).chain(0..thread) {
                let end = range(r).1;
                loop {
                    let first = next[r].0.fetch_add(block, Ordering::Relaxed);
                    if first >= end {
                        break;
                    }
                    for p in first..(first + block).min(end) {
                        // SAFETY: sizes checked for all points; the counter gave point
                        // `p` to this thread alone.
                        unsafe { f.run(inputs, shared.outputs, w, p) };
                    }
                }
            }
        };
        team.run(&job);
        Ok(())
    }
}
