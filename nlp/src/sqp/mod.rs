//! Sequential quadratic programming: a line-search Sℓ1QP method whose QP subproblems are
//! solved by clarabel.
//!
//! Each iteration at x_k (with multipliers λ_k):
//! 1. **Hessian.** B = ∇²L(x_k, λ_k) + δI + ρ_a·(J_AᵀJ_A + I_b) over the strongly active
//!    rows and bounds A (`active_sets_into`): δ is chosen for positive definiteness on the
//!    null space of the active constraints and ρ_a as small as makes B itself positive
//!    definite (inertia tests with a faer LDLᵀ, `Convexify`): clarabel needs a convex
//!    QP. Alternatively damped BFGS ([`HessianApproximation`]).
//! 2. **QP** (`qp`): the elastic subproblem min ½dᵀBd + ∇fᵀd + ρΣe over the linearised
//!    constraints relaxed by elastic variables e ≥ 0, the bounds, and affine second-order
//!    cones. It is always feasible. When e ≠ 0 (linearisation inconsistent, "elastic
//!    mode"), ρ grows by `penalty_increase` and the QP is solved again, up to
//!    `penalty_max`; past that the step minimises the linearised ℓ1 infeasibility.
//!    Without elastic variables or cones in use, clarabel's solution is then *polished*
//!    (`polish`, option `qp_polish`): the equality QP on its active set, solved exactly
//!    with the faer LDLᵀ, replaces it when that is a KKT point of the QP.
//! 3. **Line search** on the merit φ(x) = f(x) + Σ w_i·viol_i(x) (individual weights
//!    w_i ∈ [|λ_i|, ρ], Powell 1978; w_i = ρ is the classical ℓ1 merit) with Armijo's test
//!    φ(x + αd) ≤ φ(x) − η·α·pred, where pred = m(0) − m(d) ≥ 0 is the decrease of the
//!    QP model of φ. If the full step is rejected, one second-order correction (the QP
//!    again with constraint constants g(x+d) − J d) is tried before backtracking.
//! 4. **Multipliers** are the QP's: λ_{k+1}, z_{k+1}.
//!
//! Termination uses the IPM's scaled KKT error with the same options and meanings
//! (tol 1e-8, s_max, dual_inf_tol, constr_viol_tol, compl_inf_tol, acceptable_*), on
//! the problem scaled by the same gradient-based factors.
//!
//! In the iteration table, `lg(ra)` is log10 of the augmented weight ρ_a (the record's
//! `augmented_weight`; "-" when 0),
//! `lg(rg)` is the Hessian shift δ,
//! the 'r' mark after the iteration number flags elastic mode, and the step character
//! is 'S' for an accepted second-order correction, 'f' otherwise.

//!
//! Layout: `state.rs` (`SqpState`: set-up, stop tests, Hessian convexification),
//! `subproblem.rs` (the QP step with its retry policies and the elastic mode),
//! `line_search.rs` (merit and line search), `accept.rs` (accepting or rejecting a step),
//! `convexify.rs`, `bfgs.rs`, `iterate.rs` (the iterate and its KKT error), `shape.rs`
//! (sizes and patterns), `geometry.rs` (bounds, cones, violations), `qp.rs` (the
//! clarabel subproblem), `active_set.rs` (the warm active-set QP), `polish.rs`,
//! `stop.rs`, `workspace.rs` (what a solver keeps between solves), `cold_start.rs` (the
//! IPM's solution as the start of a cold solve, option `cold_start_ipm`);
//! `rti.rs`: real-time iterations ([`Rti`]), one iteration per sampling instant split
//! into a preparation and a feedback, built on the same parts.
//! Scaling, evaluation counters and the returned `Solution` are the front end's
//! (`frontend/scaled.rs`, `frontend/user_solution.rs`), shared with the IPM.

#![allow(clippy::needless_range_loop)]

mod accept;
mod active_set;
mod bfgs;
mod cold_start;
mod convexify;
mod geometry;
mod iterate;
mod line_search;
pub mod options;
mod polish;
pub(crate) mod qp;
pub mod rti;
mod rti_predictor;
mod shape;
mod state;
mod stop;
mod subproblem;
mod workspace;

use std::time::Instant;

use crate::callback::{IterationCallback, Observer};
use crate::error::SolveError;
use crate::frontend::solver::{impl_solver_options, solver_entry_points};
use crate::frontend::user_solution::conclude;
use crate::frontend::validate::validate_into;
use crate::frontend::{Solver, Termination};
use crate::numeric::NumericNlp;
use crate::solution::{BackendColumns, IterationRecord, Solution, Status};

pub use options::{HessianApproximation, SqpOptions};
pub use rti::{Feedback, Rti, RtiError, RtiResidual};
use state::SqpState;
use stop::Stop;
use workspace::Workspace;

