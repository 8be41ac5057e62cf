//! The crossing search's loop: solve the candidates of [`crate::crossing`] and keep the
//! best, round after round.
//!
//! A plan that reaches its goal stands still for the rest of the horizon (at n_step
//! 1000 the default plan walks for about 45 stances and stands for 955). A candidate
//! changes only where a foot crosses, so it is solved on the *walking horizon*: the
//! stances up to the plan's last move longer than [`NULL_MOVE`] plus [`TAIL_MARGIN`]
//! ([`walking_horizon`]); its solution is extended to the full horizon by repeating its
//! last stance ([`extend`]: every equation holds there as at that stance, and (10)
//! holds with zero moves), and candidates are compared by the full plan's cost (1).
//! At n_step 1000 this makes each candidate a problem of 55 stances instead of 1000
//! (three candidates on the default gap: the run's user CPU time 22.4 s → 14.3 s, against
//! 13.1 s without these candidates; docs/performance.md). A candidate solved on the
//! walking horizon stops when it stalls (`solve::STALL_ITERATIONS`; the crawl gait at
//! gap depth 0.5 ran 984 iterations on one before), and every candidate counts as failed
//! past `solve::SEARCH_MAX_ITER` (200) iterations of the interior-point method: the
//! family's "w 0.299 at 2.6" ran 313 and 202 on two candidates of round 1 that lost
//! to ones of 99–134 iterations (on all 31 scenarios of
//! `models/gap_crossing/scripts/scenario_table.py` no candidate past 200 won).
use crate::check::GOAL_TOL;
use crate::crossing::{self, Candidate};
use crate::plan::Plan;
use crate::scenario::{dist2, Biped, Foot, Scenario};
use crate::schedule_search::NULL_MOVE;
use crate::solve::{
    record, solve_scheduled, Phase, PlanningError, Run, Settings, Solved, Stop, CROSSING_ROUNDS,
};
use crate::terrain::Terrain;
use std::sync::atomic::AtomicBool;

/// Stances kept after the plan's last move in a candidate's walking horizon: room for
/// the candidate to end its walk a few moves later than the plan.
pub const TAIL_MARGIN: usize = 8;

/// The stances a candidate of `plan` is solved on: through the last stance at which a
/// foot moved more than [`NULL_MOVE`], plus [`TAIL_MARGIN`]; at most the plan's length.
pub fn walking_horizon(plan: &Plan) -> usize {
    let n = plan.stances.len();
    let last_move = (1..n)
        .filter(|&k| {
            let (a, b) = (&plan.stances[k - 1].feet, &plan.stances[k].feet);
            Foot::ALL
                .iter()
                .any(|&i| dist2(a.get(i), b.get(i)) > NULL_MOVE * NULL_MOVE)
        })
        .max()
        .unwrap_or(0);
    (last_move + 1 + TAIL_MARGIN).min(n)
}

/// A plan extended to `n` stances by repeating its last stance (unchanged when it has
/// `n` or more, or none).
pub fn extend(plan: &Plan, n: usize) -> Plan {
    let mut out = plan.clone();
    if let Some(&last) = plan.stances.last() {
        out.stances.resize(n.max(plan.stances.len()), last);
    }
    out
}

/// Whether the final CoMs of a plan are within [`GOAL_TOL`] of their goals.
fn reaches_goal(s: &Scenario, plan: &Plan) -> bool {
    plan.stances.last().is_some_and(|last| {
        Biped::ALL
            .iter()
            .all(|&j| dist2(last.com.get(j), s.goal.get(j)).sqrt() <= GOAL_TOL)
    })
}

