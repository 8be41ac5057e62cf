//! Assembly, factorisation (LDLᵀ without pivoting: faer's supernodal one, or our own
//! simplicial one on faer's symbolic analysis), inertia and solution of the symmetric
//! quasi-definite KKT system
//!
//! ```text
//! K = [ W + diag(dx)   Jᵀ         ]
//!     [ J             −diag(dc)   ]
//! ```
//!
//! The pattern, the AMD ordering and the symbolic factorisation are computed once in
//! [`Kkt::new`]; every [`Kkt::factorize`] only scatters values through precomputed maps.
//! When faer's analysis picks the simplicial factorisation, K is stored already permuted
//! and factorised by `Simplicial` (up-looking LDLᵀ with the rows of L precomputed).
//! faer has no inertia API, so the inertia is counted from the signs of D (Sylvester's law
//! of inertia). Unpivoted LDLᵀ needs `dc > 0` on every row (see docs/dependencies.md).

#![allow(clippy::needless_range_loop)]

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltParams, LdltRegularization};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side, Spec};
use thiserror::Error;

mod low_rank;
pub(crate) use low_rank::{LowRankKkt, LowRankTerm};

/// Numbers of positive, negative and zero eigenvalues.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Inertia {
    /// Positive eigenvalues.
    pub positive: usize,
    /// Negative eigenvalues.
    pub negative: usize,
    /// Zero eigenvalues.
    pub zero: usize,
}

/// KKT errors. `ZeroPivot` and `NonFinite` mean "singular: increase the regularisation".
#[derive(Debug, Clone, PartialEq, Error)]
pub enum KktError {
    /// A pattern has the wrong shape or content.
    #[error("invalid KKT pattern: {0}")]
    Pattern(String),
    /// A value vector has the wrong length.
    #[error("wrong length of {what}: expected {expected}, got {got}")]
    Length {
        /// Which vector.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// faer's symbolic analysis failed.
    #[error("symbolic factorisation failed: {0}")]
    Symbolic(String),
    /// Exactly zero pivot.
    #[error("zero pivot at (permuted) index {0}")]
    ZeroPivot(usize),
    /// A non-finite value in the matrix or in D.
    #[error("non-finite value in the KKT matrix or its factor")]
    NonFinite,
    /// `solve` was called without a successful factorisation.
    #[error("no valid factorisation")]
    NotFactorized,
}

/// Which faer numeric factorisation the symbolic analysis selects (the solvers use
/// `Auto`; the forced kinds are compared in the unit tests).
#[cfg_attr(not(test), allow(dead_code))]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KktFactorization {
    /// Supernodal (dense blocks; fastest when the factor has large dense parts).
    Supernodal,
    /// Simplicial (column by column; our own up-looking LDLᵀ on faer's analysis).
    Simplicial,
    /// Let faer decide from the flop ratio (the default). Measured on the gap-crossing
    /// crawl gait (n + m = 2678, 33 k factor entries) it picks simplicial, 2.5× faster
    /// than forced supernodal; on a 35 000-row KKT it picks supernodal, 30× faster than
    /// forced simplicial.
    #[default]
    Auto,
}

/// Reusable KKT system: pattern, symbolic factorisation, numeric factor and work space.
pub struct Kkt {
    n: usize,
    m: usize,
    pattern: SymbolicSparseColMat<usize>,
    values: Vec<f64>,
    h_map: Vec<usize>,
    j_map: Vec<usize>,
    diag_pos: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    /// Our own simplicial LDLᵀ (used when faer's analysis picks simplicial); `None` for
    /// supernodal, which stays with faer.
    simplicial: Option<Simplicial>,
    mem: MemBuffer,
    factored: bool,
    wx: Vec<f64>,
    wr: Vec<f64>,
    wd: Vec<f64>,
    wb: Vec<f64>,
    /// Minimum number of iterative-refinement steps (default 1).
    pub min_refinement_steps: usize,
    /// Maximum number of iterative-refinement steps (default 10).
    pub max_refinement_steps: usize,
    /// Target relative residual (default 1e-12).
    pub residual_ratio_max: f64,
    last_residual_ratio: f64,
}

impl std::fmt::Debug for Kkt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Kkt")
            .field("n", &self.n)
            .field("m", &self.m)
            .field("nnz", &self.values.len())
            .field("len_l", &self.l_values.len())
            .finish()
    }
}

impl Kkt {
    /// Builds the KKT pattern from the lower-triangular Hessian pattern (n×n) and the
    /// Jacobian pattern (m×n) and performs the symbolic analysis (AMD ordering;
    /// simplicial or supernodal as faer's flop-ratio heuristic chooses, see
    /// [`KktFactorization::Auto`]).
    pub fn new(
        n: usize,
        m: usize,
        hess_lower: &SymbolicSparseColMat<usize>,
        jac: &SymbolicSparseColMat<usize>,
    ) -> Result<Kkt, KktError> {
        Self::with_factorization(n, m, hess_lower, jac, KktFactorization::Auto)
    }

