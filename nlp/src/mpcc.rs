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
//! **One budget.** [`MpccOptions::max_iter`] and [`MpccOptions::max_wall_time`] bound the
//! whole run: each phase's solver gets the smaller of its own limit and what is left, and
//! no phase starts once the budget is spent ([`MpccSolution::budget_exhausted`]).
//!
//! **Compiled once per structure.** The penalty phases share one compiled problem whose
//! π is a parameter (`mpcc.penalty`), so only the final phase (other rows) compiles again.
//!
//! The result reports the complementarity residual and the biactive pairs
//! ([`ComplementarityReport`]), every phase, and whether the final phase rescued a failed
//! earlier phase ([`MpccSolution::rescue`], [`MpccSolution::summary`]).
//! [`solve_mpcc_with_callback`] forwards an iteration callback to every phase's solve,
//! labelling each iteration with its phase.
//!
//! Options can be set by name ([`MpccOptions::set_options_by_name`]): the driver's own
//! (`penalty_init=100`) and either back end's with a prefix (`ipm.tol=1e-10`,
//! `sqp.max_iter=50`).

use std::ops::ControlFlow;
use std::time::Instant;

use symx::Expr;
use thiserror::Error;

use crate::callback::{IterationCallback, IterationView, PhaseLabel};
use crate::compiled::Compiled;
use crate::constraint::Relation;
use crate::error::SolveError;
use crate::frontend::{Solver, SolverOptions};
use crate::option_names::{NamedOptions, OptionError};
use crate::options::IpmOptions;
use crate::problem::{BuildError, ComplementarityReport, Problem};
use crate::solution::{Solution, Status};
use crate::sqp::SqpOptions;

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
    /// Options of the SQP back end (default: [`SqpOptions::default`] with
    /// `cold_start_ipm` off: the SQP phase's problem has no strict interior).
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
    /// Iterations over all phases together. Default 6000: twice a back end's own default
    /// `max_iter`, so that a main phase that exhausts its own 3000 still leaves the exact
    /// final phase its chance to rescue the point.
    pub max_iter: usize,
    /// Wall-clock seconds over all phases together. Default 1e20 (none).
    pub max_wall_time: f64,
}

/// The driver's own options as set by name (the fields of [`MpccOptions`] but the two
/// back ends' options).
#[derive(serde::Serialize, serde::Deserialize)]
struct DriverOptions {
    penalty_init: f64,
    penalty_increase: f64,
    penalty_max: f64,
    switch_tol: f64,
    exact_final_phase: bool,
    biactive_tol: f64,
    max_iter: usize,
    max_wall_time: f64,
}

impl NamedOptions for DriverOptions {
    fn check(&self) -> Result<(), SolveError> {
        let bad = |field: &'static str, reason: &str| {
            Err(SolveError::InvalidOption {
                field,
                reason: reason.to_string(),
            })
        };
        let positive = [
            ("penalty_init", self.penalty_init),
            ("penalty_max", self.penalty_max),
            ("switch_tol", self.switch_tol),
            ("biactive_tol", self.biactive_tol),
            ("max_wall_time", self.max_wall_time),
        ];
        for (field, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return bad(field, &format!("must be finite and > 0, got {v}"));
            }
        }
        if !(self.penalty_increase.is_finite() && self.penalty_increase > 1.0) {
            return bad(
                "penalty_increase",
                &format!("must be finite and > 1, got {}", self.penalty_increase),
            );
        }
        if self.penalty_max < self.penalty_init {
            return bad(
                "penalty_max",
                &format!(
                    "must be >= penalty_init = {}, got {}",
                    self.penalty_init, self.penalty_max
                ),
            );
        }
        if self.max_iter == 0 {
            return bad("max_iter", "must be at least 1");
        }
        Ok(())
    }
}

