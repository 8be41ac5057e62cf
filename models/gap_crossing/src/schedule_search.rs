//! Local search over foot schedules: adjacent swaps, each evaluated exactly on one stance.
//!
//! A schedule says which foot moves at each transition (`schedule[t]` moves from stance
//! `t` to `t + 1`, 0-based). Swapping two consecutive entries `t`, `t + 1` (feet `j`
//! then `i` become `i` then `j`) with every foothold kept where it is changes **one
//! stance only**: stance `t + 1` then has foot `i` already at its next foothold and foot
//! `j` still at its previous one. Every displacement is the same as before, only one
//! transition earlier or later, so (3), (5) and the keep-out still hold; what is left to
//! check is (6)–(9) between the new stance's feet (plain numbers) and whether CoMs and
//! forces exist for it.
//!
//! CoMs and forces of a stance appear in that stance's equations and cost terms only, so
//! with the footholds fixed the plan's cost is a sum of independent per-stance problems:
//! minimise the stance's terms of (1) subject to (2), (4), (11) with the four feet given
//! ([`crate::model::build_stance`], solved here by [`StanceSolver`]). The gain of a swap
//! is the old stance's cost minus that problem's optimum: an exact decrease of the cost
//! at a point that satisfies every equation of the swapped schedule, (10) included
//! (one foot moves per transition by construction).
//!
//! [`propose`] evaluates every swap at a solved plan and applies the improving ones
//! greedily (largest gain first, no two touching the same transition). The result, a
//! new schedule and a feasible plan for it with a lower cost, is then re-solved with
//! every variable free (`crate::solve`), which can only lower the cost further, and the
//! search repeats from there: a descent over schedules in which each step is a
//! first-order improvement certified by a feasible point, not a guess.
use crate::model::{build_stance, STANCE_FEET};
use crate::plan::{Plan, Stance};
use crate::scenario::{dist2, Coms, Feet, Foot, Scenario};
use crate::terrain::Terrain;
use nlp::ipm::Ipm;
use nlp::{BuildError, Compiled, IpmOptions, Problem};

/// Iteration limit of one stance solve (they take 10–30 iterations from the old stance).
pub const STANCE_MAX_ITER: usize = 100;

/// Smallest gain, relative to the plan's cost, for which a swap is applied (1e-5: about
/// 2 on the default scenario's 1.7e5; a re-solve for less is not worth its time).
pub const MIN_RELATIVE_GAIN: f64 = 1e-5;

/// The per-stance problem of [`build_stance`], compiled once, solved for any feet.
pub struct StanceSolver {
    problem: Problem,
    compiled: Compiled,
    ipm: Ipm,
}

impl StanceSolver {
    /// Compiles the stance problem of scenario `s` on `terrain`.
    pub fn new(s: &Scenario, terrain: &dyn Terrain) -> Result<StanceSolver, BuildError> {
        let problem = build_stance(s, terrain)?;
        let compiled = problem.compile()?;
        let ipm = Ipm::new(IpmOptions {
            common: nlp::CommonOptions {
                max_iter: STANCE_MAX_ITER,
                ..Default::default()
            },
            ..IpmOptions::default()
        });
        Ok(StanceSolver {
            problem,
            compiled,
            ipm,
        })
    }

    /// The CoMs and forces of least cost for `feet`, starting from `start`'s CoMs and
    /// forces, with that cost; `None` when the solver does not succeed.
    pub fn solve(&mut self, s: &Scenario, feet: &Feet, start: &Stance) -> Option<(Stance, f64)> {
        let p: Vec<f64> = feet.to_array().iter().flatten().copied().collect();
        self.compiled.set_parameter(STANCE_FEET, &p).ok()?;
        let mut x0 = Vec::with_capacity(18);
        x0.extend_from_slice(&start.com.b);
        x0.extend_from_slice(&start.com.f);
        for f in start.forces.to_array() {
            x0.extend_from_slice(&f);
        }
        self.compiled.set_initial_point(&x0).ok()?;
        let sol = self.ipm.solve(&mut self.compiled).ok()?;
        if !sol.status.is_success() {
            return None;
        }
        let x = self
            .problem
            .evaluate(self.problem.variables(), &sol.x)
            .ok()?;
        let v = |o: usize| [x[o], x[o + 1], x[o + 2]];
        let stance = Stance {
            com: Coms { b: v(0), f: v(3) },
            feet: *feet,
            forces: Feet::from_array([v(6), v(9), v(12), v(15)]),
        };
        Some((stance, stance_cost(s, &stance)))
    }
}

