//! The merit function and the line search of an SQP iteration: Powell's individual
//! penalty weights, the decrease `pred` predicted by the QP model, Armijo's test with a
//! rounding allowance, and one second-order correction before backtracking.

#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use clarabel::solver::SolverStatus;

use super::bfgs::quad;
use super::iterate::TrialPoint;
use super::qp::QpResult;
use super::state::{eval_g, SqpState};
use super::workspace::ModelBuffers;
use crate::frontend::scaled::refill;

/// An accepted trial point with the QP result that led to it when that is the
/// second-order correction's (`None`: the step's own QP result).
pub(super) struct Trial {
    pub point: TrialPoint,
    pub soc: Option<QpResult>,
}

/// Outcome of the line search.
pub(super) struct LineSearch {
    /// The accepted point; `None` when α fell below `min_step`.
    pub trial: Option<Trial>,
    pub alpha: f64,
    /// Trial points evaluated.
    pub ls: usize,
    /// The second-order correction was accepted.
    pub soc_used: bool,
    /// A step at the rounding level of x, taken without the merit test.
    pub tiny: bool,
    /// ‖d‖∞.
    pub d_norm: f64,
    /// Predicted decrease m(0) − m(d) of the merit.
    pub pred: f64,
}

/// The merit at the iterate and the QP model's decrease for the step (J d and J_cone d
/// are left in the model buffers).
struct Model {
    phi0: f64,
    pred: f64,
}

