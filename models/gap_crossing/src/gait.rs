//! Initial guesses and the crawl schedule.
//!
//! Guesses are flat vectors in the layout of [`crate::plan`] (30 numbers per stance).
//! - [`standing`]: every stance equals the start; forces balance gravity.
//! - [`crawl`]: the spec's crawl-gait heuristic (BR, FR, BL, FL, repeated; each move
//!   ≤ 0.28 m toward that foot's goal; a landing that would fall in the widened gap goes
//!   just beyond it when that is within 0.27 m, else just before it), with CoMs that
//!   satisfy the leg-length equation (11) exactly and forces balancing gravity (2).
//!
//! Feet are always placed on the numeric terrain, z = h(x), so equation (3) holds to
//! rounding even at the steep gap edges (where h is not exactly 0).

use crate::plan::{Plan, Stance};
use crate::scenario::{dist2, Biped, Coms, Feet, Foot, Scenario, Vec3};
use nalgebra::{DMatrix, DVector, Vector3};

/// The crawl order: transition k (from stance k+1 to k+2, 1-based) moves
/// `CRAWL_ORDER[k % 4]`.
pub const CRAWL_ORDER: [Foot; 4] = [Foot::BR, Foot::FR, Foot::BL, Foot::FL];

/// Longest move of one foot in the crawl heuristic (m); below the 0.3 m step radius.
pub const CRAWL_MAX_MOVE: f64 = 0.28;

/// Longest jump across the widened gap the heuristic attempts (m).
pub const CRAWL_MAX_JUMP: f64 = 0.27;

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

/// Where the crawl heuristic puts foot at `cur` when it moves toward `goal` (xy
/// direction; z on the terrain).
fn crawl_landing(s: &Scenario, cur: Vec3, goal: Vec3) -> Vec3 {
    let (dx, dy) = (goal[0] - cur[0], goal[1] - cur[1]);
    let dist = dx.hypot(dy);
    if dist < 1e-12 {
        return cur;
    }
    let (ux, uy) = (dx / dist, dy / dist);
    let at = |t: f64| -> Vec3 {
        let x = cur[0] + ux * t;
        [x, cur[1] + uy * t, s.gap.height(x)]
    };
    let land = at(dist.min(CRAWL_MAX_MOVE));
    if !s.gap.in_keep_out(land[0]) {
        return land;
    }
    // The landing falls in the widened gap; the foot moves along x (ux ≠ 0, since the
    // foot itself is outside the gap).
    let (lo, hi) = s.gap.keep_out();
    let (far, near) = if ux > 0.0 {
        (hi + GAP_CLEARANCE, lo - GAP_CLEARANCE)
    } else {
        (lo - GAP_CLEARANCE, hi + GAP_CLEARANCE)
    };
    let beyond = at((far - cur[0]) / ux);
    if dist2(beyond, cur).sqrt() <= CRAWL_MAX_JUMP {
        return beyond;
    }
    let t = (near - cur[0]) / ux;
    if t > 0.0 {
        at(t)
    } else {
        cur
    }
}

/// The crawl heuristic's footholds: `n_step` foot configurations, the first the start;
/// at each transition only the scheduled foot ([`crawl_schedule`]) moves.
pub fn crawl_footholds(s: &Scenario) -> Vec<Feet> {
    footholds_for_schedule(s, &crawl_schedule(s.n_step))
}

/// The crawl heuristic's landing rule with any schedule: at transition k only
/// `schedule[k]` moves, ≤ [`CRAWL_MAX_MOVE`] toward its goal, jumping the widened gap as
/// in [`crawl_footholds`]. `schedule.len() + 1` foot configurations, the first the start.
pub fn footholds_for_schedule(s: &Scenario, schedule: &[Foot]) -> Vec<Feet> {
    let goals = foot_goals(s);
    let mut out = Vec::with_capacity(schedule.len() + 1);
    let mut feet = s.start.feet;
    out.push(feet);
    for &foot in schedule {
        let p = crawl_landing(s, feet.get(foot), goals.get(foot));
        *feet.get_mut(foot) = p;
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
