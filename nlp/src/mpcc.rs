//! Mathematical programs with complementarity constraints (MPCC): a driver over both back
//! ends for problems with [`Problem::complementarity`] pairs `0 ≤ a ⊥ b ≥ 0`.
//!
//! * [`MpccBackend::Sqp`] solves the problem in Fletcher & Leyffer's NLP form directly
//!   (products `a·b ≤ 0` as constraints; Fletcher & Leyffer 2004, "Solving mathematical
//!   programs with complementarity constraints as nonlinear programs", Optim. Methods
//!   Softw. 19(1):15–40). No constraint qualification holds at a solution, and away from
//!   it the linearised products are often inconsistent: the SQP's elastic mode (ℓ1
//!   penalty on the linearised violation) takes those steps.
//! * [`MpccBackend::Ipm`] cannot treat the products as constraints (no strictly feasible
//!   interior), so it solves the ℓ1-penalty formulation of Leyffer, López-Calva & Nocedal
//!   (2006), "Interior methods for mathematical programs with complementarity
//!   constraints", SIAM J. Optim. 17(1):52–77: the product rows are dropped and
//!   π·Σ aᵢbᵢ is added to the objective (a, b ≥ 0 kept), with π multiplied by
//!   `penalty_increase` (warm start from the previous solution) until the complementarity
//!   residual max |min(aᵢ, bᵢ)| is below `switch_tol`.
//!
//! Both then run an **exact final phase** (`exact_final_phase`, default on): each pair's
//! branch is fixed — the smaller of a, b is set to 0 (a bound when it is a variable, an
//! equality row otherwise) — and the problem without products is solved again from the
//! last point by the same back end. Complementarity then holds to the accuracy of the
//! equality constraints (exactly for variables). If that solve fails, the previous phase's
//! solution is returned.
//!
//! The result reports the complementarity residual and the biactive pairs
//! ([`ComplementarityReport`]) and every phase. [`solve_mpcc_with_callback`] forwards an
//! iteration callback to every phase's solve, labelling each iteration with its phase.

use std::ops::ControlFlow;
use std::time::Instant;

use symx::Expr;
use thiserror::Error;

use crate::callback::{IterationCallback, IterationView, PhaseLabel};
use crate::constraint::Relation;
use crate::error::SolveError;
use crate::frontend::Solver;
use crate::ipm::Ipm;
use crate::options::IpmOptions;
use crate::problem::{BuildError, ComplementarityReport, Problem};
use crate::solution::{Solution, Status};
use crate::sqp::{Sqp, SqpOptions};

/// Which back end solves the MPCC.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MpccBackend {
    /// SQP on the products-as-constraints form (Fletcher & Leyffer 2004).
    Sqp,
    /// Interior point on the ℓ1 penalty form with π updates (Leyffer, López-Calva &
    /// Nocedal 2006).
    Ipm,
}

/// Options of [`solve_mpcc`].
#[derive(Debug, Clone, PartialEq)]
pub struct MpccOptions {
    /// Options of the SQP back end.
    pub sqp: SqpOptions,
    /// Options of the IPM back end.
    pub ipm: IpmOptions,
    /// First penalty π of the IPM's penalty phase. Default 10.
    pub penalty_init: f64,
    /// Factor of the π updates. Default 10.
    pub penalty_increase: f64,
    /// Largest π. Default 1e8.
    pub penalty_max: f64,
    /// The penalty phase ends when the complementarity residual is below this. Default 1e-6.
    pub switch_tol: f64,
    /// Fix each pair's branch and re-solve (exact complementarity). Default true.
    pub exact_final_phase: bool,
    /// A pair is biactive when both a and b are within this of zero. Default 1e-6.
    pub biactive_tol: f64,
}

impl MpccOptions {
    /// The solver of `backend` with its options.
    pub fn solver(&self, backend: MpccBackend) -> Box<dyn Solver> {
        match backend {
            MpccBackend::Sqp => Box::new(Sqp::new(self.sqp.clone())),
            MpccBackend::Ipm => Box::new(Ipm::new(self.ipm.clone())),
        }
    }
}

impl Default for MpccOptions {
    fn default() -> Self {
        MpccOptions {
            sqp: SqpOptions::default(),
            ipm: IpmOptions::default(),
            penalty_init: 10.0,
            penalty_increase: 10.0,
            penalty_max: 1e8,
            switch_tol: 1e-6,
            exact_final_phase: true,
            biactive_tol: 1e-6,
        }
    }
}

/// One solve of the driver.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MpccPhase {
    /// "sqp" (products as constraints), "penalty" (IPM, π·Σab) or "final" (branches fixed).
    pub kind: &'static str,
    /// π of a penalty phase (0 otherwise).
    pub penalty: f64,
    pub status: Status,
    pub iterations: usize,
    /// Objective of that solve (the penalised one in a penalty phase).
    pub objective: f64,
    /// Complementarity residual at its solution.
    pub residual: f64,
}

