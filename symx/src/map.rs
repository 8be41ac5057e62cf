//! [`Map`]: one compiled [`Function`] evaluated at many points (CasADi's `map`), serially
//! or split over threads with rayon.
use crate::error::SymxError;
use crate::function::Function;
use std::sync::Arc;

/// `n` evaluations of a function, each input and output holding the `n` points one after
/// the other (the layout of [`Function::eval_batch`]).
///
/// With [`Map::parallel`]`(t)`, the points are split into `t` contiguous chunks: the
/// calling thread evaluates the first, a rayon pool of `t − 1` threads owned by the map
/// the others, each chunk with its own part of the work vector. Every
/// point is computed by the same tape on the same numbers, so the results are
/// bit-identical whatever the number of threads.
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
    chunks: usize,
    pool: Option<Arc<rayon::ThreadPool>>,
}

impl Function {
    /// `n` evaluations of this function (serial; see [`Map::parallel`]).
    pub fn map(&self, n: usize) -> Map {
        Map {
            function: self.clone(),
            n,
            chunks: 1,
            pool: None,
        }
    }
}

impl Map {
    /// Splits the points over `threads` threads: the caller and a rayon pool of
    /// `threads − 1` built here (1 or 0: serial); `Err` if the operating system refuses
    /// the threads.
    pub fn parallel(mut self, threads: usize) -> Result<Map, SymxError> {
        self.chunks = threads.clamp(1, self.n.max(1));
        self.pool = if self.chunks > 1 {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(self.chunks - 1)
                .build()
                .map_err(|e| SymxError::Threads {
                    message: e.to_string(),
                })?;
            Some(Arc::new(pool))
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

    /// Length of the work vector [`Map::eval`] needs: one function work vector per chunk.
    pub fn work_size(&self) -> usize {
        self.chunks * self.function.work_size()
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
        let pool = match &self.pool {
            Some(pool) => pool,
            None => return f.eval_batch(inputs, outputs, work, self.n),
        };
        // Validate all sizes once, with the serial entry point's checks.
        f.check_batch(inputs, outputs, work, self.n)?;
        let per = self.n.div_ceil(self.chunks);
        let mut out_parts: Vec<Vec<&mut [f64]>> = (0..self.chunks).map(|_| Vec::new()).collect();
        for (y, &size) in outputs.iter_mut().zip(f.output_sizes()) {
            let mut rest: &mut [f64] = y;
            for part in out_parts.iter_mut() {
                let take = (per * size).min(rest.len());
                let (head, tail) = std::mem::take(&mut rest).split_at_mut(take);
                part.push(head);
                rest = tail;
            }
        }
        let w = f.work_size();
        let run = move |c: usize, mut outs: Vec<&mut [f64]>, work: &mut [f64]| {
            let first = c * per;
            let count = per.min(self.n.saturating_sub(first));
            if count == 0 {
                return;
            }
            let ins: Vec<&[f64]> = inputs
                .iter()
                .zip(f.input_sizes())
                .map(|(x, &size)| &x[first * size..(first + count) * size])
                .collect();
            f.eval_batch(&ins, &mut outs, work, count)
                .expect("sizes checked before splitting");
        };
        // The calling thread evaluates the first chunk itself while the pool's threads
        // evaluate the others (no hand-over of every chunk to sleeping workers).
        pool.in_place_scope(|s| {
            let mut jobs = out_parts
                .into_iter()
                .enumerate()
                .zip(work.chunks_mut(w.max(1)));
            let own = jobs.next();
            for ((c, outs), work) in jobs {
                s.spawn(move |_| run(c, outs, work));
            }
            if let Some(((c, outs), work)) = own {
                run(c, outs, work);
            }
        });
        Ok(())
    }
}