impl MpccOptions {
    /// The options of `backend`, behind the interface both back ends' options share.
    pub fn backend_options(&self, backend: MpccBackend) -> Box<dyn SolverOptions> {
        match backend {
            MpccBackend::Sqp => Box::new(self.sqp.clone()),
            MpccBackend::Ipm => Box::new(self.ipm.clone()),
        }
    }

    /// The solver of `backend` with its options.
    pub fn solver(&self, backend: MpccBackend) -> Box<dyn Solver> {
        self.backend_options(backend).solver()
    }

    /// Checks the driver's options and both back ends'; the error names the first bad one.
    pub fn validate(&self) -> Result<(), SolveError> {
        self.driver().check()?;
        self.ipm.check()?;
        self.sqp.check()
    }

    /// Applies `KEY=VALUE` assignments in order: the driver's own options by their field
    /// names (`penalty_init=100`, `max_iter=500`), a back end's with its prefix
    /// (`ipm.tol=1e-10`, `sqp.max_iter=50`). On any error nothing changes and the error
    /// names the option.
    /// ```
    /// use nlp::MpccOptions;
    /// let mut o = MpccOptions::default();
    /// o.set_options_by_name(&["penalty_init=100", "ipm.tol=1e-10", "sqp.max_iter=50"]).unwrap();
    /// assert_eq!((o.penalty_init, o.ipm.tol, o.sqp.max_iter), (100.0, 1e-10, 50));
    /// let err = o.set_options_by_name(&["penalty_inti=5"]).unwrap_err();
    /// assert!(err.to_string().contains("did you mean 'penalty_init'"), "{err}");
    /// ```
    pub fn set_options_by_name(&mut self, assignments: &[&str]) -> Result<(), OptionError> {
        let (mut own, mut ipm, mut sqp) = (Vec::new(), Vec::new(), Vec::new());
        for &a in assignments {
            if let Some(rest) = a.trim_start().strip_prefix("ipm.") {
                ipm.push(rest);
            } else if let Some(rest) = a.trim_start().strip_prefix("sqp.") {
                sqp.push(rest);
            } else {
                own.push(a);
            }
        }
        let mut new = self.clone();
        let mut driver = new.driver();
        driver.set_by_name(&own)?;
        new.ipm.set_by_name(&ipm)?;
        new.sqp.set_by_name(&sqp)?;
        new.set_driver(driver);
        *self = new;
        Ok(())
    }

    fn driver(&self) -> DriverOptions {
        DriverOptions {
            penalty_init: self.penalty_init,
            penalty_increase: self.penalty_increase,
            penalty_max: self.penalty_max,
            switch_tol: self.switch_tol,
            exact_final_phase: self.exact_final_phase,
            biactive_tol: self.biactive_tol,
            max_iter: self.max_iter,
            max_wall_time: self.max_wall_time,
        }
    }

    fn set_driver(&mut self, d: DriverOptions) {
        self.penalty_init = d.penalty_init;
        self.penalty_increase = d.penalty_increase;
        self.penalty_max = d.penalty_max;
        self.switch_tol = d.switch_tol;
        self.exact_final_phase = d.exact_final_phase;
        self.biactive_tol = d.biactive_tol;
        self.max_iter = d.max_iter;
        self.max_wall_time = d.max_wall_time;
    }
}

