//! The barrier parameter update: monotone (Fiacco–McCormick) and adaptive (free mode with
//! the LOQO or probing oracle).

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use super::*;

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
        let red = self.opts.adaptive_mu_kkterror_red_fact;
        if self.free_mode {
            let ok = self.kkt_refs.is_empty() || self.kkt_refs.iter().any(|&r| e0 <= red * r);
            if !ok {
                // Switch to the monotone (fixed) mode.
                self.free_mode = false;
                let (avg, _) = self.avg_compl(&self.it.w, &self.it.zl, &self.it.zu);
                self.mu = (self.opts.adaptive_mu_monotone_init_factor * avg)
                    .clamp(mu_floor(&self.opts, self.scaling.obj), self.opts.mu_max);
                self.tau = tau(self.mu, &self.opts);
                self.filter.reset();
                return;
            }
            self.kkt_refs.push(e0);
            if self.kkt_refs.len() > self.opts.adaptive_mu_kkterror_red_iters {
                self.kkt_refs.remove(0);
            }
        } else {
            if !self.kkt_refs.is_empty() && self.kkt_refs.iter().all(|&r| e0 <= red * r) {
                self.free_mode = true;
                self.kkt_refs.clear();
                self.kkt_refs.push(e0);
            } else {
                self.update_mu_monotone(false);
                return;
            }
        }
        // Free mode: oracle.
        let (avg, mn) = self.avg_compl(&self.it.w, &self.it.zl, &self.it.zu);
        let mut mu = match self.opts.mu_oracle {
            MuOracle::Loqo => loqo_mu(avg, mn),
            MuOracle::Probing => {
                if self.solve_direction(shared, 0.0, false) {
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
                    probing_mu(avg, aff.max(0.0))
                } else {
                    loqo_mu(avg, mn)
                }
            }
        };
        mu = mu.clamp(
            mu_floor_adaptive(&self.opts, self.scaling.obj),
            self.opts.mu_max,
        );
        if mu != self.mu {
            self.mu = mu;
            self.tau = tau(mu, &self.opts);
            self.filter.reset();
        }
    }
}
