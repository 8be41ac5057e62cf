//! The end of an SQP iteration after the line search: taking the accepted trial point
//! (new derivatives, the proximal shift adapted to the step length, a BFGS update) or
//! reacting to a rejected step (a stop, or a shifted Hessian next time).

use super::bfgs::bfgs_update;
use super::line_search::{LineSearch, Trial};
use super::qp::QpResult;
use super::state::{eval_jac, SqpState};
use super::stop::{StepError, Stop};
use crate::solution::Status;

impl SqpState<'_> {
    /// After a failed line search: stops when the step is negligible or the searches keep
    /// failing, otherwise shifts the next Hessian and keeps the QP's multipliers.
    pub fn reject(&mut self, ls: &LineSearch, res: &QpResult, delta: f64) -> Option<Stop> {
        self.ls_failures += 1;
        let x = &self.it.x;
        let x_max = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if ls.d_norm <= 1e-14 * (1.0 + x_max) || self.ls_failures > 8 {
            let it = &self.it;
            let pr = self.geo.unscaled_max(&self.sc, x, &it.g, &it.cone);
            let status = if pr > self.o.constr_viol_tol {
                Status::InfeasibleProblemDetected
            } else {
                Status::SearchDirectionBecomesTooSmall
            };
            let (pred, d_norm) = (ls.pred, ls.d_norm);
            return Some(Stop {
                status,
                message: format!("line search failed (pred = {pred:.3e}, ‖d‖ = {d_norm:.3e})"),
            });
        }
        // Shorter, more conservative steps next time (a trust-region-like reaction).
        let c = &mut self.curv;
        c.extra_shift = (c.extra_shift * 10.0).max(1e-2 * (1.0 + delta));
        // Multipliers of the QP are still the best estimate.
        self.it.mult.set_from_qp(res);
        self.it.have_mult = true;
        None
    }

    /// Takes the accepted trial point (whose QP result is `trial.soc` or else `res`):
    /// adapts the proximal shift to the step length, evaluates the derivatives there and
    /// updates a BFGS matrix. The trial's vectors (holding the old point) and its QP
    /// result go back to the buffers.
    pub fn accept(
        &mut self,
        trial: Trial,
        ls: &LineSearch,
        res: &QpResult,
    ) -> Result<(), StepError> {
        self.ls_failures = 0;
        // Levenberg–Marquardt-like safeguard: a heavily cut step means the model is
        // poor at this length, so the next step is shortened by a proximal shift
        // (×10 while the cuts go on); a full step releases it at once. A gradual release
        // (÷10 per full step) kept the steps short for several iterations after a
        // single cut; with the inertia's shift no longer inheriting it (`convexify`)
        // that gradual release made hs116 fail, the immediate one solves it.
        let c = &mut self.curv;
        if ls.alpha < 0.1 && !ls.soc_used {
            c.extra_shift = (c.extra_shift * 10.0).max(1e-1);
        } else if ls.alpha == 1.0 {
            c.extra_shift = 0.0;
        }
        let Trial { mut point, soc } = trial;
        let (it, shape, cone_row) = (&mut self.it, &self.shape, &self.geo.cone_row);
        std::mem::swap(&mut it.x, &mut point.x);
        it.f = point.f;
        std::mem::swap(&mut it.g, &mut point.g);
        std::mem::swap(&mut it.cone, &mut point.cone);
        it.mult.set_from_qp(soc.as_ref().unwrap_or(res));
        it.have_mult = true;
        if let Some(r) = soc {
            self.steps.results.push(r);
        }
        let x_old = &point.x;
        // ∇L at the old point with the new multipliers (BFGS only).
        let mut l_old = vec![0.0; if shape.dense { shape.n } else { 0 }];
        if shape.dense {
            it.lagrangian_gradient(shape, cone_row, &it.mult, &mut l_old);
        }
        self.sc.grad(&it.x, &mut it.grad);
        eval_jac(&mut self.sc, &it.x, &mut it.jv, &mut it.cv);
        if it.grad.iter().chain(&it.jv).any(|v| !v.is_finite()) {
            return Err(StepError::NonFiniteDerivatives);
        }
        if shape.dense {
            let mut l_new = vec![0.0; shape.n];
            it.lagrangian_gradient(shape, cone_row, &it.mult, &mut l_new);
            let s: Vec<f64> = it.x.iter().zip(x_old).map(|(a, b)| a - b).collect();
            let y: Vec<f64> = l_new.iter().zip(&l_old).map(|(a, b)| a - b).collect();
            bfgs_update(&mut self.curv.bfgs, &s, &y);
        }
        self.steps.points.push(point);
        Ok(())
    }
}
