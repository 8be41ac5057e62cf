//! From a scenario to a checked-ready plan: guess, build, compile, solve, read back.
//!
//! - `crawl` gait: one solve of the scheduled problem (order BR, FR, BL, FL), from the
//!   crawl-gait heuristic.
//! - `free` gait: the optimiser picks which foot moves at each transition, (10). Every
//!   solve is of a scheduled problem (non-moving feet share variables), so (10) holds
//!   exactly in every candidate, and the plan is the best of:
//!   1. the crawl schedule, solved as above (so the free gait is never worse than it);
//!   2. the biped-pair schedule FR, FL, BR, BL ([`gait::PAIR_ORDER`]), solved from the
//!      same heuristic with that order, on a second thread alongside 1;
//!   3. the schedule search ([`crate::schedule_search`]) from the better of 1 and 2:
//!      adjacent swaps of the schedule whose exact per-stance evaluation lowers the
//!      cost, each round re-solved with every variable free from the improved plan,
//!      until no swap improves or [`SEARCH_ROUNDS`] rounds have run.
//!
//!   With the SQP back end, 2 and 3 have an iteration budget ([`SQP_CANDIDATE_MAX_ITER`]).
use crate::convergence::ResidualProbe;
use crate::gait;
use crate::model::{self, Formulation, ModelError};
use crate::plan::{foot_offset, Plan, PlanError, SolutionFile, SolverInfo};
use crate::scenario::{Foot, Gait, Scenario};
use crate::schedule_search::{self, StanceSolver};
use crate::terrain::{GapTerrain, Terrain};
use nlp::ipm::Ipm;
use nlp::{
    BuildError, IpmOptions, IterationRecord, IterationView, NumericNlp, Solution, SolveError,
    Solver, Sqp, SqpOptions, Status,
};
use std::ops::ControlFlow;
use std::time::Instant;

/// Largest number of schedule-search rounds (each: evaluate every adjacent swap, then
/// one solve of the improved schedule) of the free gait.
pub const SEARCH_ROUNDS: usize = 4;

/// Initial barrier parameter of the schedule search's re-solves (default 0.1): on the
/// lateral-goal test scenario, 161 iterations over its rounds instead of 238, same plans.
pub const SEARCH_MU_INIT: f64 = 1e-6;

/// Bound push (absolute and relative, variables and slacks) of the schedule search's
/// re-solves (default 1e-2, which moves a foot on a keep-out edge by 2 cm).
pub const SEARCH_BOUND_PUSH: f64 = 1e-8;

/// Iteration budget of the SQP back end on the free gait's solves other than the crawl
/// schedule (biped-pair schedule, schedule-search re-solves); past it a candidate counts
/// as failed and the planner keeps what it has (the crawl-schedule plan at worst). The
/// SQP did not converge on either in our runs (the pair schedule ran past 9 min
/// uncapped; with 150 iterations each the default free gait took 140 s against 87 s for
/// the previous pipeline, same load). The IPM needs 117 and 17–80 iterations for them
/// and is not capped.
pub const SQP_CANDIDATE_MAX_ITER: usize = 100;

/// Which back end solves the problem.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Backend {
    /// The interior-point method.
    #[default]
    Ipm,
    /// The SQP method (QPs by Clarabel).
    Sqp,
}

/// Options of a planning run.
#[derive(Clone, Debug, Default)]
pub struct Settings {
    /// Solver back end.
    pub backend: Backend,
    /// Interior-point options (tolerances, print level, limits).
    pub ipm: IpmOptions,
    /// SQP options (used with [`Backend::Sqp`]).
    pub sqp: SqpOptions,
}

impl Settings {
    /// Sets the iteration-log verbosity of both back ends.
    pub fn set_print_level(&mut self, level: u8) {
        self.ipm.print_level = level;
        self.sqp.print_level = level;
    }

