//! The barrier parameter update: monotone (Fiacco–McCormick) and adaptive (free mode with
//! the LOQO or probing oracle).

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use super::Core;
use super::Shared;
use crate::ipm::barrier::loqo_mu;
use crate::ipm::barrier::monotone_next;
use crate::ipm::barrier::mu_floor;
use crate::ipm::barrier::mu_floor_adaptive;
use crate::ipm::barrier::probing_mu;
use crate::ipm::barrier::tau;
use crate::ipm::quality;
use crate::options::MuOracle;

impl Core<'_> {
    // ------------------------------------------------------------------ barrier update

    pub(super) fn update_mu_monotone(&mut self, force: bool) {
        let floor = mu_floor(&self.opts, self.scaling.obj);
        let mut first = true;
        loop {
            if self.mu <= floor {
                return;
            }
            let (e_mu, _) = self.nlp_error(self.mu, true);
            if !(force && first) && e_mu > self.opts.barrier_tol_factor * self.mu {
                return;
            }
            first = false;
            self.mu = monotone_next(self.mu, &self.opts, self.scaling.obj);
            self.tau = tau(self.mu, &self.opts);
            self.filter.reset();
            if !self.opts.mu_allow_fast_monotone_decrease {
                return;
            }
        }
    }

    /// Adaptive μ (called after the KKT matrix is factorised).
    pub(super) fn update_mu_adaptive(&mut self, shared: &mut Shared, e0: f64) {
        // IPOPT's kkt-error globalisation (AdaptiveMuUpdate::CheckSufficientProgress):
        // progress is sufficient while fewer than `adaptive_mu_kkterror_red_iters`
        // reference values exist, else when the primal-dual error is below
        // `adaptive_mu_kkterror_red_fact` times one of them.
        let red = self.opts.adaptive_mu_kkterror_red_fact;
        let max_refs = self.opts.adaptive_mu_kkterror_red_iters;
        let err = self.pd_system_error();
        let sufficient =
            self.kkt_refs.len() < max_refs || self.kkt_refs.iter().any(|&r| err <= red * r);
        if self.free_mode && !sufficient {
            // Switch to the monotone (fixed) mode.
            self.free_mode = false;
            let (avg, _) = self.avg_compl(&self.it.w, &self.it.zl, &self.it.zu);
            self.mu = (self.opts.adaptive_mu_monotone_init_factor * avg)
                .clamp(mu_floor(&self.opts, self.scaling.obj), self.opts.mu_max);
            self.tau = tau(self.mu, &self.opts);
            self.filter.reset();
            return;
        }
        if !self.free_mode && !sufficient {
            self.update_mu_monotone(false);
            return;
        }
        // Stay in (or return to) free mode; remember this point's error.
        self.free_mode = true;
        if self.kkt_refs.len() >= max_refs {
            self.kkt_refs.remove(0);
        }
        self.kkt_refs.push(err);
        // Free mode: τ = max(τ_min, 1 − E₀) (IPOPT's AdaptiveMuUpdate), then the oracle.
        self.tau = self.opts.tau_min.max(1.0 - e0);
        let (avg, mn) = self.avg_compl(&self.it.w, &self.it.zl, &self.it.zu);
        let mut mu = match self.opts.mu_oracle {
            MuOracle::Loqo => loqo_mu(avg, mn),
            MuOracle::Probing => self.probing_oracle(shared, avg).unwrap_or(loqo_mu(avg, mn)),
            MuOracle::QualityFunction => self
                .quality_function_oracle(shared, avg)
                .unwrap_or(loqo_mu(avg, mn)),
        };
        mu = mu.clamp(
            mu_floor_adaptive(&self.opts, self.scaling.obj),
            self.opts.mu_max,
        );
        if mu != self.mu {
            self.mu = mu;
            self.filter.reset();
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
        let mut p = std::mem::take(&mut self.quality_pairs);
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
        let complete = p.ds_cen.len() == p.ds_aff.len();
        let data = quality::QualityData {
            pairs: &p,
            dual: self.grad_lag_norms(),
            primal: quality::Norms::of(self.it.c.iter().copied()),
            tau: self.tau,
        };
        let settings = quality::QualitySettings::from_options(&self.opts);
        let mu_min = mu_floor_adaptive(&self.opts, self.scaling.obj);
        let sigma = complete.then(|| data.choose_sigma(avg, mu_min, self.opts.mu_max, &settings));
        self.quality_pairs = p;
        let mu = sigma? * avg;
        mu.is_finite().then_some(mu)
    }
}
