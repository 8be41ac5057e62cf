//! The user's NLP as the interior-point core sees it: fixed variables removed
//! (IPOPT's `fixed_variable_treatment = make_parameter`) and rows without bounds dropped,
//! on top of the front end's scaled problem ([`ScaledNlp`]: scaling, evaluation
//! counters and timing).

#![allow(clippy::needless_range_loop)]

use faer::sparse::SymbolicSparseColMat;

use crate::frontend::scaled::{ScaledNlp, Scaling};
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
    /// Free variable indices (user numbering).
    pub free: Vec<usize>,
    /// Kept row indices (user numbering).
    pub rows: Vec<usize>,
    jac: SymbolicSparseColMat<usize>,
    jmap: Vec<usize>,
    hess: SymbolicSparseColMat<usize>,
    hmap: Vec<usize>,
    pub x_l: Vec<f64>,
    pub x_u: Vec<f64>,
    /// Unscaled bounds of the kept rows.
    pub g_l: Vec<f64>,
    pub g_u: Vec<f64>,
    pub x0: Vec<f64>,
    pub x_full: Vec<f64>,
    g_full: Vec<f64>,
    jac_full: Vec<f64>,
    hess_full: Vec<f64>,
    lam_full: Vec<f64>,
    grad_full: Vec<f64>,
}