    /// As [`Kkt::new`] with a chosen factorisation kind.
    pub fn with_factorization(
        n: usize,
        m: usize,
        hess_lower: &SymbolicSparseColMat<usize>,
        jac: &SymbolicSparseColMat<usize>,
        kind: KktFactorization,
    ) -> Result<Kkt, KktError> {
        if hess_lower.nrows() != n || hess_lower.ncols() != n {
            return Err(KktError::Pattern(format!(
                "Hessian pattern is {}x{}, expected {n}x{n}",
                hess_lower.nrows(),
                hess_lower.ncols()
            )));
        }
        if jac.nrows() != m || jac.ncols() != n {
            return Err(KktError::Pattern(format!(
                "Jacobian pattern is {}x{}, expected {m}x{n}",
                jac.nrows(),
                jac.ncols()
            )));
        }
        let dim = n + m;
        // Rows of each column of the upper triangle of K.
        let mut cols: Vec<Vec<usize>> = (0..dim).map(|j| vec![j]).collect();
        for c in 0..n {
            for &r in hess_lower.row_idx_of_col_raw(c) {
                if r < c {
                    return Err(KktError::Pattern(format!(
                        "Hessian pattern entry ({r}, {c}) is above the diagonal; give the lower triangle"
                    )));
                }
                cols[r].push(c);
            }
        }
        for c in 0..n {
            for &r in jac.row_idx_of_col_raw(c) {
                cols[n + r].push(c);
            }
        }
        let mut col_ptr = Vec::with_capacity(dim + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0usize);
        for col in cols.iter_mut() {
            col.sort_unstable();
            col.dedup();
            row_idx.extend_from_slice(col);
            col_ptr.push(row_idx.len());
        }
        let pattern = SymbolicSparseColMat::new_checked(dim, dim, col_ptr, None, row_idx);
        let find = |row: usize, col: usize| -> usize {
            let start = pattern.col_ptr()[col];
            let rows = &pattern.row_idx()[start..pattern.col_ptr()[col + 1]];
            // The entry exists by construction.
            start + rows.binary_search(&row).unwrap_or(0)
        };
        let mut h_map = vec![usize::MAX; hess_lower.row_idx().len()];
        for c in 0..n {
            for p in hess_lower.col_range(c) {
                let r = hess_lower.row_idx()[p];
                h_map[p] = find(c, r);
            }
        }
        let mut j_map = vec![usize::MAX; jac.row_idx().len()];
        for c in 0..n {
            for p in jac.col_range(c) {
                let r = jac.row_idx()[p];
                j_map[p] = find(c, n + r);
            }
        }
        let diag_pos: Vec<usize> = (0..dim).map(|j| find(j, j)).collect();
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: match kind {
                    KktFactorization::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
                    KktFactorization::Simplicial => SupernodalThreshold::FORCE_SIMPLICIAL,
                    KktFactorization::Auto => SupernodalThreshold::AUTO,
                },
                ..Default::default()
            },
        )
        .map_err(|e| KktError::Symbolic(format!("{e:?}")))?;
        let l_values = vec![0.0; symbolic.len_val()];
        // Simplicial: store K already permuted by the AMD ordering (upper triangle, as
        // the up-looking factorisation reads it) and factorise it ourselves with the row
        // patterns of L precomputed, so that no factorisation permutes K or walks the
        // elimination tree again (faer's `permute_self_adjoint_to_unsorted` and `ereach`
        // took 35 % of the factorisation time on the gap-crossing crawl gait).
        let (pattern, h_map, j_map, diag_pos, simplicial) =
            match Simplicial::new(&symbolic, &pattern) {
                Some((simp, ppat, pos)) => (
                    ppat,
                    h_map.iter().map(|&p| pos[p]).collect(),
                    j_map.iter().map(|&p| pos[p]).collect(),
                    diag_pos.iter().map(|&p| pos[p]).collect(),
                    Some(simp),
                ),
                None => (pattern, h_map, j_map, diag_pos, None),
            };
        let mem = MemBuffer::new(StackReq::any_of(&[
            symbolic.factorize_numeric_ldlt_scratch::<f64>(
                Par::Seq,
                Spec::<LdltParams, f64>::default(),
            ),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]));
        let nnz = pattern.row_idx().len();
        Ok(Kkt {
            n,
            m,
            pattern,
            values: vec![0.0; nnz],
            h_map,
            j_map,
            diag_pos,
            symbolic,
            l_values,
            simplicial,
            mem,
            factored: false,
            wx: vec![0.0; dim],
            wr: vec![0.0; dim],
            wd: vec![0.0; dim],
            wb: vec![0.0; dim],
            min_refinement_steps: 1,
            max_refinement_steps: 10,
            residual_ratio_max: 1e-12,
            last_residual_ratio: 0.0,
        })
    }

    /// Number of primal rows `n`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of constraint rows `m`.
    pub fn m(&self) -> usize {
        self.m
    }

    /// Dimension n + m.
    pub fn dim(&self) -> usize {
        self.n + self.m
    }

    /// True if faer chose the supernodal factorisation.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn is_supernodal(&self) -> bool {
        matches!(self.symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_))
    }

    /// Assembles and factorises K; returns its inertia. `h_vals`/`j_vals` are in the
    /// storage order of the patterns given to [`Kkt::new`]; `dx` has length n, `dc` length m.
    pub fn factorize(
        &mut self,
        h_vals: &[f64],
        dx: &[f64],
        j_vals: &[f64],
        dc: &[f64],
    ) -> Result<Inertia, KktError> {
        self.factored = false;
        let check = |what, expected: usize, got: usize| {
            if expected != got {
                Err(KktError::Length {
                    what,
                    expected,
                    got,
                })
            } else {
                Ok(())
            }
        };
        check("h_vals", self.h_map.len(), h_vals.len())?;
        check("j_vals", self.j_map.len(), j_vals.len())?;
        check("dx", self.n, dx.len())?;
        check("dc", self.m, dc.len())?;
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for (&p, &v) in self.h_map.iter().zip(h_vals) {
            self.values[p] += v;
        }
        for (&p, &v) in self.j_map.iter().zip(j_vals) {
            self.values[p] += v;
        }
        for (i, &d) in dx.iter().enumerate() {
            self.values[self.diag_pos[i]] += d;
        }
        for (i, &d) in dc.iter().enumerate() {
            self.values[self.diag_pos[self.n + i]] -= d;
        }
        if self.values.iter().any(|v| !v.is_finite()) {
            return Err(KktError::NonFinite);
        }
        if let Some(simp) = self.simplicial.as_mut() {
            let inertia = simp.factorize(
                self.pattern.col_ptr(),
                self.pattern.row_idx(),
                &self.values,
                &mut self.l_values,
            )?;
            self.factored = true;
            return Ok(inertia);
        }
        let Kkt {
            pattern,
            values,
            symbolic,
            l_values,
            mem,
            ..
        } = self;
        let kmat = SparseColMatRef::new(pattern.as_ref(), values);
        let stack = MemStack::new(mem);
        let res = symbolic.factorize_numeric_ldlt(
            l_values,
            kmat,
            Side::Upper,
            LdltRegularization::default(),
            Par::Seq,
            stack,
            Spec::<LdltParams, f64>::default(),
        );
        match res {
            Ok(_) => {}
            Err(LdltError::ZeroPivot { index }) => return Err(KktError::ZeroPivot(index)),
        }
        let inertia = self.inertia_from_d()?;
        self.factored = true;
        Ok(inertia)
    }

    fn inertia_from_d(&self) -> Result<Inertia, KktError> {
        let mut inertia = Inertia::default();
        let mut count = |d: f64| -> Result<(), KktError> {
            if !d.is_finite() {
                return Err(KktError::NonFinite);
            }
            if d > 0.0 {
                inertia.positive += 1;
            } else if d < 0.0 {
                inertia.negative += 1;
            } else {
                inertia.zero += 1;
            }
            Ok(())
        };
        self.for_each_pivot(&mut count)?;
        Ok(inertia)
    }

    /// Calls `f` with every pivot D_jj of the current factor (in factor order).
    fn for_each_pivot<E>(&self, mut f: impl FnMut(f64) -> Result<(), E>) -> Result<(), E> {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let cp = s.col_ptr();
                for j in 0..s.nrows() {
                    f(self.l_values[cp[j]])?;
                }
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let begin = s.supernode_begin();
                let end = s.supernode_end();
                let cpv = s.col_ptr_for_val();
                for k in 0..s.n_supernodes() {
                    let ncols = end[k] - begin[k];
                    if ncols == 0 {
                        continue;
                    }
                    let nrows = (cpv[k + 1] - cpv[k]) / ncols;
                    for j in 0..ncols {
                        f(self.l_values[cpv[k] + j * nrows + j])?;
                    }
                }
            }
        }
        Ok(())
    }

    /// ln |det K| of the current factorisation (the sum of ln |D_ii|; computed on demand,
    /// NaN without a valid factorisation).
    pub fn log_abs_det(&self) -> f64 {
        if !self.factored {
            return f64::NAN;
        }
        let mut sum = 0.0;
        let _ = self.for_each_pivot(|d| -> Result<(), ()> {
            sum += d.abs().ln();
            Ok(())
        });
        sum
    }

    /// x ← K⁻¹ x from the factor, in the space of `pattern` (permuted when simplicial).
    fn raw_solve(&mut self, x: &mut [f64]) {
        if let Some(simp) = &self.simplicial {
            simp.solve_in_place(&self.l_values, x);
            return;
        }
        let Kkt {
            symbolic,
            l_values,
            mem,
            ..
        } = self;
        let stack = MemStack::new(mem);
        let dim = x.len();
        let f = LdltRef::<usize, f64>::new(symbolic, l_values);
        f.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, dim, 1),
            Par::Seq,
            stack,
        );
    }

    /// y = (K + diag(shift)) x using the assembled upper triangle.
    fn matvec(&self, x: &[f64], shift: Option<&[f64]>, y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        let cp = self.pattern.col_ptr();
        let ri = self.pattern.row_idx();
        for j in 0..self.dim() {
            let xj = x[j];
            let mut acc = 0.0;
            for p in cp[j]..cp[j + 1] {
                let i = ri[p];
                let v = self.values[p];
                acc += v * x[i];
                if i != j {
                    y[i] += v * xj;
                }
            }
            y[j] += acc;
        }
        if let Some(s) = shift {
            for ((yi, si), xi) in y.iter_mut().zip(s).zip(x) {
                *yi += si * xi;
            }
        }
    }

    /// y = (K + diag(shift)) x in the original (unpermuted) ordering, K the matrix of the
    /// last [`Kkt::factorize`].
    pub fn multiply(
        &self,
        x: &[f64],
        shift: Option<&[f64]>,
        y: &mut [f64],
    ) -> Result<(), KktError> {
        let dim = self.dim();
        for (what, len) in [("x", x.len()), ("y", y.len())] {
            if len != dim {
                return Err(KktError::Length {
                    what,
                    expected: dim,
                    got: len,
                });
            }
        }
        match &self.simplicial {
            Some(simp) => {
                let px: Vec<f64> = simp.fwd.iter().map(|&o| x[o]).collect();
                let mut py = vec![0.0; dim];
                self.matvec(&px, None, &mut py);
                for (&v, &o) in py.iter().zip(&simp.fwd) {
                    y[o] = v;
                }
            }
            None => self.matvec(x, None, y),
        }
        if let Some(s) = shift {
            for ((yi, si), xi) in y.iter_mut().zip(s).zip(x) {
                *yi += si * xi;
            }
        }
        Ok(())
    }

    /// Solves K x = rhs in place with residual-checked iterative refinement.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<f64, KktError> {
        self.solve_shifted(rhs, None)
    }

    /// Solves (K + diag(shift)) x = rhs in place, using the factor of K as preconditioner
    /// of iterative refinement (e.g. to remove a static regularisation from the step).
    /// Returns the final relative residual.
    pub fn solve_shifted(
        &mut self,
        rhs: &mut [f64],
        shift: Option<&[f64]>,
    ) -> Result<f64, KktError> {
        if !self.factored {
            return Err(KktError::NotFactorized);
        }
        let dim = self.dim();
        if rhs.len() != dim {
            return Err(KktError::Length {
                what: "rhs",
                expected: dim,
                got: rhs.len(),
            });
        }
        if let Some(s) = shift {
            if s.len() != dim {
                return Err(KktError::Length {
                    what: "shift",
                    expected: dim,
                    got: s.len(),
                });
            }
        }
        let mut wb = std::mem::take(&mut self.wb);
        let mut wx = std::mem::take(&mut self.wx);
        let mut wr = std::mem::take(&mut self.wr);
        let mut wd = std::mem::take(&mut self.wd);
        // The simplicial factor works in the AMD-permuted space: permute in (and out at
        // the end); refinement runs there too, on the permuted K.
        let mut pshift = Vec::new();
        let shift = match self.simplicial.as_mut() {
            Some(simp) => {
                for (w, &o) in wb.iter_mut().zip(&simp.fwd) {
                    *w = rhs[o];
                }
                match shift {
                    Some(s) => {
                        pshift = std::mem::take(&mut simp.pshift);
                        for (w, &o) in pshift.iter_mut().zip(&simp.fwd) {
                            *w = s[o];
                        }
                        Some(&pshift[..])
                    }
                    None => None,
                }
            }
            None => {
                wb.copy_from_slice(rhs);
                shift
            }
        };
        let b_norm = inf_norm(&wb);
        wx.copy_from_slice(&wb);
        self.raw_solve(&mut wx);
        let mut ratio = f64::INFINITY;
        let mut steps = 0;
        loop {
            self.matvec(&wx, shift, &mut wr);
            for (r, b) in wr.iter_mut().zip(&wb) {
                *r = b - *r;
            }
            // IPOPT's residual ratio ‖r‖ / (min(‖x‖, 10⁶‖b‖) + ‖b‖): the cap on ‖x‖ keeps
            // a huge solution of a (nearly) singular system from looking accurate.
            let r_norm = inf_norm(&wr);
            let denom = inf_norm(&wx).min(1e6 * b_norm) + b_norm;
            let new_ratio = if denom > 0.0 { r_norm / denom } else { r_norm };
            if !new_ratio.is_finite() {
                break;
            }
            if steps > 0 && new_ratio >= ratio {
                // Refinement stopped improving: undo the last correction.
                for (x, d) in wx.iter_mut().zip(&wd) {
                    *x -= d;
                }
                break;
            }
            // The ratio is a backward error dominated by the largest entries of x: on an
            // ill-conditioned K (huge multipliers) it can pass the target while the small
            // entries are still far off. So keep refining past the target while a step
            // still gains a lot (at most ½ of the previous ratio) and the ratio is above
            // round-off; a well-conditioned system reaches round-off in one step.
            let fast = new_ratio <= 0.5 * ratio;
            ratio = new_ratio;
            let converged = ratio <= self.residual_ratio_max
                && (ratio <= REFINEMENT_FLOOR || (steps > 0 && !fast));
            if (steps >= self.min_refinement_steps && converged)
                || steps >= self.max_refinement_steps
            {
                break;
            }
            wd.copy_from_slice(&wr);
            self.raw_solve(&mut wd);
            for (x, d) in wx.iter_mut().zip(&wd) {
                *x += d;
            }
            steps += 1;
        }
        match self.simplicial.as_mut() {
            Some(simp) => {
                for (&v, &o) in wx.iter().zip(&simp.fwd) {
                    rhs[o] = v;
                }
                if !pshift.is_empty() {
                    simp.pshift = pshift;
                }
            }
            None => rhs.copy_from_slice(&wx),
        }
        self.wb = wb;
        self.wx = wx;
        self.wr = wr;
        self.wd = wd;
        self.last_residual_ratio = ratio;
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(KktError::NonFinite);
        }
        Ok(ratio)
    }
}

