//! The backtracking filter line search with second-order corrections.

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use super::one_norm;
use super::Core;
use super::Shared;

/// How the step of an accepted trial point was made (the log's character after
/// alpha_pr: lower case for the plain step, upper case for a second-order correction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum StepKind {
    /// f-type: the switching and Armijo conditions hold; the filter is not augmented.
    FType { soc: bool },
    /// h-type: the filter was augmented.
    HType { soc: bool },
    /// A soft restoration step (IPOPT's 's'; 'S' when it is acceptable to the filter,
    /// which ends the soft restoration phase).
    Soft { original: bool },
}

impl StepKind {
    pub(super) fn new(ftype: bool, soc: bool) -> StepKind {
        if ftype {
            StepKind::FType { soc }
        } else {
            StepKind::HType { soc }
        }
    }

    pub(super) fn log_char(self) -> char {
        match self {
            StepKind::FType { soc: false } => 'f',
            StepKind::HType { soc: false } => 'h',
            StepKind::FType { soc: true } => 'F',
            StepKind::HType { soc: true } => 'H',
            StepKind::Soft { original: false } => 's',
            StepKind::Soft { original: true } => 'S',
        }
    }
}

/// The outcome of [`Core::line_search`]; `trials` counts the trial step sizes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum LineSearch {
    /// A trial point was accepted (and is now the iterate).
    Accepted {
        alpha_pr: f64,
        alpha_du: f64,
        kind: StepKind,
        trials: usize,
    },
    /// Every step size down to α_min was rejected; `alpha_pr` is the last one tried.
    Failed { alpha_pr: f64, trials: usize },
}

impl Core<'_> {
    // ------------------------------------------------------------------ line search

    /// Backtracking filter line search with second-order corrections. On success the
    /// trial point is accepted.
    pub(super) fn line_search(&mut self, shared: &mut Shared) -> LineSearch {
        let theta = one_norm(&self.it.c);
        let phi = self.barrier(&self.it.w, self.it.f, self.mu);
        let gpd = self.barrier_dir_deriv(&self.dir.dw);
        let alpha_max = self.max_step_primal(&self.dir.dw, self.tau);
        let alpha_min = self.accept.alpha_min(theta, gpd);
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
            let finite = self.eval_trial_fc();
            if finite {
                let theta_t = one_norm(&self.trial.c);
                let phi_t = self.barrier(&self.trial.w, self.trial.f, self.mu);
                if self.accept.is_acceptable(
                    &self.filter,
                    alpha,
                    (theta, phi),
                    gpd,
                    (theta_t, phi_t),
                ) {
                    for i in 0..self.lay.m {
                        self.trial.y[i] = self.it.y[i] + alpha * self.dir.dy[i];
                    }
                    if self.eval_trial_derivs() {
                        let ftype = self.accept.after_step(
                            &mut self.filter,
                            alpha,
                            (theta, phi),
                            gpd,
                            phi_t,
                        );
                        let alpha_du = self.max_step_dual(&self.dir.dzl, &self.dir.dzu, self.tau);
                        self.take_dual_step(alpha_du, false);
                        self.accept_trial();
                        return LineSearch::Accepted {
                            alpha_pr: alpha,
                            alpha_du,
                            kind: StepKind::new(ftype, false),
                            trials: ls,
                        };
                    }
                } else if alpha == alpha_max
                    && theta_t >= theta
                    && self.opts.max_soc > 0
                    && self.lay.m > 0
                {
                    // Second-order corrections (IPOPT's TrySecondOrderCorrection):
                    // c_soc ← α_soc·c_soc + c(trial), starting from c_soc = c and
                    // α_soc = α; another correction is tried while the last one
                    // reduced θ by κ_soc against the trial point before it. The
                    // acceptance tests use the original step size α.
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
                        if !self.solve_direction(shared, self.mu, true) {
                            break;
                        }
                        a_soc = self.max_step_primal(&self.dir_soc.dw, self.tau);
                        for j in 0..self.lay.nw {
                            self.trial.w[j] = self.it.w[j] + a_soc * self.dir_soc.dw[j];
                        }
                        if !self.eval_trial_fc() {
                            break;
                        }
                        let th = one_norm(&self.trial.c);
                        let ph = self.barrier(&self.trial.w, self.trial.f, self.mu);
                        if self.accept.is_acceptable(
                            &self.filter,
                            alpha,
                            (theta, phi),
                            gpd,
                            (th, ph),
                        ) {
                            for i in 0..self.lay.m {
                                self.trial.y[i] = self.it.y[i] + a_soc * self.dir_soc.dy[i];
                            }
                            if self.eval_trial_derivs() {
                                let ftype = self.accept.after_step(
                                    &mut self.filter,
                                    alpha,
                                    (theta, phi),
                                    gpd,
                                    ph,
                                );
                                let alpha_du = self.max_step_dual(
                                    &self.dir_soc.dzl,
                                    &self.dir_soc.dzu,
                                    self.tau,
                                );
                                self.take_dual_step(alpha_du, true);
                                self.accept_trial();
                                return LineSearch::Accepted {
                                    alpha_pr: a_soc,
                                    alpha_du,
                                    kind: StepKind::new(ftype, true),
                                    trials: ls,
                                };
                            }
                            break;
                        }
                        theta_trial = th;
                    }
                }
            }
            alpha *= self.opts.alpha_red_factor;
        }
    }

    /// z ← z + α_du·dz with the κ_Σ safeguard at the trial point (w_t).
    pub(super) fn take_dual_step(&mut self, alpha_du: f64, soc: bool) {
        let ks = self.opts.kappa_sigma;
        let mu = self.mu;
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
        let alpha = self.max_step_primal(&self.dir.dw, self.tau);
        for j in 0..self.lay.nw {
            self.trial.w[j] = self.it.w[j] + alpha * self.dir.dw[j];
        }
        for i in 0..self.lay.m {
            self.trial.y[i] = self.it.y[i] + alpha * self.dir.dy[i];
        }
        if !self.eval_trial_fc() || !self.eval_trial_derivs() {
            return false;
        }
        let alpha_du = self.max_step_dual(&self.dir.dzl, &self.dir.dzu, self.tau);
        self.take_dual_step(alpha_du, false);
        self.accept_trial();
        true
    }
}
