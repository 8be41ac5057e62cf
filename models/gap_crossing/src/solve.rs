//! From a scenario to a checked-ready plan: guess, build, compile, solve, read back,
//! and the verdict ([`decide`]: solved, or why not, as a [`PlanStatus`]).
//!
//! - `crawl` gait: one solve of the scheduled problem (order BR, FR, BL, FL), from the
//!   crawl-gait heuristic's footholds with each stance's least-cost CoMs and forces
//!   (`solve_from_footholds`), then the crossing search.
//! - `free` gait: the optimiser picks which foot moves at each transition, (10). Every
//!   solve is of a scheduled problem (non-moving feet share variables), so (10) holds
//!   exactly in every candidate, and the plan is the best of:
//!   1. the crawl schedule, solved as above (so the free gait is never worse than it);
//!   2. the biped-pair schedule FR, FL, BR, BL ([`gait::PAIR_ORDER`]), solved from the
//!      same heuristic with that order, on a second thread alongside 1;
//!   3. the crossing search ([`crate::crossing`], [`CROSSING_ROUNDS`] rounds) from the
//!      better of 1 and 2, which the crawl gait also runs after its solve; then
//!   4. the schedule search ([`crate::schedule_search`]) from the crossing search's
//!      result and from the other plan of 1 and 2: the cheapest schedule in a band of
//!      foothold counts around the current one (exact per-stance evaluation), each
//!      round re-solved with every variable free from the improved plan, until nothing
//!      improves or [`SEARCH_ROUNDS`] rounds have run; a re-solve that stalls
//!      ([`STALL_ITERATIONS`]) counts as failed.
//!
//!   Independent solves share the threads (rayon): 1 ‖ 2; then three chains, 3 → 4
//!   from the better plan ‖ 4 from the other ‖ the reference without (10); the
//!   candidates of a crossing-search round among themselves. Their records are logged
//!   and the best plan chosen in a fixed order afterwards, so the outcome is
//!   bit-identical whatever the number of threads. A plan is decoded from the solver's
//!   vector once per solve (`Run` holds it).
//!
//!   Every model is built in a fresh symx arena ([`symx::with_fresh_arena`]), emptied
//!   and freed after the solve: at n_step 1000 each build adds 1.8 million nodes, which
//!   would otherwise stay allocated for the rest of the run.
//!
//!   With the SQP back end, 2–4 have an iteration budget ([`SQP_CANDIDATE_MAX_ITER`]).
use crate::check::{self, GoalCheck, GOAL_TOL};
use crate::crossing_search;
use crate::early_start::{self, Early, Verdict};
use crate::frame;
use crate::gait;
use crate::model::{self, Formulation, ModelError};
use crate::plan::{foot_offset, Plan, PlanError, SolutionFile, SolverInfo};
use crate::reach::{self, Unreachable};
use crate::scenario::{dist2, Biped, Foot, Gait, Scenario};
use crate::schedule_search::{self, StanceSolver};
use crate::status::{GoalShortfall, PlanStatus};
use crate::terrain::{self, Terrain};
use nlp::{
    BuildError, IpmOptions, IterationRecord, IterationView, NumericNlp, OptionError, Solution,
    SolveError, Solver, SolverOptions, SqpOptions, Status,
};
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Largest number of schedule-search rounds (each: evaluate every adjacent swap, then
/// one solve of the improved schedule) of the free gait.
pub const SEARCH_ROUNDS: usize = 4;

/// Largest number of crossing-search rounds ([`crate::crossing`]).
pub const CROSSING_ROUNDS: usize = 4;

/// Initial barrier parameter of the schedule search's re-solves (default 0.1): on the
/// lateral-goal test scenario, 161 iterations over its rounds instead of 238, same plans.
pub const SEARCH_MU_INIT: f64 = 1e-6;

/// Iteration limit of the interior-point method on the schedule search's re-solves, on
/// the crossing search's candidates and on the reference solve without (10). From a plan that satisfies every equation they
/// take 14–80 iterations; at n_step 1000 one re-solve ran to the default limit of 3000
/// (90 of the run's 117 s of CPU) without converging. Past this limit the candidate
/// counts as failed and the planner keeps what it has.
pub const SEARCH_MAX_ITER: usize = 200;

/// A warm re-solve (schedule search, reference without (10)) whose primal step stays
/// below [`STALL_STEP`] for this many iterations in a row (outside restoration) is
/// stopped and counts as failed: at n_step 1000 the pair plan's first re-solve jammed at
/// iteration 18 (α_pr ≈ 6e-5 after 15 backtracks, inf_pr 8.3e-4 unchanged) and ran to
/// [`SEARCH_MAX_ITER`], half of the run's CPU time.
pub const STALL_ITERATIONS: usize = 10;

/// The primal step size below which an iteration counts toward [`STALL_ITERATIONS`].
pub const STALL_STEP: f64 = 1e-2;

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
    /// The chosen back end's options (the one place that maps [`Backend`] to them).
    pub fn options(&self) -> &dyn SolverOptions {
        match self.backend {
            Backend::Ipm => &self.ipm,
            Backend::Sqp => &self.sqp,
        }
    }

    /// The chosen back end's options, mutably.
    pub fn options_mut(&mut self) -> &mut dyn SolverOptions {
        match self.backend {
            Backend::Ipm => &mut self.ipm,
            Backend::Sqp => &mut self.sqp,
        }
    }

    /// Applies `KEY=VALUE` option assignments (IPOPT-style names, see
    /// [`nlp::NamedOptions`]) to the chosen back end's options; on error nothing
    /// changes, and the error names the option (and the nearest valid names).
    pub fn set_by_name<S: AsRef<str>>(&mut self, assignments: &[S]) -> Result<(), OptionError> {
        let assignments: Vec<&str> = assignments.iter().map(AsRef::as_ref).collect();
        self.options_mut().set_options_by_name(&assignments)
    }

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
        let mut w = self.capped();
        w.ipm.mu_init = SEARCH_MU_INIT;
        w.ipm.bound_push = SEARCH_BOUND_PUSH;
        w.ipm.bound_frac = SEARCH_BOUND_PUSH;
        w.ipm.slack_bound_push = SEARCH_BOUND_PUSH;
        w.ipm.slack_bound_frac = SEARCH_BOUND_PUSH;
        w
    }

    /// These settings with the interior-point method limited to [`SEARCH_MAX_ITER`].
    pub(crate) fn capped(&self) -> Settings {
        let mut c = self.clone();
        c.ipm.max_iter = c.ipm.max_iter.min(SEARCH_MAX_ITER);
        c
    }

    fn print_level(&self) -> u8 {
        self.options().print_level
    }

    /// The chosen back end with its options.
    pub fn solver(&self) -> Box<dyn Solver> {
        self.options().solver()
    }

    fn solve(
        &self,
        nlp: &mut dyn NumericNlp,
        mut callback: impl FnMut(&IterationView<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError> {
        self.solver().solve_with_callback(nlp, &mut callback)
    }
}

/// When a scheduled solve stops before the solver's own tests end it.
#[derive(Clone, Copy, Default)]
pub(crate) struct Stop<'a> {
    /// Stop when the solve stalls ([`STALL_ITERATIONS`]): the run then counts as failed.
    pub(crate) on_stall: bool,
    /// Stop as soon as this flag is set: a speculative solve whose result is no longer
    /// wanted ([`crate::early_start`]); its result is discarded.
    pub(crate) cancel: Option<&'a AtomicBool>,
}

