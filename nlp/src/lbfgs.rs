//! Limited-memory quasi-Newton approximation of the Lagrangian Hessian (IPOPT's
//! `hessian_approximation = limited-memory`; the rules follow IPOPT's
//! LimMemQuasiNewtonUpdater) in the compact form of Byrd, Nocedal & Schnabel,
//! "Representations of quasi-Newton matrices and their use in limited memory methods",
//! Math. Prog. 63:129–156, 1994:
//!
//! ```text
//! BFGS (eq. 2.17):  B = σI − [σS Y] [σSᵀS  L; Lᵀ  −D]⁻¹ [σS Y]ᵀ
//! SR1  (eq. 5.2):   B = σI + (Y − σS) (D + L + Lᵀ − σSᵀS)⁻¹ (Y − σS)ᵀ
//! ```
//!
//! with S, Y the stored pairs (oldest first), D = diag(sᵢᵀyᵢ) and L the strictly lower
//! part of SᵀY. Both are B = σI + V N⁻¹ Vᵀ ([`LowRankTerm`]), which the KKT system
//! handles by Sherman–Morrison–Woodbury (`crate::kkt::LowRankKkt`).
//!
//! Pairs: s = x₊ − x, y = ∇ₓL(x₊, λ₊) − ∇ₓL(x, λ₊) (the new multipliers on both sides).
//! A pair is skipped when ‖s‖∞ < 100ε, or (BFGS) when sᵀy ≤ √ε‖s‖‖y‖, or (SR1) when
//! |sᵀ(y − Bs)| ≤ √ε‖s‖‖y − Bs‖; after `limited_memory_max_skipping` skips in a row the
//! memory is reset to B = `limited_memory_init_val`·I. σ follows
//! `limited_memory_initialization` from the newest pair, clamped to
//! [`limited_memory_init_val_min`, `limited_memory_init_val_max`].

#![allow(clippy::needless_range_loop)]

use std::collections::VecDeque;

use faer::sparse::SymbolicSparseColMat;
use faer::Mat;

use crate::kkt::{Inertia, Kkt, KktError, LowRankKkt, LowRankTerm};
use crate::options::{IpmHessian, IpmOptions, LimitedMemoryInit, LimitedMemoryUpdate};

/// The settings of the limited-memory approximation (copied from [`IpmOptions`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settings {
    pub max_history: usize,
    pub update: LimitedMemoryUpdate,
    pub init: LimitedMemoryInit,
    pub init_val: f64,
    pub init_val_min: f64,
    pub init_val_max: f64,
    pub max_skipping: usize,
}

impl Settings {
    pub(crate) fn from_options(o: &IpmOptions) -> Settings {
        Settings {
            max_history: o.limited_memory_max_history,
            update: o.limited_memory_update_type,
            init: o.limited_memory_initialization,
            init_val: o.limited_memory_init_val,
            init_val_min: o.limited_memory_init_val_min,
            init_val_max: o.limited_memory_init_val_max,
            max_skipping: o.limited_memory_max_skipping,
        }
    }
}

/// The point of the previous update.
#[derive(Debug, Clone)]
struct Last {
    x: Vec<f64>,
    grad: Vec<f64>,
    jac: Vec<f64>,
}

/// What one call of [`LimitedMemory::update`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum UpdateKind {
    /// First point, or the memory was reset after too many skips: B = init_val·I.
    Reset,
    /// A pair was added.
    Updated,
    /// The pair was rejected; B is unchanged.
    Skipped,
    /// The point is the previous one: nothing to do.
    Unchanged,
}

