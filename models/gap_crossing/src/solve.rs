//! From a scenario to a checked-ready plan: guess, build, compile, solve, read back.
//!
//! - `crawl` gait: one solve of the scheduled problem (order BR, FR, BL, FL), from the
//!   crawl-gait heuristic.
//! - `free` gait: every returned plan satisfies (10) exactly (non-moving feet share
//!   variables), and is the better of two candidates:
//!   1. the crawl schedule, solved as above;
//!   2. the schedule chosen by the optimiser: the lifted complementarity problem
//!      ([`Formulation::Complementarity`]) is solved from candidate 1 with the exact
//!      penalty `π` ([`PENALTIES`], raised until `Σ_{i<j} s_i s_j` ≤
//!      [`COMPLEMENTARITY_TOL`]); the foot that moves most at each transition gives a
//!      schedule, which is solved exactly from a consistent warm start
//!      ([`scheduled_guess`]) unless it is the crawl schedule again.
//!
//!   So the free gait is never worse than the crawl gait, and its complementarity is
//!   exact rather than approximate.
use crate::convergence::ResidualProbe;
use crate::gait;
use crate::model::{self, Formulation, ModelError, PENALTY};
use crate::plan::{foot_offset, Plan, PlanError, SolutionFile, SolverInfo};
use crate::scenario::{Foot, Gait, Scenario};
use crate::terrain::{GapTerrain, Terrain};
use nlp::ipm::Ipm;
use nlp::{
    BuildError, IpmOptions, IterationRecord, IterationView, NumericNlp, Solution, SolveError, Sqp,
    SqpOptions, Status,
};
use std::ops::ControlFlow;
use std::time::Instant;

/// Complementarity residual below which the free gait's first phase stops raising `π`.
pub const COMPLEMENTARITY_TOL: f64 = 1e-10;

/// Penalty values tried in turn by the free gait's complementarity phase. Starting from
/// the (complementary) crawl solution, one large value keeps the iterates near
/// complementary points; small values let several feet move at once, and raising `π`
/// afterwards did not recover a better complementary plan in our runs.
pub const PENALTIES: [f64; 1] = [1e8];