/// Simplicial LDLᵀ of the AMD-permuted K (up-looking, Davis's LDL), on the pattern of L
/// from faer's symbolic analysis. The rows of L (for each k, the columns j < k with
/// L_kj ≠ 0 and the positions of those entries) are precomputed once, so a numeric
/// factorisation does the arithmetic only. Ascending column order is a topological order
/// of the elimination tree (parents have larger indices), as the algorithm needs.
struct Simplicial {
    /// Permutation: permuted index k is original index `fwd[k]`.
    fwd: Vec<usize>,
    /// Column pointers and row indices of L (diagonal first in each column, rows
    /// ascending); the diagonal slot holds D.
    l_col_ptr: Vec<usize>,
    l_row_idx: Vec<usize>,
    /// Rows of L below the diagonal: for row k, `row_col[row_ptr[k]..row_ptr[k+1]]` are
    /// the columns j (ascending) and `row_pos[..]` the positions of L_kj in the values.
    row_ptr: Vec<usize>,
    row_col: Vec<usize>,
    row_pos: Vec<usize>,
    /// 1 / D.
    d_inv: Vec<f64>,
    /// Dense accumulator of the current row (all zero between rows).
    x: Vec<f64>,
    /// The permuted shift of `solve_shifted`.
    pshift: Vec<f64>,
}

