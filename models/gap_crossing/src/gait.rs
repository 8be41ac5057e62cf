//! Initial guesses and the crawl schedule.
//!
//! Guesses are flat vectors in the layout of [`crate::plan`] (30 numbers per stance).
//! - [`standing`]: every stance equals the start; forces balance gravity.
//! - [`crawl`]: the crawl-gait heuristic (BR, FR, BL, FL, repeated; each move ≤ 0.28 m
//!   toward that foot's goal; a landing that would fall in the keep-out goes to the
//!   point of an allowed region within one jump closest to the goal, see
//!   [`footholds_for_schedule`]), with CoMs that satisfy the leg-length equation (11)
//!   exactly and forces balancing gravity (2). On the spec's default gap it gives the
//!   spec's crawl footholds (its 0.27 m jump limit is never reached there).
//!
//! Feet are always placed on the numeric terrain, z = h(x), so equation (3) holds to
//! rounding even at the steep gap edges (where h is not exactly 0).

use crate::plan::{Plan, Stance};
use crate::reach;
use crate::scenario::{dist2, Biped, Coms, Feet, Foot, Scenario, Vec3};
use crate::terrain::{self, Region, Terrain};
use nalgebra::{DMatrix, DVector, Vector3};

/// The crawl order: transition k (from stance k+1 to k+2, 1-based) moves
/// `CRAWL_ORDER[k % 4]`.
pub const CRAWL_ORDER: [Foot; 4] = [Foot::BR, Foot::FR, Foot::BL, Foot::FL];

/// Longest move of one foot in the crawl heuristic (m); below the 0.3 m step radius.
pub const CRAWL_MAX_MOVE: f64 = 0.28;

/// How far outside the widened gap a foot lands when it is placed "just" before or
/// beyond it (m): small against the 0.03 m margin, large against the 1e-6 tolerance.
pub const GAP_CLEARANCE: f64 = 1e-3;

/// The biped-pair order: both front feet, then both back feet. Of the 24 periodic
/// orders it gave the lowest cost on the default scenario and on every test scenario
/// (about 3 % below [`CRAWL_ORDER`], the highest; see docs/gap-crossing.md).
pub const PAIR_ORDER: [Foot; 4] = [Foot::FR, Foot::FL, Foot::BR, Foot::BL];

/// The schedule repeating [`PAIR_ORDER`], `n_step − 1` entries.
pub fn pair_schedule(n_step: usize) -> Vec<Foot> {
    (0..n_step.saturating_sub(1))
        .map(|k| PAIR_ORDER[k % 4])
        .collect()
}

/// Which foot may move at each transition in the `crawl` gait mode: entry k is the foot
/// allowed to move from stance k to stance k+1 (0-based), `n_step − 1` entries.
pub fn crawl_schedule(n_step: usize) -> Vec<Foot> {
    (0..n_step.saturating_sub(1))
        .map(|k| CRAWL_ORDER[k % 4])
        .collect()
}

/// Each foot's goal: start foot + (goal CoM − start CoM) of its biped.
pub fn foot_goals(s: &Scenario) -> Feet {
    let mut g = s.start.feet;
    for i in Foot::ALL {
        let j = i.biped();
        let (c0, c1) = (s.start.com.get(j), s.goal.get(j));
        let p = g.get_mut(i);
        for a in 0..3 {
            p[a] += c1[a] - c0[a];
        }
    }
    g
}

/// How far below the step reach the guess's longest jump stays at most (m): a jump of
/// `reach − JUMP_SLACK` leaves the solver a little room on (5). When a crossable
/// keep-out is wider than `reach − 2·JUMP_SLACK`, the jump stays half-way between its
/// width and the reach instead (see `Ground::of`).
pub const JUMP_SLACK: f64 = 1e-4;

/// The landing rule's view of the terrain: its allowed regions, the jump length and the
/// clearance kept from region edges.
struct Ground {
    terrain: Box<dyn Terrain>,
    regions: Vec<Region>,
    jump: f64,
    clearance: f64,
}