impl<'a> Reduced<'a> {
    /// `x_l..g_u` are the validated user bounds, `x0` the user starting point.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        user: &'a mut dyn NumericNlp,
        x_l: &[f64],
        x_u: &[f64],
        g_l: &[f64],
        g_u: &[f64],
        x0: &[f64],
    ) -> Self {
        let n_user = x_l.len();
        let m_user = g_l.len();
        let free: Vec<usize> = (0..n_user).filter(|&j| x_l[j] != x_u[j]).collect();
        let rows: Vec<usize> = (0..m_user)
            .filter(|&i| g_l[i] > f64::NEG_INFINITY || g_u[i] < f64::INFINITY)
            .collect();
        let mut col_new = vec![usize::MAX; n_user];
        for (k, &j) in free.iter().enumerate() {
            col_new[j] = k;
        }
        let mut row_new = vec![usize::MAX; m_user];
        for (k, &i) in rows.iter().enumerate() {
            row_new[i] = k;
        }
        let (jac, jmap) = {
            let pat = user.jac_g_sparsity();
            sub_pattern(pat, &free, &row_new, rows.len(), false)
        };
        let (hess, hmap) = {
            let pat = user.hess_l_sparsity();
            sub_pattern(pat, &free, &col_new, free.len(), true)
        };
        let mut x_full = x0.to_vec();
        for j in 0..n_user {
            if x_l[j] == x_u[j] {
                x_full[j] = x_l[j];
            }
        }
        let jac_len = user.jac_g_sparsity().row_idx().len();
        let hess_len = user.hess_l_sparsity().row_idx().len();
        Reduced {
            free: free.clone(),
            jac,
            jmap,
            hess,
            hmap,
            x_l: free.iter().map(|&j| x_l[j]).collect(),
            x_u: free.iter().map(|&j| x_u[j]).collect(),
            g_l: rows.iter().map(|&i| g_l[i]).collect(),
            g_u: rows.iter().map(|&i| g_u[i]).collect(),
            x0: free.iter().map(|&j| x0[j]).collect(),
            rows,
            x_full,
            g_full: vec![0.0; m_user],
            jac_full: vec![0.0; jac_len],
            hess_full: vec![0.0; hess_len],
            lam_full: vec![0.0; m_user],
            grad_full: vec![0.0; n_user],
            sc: ScaledNlp::new(user),
        }
    }

    /// The scaling of the reduced problem (the factors of the kept rows).
    pub fn scaling(&self) -> Scaling {
        self.sc.scaling.restrict(&self.rows)
    }

    fn set_x(&mut self, x: &[f64]) {
        for (k, &j) in self.free.iter().enumerate() {
            self.x_full[j] = x[k];
        }
    }

    /// Unscaled max-norms at the reduced point `x` (counted), for choosing the factors:
    /// of ∇f over the free variables, and of each kept row of the Jacobian over them.
    pub fn unscaled_gradient_norms(&mut self, x: &[f64]) -> (f64, Vec<f64>) {
        self.set_x(x);
        let mut is_free = vec![false; self.x_full.len()];
        for &j in &self.free {
            is_free[j] = true;
        }
        let (gmax, rmax) = self
            .sc
            .unscaled_gradient_norms(&self.x_full, Some(&is_free));
        (gmax, self.rows.iter().map(|&i| rmax[i]).collect())
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
        self.free.len()
    }
    fn m(&self) -> usize {
        self.rows.len()
    }
    fn bounds(&self, x_l: &mut [f64], x_u: &mut [f64], g_l: &mut [f64], g_u: &mut [f64]) {
        x_l.copy_from_slice(&self.x_l);
        x_u.copy_from_slice(&self.x_u);
        for (k, &i) in self.rows.iter().enumerate() {
            g_l[k] = self.g_l[k] * self.sc.scaling.rows[i];
            g_u[k] = self.g_u[k] * self.sc.scaling.rows[i];
        }
    }
    fn initial_point(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.x0);
    }
    fn jac_g_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        &self.jac
    }
    fn hess_l_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        &self.hess
    }
    fn eval_f(&mut self, x: &[f64]) -> f64 {
        self.set_x(x);
        self.sc.f(&self.x_full)
    }
    fn eval_grad_f(&mut self, x: &[f64], grad: &mut [f64]) {
        self.set_x(x);
        self.sc.grad(&self.x_full, &mut self.grad_full);
        for (k, &j) in self.free.iter().enumerate() {
            grad[k] = self.grad_full[j];
        }
    }
    fn eval_g(&mut self, x: &[f64], g: &mut [f64]) {
        self.set_x(x);
        self.sc.g(&self.x_full, &mut self.g_full);
        for (k, &i) in self.rows.iter().enumerate() {
            g[k] = self.g_full[i];
        }
    }
    fn eval_jac_g(&mut self, x: &[f64], values: &mut [f64]) {
        self.set_x(x);
        self.sc.jac(&self.x_full, &mut self.jac_full);
        for (v, &q) in values.iter_mut().zip(&self.jmap) {
            *v = self.jac_full[q];
        }
    }
    fn eval_hess_l(&mut self, x: &[f64], obj_factor: f64, lambda: &[f64], values: &mut [f64]) {
        self.set_x(x);
        for (k, &i) in self.rows.iter().enumerate() {
            self.lam_full[i] = lambda[k];
        }
        let (x_full, lam) = (&self.x_full, &self.lam_full);
        self.sc.hess(x_full, obj_factor, lam, &mut self.hess_full);
        for (p, &q) in self.hmap.iter().enumerate() {
            values[p] = self.hess_full[q];
        }
    }
    fn variable_name(&self, i: usize) -> String {
        self.sc.user().variable_name(self.free[i])
    }
    fn constraint_name(&self, i: usize) -> String {
        self.sc.user().constraint_name(self.rows[i])
    }
}

impl IpmProblem for Reduced<'_> {
    /// Fixed variables at their values, free ones from `x`; λ = y·s_g/s_f (rows without
    /// bounds: 0), as in the returned solution.
    fn user_point(&self, x: &[f64], y: &[f64], x_user: &mut [f64], lambda_user: &mut [f64]) {
        x_user.copy_from_slice(&self.x_full);
        for (k, &j) in self.free.iter().enumerate() {
            x_user[j] = x[k];
        }
        lambda_user.iter_mut().for_each(|v| *v = 0.0);
        for (k, &i) in self.rows.iter().enumerate() {
            lambda_user[i] = self.sc.scaling.lambda_to_user(i, y[k]);
        }
    }
}
