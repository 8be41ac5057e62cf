//! The barrier parameter update: monotone (Fiacco–McCormick) and adaptive (free mode with
//! the LOQO or probing oracle).

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use super::*;
use crate::ipm::quality;

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
        let mut prods = Vec::new();
        for j in 0..self.lay.nw {
            if self.lay.has_l[j] {
                prods.push((self.it.w[j] - self.lay.wl[j]) * self.it.zl[j]);
            }
            if self.lay.has_u[j] {
                prods.push((self.lay.wu[j] - self.it.w[j]) * self.it.zu[j]);
            }
        }
        let n_comp = prods.len();
        let compl = quality::Norms::of(prods);
        quality::kkt_error(
            self.opts.quality_function_norm_type,
            [dual, primal, compl],
            [self.lay.nw, self.lay.m, n_comp],
        )
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
        let nw = self.lay.nw;
        let aff = (
            self.dir.dw.clone(),
            self.dir.dzl.clone(),
            self.dir.dzu.clone(),
        );
        if !self.solve_direction(shared, avg, false) {
            return None;
        }
        let mut p = Pairs::default();
        for j in 0..nw {
            let cen_w = self.dir.dw[j] - aff.0[j];
            if self.lay.has_l[j] {
                p.push(
                    self.it.w[j] - self.lay.wl[j],
                    self.it.zl[j],
                    aff.0[j],
                    aff.1[j],
                );
                p.push_cen(cen_w, self.dir.dzl[j] - aff.1[j]);
            }
            if self.lay.has_u[j] {
                p.push(
                    self.lay.wu[j] - self.it.w[j],
                    self.it.zu[j],
                    -aff.0[j],
                    aff.2[j],
                );
                p.push_cen(-cen_w, self.dir.dzu[j] - aff.2[j]);
            }
        }
        let dual = self.grad_lag_norms();
        let data = quality::QualityData {
            slack: &p.slack,
            z: &p.z,
            ds_aff: &p.ds_aff,
            dz_aff: &p.dz_aff,
            ds_cen: &p.ds_cen,
            dz_cen: &p.dz_cen,
            dual,
            primal: quality::Norms::of(self.it.c.iter().copied()),
            n_dual: nw,
            n_pri: self.lay.m,
            tau: self.tau,
        };
        let settings = quality::QualitySettings::from_options(&self.opts);
        let mu_min = mu_floor_adaptive(&self.opts, self.scaling.obj);
        let sigma = data.choose_sigma(avg, mu_min, self.opts.mu_max, &settings);
        let mu = sigma * avg;
        mu.is_finite().then_some(mu)
    }
}

/// The complementarity pairs of the quality-function oracle, flattened.
#[derive(Default)]
struct Pairs {
    slack: Vec<f64>,
    z: Vec<f64>,
    ds_aff: Vec<f64>,
    dz_aff: Vec<f64>,
    ds_cen: Vec<f64>,
    dz_cen: Vec<f64>,
}

impl Pairs {
    fn push(&mut self, slack: f64, z: f64, ds_aff: f64, dz_aff: f64) {
        self.slack.push(slack);
        self.z.push(z);
        self.ds_aff.push(ds_aff);
        self.dz_aff.push(dz_aff);
    }

    fn push_cen(&mut self, ds: f64, dz: f64) {
        self.ds_cen.push(ds);
        self.dz_cen.push(dz);
    }
}