impl Ground {
    fn of(s: &Scenario) -> Ground {
        let terrain = terrain::of(s);
        let regions = terrain.regions();
        let reach = s.step_radius_sq.sqrt();
        // The widest distance between two regions that a step can span
        // (`reach::within_reach`): the jump is long enough for it, and landings keep
        // [`GAP_CLEARANCE`] from region edges, less when that jump would not fit.
        let widest = regions
            .iter()
            .enumerate()
            .flat_map(|(a, ra)| regions[a + 1..].iter().map(move |rb| ra.distance(rb)))
            .filter(|&d| d > 0.0 && reach::within_reach(d, reach))
            .fold(0.0, f64::max);
        let jump = reach - JUMP_SLACK.min((reach - widest) / 2.0);
        let clearance = GAP_CLEARANCE.min((jump - widest) / 4.0);
        Ground {
            terrain,
            regions,
            jump,
            clearance,
        }
    }

    fn on(&self, x: f64, y: f64) -> Vec3 {
        [x, y, self.terrain.height_at(x, y)]
    }

    /// Where a foot at `cur` heading for `goal` lands (see [`footholds_for_schedule`]).
    fn landing(&self, cur: Vec3, goal: Vec3) -> Vec3 {
        let (dx, dy) = (goal[0] - cur[0], goal[1] - cur[1]);
        let dist = dx.hypot(dy);
        if dist < 1e-12 {
            return cur;
        }
        let t = dist.min(CRAWL_MAX_MOVE);
        let (px, py) = (cur[0] + dx / dist * t, cur[1] + dy / dist * t);
        if self.regions.iter().any(|r| r.contains(px, py, 0.0)) {
            return self.on(px, py);
        }
        // The straight move ends in the keep-out: among the points of every region
        // within one jump, the one closest to the goal (this region's edge when no other
        // region is within reach: the foot walks up to the gap and jumps next time).
        let mut best: Option<(f64, Vec3)> = None;
        for r in &self.regions {
            if let Some(q) = self.jump_into(r, cur, goal) {
                let d = (q[0] - goal[0]).hypot(q[1] - goal[1]);
                if best.is_none_or(|(b, _)| d < b) {
                    best = Some((d, q));
                }
            }
        }
        best.map_or(cur, |(_, q)| q)
    }

    /// The point of region `r` (shrunk by the clearance) within one jump of `cur`
    /// (3-D distance) closest to `goal` horizontally, if any.
    fn jump_into(&self, r: &Region, cur: Vec3, goal: Vec3) -> Option<Vec3> {
        let mut radius = self.jump;
        let mut q = None;
        // The disc's radius in x–y depends on the height difference at the landing.
        for _ in 0..3 {
            let p = project_box_disc(
                r,
                self.clearance,
                [cur[0], cur[1]],
                radius,
                [goal[0], goal[1]],
            )?;
            let landing = self.on(p[0], p[1]);
            let dz = landing[2] - cur[2];
            q = Some(landing);
            if dz.abs() >= self.jump {
                return None;
            }
            radius = (self.jump * self.jump - dz * dz).sqrt();
        }
        q.filter(|q| dist2(*q, cur).sqrt() <= self.jump + 1e-9)
    }
}