/// Result of [`solve_mpcc`].
#[derive(Debug, Clone)]
pub struct MpccSolution {
    /// The returned solution (of the last successful phase, or of the phase a callback
    /// stopped); `objective` is f(x) of the original problem. Its multipliers belong to
    /// the problem of that phase.
    pub solution: Solution,
    /// Complementarity residual and biactive pairs at `solution.x`.
    pub report: ComplementarityReport,
    /// Every solve, in order.
    pub phases: Vec<MpccPhase>,
    /// Total iterations over the phases.
    pub iterations: usize,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Errors of [`solve_mpcc`].
#[derive(Debug, Error)]
pub enum MpccError {
    #[error("building a phase problem: {0}")]
    Build(#[from] BuildError),
    #[error("solver: {0}")]
    Solve(#[from] SolveError),
}

fn run(
    solver: &dyn Solver,
    pb: &Problem,
    x0: Option<&[f64]>,
    callback: Option<&mut IterationCallback<'_>>,
    phase: PhaseLabel,
) -> Result<Solution, MpccError> {
    let mut c = pb.compile()?;
    if let Some(x0) = x0 {
        c.set_initial_point(x0)?;
    }
    // The phase's view: the solver's, labelled with the phase.
    let mut labelled = callback.map(|cb| {
        move |v: &IterationView<'_>| {
            cb(&IterationView {
                phase: Some(phase),
                ..*v
            })
        }
    });
    let cb = labelled.as_mut().map(|f| f as &mut IterationCallback<'_>);
    Ok(solver.solve_dyn(&mut c, None, cb)?)
}

fn ok(s: Status) -> bool {
    matches!(s, Status::SolveSucceeded | Status::SolvedToAcceptableLevel)
}

/// Solves `problem` (with its complementarity pairs) by `backend`; see the module docs.
pub fn solve_mpcc(
    problem: &Problem,
    backend: MpccBackend,
    options: &MpccOptions,
) -> Result<MpccSolution, MpccError> {
    solve(problem, backend, options, None)
}

/// [`solve_mpcc`] with a per-iteration callback, forwarded to every phase's solve (see
/// [`Ipm::solve_with_callback`]); [`IterationView::phase`] tells which phase an iteration
/// belongs to. [`ControlFlow::Break`] ends the whole driver: the stopped phase's point is
/// returned with status [`Status::UserRequestedStop`] and no later phase runs.
pub fn solve_mpcc_with_callback(
    problem: &Problem,
    backend: MpccBackend,
    options: &MpccOptions,
    mut callback: impl FnMut(&IterationView<'_>) -> ControlFlow<()>,
) -> Result<MpccSolution, MpccError> {
    solve(problem, backend, options, Some(&mut callback))
}

fn solve(
    problem: &Problem,
    backend: MpccBackend,
    options: &MpccOptions,
    mut callback: Option<&mut IterationCallback<'_>>,
) -> Result<MpccSolution, MpccError> {
    let t = Instant::now();
    let o = options;
    let solver = o.solver(backend);
    let f = problem.objective();
    let pairs = problem.complementarity_pairs().to_vec();
    let mut phases = Vec::new();
    let record = |phases: &mut Vec<MpccPhase>,
                  kind: &'static str,
                  penalty: f64,
                  sol: &Solution|
     -> Result<ComplementarityReport, MpccError> {
        let rep = problem.complementarity_report(&sol.x, o.biactive_tol)?;
        phases.push(MpccPhase {
            kind,
            penalty,
            status: sol.status,
            iterations: sol.stats.iterations,
            objective: sol.objective,
            residual: rep.residual,
        });
        Ok(rep)
    };
    // ---- first phase ----
    let label = |phases: &Vec<MpccPhase>, kind: &'static str, penalty: f64| PhaseLabel {
        index: phases.len(),
        kind,
        penalty,
    };
    let stopped = |sol: &Solution| sol.status == Status::UserRequestedStop;
    let mut best = match backend {
        MpccBackend::Sqp => {
            let phase = label(&phases, "sqp", 0.0);
            let sol = run(
                solver.as_ref(),
                problem,
                None,
                callback.as_deref_mut(),
                phase,
            )?;
            record(&mut phases, "sqp", 0.0, &sol)?;
            sol
        }
        MpccBackend::Ipm => {
            let mut pi = o.penalty_init;
            let mut x: Option<Vec<f64>> = None;
            loop {
                let mut obj = f;
                for (_, a, b) in &pairs {
                    obj += pi * (*a * *b);
                }
                let pb = problem.mpcc_copy(obj, false);
                let phase = label(&phases, "penalty", pi);
                let cb = callback.as_deref_mut();
                let sol = run(solver.as_ref(), &pb, x.as_deref(), cb, phase)?;
                let rep = record(&mut phases, "penalty", pi, &sol)?;
                x = Some(sol.x.clone());
                if stopped(&sol)
                    || (ok(sol.status) && rep.residual <= o.switch_tol)
                    || pi * o.penalty_increase > o.penalty_max
                {
                    break sol;
                }
                pi *= o.penalty_increase;
            }
        }
    };
    // The objective of the original problem at the returned point.
    let f_at = |x: &[f64]| -> Result<f64, MpccError> { Ok(problem.evaluate(&[f], x)?[0]) };
    best.objective = f_at(&best.x)?;
    // ---- exact final phase ----
    if o.exact_final_phase && !pairs.is_empty() && !stopped(&best) {
        let vals = problem.evaluate(
            &pairs
                .iter()
                .flat_map(|(_, a, b)| [*a, *b])
                .collect::<Vec<Expr>>(),
            &best.x,
        )?;
        let mut pb = problem.mpcc_copy(f, false);
        for (k, (name, a, b)) in pairs.iter().enumerate() {
            let side = if vals[2 * k] <= vals[2 * k + 1] {
                *a
            } else {
                *b
            };
            pb.subject_to_named(&format!("{name}.branch"), side.eq(0.0))?;
        }
        let phase = label(&phases, "final", 0.0);
        let sol = run(solver.as_ref(), &pb, Some(&best.x), callback, phase)?;
        record(&mut phases, "final", 0.0, &sol)?;
        if ok(sol.status) || stopped(&sol) {
            best = sol;
        }
    }
    let report = problem.complementarity_report(&best.x, o.biactive_tol)?;
    Ok(MpccSolution {
        iterations: phases.iter().map(|p| p.iterations).sum(),
        solution: best,
        report,
        phases,
        seconds: t.elapsed().as_secs_f64(),
    })
}
