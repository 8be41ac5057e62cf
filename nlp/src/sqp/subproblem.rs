//! The QP step of an SQP iteration: the elastic QP solved with its retry policies (a
//! larger shift when clarabel fails, a pure shift when the QP reads as unbounded), the
//! elastic mode (ρ raised while it lowers the linearised infeasibility), then polishing.

use std::time::Instant;

use clarabel::solver::SolverStatus as S;
use faer::sparse::SymbolicSparseColMat;

use super::active_set::{self, MAX_PENALTY_INCREASES};
use super::geometry::Geometry;
use super::iterate::Iterate;
use super::options::SqpOptions;
use super::polish::{self, WorkingSet};
use super::qp::{QpData, QpResult};
use super::state::{Curvature, SqpState};
use super::stop::StepError;
use crate::kkt::Kkt;

/// Retry policies of one QP step, each with its own budget: how often an unbounded QP
/// is solved again with a pure shift ×100, how often another clarabel failure is solved
/// again with the shift ×10, and how often elastic mode raises ρ. (Before, one counter of
/// all QP solves in the step served all three, with limits 8, 4 and 12 solves.) The
/// third, `MAX_PENALTY_INCREASES`, is the active-set method's (`penalty_for`).
const MAX_UNBOUNDED_RETRIES: usize = 7;
const MAX_FAILED_QP_RETRIES: usize = 3;

impl SqpState<'_> {
    /// The QP at the iterate with shift `delta` (and the constraint values `g` instead
    /// of the iterate's: a second-order correction) solved by the active-set method
    /// (`active_set.rs`) from the working set `start` (the last QP's) or, without one,
    /// from the iterate's multipliers; `None` when the method does not apply (option
    /// off, BFGS, cones) or gives up. The working set of a solved QP is kept for the next
    /// one, and clarabel's copy of the QP is brought up to date (`Qp::load`) for a
    /// fallback.
    pub fn active_set_qp(
        &mut self,
        g: Option<&[f64]>,
        delta: f64,
        start: Option<WorkingSet>,
        may_raise_penalty: bool,
    ) -> Option<QpResult> {
        let o = self.o;
        if !o.qp_active_set || self.shape.dense || self.shape.n_cone > 0 {
            self.steps.spare_working_set = start.or(self.steps.spare_working_set.take());
            return None;
        }
        let mut data = qp_data(&self.it, &self.geo, &self.curv, false, delta, self.rho);
        if let Some(g) = g {
            data.g = g;
        }
        let data = &data;
        let kkt = self.kkt.as_mut()?;
        let steps = &mut self.steps;
        let mut w = match start.filter(|w| active_set::fits(w, data)) {
            Some(w) => w,
            None => {
                let mut w = steps
                    .spare_working_set
                    .take()
                    .unwrap_or_else(|| WorkingSet {
                        rows: Vec::new(),
                        vars: Vec::new(),
                    });
                active_set::guess_into(data, &self.it.mult, &mut w);
                w
            }
        };
        let mut res = steps.results.pop().unwrap_or_else(QpResult::empty);
        let t_qp = Instant::now();
        let solved = active_set::solve_in(
            kkt,
            data,
            (&self.shape.jp, &self.shape.hp),
            (&mut w, &mut res),
            (o.qp_active_set_max_iter as usize, self.qp.n_elastic()),
            (&mut self.work.n_fact, false),
            &mut steps.active_set,
        );
        self.work.qp_seconds += t_qp.elapsed().as_secs_f64();
        let solved = match solved {
            Ok(s) => s,
            Err(f) => {
                self.work.active_set_failures[f as usize] += 1;
                steps.spare_working_set = Some(w);
                steps.results.push(res);
                return None;
            }
        };
        // ρ as the elastic mode would raise it (not in a second-order correction, whose
        // merit is that of the step's ρ).
        let increases = if may_raise_penalty {
            MAX_PENALTY_INCREASES
        } else {
            0
        };
        let limits = (o.penalty_increase, increases, o.penalty_max);
        let Some(rho) = active_set::penalty_for(solved.max_multiplier, self.rho, limits) else {
            self.work.active_set_failures[4] += 1;
            steps.spare_working_set = Some(w);
            steps.results.push(res);
            return None;
        };
        self.rho = rho;
        self.work.n_qp += 1;
        self.work.n_active_set += 1;
        self.work.qp_iterations += solved.iterations as u64;
        self.qp.load(data);
        if let Some(old) = steps.working_set.replace(w) {
            steps.spare_working_set = Some(old);
        }
        Some(res)
    }
}

/// The QP data at iterate `it` with shift `shift` and penalty `rho`.
pub(super) fn qp_data<'d>(
    it: &'d Iterate,
    geo: &'d Geometry,
    curv: &'d Curvature,
    dense: bool,
    shift: f64,
    rho: f64,
) -> QpData<'d> {
    QpData {
        x: &it.x,
        x_l: &geo.x_l,
        x_u: &geo.x_u,
        g: &it.g,
        g_l: &geo.g_l,
        g_u: &geo.g_u,
        grad: &it.grad,
        jac: &it.jv,
        cone: &it.cone,
        cone_jac: &it.cv,
        hess: &curv.hv,
        shift,
        bound_weight: &curv.bound_weight,
        row_weight: &curv.row_weight,
        dense_b: if dense { Some(&curv.bfgs) } else { None },
        rho,
    }
}