/// The SQP solver: `Sqp::new(opts).solve(&mut nlp)`, the same call shape as
/// [`Ipm`](crate::Ipm). It keeps the KKT matrix (pattern, ordering, symbolic
/// factorisation) and the QP layouts between solves of problems with the same structure
/// (see [`Sqp::solve_warm`]); a clone starts without them.
#[derive(Debug, Clone, Default)]
pub struct Sqp {
    /// Options.
    pub options: SqpOptions,
    workspace: Workspace,
}

impl Solver for Sqp {
    fn name(&self) -> &'static str {
        "sqp"
    }

    fn solve_dyn(
        &self,
        nlp: &mut dyn NumericNlp,
        warm: Option<&Solution>,
        callback: Option<&mut IterationCallback<'_>>,
    ) -> Result<Solution, SolveError> {
        if warm.is_some() || !self.options.cold_start_ipm {
            let mut sol = Solution::empty();
            self.run_into(nlp, warm, callback, &mut sol)?;
            return Ok(sol);
        }
        self.solve_from_ipm(nlp, callback)
    }

    fn solve_warm_into(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
        out: &mut Solution,
    ) -> Result<(), SolveError> {
        Sqp::solve_warm_into(self, nlp, previous, out)
    }
}

impl Sqp {
    /// A cold solve with [`SqpOptions::cold_start_ipm`]: the IPM, then the SQP from its
    /// solution (cold when the IPM fails); the IPM's solution stands when the SQP does
    /// not converge from it. The callback sees both solves' iterations, numbered on, and
    /// the statistics count both.
    fn solve_from_ipm(
        &self,
        nlp: &mut dyn NumericNlp,
        mut callback: Option<&mut IterationCallback<'_>>,
    ) -> Result<Solution, SolveError> {
        let (mut ipm, solved) =
            match cold_start::ipm_start(&self.options, nlp, callback.as_deref_mut())? {
                cold_start::IpmStart::Stopped(sol) => return Ok(sol),
                cold_start::IpmStart::Failed(ipm) => (ipm, false),
                cold_start::IpmStart::Solved(ipm) => (ipm, true),
            };
        let start = solved.then_some(&ipm);
        let mut sol = Solution::empty();
        match callback {
            Some(cb) => {
                let mut numbered = cold_start::continue_numbering(cb, ipm.stats.iterations);
                self.run_into(nlp, start, Some(&mut numbered), &mut sol)?;
            }
            None => self.run_into(nlp, start, None, &mut sol)?,
        }
        cold_start::count_start_in(&ipm.stats, &mut sol.stats);
        if !solved || sol.status.is_success() || sol.status == Status::UserRequestedStop {
            return Ok(sol);
        }
        // The SQP did not converge from the IPM's solution: that solution stands, with
        // the time and work of both solves.
        ipm.message = format!(
            "{}{}the interior-point solution: the SQP started from it ended with {:?}",
            ipm.message,
            if ipm.message.is_empty() { "" } else { "; " },
            sol.status
        );
        ipm.stats = std::mem::take(&mut sol.stats);
        Ok(ipm)
    }

    /// A solver with the given options.
    pub fn new(options: SqpOptions) -> Self {
        Sqp {
            options,
            workspace: Workspace::default(),
        }
    }

    /// [`Sqp::solve_warm`] with the result written into `out` (for example the previous
    /// step's solution in an MPC loop), reusing its vectors. A re-solve of a problem with
    /// the same structure as this solver's previous solve (same patterns and bounds
    /// structure, exact Hessian, no cones, no callback, `print_level` < 3) whose QPs the
    /// active-set method solves allocates nothing once the kept vectors have grown to
    /// the most iterations, active-set changes and QPs seen; a QP handed to clarabel
    /// still allocates. The iterates are those of a fresh solver's `solve_warm`.
    /// On error `out` is left unspecified.
    /// ```
    /// use nlp::{Problem, Relation, Sqp};
    ///
    /// let mut pb = Problem::new();
    /// let x = pb.variable("x", 2).unwrap();
    /// let p = pb.parameter("p", 1).unwrap();
    /// pb.set_value(&p, &[0.0]).unwrap();
    /// pb.minimize((x[0] - p[0]).sq() + (x[1] - 2.0).sq());
    /// pb.subject_to((x[0] - x[1]).le(10.0)).unwrap();
    /// let mut nlp = pb.compile().unwrap();
    /// let sqp = Sqp::default();
    /// let mut sol = sqp.solve(&mut nlp).unwrap();
    /// let mut next = sol.clone();
    /// for step in 0..3 {
    ///     nlp.set_value("p", &[step as f64]).unwrap();
    ///     sqp.solve_warm_into(&mut nlp, &sol, &mut next).unwrap();
    ///     assert!(next.status.is_success());
    ///     assert!((next.x[0] - step as f64).abs() < 1e-6);
    ///     std::mem::swap(&mut sol, &mut next);
    /// }
    /// ```
    pub fn solve_warm_into(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
        out: &mut Solution,
    ) -> Result<(), SolveError> {
        self.run_into(nlp, Some(previous), None, out)
    }
}

solver_entry_points!(
    Sqp,
    "Starts from a previous solution's x and multipliers (λ, z_L, z_U): with a good \
     guess the first QPs already have the right active set."
);

