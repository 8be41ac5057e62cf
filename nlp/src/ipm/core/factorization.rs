//! Assembly and factorisation of the primal-dual system with inertia correction, its
//! static regularisation, and the least-squares multiplier estimate.

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use std::time::Instant;

use super::perturbation::Factored;
use super::vectors::inf_norm;
use super::Core;
use super::Shared;

/// How much `Core::solve_with_higher_quality` lowers the static regularisations.
const QUALITY_REG_SCALE: f64 = 1e-2;

/// How many times a solve may refactorise with lowered static regularisation after a
/// failed refinement: IPOPT's `IncreaseQuality` raises the pivot tolerance for good, and
/// from MUMPS' default 1e-6 (×√ per call, at most 0.1) it succeeds three times.
const QUALITY_RETRIES: usize = 3;

/// The retry is tried only once μ ≤ this. Near the solution refinement fails from the
/// ill-conditioning of Σ ~ 1/μ (catmix_colloc at μ = 2.5e-9: ratio 1.7e-10 → 1e-15 after
/// the retry); early failures mark a nearly rank-deficient Jacobian, where δ_c is the
/// better step (race_car_rk4_400 at μ = 2e-2: with the retry 196 iterations instead of
/// 61; measured in docs/solvers.md §6).
const QUALITY_MU_MAX: f64 = 1e-6;

/// Lower bound of the lowered equality-row regularisation, relative to `eq_reg` (see
/// `Core::step_eq_reg`).
const EQ_REG_FLOOR: f64 = 1e-9;

/// The static regularisation of the equality rows in the least-squares multiplier
/// system, 1e-2 × the step's: the Schur complement there is J Jᵀ, whose smallest
/// eigenvalue on a long chain is far below its diagonal (≈ (π/N)² × it), so a
/// regularisation relative to the diagonal perturbs the smooth part of y and can trip
/// the singularity test (y = 0). Measured: 1× fails the hanging chain with 50 000 links
/// (rows scaled up to gradient 0.8 by nlp_scaling_min_gradient; not solved in 40 s),
/// 1e-2× solves it in 8 iterations; 1e-6× (chosen before the row scaling, for the
/// unscaled 5000-link chain) changed hs027 from 54 to 77 iterations through round-off
/// alone (the path of hs027 is long and sensitive).
const LS_EQ_REG: f64 = 1e-2;

