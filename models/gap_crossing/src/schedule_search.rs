//! Search over foot schedules with the footholds kept: a shortest path through the
//! lattice of foothold counts, each stance evaluated exactly.
//!
//! A schedule says which foot moves at each transition (`schedule[t]` moves from stance
//! `t` to `t + 1`, 0-based). Keep every foot's sequence of footholds (its position after
//! each of its scheduled moves) and the plan is fixed by how many moves each foot has
//! made at each stance: the *counts* `c = (c_BR, c_BL, c_FR, c_FL)`, with `Σ c = k` at
//! stance `k`. A schedule is a monotone path through this 4-D lattice from `(0, 0, 0, 0)`
//! to the final counts, one foot's count going up by one per transition. Every path
//! keeps every displacement (only when it happens changes), so (3), (5) and the keep-out
//! hold on every path, and (10) holds by construction (one foot per transition); what is
//! left for a lattice point is (6)–(9) between its four feet (plain numbers) and whether
//! CoMs and forces exist for them.
//!
//! CoMs and forces of a stance appear in that stance's equations and cost terms only, so
//! with the footholds fixed the plan's cost is a sum over the path of independent
//! per-stance problems: minimise the stance's terms of (1) subject to (2), (4), (11)
//! with the four feet given ([`crate::model::build_stance`], solved here by
//! [`StanceSolver`]). The best path is then a shortest-path problem, solved exactly by
//! dynamic programming over the stances ([`propose`]).
//!
//! The lattice is restricted to a band around the current schedule's path: at stance
//! `k`, the counts `c(k) + δ` with every `|δ_i| ≤ 1` and `Σ δ = 0` (19 points: the path's
//! own, one foot a step ahead and another a step behind, or two ahead and two behind).
//! The band holds every single adjacent swap (one foot ahead and the other behind at one
//! stance), but also moving one foot's step several transitions earlier or later (a
//! foot ahead for several stances in a row), any number of swaps at once, and swaps of
//! two pairs; the dynamic programme picks the best combination, not a greedy one. Points
//! whose feet are within [`NULL_MOVE`] of the path's own at that stance are left out
//! (the same configuration). The programme is solved lazily ([`propose`]): only the
//! points the shortest path needs are solved, each once.
//!
//! The result, a new schedule and a plan for it that satisfies every equation with a
//! lower cost, is re-solved with every variable free (`crate::solve`), which moves the
//! footholds and can only lower the cost further, and the search repeats from there: a
//! descent over schedules in which each step is certified by a feasible point.
use crate::model::{build_stance, STANCE_FEET};
use crate::plan::{Plan, Stance};
use crate::scenario::{dist2, Coms, Feet, Foot, Scenario, Vec3};
use crate::solve::Settings;
use crate::terrain::Terrain;
use nlp::{BuildError, Compiled, Problem, Solution, Solver};
use std::collections::HashMap;

/// Iteration limit of one stance solve (they take 10–30 iterations from the old stance).
pub const STANCE_MAX_ITER: usize = 100;

/// Smallest gain, relative to the plan's cost, for which a swap is applied (1e-5: about
/// 2 on the default scenario's 1.7e5; a re-solve for less is not worth its time).
pub const MIN_RELATIVE_GAIN: f64 = 1e-5;

/// The per-stance problem of [`build_stance`], compiled once, solved for any feet.
pub struct StanceSolver {
    problem: Problem,
    compiled: Compiled,
    settings: Settings,
    solver: Box<dyn Solver>,
    /// The last successful solve: its multipliers warm-start the next one
    /// ([`StanceSolver::solve`]).
    last: Option<Solution>,
    /// Where a warm solve writes its result (swapped with `last`, so that a solve
    /// allocates nothing after the first).
    next: Option<Solution>,
}

impl StanceSolver {
    /// Compiles the stance problem of scenario `s` on `terrain`, solved by the default
    /// interior-point method ([`StanceSolver::with_settings`] with the defaults).
    pub fn new(s: &Scenario, terrain: &dyn Terrain) -> Result<StanceSolver, BuildError> {
        StanceSolver::with_settings(s, terrain, &Settings::default())
    }