    /// The settings of a re-solve that starts from a plan satisfying every equation,
    /// close to a local minimum (the schedule search's): the interior-point method
    /// starts with a small barrier parameter and hardly pushes the point off its bounds,
    /// as IPOPT users do for warm starts ([`SEARCH_MU_INIT`], [`SEARCH_BOUND_PUSH`]).
    /// The settings of the free gait's solves other than the crawl schedule: with the
    /// SQP back end, at most [`SQP_CANDIDATE_MAX_ITER`] iterations.
    fn candidate(&self) -> Settings {
        let mut c = self.clone();
        if c.backend == Backend::Sqp {
            c.sqp.max_iter = c.sqp.max_iter.min(SQP_CANDIDATE_MAX_ITER);
        }
        c
    }

    fn warm(&self) -> Settings {
        let mut w = self.clone();
        w.ipm.mu_init = SEARCH_MU_INIT;
        w.ipm.bound_push = SEARCH_BOUND_PUSH;
        w.ipm.bound_frac = SEARCH_BOUND_PUSH;
        w.ipm.slack_bound_push = SEARCH_BOUND_PUSH;
        w.ipm.slack_bound_frac = SEARCH_BOUND_PUSH;
        w
    }

    fn print_level(&self) -> u8 {
        match self.backend {
            Backend::Ipm => self.ipm.print_level,
            Backend::Sqp => self.sqp.print_level,
        }
    }

    /// The chosen back end with its options.
    pub fn solver(&self) -> Box<dyn Solver> {
        match self.backend {
            Backend::Ipm => Box::new(Ipm::new(self.ipm.clone())),
            Backend::Sqp => Box::new(Sqp::new(self.sqp.clone())),
        }
    }

