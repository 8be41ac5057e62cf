//! IPOPT's soft restoration phase (BacktrackingLineSearch::TrySoftRestoStep): when the
//! line search fails, the step along the current direction with equal primal and dual
//! step sizes is taken if it is acceptable to the filter or reduces the primal-dual
//! system error by the factor `soft_resto_pderror_reduction_factor`; the phase goes on,
//! one such step per iteration, until a step is acceptable to the filter again, for at
//! most `max_soft_resto_iters` iterations. Only a failed soft step starts the
//! restoration phase proper.

#![allow(clippy::needless_range_loop)]

use super::step_kind::LineSearch;
use super::step_kind::StepKind;
use super::vectors::one_norm;
use super::Core;
use super::Shared;

/// An accepted soft restoration step.
pub(super) struct SoftStep {
    /// The common primal and dual step size.
    pub(super) alpha: f64,
    /// The new point is acceptable to the filter (IPOPT's 'S'; the phase ends).
    pub(super) original: bool,
}

impl Core<'_> {
    /// IPOPT's primal-dual system error at the current iterate (its
    /// `curr_primal_dual_system_error`): the 1-norms of the dual infeasibility, the
    /// constraint residual and the complementarity against `mu`, each divided by its
    /// number of entries, summed (scaled problem).
    fn primal_dual_error(&mut self, mu: f64) -> f64 {
        let n = self.lay.n;
        let mut work = std::mem::take(&mut self.kw.work_nw);
        self.at_times(&self.it.jac, &self.it.y, &mut work);
        let (mut dual, mut compl, mut n_compl) = (0.0, 0.0, 0usize);
        for j in 0..self.lay.nw {
            let gj = if j < n { self.it.grad[j] } else { 0.0 };
            dual += (gj + work[j] - self.it.zl[j] + self.it.zu[j]).abs();
            if self.lay.has_l[j] {
                compl += ((self.it.w[j] - self.lay.wl[j]) * self.it.zl[j] - mu).abs();
                n_compl += 1;
            }
            if self.lay.has_u[j] {
                compl += ((self.lay.wu[j] - self.it.w[j]) * self.it.zu[j] - mu).abs();
                n_compl += 1;
            }
        }
        self.kw.work_nw = work;
        let mut e = dual / self.lay.nw.max(1) as f64;
        if self.lay.m > 0 {
            e += one_norm(&self.it.c) / self.lay.m as f64;
        }
        if n_compl > 0 {
            e += compl / n_compl as f64;
        }
        e
    }

    /// Tries the soft restoration step along the current direction; on success the
    /// trial point is the iterate. The filter must already hold the current point
    /// (IPOPT's PrepareRestoPhaseStart).
    pub(super) fn try_soft_resto_step(&mut self) -> Option<SoftStep> {
        let factor = self.opts.soft_resto_pderror_reduction_factor;
        if factor <= 0.0 {
            return None;
        }
        let alpha = self
            .max_step_primal(&self.dir.dw, self.mu_update.tau())
            .min(self.max_step_dual(&self.dir.dzl, &self.dir.dzu, self.mu_update.tau()));
        for j in 0..self.lay.nw {
            self.trial.w[j] = self.it.w[j] + alpha * self.dir.dw[j];
        }
        if !self.eval_trial_fc() {
            return None;
        }
        let theta = one_norm(&self.it.c);
        let phi = self.barrier(&self.it.w, self.it.f, self.mu_update.mu());
        let theta_t = one_norm(&self.trial.c);
        let phi_t = self.barrier(&self.trial.w, self.trial.f, self.mu_update.mu());
        // IPOPT tests with step size 0: the switching condition fails, so this is the
        // sufficient-reduction test and the filter.
        let original =
            self.accept
                .is_acceptable(&self.filter, 0.0, (theta, phi), 0.0, (theta_t, phi_t));
        for i in 0..self.lay.m {
            self.trial.y[i] = self.it.y[i] + alpha * self.dir.dy[i];
        }
        if !self.eval_trial_derivs() {
            return None;
        }
        // In free (adaptive) mode IPOPT measures the error at μ = 0.
        let mu_e = if self.mu_update.free_mode() {
            0.0
        } else {
            self.mu_update.mu()
        };
        let current = self.primal_dual_error(mu_e);
        let saved = (!original).then(|| self.it.clone());
        self.take_dual_step(alpha, false);
        self.accept_trial();
        if original {
            return Some(SoftStep { alpha, original });
        }
        if self.primal_dual_error(mu_e) <= factor * current {
            return Some(SoftStep { alpha, original });
        }
        if let Some(it) = saved {
            self.it = it;
        }
        None
    }
}

impl Core<'_> {
    /// Leaves the soft restoration phase (a tiny step or a restoration phase moved the
    /// iterate).
    pub(super) fn end_soft_resto(&mut self) {
        self.soft_resto = None;
    }

    /// The line search of one iteration inside IPOPT's soft restoration logic: in the
    /// soft restoration phase one soft step replaces the line search; otherwise a
    /// failed line search (outside the restoration phase) tries a soft step before it
    /// is reported. A `Failed` result starts the restoration phase; the filter then
    /// holds the current point ([`LineSearch::filter_augmented`]).
    pub(super) fn search_step(&mut self, shared: &mut Shared) -> LineSearch {
        let (failed, count) = match self.soft_resto {
            Some(k) => {
                // The filter got the point where the soft phase started.
                let failed = LineSearch::Failed {
                    alpha_pr: 0.0,
                    trials: 0,
                };
                if k + 1 > self.opts.max_soft_resto_iters {
                    self.end_soft_resto();
                    return failed;
                }
                (failed, k + 1)
            }
            None => {
                let ls = self.line_search(shared);
                if matches!(ls, LineSearch::Accepted { .. }) {
                    return ls;
                }
                // IPOPT's PrepareRestoPhaseStart: the filter gets the current point.
                let theta = one_norm(&self.it.c);
                let phi = self.barrier(&self.it.w, self.it.f, self.mu_update.mu());
                self.accept.augment(&mut self.filter, theta, phi);
                (ls, 0)
            }
        };
        let trials = match failed {
            LineSearch::Failed { trials, .. } => trials + 1,
            LineSearch::Accepted { trials, .. } => trials,
        };
        match self.try_soft_resto_step() {
            Some(step) => {
                self.soft_resto = (!step.original).then_some(count);
                LineSearch::Accepted {
                    alpha_pr: step.alpha,
                    alpha_du: step.alpha,
                    kind: StepKind::Soft {
                        original: step.original,
                    },
                    trials,
                }
            }
            None => {
                self.end_soft_resto();
                failed
            }
        }
    }
}
