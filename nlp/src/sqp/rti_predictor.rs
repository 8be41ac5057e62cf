//! The real-time iteration's predictor-corrector: the QP step for the initial state the
//! plan predicts, solved in the preparation, and its correction for the measured one in
//! the feedback (acados' split: everything that does not depend on the measurement is
//! done before it).
//!
//! For a fixed working set W the equality QP's solution is affine in x0 (x0 enters only
//! the constants of the rows `X₀ − x0 = 0`), so the step for the measured x0 is the
//! prepared step plus K⁻¹δ, where δ is non-zero on the x0 rows of W only. The preparation
//! moves the linearisation's x0 to the plan's own initial state (each entry of x0 with one
//! equality row: the value that row holds at the plan), so that with a plan that predicts
//! the plant well δ is small, and solves W's equality QP there with the refined solve.
//! The feedback solves for the correction with the regularised factor alone (one refined
//! solve of K + diag(ε) on W's rows, which converges in one refinement step where the
//! exact K needs three or four), and accepts it only when the error this leaves in W's
//! rows, ε·|δλ_i|, is within the residual ratio the refined solve targets (1e-12,
//! `Kkt::residual_ratio_max`'s default), first after one back-substitution, then (a
//! measured state off the prediction) after one refinement sweep; the active-set method
//! then checks the step like any of its own (`active_set::accept_step_in`), and otherwise
//! runs from W as before.

use super::polish::{solve_working_set_into, EqScratch, Side, WorkingSet, ZERO_BLOCK_REG};
use super::qp::QpData;
use crate::frontend::scaled::refill;
use crate::kkt::Kkt;

/// The residual ratio a corrected step must meet in W's rows, relative to the step's
/// size: the target of the KKT's refined solves (`Kkt::residual_ratio_max`).
const CORRECTION_RATIO: f64 = 1e-12;

/// The prepared step and the correction's vectors, kept between steps (no allocation
/// once grown).
#[derive(Default)]
pub(super) struct Predictor {
    /// The initial state the prepared constraint values g correspond to.
    pub x0_lin: Vec<f64>,
    /// W's equality-QP step and total row multipliers at `x0_lin`, when `ready`.
    d: Vec<f64>,
    lambda: Vec<f64>,
    ready: bool,
    /// The correction's right-hand side and solution (n + m), then the corrected step.
    rhs: Vec<f64>,
}

impl Predictor {
    /// Starts a preparation: `x0_lin` ← the parameter's values `x0`, no prepared step.
    pub fn reset(&mut self, x0: &[f64]) {
        self.x0_lin.clear();
        self.x0_lin.extend_from_slice(x0);
        self.ready = false;
    }

    /// Moves the linearisation's x0 to the plan's initial state: for each entry k of x0
    /// with exactly one row among `terms` (`(row, k, coefficient)`), an equality, `g` of
    /// that row is set to its bound and `x0_lin[k]` moved accordingly; other entries keep
    /// the parameter's value.
    pub fn move_to_plan(
        &mut self,
        terms: &[(usize, usize, f64)],
        g: &mut [f64],
        (g_l, g_u): (&[f64], &[f64]),
    ) {
        for (k, x0_k) in self.x0_lin.iter_mut().enumerate() {
            let mut rows = terms.iter().filter(|t| t.1 == k);
            let (Some(&(row, _, c)), None) = (rows.next(), rows.next()) else {
                continue;
            };
            let b = g_u[row];
            if g_l[row] == b && b.is_finite() && c != 0.0 {
                let dx0 = (b - g[row]) / c;
                g[row] += c * dx0;
                *x0_k += dx0;
            }
        }
    }

    /// Solves W's equality QP of `p` (at `x0_lin`) with the factorisation in `kkt`.
    pub fn solve(&mut self, kkt: &mut Kkt, p: &QpData, w: &WorkingSet, eq: &mut EqScratch) {
        self.ready = solve_working_set_into(kkt, p, w, eq, (&mut self.d, &mut self.lambda));
    }

