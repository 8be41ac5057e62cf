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
//! gap depth 0.5 ran 984 iterations on one before).
use crate::check::GOAL_TOL;
use crate::crossing::{self, Candidate};
use crate::plan::{Plan, STANCE_LEN};
use crate::scenario::{dist2, Biped, Foot, Scenario};
use crate::schedule_search::NULL_MOVE;
use crate::solve::{
    record, solve_scheduled, Phase, PlanningError, Run, Settings, Solved, CROSSING_ROUNDS,
};
use crate::terrain::Terrain;

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

/// A flat plan extended to `n` stances by repeating its last stance.
pub fn extend(flat: &[f64], n: usize) -> Vec<f64> {
    let mut out = flat.to_vec();
    let last = flat[flat.len() - STANCE_LEN..].to_vec();
    while out.len() < n * STANCE_LEN {
        out.extend_from_slice(&last);
    }
    out
}

/// Whether the final CoMs of a flat plan are within [`GOAL_TOL`] of their goals.
fn reaches_goal(s: &Scenario, flat: &[f64]) -> bool {
    Plan::from_flat(s, flat).is_ok_and(|p| {
        p.stances.last().is_some_and(|last| {
            Biped::ALL
                .iter()
                .all(|&j| dist2(last.com.get(j), s.goal.get(j)).sqrt() <= GOAL_TOL)
        })
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
            false,
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
        true,
    )?;
    solved.run.flat = extend(&solved.run.flat, s.n_step);
    solved.run.schedule = schedule.to_vec();
    solved.run.solution.objective = Plan::from_flat(s, &solved.run.flat)?.cost(s);
    Ok(solved)
}

/// The crossing search ([`crate::crossing`]) from a solved run: each round solves, in
/// parallel, every candidate in which one foot crosses a keep-out zone one move earlier
/// (on the walking horizon, module docs), and keeps the best that succeeds with a lower
/// objective (and reaches the goal when `best` does), for up to [`CROSSING_ROUNDS`]
/// rounds.
pub(crate) fn search(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    settings: &Settings,
    mut best: Run,
    phases: &mut Vec<Phase>,
) -> Result<Run, PlanningError> {
    use rayon::prelude::*;
    for round in 1..=CROSSING_ROUNDS {
        if !best.solution.status.is_success() {
            break;
        }
        let plan = Plan::from_flat(s, &best.flat)?;
        let candidates = crossing::earlier_crossings(s, terrain, &plan, &best.schedule);
        if candidates.is_empty() {
            break;
        }
        let horizon = walking_horizon(&plan);
        let solved: Vec<Result<Solved, PlanningError>> = candidates
            .par_iter()
            .map(|c| solve_candidate(s, terrain, &best.schedule, c, settings, horizon, round))
            .collect();
        let needs_goal = reaches_goal(s, &best.flat);
        let mut improved = false;
        for r in solved {
            let next = record(r?, settings, phases);
            if next.beats(&best) && (!needs_goal || reaches_goal(s, &next.flat)) {
                best = next;
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    Ok(best)
}