/// Solves candidate `c` of a plan of `schedule` on the first `horizon` stances and
/// extends the solution to the full horizon; the run's objective is the full plan's
/// cost.
#[allow(clippy::too_many_arguments)]
fn solve_candidate(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    schedule: &[Foot],
    c: &Candidate,
    settings: &Settings,
    horizon: usize,
    round: usize,
    cancel: Option<&AtomicBool>,
) -> Result<Solved, PlanningError> {
    let mut name = format!(
        "crossing search {round}: {} crosses at transition {}",
        c.foot,
        c.transition + 1
    );
    if horizon >= s.n_step {
        return solve_scheduled(
            s,
            terrain,
            schedule,
            &c.plan.to_flat(),
            settings,
            &name,
            Stop {
                on_stall: false,
                cancel,
            },
        );
    }
    name.push_str(&format!(" (on {horizon} stances)"));
    let short = Scenario {
        n_step: horizon,
        ..s.clone()
    };
    let guess = Plan {
        stances: c.plan.stances[..horizon].to_vec(),
    };
    let mut solved = solve_scheduled(
        &short,
        terrain,
        &schedule[..horizon - 1],
        &guess.to_flat(),
        settings,
        &name,
        Stop {
            on_stall: true,
            cancel,
        },
    )?;
    solved.run.plan = extend(&solved.run.plan, s.n_step);
    solved.run.schedule = schedule.to_vec();
    solved.run.solution.objective = solved.run.plan.cost(s);
    Ok(solved)
}

/// The solves of a crossing search, not yet recorded ([`record`]), in the order they
/// ran, and which of them is the best plan (`None`: none beat the start).
pub(crate) struct Searched {
    pub(crate) solved: Vec<Solved>,
    pub(crate) best: Option<usize>,
}

impl Searched {
    /// The best plan's run (`None`: the start stays the best).
    pub(crate) fn best_run(&self) -> Option<&Run> {
        self.best.map(|k| &self.solved[k].run)
    }

    /// Records every solve in order ([`record`]) and returns the best run: the
    /// search's best, or `start` when none beat it.
    pub(crate) fn record(self, start: Run, settings: &Settings, phases: &mut Vec<Phase>) -> Run {
        let mut best = start;
        for (k, solved) in self.solved.into_iter().enumerate() {
            let run = record(solved, settings, phases);
            if Some(k) == self.best {
                best = run;
            }
        }
        best
    }
}

/// The crossing search ([`crate::crossing`]) from a solved run, recorded: [`run`] then
/// [`Searched::record`].
pub(crate) fn search(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    settings: &Settings,
    start: Run,
    phases: &mut Vec<Phase>,
) -> Result<Run, PlanningError> {
    Ok(run(s, terrain, settings, &start, None)?.record(start, settings, phases))
}

/// The crossing search ([`crate::crossing`]) from a solved run, not yet recorded (so
/// that it can run alongside other solves): each round solves, in parallel, every
/// candidate in which one foot crosses a keep-out zone one move earlier (on the walking
/// horizon, module docs), and keeps the best that succeeds with a lower objective (and
/// reaches the goal when the plan it started from does), compared in a fixed order, for
/// up to [`CROSSING_ROUNDS`] rounds. Once `cancel` is set (a speculative search,
/// [`crate::early_start`]) the solves stop and no further round starts: the result is
/// then incomplete and must be discarded.
pub(crate) fn run(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    settings: &Settings,
    start: &Run,
    cancel: Option<&AtomicBool>,
) -> Result<Searched, PlanningError> {
    use rayon::prelude::*;
    // Capped like the schedule search's re-solves: a candidate still running past
    // `SEARCH_MAX_ITER` iterations counts as failed (module docs).
    let settings = &settings.capped();
    let mut out = Searched {
        solved: Vec::new(),
        best: None,
    };
    let stop = Stop {
        on_stall: false,
        cancel,
    };
    for round in 1..=CROSSING_ROUNDS {
        if stop.cancelled() {
            break;
        }
        let current = out.best_run().unwrap_or(start);
        if !current.solution.status.is_success() {
            break;
        }
        let candidates = crossing::earlier_crossings(s, terrain, &current.plan, &current.schedule);
        if candidates.is_empty() {
            break;
        }
        let horizon = walking_horizon(&current.plan);
        let schedule = &current.schedule;
        let solved: Vec<Result<Solved, PlanningError>> = candidates
            .par_iter()
            .map(|c| solve_candidate(s, terrain, schedule, c, settings, horizon, round, cancel))
            .collect();
        let needs_goal = reaches_goal(s, &current.plan);
        let mut improved = false;
        for r in solved {
            let next = r?;
            let best = out.best_run().unwrap_or(start);
            let wins = next.run.beats(best) && (!needs_goal || reaches_goal(s, &next.run.plan));
            out.solved.push(next);
            if wins {
                out.best = Some(out.solved.len() - 1);
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    Ok(out)
}
