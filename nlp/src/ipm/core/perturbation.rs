//! The perturbation handler (IPOPT's PDPerturbationHandler): the Hessian perturbation
//! δ_w and the Jacobian perturbation δ_c, their state and rules, and the inertia-correcting
//! factorisation.

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use super::*;

/// State of the inertia correction across iterations.
#[derive(Default)]
pub(super) struct Perturbation {
    /// δ_w of the current factorisation.
    pub(super) delta_w: f64,
    /// The last nonzero δ_w (0 if none was needed yet, or after a restoration phase).
    pub(super) delta_w_last: f64,
    /// δ_c of the current factorisation.
    pub(super) delta_c: f64,
    /// δ_c is applied from the start (after three singular iterations in a row).
    pub(super) jac_degenerate: bool,
    /// Iterations in a row whose unregularised system was singular.
    pub(super) singular_iters: usize,
    /// Iterations in a row that needed δ_w > 0.
    pub(super) perturbed_iters: usize,
    /// A step was solved without δ_c: the Jacobian is not degenerate, and
    /// `jac_degenerate` can no longer be set (IPOPT's PDPerturbationHandler decides
    /// degeneracy once, in the first iterations: "Nj" in its info string).
    pub(super) jac_determined: bool,
}

impl Perturbation {
    /// δ_c = jacobian_regularization_value · μ^jacobian_regularization_exponent.
    pub(super) fn delta_cd(opts: &IpmOptions, mu: f64) -> f64 {
        opts.jacobian_regularization_value * mu.powf(opts.jacobian_regularization_exponent)
    }

    /// IPOPT's next trial δ_w: the first one is `first_hessian_perturbation`, or
    /// κ_w⁻·δ_w_last when an earlier iteration needed one; then ×κ_w⁺ (×κ̄_w⁺ while no
    /// earlier iteration needed one).
    pub(super) fn next_delta_w(&self, o: &IpmOptions, delta_w: f64) -> f64 {
        if delta_w == 0.0 {
            if self.delta_w_last == 0.0 {
                o.first_hessian_perturbation
            } else {
                o.min_hessian_perturbation
                    .max(o.perturb_dec_fact * self.delta_w_last)
            }
        } else if self.delta_w_last == 0.0 {
            delta_w * o.perturb_inc_fact_first
        } else {
            delta_w * o.perturb_inc_fact
        }
    }
}

impl Core<'_> {
    /// Factorises the KKT matrix with IPOPT's inertia correction. Returns false if δ_w
    /// exceeded its maximum.
    pub(super) fn factorize_with_inertia_correction(&mut self, shared: &mut Shared) -> bool {
        let (n, m) = (self.lay.n, self.lay.m);
        self.update_eq_reg();
        let mut delta_w = 0.0;
        self.pert.delta_c = if self.pert.jac_degenerate && m > 0 {
            Perturbation::delta_cd(&self.opts, self.mu)
        } else {
            0.0
        };
        let mut tried_delta_c = self.pert.delta_c > 0.0;
        // After `perturbation_skip_zero_after` iterations in a row that needed δ_w > 0,
        // start from IPOPT's second trial κ_w⁻·δ_w_last and skip the δ_w = 0 trial
        // (saves one factorisation per iteration on nonconvex problems). δ_w then keeps
        // shrinking by κ_w⁻ per iteration while the inertia allows it.
        let skip = self.opts.perturbation_skip_zero_after;
        let skipped = skip > 0 && self.pert.perturbed_iters >= skip && self.pert.delta_w_last > 0.0;
        if skipped {
            delta_w = self.pert.next_delta_w(&self.opts, 0.0);
        }
        loop {
            let res = self.factor_kkt(shared, delta_w);
            let singular = match res {
                Ok(inertia) => {
                    if inertia.positive == n && inertia.negative == m && inertia.zero == 0 {
                        self.pert.delta_w = delta_w;
                        if delta_w > 0.0 {
                            self.pert.delta_w_last = delta_w;
                            self.pert.perturbed_iters += 1;
                        } else {
                            self.pert.perturbed_iters = 0;
                        }
                        return true;
                    }
                    inertia.zero > 0
                }
                Err(_) => true,
            };
            let o = &self.opts;
            if singular && !tried_delta_c && m > 0 {
                tried_delta_c = true;
                self.pert.delta_c = Perturbation::delta_cd(&self.opts, self.mu);
                if self.pert.delta_c > 0.0 {
                    continue;
                }
            }
            delta_w = self.pert.next_delta_w(&self.opts, delta_w);
            if delta_w > o.max_hessian_perturbation {
                self.pert.delta_w = delta_w;
                return false;
            }
        }
    }
}