    fn solve(
        &self,
        nlp: &mut dyn NumericNlp,
        mut callback: impl FnMut(&IterationView<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError> {
        self.solver().solve_with_callback(nlp, &mut callback)
    }
}

/// One solver run within a plan's solve (the free gait has several).
#[derive(Clone, Debug)]
pub struct Phase {
    /// What this run solved.
    pub name: String,
    /// The solver's status.
    pub status: Status,
    /// The solver's iteration count (restoration iterations included).
    pub iterations: usize,
    /// Iteration records, IPOPT columns: `iterations + 1` rows, plus the starting row of
    /// each restoration phase.
    pub records: Vec<IterationRecord>,
    /// Residual of (10) at each iterate, one per record ([`complementarity_residual`]
    /// of the iterate, recorded by the solver's iteration callback).
    pub residuals: Vec<f64>,
    /// The run had a fixed foot schedule ([`Formulation::Scheduled`]): (10) holds by
    /// construction, every residual is exactly 0.
    pub scheduled: bool,
    /// Residual of (10) at the end of the run: max over transitions of `Σ_{i<j} ‖Δr_i‖²‖Δr_j‖²`.
    pub complementarity: f64,
}

/// The result of planning.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The solution file (the spec's schema).
    pub file: SolutionFile,
    /// The solver runs, in order.
    pub phases: Vec<Phase>,
    /// Index in `phases` of the run whose solution is the plan.
    pub chosen: usize,
}

/// What can stop a planning run (a failed solve is an `Outcome` with a failing status).
#[derive(Debug, thiserror::Error)]
pub enum PlanningError {
    #[error("building the model: {0}")]
    Model(#[from] ModelError),
    #[error("compiling the model: {0}")]
    Build(#[from] BuildError),
    #[error("solver input: {0}")]
    Solve(#[from] SolveError),
    #[error("reading the plan: {0}")]
    Plan(#[from] PlanError),
}

/// Residual of (10) for a flat plan: the largest `Σ_{i<j} ‖Δr_i‖²‖Δr_j‖²` over transitions.
pub fn complementarity_residual(s: &Scenario, x: &[f64]) -> f64 {
    (1..s.n_step)
        .map(|k| {
            let d = Foot::ALL.map(|i| step_sq(x, k, i));
            let mut r = 0.0;
            for a in 0..4 {
                for b in a + 1..4 {
                    r += d[a] * d[b];
                }
            }
            r
        })
        .fold(0.0, f64::max)
}

fn step_sq(x: &[f64], k: usize, i: Foot) -> f64 {
    let (a, b) = (foot_offset(k - 1, i), foot_offset(k, i));
    (0..3).map(|d| (x[b + d] - x[a + d]).powi(2)).sum()
}

/// A solved candidate of the plan.
struct Run {
    solution: Solution,
    flat: Vec<f64>,
    schedule: Vec<Foot>,
    /// Index of its [`Phase`].
    phase: usize,
}

impl Run {
    /// Whether this run succeeded with a lower objective than `other` (or `other` failed).
    fn beats(&self, other: &Run) -> bool {
        self.solution.status.is_success()
            && (!other.solution.status.is_success()
                || self.solution.objective < other.solution.objective)
    }
}

/// One scheduled solve, not yet recorded: what [`solve_scheduled`] returns, so that
/// independent solves can run on separate threads and be logged in a fixed order.
struct Solved {
    name: String,
    run: Run,
    phase: Phase,
}

/// Solves the scheduled problem with `schedule` from `guess` (which also fixes the sides
/// of the keep-out zones, see [`model::build`]). Prints nothing: the solver's log is
/// printed by [`record`], from the iteration records.
fn solve_scheduled(
    s: &Scenario,
    terrain: &dyn Terrain,
    schedule: &[Foot],
    guess: &[f64],
    settings: &Settings,
    name: &str,
) -> Result<Solved, PlanningError> {
    let formulation = Formulation::Scheduled(schedule.to_vec());
    let model = model::build(s, terrain, &formulation, guess)?;
    let mut compiled = model.problem.compile()?;
    let mut probe = ResidualProbe::new(s, &model)?;
    let mut residuals = Vec::new();
    let mut quiet = settings.clone();
    quiet.set_print_level(0);
    let solution = quiet.solve(&mut compiled, |v| {
        residuals.push(probe.at(v.x()));
        ControlFlow::Continue(())
    })?;
    let flat = model.problem.evaluate(&model.layout, &solution.x)?;
    let phase = Phase {
        name: name.to_string(),
        status: solution.status,
        iterations: solution.stats.iterations,
        records: solution.stats.records.clone(),
        residuals,
        scheduled: true,
        complementarity: complementarity_residual(s, &flat),
    };
    Ok(Solved {
        name: name.to_string(),
        run: Run {
            solution,
            flat,
            schedule: schedule.to_vec(),
            phase: 0,
        },
        phase,
    })
}

/// Appends a solve's [`Phase`] and prints its log (at the settings' print level: the
/// iteration table from 5, the summary from 3).
fn record(solved: Solved, settings: &Settings, phases: &mut Vec<Phase>) -> Run {
    let level = settings.print_level();
    if level > 0 {
        println!("\n== {}", solved.name);
    }
    if level >= 5 {
        print!("{}", nlp::format_table(&solved.phase.records));
    }
    if level >= 3 {
        print!("{}", nlp::format_summary(&solved.run.solution));
    }
    phases.push(solved.phase);
    Run {
        phase: phases.len() - 1,
        ..solved.run
    }
}

/// [`solve_scheduled`] then [`record`].
fn run(
    s: &Scenario,
    terrain: &dyn Terrain,
    schedule: &[Foot],
    guess: &[f64],
    settings: &Settings,
    phases: &mut Vec<Phase>,
    name: &str,
) -> Result<Run, PlanningError> {
    let solved = solve_scheduled(s, terrain, schedule, guess, settings, name)?;
    Ok(record(solved, settings, phases))
}

/// Plans scenario `s` (its `gait` field chooses the formulation) on the spec's gap terrain.
pub fn plan(s: &Scenario, settings: &Settings) -> Result<Outcome, PlanningError> {
    plan_on(s, &GapTerrain { gap: s.gap }, settings)
}

/// Plans scenario `s` on any terrain.
pub fn plan_on(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    settings: &Settings,
) -> Result<Outcome, PlanningError> {
    let started = Instant::now();
    let mut phases = Vec::new();
    let crawl = gait::crawl_schedule(s.n_step);
    let guess = gait::crawl(s);
    let last = match s.gait {
        Gait::Crawl => run(
            s,
            terrain,
            &crawl,
            &guess,
            settings,
            &mut phases,
            "crawl gait",
        )?,
        Gait::Free => free_gait(s, terrain, settings, &mut phases)?,
    };
    let plan = Plan::from_flat(s, &last.flat)?;
    let solver = SolverInfo {
        name: match settings.backend {
            Backend::Ipm => "ipm",
            Backend::Sqp => "sqp",
        }
        .into(),
        status: status_name(last.solution.status).into(),
        iterations: phases.iter().map(|p| p.iterations).sum(),
        objective: plan.cost(s),
        max_constraint_violation: last.solution.constr_viol,
        solve_seconds: started.elapsed().as_secs_f64(),
    };
    Ok(Outcome {
        file: SolutionFile::new(s.clone(), solver, plan),
        phases,
        chosen: last.phase,
    })
}

/// The free gait (see the module docs): the best of the crawl schedule, the biped-pair
/// schedule and the schedule search from the better of the two.
fn free_gait(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    settings: &Settings,
    phases: &mut Vec<Phase>,
) -> Result<Run, PlanningError> {
    // The two starting schedules are independent: solved on two threads.
    let crawl = gait::crawl_schedule(s.n_step);
    let pair = gait::pair_schedule(s.n_step);
    let candidate = settings.candidate();
    let (crawl_run, pair_run) = rayon::join(
        || {
            let guess = gait::crawl(s);
            solve_scheduled(
                s,
                terrain,
                &crawl,
                &guess,
                settings,
                "free gait: crawl schedule",
            )
        },
        || {
            let footholds = gait::footholds_for_schedule(s, &pair);
            let guess = gait::plan_for_footholds(s, &footholds).to_flat();
            solve_scheduled(
                s,
                terrain,
                &pair,
                &guess,
                &candidate,
                "free gait: biped-pair schedule",
            )
        },
    );
    let mut best = record(crawl_run?, settings, phases);
    let pair_run = record(pair_run?, settings, phases);
    if pair_run.beats(&best) {
        best = pair_run;
    }
    if !best.solution.status.is_success() {
        return Ok(best);
    }
    // Schedule search from the better plan: each round's proposal satisfies every
    // equation of its schedule with a lower cost; the re-solve frees every variable.
    let search_settings = candidate.warm();
    let mut stance_solver = StanceSolver::new(s, terrain)?;
    for round in 1..=SEARCH_ROUNDS {
        let current = Plan::from_flat(s, &best.flat)?;
        let Some(proposal) =
            schedule_search::propose(s, &mut stance_solver, &current, &best.schedule)
        else {
            break;
        };
        let next = run(
            s,
            terrain,
            &proposal.schedule,
            &proposal.plan.to_flat(),
            &search_settings,
            phases,
            &format!(
                "free gait: schedule search {round} ({} swap{})",
                proposal.swaps,
                if proposal.swaps == 1 { "" } else { "s" }
            ),
        )?;
        if !next.beats(&best) {
            break;
        }
        best = next;
    }
    Ok(best)
}

/// The status word written to the solution file (`solved` for success).
pub fn status_name(status: Status) -> &'static str {
    match status {
        Status::SolveSucceeded => "solved",
        Status::SolvedToAcceptableLevel => "solved_to_acceptable_level",
        Status::InfeasibleProblemDetected => "local_infeasibility",
        Status::RestorationFailed => "restoration_failed",
        Status::MaximumIterationsExceeded => "maximum_iterations_exceeded",
        Status::MaximumWallTimeExceeded => "maximum_wall_time_exceeded",
        Status::DivergingIterates => "diverging_iterates",
        Status::InvalidNumberDetected => "invalid_number_detected",
        _ => "failed",
    }
}