impl Simplicial {
    /// Builds the permuted upper pattern of K and the map from positions in `pattern`
    /// (the original upper triangle) to positions in the permuted one. `None` if faer's
    /// analysis is supernodal (or, defensively, if the permuted K does not fit L's
    /// pattern).
    fn new(
        symbolic: &SymbolicCholesky<usize>,
        pattern: &SymbolicSparseColMat<usize>,
    ) -> Option<(Simplicial, SymbolicSparseColMat<usize>, Vec<usize>)> {
        let SymbolicCholeskyRaw::Simplicial(s) = symbolic.raw() else {
            return None;
        };
        let dim = pattern.ncols();
        let (fwd, inv): (Vec<usize>, Vec<usize>) = match symbolic.perm() {
            Some(p) => {
                let (f, i) = p.arrays();
                (f.to_vec(), i.to_vec())
            }
            None => ((0..dim).collect(), (0..dim).collect()),
        };
        // Permuted upper triangle: original entry (r, c), r ≤ c, goes to
        // (min, max) of (inv[r], inv[c]).
        let cp = pattern.col_ptr();
        let ri = pattern.row_idx();
        let nnz = ri.len();
        let mut count = vec![0usize; dim + 1];
        let mut target = Vec::with_capacity(nnz);
        for c in 0..dim {
            for &r in &ri[cp[c]..cp[c + 1]] {
                let (a, b) = (inv[r], inv[c]);
                let (row, col) = if a <= b { (a, b) } else { (b, a) };
                target.push((row, col));
                count[col + 1] += 1;
            }
        }
        for j in 0..dim {
            count[j + 1] += count[j];
        }
        let col_ptr = count.clone();
        let mut next = count;
        let mut row_idx = vec![0usize; nnz];
        let mut pos = vec![0usize; nnz];
        // Fill column by column; then sort each column's rows, carrying `pos` along.
        for (p, &(row, col)) in target.iter().enumerate() {
            let q = next[col];
            next[col] += 1;
            row_idx[q] = row;
            pos[p] = q;
        }
        let mut order: Vec<usize> = Vec::new();
        let mut where_new = vec![0usize; nnz];
        let mut sorted_rows = vec![0usize; nnz];
        for j in 0..dim {
            let (a, b) = (col_ptr[j], col_ptr[j + 1]);
            order.clear();
            order.extend(a..b);
            order.sort_unstable_by_key(|&q| row_idx[q]);
            for (t, &q) in order.iter().enumerate() {
                where_new[q] = a + t;
                sorted_rows[a + t] = row_idx[q];
            }
        }
        for p in pos.iter_mut() {
            *p = where_new[*p];
        }
        let ppat = SymbolicSparseColMat::new_checked(dim, dim, col_ptr, None, sorted_rows);
        let l_col_ptr = s.col_ptr().to_vec();
        let l_row_idx = s.row_idx().to_vec();
        if l_col_ptr.len() != dim + 1
            || l_col_ptr[dim] != l_row_idx.len()
            || l_row_idx.iter().any(|&r| r >= dim)
        {
            return None;
        }
        // Rows of L.
        let mut row_ptr = vec![0usize; dim + 1];
        for j in 0..dim {
            if l_row_idx[l_col_ptr[j]] != j {
                return None;
            }
            for &r in &l_row_idx[l_col_ptr[j] + 1..l_col_ptr[j + 1]] {
                if r <= j {
                    return None;
                }
                row_ptr[r + 1] += 1;
            }
        }
        for k in 0..dim {
            row_ptr[k + 1] += row_ptr[k];
        }
        let mut fill = row_ptr.clone();
        let mut row_col = vec![0usize; row_ptr[dim]];
        let mut row_pos = vec![0usize; row_ptr[dim]];
        for j in 0..dim {
            for p in l_col_ptr[j] + 1..l_col_ptr[j + 1] {
                let r = l_row_idx[p];
                row_col[fill[r]] = j;
                row_pos[fill[r]] = p;
                fill[r] += 1;
            }
        }
        // Every off-diagonal entry (i, k), i < k, of the permuted K must be an entry
        // L_ki of the factor.
        let simp = Simplicial {
            fwd,
            l_col_ptr,
            l_row_idx,
            row_ptr,
            row_col,
            row_pos,
            d_inv: vec![0.0; dim],
            x: vec![0.0; dim],
            pshift: vec![0.0; dim],
        };
        for k in 0..dim {
            let cols = &simp.row_col[simp.row_ptr[k]..simp.row_ptr[k + 1]];
            for &i in ppat.row_idx_of_col_raw(k) {
                if i < k && cols.binary_search(&i).is_err() {
                    return None;
                }
            }
        }
        Some((simp, ppat, pos))
    }

