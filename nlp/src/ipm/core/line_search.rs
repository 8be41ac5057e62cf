//! The backtracking filter line search with second-order corrections.

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use super::step_kind::{LineSearch, StepKind};
use super::vectors::one_norm;
use super::Core;
use super::Shared;

/// The current point's merit values the trial points are judged against.
struct Merit {
    /// Infeasibility θ = ‖c‖₁.
    theta: f64,
    /// Barrier objective φ.
    phi: f64,
    /// Directional derivative of φ along the search direction.
    gpd: f64,
}

impl Core<'_> {
    // ------------------------------------------------------------------ line search

    /// Backtracking filter line search with second-order corrections. On success the
    /// trial point is accepted.
    pub(super) fn line_search(&mut self, shared: &mut Shared) -> LineSearch {
        let here = Merit {
            theta: one_norm(&self.it.c),
            phi: self.barrier(&self.it.w, self.it.f, self.mu_update.mu()),
            gpd: self.barrier_at(self.mu_update.mu()).dir_deriv(
                &self.it.w,
                &self.it.grad[..self.lay.n],
                &self.dir.dw,
            ),
        };
        let alpha_max = self.max_step_primal(&self.dir.dw, self.mu_update.tau());
        let alpha_min = self.accept.alpha_min(here.theta, here.gpd);
        let mut alpha = alpha_max;
        let mut ls = 0usize;
        loop {
            // The first trial step is always tried, even below α_min (IPOPT).
            if ls > 0 && !(alpha > alpha_min) {
                return LineSearch::Failed {
                    alpha_pr: alpha,
                    trials: ls,
                };
            }
            ls += 1;
            for j in 0..self.lay.nw {
                self.trial.w[j] = self.it.w[j] + alpha * self.dir.dw[j];
            }
            if self.eval_trial_fc() {
                let theta_t = one_norm(&self.trial.c);
                let phi_t = self.barrier(&self.trial.w, self.trial.f, self.mu_update.mu());
                if self.is_acceptable(&here, alpha, (theta_t, phi_t)) {
                    let trial = self.accept_if_smooth(&here, alpha, alpha, phi_t, false, ls);
                    if let Some(accepted) = trial {
                        return accepted;
                    }
                } else if alpha == alpha_max
                    && theta_t >= here.theta
                    && self.opts.max_soc > 0
                    && self.lay.m > 0
                {
                    let corrected =
                        self.second_order_corrections(shared, &here, alpha, theta_t, ls);
                    if let Some(accepted) = corrected {
                        return accepted;
                    }
                }
            }
            alpha *= self.opts.alpha_red_factor;
        }
    }

    /// Second-order corrections (IPOPT's TrySecondOrderCorrection) after the full step
    /// `alpha` was rejected with infeasibility `theta_t`: c_soc ← α_soc·c_soc + c(trial),
    /// starting from c_soc = c and α_soc = α; another correction is tried while the last
    /// one reduced θ by κ_soc against the trial point before it. The acceptance tests use
    /// the original step size α. `Some` when a corrected step was accepted.
    fn second_order_corrections(
        &mut self,
        shared: &mut Shared,
        here: &Merit,
        alpha: f64,
        theta_t: f64,
        trials: usize,
    ) -> Option<LineSearch> {
        self.c_soc.copy_from_slice(&self.it.c);
        let mut a_soc = alpha;
        let mut theta_trial = theta_t;
        let mut theta_soc_old = 0.0;
        for count in 0..self.opts.max_soc {
            if count > 0 && !(theta_trial <= self.opts.kappa_soc * theta_soc_old) {
                break;
            }
            theta_soc_old = theta_trial;
            for i in 0..self.lay.m {
                self.c_soc[i] = a_soc * self.c_soc[i] + self.trial.c[i];
            }
            if !self.solve_direction(shared, self.mu_update.mu(), true) {
                break;
            }
            a_soc = self.max_step_primal(&self.dir_soc.dw, self.mu_update.tau());
            for j in 0..self.lay.nw {
                self.trial.w[j] = self.it.w[j] + a_soc * self.dir_soc.dw[j];
            }
            if !self.eval_trial_fc() {
                break;
            }
            let th = one_norm(&self.trial.c);
            let ph = self.barrier(&self.trial.w, self.trial.f, self.mu_update.mu());
            if self.is_acceptable(here, alpha, (th, ph)) {
                return self.accept_if_smooth(here, alpha, a_soc, ph, true, trials);
            }
            theta_trial = th;
        }
        None
    }

    /// The filter's verdict on the trial point `(θ, φ)` reached with step size `alpha`.
    fn is_acceptable(&self, here: &Merit, alpha: f64, trial: (f64, f64)) -> bool {
        self.accept
            .is_acceptable(&self.filter, alpha, (here.theta, here.phi), here.gpd, trial)
    }

    /// Completes an acceptable trial point (primal step `alpha_pr` along the direction,
    /// the second-order one if `soc`) with its multipliers `y`; if its derivatives are
    /// finite, updates the filter (with the line search's `alpha`), takes the dual step
    /// and accepts it. `None` when the derivatives are not finite.
    fn accept_if_smooth(
        &mut self,
        here: &Merit,
        alpha: f64,
        alpha_pr: f64,
        phi_t: f64,
        soc: bool,
        trials: usize,
    ) -> Option<LineSearch> {
        let dir = if soc { &self.dir_soc } else { &self.dir };
        for i in 0..self.lay.m {
            self.trial.y[i] = self.it.y[i] + alpha_pr * dir.dy[i];
        }
        if !self.eval_trial_derivs() {
            return None;
        }
        let ftype = self.accept.after_step(
            &mut self.filter,
            alpha,
            (here.theta, here.phi),
            here.gpd,
            phi_t,
        );
        let dir = if soc { &self.dir_soc } else { &self.dir };
        let alpha_du = self.max_step_dual(&dir.dzl, &dir.dzu, self.mu_update.tau());
        self.take_dual_step(alpha_du, soc);
        self.accept_trial();
        Some(LineSearch::Accepted {
            alpha_pr,
            alpha_du,
            kind: StepKind::new(ftype, soc),
            trials,
        })
    }

    /// z ← z + α_du·dz with the κ_Σ safeguard at the trial point (w_t).
    pub(super) fn take_dual_step(&mut self, alpha_du: f64, soc: bool) {
        let ks = self.opts.kappa_sigma;
        let mu = self.mu_update.mu();
        for j in 0..self.lay.nw {
            let (dl, du) = if soc {
                (self.dir_soc.dzl[j], self.dir_soc.dzu[j])
            } else {
                (self.dir.dzl[j], self.dir.dzu[j])
            };
            if self.lay.has_l[j] {
                let s = self.trial.w[j] - self.lay.wl[j];
                let z = self.it.zl[j] + alpha_du * dl;
                self.it.zl[j] = z.min(ks * mu / s).max(mu / (ks * s));
            }
            if self.lay.has_u[j] {
                let s = self.lay.wu[j] - self.trial.w[j];
                let z = self.it.zu[j] + alpha_du * du;
                self.it.zu[j] = z.min(ks * mu / s).max(mu / (ks * s));
            }
        }
    }

    /// Full step without line search (tiny steps).
    pub(super) fn take_full_step(&mut self) -> bool {
        let alpha = self.max_step_primal(&self.dir.dw, self.mu_update.tau());
        for j in 0..self.lay.nw {
            self.trial.w[j] = self.it.w[j] + alpha * self.dir.dw[j];
        }
        for i in 0..self.lay.m {
            self.trial.y[i] = self.it.y[i] + alpha * self.dir.dy[i];
        }
        if !self.eval_trial_fc() || !self.eval_trial_derivs() {
            return false;
        }
        let alpha_du = self.max_step_dual(&self.dir.dzl, &self.dir.dzu, self.mu_update.tau());
        self.take_dual_step(alpha_du, false);
        self.accept_trial();
        true
    }
}