    /// Compiles the stance problem of scenario `s` on `terrain`, solved by the back end
    /// and options of `settings` (the user's `--solver` and `--opt`: tolerances, the
    /// wall-time limit, ...), with two exceptions: at most [`STANCE_MAX_ITER`] iterations
    /// per solve, and print level 0, because a search round solves hundreds of these
    /// 18-variable problems, whose logs would drown those of the plan's solves.
    pub fn with_settings(
        s: &Scenario,
        terrain: &dyn Terrain,
        settings: &Settings,
    ) -> Result<StanceSolver, BuildError> {
        let problem = build_stance(s, terrain)?;
        let compiled = problem.compile()?;
        let mut settings = settings.clone();
        let common = &mut **settings.options_mut();
        common.max_iter = common.max_iter.min(STANCE_MAX_ITER);
        common.print_level = 0;
        Ok(StanceSolver {
            problem,
            compiled,
            solver: settings.solver(),
            settings,
            last: None,
            next: None,
        })
    }

    /// The settings its solves run with (the caller's, with the two exceptions of
    /// [`StanceSolver::with_settings`]).
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The CoMs and forces of least cost for `feet`, starting from `start`'s CoMs and
    /// forces, with that cost; `None` when the solver does not succeed.
    ///
    /// Consecutive stance problems differ in a foot or a stance, so their multipliers are
    /// alike: after a successful solve the next one is warm-started (IPOPT's
    /// `warm_start_init_point`) from `start` with the previous solve's multipliers, and
    /// solved again from `start` alone if that fails. On the default scenario this takes
    /// the stance solves from 24.4 to 13.4 iterations on average, same plans.
    pub fn solve(&mut self, s: &Scenario, feet: &Feet, start: &Stance) -> Option<(Stance, f64)> {
        let p = feet.to_array();
        self.compiled
            .set_value(STANCE_FEET, p.as_flattened())
            .ok()?;
        let [f0, f1, f2, f3] = start.forces.to_array();
        let x0 = [start.com.b, start.com.f, f0, f1, f2, f3];
        let x0 = x0.as_flattened();
        self.compiled.set_initial_point(x0).ok()?;
        let warm = match self.last.as_mut() {
            Some(previous) => {
                previous.x.copy_from_slice(x0);
                let next = self.next.get_or_insert_with(|| previous.clone());
                self.solver
                    .solve_warm_into(&mut self.compiled, previous, next)
                    .is_ok()
                    && next.status.is_success()
            }
            None => false,
        };
        if warm {
            std::mem::swap(&mut self.last, &mut self.next);
        } else {
            self.last = Some(self.solver.solve(&mut self.compiled).ok()?);
        }
        let sol = self.last.as_ref().expect("just solved");
        if !sol.status.is_success() {
            self.last = None;
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

    /// Replaces the CoMs and forces of every stance of `plan` but the first (the start)
    /// by the least-cost ones for that stance's feet ([`StanceSolver::solve`], from the
    /// stance's own): with the feet fixed, the problem separates by stance, so the
    /// footholds of a heuristic guess get CoMs and forces that satisfy (2), (4) and (11)
    /// at a local minimum of their terms of (1). A stance whose solve fails keeps its
    /// own. A stance equal to the one before it as it was (a robot standing at its goal)
    /// is the same problem from the same start: it takes that stance's result without a
    /// solve. Returns how many stances were replaced.
    pub fn optimise_stances(&mut self, s: &Scenario, plan: &mut Plan) -> usize {
        let mut replaced = 0;
        let mut previous: Option<(Stance, Option<Stance>)> = None;
        for k in 1..plan.stances.len() {
            let stance = plan.stances[k];
            let result = match previous {
                Some((before, result)) if before == stance => result,
                _ => self
                    .solve(s, &stance.feet, &stance)
                    .map(|(better, _)| better),
            };
            previous = Some((stance, result));
            if let Some(better) = result {
                plan.stances[k] = better;
                replaced += 1;
            }
        }
        replaced
    }
}

/// The terms of cost (1) of one stance.
pub fn stance_cost(s: &Scenario, st: &Stance) -> f64 {
    Plan { stances: vec![*st] }.cost(s)
}

pub use crate::gait::feet_distances_ok;

/// Foothold counts: how many scheduled moves each foot (BR, BL, FR, FL) has made.
pub type Counts = [usize; 4];

/// Each foot's footholds under `schedule` at `plan` (a plan of that schedule): entry `c`
/// is its position after its `c`-th scheduled move (entry 0: the start). A scheduled
/// move that does not displace the foot repeats the previous position.
pub fn footholds(plan: &Plan, schedule: &[Foot]) -> [Vec<Vec3>; 4] {
    let mut seq: [Vec<Vec3>; 4] = Foot::ALL.map(|i| vec![plan.stances[0].feet.get(i)]);
    for (t, &i) in schedule.iter().enumerate() {
        seq[i.index()].push(plan.stances[t + 1].feet.get(i));
    }
    seq
}

/// The counts of `schedule` at each stance (`n_step` entries, the first all zero).
pub fn path_counts(schedule: &[Foot]) -> Vec<Counts> {
    let mut c = [0; 4];
    let mut out = vec![c];
    for &i in schedule {
        c[i.index()] += 1;
        out.push(c);
    }
    out
}

/// The band's offsets from the path: every `δ ∈ {−1, 0, 1}⁴` with `Σ δ = 0` (19, the
/// path's own first).
fn band_offsets() -> Vec<[i64; 4]> {
    let mut out = vec![[0; 4]];
    for code in 0..81_i64 {
        let d = [
            code % 3 - 1,
            code / 3 % 3 - 1,
            code / 9 % 3 - 1,
            code / 27 % 3 - 1,
        ];
        if d.iter().sum::<i64>() == 0 && d != [0; 4] {
            out.push(d);
        }
    }
    out
}

/// What is known of a band point's stance (the stance is boxed: most points stay bounds).
#[derive(Clone)]
enum Value {
    /// Not solved yet: a lower bound of its cost ([`cost_lower_bound`]).
    Bound(f64),
    /// Solved: the stance and its cost.
    Exact(Box<Stance>, f64),
    /// (6)–(9) violated, or the stance problem failed.
    Infeasible,
}

impl Value {
    fn cost(&self) -> f64 {
        match self {
            Value::Bound(c) | Value::Exact(_, c) => *c,
            Value::Infeasible => f64::INFINITY,
        }
    }
}

/// An improved schedule: the result of [`propose`].
#[derive(Clone, Debug)]
pub struct Proposal {
    /// The new schedule.
    pub schedule: Vec<Foot>,
    /// A plan of that schedule satisfying every equation, with the old plan's footholds
    /// (the stances off the old path replaced by their stance problem's solution).
    pub plan: Plan,
    /// Its decrease of the cost (old cost minus the plan's).
    pub gain: f64,
    /// How many stances differ from the old plan.
    pub changed: usize,
    /// How many stance problems were solved (band points evaluated).
    pub evaluated: usize,
}

/// The band of the dynamic programme: for each stance, its lattice points.
struct Band {
    /// `points[k]`: the counts of stance `k`'s band points (the path's own first).
    points: Vec<Vec<Counts>>,
    /// `values[k][p]`: what is known of point `p` of stance `k`.
    values: Vec<Vec<Value>>,
    /// `preds[k][p]`: indices in stance `k − 1`'s points of `p`'s predecessors (one
    /// foot's count one lower).
    preds: Vec<Vec<Vec<usize>>>,
}

impl Band {
    /// The band around `path`, every point off the path given its lower bound (or
    /// marked infeasible by (6)–(9)), the path's points their plan stance.
    fn new(
        s: &Scenario,
        plan: &Plan,
        path: &[Counts],
        holds: &[Vec<Vec3>; 4],
        known: &Known,
    ) -> Band {
        let offsets = band_offsets();
        let n = path.len();
        let mut band = Band {
            points: Vec::with_capacity(n),
            values: Vec::with_capacity(n),
            preds: Vec::with_capacity(n),
        };
        for (k, &base) in path.iter().enumerate() {
            let own = feet_at(holds, &base);
            let points: Vec<Counts> = if k == 0 {
                vec![base]
            } else {
                offsets
                    .iter()
                    .filter_map(|d| shifted(base, d, holds))
                    .filter(|c| *c == base || !same_feet(&feet_at(holds, c), &own))
                    .collect()
            };
            let values = points
                .iter()
                .map(|c| {
                    if *c == base {
                        let st = plan.stances[k];
                        return Value::Exact(Box::new(st), stance_cost(s, &st));
                    }
                    let feet = feet_at(holds, c);
                    if let Some((st, cost)) = known.get(&feet_key(&feet)) {
                        Value::Exact(Box::new(*st), *cost)
                    } else if feet_distances_ok(s, &feet) {
                        Value::Bound(cost_lower_bound(s, &feet))
                    } else {
                        Value::Infeasible
                    }
                })
                .collect();
            let preds = match band.points.last() {
                None => vec![Vec::new()],
                Some(prev) => points
                    .iter()
                    .map(|c| {
                        (0..prev.len())
                            .filter(|&q| is_successor(&prev[q], c))
                            .collect()
                    })
                    .collect(),
            };
            band.points.push(points);
            band.values.push(values);
            band.preds.push(preds);
        }
        band
    }

    /// The cheapest path from the start to the final counts with the values known now
    /// (bounds for unsolved points): the point index at each stance, and the path's cost.
    fn shortest_path(&self) -> Option<(Vec<usize>, f64)> {
        let n = self.points.len();
        let mut best: Vec<Vec<(f64, usize)>> = Vec::with_capacity(n);
        best.push(vec![(self.values[0][0].cost(), 0)]);
        for k in 1..n {
            let layer = (0..self.points[k].len())
                .map(|p| {
                    let own = self.values[k][p].cost();
                    self.preds[k][p]
                        .iter()
                        .map(|&q| (best[k - 1][q].0 + own, q))
                        .min_by(|a, b| a.0.total_cmp(&b.0))
                        .unwrap_or((f64::INFINITY, 0))
                })
                .collect();
            best.push(layer);
        }
        // The path's own point is first: at the last stance it is the final counts.
        let cost = best[n - 1][0].0;
        if !cost.is_finite() {
            return None;
        }
        let mut at = vec![0; n];
        for k in (1..n).rev() {
            at[k - 1] = best[k][at[k]].1;
        }
        Some((at, cost))
    }
}

/// Smallest foot displacement (m) for which two lattice points of one stance count as
/// different configurations: counts that differ only by moves shorter than this (a
/// robot standing at its goal makes scheduled "moves" of 1e-4 m and less) give the
/// path's own configuration up to a millimetre, so they are left out of the band.
pub const NULL_MOVE: f64 = 1e-3;

/// Whether every foot of `a` is within [`NULL_MOVE`] of its place in `b`.
fn same_feet(a: &Feet, b: &Feet) -> bool {
    Foot::ALL
        .iter()
        .all(|&i| dist2(a.get(i), b.get(i)) < NULL_MOVE * NULL_MOVE)
}

/// Stances solved for given feet (the plan's own, and those solved by the search), by
/// the feet's bit patterns: feet repeat across stances (a robot standing at its goal,
/// scheduled moves that do not displace a foot), and the stance problem depends on the
/// feet only, so each is solved once.
type Known = HashMap<[u64; 12], (Stance, f64)>;

fn feet_key(feet: &Feet) -> [u64; 12] {
    let a = feet.to_array();
    std::array::from_fn(|i| a[i / 3][i % 3].to_bits())
}

/// A lower bound of the stance problem's optimum for `feet`, from (11) and the vertical
/// part of (2) alone: each CoM lies on the circle of points at squared distance
/// `leg_length_sq` from both feet of its biped, so its cost term is at least the squared
/// distance from its goal to that circle; the four vertical forces sum to the robot's
/// weight, so `Σ ‖F_i‖² ≥ (M g)² / 4` (Cauchy–Schwarz). Infinite when a biped's feet are
/// too far apart for its legs.
pub fn cost_lower_bound(s: &Scenario, feet: &Feet) -> f64 {
    let mut com = 0.0;
    for (a, b, goal) in [(feet.br, feet.bl, s.goal.b), (feet.fr, feet.fl, s.goal.f)] {
        let centre: Vec3 = std::array::from_fn(|d| 0.5 * (a[d] + b[d]));
        let ab2 = dist2(a, b);
        let rho2 = s.leg_length_sq - 0.25 * ab2;
        if rho2 < 0.0 || ab2 == 0.0 {
            return f64::INFINITY;
        }
        let len = ab2.sqrt();
        let u: Vec3 = std::array::from_fn(|d| (b[d] - a[d]) / len);
        let v: Vec3 = std::array::from_fn(|d| goal[d] - centre[d]);
        let h = (0..3).map(|d| v[d] * u[d]).sum::<f64>();
        let w = (dist2(v, [0.0; 3]) - h * h).max(0.0).sqrt();
        com += h * h + (w - rho2.sqrt()).powi(2);
    }
    let weight = s.masses.total() * s.gravity;
    s.weights.com * com + s.weights.force * weight * weight / 4.0
}

/// The best schedule with the footholds of `plan` (a plan of `schedule`) within the band
/// around `schedule` (module docs), with its plan; `None` when it does not lower the cost
/// by more than [`MIN_RELATIVE_GAIN`] of it.
///
/// Solved lazily, exactly: the shortest path is computed with lower bounds for the
/// points not solved yet ([`cost_lower_bound`]); the first unsolved point on it is
/// solved (one stance problem per shortest path: the solve often moves the path off the
/// others), and this repeats until the shortest path runs through solved points only.
/// Its cost is then at most that of any other path (their unsolved points cost at least
/// their bounds), so it is the best path of the band, found without solving most of it.
pub fn propose(
    s: &Scenario,
    solver: &mut StanceSolver,
    plan: &Plan,
    schedule: &[Foot],
) -> Option<Proposal> {
    let n = plan.stances.len();
    if n < 2 || schedule.len() != n - 1 {
        return None;
    }
    let holds = footholds(plan, schedule);
    let path = path_counts(schedule);
    let mut known: Known = plan
        .stances
        .iter()
        .skip(1)
        .map(|st| (feet_key(&st.feet), (*st, stance_cost(s, st))))
        .collect();
    let mut band = Band::new(s, plan, &path, &holds, &known);
    let mut evaluated = 0;
    let cost = plan.cost(s);
    // The least cost a proposal must beat to be returned.
    let worth = cost - MIN_RELATIVE_GAIN * cost;
    let at = loop {
        let (at, bound) = band.shortest_path()?;
        // `bound` is a lower bound of the band's best path, and it only grows as points
        // are solved (a solved point costs at least its bound): once it reaches `worth`,
        // no path of the band can be returned and the round stops here.
        if bound >= worth {
            return None;
        }
        // The unsolved points on the path are solved in order, but at most one stance
        // problem per shortest path (points whose feet are known cost nothing): each
        // solve can move the path off the others (a lazy shortest path that evaluates
        // one point at a time; same result, fewer solves).
        let mut open = 0;
        for (k, &p) in at.iter().enumerate() {
            if let Value::Bound(_) = band.values[k][p] {
                open += 1;
                let feet = feet_at(&holds, &band.points[k][p]);
                let key = feet_key(&feet);
                let (solved, fresh) = match known.get(&key) {
                    Some(&(st, c)) => (Some((st, c)), false),
                    None => {
                        evaluated += 1;
                        (solver.solve(s, &feet, &plan.stances[k]), true)
                    }
                };
                band.values[k][p] = match solved {
                    Some((st, c)) => {
                        known.insert(key, (st, c));
                        Value::Exact(Box::new(st), c)
                    }
                    None => Value::Infeasible,
                };
                if fresh {
                    break;
                }
            }
        }
        if open == 0 {
            break at;
        }
    };
    let mut stances = Vec::with_capacity(n);
    for (k, &p) in at.iter().enumerate() {
        let Value::Exact(st, _) = &band.values[k][p] else {
            return None;
        };
        stances.push(**st);
    }
    let new_schedule: Vec<Foot> = (1..n)
        .map(|k| {
            let (a, b) = (&band.points[k - 1][at[k - 1]], &band.points[k][at[k]]);
            Foot::ALL[(0..4).find(|&i| a[i] != b[i]).unwrap_or(0)]
        })
        .collect();
    let new_plan = Plan { stances };
    if !within_com_travel(s, &new_plan) {
        return None;
    }
    let gain = cost - new_plan.cost(s);
    if gain <= MIN_RELATIVE_GAIN * cost {
        return None;
    }
    let changed = (0..n)
        .filter(|&k| new_plan.stances[k] != plan.stances[k])
        .count();
    Some(Proposal {
        schedule: new_schedule,
        plan: new_plan,
        gain,
        changed,
        evaluated,
    })
}

/// Whether every CoM of `plan` moves at most the scenario's `motion.com_travel_max` per
/// transition, within the checker's tolerance (true when no limit is set): the stance
/// problems are solved one by one, so the limit, which links two stances, is checked on
/// the path chosen.
fn within_com_travel(s: &Scenario, plan: &Plan) -> bool {
    let Some(t) = s.motion.com_travel_max else {
        return true;
    };
    plan.stances.windows(2).all(|w| {
        crate::scenario::Biped::ALL
            .iter()
            .all(|&j| dist2(w[0].com.get(j), w[1].com.get(j)).sqrt() <= t + crate::check::TOL)
    })
}

/// `base + d` when every count stays within its foot's footholds.
fn shifted(base: Counts, d: &[i64; 4], holds: &[Vec<Vec3>; 4]) -> Option<Counts> {
    let mut c = [0; 4];
    for i in 0..4 {
        let v = base[i] as i64 + d[i];
        if v < 0 || v >= holds[i].len() as i64 {
            return None;
        }
        c[i] = v as usize;
    }
    Some(c)
}

/// Whether `next` is `prev` with exactly one count one higher.
fn is_successor(prev: &Counts, next: &Counts) -> bool {
    let mut ups = 0;
    for i in 0..4 {
        match next[i] as i64 - prev[i] as i64 {
            0 => {}
            1 => ups += 1,
            _ => return false,
        }
    }
    ups == 1
}

/// The feet at lattice point `c`.
fn feet_at(holds: &[Vec<Vec3>; 4], c: &Counts) -> Feet {
    Feet::from_array(std::array::from_fn(|i| holds[i][c[i]]))
}
