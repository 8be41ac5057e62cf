//! The user's NLP as the interior-point core sees it: fixed variables removed
//! (IPOPT's `fixed_variable_treatment = make_parameter`) and rows without bounds dropped,
//! on top of the front end's scaled problem ([`ScaledNlp`]: scaling, evaluation
//! counters and timing).

#![allow(clippy::needless_range_loop)]

use faer::sparse::SymbolicSparseColMat;

use crate::frontend::scaled::{refill, NormScratch, ScaledBuffers, ScaledNlp, Scaling};
use crate::frontend::validate::Validated;
use crate::numeric::NumericNlp;

/// The problem interface of the core: a [`NumericNlp`] plus a hook that the restoration
/// phase uses to stop its inner iteration.
pub(crate) trait IpmProblem: NumericNlp {
    /// Called after each accepted inner iterate `w = [x; s]`; `true` stops the loop.
    fn restoration_accepts(&mut self, _w: &[f64]) -> bool {
        false
    }

    /// Writes the point `x` (this problem's variables) and multipliers `y` (this
    /// problem's rows) in the user's spaces, for the iteration callback.
    fn user_point(&self, x: &[f64], y: &[f64], x_user: &mut [f64], lambda_user: &mut [f64]);

    /// For the iteration log of a restoration phase: the original problem's unscaled
    /// objective and unscaled constraint violation (max-norm) at the inner iterate `w`,
    /// which IPOPT prints in the objective and inf_pr columns of the 'r' rows. `None`
    /// (the default): not a restoration problem.
    fn original_measures(&mut self, _w: &[f64]) -> Option<(f64, f64)> {
        None
    }
}

/// The reduced problem: free variables and bounded rows of the scaled user problem.
pub(crate) struct Reduced<'a> {
    /// The scaled user problem (factors of every user row; 1 on dropped rows).
    pub sc: ScaledNlp<'a>,
    parts: ReducedParts,
}

/// The vectors and patterns of a [`Reduced`] problem, kept between solves: a solve
/// of a problem with the same structure (patterns, fixed variables and unbounded rows)
/// reuses the sub-patterns and allocates nothing here.
#[derive(Default)]
pub(crate) struct ReducedParts {
    free: Vec<usize>,
    rows: Vec<usize>,
    /// The user's Jacobian and Hessian patterns the sub-patterns were built from.
    user_patterns: Option<(SymbolicSparseColMat<usize>, SymbolicSparseColMat<usize>)>,
    sub: Option<SubPatterns>,
    x_l: Vec<f64>,
    x_u: Vec<f64>,
    g_l: Vec<f64>,
    g_u: Vec<f64>,
    x0: Vec<f64>,
    x_full: Vec<f64>,
    g_full: Vec<f64>,
    jac_full: Vec<f64>,
    hess_full: Vec<f64>,
    lam_full: Vec<f64>,
    grad_full: Vec<f64>,
    scaled: ScaledBuffers,
    /// Scratch: the candidate free variables and kept rows of a new solve.
    next_free: Vec<usize>,
    next_rows: Vec<usize>,
    /// Scratch of the gradient norms (`is_free` marks the free variables).
    norms: NormScratch,
    is_free: Vec<bool>,
    /// The reduced problem's row factors (see [`Reduced::scaling`]).
    restricted: Scaling,
}

/// The reduced problem's Jacobian and Hessian patterns with, per entry, the position of
/// the user's entry.
struct SubPatterns {
    jac: SymbolicSparseColMat<usize>,
    jmap: Vec<usize>,
    hess: SymbolicSparseColMat<usize>,
    hmap: Vec<usize>,
}

impl SubPatterns {
    fn new(user: &dyn NumericNlp, free: &[usize], rows: &[usize]) -> SubPatterns {
        let (n_user, m_user) = (user.n(), user.m());
        let mut col_new = vec![usize::MAX; n_user];
        for (k, &j) in free.iter().enumerate() {
            col_new[j] = k;
        }
        let mut row_new = vec![usize::MAX; m_user];
        for (k, &i) in rows.iter().enumerate() {
            row_new[i] = k;
        }
        let (jac, jmap) = sub_pattern(user.jac_g_sparsity(), free, &row_new, rows.len(), false);
        let (hess, hmap) = sub_pattern(user.hess_l_sparsity(), free, &col_new, free.len(), true);
        SubPatterns {
            jac,
            jmap,
            hess,
            hmap,
        }
    }
}