/// The stored pairs, σ and the compact representation of B.
#[derive(Debug, Clone)]
pub(crate) struct LimitedMemory {
    set: Settings,
    n: usize,
    s: VecDeque<Vec<f64>>,
    y: VecDeque<Vec<f64>>,
    sigma: f64,
    last: Option<Last>,
    skipped: usize,
    term: LowRankTerm,
    jty: Vec<f64>,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm2(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// out = Jᵀ λ for a Jacobian with CSC pattern `pat` and values `jac`.
fn jac_t_times(pat: &SymbolicSparseColMat<usize>, jac: &[f64], lambda: &[f64], out: &mut [f64]) {
    for (j, o) in out.iter_mut().enumerate() {
        *o = pat
            .col_range(j)
            .map(|p| jac[p] * lambda[pat.row_idx()[p]])
            .sum();
    }
}

impl LimitedMemory {
    /// An empty memory for n variables (B = init_val·I).
    pub(crate) fn new(n: usize, set: Settings) -> LimitedMemory {
        LimitedMemory {
            set,
            n,
            s: VecDeque::new(),
            y: VecDeque::new(),
            sigma: set.init_val,
            last: None,
            skipped: 0,
            term: LowRankTerm::diagonal(n, set.init_val),
            jty: vec![0.0; n],
        }
    }

    /// The current approximation B = σI + V N⁻¹ Vᵀ.
    pub(crate) fn term(&self) -> &LowRankTerm {
        &self.term
    }

    /// Number of stored pairs.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.s.len()
    }

    /// Updates B with the pair from the previous point to `x` (gradient `grad`,
    /// Jacobian values `jac` in `pat` order), both sides with the multipliers `lambda`.
    pub(crate) fn update(
        &mut self,
        x: &[f64],
        grad: &[f64],
        jac: &[f64],
        pat: &SymbolicSparseColMat<usize>,
        lambda: &[f64],
    ) -> UpdateKind {
        let Some(last) = self
            .last
            .as_mut()
            .filter(|_| self.skipped < self.set.max_skipping)
        else {
            self.s.clear();
            self.y.clear();
            self.skipped = 0;
            self.sigma = self.set.init_val;
            self.term = LowRankTerm::diagonal(self.n, self.sigma);
            self.last = Some(Last {
                x: x.to_vec(),
                grad: grad.to_vec(),
                jac: jac.to_vec(),
            });
            return UpdateKind::Reset;
        };
        let n = self.n;
        if x == &last.x[..] {
            // The same point evaluated again (the core re-evaluates after its initial
            // least-squares multipliers): not a new iterate, so no pair and no skip
            // (IPOPT updates once per iteration).
            return UpdateKind::Unchanged;
        }
        let s: Vec<f64> = (0..n).map(|j| x[j] - last.x[j]).collect();
        // y = ∇f₊ − ∇f + (J₊ − J)ᵀ λ₊.
        jac_t_times(pat, jac, lambda, &mut self.jty);
        let mut y: Vec<f64> = (0..n)
            .map(|j| grad[j] - last.grad[j] + self.jty[j])
            .collect();
        jac_t_times(pat, &last.jac, lambda, &mut self.jty);
        for (yj, v) in y.iter_mut().zip(&self.jty) {
            *yj -= v;
        }
        last.x.copy_from_slice(x);
        last.grad.copy_from_slice(grad);
        last.jac.copy_from_slice(jac);
        let kind = if self.accept(&s, &y) {
            self.add_pair(s, y);
            UpdateKind::Updated
        } else {
            UpdateKind::Skipped
        };
        if kind == UpdateKind::Skipped {
            self.skipped += 1;
        } else {
            self.skipped = 0;
        }
        kind
    }

    /// The skipping tests.
    fn accept(&self, s: &[f64], y: &[f64]) -> bool {
        let tol = f64::EPSILON.sqrt();
        let s_max = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let finite = s_max.is_finite() && y.iter().all(|v| v.is_finite());
        if !finite || s_max < 100.0 * f64::EPSILON {
            return false;
        }
        match self.set.update {
            LimitedMemoryUpdate::Bfgs => dot(s, y) > tol * norm2(s) * norm2(y),
            LimitedMemoryUpdate::Sr1 => {
                let mut bs = vec![0.0; self.n];
                self.term.apply(s, &mut bs);
                let r: Vec<f64> = y.iter().zip(&bs).map(|(a, b)| a - b).collect();
                dot(s, &r).abs() > tol * norm2(s) * norm2(&r)
            }
        }
    }

    /// σ from the newest pair by the initialisation rule, clamped.
    fn sigma_from(&self, s: &[f64], y: &[f64]) -> f64 {
        let mut sty = dot(s, y);
        if self.set.update == LimitedMemoryUpdate::Sr1 {
            // IPOPT: the first SR1 pair keeps init_val (a σ from it would make the next
            // pair fail the skipping test), later ones use max(1e-8, |sᵀy|).
            if self.s.is_empty() {
                return self.set.init_val;
            }
            sty = sty.abs().max(1e-8);
        }
        let s1 = sty / dot(s, s);
        let s2 = dot(y, y) / sty;
        let sigma = match self.set.init {
            LimitedMemoryInit::Scalar1 => s1,
            LimitedMemoryInit::Scalar2 => s2,
            LimitedMemoryInit::Scalar3 => 0.5 * (s1 + s2),
            LimitedMemoryInit::Scalar4 => (s1 * s2).sqrt(),
            LimitedMemoryInit::Constant => self.set.init_val,
        };
        if sigma.is_nan() {
            return self.set.init_val_min;
        }
        sigma.clamp(self.set.init_val_min, self.set.init_val_max)
    }

    /// Stores the pair (dropping the oldest beyond the history), sets σ and rebuilds the
    /// compact form; pairs are dropped oldest first while N is singular.
    fn add_pair(&mut self, s: Vec<f64>, y: Vec<f64>) {
        self.sigma = self.sigma_from(&s, &y);
        if self.set.max_history == 0 {
            self.term = LowRankTerm::diagonal(self.n, self.sigma);
            return;
        }
        if self.s.len() == self.set.max_history {
            self.s.pop_front();
            self.y.pop_front();
        }
        self.s.push_back(s);
        self.y.push_back(y);
        loop {
            if let Some(t) = self.compact() {
                self.term = t;
                return;
            }
            self.s.pop_front();
            self.y.pop_front();
        }
    }

    /// The compact form of the stored pairs with the current σ (`None`: N singular).
    fn compact(&self) -> Option<LowRankTerm> {
        let k = self.s.len();
        if k == 0 {
            return Some(LowRankTerm::diagonal(self.n, self.sigma));
        }
        let sig = self.sigma;
        let sty = |i: usize, j: usize| dot(&self.s[i], &self.y[j]);
        let sts = |i: usize, j: usize| dot(&self.s[i], &self.s[j]);
        match self.set.update {
            LimitedMemoryUpdate::Bfgs => {
                // V = [σS, Y], N = −[σSᵀS, L; Lᵀ, −D].
                let mut cols = Vec::with_capacity(2 * k);
                cols.extend(self.s.iter().map(|s| s.iter().map(|v| sig * v).collect()));
                cols.extend(self.y.iter().cloned());
                let mut nm = Mat::<f64>::zeros(2 * k, 2 * k);
                for i in 0..k {
                    for j in 0..k {
                        nm[(i, j)] = -sig * sts(i, j);
                        if i > j {
                            nm[(i, k + j)] = -sty(i, j);
                            nm[(k + j, i)] = -sty(i, j);
                        }
                    }
                    nm[(k + i, k + i)] = sty(i, i);
                }
                LowRankTerm::new(self.n, sig, cols, &nm)
            }
            LimitedMemoryUpdate::Sr1 => {
                // V = Y − σS, N = D + L + Lᵀ − σSᵀS.
                let cols = self
                    .s
                    .iter()
                    .zip(&self.y)
                    .map(|(s, y)| y.iter().zip(s).map(|(a, b)| a - sig * b).collect())
                    .collect();
                let mut nm = Mat::<f64>::zeros(k, k);
                for i in 0..k {
                    for j in 0..k {
                        let l = if i >= j { sty(i, j) } else { sty(j, i) };
                        nm[(i, j)] = l - sig * sts(i, j);
                    }
                }
                LowRankTerm::new(self.n, sig, cols, &nm)
            }
        }
    }
}

/// The limited-memory Hessian inside the interior-point iteration: the memory and the
/// low-rank KKT solver, behind the three calls the core makes (update where it would
/// evaluate the Hessian, factorise, solve).
#[derive(Debug)]
pub(crate) struct LimitedMemoryHessian {
    memory: LimitedMemory,
    solver: LowRankKkt,
}

impl LimitedMemoryHessian {
    /// `Some` when the options ask for the limited-memory Hessian.
    pub(crate) fn from_options(opts: &IpmOptions, n: usize) -> Option<LimitedMemoryHessian> {
        (opts.hessian_approximation == IpmHessian::LimitedMemory).then(|| LimitedMemoryHessian {
            memory: LimitedMemory::new(n, Settings::from_options(opts)),
            solver: LowRankKkt::default(),
        })
    }

    /// See [`LimitedMemory::update`].
    pub(crate) fn update(
        &mut self,
        x: &[f64],
        grad: &[f64],
        jac: &[f64],
        pat: &SymbolicSparseColMat<usize>,
        lambda: &[f64],
    ) -> UpdateKind {
        self.memory.update(x, grad, jac, pat, lambda)
    }

    /// Factorises the KKT matrix with Hessian block `hess` + diag(dx) + B.
    pub(crate) fn factorize(
        &mut self,
        kkt: &mut Kkt,
        hess: &[f64],
        dx: &[f64],
        jac: &[f64],
        dc: &[f64],
    ) -> Result<Inertia, KktError> {
        self.solver
            .factorize(kkt, self.memory.term(), hess, dx, jac, dc)
    }

    /// Solves the last factorised system (+ diag(shift)) in place.
    pub(crate) fn solve_shifted(
        &mut self,
        kkt: &mut Kkt,
        rhs: &mut [f64],
        shift: Option<&[f64]>,
    ) -> Result<f64, KktError> {
        self.solver.solve_shifted(kkt, rhs, shift)
    }
}

#[cfg(test)]
mod tests;