impl Default for MpccOptions {
    fn default() -> Self {
        MpccOptions {
            // The SQP phase's problem (the products as constraints) has no strict interior
            // and fails MFCQ everywhere: the IPM is no start for it, the SQP runs alone.
            sqp: SqpOptions {
                cold_start_ipm: false,
                ..SqpOptions::default()
            },
            ipm: IpmOptions::default(),
            penalty_init: 10.0,
            penalty_increase: 10.0,
            penalty_max: 1e8,
            switch_tol: 1e-6,
            exact_final_phase: true,
            biactive_tol: 1e-6,
            max_iter: 6000,
            max_wall_time: 1e20,
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

/// A failed phase whose point a later phase turned into a solution: the final phase
/// solved the branch problem from a main phase that stopped without converging.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Rescue {
    /// Index in [`MpccSolution::phases`] of the last failed phase before the rescue.
    pub failed_phase: usize,
    /// Its status.
    pub failed_status: Status,
    /// Index of the phase that succeeded from its point.
    pub rescued_by: usize,
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
    /// Set when the main phase failed and the final phase succeeded from its point: the
    /// solution is a KKT point of the branch problem, reached only through the rescue.
    pub rescue: Option<Rescue>,
    /// The run ended because [`MpccOptions::max_iter`] or [`MpccOptions::max_wall_time`]
    /// was spent (a phase hit its share, or a phase could not start).
    pub budget_exhausted: bool,
}

impl MpccSolution {
    /// One line per phase and a last line saying how the run ended, e.g.
    /// `sqp: MaximumIterationsExceeded, 3000 iterations` … `final phase rescued a failed
    /// sqp phase (MaximumIterationsExceeded)`.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        for p in &self.phases {
            let pi = if p.kind == "penalty" {
                format!(" (pi = {:e})", p.penalty)
            } else {
                String::new()
            };
            out += &format!(
                "{}{pi}: {:?}, {} iterations, residual {:.1e}\n",
                p.kind, p.status, p.iterations, p.residual
            );
        }
        out += &match (self.rescue, self.budget_exhausted) {
            (Some(r), _) => format!(
                "{:?}: the final phase rescued a failed {} phase ({:?})",
                self.solution.status, self.phases[r.failed_phase].kind, r.failed_status
            ),
            (None, true) => format!(
                "{:?}: the budget of {} iterations over all phases was spent",
                self.solution.status, self.iterations
            ),
            (None, false) => format!("{:?}", self.solution.status),
        };
        out
    }
}

/// Errors of [`solve_mpcc`].
#[derive(Debug, Error)]
pub enum MpccError {
    #[error("building a phase problem: {0}")]
    Build(#[from] BuildError),
    #[error("solver: {0}")]
    Solve(#[from] SolveError),
}

/// The name of the penalty parameter π in the penalty phases' problem.
const PENALTY_PARAMETER: &str = "mpcc.penalty";

/// What is left of the run's budget, and the phase solvers it limits.
struct Budget<'a> {
    options: &'a MpccOptions,
    backend: MpccBackend,
    start: Instant,
    used: usize,
}

impl Budget<'_> {
    /// The back end's solver limited to what is left, or `None` when nothing is left.
    fn solver(&self) -> Option<Box<dyn Solver>> {
        let iters = self.options.max_iter.saturating_sub(self.used);
        let secs = self.options.max_wall_time - self.start.elapsed().as_secs_f64();
        (iters > 0 && secs > 0.0).then(|| self.limited(iters, secs))
    }

    /// The solver of the first phase, which always runs (with the least positive time
    /// when compiling already spent the budget, so that it reports the limit itself).
    fn first_solver(&self) -> Box<dyn Solver> {
        let secs = self.options.max_wall_time - self.start.elapsed().as_secs_f64();
        self.limited(self.options.max_iter, secs.max(f64::MIN_POSITIVE))
    }

    fn limited(&self, iters: usize, secs: f64) -> Box<dyn Solver> {
        let mut o = self.options.backend_options(self.backend);
        let c = &mut **o;
        c.max_iter = c.max_iter.min(iters);
        c.max_wall_time = c.max_wall_time.min(secs);
        o.solver()
    }

    /// Whether `sol` stopped on a limit the run's budget (not the back end's own) set.
    fn spent_by(&self, sol: &Solution) -> bool {
        match sol.status {
            Status::MaximumIterationsExceeded => self.used >= self.options.max_iter,
            Status::MaximumWallTimeExceeded => {
                self.start.elapsed().as_secs_f64() >= self.options.max_wall_time
            }
            _ => false,
        }
    }
}