/// True if `a` and `b` have the same shape and entries.
pub(crate) fn same_pattern(
    a: &SymbolicSparseColMat<usize>,
    b: &SymbolicSparseColMat<usize>,
) -> bool {
    a.nrows() == b.nrows()
        && a.ncols() == b.ncols()
        && (0..a.ncols()).all(|j| a.row_idx()[a.col_range(j)] == b.row_idx()[b.col_range(j)])
}

impl<'a> Reduced<'a> {
    /// The reduced problem of `user` with the validated bounds and starting point `v`,
    /// in the vectors of `parts` (from [`Reduced::into_parts`] of an earlier solve, or
    /// the default).
    pub fn new(user: &'a mut dyn NumericNlp, v: &Validated, mut parts: ReducedParts) -> Self {
        let (x_l, x_u, g_l, g_u, x0) = (&v.x_l, &v.x_u, &v.g_l, &v.g_u, &v.x0);
        let n_user = x_l.len();
        let m_user = g_l.len();
        parts.next_free.clear();
        parts
            .next_free
            .extend((0..n_user).filter(|&j| x_l[j] != x_u[j]));
        parts.next_rows.clear();
        parts
            .next_rows
            .extend((0..m_user).filter(|&i| g_l[i] > f64::NEG_INFINITY || g_u[i] < f64::INFINITY));
        let same = parts.sub.is_some()
            && parts.next_free == parts.free
            && parts.next_rows == parts.rows
            && parts.user_patterns.as_ref().is_some_and(|(j, h)| {
                same_pattern(j, user.jac_g_sparsity()) && same_pattern(h, user.hess_l_sparsity())
            });
        std::mem::swap(&mut parts.free, &mut parts.next_free);
        std::mem::swap(&mut parts.rows, &mut parts.next_rows);
        if !same {
            parts.sub = Some(SubPatterns::new(&*user, &parts.free, &parts.rows));
            parts.user_patterns = Some((
                user.jac_g_sparsity().clone(),
                user.hess_l_sparsity().clone(),
            ));
        }
        let (free, rows) = (&parts.free, &parts.rows);
        let pick = |out: &mut Vec<f64>, from: &[f64], idx: &[usize]| {
            out.clear();
            out.extend(idx.iter().map(|&k| from[k]));
        };
        pick(&mut parts.x_l, x_l, free);
        pick(&mut parts.x_u, x_u, free);
        pick(&mut parts.g_l, g_l, rows);
        pick(&mut parts.g_u, g_u, rows);
        pick(&mut parts.x0, x0, free);
        parts.x_full.clear();
        parts.x_full.extend_from_slice(x0);
        for j in 0..n_user {
            if x_l[j] == x_u[j] {
                parts.x_full[j] = x_l[j];
            }
        }
        refill(&mut parts.g_full, m_user, 0.0);
        refill(
            &mut parts.jac_full,
            user.jac_g_sparsity().row_idx().len(),
            0.0,
        );
        refill(
            &mut parts.hess_full,
            user.hess_l_sparsity().row_idx().len(),
            0.0,
        );
        refill(&mut parts.lam_full, m_user, 0.0);
        refill(&mut parts.grad_full, n_user, 0.0);
        let scaled = std::mem::take(&mut parts.scaled);
        Reduced {
            sc: ScaledNlp::with_buffers(user, scaled),
            parts,
        }
    }

    /// The vectors and patterns, for [`Reduced::new`] in a later solve.
    pub fn into_parts(self) -> ReducedParts {
        let mut parts = self.parts;
        parts.scaled = self.sc.into_buffers();
        parts
    }