    /// Numeric LDLᵀ of the permuted upper triangle (`col_ptr`, `row_idx`, `values`) into
    /// `l` (the L pattern's values, D on the diagonal slots). Returns the inertia;
    /// `ZeroPivot` (permuted index) on an exactly zero pivot, `NonFinite` on a
    /// non-finite one.
    fn factorize(
        &mut self,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
        l: &mut [f64],
    ) -> Result<Inertia, KktError> {
        let dim = self.d_inv.len();
        let x = &mut self.x[..dim];
        let lcp = &self.l_col_ptr;
        let lri = &self.l_row_idx;
        let mut inertia = Inertia::default();
        for k in 0..dim {
            for p in col_ptr[k]..col_ptr[k + 1] {
                x[row_idx[p]] += values[p];
            }
            let mut d = x[k];
            x[k] = 0.0;
            let (a, b) = (self.row_ptr[k], self.row_ptr[k + 1]);
            for (&j, &pos) in self.row_col[a..b].iter().zip(&self.row_pos[a..b]) {
                let xj = x[j];
                x[j] = 0.0;
                let start = lcp[j] + 1;
                for (&i, &lij) in lri[start..pos].iter().zip(&l[start..pos]) {
                    x[i] -= lij * xj;
                }
                let lkj = xj * self.d_inv[j];
                d -= lkj * xj;
                l[pos] = lkj;
            }
            if d == 0.0 || !d.is_finite() {
                // Leave the accumulator clean for the next factorisation.
                x.fill(0.0);
                return Err(if d == 0.0 {
                    KktError::ZeroPivot(k)
                } else {
                    KktError::NonFinite
                });
            }
            l[lcp[k]] = d;
            self.d_inv[k] = 1.0 / d;
            if d > 0.0 {
                inertia.positive += 1;
            } else {
                inertia.negative += 1;
            }
        }
        Ok(inertia)
    }