impl Core<'_> {
    // ------------------------------------------------------------------ linear algebra

    /// Whether a solve with residual ratio `res` gets `solve_with_higher_quality`: its
    /// refinement failed (ratio above `singular_ratio`) with δ_c = δ_w = 0, μ ≤
    /// `QUALITY_MU_MAX`, and fewer than `QUALITY_RETRIES` retries so far.
    pub(super) fn quality_retry_allowed(
        &self,
        res: &Result<f64, crate::kkt::KktError>,
        singular_ratio: f64,
    ) -> bool {
        self.pert.delta_c() == 0.0
            && self.pert.delta_w() == 0.0
            && self.mu_update.mu() <= QUALITY_MU_MAX
            && self.count.quality_retries < QUALITY_RETRIES
            && matches!(res, Ok(r) if *r > singular_ratio)
    }

    /// symnlp's counterpart of IPOPT's `IncreaseQuality` after a failed iterative
    /// refinement: faer's LDLᵀ has no pivot tolerance to raise, so the matrix is
    /// refactorised once with δ_w = `delta_w` and both static regularisations lowered
    /// by `QUALITY_REG_SCALE` (a factor closer to K, so refinement against K converges
    /// faster), and `rhs_copy` is solved again. Returns the new residual ratio if the
    /// factorisation has the inertia (n, m, 0); otherwise None, with the matrix left
    /// factorised with the lowered values (the caller must refactorise before using it).
    pub(super) fn solve_with_higher_quality(
        &mut self,
        shared: &mut Shared,
        delta_w: f64,
    ) -> Option<f64> {
        let (n, m) = (self.lay.n, self.lay.m);
        self.count.quality_retries += 1;
        self.kw.reg_scale = QUALITY_REG_SCALE;
        let fact = self.factor_kkt(shared, delta_w, self.pert.delta_c());
        self.kw.reg_scale = 1.0;
        if !matches!(fact, Ok(i) if i.positive == n && i.negative == m && i.zero == 0) {
            return None;
        }
        let t = Instant::now();
        self.kw.rhs.copy_from_slice(&self.kw.rhs_copy);
        let res = self.kw.solve_rhs();
        shared.stats.factor_seconds += t.elapsed().as_secs_f64();
        res.ok()
    }

    /// Static regularisation of the equality rows, relative to each row's scale:
    /// kkt_static_regularization · clamp(max_j J_ij², 1e-3, 1). An absolute 1e-8 would swamp
    /// the Schur complement J H⁻¹ Jᵀ of a Jacobian with small entries (hanging chain
    /// with 500 links: entries 0.008, smallest σ(J)² ≈ 2.5e-9), refinement could not
    /// remove it, and the step would be regularised for nothing. The floor 1e-3 was
    /// chosen by measurement on the chain (50 … 5000 links: 7, 8, 19 iterations; with no
    /// floor the 5000-link chain fails, an absolute 1e-8 fails at 500 links).
    pub(super) fn update_eq_reg(&mut self) {
        let reg = self.opts.kkt_static_regularization;
        let mut rmax = std::mem::take(&mut self.kw.eq_reg);
        rmax.fill(0.0);
        let jp = self.nlp.jac_g_sparsity();
        let ri = jp.row_idx();
        for (p, &v) in self.it.jac.iter().enumerate() {
            let r = &mut rmax[ri[p]];
            *r = r.max(v.abs());
        }
        for r in rmax.iter_mut() {
            *r = if *r > 0.0 && r.is_finite() {
                reg * (*r * *r).clamp(1e-3, 1.0)
            } else {
                reg
            };
        }
        self.kw.eq_reg = rmax;
    }

    /// The static regularisation of the equality rows for this factorisation. With
    /// δ_w = 0 it is `eq_reg` lowered, row by row, to kkt_static_regularization ×
    /// Σ_j J_ij² / |D_jj| where that is smaller (D the diagonal of W + Σ + the static
    /// Hessian regularisation, so the sum estimates the row's Schur complement
    /// J D⁻¹ Jᵀ), but not below 1e-3 × `eq_reg`. The hanging chain needs it: with 50 000
    /// links (rows scaled up to gradient 0.8) the Schur diagonal is ≈ 1e-4 against
    /// `eq_reg` = 6.4e-9, and its smooth modes are (π/N)² ≈ 4e-9 times smaller still,
    /// so refinement could not remove `eq_reg` and the solve did not converge (40 s);
    /// with the lowering it takes 8 iterations. The lower bound `EQ_REG_FLOOR` × `eq_reg`
    /// only keeps the pivot away from 0. The regularised matrix [[H, Jᵀ], [J, −R]] has
    /// IPOPT's inertia (n, m, 0) iff H + Jᵀ R⁻¹ J is positive definite, so an R larger
    /// than the squared small singular values of J hides negative curvature of the
    /// reduced Hessian (no δ_w where IPOPT takes one): with the former bound 1e-3 the
    /// rocket OCP (corpus `rocket_trap_*`) took Newton steps that ascend the barrier
    /// function at θ ≈ 1e-7 (∇φᵀd = +5e-3) and crawled for 150 iterations with α ≈ 1e-4;
    /// 183 / 96 / 166 iterations against IPOPT's 27 / 26 / 34. Bounds 1e-4, 1e-5, 1e-6,
    /// 1e-7, 1e-9 gave 53 / 82 / 72, 35 / 38 / 54, 34 / 46 / 53, 34 / 27 / 36 and
    /// 34 / 27 / 35; the other 39 OCP instances and the 73 HS problems are unchanged
    /// (docs/solvers.md §6). With δ_w > 0 (inertia correction) `eq_reg` is kept:
    /// lowering it there too took the 5000-link chain 14 iterations (IPOPT's count)
    /// instead of 11, and `kkt_static_regularization` = 1e-14 for every factorisation
    /// made glider_trap_100 fail after 701 iterations (556 with this rule).
    pub(super) fn step_eq_reg(&mut self, delta_w: f64) {
        let mut out = std::mem::take(&mut self.kw.eq_reg_step);
        if delta_w == 0.0 {
            let reg = self.opts.kkt_static_regularization;
            out.fill(0.0);
            let jp = self.nlp.jac_g_sparsity();
            let ri = jp.row_idx();
            for j in 0..self.lay.n {
                let hd = self.kw.hess_diag[j];
                let h = if hd == usize::MAX {
                    0.0
                } else {
                    self.it.hess[hd]
                };
                let d = (h + self.kw.kdx[j]).abs();
                if d > 0.0 {
                    for p in jp.col_range(j) {
                        out[ri[p]] += self.it.jac[p] * self.it.jac[p] / d;
                    }
                }
            }
            for (o, &e) in out.iter_mut().zip(&self.kw.eq_reg) {
                let r = reg * *o;
                *o = if r > 0.0 && r.is_finite() {
                    r.min(e).max(EQ_REG_FLOOR * e)
                } else {
                    e
                };
            }
        } else {
            out.copy_from_slice(&self.kw.eq_reg);
        }
        if self.kw.reg_scale != 1.0 {
            for o in out.iter_mut() {
                *o *= self.kw.reg_scale;
            }
        }
        self.kw.eq_reg_step = out;
    }

    /// Factorises the KKT matrix with IPOPT's inertia correction (the perturbation
    /// handler's Algorithm IC, `perturbation.rs`). Returns false if δ_w exceeded its
    /// maximum.
    pub(super) fn factorize_with_inertia_correction(&mut self, shared: &mut Shared) -> bool {
        let (n, m) = (self.lay.n, self.lay.m);
        self.update_eq_reg();
        let (mut pert, opts) = (std::mem::take(&mut self.pert), self.opts.clone());
        let ok = pert.correct_inertia(&opts, self.mu_update.mu(), m > 0, |delta_w, delta_c| {
            Factored::of(&self.factor_kkt(shared, delta_w, delta_c), n, m)
        });
        self.pert = pert;
        ok
    }

    /// Assembles the KKT matrix for the current iterate with Hessian perturbation
    /// `delta_w` and Jacobian perturbation `delta_c` (the static regularisation
    /// `kkt_static_regularization` on equality rows when δ_c = 0) and factorises it.
    pub(super) fn factor_kkt(
        &mut self,
        shared: &mut Shared,
        delta_w: f64,
        delta_c: f64,
    ) -> Result<crate::kkt::Inertia, crate::kkt::KktError> {
        let (n, m) = (self.lay.n, self.lay.m);
        // The static Hessian regularisation only keeps exact zero pivots away while
        // δ_w = 0; a real δ_w > 0 does that itself.
        let x_reg = if delta_w == 0.0 {
            self.opts.kkt_static_hessian_regularization * self.kw.reg_scale
        } else {
            0.0
        };
        for j in 0..n {
            let mut sig = 0.0;
            if self.lay.has_l[j] {
                sig += self.it.zl[j] / (self.it.w[j] - self.lay.wl[j]);
            }
            if self.lay.has_u[j] {
                sig += self.it.zu[j] / (self.lay.wu[j] - self.it.w[j]);
            }
            self.kw.kdx[j] = sig + delta_w + x_reg;
        }
        self.step_eq_reg(delta_w);
        self.kw.shift[..n].fill(-x_reg);
        for i in 0..m {
            self.kw.shift[n + i] = if self.lay.slack_of_row[i] == usize::MAX && delta_c == 0.0 {
                self.kw.eq_reg_step[i]
            } else {
                0.0
            };
        }
        for k in 0..self.lay.ni {
            let j = n + k;
            let mut sig = 0.0;
            if self.lay.has_l[j] {
                sig += self.it.zl[j] / (self.it.w[j] - self.lay.wl[j]);
            }
            if self.lay.has_u[j] {
                sig += self.it.zu[j] / (self.lay.wu[j] - self.it.w[j]);
            }
            self.kw.ds[k] = (sig + delta_w).max(1e-300);
        }
        for i in 0..m {
            let k = self.lay.slack_of_row[i];
            // Equality rows carry δ_c, or the static regularisation that faer's
            // unpivoted LDLᵀ needs (removed again by iterative refinement); inequality
            // rows already carry 1/(Σ_s + δ_w) > 0 from the eliminated slack, plus δ_c.
            self.kw.kdc[i] = if k == usize::MAX {
                if delta_c > 0.0 {
                    delta_c
                } else {
                    self.kw.eq_reg_step[i]
                }
            } else {
                delta_c + 1.0 / self.kw.ds[k]
            };
        }
        let t = Instant::now();
        let (h, dx, j, dc) = (&self.it.hess, &self.kw.kdx, &self.it.jac, &self.kw.kdc);
        let res = match self.kw.lm.as_mut() {
            Some(lm) => lm.factorize(&mut self.kw.kkt, h, dx, j, dc),
            None => self.kw.kkt.factorize(h, dx, j, dc),
        };
        shared.stats.factor_seconds += t.elapsed().as_secs_f64();
        shared.stats.n_factorizations += 1;
        res
    }

    /// IPOPT's `recalc_y`: y ← the least-squares estimate at the current point, kept
    /// unchanged when the estimate cannot be computed (IPOPT skips the update when its
    /// calculator fails; there is no size limit).
    pub(super) fn recalc_multipliers(&mut self) {
        self.y_saved.copy_from_slice(&self.it.y);
        if !self.least_squares_multipliers(f64::INFINITY) {
            self.it.y.copy_from_slice(&self.y_saved);
        }
    }

    /// y = argmin ‖∇f + Aᵀy − z_L + z_U‖₂ (IPOPT's least-squares estimate), set to 0 if
    /// larger than `max_norm` (max-norm) or not computable. True when the estimate was
    /// taken.
    pub(crate) fn least_squares_multipliers(&mut self, max_norm: f64) -> bool {
        let (n, m) = (self.lay.n, self.lay.m);
        if m == 0 {
            return false;
        }
        let xreg = self.opts.kkt_static_hessian_regularization;
        self.kw.kdx.iter_mut().for_each(|v| *v = 1.0 + xreg);
        self.update_eq_reg();
        for i in 0..m {
            self.kw.kdc[i] = if self.lay.slack_of_row[i] == usize::MAX {
                LS_EQ_REG * self.kw.eq_reg[i]
            } else {
                1.0
            };
        }
        self.least_squares_rhs();
        let singular = self.equality_rows_singular();
        for j in 0..n {
            self.kw.shift[j] = -xreg;
        }
        for i in 0..m {
            self.kw.shift[n + i] = if self.lay.slack_of_row[i] == usize::MAX {
                LS_EQ_REG * self.kw.eq_reg[i]
            } else {
                0.0
            };
        }
        let ok = !singular
            && self.factorize_least_squares()
            && self
                .kw
                .kkt
                .solve_shifted(&mut self.kw.rhs, Some(&self.kw.shift))
                .is_ok();
        if ok {
            let ymax = inf_norm(&self.kw.rhs[n..]);
            if ymax <= max_norm && ymax.is_finite() {
                self.it.y.copy_from_slice(&self.kw.rhs[n..]);
                return true;
            }
        }
        self.it.y.iter_mut().for_each(|v| *v = 0.0);
        false
    }

    /// The least-squares system's right-hand side (W = I, Σ_s = 1):
    /// `[−(∇f − z_L + z_U)_x ; z_L − z_U of the row's slack, or 0]`.
    fn least_squares_rhs(&mut self) {
        let (n, m) = (self.lay.n, self.lay.m);
        for j in 0..n {
            self.kw.rhs[j] = -(self.it.grad[j] - self.it.zl[j] + self.it.zu[j]);
        }
        for i in 0..m {
            let k = self.lay.slack_of_row[i];
            self.kw.rhs[n + i] = if k == usize::MAX {
                0.0
            } else {
                // s-row: ds − y_i = r_s := z_L − z_U; row i: J dx − ds = 0
                // ⇒ J dx − y_i = r_s.
                self.it.zl[n + k] - self.it.zu[n + k]
            };
        }
    }

    /// Whether the equality rows' Jacobian is (numerically) rank-deficient. IPOPT
    /// computes the least-squares multipliers with an unregularised factorisation and
    /// sets them to zero when the linear solver reports the system singular. The static
    /// regularisation δ_s hides that singularity from faer, so detect it from the
    /// determinant instead: det K(δ) = det(−δI − J Jᵀ) on the equality rows, and
    /// multiplying δ by 10 multiplies |det K| by about 10 per (numerically) zero
    /// singular value of J. Leaves `kdc` as it found it.
    fn equality_rows_singular(&mut self) -> bool {
        let n_eq = self
            .lay
            .slack_of_row
            .iter()
            .filter(|&&k| k == usize::MAX)
            .count();
        if n_eq == 0 || !(self.opts.kkt_static_regularization > 0.0) {
            return false;
        }
        let mut singular = false;
        self.set_equality_kdc(10.0 * LS_EQ_REG);
        if self.factorize_least_squares() {
            let ld10 = self.kw.kkt.log_abs_det();
            self.set_equality_kdc(LS_EQ_REG);
            if self.factorize_least_squares() {
                singular = (ld10 - self.kw.kkt.log_abs_det()) / std::f64::consts::LN_10 > 0.5;
            }
        }
        self.set_equality_kdc(LS_EQ_REG);
        singular
    }

    /// `kdc = scale · eq_reg` on the equality rows.
    fn set_equality_kdc(&mut self, scale: f64) {
        for i in 0..self.lay.m {
            if self.lay.slack_of_row[i] == usize::MAX {
                self.kw.kdc[i] = scale * self.kw.eq_reg[i];
            }
        }
    }

    /// Factorises the least-squares system `[I J'; J −kdc]` (with `kdx` on the
    /// diagonal); true on success.
    fn factorize_least_squares(&mut self) -> bool {
        self.kw
            .kkt
            .factorize(&self.kw.hzero, &self.kw.kdx, &self.it.jac, &self.kw.kdc)
            .is_ok()
    }
}