fn run(
    solver: &dyn Solver,
    c: &mut Compiled,
    x0: Option<&[f64]>,
    callback: Option<&mut IterationCallback<'_>>,
    phase: PhaseLabel,
) -> Result<Solution, MpccError> {
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
    Ok(solver.solve_dyn(c, None, cb)?)
}

fn ok(s: Status) -> bool {
    matches!(s, Status::SolveSucceeded | Status::SolvedToAcceptableLevel)
}

/// Whether the user's callback stopped the phase that returned `sol`.
fn stopped(sol: &Solution) -> bool {
    sol.status == Status::UserRequestedStop
}

/// The phases run so far, each recorded with its complementarity residual.
struct Phases<'p> {
    problem: &'p Problem,
    biactive_tol: f64,
    list: Vec<MpccPhase>,
}

impl Phases<'_> {
    /// Records the phase of `kind` (penalty π `penalty`) that returned `sol`; its
    /// complementarity report.
    fn record(
        &mut self,
        kind: &'static str,
        penalty: f64,
        sol: &Solution,
    ) -> Result<ComplementarityReport, MpccError> {
        let rep = self
            .problem
            .complementarity_report(&sol.x, self.biactive_tol)?;
        self.list.push(MpccPhase {
            kind,
            penalty,
            status: sol.status,
            iterations: sol.stats.iterations,
            objective: sol.objective,
            residual: rep.residual,
        });
        Ok(rep)
    }

    /// The callback's label of the next phase.
    fn label(&self, kind: &'static str, penalty: f64) -> PhaseLabel {
        PhaseLabel {
            index: self.list.len(),
            kind,
            penalty,
        }
    }
}

/// The SQP back end's one main phase (products as constraints): its solution and
/// whether it spent the budget.
fn sqp_phase(
    problem: &Problem,
    budget: &mut Budget<'_>,
    phases: &mut Phases<'_>,
    callback: Option<&mut IterationCallback<'_>>,
) -> Result<(Solution, bool), MpccError> {
    let mut c = problem.compile()?;
    let solver = budget.first_solver();
    let phase = phases.label("sqp", 0.0);
    let sol = run(solver.as_ref(), &mut c, None, callback, phase)?;
    phases.record("sqp", 0.0, &sol)?;
    budget.used += sol.stats.iterations;
    let spent = budget.spent_by(&sol);
    Ok((sol, spent))
}

/// The IPM back end's penalty phases: f + π·Σ aᵢbᵢ with π a parameter (one
/// compilation for every π), raised until the complementarity residual is at most
/// `switch_tol`, π would pass `penalty_max`, or the budget is spent. The last phase's
/// solution and whether it spent the budget.
fn penalty_phases(
    problem: &Problem,
    budget: &mut Budget<'_>,
    phases: &mut Phases<'_>,
    mut callback: Option<&mut IterationCallback<'_>>,
) -> Result<(Solution, bool), MpccError> {
    let o = budget.options;
    let f = problem.objective();
    let mut pb = problem.mpcc_copy(f, false);
    let pi_param = pb.parameter(PENALTY_PARAMETER, 1)?[0];
    let mut obj = f;
    for (_, a, b) in problem.complementarity_pairs() {
        obj += pi_param * (*a * *b);
    }
    pb.minimize(obj);
    let mut pi = o.penalty_init;
    pb.set_value(PENALTY_PARAMETER, &[pi])?;
    let mut c = pb.compile()?;
    let mut x: Option<Vec<f64>> = None;
    let mut last: Option<Solution> = None;
    loop {
        let solver = match &last {
            None => budget.first_solver(),
            Some(_) => match budget.solver() {
                Some(solver) => solver,
                None => return Ok((last.take().expect("matched Some"), true)),
            },
        };
        c.set_value(PENALTY_PARAMETER, &[pi])?;
        let phase = phases.label("penalty", pi);
        let cb = callback.as_deref_mut();
        let sol = run(solver.as_ref(), &mut c, x.as_deref(), cb, phase)?;
        let rep = phases.record("penalty", pi, &sol)?;
        budget.used += sol.stats.iterations;
        x = Some(sol.x.clone());
        if budget.spent_by(&sol) {
            return Ok((sol, true));
        }
        if stopped(&sol)
            || (ok(sol.status) && rep.residual <= o.switch_tol)
            || pi * o.penalty_increase > o.penalty_max
        {
            return Ok((sol, false));
        }
        pi *= o.penalty_increase;
        last = Some(sol);
    }
}