impl_solver_options!(SqpOptions => Sqp);

impl Sqp {
    /// One solve in the kept workspace, written into `sol`.
    fn run_into(
        &self,
        nlp: &mut dyn NumericNlp,
        warm: Option<&Solution>,
        callback: Option<&mut IterationCallback<'_>>,
        sol: &mut Solution,
    ) -> Result<(), SolveError> {
        let start = Instant::now();
        let o = &self.options;
        o.validate()?;
        let mut kept = self.workspace.take();
        if let Err(e) = validate_into(nlp, warm, &mut kept.bufs.validated) {
            self.workspace.put(kept);
            return Err(e);
        }
        let (n, m) = (nlp.n(), nlp.m());
        let mut observer = callback.map(|cb| Observer::new(cb, n, m, None));
        let records = std::mem::take(&mut sol.stats.records);
        let mut s = SqpState::new(o, nlp, warm, kept, records);
        let mut iter = 0usize;
        let stop = match s.setup_kkt() {
            Err(e) => Stop::from(e),
            Ok(()) => iterate(&mut s, &mut iter, observer.as_mut(), start),
        };
        s.stats.iterations = iter;
        let w = &s.work;
        s.stats.n_factorizations = w.n_fact;
        s.stats.factor_seconds = w.factor_seconds;
        s.stats.n_qp_solves = w.n_qp;
        s.stats.qp_iterations = w.qp_iterations as usize;
        s.stats.qp_seconds = w.qp_seconds;
        s.write_solution(stop, sol);
        conclude(
            sol,
            std::mem::take(&mut s.stats),
            &s.sc,
            start,
            o.print_level,
        );
        if o.print_level >= 3 {
            crate::log::log_out!(
                "Polished QP solutions: {} of {}",
                s.work.n_polished,
                s.work.n_qp
            );
            let [shape, eq, cycle, limit, penalty] = s.work.active_set_failures;
            crate::log::log_out!(
                "Active-set QPs: {} solved; handed to clarabel: shape {shape}, equality QP \
                 {eq}, cycle {cycle}, iteration limit {limit}, penalty {penalty}",
                s.work.n_active_set
            );
        }
        s.keep_parts(&self.workspace);
        Ok(())
    }
}

/// The SQP iterations from the state's first iterate until a stop; `iter` counts them.
fn iterate(
    s: &mut SqpState<'_>,
    iter: &mut usize,
    mut observer: Option<&mut Observer<'_>>,
    start: Instant,
) -> Stop {
    let mut termination = Termination::default();
    loop {
        if let Some(stop) = s.check(*iter, &mut termination, observer.as_deref_mut(), start) {
            return stop;
        }
        *iter += 1;
        let t_hess = Instant::now();
        let delta = s.convexify();
        s.work.factor_seconds += t_hess.elapsed().as_secs_f64();
        let (res, delta) = match delta.and_then(|delta| s.subproblem(delta)) {
            Ok(r) => r,
            Err(e) => return e.into(),
        };
        let elastic = res.e.iter().any(|v| *v > s.o.elastic_tol);
        if s.o.print_level >= 6 {
            print_penalty_line(s, &res);
        }
        s.update_merit_weights(&res, *iter == 1);
        let mut ls = s.line_search(&res, delta);
        s.record = IterationRecord {
            iter: *iter,
            restoration: elastic,
            objective: 0.0,
            inf_pr: 0.0,
            inf_du: 0.0,
            d_norm: ls.d_norm,
            regularization: delta,
            backend: BackendColumns::Sqp {
                augmented_weight: s.curv.rho_a_last,
            },
            alpha_du: ls.alpha,
            alpha_pr: ls.alpha,
            alpha_pr_char: if ls.soc_used {
                'S'
            } else if ls.tiny {
                't'
            } else {
                'f'
            },
            ls: ls.ls,
        };
        s.stats.max_regularization = s.stats.max_regularization.max(delta);
        let Some(trial) = ls.trial.take() else {
            let stop = s.reject(&ls, &res, delta);
            s.steps.results.push(res);
            match stop {
                Some(stop) => return stop,
                None => continue,
            }
        };
        let accepted = s.accept(trial, &ls, &res);
        s.steps.results.push(res);
        if let Err(e) = accepted {
            return e.into();
        }
    }
}

/// At `print_level` ≥ 6, under the iteration's row: the ℓ1 penalty ρ after the QP, the
/// largest multiplier in the Hessian ∇²L (the iterate's) and of the QP's solution, and
/// the QP's Σe (the diagnostics of elastic mode: ρ → λ → δ).
fn print_penalty_line(s: &SqpState<'_>, res: &qp::QpResult) {
    let max_abs = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let e_sum: f64 = res.e.iter().map(|v| v.max(0.0)).sum();
    crate::log::log_out!(
        "      rho {:.2e}  max|lambda| Hessian {:.2e}  QP {:.2e}  sum e {:.2e}",
        s.rho,
        max_abs(&s.it.mult.lambda),
        max_abs(&res.lambda),
        e_sum
    );
}
