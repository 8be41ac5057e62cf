//! Error measures (IPOPT's scaled optimality error) and the barrier function on the
//! core's bounds.

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use super::vectors::inf_norm;
use super::Core;
use crate::ipm::barrier::Barrier;
use crate::ipm::termination::scaled_error;

impl Core<'_> {
    // ------------------------------------------------------------------ error measures

    /// (scaled dual infeasibility, primal infeasibility, complementarity at μ_t) with or
    /// without the κ_d damping term, max-norms. Also returns unscaled versions.
    pub(super) fn errors(&mut self, mu_t: f64, damping: bool) -> ([f64; 3], [f64; 3]) {
        let n = self.lay.n;
        let mut work = std::mem::take(&mut self.kw.work_nw);
        self.at_times(&self.it.jac, &self.it.y, &mut work);
        let kd = if damping {
            self.opts.kappa_d * mu_t
        } else {
            0.0
        };
        let mut dual: f64 = 0.0;
        let mut dual_u: f64 = 0.0;
        let mut compl: f64 = 0.0;
        for j in 0..self.lay.nw {
            let gj = if j < n { self.it.grad[j] } else { 0.0 };
            let mut r = gj + work[j] - self.it.zl[j] + self.it.zu[j];
            if self.lay.has_l[j] && !self.lay.has_u[j] {
                r += kd;
            } else if self.lay.has_u[j] && !self.lay.has_l[j] {
                r -= kd;
            }
            dual = dual.max(r.abs());
            // A slack's dual residual is in units of its row's multiplier.
            let r_user = if j < n {
                self.scaling.z_to_user(r.abs())
            } else {
                self.scaling
                    .lambda_to_user(self.lay.row_of_slack[j - n], r.abs())
            };
            dual_u = dual_u.max(r_user);
            if self.lay.has_l[j] {
                compl = compl.max(((self.it.w[j] - self.lay.wl[j]) * self.it.zl[j] - mu_t).abs());
            }
            if self.lay.has_u[j] {
                compl = compl.max(((self.lay.wu[j] - self.it.w[j]) * self.it.zu[j] - mu_t).abs());
            }
        }
        self.kw.work_nw = work;
        let primal = inf_norm(&self.it.c);
        let primal_u = self.scaling.max_row_to_user(&self.it.c);
        (
            [dual, primal, compl],
            [dual_u, primal_u, self.scaling.objective_to_user(compl)],
        )
    }

    /// IPOPT's scaled optimality error E_μ (`crate::ipm::termination::scaled_error`)
    /// and the unscaled parts.
    pub(super) fn nlp_error(&mut self, mu_t: f64, damping: bool) -> (f64, [f64; 3]) {
        let (e, eu) = self.errors(mu_t, damping);
        (self.scaled_error(e), eu)
    }

    /// IPOPT's scaled optimality error of the measures `e` of [`Core::errors`] at the
    /// current iterate.
    pub(super) fn scaled_error(&self, e: [f64; 3]) -> f64 {
        let it = &self.it;
        let lay = &self.lay;
        scaled_error(
            e,
            &it.y,
            (&it.zl, &lay.has_l),
            (&it.zu, &lay.has_u),
            self.opts.s_max,
        )
    }

    pub(super) fn avg_compl(&self, w: &[f64], zl: &[f64], zu: &[f64]) -> (f64, f64) {
        let mut sum = 0.0;
        let mut cnt = 0usize;
        let mut mn = f64::INFINITY;
        for j in 0..self.lay.nw {
            if self.lay.has_l[j] {
                let v = (w[j] - self.lay.wl[j]) * zl[j];
                sum += v;
                cnt += 1;
                mn = mn.min(v);
            }
            if self.lay.has_u[j] {
                let v = (self.lay.wu[j] - w[j]) * zu[j];
                sum += v;
                cnt += 1;
                mn = mn.min(v);
            }
        }
        if cnt == 0 {
            (0.0, 0.0)
        } else {
            (sum / cnt as f64, mn)
        }
    }

    // ------------------------------------------------------------------ barrier function

    /// The barrier function at barrier parameter `mu` on this problem's bounds.
    pub(super) fn barrier_at(&self, mu: f64) -> Barrier<'_> {
        Barrier {
            mu,
            kappa_d: self.opts.kappa_d,
            wl: &self.lay.wl,
            wu: &self.lay.wu,
            has_l: &self.lay.has_l,
            has_u: &self.lay.has_u,
        }
    }

    /// φ_μ at `(w, f)`.
    pub(super) fn barrier(&self, w: &[f64], f: f64, mu: f64) -> f64 {
        self.barrier_at(mu).value(w, f)
    }
}