/// The exact final phase from `x`: every pair's branch fixed (the side smaller at `x`
/// set to zero) and the problem solved again.
fn final_phase(
    problem: &Problem,
    solver: &dyn Solver,
    x: &[f64],
    callback: Option<&mut IterationCallback<'_>>,
    phases: &mut Phases<'_>,
) -> Result<Solution, MpccError> {
    let pairs = problem.complementarity_pairs();
    let sides: Vec<Expr> = pairs.iter().flat_map(|(_, a, b)| [*a, *b]).collect();
    let vals = problem.evaluate(&sides, x)?;
    let mut pb = problem.mpcc_copy(problem.objective(), false);
    for (k, (name, a, b)) in pairs.iter().enumerate() {
        let side = if vals[2 * k] <= vals[2 * k + 1] {
            *a
        } else {
            *b
        };
        pb.subject_to_named(&format!("{name}.branch"), side.eq(0.0))?;
    }
    let mut c = pb.compile()?;
    let phase = phases.label("final", 0.0);
    let sol = run(solver, &mut c, Some(x), callback, phase)?;
    phases.record("final", 0.0, &sol)?;
    Ok(sol)
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
/// [`Ipm::solve_with_callback`](crate::Ipm::solve_with_callback));
/// [`IterationView::phase`] tells which phase an iteration belongs to. [`ControlFlow::Break`] ends the whole driver: the stopped phase's point is
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
    // The back end's own options are checked by its solver, the other's not at all.
    options.driver().check()?;
    let o = options;
    let mut budget = Budget {
        options,
        backend,
        start: Instant::now(),
        used: 0,
    };
    let mut phases = Phases {
        problem,
        biactive_tol: o.biactive_tol,
        list: Vec::new(),
    };
    // ---- main phase(s) ----
    let cb = callback.as_deref_mut();
    let (mut best, mut spent) = match backend {
        MpccBackend::Sqp => sqp_phase(problem, &mut budget, &mut phases, cb)?,
        MpccBackend::Ipm => penalty_phases(problem, &mut budget, &mut phases, cb)?,
    };
    // The objective of the original problem at the returned point.
    best.objective = problem.evaluate(&[problem.objective()], &best.x)?[0];
    let main_phase = phases.list.len() - 1;
    let mut rescue = None;
    // ---- exact final phase ----
    if o.exact_final_phase && !problem.complementarity_pairs().is_empty() && !stopped(&best) {
        match budget.solver() {
            None => spent = true,
            Some(solver) => {
                let sol = final_phase(problem, solver.as_ref(), &best.x, callback, &mut phases)?;
                budget.used += sol.stats.iterations;
                let failed_status = phases.list[main_phase].status;
                if ok(sol.status) && !ok(failed_status) {
                    rescue = Some(Rescue {
                        failed_phase: main_phase,
                        failed_status,
                        rescued_by: phases.list.len() - 1,
                    });
                }
                if ok(sol.status) || stopped(&sol) {
                    best = sol;
                } else {
                    spent |= budget.spent_by(&sol);
                }
            }
        }
    }
    let phases = phases.list;
    let report = problem.complementarity_report(&best.x, o.biactive_tol)?;
    Ok(MpccSolution {
        iterations: budget.used,
        solution: best,
        report,
        phases,
        seconds: budget.start.elapsed().as_secs_f64(),
        rescue,
        budget_exhausted: spent,
    })
}