impl SqpState<'_> {
    /// The step's QP result and the shift it was solved with (≥ `delta`). See the module
    /// documentation for the retries and the elastic mode; without cones or elastic
    /// variables in use the result is polished (`polish.rs`, option `qp_polish`).
    pub fn subproblem(&mut self, delta: f64) -> Result<(QpResult, f64), StepError> {
        let o = self.o;
        let t_qp_loop = Instant::now();
        let start = self.steps.working_set.take();
        if let Some(res) = self.active_set_qp(None, delta, start, true) {
            self.work.factor_seconds += t_qp_loop.elapsed().as_secs_f64();
            return Ok((res, delta));
        }
        let found = self.clarabel_qp(delta);
        self.work.factor_seconds += t_qp_loop.elapsed().as_secs_f64();
        let (res, qp_shift) = found?;
        // Polish: the exact solution of the equality QP on clarabel's active set (not
        // with cones or elastic variables in use).
        let dense = self.shape.dense;
        let data = qp_data(&self.it, &self.geo, &self.curv, dense, qp_shift, self.rho);
        let can_polish = o.qp_polish && !dense && self.shape.n_cone == 0;
        let res = polished(
            self.kkt.as_mut().filter(|_| can_polish),
            o,
            (&data, &self.shape.jp, &self.shape.hp),
            res,
            &mut self.work.n_fact,
            &mut self.work.n_polished,
        );
        Ok((res, qp_shift))
    }

    /// The elastic QP solved by clarabel from shift `delta` on, with the retry policies
    /// and the elastic mode of the module documentation: the accepted result and the
    /// shift it was solved with (the curvature's weights and ρ as they were for it).
    fn clarabel_qp(&mut self, delta: f64) -> Result<(QpResult, f64), StepError> {
        let o = self.o;
        let dense = self.shape.dense;
        let mut qp_shift = delta;
        let (mut unbounded_retries, mut failed_retries, mut penalty_increases) = (0, 0, 0);
        let mut elastic_prev: Option<(QpResult, f64, f64)> = None;
        loop {
            let data = qp_data(&self.it, &self.geo, &self.curv, dense, qp_shift, self.rho);
            let t_qp = Instant::now();
            let res = self.qp.solve(&data);
            self.work.qp_seconds += t_qp.elapsed().as_secs_f64();
            self.work.n_qp += 1;
            let res = res?;
            self.work.qp_iterations += res.iterations as u64;
            match res.status {
                S::Solved | S::AlmostSolved => {}
                S::DualInfeasible | S::AlmostDualInfeasible
                    if unbounded_retries < MAX_UNBOUNDED_RETRIES =>
                {
                    unbounded_retries += 1;
                    // Unbounded QP: B too flat along a feasible direction (δ·I and
                    // ρ_a·J_AᵀJ_A certified by `Convexify` are positive definite,
                    // but a near-singular B may still read as unbounded to
                    // clarabel): fall back to a pure shift.
                    self.curv.row_weight.iter_mut().for_each(|v| *v = 0.0);
                    self.curv.bound_weight.iter_mut().for_each(|v| *v = 0.0);
                    qp_shift = (qp_shift * 100.0).max(o.first_hessian_shift);
                    continue;
                }
                _ if failed_retries < MAX_FAILED_QP_RETRIES => {
                    failed_retries += 1;
                    qp_shift = (qp_shift * 10.0).max(o.first_hessian_shift);
                    continue;
                }
                st => return Err(StepError::QpStatus(st)),
            }
            let e_max = res.e.iter().fold(0.0f64, |a, v| a.max(*v));
            let e_sum: f64 = res.e.iter().map(|v| v.max(0.0)).sum();
            if e_max > o.elastic_tol {
                // Elastic mode. A larger ρ helps only while it lowers the linearised
                // infeasibility; when the linearisation is inconsistent (typical of
                // complementarity products away from the solution) Σe stalls, and
                // the step of the smaller ρ is kept (Fletcher & Leyffer 2004, §3).
                if let Some((_, prev_sum, _)) = &elastic_prev {
                    if e_sum > 0.9 * prev_sum {
                        let (prev, _, prev_rho) = elastic_prev.take().expect("checked");
                        self.rho = prev_rho;
                        return Ok((prev, qp_shift));
                    }
                }
                if self.rho < o.penalty_max && penalty_increases < MAX_PENALTY_INCREASES {
                    penalty_increases += 1;
                    elastic_prev = Some((res, e_sum, self.rho));
                    self.rho = (self.rho * o.penalty_increase).min(o.penalty_max);
                    continue;
                }
            }
            return Ok((res, qp_shift));
        }
    }
}

/// The QP result `res` polished ([`polish::polish`]) when a KKT matrix is given and no
/// elastic variable is in use; `res` itself otherwise or when polishing is rejected.
fn polished(
    kkt: Option<&mut Kkt>,
    o: &SqpOptions,
    (data, jp, hp): (
        &QpData,
        &SymbolicSparseColMat<usize>,
        &SymbolicSparseColMat<usize>,
    ),
    res: QpResult,
    n_fact: &mut usize,
    n_polished: &mut usize,
) -> QpResult {
    match kkt {
        Some(kkt) if res.e.iter().all(|v| *v <= o.elastic_tol) => {
            match polish::polish(kkt, data, jp, hp, &res, n_fact) {
                Some(p) => {
                    *n_polished += 1;
                    p
                }
                None => res,
            }
        }
        _ => res,
    }
}
