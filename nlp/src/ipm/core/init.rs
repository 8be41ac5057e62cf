//! Starting points: the cold, warm and exact starts, and the restart after a restoration
//! phase.

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use super::vectors::first_non_finite;
use super::vectors::one_norm;
use super::Core;
use super::Start;
use crate::ipm::error::At;
use crate::ipm::error::CoreError;
use crate::ipm::filter::Acceptance;
use crate::ipm::mu_update::tau;

impl Core<'_> {
    // ------------------------------------------------------------------ initialisation

    pub(super) fn push_into_bounds(&self, j: usize, v: f64, push: f64, frac: f64) -> f64 {
        let (l, u) = (self.lay.wl[j], self.lay.wu[j]);
        let mut v = v;
        if self.lay.has_l[j] && self.lay.has_u[j] {
            let pl = (push * l.abs().max(1.0)).min(frac * (u - l));
            let pu = (push * u.abs().max(1.0)).min(frac * (u - l));
            if l + pl > u - pu {
                v = 0.5 * (l + u);
            } else {
                v = v.clamp(l + pl, u - pu);
            }
        } else if self.lay.has_l[j] {
            v = v.max(l + push * l.abs().max(1.0));
        } else if self.lay.has_u[j] {
            v = v.min(u - push * u.abs().max(1.0));
        }
        v
    }

    /// Err names the first non-finite entry of g.
    pub(super) fn check_g(&self, at: At) -> Result<(), CoreError> {
        match first_non_finite(&self.it.g) {
            Some(i) => Err(CoreError::Constraint {
                value: self.it.g[i],
                index: i,
                name: self.nlp.constraint_name(i),
                at,
            }),
            None => Ok(()),
        }
    }

    pub(super) fn initialize(&mut self, start: Start<'_>) -> Result<(), CoreError> {
        let mut x0 = std::mem::take(&mut self.x_start);
        self.nlp.initial_point(&mut x0);
        let res = self.initialize_from(start, &x0);
        self.x_start = x0;
        res
    }

    fn initialize_from(&mut self, start: Start<'_>, x0: &[f64]) -> Result<(), CoreError> {
        let n = self.lay.n;
        match start {
            Start::Exact { w, y, zl, zu } => {
                self.it.w.copy_from_slice(w);
                self.it.y.copy_from_slice(y);
                self.it.zl.copy_from_slice(zl);
                self.it.zu.copy_from_slice(zu);
                self.eval_current()?;
            }
            Start::Cold | Start::Warm { .. } => {
                let warm = matches!(start, Start::Warm { .. });
                let (bp, bf, sp, sf) = if warm {
                    (
                        self.opts.warm_start_bound_push,
                        self.opts.warm_start_bound_frac,
                        self.opts.warm_start_slack_bound_push,
                        self.opts.warm_start_slack_bound_frac,
                    )
                } else {
                    (
                        self.opts.bound_push,
                        self.opts.bound_frac,
                        self.opts.slack_bound_push,
                        self.opts.slack_bound_frac,
                    )
                };
                for j in 0..n {
                    self.it.w[j] = self.push_into_bounds(j, x0[j], bp, bf);
                }
                // Slacks from g(x0).
                self.nlp.eval_g(&self.it.w[..n], &mut self.it.g);
                self.check_g(At::Start)?;
                for k in 0..self.lay.ni {
                    let gi = self.it.g[self.lay.row_of_slack[k]];
                    self.it.w[n + k] = self.push_into_bounds(n + k, gi, sp, sf);
                }
                match start {
                    Start::Warm { y, zl, zu } => {
                        let zmin = self.opts.warm_start_mult_bound_push;
                        self.it.y.copy_from_slice(y);
                        for j in 0..self.lay.nw {
                            let (a, b) = if j < n {
                                (zl[j], zu[j])
                            } else {
                                // slack multipliers from y: ∇_s L = −y − v_L + v_U = 0
                                let yi = y[self.lay.row_of_slack[j - n]];
                                ((-yi).max(0.0), yi.max(0.0))
                            };
                            self.it.zl[j] = if self.lay.has_l[j] { a.max(zmin) } else { 0.0 };
                            self.it.zu[j] = if self.lay.has_u[j] { b.max(zmin) } else { 0.0 };
                        }
                        self.eval_current()?;
                    }
                    _ => {
                        let v = self.opts.bound_mult_init_val;
                        for j in 0..self.lay.nw {
                            self.it.zl[j] = if self.lay.has_l[j] { v } else { 0.0 };
                            self.it.zu[j] = if self.lay.has_u[j] { v } else { 0.0 };
                        }
                        self.it.y.iter_mut().for_each(|v| *v = 0.0);
                        self.eval_current()?;
                        if self.lay.m > 0 {
                            self.least_squares_multipliers(self.opts.constr_mult_init_max);
                            // Hessian at the new multipliers.
                            self.eval_hessian(At::Start)?;
                        }
                    }
                }
            }
        }
        let theta0 = one_norm(&self.it.c);
        self.accept = Acceptance::new(&self.opts, theta0);
        Ok(())
    }

    // ------------------------------------------------------------------ for restoration

    /// Replaces the iterate by a restoration result `w` and re-evaluates everything.
    ///
    /// Multipliers as IPOPT sets them after a successful restoration
    /// (`MinC_1NrmRestorationPhase`): the bound multipliers take one primal-dual Newton
    /// step for complementarity, the whole move of the restoration phase counting as the
    /// primal step (Δz = (μ − z·Δs)/s − z, cut by the fraction to the boundary), and are
    /// all reset to 1 if one exceeds `bound_mult_reset_threshold`; the constraint
    /// multipliers are the least-squares estimate if `constr_mult_reset_threshold` > 0 and
    /// it is no larger than that, else 0.
    pub(crate) fn restart_from(&mut self, w: &[f64]) -> Result<(), CoreError> {
        let (mu, nw) = (self.mu_update.mu(), self.lay.nw);
        let mut dzl = vec![0.0; nw];
        let mut dzu = vec![0.0; nw];
        for j in 0..nw {
            if self.lay.has_l[j] {
                let (s, s_new) = (self.it.w[j] - self.lay.wl[j], w[j] - self.lay.wl[j]);
                dzl[j] = (mu + self.it.zl[j] * (s - s_new)) / s - self.it.zl[j];
            }
            if self.lay.has_u[j] {
                let (s, s_new) = (self.lay.wu[j] - self.it.w[j], self.lay.wu[j] - w[j]);
                dzu[j] = (mu + self.it.zu[j] * (s - s_new)) / s - self.it.zu[j];
            }
        }
        let alpha = self.max_step_dual(&dzl, &dzu, tau(mu, &self.opts));
        let mut z_max: f64 = 0.0;
        for j in 0..nw {
            self.it.zl[j] += alpha * dzl[j];
            self.it.zu[j] += alpha * dzu[j];
            z_max = z_max.max(self.it.zl[j]).max(self.it.zu[j]);
        }
        if z_max > self.opts.bound_mult_reset_threshold {
            for j in 0..nw {
                self.it.zl[j] = if self.lay.has_l[j] { 1.0 } else { 0.0 };
                self.it.zu[j] = if self.lay.has_u[j] { 1.0 } else { 0.0 };
            }
        }
        self.it.w.copy_from_slice(w);
        self.it.y.iter_mut().for_each(|v| *v = 0.0);
        self.eval_first_order(At::RestorationResult)?;
        let mut c = std::mem::take(&mut self.it.c);
        self.constraint_residual(&self.it.w, &self.it.g, &mut c);
        self.it.c = c;
        if self.opts.constr_mult_reset_threshold > 0.0 {
            self.least_squares_multipliers(self.opts.constr_mult_reset_threshold);
        }
        self.eval_hessian(At::RestorationResult)
    }
}