    /// Free variable indices (user numbering).
    pub fn free(&self) -> &[usize] {
        &self.parts.free
    }

    /// Kept row indices (user numbering).
    pub fn rows(&self) -> &[usize] {
        &self.parts.rows
    }

    /// Unscaled lower bounds of the kept rows.
    pub fn g_l(&self) -> &[f64] {
        &self.parts.g_l
    }

    /// Unscaled upper bounds of the kept rows.
    pub fn g_u(&self) -> &[f64] {
        &self.parts.g_u
    }

    /// The starting point of the free variables.
    pub fn x0(&self) -> &[f64] {
        &self.parts.x0
    }

    /// The user's point with fixed variables at their values (and the free ones at the
    /// last point evaluated).
    pub fn x_full(&self) -> &[f64] {
        &self.parts.x_full
    }

    fn sub(&self) -> &SubPatterns {
        self.parts
            .sub
            .as_ref()
            .expect("the sub-patterns are built by Reduced::new")
    }

    /// The scaling of the reduced problem (the factors of the kept rows), from the
    /// scaled problem's factors; give it back with [`Reduced::put_scaling`] to reuse its
    /// vector.
    pub fn take_scaling(&mut self) -> Scaling {
        let mut out = std::mem::take(&mut self.parts.restricted);
        self.sc.scaling.restrict_into(&self.parts.rows, &mut out);
        out
    }

    /// Keeps the vector of a scaling from [`Reduced::take_scaling`].
    pub fn put_scaling(&mut self, scaling: Scaling) {
        self.parts.restricted = scaling;
    }

    fn set_x(&mut self, x: &[f64]) {
        for (k, &j) in self.parts.free.iter().enumerate() {
            self.parts.x_full[j] = x[k];
        }
    }

    /// Unscaled max-norms at the starting point (counted), for choosing the factors: of
    /// ∇f over the free variables (returned), and of each kept row of the Jacobian over
    /// them (in `row_norms()`).
    pub fn unscaled_gradient_norms_at_start(&mut self) -> f64 {
        for k in 0..self.parts.free.len() {
            let j = self.parts.free[k];
            self.parts.x_full[j] = self.parts.x0[k];
        }
        let n_user = self.parts.x_full.len();
        refill(&mut self.parts.is_free, n_user, false);
        for &j in &self.parts.free {
            self.parts.is_free[j] = true;
        }
        let p = &mut self.parts;
        self.sc
            .unscaled_gradient_norms_into(&p.x_full, Some(&p.is_free), &mut p.norms)
    }

    /// The row norm of kept row `k` from [`Reduced::unscaled_gradient_norms_at_start`].
    pub fn row_norm(&self, k: usize) -> f64 {
        self.parts.norms.rmax[self.parts.rows[k]]
    }
}

/// Sub-pattern of `pat` restricted to columns `cols` (old indices, in new order) and rows
/// with `row_new[r] != usize::MAX`. Returns the pattern and, per new storage position,
/// the old storage position. With `lower`, entries are put in the lower triangle of the
/// new numbering (the reordering is monotone, so this is automatic).
fn sub_pattern(
    pat: &SymbolicSparseColMat<usize>,
    cols: &[usize],
    row_new: &[usize],
    nrows: usize,
    _lower: bool,
) -> (SymbolicSparseColMat<usize>, Vec<usize>) {
    let nnz = pat.row_idx().len();
    let mut col_ptr = Vec::with_capacity(cols.len() + 1);
    col_ptr.push(0usize);
    let mut row_idx = Vec::with_capacity(nnz);
    let mut map = Vec::with_capacity(nnz);
    // One buffer for every column's entries (a vector per column was ~60 % of a warm
    // cart-pole MPC re-solve's allocations).
    let mut entries: Vec<(usize, usize)> = Vec::new();
    for &c in cols {
        entries.clear();
        if c < pat.ncols() {
            for p in pat.col_range(c) {
                let r = pat.row_idx()[p];
                if r < row_new.len() && row_new[r] != usize::MAX {
                    entries.push((row_new[r], p));
                }
            }
        }
        entries.sort_unstable();
        entries.dedup_by_key(|e| e.0);
        for &(r, p) in &entries {
            row_idx.push(r);
            map.push(p);
        }
        col_ptr.push(row_idx.len());
    }
    (
        SymbolicSparseColMat::new_checked(nrows, cols.len(), col_ptr, None, row_idx),
        map,
    )
}