    /// The step (d, rows' total multipliers) of W's equality QP for the initial state
    /// `x0`: the prepared one plus the correction for `x0 − x0_lin` (see the module
    /// documentation). `None` when nothing was prepared, the solve fails or the
    /// correction is not accurate enough (the caller solves the QP from W instead).
    /// The correction is first one back-substitution; when that misses the accuracy (a
    /// measured state off the prediction by more than ≈ 1e-6, as any plant that is not
    /// the model gives), it is solved again with one refinement sweep.
    pub fn correct(
        &mut self,
        kkt: &mut Kkt,
        p: &QpData,
        w: &WorkingSet,
        terms: &[(usize, usize, f64)],
        x0: &[f64],
    ) -> Option<(&[f64], &[f64])> {
        if !self.ready {
            return None;
        }
        let accurate = self.try_correction(kkt, p, w, terms, x0, 0)?
            || self.try_correction(kkt, p, w, terms, x0, 1)?;
        accurate.then(|| self.rhs.split_at(p.x.len()))
    }

    /// The corrected step into `rhs` with `sweeps` refinement sweeps; whether it is
    /// accurate enough (`None` when the solve fails).
    fn try_correction(
        &mut self,
        kkt: &mut Kkt,
        p: &QpData,
        w: &WorkingSet,
        terms: &[(usize, usize, f64)],
        x0: &[f64],
        sweeps: usize,
    ) -> Option<bool> {
        let (n, m) = (p.x.len(), p.g.len());
        refill(&mut self.rhs, n + m, 0.0);
        let mut moved = false;
        for &(row, k, c) in terms {
            if w.rows[row] != Side::Free {
                self.rhs[n + row] -= c * (x0[k] - self.x0_lin[k]);
                moved |= self.rhs[n + row] != 0.0;
            }
        }
        let rhs_max = self.rhs.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut ratio = 0.0;
        if moved {
            // A back-substitution and its residual, with `sweeps` refinement sweeps.
            let limits = (kkt.min_refinement_steps, kkt.max_refinement_steps);
            (kkt.min_refinement_steps, kkt.max_refinement_steps) = (sweeps, sweeps);
            let solved = kkt.solve_shifted(&mut self.rhs, None);
            (kkt.min_refinement_steps, kkt.max_refinement_steps) = limits;
            ratio = solved.ok()?;
        }
        let correction_max = self.rhs.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let (dd, dl) = self.rhs.split_at_mut(n);
        let mut dl_max = 0.0f64;
        for (i, v) in dl.iter_mut().enumerate() {
            if w.rows[i] == Side::Free {
                // A row outside W: no multiplier, or the augmented term's (exact).
                if p.row_weight[i] == 0.0 {
                    *v = 0.0;
                }
            } else {
                dl_max = dl_max.max(v.abs());
            }
            *v += self.lambda[i];
        }
        for (j, v) in dd.iter_mut().enumerate() {
            // A bound of W stays at its target, which x0 does not move.
            *v = if w.vars[j] == Side::Free {
                *v + self.d[j]
            } else {
                self.d[j]
            };
        }
        // The correction's residual in K + diag(ε), from the solve's residual ratio
        // ‖r‖ / (min(‖x‖, 10⁶‖b‖) + ‖b‖) ≤ ‖r‖ / ... bounded by ratio·(‖x‖ + ‖b‖), plus
        // the regularisation ε·|δλ_i| it leaves in W's rows: within the refined solve's
        // target relative to the whole step.
        let size = self.rhs.iter().fold(1.0f64, |a, v| a.max(v.abs()));
        let error = ratio * (correction_max + rhs_max) + ZERO_BLOCK_REG * dl_max;
        Some(size.is_finite() && !error.is_nan() && error <= CORRECTION_RATIO * size)
    }
}