impl Stop<'_> {
    /// Whether the flag [`Stop::cancel`] is set.
    pub(crate) fn cancelled(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::SeqCst))
    }
}

/// Counts the consecutive iterations of a solve whose primal step is below
/// [`STALL_STEP`] ([`STALL_ITERATIONS`] in a row: stalled).
#[derive(Default)]
struct StallGuard {
    run: usize,
}

impl StallGuard {
    /// Whether the solve has stalled, after the iteration `r`.
    fn stalled(&mut self, r: &IterationRecord) -> bool {
        if r.iter > 0 && !r.restoration && r.alpha_pr < STALL_STEP {
            self.run += 1;
        } else {
            self.run = 0;
        }
        self.run >= STALL_ITERATIONS
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
    /// The verdict: solved, or why not ([`decide`]).
    pub status: PlanStatus,
    /// The solution file (the spec's schema); its `solver.status` is the word of
    /// `status` ([`crate::status::StatusKind::word`]). When not solved, the best plan found.
    pub file: SolutionFile,
    /// The solver runs, in order (none when a certificate decided before solving).
    pub phases: Vec<Phase>,
    /// Index in `phases` of the run whose solution is the plan (0 when `phases` is empty).
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
    #[error("{0}")]
    TooLarge(#[from] crate::limits::TooLarge),
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
pub(crate) struct Run {
    pub(crate) solution: Solution,
    /// The solution as a plan, decoded once when the solve ends.
    pub(crate) plan: Plan,
    pub(crate) schedule: Vec<Foot>,
    /// Index of its [`Phase`].
    pub(crate) phase: usize,
}

impl Run {
    /// Its objective when it succeeded (what [`Run::beats`] compares), else `None`.
    pub(crate) fn verdict(&self) -> Verdict {
        self.solution
            .status
            .is_success()
            .then_some(self.solution.objective)
    }

    /// Whether this run succeeded with a lower objective than `other` (or `other` failed).
    pub(crate) fn beats(&self, other: &Run) -> bool {
        self.solution.status.is_success()
            && (!other.solution.status.is_success()
                || self.solution.objective < other.solution.objective)
    }
}

/// One scheduled solve, not yet recorded: what [`solve_scheduled`] returns, so that
/// independent solves can run on separate threads and be logged in a fixed order.
pub(crate) struct Solved {
    pub(crate) name: String,
    pub(crate) run: Run,
    pub(crate) phase: Phase,
}

/// Solves the scheduled problem with `schedule` from `guess` (which also fixes the sides
/// of the keep-out zones, see [`model::build`]). Prints nothing: the solver's log is
/// printed by [`record`], from the iteration records.
pub(crate) fn solve_scheduled(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    schedule: &[Foot],
    guess: &[f64],
    settings: &Settings,
    name: &str,
    stop: Stop<'_>,
) -> Result<Solved, PlanningError> {
    symx::with_fresh_arena(|| {
        solve_scheduled_here(s, terrain, schedule, guess, settings, name, stop)
    })
}

/// [`solve_scheduled`] on the calling thread's expression arena.
fn solve_scheduled_here(
    s: &Scenario,
    terrain: &dyn Terrain,
    schedule: &[Foot],
    guess: &[f64],
    settings: &Settings,
    name: &str,
    stop: Stop<'_>,
) -> Result<Solved, PlanningError> {
    let formulation = Formulation::Scheduled(schedule.to_vec());
    let model = model::build(s, terrain, &formulation, guess)?;
    let mut compiled = model.problem.compile()?;
    // (10) holds by construction at every iterate of a scheduled problem: at each
    // transition the feet that do not move share their variables with the stance before,
    // so all but one step are exactly 0 and so is every product of two steps. The
    // residual is recorded as that exact 0 instead of being evaluated (a compiled layout
    // and a pass over the plan per iteration: `convergence::ResidualProbe` does it for the lifted
    // formulation).
    let mut residuals = Vec::new();
    let mut quiet = settings.clone();
    quiet.set_print_level(0);
    let mut guard = StallGuard::default();
    let solution = quiet.solve(&mut compiled, |v| {
        residuals.push(0.0);
        let stalled = stop.on_stall && guard.stalled(v.record());
        if stalled || stop.cancelled() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })?;
    let flat = model.problem.evaluate(&model.layout, &solution.x)?;
    let plan = Plan::from_flat(s, &flat)?;
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
            plan,
            schedule: schedule.to_vec(),
            phase: 0,
        },
        phase,
    })
}

