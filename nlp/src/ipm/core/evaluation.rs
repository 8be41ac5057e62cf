//! Evaluation of the problem at the iterate and the trial point, acceptance of a trial
//! point, and the products with the Jacobian the parts share.

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use super::vectors::{all_finite, first_non_finite, inf_norm};
use super::Core;
use crate::ipm::error::At;
use crate::ipm::error::CoreError;

impl Core<'_> {
    // ------------------------------------------------------------------ evaluation

    /// c = g − s (inequality rows) or g − g_eq (equality rows).
    pub(super) fn constraint_residual(&self, w: &[f64], g: &[f64], c: &mut [f64]) {
        for i in 0..self.lay.m {
            let k = self.lay.slack_of_row[i];
            c[i] = if k == usize::MAX {
                g[i] - self.lay.g_eq[i]
            } else {
                g[i] - w[self.lay.n + k]
            };
        }
    }

    /// out = Aᵀ y with A = [J, −E].
    pub(super) fn at_times(&self, jac: &[f64], y: &[f64], out: &mut [f64]) {
        let pat = self.nlp.jac_g_sparsity();
        let rows = pat.row_idx();
        for (j, o) in out[..self.lay.n].iter_mut().enumerate() {
            let range = pat.col_range(j);
            let mut s = 0.0;
            for (&v, &i) in jac[range.clone()].iter().zip(&rows[range]) {
                s += v * y[i];
            }
            *o = s;
        }
        for k in 0..self.lay.ni {
            out[self.lay.n + k] = -y[self.lay.row_of_slack[k]];
        }
    }

    /// Evaluates f and g at `w_t` into the trial buffers; false if non-finite.
    pub(super) fn eval_trial_fc(&mut self) -> bool {
        let x = &self.trial.w[..self.lay.n];
        self.trial.f = self.nlp.eval_f(x);
        if !self.trial.f.is_finite() {
            return false;
        }
        self.nlp.eval_g(x, &mut self.trial.g);
        if !all_finite(&self.trial.g) {
            return false;
        }
        let (w_t, g_t) = (&self.trial.w, &self.trial.g);
        let mut c_t = std::mem::take(&mut self.trial.c);
        self.constraint_residual(w_t, g_t, &mut c_t);
        self.trial.c = c_t;
        true
    }

    /// Evaluates ∇f, J and the Hessian at the trial point with multipliers `y_t`.
    pub(super) fn eval_trial_derivs(&mut self) -> bool {
        let x = &self.trial.w[..self.lay.n];
        self.nlp.eval_grad_f(x, &mut self.trial.grad);
        if !all_finite(&self.trial.grad) {
            return false;
        }
        self.nlp.eval_jac_g(x, &mut self.trial.jac);
        if !all_finite(&self.trial.jac) {
            return false;
        }
        if self.kw.lm.is_some() {
            // The Hessian values stay 0: W = the low-rank approximation, updated in
            // `accept_trial` (after `recalc_y` may have changed y, as in IPOPT).
            return true;
        }
        self.nlp
            .eval_hess_l(x, 1.0, &self.trial.y, &mut self.trial.hess);
        all_finite(&self.trial.hess)
    }

    /// Makes the trial point current (swapping buffers), then applies `recalc_y` and the
    /// limited-memory update at the new point (IPOPT's AcceptTrialPoint and UpdateHessian).
    pub(super) fn accept_trial(&mut self) {
        std::mem::swap(&mut self.it.w, &mut self.trial.w);
        std::mem::swap(&mut self.it.y, &mut self.trial.y);
        std::mem::swap(&mut self.it.grad, &mut self.trial.grad);
        std::mem::swap(&mut self.it.g, &mut self.trial.g);
        std::mem::swap(&mut self.it.c, &mut self.trial.c);
        std::mem::swap(&mut self.it.jac, &mut self.trial.jac);
        std::mem::swap(&mut self.it.hess, &mut self.trial.hess);
        self.it.f = self.trial.f;
        if self.recalc_y && inf_norm(&self.it.c) < self.opts.recalc_y_feas_tol {
            self.recalc_multipliers();
        }
        if let Some(lm) = self.kw.lm.as_mut() {
            let x = &self.it.w[..self.lay.n];
            let (g, j, pat) = (&self.it.grad, &self.it.jac, self.nlp.jac_g_sparsity());
            lm.update(x, g, j, pat, &self.it.y);
        }
    }

    /// Evaluates everything at the current w, y. Err names the callback on NaN/Inf.
    pub(super) fn eval_current(&mut self) -> Result<(), CoreError> {
        self.eval_all(At::Start)
    }

    /// f, ∇f, g, J and ∇²L at the current w, y, and the residual c; Err names the first
    /// non-finite value.
    pub(super) fn eval_all(&mut self, at: At) -> Result<(), CoreError> {
        self.eval_first_order(at)?;
        self.eval_hessian(at)?;
        let mut c = std::mem::take(&mut self.it.c);
        self.constraint_residual(&self.it.w, &self.it.g, &mut c);
        self.it.c = c;
        Ok(())
    }

    /// f, ∇f, g and J at the current w; Err names the first non-finite value.
    pub(super) fn eval_first_order(&mut self, at: At) -> Result<(), CoreError> {
        let n = self.lay.n;
        let x = &self.it.w[..n];
        self.it.f = self.nlp.eval_f(x);
        if !self.it.f.is_finite() {
            return Err(CoreError::Objective {
                value: self.it.f,
                at,
            });
        }
        self.nlp.eval_grad_f(x, &mut self.it.grad);
        if let Some(i) = first_non_finite(&self.it.grad) {
            return Err(CoreError::Gradient {
                value: self.it.grad[i],
                index: i,
                name: self.nlp.variable_name(i),
                at,
            });
        }
        self.nlp.eval_g(x, &mut self.it.g);
        self.check_g(at)?;
        self.nlp.eval_jac_g(x, &mut self.it.jac);
        if let Some(p) = first_non_finite(&self.it.jac) {
            let pat = self.nlp.jac_g_sparsity();
            let col = (0..n).find(|&j| pat.col_range(j).contains(&p)).unwrap_or(0);
            let row = pat.row_idx()[p];
            return Err(CoreError::Jacobian {
                value: self.it.jac[p],
                row,
                row_name: self.nlp.constraint_name(row),
                col,
                col_name: self.nlp.variable_name(col),
                at,
            });
        }
        Ok(())
    }

    /// ∇²L at the current w, y; Err names the first non-finite entry.
    pub(super) fn eval_hessian(&mut self, at: At) -> Result<(), CoreError> {
        let n = self.lay.n;
        let x = &self.it.w[..n];
        if let Some(lm) = self.kw.lm.as_mut() {
            let (g, j, pat) = (&self.it.grad, &self.it.jac, self.nlp.jac_g_sparsity());
            lm.update(x, g, j, pat, &self.it.y);
            return Ok(()); // the Hessian values stay 0: W = the low-rank approximation
        }
        self.nlp.eval_hess_l(x, 1.0, &self.it.y, &mut self.it.hess);
        if let Some(p) = first_non_finite(&self.it.hess) {
            let pat = self.nlp.hess_l_sparsity();
            let col = (0..n).find(|&j| pat.col_range(j).contains(&p)).unwrap_or(0);
            let row = pat.row_idx()[p];
            return Err(CoreError::Hessian {
                value: self.it.hess[p],
                row,
                row_name: self.nlp.variable_name(row),
                col,
                col_name: self.nlp.variable_name(col),
                at,
            });
        }
        Ok(())
    }
}