/// The terms of cost (1) of one stance.
pub fn stance_cost(s: &Scenario, st: &Stance) -> f64 {
    Plan { stances: vec![*st] }.cost(s)
}

/// Whether the feet of one stance satisfy (6)–(9).
pub fn feet_distances_ok(s: &Scenario, feet: &Feet) -> bool {
    let pairs = [
        (Foot::BR, Foot::FR, s.same_side_sq),
        (Foot::BL, Foot::FL, s.same_side_sq),
        (Foot::BR, Foot::BL, s.same_biped_sq),
        (Foot::FR, Foot::FL, s.same_biped_sq),
    ];
    pairs.iter().all(|&(a, b, bounds)| {
        let d2 = dist2(feet.get(a), feet.get(b));
        d2 >= bounds.min && d2 <= bounds.max
    })
}

/// One evaluated swap of `schedule[at]` and `schedule[at + 1]`.
#[derive(Clone, Debug)]
pub struct Swap {
    /// The first of the two transitions swapped.
    pub at: usize,
    /// Decrease of the plan's cost (stance `at + 1`'s old cost minus its new one).
    pub gain: f64,
    /// The new stance `at + 1`.
    pub stance: Stance,
}

/// Every adjacent swap of `schedule` at `plan` (a plan of that schedule) that lowers the
/// cost, best first.
pub fn improving_swaps(
    s: &Scenario,
    solver: &mut StanceSolver,
    plan: &Plan,
    schedule: &[Foot],
) -> Vec<Swap> {
    let cost = plan.cost(s);
    let mut swaps = Vec::new();
    for at in 0..schedule.len().saturating_sub(1) {
        let (j, i) = (schedule[at], schedule[at + 1]);
        if i == j {
            continue;
        }
        let (before, old, after) = (
            &plan.stances[at],
            &plan.stances[at + 1],
            &plan.stances[at + 2],
        );
        // Foot i already at its next foothold, foot j still at its previous one.
        let mut feet = old.feet;
        *feet.get_mut(i) = after.feet.get(i);
        *feet.get_mut(j) = before.feet.get(j);
        if feet == old.feet || !feet_distances_ok(s, &feet) {
            continue;
        }
        let Some((stance, new_cost)) = solver.solve(s, &feet, old) else {
            continue;
        };
        let gain = stance_cost(s, old) - new_cost;
        if gain > MIN_RELATIVE_GAIN * cost {
            swaps.push(Swap { at, gain, stance });
        }
    }
    swaps.sort_by(|a, b| b.gain.total_cmp(&a.gain));
    swaps
}

/// An improved schedule: the result of [`propose`].
#[derive(Clone, Debug)]
pub struct Proposal {
    /// The schedule with the swaps applied.
    pub schedule: Vec<Foot>,
    /// A plan of that schedule satisfying every equation (the old plan with the swapped
    /// stances replaced).
    pub plan: Plan,
    /// Its decrease of the cost (the sum of the swaps' gains).
    pub gain: f64,
    /// How many swaps were applied.
    pub swaps: usize,
}

/// A better schedule than `schedule` and a plan for it, by the improving adjacent swaps
/// at `plan` (a plan of `schedule`) applied greedily: largest gain first, skipping swaps
/// that share a transition with one already taken. `None` when no swap improves.
pub fn propose(
    s: &Scenario,
    solver: &mut StanceSolver,
    plan: &Plan,
    schedule: &[Foot],
) -> Option<Proposal> {
    let mut taken = vec![false; schedule.len()];
    let mut out = Proposal {
        schedule: schedule.to_vec(),
        plan: plan.clone(),
        gain: 0.0,
        swaps: 0,
    };
    for sw in improving_swaps(s, solver, plan, schedule) {
        if taken[sw.at] || taken[sw.at + 1] {
            continue;
        }
        taken[sw.at] = true;
        taken[sw.at + 1] = true;
        out.schedule.swap(sw.at, sw.at + 1);
        out.plan.stances[sw.at + 1] = sw.stance;
        out.gain += sw.gain;
        out.swaps += 1;
    }
    (out.swaps > 0).then_some(out)
}