/// Iteration budget of the SQP back end on the step-choosing (penalised) run. That run
/// does not converge with the SQP (3000 iterations, ≈ 9 min at n_step 60, see
/// docs/gap-crossing.md); past this budget the planner keeps the crawl-schedule plan, as
/// it does whenever the step-choosing run fails. The IPM solves it in about 140
/// iterations and is not capped.
pub const SQP_CHOOSE_MAX_ITER: usize = 300;

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

    fn print_level(&self) -> u8 {
        match self.backend {
            Backend::Ipm => self.ipm.print_level,
            Backend::Sqp => self.sqp.print_level,
        }
    }

    fn solve(
        &self,
        nlp: &mut dyn NumericNlp,
        callback: impl FnMut(&IterationView<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError> {
        match self.backend {
            Backend::Ipm => Ipm::new(self.ipm.clone()).solve_with_callback(nlp, callback),
            Backend::Sqp => Sqp::new(self.sqp.clone()).solve_with_callback(nlp, callback),
        }
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

/// (10) residual under which the complementarity phase's point warm-starts the exact
/// phase as it is.
pub const NEARLY_COMPLEMENTARY: f64 = 1e-4;

/// Squared move (m²) below which a transition counts as "no foot moves" when reading a
/// schedule off a plan: 1e-6 m², a millimetre.
pub const NEGLIGIBLE_MOVE_SQ: f64 = 1e-6;

/// The foot that moves most at each transition of a flat plan; where no foot moves more
/// than [`NEGLIGIBLE_MOVE_SQ`], the `fallback` schedule's foot (any foot would do).
pub fn schedule_of(s: &Scenario, x: &[f64], fallback: &[Foot]) -> Vec<Foot> {
    (1..s.n_step)
        .map(|k| {
            let (foot, moved) = Foot::ALL
                .into_iter()
                .map(|i| (i, step_sq(x, k, i)))
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap_or((Foot::BR, 0.0));
            if moved > NEGLIGIBLE_MOVE_SQ {
                foot
            } else {
                fallback[k - 1]
            }
        })
        .collect()
}

/// A warm start for the scheduled problem with `schedule` built from a free-gait plan
/// `flat`: at each transition only the scheduled foot moves, toward where `flat` has it,
/// at most [`gait::CRAWL_MAX_MOVE`] in x–y, never into a keep-out zone, on the terrain;
/// CoMs and forces are rebuilt to fit ([`gait::plan_for_footholds`]).
pub fn scheduled_guess(
    s: &Scenario,
    terrain: &dyn Terrain,
    flat: &[f64],
    schedule: &[Foot],
) -> Vec<f64> {
    let mut feet = s.start.feet;
    let mut footholds = vec![feet];
    for (t, &i) in schedule.iter().enumerate() {
        let k = t + 1;
        let cur = feet.get(i);
        let o = foot_offset(k, i);
        let (dx, dy) = (flat[o] - cur[0], flat[o + 1] - cur[1]);
        let dist = dx.hypot(dy);
        let scale = if dist > gait::CRAWL_MAX_MOVE {
            gait::CRAWL_MAX_MOVE / dist
        } else {
            1.0
        };
        let mut x = cur[0] + dx * scale;
        let y = cur[1] + dy * scale;
        for (lo, hi) in terrain.keep_out() {
            if x > lo && x < hi {
                // Stay on the side the foot comes from.
                x = if cur[0] <= lo {
                    lo - gait::GAP_CLEARANCE
                } else {
                    hi + gait::GAP_CLEARANCE
                };
            }
        }
        *feet.get_mut(i) = [x, y, terrain.height_at(x, y)];
        footholds.push(feet);
    }
    gait::plan_for_footholds(s, &footholds).to_flat()
}

#[derive(Clone)]
struct Run {
    solution: Solution,
    flat: Vec<f64>,
    /// Index of its [`Phase`].
    phase: usize,
}

fn run(
    s: &Scenario,
    terrain: &dyn Terrain,
    formulation: &Formulation,
    guess: &[f64],
    settings: &Settings,
    phases: &mut Vec<Phase>,
    name: &str,
) -> Result<Run, PlanningError> {
    if settings.print_level() > 0 {
        println!("\n== {name}");
    }
    let model = model::build(s, terrain, formulation, guess)?;
    let mut compiled = model.problem.compile()?;
    let mut probe = ResidualProbe::new(s, &model)?;
    let mut settings = settings.clone();
    if model.has_penalty && settings.backend == Backend::Sqp {
        settings.sqp.max_iter = settings.sqp.max_iter.min(SQP_CHOOSE_MAX_ITER);
    }
    let penalties: &[f64] = if model.has_penalty {
        &PENALTIES
    } else {
        &[0.0]
    };
    let mut last: Option<Run> = None;
    let mut best: Option<Run> = None;
    for &penalty in penalties {
        if model.has_penalty {
            compiled.set_parameter(PENALTY, &[penalty])?;
        }
        if let Some(prev) = &last {
            compiled.set_initial_point(&prev.solution.x)?;
        }
        let mut residuals = Vec::new();
        let solution = settings.solve(&mut compiled, |v| {
            residuals.push(probe.at(v.x()));
            ControlFlow::Continue(())
        })?;
        let flat = model.problem.evaluate(&model.layout, &solution.x)?;
        let complementarity = complementarity_residual(s, &flat);
        phases.push(Phase {
            name: if model.has_penalty {
                format!("{name}, penalty {penalty:e}")
            } else {
                name.to_string()
            },
            status: solution.status,
            iterations: solution.stats.iterations,
            records: solution.stats.records.clone(),
            residuals,
            scheduled: matches!(formulation, Formulation::Scheduled(_)),
            complementarity,
        });
        let success = solution.status.is_success();
        let done = !success || complementarity <= COMPLEMENTARITY_TOL;
        let this = Run {
            solution,
            flat,
            phase: phases.len() - 1,
        };
        // Keep the successful run with the lowest objective: a larger penalty can only
        // make the choice of steps more conservative.
        if success
            && best
                .as_ref()
                .is_none_or(|b| this.solution.objective < b.solution.objective)
        {
            best = Some(this.clone());
        }
        last = Some(this);
        if done {
            break;
        }
    }
    Ok(best.or(last).expect("at least one penalty is tried"))
}

/// Plans scenario `s` (its `gait` field chooses the formulation) on the spec's gap terrain.
pub fn plan(s: &Scenario, settings: &Settings) -> Result<Outcome, PlanningError> {
    plan_on(s, &GapTerrain { gap: s.gap }, settings)
}

/// Plans scenario `s` on any terrain.
pub fn plan_on(
    s: &Scenario,
    terrain: &dyn Terrain,
    settings: &Settings,
) -> Result<Outcome, PlanningError> {
    let started = Instant::now();
    let mut phases = Vec::new();
    let guess = gait::crawl(s);
    let last = match s.gait {
        Gait::Crawl => {
            let f = Formulation::Scheduled(gait::crawl_schedule(s.n_step));
            run(s, terrain, &f, &guess, settings, &mut phases, "crawl gait")?
        }
        Gait::Free => {
            // Two exact candidates, the better one wins: the crawl schedule, and the
            // schedule chosen by the lifted complementarity problem.
            let crawl = Formulation::Scheduled(gait::crawl_schedule(s.n_step));

            let crawl_run = run(
                s,
                terrain,
                &crawl,
                &guess,
                settings,
                &mut phases,
                "free gait: crawl schedule",
            )?;
            let choice = run(
                s,
                terrain,
                &Formulation::Complementarity,
                &crawl_run.flat,
                settings,
                &mut phases,
                "free gait: choose the steps",
            )?;
            let mut best = crawl_run;
            let crawl_schedule = gait::crawl_schedule(s.n_step);
            let schedule = schedule_of(s, &choice.flat, &crawl_schedule);
            if choice.solution.status.is_success() && schedule != crawl_schedule {
                // A nearly complementary point (non-moving feet displaced by ≲ 1e-2 m) is
                // already a good start; otherwise rebuild a consistent one.
                let nearly = complementarity_residual(s, &choice.flat) <= NEARLY_COMPLEMENTARY;
                let warm = if nearly {
                    choice.flat.clone()
                } else {
                    scheduled_guess(s, terrain, &choice.flat, &schedule)
                };
                let exact = run(
                    s,
                    terrain,
                    &Formulation::Scheduled(schedule),
                    &warm,
                    settings,
                    &mut phases,
                    "free gait: exact steps",
                )?;
                let better = exact.solution.status.is_success()
                    && (!best.solution.status.is_success()
                        || exact.solution.objective < best.solution.objective);
                if better {
                    best = exact;
                }
            }
            best
        }
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