impl SqpState<'_> {
    /// Powell (1978): w_i = max(|λ_i|, ½(w_i + |λ_i|)) with the QP's multipliers, kept in
    /// [floor, ρ]. Any w with |λ_i| ≤ w_i ≤ ρ keeps pred ≥ 0 (the step is a descent
    /// direction of the weighted merit), and rows with small multipliers no longer pay ρ
    /// for second-order violations: with one ρ ≥ max|λ_i| (≈ 600 on the gap-crossing
    /// step-length rows), the bilinear moment rows' O(‖d‖²) violation priced every long
    /// step out. `first`: no multiplier history yet, start from the classical weights ρ.
    pub fn update_merit_weights(&mut self, res: &QpResult, first: bool) {
        let (o, rho) = (self.o, self.rho);
        let merit_w = &mut self.steps.merit_w;
        if first {
            merit_w.iter_mut().for_each(|w| *w = rho);
        }
        for (w, l) in merit_w.iter_mut().zip(&res.lambda) {
            *w = if o.individual_penalties {
                let l = l.abs();
                l.max(0.5 * (*w + l))
                    .max(o.penalty_weight_floor * rho)
                    .min(rho)
            } else {
                rho
            };
        }
    }

    /// The merit φ(x_k) and pred = m(0) − m(d) for the step `d` of the QP with shift
    /// `delta`.
    fn model(&mut self, d: &[f64], delta: f64) -> Model {
        let (s, it, geo, curv) = (&self.shape, &self.it, &self.geo, &self.curv);
        let (n, m, w, rho) = (s.n, s.m, &self.steps.merit_w, self.rho);
        let ModelBuffers {
            jd,
            cd,
            lin_g,
            lin_c,
            ..
        } = &mut self.steps.model;
        let phi0 = it.f + geo.penalty(&it.g, &it.cone, w, rho);
        refill(jd, m, 0.0);
        for c in 0..n {
            for p in s.jp.col_range(c) {
                jd[s.jp.row_idx()[p]] += it.jv[p] * d[c];
            }
        }
        refill(cd, s.n_cone, 0.0);
        if let Some(cp) = s.cp.as_ref() {
            for c in 0..n {
                for p in cp.col_range(c) {
                    cd[cp.row_idx()[p]] += it.cv[p] * d[c];
                }
            }
        }
        lin_g.clear();
        lin_g.extend((0..m).map(|i| it.g[i] + jd[i]));
        lin_c.clear();
        lin_c.extend((0..s.n_cone).map(|k| it.cone[k] + cd[k]));
        let mut dbd = quad(&s.hp, &curv.hv, delta, s.dense.then_some(&curv.bfgs[..]), d);
        if !s.dense {
            dbd += (0..m)
                .map(|i| curv.row_weight[i] * jd[i] * jd[i])
                .sum::<f64>();
            dbd += (0..n)
                .map(|j| curv.bound_weight[j] * d[j] * d[j])
                .sum::<f64>();
        }
        let gd: f64 = it.grad.iter().zip(d).map(|(a, b)| a * b).sum();
        let pred = -(gd + 0.5 * dbd) + geo.penalty(&it.g, &it.cone, w, rho)
            - geo.penalty(lin_g, lin_c, w, rho);
        Model { phi0, pred }
    }

    /// A trial point not in use (its vectors are overwritten by [`SqpState::evaluate`]).
    fn take_point(&mut self) -> TrialPoint {
        self.steps.points.pop().unwrap_or_default()
    }

    /// The point x + α·step clamped to the bounds, evaluated into `pt`.
    fn evaluate(&mut self, step: &[f64], alpha: f64, pt: &mut TrialPoint) {
        let (s, geo, x) = (&self.shape, &self.geo, &self.it.x);
        pt.x.clear();
        pt.x.extend((0..s.n).map(|j| (x[j] + alpha * step[j]).clamp(geo.x_l[j], geo.x_u[j])));
        refill(&mut pt.g, s.m, 0.0);
        refill(&mut pt.cone, s.n_cone, 0.0);
        pt.f = self.sc.f(&pt.x);
        eval_g(&mut self.sc, &pt.x, &mut pt.g, &mut pt.cone);
    }

    /// The second-order correction after a rejected full step with constraint values
    /// `gt`, `ct`: the QP again with constants g(x+d) − J d; its point when it passes
    /// Armijo's test with `bound`.
    fn second_order_correction(
        &mut self,
        full: &TrialPoint,
        bound: f64,
        delta: f64,
    ) -> Option<Trial> {
        let (m, n_cone) = (self.shape.m, self.shape.n_cone);
        let mut mb = std::mem::take(&mut self.steps.model);
        mb.gh.clear();
        mb.gh.extend((0..m).map(|i| full.g[i] - mb.jd[i]));
        mb.chat.clear();
        mb.chat.extend((0..n_cone).map(|k| full.cone[k] - mb.cd[k]));
        let r2 = self.correction_qp(&mb.gh, &mb.chat, delta);
        self.steps.model = mb;
        let r2 = r2?;
        let mut pt = self.take_point();
        self.evaluate(&r2.d, 1.0, &mut pt);
        let phis = pt.f
            + self
                .geo
                .penalty(&pt.g, &pt.cone, &self.steps.merit_w, self.rho);
        if phis.is_finite() && phis <= bound {
            Some(Trial {
                point: pt,
                soc: Some(r2),
            })
        } else {
            self.steps.points.push(pt);
            self.steps.results.push(r2);
            None
        }
    }

    /// The QP of the second-order correction (constraint constants `gh`, cone constants
    /// `chat`): the active-set method from the step's working set, clarabel otherwise.
    fn correction_qp(&mut self, gh: &[f64], chat: &[f64], delta: f64) -> Option<QpResult> {
        let mut start = self.steps.spare_working_set.take();
        if let (Some(w), Some(s)) = (self.steps.working_set.as_ref(), start.as_mut()) {
            s.clone_from(w);
        } else {
            start = self.steps.working_set.clone();
        }
        match self.active_set_qp(Some(gh), delta, start, false) {
            Some(r) => Some(r),
            None => {
                let (geo, x) = (&self.geo, &self.it.x);
                let t_qp = Instant::now();
                let r2 = self
                    .qp
                    .resolve_with_g(x, &geo.x_l, &geo.x_u, gh, &geo.g_l, &geo.g_u, chat);
                self.work.qp_seconds += t_qp.elapsed().as_secs_f64();
                self.work.n_qp += 1;
                let r2 = r2.ok()?;
                self.work.qp_iterations += r2.iterations as u64;
                matches!(r2.status, SolverStatus::Solved | SolverStatus::AlmostSolved).then_some(r2)
            }
        }
    }

    /// Backtracking line search on the merit along the QP step of `res` (shift `delta`).
    pub fn line_search(&mut self, res: &QpResult, delta: f64) -> LineSearch {
        let o = self.o;
        let d = &res.d;
        let model = self.model(d, delta);
        let Model { phi0, pred } = model;
        let d_norm = d.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        // Rounding allowance of the merit: of f, and of every weighted row value (a row
        // at its bound shows violations at the rounding level of g_i, which the weights
        // up to ρ magnify; near a solution these decided the line search, see
        // benches/reference/results/performance-notebook.md, "SQP on the flagship").
        let g_noise: f64 = (0..self.shape.m)
            .filter(|&i| !self.geo.cone_row[i])
            .map(|i| self.steps.merit_w[i] * self.it.g[i].abs().max(1.0))
            .sum();
        let slack = 10.0 * f64::EPSILON * (phi0.abs().max(1.0) + g_noise);
        let x_max = self.it.x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        // A step at rounding level of x is taken without the merit test (IPOPT's 't').
        let tiny = d_norm <= 1e-9 * (1.0 + x_max);
        let mut out = LineSearch {
            trial: None,
            alpha: 1.0,
            ls: 0,
            soc_used: false,
            tiny,
            d_norm,
            pred,
        };
        let mut pt = self.take_point();
        loop {
            out.ls += 1;
            let alpha = out.alpha;
            self.evaluate(d, alpha, &mut pt);
            let finite = pt.f.is_finite()
                && pt.g.iter().all(|v| v.is_finite())
                && pt.cone.iter().all(|v| v.is_finite());
            if finite {
                let phi = pt.f
                    + self
                        .geo
                        .penalty(&pt.g, &pt.cone, &self.steps.merit_w, self.rho);
                if tiny || phi <= phi0 - o.armijo * alpha * pred.max(0.0) + slack {
                    out.trial = Some(Trial {
                        point: pt,
                        soc: None,
                    });
                    return out;
                }
                if alpha == 1.0 && o.second_order_correction && pred > 0.0 {
                    let bound = phi0 - o.armijo * pred + slack;
                    if let Some(t) = self.second_order_correction(&pt, bound, delta) {
                        self.steps.points.push(pt);
                        out.trial = Some(t);
                        out.soc_used = true;
                        return out;
                    }
                }
            }
            out.alpha *= o.backtrack;
            if out.alpha < o.min_step {
                self.steps.points.push(pt);
                return out;
            }
        }
    }
}