/// The projection of `g` onto the box `r` (shrunk by `inset`) intersected with the disc
/// of `radius` about `c`, by Dykstra's alternating projections (which converge to the
/// projection onto an intersection of convex sets); `None` when they do not meet.
fn project_box_disc(
    r: &Region,
    inset: f64,
    c: [f64; 2],
    radius: f64,
    g: [f64; 2],
) -> Option<[f64; 2]> {
    let disc = |p: [f64; 2]| {
        let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
        let d = dx.hypot(dy);
        if d <= radius {
            p
        } else {
            [c[0] + dx * radius / d, c[1] + dy * radius / d]
        }
    };
    let (mut x, mut p, mut q) = (g, [0.0; 2], [0.0; 2]);
    for _ in 0..400 {
        let y = r.clamp(x[0] + p[0], x[1] + p[1], inset);
        p = [x[0] + p[0] - y[0], x[1] + p[1] - y[1]];
        let nx = disc([y[0] + q[0], y[1] + q[1]]);
        q = [y[0] + q[0] - nx[0], y[1] + q[1] - nx[1]];
        x = nx;
    }
    let y = r.clamp(x[0], x[1], inset);
    ((y[0] - c[0]).hypot(y[1] - c[1]) <= radius + 1e-12).then_some(y)
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

/// The crawl heuristic's footholds: `n_step` foot configurations, the first the start;
/// at each transition only the scheduled foot ([`crawl_schedule`]) moves.
pub fn crawl_footholds(s: &Scenario) -> Vec<Feet> {
    footholds_for_schedule(s, &crawl_schedule(s.n_step))
}

/// The landing rule with any schedule: at transition k only `schedule[k]` moves,
/// ≤ [`CRAWL_MAX_MOVE`] straight toward its goal when that lands in an allowed region of
/// the terrain; otherwise it lands on the point, among all regions' points within one
/// jump (`reach − JUMP_SLACK`, 3-D, kept [`GAP_CLEARANCE`] or less inside the region),
/// closest to its goal: beyond the keep-out when it can get there, else on the near
/// edge, from where it jumps at its next move, in any direction (a lateral goal makes a
/// diagonal approach). This is the crossing decision: the first move from which another
/// region is reachable crosses (the earliest crossing stance of each foot).
/// `schedule.len() + 1` foot configurations, the first the start.
pub fn footholds_for_schedule(s: &Scenario, schedule: &[Foot]) -> Vec<Feet> {
    let ground = Ground::of(s);
    let goals = foot_goals(s);
    let mut out = Vec::with_capacity(schedule.len() + 1);
    let mut feet = s.start.feet;
    out.push(feet);
    for &foot in schedule {
        let cur = feet.get(foot);
        let p = ground.landing(cur, goals.get(foot));
        // A landing that would break (6)–(9) with the other feet (feet converging on a
        // region's corner when the goal lies diagonally past it) is not taken while
        // the feet satisfy them: the foot stays, and moves at a later turn.
        let mut next = feet;
        *next.get_mut(foot) = p;
        if feet_distances_ok(s, &next) || !feet_distances_ok(s, &feet) {
            feet = next;
        }
        out.push(feet);
    }
    out
}

/// A CoM at squared distance `leg_length_sq` from both feet of its biped: above the
/// feet's midpoint, perpendicular to the segment joining them, as high as possible.
/// (When the feet are too far apart for any such point, the midpoint.)
pub fn com_over(s: &Scenario, a: Vec3, b: Vec3) -> Vec3 {
    let (a, b) = (Vector3::from(a), Vector3::from(b));
    let mid = (a + b) / 2.0;
    let half = (b - a).norm() / 2.0;
    let h = (s.leg_length_sq - half * half).max(0.0).sqrt();
    let z = Vector3::z();
    let up = if half > 0.0 {
        let e = (b - a).normalize();
        let u = z - e * z.dot(&e);
        if u.norm() > 1e-12 {
            u.normalize()
        } else {
            z
        }
    } else {
        z
    };
    (mid + up * h).into()
}

/// CoMs for a foot configuration, by [`com_over`] for each biped.
pub fn coms_for(s: &Scenario, feet: &Feet) -> Coms {
    let c = |j: Biped| {
        let [p, q] = j.feet();
        com_over(s, feet.get(p), feet.get(q))
    };
    Coms {
        b: c(Biped::B),
        f: c(Biped::F),
    }
}

/// Forces balancing gravity (2): the minimum-norm solution of the six balance equations
/// (which also minimises the force term of the cost (1)). For a symmetric stance this is
/// an equal vertical share, (m1 + m2) g / 4 per foot. Friction cones are not enforced.
pub fn balance_forces(s: &Scenario, coms: &Coms, feet: &Feet) -> Feet {
    let m = s.masses.total();
    let w = (Vector3::from(coms.b) * s.masses.b + Vector3::from(coms.f) * s.masses.f) / m;
    let mut a = DMatrix::<f64>::zeros(6, 12);
    for (c, i) in Foot::ALL.iter().enumerate() {
        let d = Vector3::from(feet.get(*i)) - w;
        for r in 0..3 {
            a[(r, 3 * c + r)] = 1.0;
        }
        // d × F = skew(d) F
        let sk = d.cross_matrix();
        for r in 0..3 {
            for q in 0..3 {
                a[(3 + r, 3 * c + q)] = sk[(r, q)];
            }
        }
    }
    let g = s.gravity_vector();
    let b = DVector::from_vec(vec![-m * g[0], -m * g[1], -m * g[2], 0.0, 0.0, 0.0]);
    let f = match a.clone().pseudo_inverse(1e-12) {
        Ok(p) => p * b,
        Err(_) => DVector::zeros(12),
    };
    Feet::from_array(std::array::from_fn(|c| {
        [f[3 * c], f[3 * c + 1], f[3 * c + 2]]
    }))
}

/// A plan from foot configurations: stance 1 takes the scenario's start CoMs, later
/// stances [`coms_for`]; forces from [`balance_forces`].
pub fn plan_for_footholds(s: &Scenario, footholds: &[Feet]) -> Plan {
    let stances = footholds
        .iter()
        .enumerate()
        .map(|(k, feet)| {
            let com = if k == 0 {
                s.start.com
            } else {
                coms_for(s, feet)
            };
            Stance {
                com,
                feet: *feet,
                forces: balance_forces(s, &com, feet),
            }
        })
        .collect();
    Plan { stances }
}

/// Standing-still guess: every stance is the start, forces balance gravity
/// ([`balance_forces`]; for the default start, (m1 + m2)·9.81/4 N vertical per foot).
pub fn standing(s: &Scenario) -> Vec<f64> {
    let forces = balance_forces(s, &s.start.com, &s.start.feet);
    let st = Stance {
        com: s.start.com,
        feet: s.start.feet,
        forces,
    };
    Plan {
        stances: vec![st; s.n_step],
    }
    .to_flat()
}

/// The crawl-gait heuristic as a plan ([`crawl_footholds`], [`plan_for_footholds`]).
pub fn crawl_plan(s: &Scenario) -> Plan {
    plan_for_footholds(s, &crawl_footholds(s))
}

/// Crawl-gait guess as a flat vector.
pub fn crawl(s: &Scenario) -> Vec<f64> {
    crawl_plan(s).to_flat()
}

/// Number of transitions the crawl heuristic needs before both CoMs are within `tol` of
/// their goals (searching up to `limit` stances), or `None`.
pub fn crawl_stances_to_goal(s: &Scenario, tol: f64, limit: usize) -> Option<usize> {
    let long = Scenario {
        n_step: limit,
        ..s.clone()
    };
    let feet = crawl_footholds(&long);
    feet.iter()
        .position(|f| {
            let c = coms_for(s, f);
            Biped::ALL
                .iter()
                .all(|&j| dist2(c.get(j), s.goal.get(j)).sqrt() <= tol)
        })
        .map(|k| k + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_is_br_fr_bl_fl() {
        assert_eq!(
            crawl_schedule(6),
            vec![Foot::BR, Foot::FR, Foot::BL, Foot::FL, Foot::BR]
        );
        assert!(crawl_schedule(1).is_empty());
    }

    #[test]
    fn pair_schedule_is_fr_fl_br_bl() {
        assert_eq!(
            pair_schedule(6),
            vec![Foot::FR, Foot::FL, Foot::BR, Foot::BL, Foot::FR]
        );
    }

    /// The crawl heuristic is the landing rule with the crawl schedule; with another
    /// schedule only the scheduled foot moves at each transition.
    #[test]
    fn footholds_follow_the_schedule() {
        let s = Scenario::default();
        assert_eq!(
            footholds_for_schedule(&s, &crawl_schedule(s.n_step)),
            crawl_footholds(&s)
        );
        let pair = pair_schedule(s.n_step);
        let f = footholds_for_schedule(&s, &pair);
        for (t, &foot) in pair.iter().enumerate() {
            for i in Foot::ALL {
                if i != foot {
                    assert_eq!(f[t].get(i), f[t + 1].get(i));
                }
            }
        }
    }

    #[test]
    fn standing_default_has_equal_vertical_forces() {
        let s = Scenario::default();
        let x = standing(&s);
        assert_eq!(x.len(), 30 * 60);
        let p = Plan::from_flat(&s, &x).unwrap();
        let share = 100.0 * 9.81 / 4.0;
        for f in p.stances[7].forces.to_array() {
            // Pseudo-inverse rounding: 1e-9 N against forces of 245 N.
            assert!((f[2] - share).abs() < 1e-9 && f[0].abs() < 1e-9 && f[1].abs() < 1e-9);
        }
    }

    #[test]
    fn com_over_keeps_legs_rigid() {
        let s = Scenario::default();
        let c = com_over(&s, [0.1, 0.0, 0.0], [0.0, 1.0, -1e-5]);
        assert!((dist2(c, [0.1, 0.0, 0.0]) - 0.5).abs() < 1e-12);
        assert!((dist2(c, [0.0, 1.0, -1e-5]) - 0.5).abs() < 1e-12);
        assert!(c[2] > 0.4);
    }
}