/// Appends a solve's [`Phase`] and prints its log (at the settings' print level: the
/// iteration table from 5, the summary from 3).
pub(crate) fn record(solved: Solved, settings: &Settings, phases: &mut Vec<Phase>) -> Run {
    let level = settings.print_level();
    if level > 0 {
        crate::outln!("\n== {}", solved.name);
    }
    if level >= 5 {
        crate::out!("{}", nlp::format_table(&solved.phase.records));
    }
    if level >= 3 {
        crate::out!("{}", nlp::format_summary(&solved.run.solution));
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
    terrain: &(dyn Terrain + Sync),
    schedule: &[Foot],
    guess: &[f64],
    settings: &Settings,
    phases: &mut Vec<Phase>,
    name: &str,
) -> Result<Run, PlanningError> {
    let solved = solve_scheduled(s, terrain, schedule, guess, settings, name, Stop::default())?;
    Ok(record(solved, settings, phases))
}

/// Plans scenario `s` (its `gait` field chooses the formulation) on its terrain
/// ([`terrain::of`]), in the start's frame ([`frame`]): the outcome does not depend on
/// where the world origin is (up to the round-off of the translation). The plan and the
/// file are in `s`'s coordinates; `solver.objective` is the cost computed in the
/// start's frame.
pub fn plan(s: &Scenario, settings: &Settings) -> Result<Outcome, PlanningError> {
    let d = frame::offset(s);
    if d == [0.0, 0.0] {
        return plan_on(s, &*terrain::of(s), settings);
    }
    let local = frame::translated(s, d);
    let mut out = plan_on(&local, &*terrain::of(&local), settings)?;
    let back = [-d[0], -d[1]];
    let mut plan = out.file.plan();
    frame::translate_plan(&mut plan, back);
    // Stance 1 is the scenario's start, exactly.
    plan.stances[0].com = s.start.com;
    plan.stances[0].feet = s.start.feet;
    out.file = SolutionFile::new(s.clone(), out.file.solver.clone(), plan);
    if let PlanStatus::GapNotCrossable(c) = &mut out.status {
        c.reachable_x[0] += back[0];
        c.reachable_x[1] += back[0];
    }
    Ok(out)
}

/// The largest bound magnitude of the model of `s` (forces in N, coordinates in m,
/// squared lengths in m²): F_thr, the squared-distance bounds of (5)–(9) and the finite
/// edges of the allowed regions.
fn largest_bound(s: &Scenario, terrain: &dyn Terrain) -> f64 {
    let mut m = s
        .friction
        .f_thr
        .abs()
        .max(s.step_radius_sq)
        .max(s.same_side_sq.max)
        .max(s.same_biped_sq.max);
    for r in terrain.regions() {
        for v in r.x.into_iter().chain(r.y) {
            if v.is_finite() {
                m = m.max(v.abs());
            }
        }
    }
    m
}

impl Settings {
    /// These settings with the interior-point method's bound relaxation made consistent
    /// with the checker, the one place where the two meet: IPOPT-style relaxation moves
    /// each bound by `bound_relax_factor·max(1, |bound|)`, so with the default 1e-8 an
    /// F_thr of 150 N was relaxed by 1.5e-6 N, beyond the checker's absolute
    /// [`check::TOL`] (1e-6), and a solve ended `check_failed`. The factor is capped so
    /// that no bound of the model moves by more than `check::TOL / 2`; on the default
    /// scenario (largest bound 10 N) the cap is 5e-8 and the default 1e-8 stays.
    pub fn consistent_with_checker(&self, s: &Scenario, terrain: &dyn Terrain) -> Settings {
        let mut c = self.clone();
        let cap = check::TOL / 2.0 / largest_bound(s, terrain).max(1.0);
        c.ipm.bound_relax_factor = c.ipm.bound_relax_factor.min(cap);
        c
    }
}

/// Plans scenario `s` on any terrain.
pub fn plan_on(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    settings: &Settings,
) -> Result<Outcome, PlanningError> {
    crate::limits::check(s)?;
    if let Some(out) = proved_impossible(s, settings) {
        return Ok(out);
    }
    let settings = &settings.consistent_with_checker(s, terrain);
    let started = Instant::now();
    let mut phases = Vec::new();
    let (last, without_10) = match s.gait {
        Gait::Crawl => {
            let schedule = gait::crawl_schedule(s.n_step);
            let plan = gait::crawl_plan(s);
            let solved = solve_from_footholds(s, terrain, &schedule, plan, settings, "crawl gait")?;
            let first = record(solved, settings, &mut phases);
            (
                crossing_search::search(s, terrain, settings, first, &mut phases)?,
                None,
            )
        }
        Gait::Free => free_gait(s, terrain, settings, &mut phases)?,
    };
    finish(s, settings, last, without_10, phases, started)
}

/// Plans `s` by one warm solve of its scheduled problem with `schedule` from `guess` (a
/// plan of `s`, e.g. the rest of an earlier plan: the re-plan of [`crate::replan`]), with
/// the warm-start settings of the schedule search (barrier parameter [`SEARCH_MU_INIT`],
/// bound push [`SEARCH_BOUND_PUSH`], at most [`SEARCH_MAX_ITER`] iterations). The
/// certificates are decided first, as in [`plan_on`]. With `improve`, the free gait's
/// schedule search ([`crate::schedule_search`], up to [`SEARCH_ROUNDS`] rounds) then
/// starts from the warm solve's plan, and the best plan is kept.
pub fn plan_warm(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    schedule: &[Foot],
    guess: &Plan,
    settings: &Settings,
    improve: bool,
) -> Result<Outcome, PlanningError> {
    crate::limits::check(s)?;
    if let Some(out) = proved_impossible(s, settings) {
        return Ok(out);
    }
    let settings = &settings.consistent_with_checker(s, terrain).warm();
    let started = Instant::now();
    let mut phases = Vec::new();
    let last = run(
        s,
        terrain,
        schedule,
        &guess.to_flat(),
        settings,
        &mut phases,
        "re-plan",
    )?;
    if !improve {
        return finish(s, settings, last, None, phases, started);
    }
    let mut best = last;
    for solved in search_from(s, terrain, &settings.candidate(), &best, "re-plan", None)? {
        let next = record(solved, settings, &mut phases);
        if next.beats(&best) {
            best = next;
        }
    }
    finish(s, settings, best, None, phases, started)
}

/// The outcome of a planning run whose chosen solve is `last`: the plan, its solver
/// report and the verdict ([`decide`]).
fn finish(
    s: &Scenario,
    settings: &Settings,
    last: Run,
    without_10: Option<f64>,
    phases: Vec<Phase>,
    started: Instant,
) -> Result<Outcome, PlanningError> {
    let plan = last.plan;
    let solver = SolverInfo {
        name: settings.options().solver().name().into(),
        status: String::new(),
        iterations: phases.iter().map(|p| p.iterations).sum(),
        objective: plan.cost(s),
        objective_without_10: without_10,
        max_constraint_violation: last.solution.constr_viol,
        solve_seconds: started.elapsed().as_secs_f64(),
        reason: None,
    };
    let mut file = SolutionFile::new(s.clone(), solver, plan);
    let status = decide(s, last.solution.status, &file);
    file.solver.status = status.kind().word().into();
    file.solver.reason = (!status.is_solved()).then(|| status.to_string());
    Ok(Outcome {
        status,
        file,
        phases,
        chosen: last.phase,
    })
}

/// Largest distance of the file's final CoMs from their goals (m).
fn goal_distance(s: &Scenario, file: &SolutionFile) -> f64 {
    file.stances.last().map_or(f64::INFINITY, |last| {
        Biped::ALL
            .iter()
            .map(|&j| dist2(last.com.get(j), s.goal.get(j)).sqrt())
            .fold(0.0, f64::max)
    })
}

/// How far a plan ending `distance` from its goal falls short, with the bound.
fn shortfall(s: &Scenario, distance: f64, bound: Unreachable) -> GoalShortfall {
    GoalShortfall {
        n_step: s.n_step,
        distance,
        guess_needs: gait::crawl_stances_to_goal(s, GOAL_TOL, 4 * bound.needed + 100),
        bound,
    }
}

/// The first certificate that no plan of `s` exists, in the order of [`decide`] (a plan
/// ending `distance` from its goal is reported with it), or `None`.
fn certificate(s: &Scenario, distance: f64) -> Option<PlanStatus> {
    if let Some(c) = reach::uncrossable(s) {
        return Some(PlanStatus::GapNotCrossable(c));
    }
    if let Some(c) = reach::force_threshold(s, &*terrain::of(s)) {
        return Some(PlanStatus::Infeasible(c));
    }
    let bound = reach::stances_needed(s);
    (s.n_step < bound.needed).then(|| PlanStatus::GoalNotReached(shortfall(s, distance, bound)))
}

/// The outcome of a scenario that a certificate proves impossible, decided before any
/// solve ([`decide`]'s certificates on the planner's guess): the file holds the crawl
/// guess (not a plan: 0 iterations, no solver runs) with the status and the certificate
/// in `solver.reason`. `None` when no certificate applies.
fn proved_impossible(s: &Scenario, settings: &Settings) -> Option<Outcome> {
    let plan = gait::crawl_plan(s);
    let solver = SolverInfo {
        name: settings.options().solver().name().into(),
        status: String::new(),
        iterations: 0,
        objective: plan.cost(s),
        objective_without_10: None,
        max_constraint_violation: f64::NAN,
        solve_seconds: 0.0,
        reason: None,
    };
    let mut file = SolutionFile::new(s.clone(), solver, plan);
    let distance = goal_distance(s, &file);
    let status = certificate(s, distance)?;
    file.solver.status = status.kind().word().into();
    file.solver.reason = Some(status.to_string());
    Some(Outcome {
        status,
        file,
        phases: Vec::new(),
        chosen: 0,
    })
}

/// The verdict on a plan of scenario `s` returned by a solver with `solver_status`, in
/// this order: a proof that no plan exists ([`reach::uncrossable`]: gap not crossable;
/// [`reach::force_threshold`]: infeasible; n_step below [`reach::stances_needed`]: goal
/// not reached); the
/// solver's failure; the independent checker's violations of (2)–(11), the keep-out and
/// the start; a final CoM farther than [`GOAL_TOL`] (0.05 m) from its goal (no plan
/// found); else solved.
pub fn decide(s: &Scenario, solver_status: Status, file: &SolutionFile) -> PlanStatus {
    let distance = goal_distance(s, file);
    if let Some(c) = certificate(s, distance) {
        return c;
    }
    let bound = reach::stances_needed(s);
    let shortfall = |bound: Unreachable| shortfall(s, distance, bound);
    if !solver_status.is_success() {
        return PlanStatus::SolverFailed(solver_status);
    }
    let report = check::check_with(
        file,
        &check::Options {
            goal: GoalCheck::Skip,
            ..check::Options::default()
        },
    );
    // The goal is judged below, by distance (a `cross` finding is a goal not reached).
    let mut labels: Vec<String> = report
        .violations
        .iter()
        .filter(|v| v.equation != "cross")
        .map(|v| v.equation.clone())
        .collect();
    if !labels.is_empty() {
        let violations = labels.len();
        labels.sort();
        labels.dedup();
        return PlanStatus::CheckFailed { violations, labels };
    }
    if distance.is_nan() || distance > GOAL_TOL {
        return PlanStatus::NoPlanFound(shortfall(bound));
    }
    PlanStatus::Solved
}

/// The free gait (see the module docs): the best of the crawl schedule, the biped-pair
/// schedule and the schedule search from the better of the two; with the reference
/// objective without (10) ([`objective_without_10`], from the better of the crawl and
/// pair plans as solved).
fn free_gait(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    settings: &Settings,
    phases: &mut Vec<Phase>,
) -> Result<(Run, Option<f64>), PlanningError> {
    // The two starting schedules are independent: solved on two threads, each going on
    // with what it can start early ([`crate::early_start`]).
    let candidate = settings.candidate();
    let (crawl_run, pair_run, early) = early_start::first_phase(s, terrain, settings, &candidate)?;
    let crawl_run = record(crawl_run, settings, phases);
    let pair_run = record(pair_run, settings, phases);
    let pair_better = pair_run.beats(&crawl_run);
    let (better, worse) = if pair_better {
        (pair_run, crawl_run)
    } else {
        (crawl_run, pair_run)
    };
    if !better.solution.status.is_success() {
        return Ok((better, None));
    }
    // The reference without (10) starts from the better of the two plans as solved (a
    // crossing-search plan ends in exact copies of its last stance, from which the
    // reference stalled at n_step 300 and 1000).
    let reference_start = better.plan.to_flat();
    let (better_label, worse_label) = if pair_better {
        ("biped-pair", "crawl")
    } else {
        ("crawl", "biped-pair")
    };
    let (crossed, from_better, from_worse, reference) = chains(
        s,
        terrain,
        &candidate,
        (&better, better_label),
        (&worse, worse_label),
        &reference_start,
        early,
    )?;
    let better = crossed.record(better, settings, phases);
    let (crawl_run, pair_run, from_crawl, from_pair) = if pair_better {
        (worse, better, from_worse, from_better)
    } else {
        (better, worse, from_better, from_worse)
    };
    let mut best = pair_run_or(crawl_run, pair_run);
    for solved in from_crawl.into_iter().chain(from_pair) {
        let next = record(solved, settings, phases);
        if next.beats(&best) {
            best = next;
        }
    }
    Ok((best, reference))
}

/// The free gait's solves after the crawl and pair plans, not yet recorded: three
/// independent chains sharing the threads: the crossing search ([`crossing_search`])
/// from the better plan then the schedule search from its result; the schedule search
/// from the other plan; the reference without (10) from `reference_start`; each unless
/// `early` holds it already ([`crate::early_start`]). Their logs
/// are recorded afterwards, in a fixed order, and the best plan is chosen in that
/// order, so the outcome does not depend on the number of threads.
#[allow(clippy::type_complexity)]
fn chains(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    candidate: &Settings,
    (better, better_label): (&Run, &str),
    (worse, worse_label): (&Run, &str),
    reference_start: &[f64],
    early: Early,
) -> Result<
    (
        crossing_search::Searched,
        Vec<Solved>,
        Vec<Solved>,
        Option<f64>,
    ),
    PlanningError,
> {
    let Early {
        crossed,
        from_better,
        from_worse,
        reference,
    } = early;
    let (better_chain, other_chain) = rayon::join(
        || -> Result<_, PlanningError> {
            let crossed = match crossed {
                Some(crossed) => crossed,
                None => crossing_search::run(s, terrain, candidate, better, None)?,
            };
            let searched = match from_better {
                Some(searched) => searched,
                None => {
                    let from = crossed.best_run().unwrap_or(better);
                    search_from(s, terrain, candidate, from, better_label, None)?
                }
            };
            Ok((crossed, searched))
        },
        || -> Result<_, PlanningError> {
            let (from_worse, reference) = rayon::join(
                || match from_worse {
                    Some(done) => Ok(done),
                    None => search_from(s, terrain, candidate, worse, worse_label, None),
                },
                || match reference {
                    Some(done) => Ok(done),
                    None => objective_without_10(s, terrain, reference_start, candidate),
                },
            );
            Ok((from_worse?, reference?))
        },
    );
    let (crossed, from_better) = better_chain?;
    let (from_worse, reference) = other_chain?;
    Ok((crossed, from_better, from_worse, reference))
}

/// The better of the crawl and biped-pair runs (the crawl run on a tie or when both fail).
fn pair_run_or(crawl: Run, pair: Run) -> Run {
    if pair.beats(&crawl) {
        pair
    } else {
        crawl
    }
}

/// Schedule search from `from` ([`crate::schedule_search`]), not yet recorded: each
/// round's proposal satisfies every equation of its schedule with a lower cost; its
/// re-solve frees every variable. Stops when no proposal improves, a re-solve does not
/// beat the plan it started from, or after [`SEARCH_ROUNDS`] rounds. Nothing when
/// `from` failed. Once `cancel` is set (a speculative search, [`crate::early_start`])
/// its re-solve stops and no further round starts: the result is then incomplete and
/// must be discarded.
pub(crate) fn search_from(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    candidate: &Settings,
    from: &Run,
    label: &str,
    cancel: Option<&AtomicBool>,
) -> Result<Vec<Solved>, PlanningError> {
    let mut out: Vec<Solved> = Vec::new();
    if !from.solution.status.is_success() {
        return Ok(out);
    }
    let search_settings = candidate.warm();
    let mut stance_solver = stance_solver(s, terrain, candidate)?;
    let mut best = from;
    let stop = Stop {
        on_stall: true,
        cancel,
    };
    for round in 1..=SEARCH_ROUNDS {
        if stop.cancelled() {
            break;
        }
        let Some(proposal) =
            schedule_search::propose(s, &mut stance_solver, &best.plan, &best.schedule)
        else {
            break;
        };
        let next = solve_scheduled(
            s,
            terrain,
            &proposal.schedule,
            &proposal.plan.to_flat(),
            &search_settings,
            &format!(
                "free gait: search from {label} {round} ({} stance{} changed, {} evaluated)",
                proposal.changed,
                if proposal.changed == 1 { "" } else { "s" },
                proposal.evaluated
            ),
            stop,
        )?;
        let improved = next.run.beats(best);
        out.push(next);
        if !improved {
            break;
        }
        best = &out.last().expect("just pushed").run;
    }
    Ok(out)
}

/// The scheduled solve of `schedule` (not yet recorded) from the footholds of a heuristic
/// `plan`, with each stance's least-cost CoMs and forces for them
/// ([`StanceSolver::optimise_stances`]) instead of the heuristic's rigid-leg CoMs: on the
/// default scenario the crawl guess's cost falls from 2.88e5 to 1.99e5 and its solve from
/// 156 to 101 iterations (the pair schedule's 117 to 87).
pub(crate) fn solve_from_footholds(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    schedule: &[Foot],
    mut plan: Plan,
    settings: &Settings,
    name: &str,
) -> Result<Solved, PlanningError> {
    stance_solver(s, terrain, settings)?.optimise_stances(s, &mut plan);
    let guess = plan.to_flat();
    solve_scheduled(
        s,
        terrain,
        schedule,
        &guess,
        settings,
        name,
        Stop::default(),
    )
}

/// The stance solver of the schedule search, from the settings of the free gait's
/// candidates: the user's back end and options ([`StanceSolver::with_settings`]).
fn stance_solver(
    s: &Scenario,
    terrain: &dyn Terrain,
    candidate: &Settings,
) -> Result<StanceSolver, BuildError> {
    StanceSolver::with_settings(s, terrain, candidate)
}

/// The reference objective of the problem without (10): every foot may move at every
/// transition (the lifted formulation, [`Formulation::Complementarity`], with its penalty
/// π set to 0, so (5) bounds each step and nothing couples the feet), warm-started from
/// `plan` (a plan that satisfies every equation, hence feasible for the relaxation) with
/// its keep-out sides. Dropping a constraint can only lower the optimum, so this says how
/// much (10) costs; it is a local optimum of a nonconvex problem, a reference rather than
/// a certified bound. `None` when the solve does not succeed.
pub fn objective_without_10(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    plan: &[f64],
    settings: &Settings,
) -> Result<Option<f64>, PlanningError> {
    symx::with_fresh_arena(|| objective_without_10_here(s, terrain, plan, settings))
}

/// [`objective_without_10`] on the calling thread's expression arena.
fn objective_without_10_here(
    s: &Scenario,
    terrain: &dyn Terrain,
    plan: &[f64],
    settings: &Settings,
) -> Result<Option<f64>, PlanningError> {
    let model = model::build(s, terrain, &Formulation::Complementarity, plan)?;
    let mut compiled = model.problem.compile()?;
    compiled.set_value(model::PENALTY, &[0.0])?;
    let mut quiet = settings.capped();
    quiet.set_print_level(0);
    let mut guard = StallGuard::default();
    let solution = quiet.solve(&mut compiled, |v| {
        if guard.stalled(v.record()) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })?;
    if !solution.status.is_success() {
        return Ok(None);
    }
    let flat = model.problem.evaluate(&model.layout, &solution.x)?;
    Ok(Some(Plan::from_flat(s, &flat)?.cost(s)))
}

/// The solver's own status as a word (for logs and examples; the solution file holds
/// the plan's `status::StatusKind` word).
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

#[cfg(test)]
mod tests {
    use super::*;

    fn row(iter: usize, alpha_pr: f64, restoration: bool) -> IterationRecord {
        IterationRecord {
            iter,
            restoration,
            objective: 0.0,
            inf_pr: 0.0,
            inf_du: 0.0,
            d_norm: 1.0,
            regularization: 0.0,
            backend: nlp::BackendColumns::Ipm {
                mu: 1e-6,
                jacobian_regularization: 0.0,
            },
            alpha_du: 1.0,
            alpha_pr,
            alpha_pr_char: 'h',
            ls: 15,
        }
    }

    /// The schedule search's stance solves take the user's back end and options
    /// (issue 23 item 3): with `--solver sqp --opt tol=1e-9 --opt max_wall_time=7
    /// --opt print_level=5`, the stance solver that [`search_from`] builds from the
    /// free gait's candidate settings runs the SQP with that tolerance and wall-time
    /// limit, at most [`schedule_search::STANCE_MAX_ITER`] iterations and print level 0.
    #[test]
    fn stance_solves_take_the_users_back_end_and_options() {
        let s = Scenario::default();
        let t = terrain::of(&s);
        let mut user = Settings {
            backend: Backend::Sqp,
            ..Settings::default()
        };
        user.set_by_name(&["tol=1e-9", "max_wall_time=7", "print_level=5"])
            .unwrap();
        let solver = stance_solver(&s, &*t, &user.candidate()).unwrap();
        let got = solver.settings();
        assert_eq!(got.backend, Backend::Sqp);
        assert_eq!(got.sqp.tol, 1e-9);
        assert_eq!(got.sqp.max_wall_time, 7.0);
        assert_eq!(got.sqp.print_level, 0);
        assert!(got.sqp.max_iter <= schedule_search::STANCE_MAX_ITER);
        assert_eq!(got.ipm.tol, IpmOptions::default().tol);
    }

    /// The guard trips on the `STALL_ITERATIONS`-th consecutive short step, not before;
    /// a full step or a restoration row restarts the count; the initial row (step 0)
    /// does not count.
    #[test]
    fn stall_guard_counts_consecutive_short_steps() {
        let mut g = StallGuard::default();
        assert!(!g.stalled(&row(0, 0.0, false)));
        for k in 1..STALL_ITERATIONS {
            assert!(!g.stalled(&row(k, 6e-5, false)), "tripped after {k}");
        }
        assert!(!g.stalled(&row(STALL_ITERATIONS, 1.0, false)));
        for k in 1..STALL_ITERATIONS {
            assert!(!g.stalled(&row(100 + k, 6e-5, false)));
        }
        assert!(!g.stalled(&row(200, 6e-5, true)));
        for k in 1..STALL_ITERATIONS {
            assert!(!g.stalled(&row(300 + k, STALL_STEP / 2.0, false)));
        }
        assert!(g.stalled(&row(400, STALL_STEP / 2.0, false)));
    }
}
