//! The Newton step: solving the factorised KKT system for the search direction, and the
//! fraction-to-the-boundary step sizes.

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use std::time::Instant;

use super::vectors::all_finite;
use super::Core;
use super::Shared;
use crate::kkt::KktError;

impl Core<'_> {
    /// Solves for the direction with complementarity target `mu_t`; `soc` replaces the
    /// primal residual c by the given vector. Writes into (dw, dy, dzl, dzu) or the SOC
    /// buffers.
    pub(super) fn solve_direction(&mut self, shared: &mut Shared, mu_t: f64, soc: bool) -> bool {
        self.assemble_direction_rhs(mu_t, soc);
        if !self.solve_kkt_rhs(shared, soc) {
            return false;
        }
        self.recover_direction(mu_t, soc)
    }

    /// The reduced KKT right-hand side for complementarity target `mu_t` (slack rows
    /// condensed into the constraint rows), with `c_soc` for `c` if `soc`.
    fn assemble_direction_rhs(&mut self, mu_t: f64, soc: bool) {
        let (n, m) = (self.lay.n, self.lay.m);
        let mut work = std::mem::take(&mut self.kw.work_nw);
        self.at_times(&self.it.jac, &self.it.y, &mut work);
        let kd = self.opts.kappa_d * mu_t;
        // rhs_w = −(∇f + Aᵀy) + μ/(w−wl) − μ/(wu−w) ∓ κ_d μ
        for j in 0..self.lay.nw {
            let gj = if j < n { self.it.grad[j] } else { 0.0 };
            let mut r = -(gj + work[j]);
            if self.lay.has_l[j] {
                r += mu_t / (self.it.w[j] - self.lay.wl[j]);
                if !self.lay.has_u[j] {
                    r -= kd;
                }
            }
            if self.lay.has_u[j] {
                r -= mu_t / (self.lay.wu[j] - self.it.w[j]);
                if !self.lay.has_l[j] {
                    r += kd;
                }
            }
            if j < n {
                self.kw.rhs[j] = r;
            } else {
                self.kw.rhs_s[j - n] = r;
            }
        }
        self.kw.work_nw = work;
        for i in 0..m {
            let ci = if soc { self.c_soc[i] } else { self.it.c[i] };
            let k = self.lay.slack_of_row[i];
            self.kw.rhs[n + i] = if k == usize::MAX {
                -ci
            } else {
                -ci + self.kw.rhs_s[k] / self.kw.ds[k]
            };
        }
    }

    /// Solves the assembled system in place, refined against the system without the
    /// static regularisation; a (numerically) singular system is retried with a better
    /// factor, then regularised. False when no usable solution was found.
    fn solve_kkt_rhs(&mut self, shared: &mut Shared, soc: bool) -> bool {
        // Refine against the system without the static regularisation.
        let mut t = Instant::now();
        self.kw.rhs_copy.copy_from_slice(&self.kw.rhs);
        let mut res = self.kw.solve_rhs();
        let singular_ratio = self.opts.singular_residual_ratio();
        if self.quality_retry_allowed(&res, singular_ratio) {
            // Refinement failed near the solution: first try a more accurate factor
            // (IPOPT's IncreaseQuality); if that fails too, the singular-matrix
            // treatment below refactorises.
            shared.stats.factor_seconds += t.elapsed().as_secs_f64();
            if let Some(r) = self.solve_with_higher_quality(shared, self.pert.delta_w()) {
                res = if r <= singular_ratio { Ok(r) } else { res };
            }
            t = Instant::now();
        }
        if self.pert.delta_c() == 0.0 && !matches!(res, Ok(r) if r <= singular_ratio) {
            // The system without the static regularisation is (numerically) singular:
            // a rank-deficient Jacobian of the equality rows with inconsistent
            // linearised constraints. Take IPOPT's regularised step: refactorise with
            // δ_c = 1e-8·μ^¼ and solve that system (IPOPT's "L"). When the first three
            // iterations are all singular, before any step was solved without δ_c, δ_c
            // is applied from the start in every later iteration (IPOPT's "Jacobian
            // degenerate", decided once as IPOPT does: counting any three singular
            // iterations in a row, at any point of the solve, put catenary_999's δ_c on
            // in 1281 of 1307 iterations, IPOPT's in none of 70).
            shared.stats.factor_seconds += t.elapsed().as_secs_f64();
            match self.solve_regularised(shared) {
                Some(r) => res = r,
                None => return false,
            }
        } else {
            shared.stats.factor_seconds += t.elapsed().as_secs_f64();
            if self.pert.delta_c() == 0.0 && !soc {
                self.pert.solved_without_delta_c();
            }
        }
        res.is_ok()
    }

    /// IPOPT's regularised step for a singular system: refactorises with `δ_c`, then
    /// raises `δ_w` while the solve stays singular. `None` when no factor is usable.
    fn solve_regularised(&mut self, shared: &mut Shared) -> Option<Result<f64, KktError>> {
        let (n, m) = (self.lay.n, self.lay.m);
        let singular_ratio = self.opts.singular_residual_ratio();
        let delta_c = self.pert.singular_system(&self.opts, self.mu_update.mu());
        let dw = self.pert.delta_w();
        let ok = matches!(self.factor_kkt(shared, dw, delta_c),
                Ok(i) if i.positive == n && i.negative == m && i.zero == 0);
        if !ok {
            // Should not happen (δ_c does not change the inertia); fall back to
            // the statically regularised system as it is.
            self.pert.drop_delta_c();
            if self.factor_kkt(shared, dw, self.pert.delta_c()).is_err() {
                return None;
            }
        }
        let t = Instant::now();
        self.kw.rhs.copy_from_slice(&self.kw.rhs_copy);
        let mut res = self.kw.solve_rhs();
        shared.stats.factor_seconds += t.elapsed().as_secs_f64();
        let mut dw = self.pert.delta_w();
        while ok && !matches!(res, Ok(r) if r <= singular_ratio) {
            // Still singular (singular reduced Hessian): IPOPT increases δ_w.
            dw = self.pert.next_delta_w(&self.opts, dw);
            if dw > self.opts.max_hessian_perturbation {
                return None;
            }
            match self.factor_kkt(shared, dw, self.pert.delta_c()) {
                Ok(i) if i.positive == n && i.negative == m && i.zero == 0 => {}
                Ok(_) => continue,
                Err(_) => continue,
            }
            self.pert.raise_delta_w(dw);
            let t = Instant::now();
            self.kw.rhs.copy_from_slice(&self.kw.rhs_copy);
            res = self.kw.solve_rhs();
            shared.stats.factor_seconds += t.elapsed().as_secs_f64();
        }
        Some(res)
    }

    /// The full direction from the solved reduced system: slack steps, then the bound
    /// multipliers' steps. False when it is not finite.
    fn recover_direction(&mut self, mu_t: f64, soc: bool) -> bool {
        let n = self.lay.n;
        let (dw, dy, dzl, dzu) = if soc {
            (
                &mut self.dir_soc.dw,
                &mut self.dir_soc.dy,
                &mut self.dir_soc.dzl,
                &mut self.dir_soc.dzu,
            )
        } else {
            (
                &mut self.dir.dw,
                &mut self.dir.dy,
                &mut self.dir.dzl,
                &mut self.dir.dzu,
            )
        };
        dw[..n].copy_from_slice(&self.kw.rhs[..n]);
        dy.copy_from_slice(&self.kw.rhs[n..]);
        for k in 0..self.lay.ni {
            let i = self.lay.row_of_slack[k];
            dw[n + k] = (self.kw.rhs_s[k] + dy[i]) / self.kw.ds[k];
        }
        for j in 0..self.lay.nw {
            if self.lay.has_l[j] {
                let s = self.it.w[j] - self.lay.wl[j];
                dzl[j] = mu_t / s - self.it.zl[j] - self.it.zl[j] / s * dw[j];
            } else {
                dzl[j] = 0.0;
            }
            if self.lay.has_u[j] {
                let s = self.lay.wu[j] - self.it.w[j];
                dzu[j] = mu_t / s - self.it.zu[j] + self.it.zu[j] / s * dw[j];
            } else {
                dzu[j] = 0.0;
            }
        }
        all_finite(dw) && all_finite(dy)
    }

    pub(super) fn max_step_primal(&self, dw: &[f64], tau: f64) -> f64 {
        let mut a: f64 = 1.0;
        for j in 0..self.lay.nw {
            if dw[j] < 0.0 && self.lay.has_l[j] {
                a = a.min(tau * (self.it.w[j] - self.lay.wl[j]) / -dw[j]);
            }
            if dw[j] > 0.0 && self.lay.has_u[j] {
                a = a.min(tau * (self.lay.wu[j] - self.it.w[j]) / dw[j]);
            }
        }
        a
    }

    pub(super) fn max_step_dual(&self, dzl: &[f64], dzu: &[f64], tau: f64) -> f64 {
        let mut a: f64 = 1.0;
        for j in 0..self.lay.nw {
            if self.lay.has_l[j] && dzl[j] < 0.0 {
                a = a.min(tau * self.it.zl[j] / -dzl[j]);
            }
            if self.lay.has_u[j] && dzu[j] < 0.0 {
                a = a.min(tau * self.it.zu[j] / -dzu[j]);
            }
        }
        a
    }
}
