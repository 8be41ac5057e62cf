//! The core's side of the μ update ([`MuUpdate`](crate::ipm::mu_update::MuUpdate)):
//! the errors its rules test and the adaptive oracles' steps, solved with the factorised
//! KKT matrix.

#![allow(clippy::needless_range_loop)]

use super::Core;
use super::Shared;
use crate::ipm::mu_update::{loqo_mu, probing_mu, AdaptiveMode};
use crate::ipm::quality;
use crate::options::MuOracle;

impl Core<'_> {
    /// The monotone rule, testing the barrier problem's error E_μ; `force` after a tiny
    /// step.
    pub(super) fn update_mu_monotone(&mut self, force: bool) {
        let mut part = std::mem::take(&mut self.mu_update);
        let changed = part.monotone(force, |mu| self.nlp_error(mu, true).0);
        self.mu_update = part;
        if changed {
            self.filter.reset();
        }
    }

    /// The adaptive rule (called after the KKT matrix is factorised); `e0` is the
    /// optimality error at μ = 0.
    pub(super) fn update_mu_adaptive(&mut self, shared: &mut Shared, e0: f64) {
        let err = self.pd_system_error();
        let (avg, mn) = self.avg_compl(&self.it.w, &self.it.zl, &self.it.zu);
        match self.mu_update.adaptive_mode(err, avg, e0) {
            AdaptiveMode::SwitchedToFixed => self.filter.reset(),
            AdaptiveMode::Fixed => self.update_mu_monotone(false),
            AdaptiveMode::Free => {
                let mu = match self.mu_update.oracle() {
                    MuOracle::Loqo => loqo_mu(avg, mn),
                    MuOracle::Probing => {
                        self.probing_oracle(shared, avg).unwrap_or(loqo_mu(avg, mn))
                    }
                    MuOracle::QualityFunction => self
                        .quality_function_oracle(shared, avg)
                        .unwrap_or(loqo_mu(avg, mn)),
                };
                if self.mu_update.set_free_mu(mu) {
                    self.filter.reset();
                }
            }
        }
    }

    /// IPOPT's quality_function_pd_system: the KKT error at μ = 0 in the norm of
    /// `quality_function_norm_type` (by default mean squares of ∇L, c and the products).
    fn pd_system_error(&mut self) -> f64 {
        let dual = self.grad_lag_norms();
        let primal = quality::Norms::of(self.it.c.iter().copied());
        let (it, lay) = (&self.it, &self.lay);
        let compl = quality::Norms::of((0..lay.nw).flat_map(|j| {
            let lower = lay.has_l[j].then(|| (it.w[j] - lay.wl[j]) * it.zl[j]);
            let upper = lay.has_u[j].then(|| (lay.wu[j] - it.w[j]) * it.zu[j]);
            lower.into_iter().chain(upper)
        }));
        quality::kkt_error(self.opts.quality_function_norm_type, [dual, primal, compl])
    }

    /// Norms of ∇L without the damping term (IPOPT's curr_grad_lag_x, curr_grad_lag_s).
    fn grad_lag_norms(&mut self) -> quality::Norms {
        let mut work = std::mem::take(&mut self.kw.work_nw);
        self.at_times(&self.it.jac, &self.it.y, &mut work);
        let n = self.lay.n;
        let dual = quality::Norms::of((0..self.lay.nw).map(|j| {
            let g = if j < n { self.it.grad[j] } else { 0.0 };
            g + work[j] - self.it.zl[j] + self.it.zu[j]
        }));
        self.kw.work_nw = work;
        dual
    }

    /// Mehrotra's probing oracle: μ from the affine-scaling step's complementarity.
    fn probing_oracle(&mut self, shared: &mut Shared, avg: f64) -> Option<f64> {
        if !self.solve_direction(shared, 0.0, false) {
            return None;
        }
        let ap = self.max_step_primal(&self.dir.dw, 1.0);
        let ad = self.max_step_dual(&self.dir.dzl, &self.dir.dzu, 1.0);
        let mut sum = 0.0;
        let mut cnt = 0usize;
        for j in 0..self.lay.nw {
            if self.lay.has_l[j] {
                sum += (self.it.w[j] + ap * self.dir.dw[j] - self.lay.wl[j])
                    * (self.it.zl[j] + ad * self.dir.dzl[j]);
                cnt += 1;
            }
            if self.lay.has_u[j] {
                sum += (self.lay.wu[j] - self.it.w[j] - ap * self.dir.dw[j])
                    * (self.it.zu[j] + ad * self.dir.dzu[j]);
                cnt += 1;
            }
        }
        let aff = if cnt > 0 { sum / cnt as f64 } else { 0.0 };
        Some(probing_mu(avg, aff.max(0.0)))
    }

    /// IPOPT's quality-function oracle (`crate::ipm::quality`): the affine step (μ = 0)
    /// and the centring step (the difference to the step for μ = avg; the step is
    /// affine in μ) from the factorised KKT matrix, then σ by golden section. None when
    /// a solve fails.
    fn quality_function_oracle(&mut self, shared: &mut Shared, avg: f64) -> Option<f64> {
        if avg <= 0.0 || !self.solve_direction(shared, 0.0, false) {
            return None;
        }
        // The pairs with their affine step, then (after the solve for μ = avg) their
        // centring step, in the same order.
        let mut p = std::mem::take(self.mu_update.pairs_mut());
        p.clear();
        for j in 0..self.lay.nw {
            let dw = self.dir.dw[j];
            if self.lay.has_l[j] {
                p.push_affine(
                    self.it.w[j] - self.lay.wl[j],
                    self.it.zl[j],
                    dw,
                    self.dir.dzl[j],
                );
            }
            if self.lay.has_u[j] {
                p.push_affine(
                    self.lay.wu[j] - self.it.w[j],
                    self.it.zu[j],
                    -dw,
                    self.dir.dzu[j],
                );
            }
        }
        if self.solve_direction(shared, avg, false) {
            for j in 0..self.lay.nw {
                let dw = self.dir.dw[j];
                if self.lay.has_l[j] {
                    p.push_centring_from(dw, self.dir.dzl[j]);
                }
                if self.lay.has_u[j] {
                    p.push_centring_from(-dw, self.dir.dzu[j]);
                }
            }
        }
        let (dual, primal) = (
            self.grad_lag_norms(),
            quality::Norms::of(self.it.c.iter().copied()),
        );
        self.mu_update.quality_function_mu(p, dual, primal, avg)
    }
}