impl NumericNlp for Reduced<'_> {
    fn n(&self) -> usize {
        self.parts.free.len()
    }
    fn m(&self) -> usize {
        self.parts.rows.len()
    }
    fn bounds(&self, x_l: &mut [f64], x_u: &mut [f64], g_l: &mut [f64], g_u: &mut [f64]) {
        x_l.copy_from_slice(&self.parts.x_l);
        x_u.copy_from_slice(&self.parts.x_u);
        for (k, &i) in self.parts.rows.iter().enumerate() {
            g_l[k] = self.parts.g_l[k] * self.sc.scaling.rows[i];
            g_u[k] = self.parts.g_u[k] * self.sc.scaling.rows[i];
        }
    }
    fn initial_point(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.parts.x0);
    }
    fn jac_g_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        &self.sub().jac
    }
    fn hess_l_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        &self.sub().hess
    }
    fn eval_f(&mut self, x: &[f64]) -> f64 {
        self.set_x(x);
        self.sc.f(&self.parts.x_full)
    }
    fn eval_grad_f(&mut self, x: &[f64], grad: &mut [f64]) {
        self.set_x(x);
        self.sc.grad(&self.parts.x_full, &mut self.parts.grad_full);
        for (k, &j) in self.parts.free.iter().enumerate() {
            grad[k] = self.parts.grad_full[j];
        }
    }
    fn eval_g(&mut self, x: &[f64], g: &mut [f64]) {
        self.set_x(x);
        self.sc.g(&self.parts.x_full, &mut self.parts.g_full);
        for (k, &i) in self.parts.rows.iter().enumerate() {
            g[k] = self.parts.g_full[i];
        }
    }
    fn eval_jac_g(&mut self, x: &[f64], values: &mut [f64]) {
        self.set_x(x);
        self.sc.jac(&self.parts.x_full, &mut self.parts.jac_full);
        let jmap = &self.parts.sub.as_ref().expect("sub-patterns").jmap;
        for (v, &q) in values.iter_mut().zip(jmap) {
            *v = self.parts.jac_full[q];
        }
    }
    fn eval_hess_l(&mut self, x: &[f64], obj_factor: f64, lambda: &[f64], values: &mut [f64]) {
        self.set_x(x);
        for (k, &i) in self.parts.rows.iter().enumerate() {
            self.parts.lam_full[i] = lambda[k];
        }
        let p = &mut self.parts;
        self.sc
            .hess(&p.x_full, obj_factor, &p.lam_full, &mut p.hess_full);
        let hmap = &p.sub.as_ref().expect("sub-patterns").hmap;
        for (v, &q) in values.iter_mut().zip(hmap) {
            *v = p.hess_full[q];
        }
    }
    fn variable_name(&self, i: usize) -> String {
        self.sc.user().variable_name(self.parts.free[i])
    }
    fn constraint_name(&self, i: usize) -> String {
        self.sc.user().constraint_name(self.parts.rows[i])
    }
}

impl IpmProblem for Reduced<'_> {
    /// Fixed variables at their values, free ones from `x`; λ = y·s_g/s_f (rows without
    /// bounds: 0), as in the returned solution.
    fn user_point(&self, x: &[f64], y: &[f64], x_user: &mut [f64], lambda_user: &mut [f64]) {
        x_user.copy_from_slice(&self.parts.x_full);
        for (k, &j) in self.parts.free.iter().enumerate() {
            x_user[j] = x[k];
        }
        lambda_user.iter_mut().for_each(|v| *v = 0.0);
        for (k, &i) in self.parts.rows.iter().enumerate() {
            lambda_user[i] = self.sc.scaling.lambda_to_user(i, y[k]);
        }
    }
}