    /// x ← (L D Lᵀ)⁻¹ x in the permuted space.
    fn solve_in_place(&self, l: &[f64], x: &mut [f64]) {
        let dim = self.d_inv.len();
        let lcp = &self.l_col_ptr;
        let lri = &self.l_row_idx;
        for j in 0..dim {
            let xj = x[j];
            if xj != 0.0 {
                let (a, b) = (lcp[j] + 1, lcp[j + 1]);
                for (&i, &lij) in lri[a..b].iter().zip(&l[a..b]) {
                    x[i] -= lij * xj;
                }
            }
        }
        for (xj, dj) in x.iter_mut().zip(&self.d_inv) {
            *xj *= dj;
        }
        for j in (0..dim).rev() {
            let (a, b) = (lcp[j] + 1, lcp[j + 1]);
            let mut acc = x[j];
            for (&i, &lij) in lri[a..b].iter().zip(&l[a..b]) {
                acc -= lij * x[i];
            }
            x[j] = acc;
        }
    }
}

/// Residual ratio below which refinement stops even while it still improves.
const REFINEMENT_FLOOR: f64 = 1e-14;

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, &b| a.max(b.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// Tiny deterministic generator (xorshift) so the tests need no extra dependency.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn sym(&mut self) -> f64 {
            2.0 * self.next() - 1.0
        }
    }

    fn pattern(
        nrows: usize,
        ncols: usize,
        entries: &[(usize, usize)],
    ) -> SymbolicSparseColMat<usize> {
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); ncols];
        for &(r, c) in entries {
            cols[c].push(r);
        }
        let mut cp = vec![0];
        let mut ri = Vec::new();
        for mut c in cols {
            c.sort_unstable();
            c.dedup();
            ri.extend(c);
            cp.push(ri.len());
        }
        SymbolicSparseColMat::new_checked(nrows, ncols, cp, None, ri)
    }

    struct Case {
        n: usize,
        m: usize,
        h: SymbolicSparseColMat<usize>,
        j: SymbolicSparseColMat<usize>,
        hv: Vec<f64>,
        jv: Vec<f64>,
        dx: Vec<f64>,
        dc: Vec<f64>,
    }

    fn random_case(rng: &mut Rng, n: usize, m: usize, density: f64, indefinite: bool) -> Case {
        let mut he = Vec::new();
        for c in 0..n {
            for r in c..n {
                if r == c || rng.next() < density {
                    he.push((r, c));
                }
            }
        }
        let mut je = Vec::new();
        for r in 0..m {
            je.push((r, (r * 7) % n));
            for c in 0..n {
                if rng.next() < density {
                    je.push((r, c));
                }
            }
        }
        let h = pattern(n, n, &he);
        let j = pattern(m, n, &je);
        let hv = (0..h.row_idx().len())
            .map(|_| {
                if indefinite {
                    3.0 * rng.sym()
                } else {
                    rng.sym()
                }
            })
            .collect();
        let jv = (0..j.row_idx().len()).map(|_| rng.sym()).collect();
        let dx = (0..n)
            .map(|_| if indefinite { 0.0 } else { 10.0 + rng.next() })
            .collect();
        let dc = (0..m).map(|_| 1e-3 + rng.next() * 1e-2).collect();
        Case {
            n,
            m,
            h,
            j,
            hv,
            jv,
            dx,
            dc,
        }
    }

    fn dense(c: &Case) -> Mat<f64> {
        let dim = c.n + c.m;
        let mut k = Mat::<f64>::zeros(dim, dim);
        for col in 0..c.n {
            for p in c.h.col_range(col) {
                let r = c.h.row_idx()[p];
                k[(r, col)] += c.hv[p];
                if r != col {
                    k[(col, r)] += c.hv[p];
                }
            }
            for p in c.j.col_range(col) {
                let r = c.j.row_idx()[p];
                k[(c.n + r, col)] += c.jv[p];
                k[(col, c.n + r)] += c.jv[p];
            }
        }
        for i in 0..c.n {
            k[(i, i)] += c.dx[i];
        }
        for i in 0..c.m {
            k[(c.n + i, c.n + i)] -= c.dc[i];
        }
        k
    }

    fn check_case(c: &Case) {
        for kind in [
            KktFactorization::Supernodal,
            KktFactorization::Simplicial,
            KktFactorization::Auto,
        ] {
            check_case_kind(c, kind);
        }
    }

    fn check_case_kind(c: &Case, kind: KktFactorization) {
        let mut kkt = Kkt::with_factorization(c.n, c.m, &c.h, &c.j, kind).unwrap();
        assert_eq!(
            kkt.is_supernodal(),
            kind == KktFactorization::Supernodal
                || (kind == KktFactorization::Auto && kkt.is_supernodal())
        );
        // Simplicial analyses run on our own factorisation of the permuted K.
        assert_eq!(kkt.simplicial.is_some(), !kkt.is_supernodal());
        let inertia = kkt.factorize(&c.hv, &c.dx, &c.jv, &c.dc).unwrap();
        let kd = dense(c);
        let eig = kd.self_adjoint_eigenvalues(Side::Lower).unwrap();
        let pos = eig.iter().filter(|&&e| e > 0.0).count();
        let neg = eig.iter().filter(|&&e| e < 0.0).count();
        assert_eq!(
            (inertia.positive, inertia.negative),
            (pos, neg),
            "eig {eig:?}"
        );
        let dim = c.n + c.m;
        let mut rng = Rng(99);
        let b: Vec<f64> = (0..dim).map(|_| rng.sym()).collect();
        let mut x = b.clone();
        let ratio = kkt.solve(&mut x).unwrap();
        assert!(ratio < 1e-12, "residual ratio {ratio}");
        // Dense residual check.
        let mut maxr: f64 = 0.0;
        for i in 0..dim {
            let mut s = 0.0;
            for j in 0..dim {
                s += kd[(i, j)] * x[j];
            }
            maxr = maxr.max((s - b[i]).abs());
        }
        assert!(maxr < 1e-9, "dense residual {maxr}");
    }

    #[test]
    fn quasi_definite_inertia_and_solve() {
        let mut rng = Rng(12345);
        for &(n, m) in &[(5, 2), (10, 4), (30, 12), (60, 25)] {
            let c = random_case(&mut rng, n, m, 0.2, false);
            check_case(&c);
            let mut kkt = Kkt::new(c.n, c.m, &c.h, &c.j).unwrap();
            let i = kkt.factorize(&c.hv, &c.dx, &c.jv, &c.dc).unwrap();
            assert_eq!((i.positive, i.negative, i.zero), (n, m, 0));
        }
    }

    #[test]
    fn indefinite_inertia_matches_dense() {
        let mut rng = Rng(777);
        for k in 0..20 {
            let n = 4 + k;
            let m = k / 2 + 1;
            let c = random_case(&mut rng, n, m, 0.3, true);
            check_case(&c);
        }
    }

    #[test]
    fn refactorization_reuses_symbolic() {
        let mut rng = Rng(4242);
        let c = random_case(&mut rng, 20, 8, 0.25, true);
        let mut kkt = Kkt::new(c.n, c.m, &c.h, &c.j).unwrap();
        let mut dx = c.dx.clone();
        // Increasing δ_w eventually yields the quasi-definite inertia (n, m, 0).
        let mut delta = 1e-4;
        loop {
            dx.iter_mut().for_each(|d| *d = delta);
            let i = kkt.factorize(&c.hv, &dx, &c.jv, &c.dc).unwrap();
            if i.negative == c.m {
                assert_eq!(i.positive, c.n);
                break;
            }
            delta *= 8.0;
            assert!(delta < 1e6);
        }
    }

    #[test]
    fn shifted_solve_removes_regularisation() {
        let mut rng = Rng(31337);
        let c = random_case(&mut rng, 15, 6, 0.3, false);
        let mut kkt = Kkt::new(c.n, c.m, &c.h, &c.j).unwrap();
        // Factor with dc + 1e-8, solve the system with dc.
        let dc_reg: Vec<f64> = c.dc.iter().map(|d| d + 1e-8).collect();
        kkt.factorize(&c.hv, &c.dx, &c.jv, &dc_reg).unwrap();
        let mut shift = vec![0.0; c.n + c.m];
        shift[c.n..].iter_mut().for_each(|s| *s = 1e-8);
        let b: Vec<f64> = (0..c.n + c.m).map(|_| rng.sym()).collect();
        let mut x = b.clone();
        let ratio = kkt.solve_shifted(&mut x, Some(&shift)).unwrap();
        assert!(ratio < 1e-13, "{ratio}");
    }

    #[test]
    fn zero_block_without_regularisation_is_an_error_not_a_panic() {
        let h = pattern(2, 2, &[(0, 0), (1, 1)]);
        let j = pattern(1, 2, &[(0, 0)]);
        let mut kkt = Kkt::new(2, 1, &h, &j).unwrap();
        // H = 0, J = 0, dc = 0: K is singular.
        let r = kkt.factorize(&[0.0, 0.0], &[0.0, 0.0], &[0.0], &[0.0]);
        assert!(r.is_err() || r.unwrap().zero > 0);
        let r = kkt.factorize(&[f64::NAN, 0.0], &[1.0, 1.0], &[1.0], &[1.0]);
        assert_eq!(r, Err(KktError::NonFinite));
        let mut b = vec![1.0; 3];
        assert_eq!(kkt.solve(&mut b), Err(KktError::NotFactorized));
    }

    #[test]
    fn rejects_upper_hessian_pattern() {
        let h = pattern(2, 2, &[(0, 1)]);
        let j = pattern(0, 2, &[]);
        assert!(matches!(Kkt::new(2, 0, &h, &j), Err(KktError::Pattern(_))));
        let h = pattern(3, 3, &[]);
        assert!(matches!(Kkt::new(2, 0, &h, &j), Err(KktError::Pattern(_))));
    }

    /// hs061, iteration 2: multipliers ~1e8 make the Schur complement tiny, so the static
    /// regularisation slows refinement down (factor ≈ 0.28 per step). The backward error
    /// passes 1e-10 after two steps while x[0] is still 12 % off (2.68 instead of 2.4);
    /// refinement must continue while it gains.
    #[test]
    fn refinement_continues_while_it_gains_on_ill_conditioned_systems() {
        let h = pattern(3, 3, &[(0, 0), (1, 1), (2, 2)]);
        let j = pattern(2, 3, &[(0, 0), (1, 0), (0, 1), (1, 2)]);
        let (x1, x2, x3) = (2.600000002744226f64, -4.0f64, 6.000000000000001f64);
        let (y1, y2) = (142262354.26711383f64, -106696762.65033539f64);
        let hv = [8.0, 4.0 - 4.0 * y1, 4.0 - 2.0 * y2];
        let jv = [3.0, 4.0, -4.0 * x2, -2.0 * x3];
        let g = [8.0 * x1 - 33.0, 4.0 * x2 + 16.0, 4.0 * x3 - 24.0];
        let c = [3.0 * x1 - 2.0 * x2 * x2 - 7.0, 4.0 * x1 - x3 * x3 - 11.0];
        let mut x = vec![
            -(g[0] + 3.0 * y1 + 4.0 * y2),
            -(g[1] - 4.0 * x2 * y1),
            -(g[2] - 2.0 * x3 * y2),
            -c[0],
            -c[1],
        ];
        let mut kkt = Kkt::new(3, 2, &h, &j).unwrap();
        kkt.residual_ratio_max = 1e-10;
        let i = kkt.factorize(&hv, &[1e-8; 3], &jv, &[1e-8; 2]).unwrap();
        assert_eq!((i.positive, i.negative), (3, 2));
        let shift = [-1e-8, -1e-8, -1e-8, 1e-8, 1e-8];
        kkt.solve_shifted(&mut x, Some(&shift)).unwrap();
        // Exact step (50-digit arithmetic): (2.39999799, 1.50000038, −2.25000067, …).
        assert!((x[0] - 2.4).abs() < 1e-3, "{x:?}");
        assert!((x[1] - 1.5).abs() < 1e-3, "{x:?}");
        assert!((x[2] + 2.25).abs() < 1e-3, "{x:?}");
    }
}
