//! What no plan can do, proved from the geometry: certificates that a goal is
//! unreachable.
//!
//! Two facts bound every plan, whatever the solver does:
//! - a foot moves at most `r = √step_radius_sq` (0.3 m) per transition, in 3-D, hence at
//!   most `r` horizontally (5);
//! - at the end, each CoM is within `GOAL_TOL` (0.05 m) of its goal and each foot within
//!   `√leg_length_sq` of its CoM (11), so each foot ends within
//!   `ρ = √leg_length_sq + GOAL_TOL` of its biped's goal CoM.
//!
//! [`uncrossable`]: a foot stands only in the terrain's allowed regions, and can step
//! from one region to another only when their horizontal distance is below `r` (at
//! distance ≥ r a step would need `‖Δr‖ ≥ r`; the spec counts equality as not crossable,
//! see docs/gap-crossing.md). If no point of the ground over a region reachable that way
//! from a foot's start comes within `ρ` of its goal CoM (3-D: [`Terrain::distance_from`],
//! with the ground's height range where the terrain bounds it), no plan reaches the goal.
//! For the spec's gap this is "the keep-out zone (gap plus both margins) is at least as
//! wide as the step reach"; on a height map (one region, the grid's rectangle) it is "the
//! goal CoM is farther than ρ from the ground", e.g. a goal 1.5 m above a flat map.
//!
//! A continuous surface has no rise certificate for a single step: however steep, it can
//! be climbed in steps shorter than `r`. What a height map's rises and drops do bound is
//! the height of the final feet (the goal CoM high above the highest ground needs feet
//! on ground within ρ in 3-D, above) and the moves (below: the 3-D distance from a foot's
//! start to its goal CoM, and `h_top` = the largest height on the map). The heights and
//! slopes of a height map are bounded cell by cell by the Bernstein coefficients of its
//! bicubic pieces (`terrain::HeightMap`), which also gives the slope bound of
//! [`force_threshold`].
//!
//! [`stances_needed`]: each foot needs at least `⌈(‖start − goal CoM‖ − ρ)/r⌉` moves
//! and one foot moves per transition (10), so `1 + Σ` moves stances at least. Sharper,
//! when the terrain's height is bounded above by `h_top` (`Terrain::height_bound`: 0
//! for gaps and stones, the rise of a step up; a height map's largest height) and the goal CoM
//! is more than `GOAL_TOL` above it: the final CoM is at least `a = z_goal − GOAL_TOL −
//! h_top` above the final foot, which is at `√leg_length_sq` from it, so the foot ends
//! within `√(leg_length_sq − a²)` of the CoM horizontally and within
//! `ρ_h = √(leg_length_sq − a²) + GOAL_TOL` of the goal CoM; a move covers at most `r`
//! horizontally, so the foot needs `⌈(horizontal distance to the goal CoM − ρ_h)/r⌉`
//! moves. The larger of the two counts holds. On the default scenario: a = 0.45 m,
//! ρ_h = 0.5954 m against ρ = 0.7571 m, 9 moves per foot instead of 8, 37 stances
//! instead of 33.
use crate::check::GOAL_TOL;
use crate::footing::Unstandable;
use crate::scenario::{Foot, Scenario};
use crate::terrain::{self, Region, Terrain};
use std::fmt;

/// Tolerance (m) on comparing a distance between allowed regions with the step reach: a
/// keep-out narrower than `reach − WIDTH_TOL` is crossable, one wider is not. Widths
/// are differences of coordinates, so a keep-out typed as exactly the reach (e.g. a gap
/// 2.5–2.74 with 0.03 m margins, 0.2999999999999998 m in binary) must count as the
/// reach itself; 1e-9 m is far above the round-off of such differences for
/// coordinates up to 1e5 m (≈ 1e-11 m) and far below the checker's 1e-6 tolerance.
pub const WIDTH_TOL: f64 = 1e-9;

/// Whether two regions `distance` apart (m) can be stepped between with reach `reach`
/// (the comparison of [`WIDTH_TOL`]).
pub fn within_reach(distance: f64, reach: f64) -> bool {
    distance < reach - WIDTH_TOL
}

/// Proof that a foot cannot reach its goal: the regions it can reach and the step
/// needed to leave them.
#[derive(Clone, Debug, PartialEq)]
pub struct Uncrossable {
    /// The foot.
    pub foot: Foot,
    /// The step reach r (m).
    pub reach: f64,
    /// How close to its goal CoM the foot must end, ρ (m).
    pub need_within: f64,
    /// A lower bound on the 3-D distance from the goal CoM to the points the foot can
    /// stand on (m; [`Terrain::distance_from`]: horizontal, and vertical where the terrain
    /// bounds its heights).
    pub nearest: f64,
    /// The x range covered by the regions the foot can reach (m).
    pub reachable_x: [f64; 2],
    /// A lower bound on the distance from a reachable region to any other region (m;
    /// ≥ reach; 3-D where the terrain bounds its heights), `None` when there is no other
    /// region.
    pub shortest_exit: Option<f64>,
    /// On a height map: the cells no foot can stand on, which split its ground into
    /// regions (`None` on the other terrains; [`crate::footing`]).
    pub unstandable: Option<Unstandable>,
}

impl Uncrossable {
    /// The certificate for `foot` of scenario `s`: the step reach and the goal radius are
    /// `s`'s ([`goal_radius`]), the rest as found by the caller.
    pub fn for_foot(
        s: &Scenario,
        foot: Foot,
        nearest: f64,
        reachable_x: [f64; 2],
        shortest_exit: Option<f64>,
        unstandable: Option<Unstandable>,
    ) -> Uncrossable {
        Uncrossable {
            foot,
            reach: s.step_radius_sq.sqrt(),
            need_within: goal_radius(s),
            nearest,
            reachable_x,
            shortest_exit,
            unstandable,
        }
    }
}

impl fmt::Display for Uncrossable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(u) = &self.unstandable {
            write!(f, "{u}; ")?;
        }
        write!(
            f,
            "foot {} can stand only in x ∈ [{:.4}, {:.4}] m (the regions it can reach from its start)",
            self.foot, self.reachable_x[0], self.reachable_x[1]
        )?;
        if let Some(d) = self.shortest_exit {
            write!(
                f,
                "; the next region is at least {d:.4} m away (3-D, rises and drops included), not less than the step reach {:.4} m",
                self.reach
            )?;
        }
        write!(
            f,
            "; it must end within {:.4} m of its goal CoM (leg + 0.05 m goal tolerance) but can come no closer than {:.4} m (3-D, the ground's heights included)",
            self.need_within, self.nearest
        )
    }
}

/// The lower bound on the stances any plan needs to reach the goal.
#[derive(Clone, Debug, PartialEq)]
pub struct Unreachable {
    /// Stances needed at least: 1 + the sum of `moves`.
    pub needed: usize,
    /// Moves needed at least by each foot, BR, BL, FR, FL.
    pub moves: [usize; 4],
}

impl fmt::Display for Unreachable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "any plan needs at least {} stances (moves per foot at ≤ 0.3 m each: BR {}, BL {}, FR {}, FL {})",
            self.needed, self.moves[0], self.moves[1], self.moves[2], self.moves[3]
        )
    }
}

/// Proof that the normal-force threshold F_thr of (4) cannot be met: every foot pushes
/// with a normal force of at least F_thr, which holds the body up with at least
/// `4·F_thr·(cos θ − μ sin θ)` (θ the steepest ground slope a foot may stand on, the
/// tangential force at most μ times the normal one), more than the weight (2) allows.
#[derive(Clone, Debug, PartialEq)]
pub struct ForceThreshold {
    /// F_thr (N).
    pub f_thr: f64,
    /// The friction coefficient μ.
    pub mu: f64,
    /// Bound on the ground slope tan θ where feet may stand.
    pub slope: f64,
    /// The least total vertical force the four feet exert, `4·(F_thr − TOL)·(cos θ −
    /// μ sin θ)` (N; the checker's tolerance [`crate::check::TOL`] granted per foot).
    pub least_vertical: f64,
    /// The weight (m1 + m2)·g (N).
    pub weight: f64,
}

impl fmt::Display for ForceThreshold {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "each of the 4 feet must push with a normal force of at least F_thr = {} N; with ground slopes up to {:.3e} and μ = {} they hold the body up with at least {:.4} N, more than its weight (m1 + m2)·g = {:.4} N",
            self.f_thr, self.slope, self.mu, self.least_vertical, self.weight
        )
    }
}

/// The [`ForceThreshold`] certificate, or `None` when F_thr can be met as far as this
/// test sees (or the terrain bounds no slope).
pub fn force_threshold(s: &Scenario, terrain: &dyn Terrain) -> Option<ForceThreshold> {
    let slope = terrain.slope_bound()?;
    // cos θ − μ sin θ with tan θ = slope, decreasing in θ.
    let c = (1.0 - s.friction.mu * slope) / slope.hypot(1.0);
    let least_vertical = 4.0 * (s.friction.f_thr - crate::check::TOL) * c;
    let weight = s.masses.total() * s.gravity;
    (c > 0.0 && least_vertical > weight).then_some(ForceThreshold {
        f_thr: s.friction.f_thr,
        mu: s.friction.mu,
        slope,
        least_vertical,
        weight,
    })
}

/// `ρ`: how close to its goal CoM each foot must end (m).
pub fn goal_radius(s: &Scenario) -> f64 {
    s.leg_length_sq.sqrt() + GOAL_TOL
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|d| (a[d] - b[d]).powi(2)).sum::<f64>().sqrt()
}

/// `ρ_h`: how close to its goal CoM each foot must end horizontally, when the terrain's
/// height is bounded by `top` and the goal CoM is more than `GOAL_TOL` above it (module
/// docs); `None` otherwise.
pub fn horizontal_goal_radius(s: &Scenario, goal_z: f64, top: f64) -> Option<f64> {
    let a = goal_z - GOAL_TOL - top;
    (a > 0.0 && a * a < s.leg_length_sq).then(|| (s.leg_length_sq - a * a).sqrt() + GOAL_TOL)
}

/// The lower bound of the module docs on the stances needed to reach the goal.
pub fn stances_needed(s: &Scenario) -> Unreachable {
    let r = s.step_radius_sq.sqrt();
    let rho = goal_radius(s);
    let top = terrain::of(s).height_bound();
    let moves = Foot::ALL.map(|i| {
        let (p, g) = (s.start.feet.get(i), s.goal.get(i.biped()));
        let mut d = dist(p, g) - rho;
        if let Some(rho_h) = top.and_then(|top| horizontal_goal_radius(s, g[2], top)) {
            d = d.max((p[0] - g[0]).hypot(p[1] - g[1]) - rho_h);
        }
        if d <= 0.0 {
            0
        } else {
            (d / r).ceil() as usize
        }
    });
    Unreachable {
        needed: 1 + moves.iter().sum::<usize>(),
        moves,
    }
}

/// The shortest 3-D distance between points standing on regions `a` and `b`, as far as
/// the terrain tells: their horizontal distance and, when the terrain knows the heights
/// over each ([`Terrain::height_range`]), the vertical gap between those ranges (a rise
/// or drop beyond the reach is a certificate too).
pub fn step_distance(terrain: &dyn Terrain, a: &Region, b: &Region) -> f64 {
    let vertical = match (terrain.height_range(a), terrain.height_range(b)) {
        (Some([a0, a1]), Some([b0, b1])) => (b0 - a1).max(a0 - b1).max(0.0),
        _ => 0.0,
    };
    a.distance(b).hypot(vertical)
}

/// Indices of the regions reachable from the region(s) holding `(x, y)`, by steps
/// between regions closer than `reach` ([`step_distance`], [`within_reach`]).
fn reachable(terrain: &dyn Terrain, regions: &[Region], x: f64, y: f64, reach: f64) -> Vec<usize> {
    let mut seen = vec![false; regions.len()];
    let mut stack: Vec<usize> = (0..regions.len())
        .filter(|&k| regions[k].contains(x, y, 1e-9))
        .collect();
    for &k in &stack {
        seen[k] = true;
    }
    while let Some(a) = stack.pop() {
        for b in 0..regions.len() {
            if !seen[b] && within_reach(step_distance(terrain, &regions[a], &regions[b]), reach) {
                seen[b] = true;
                stack.push(b);
            }
        }
    }
    (0..regions.len()).filter(|&k| seen[k]).collect()
}

/// A certificate that some foot cannot reach its goal, or `None` when every foot can
/// (as far as this geometric test sees): on the terrain's regions, then, on a height map,
/// on the ground a foot can stand on ([`crate::footing::uncrossable`]).
pub fn uncrossable(s: &Scenario) -> Option<Uncrossable> {
    let terrain = terrain::of(s);
    let terrain = &*terrain;
    let regions = terrain.regions();
    let reach = s.step_radius_sq.sqrt();
    let rho = goal_radius(s);
    for i in Foot::ALL {
        let p = s.start.feet.get(i);
        let g = s.goal.get(i.biped());
        let ok = reachable(terrain, &regions, p[0], p[1], reach);
        let nearest = ok
            .iter()
            .map(|&k| terrain.distance_from(&regions[k], g))
            .fold(f64::INFINITY, f64::min);
        if nearest <= rho {
            continue;
        }
        let reachable_x = ok.iter().fold([f64::INFINITY, f64::NEG_INFINITY], |a, &k| {
            [a[0].min(regions[k].x[0]), a[1].max(regions[k].x[1])]
        });
        let shortest_exit = ok
            .iter()
            .flat_map(|&a| {
                (0..regions.len())
                    .filter(|b| !ok.contains(b))
                    .map(move |b| (a, b))
            })
            .map(|(a, b)| step_distance(terrain, &regions[a], &regions[b]))
            .min_by(f64::total_cmp);
        return Some(Uncrossable::for_foot(
            s,
            i,
            nearest,
            reachable_x,
            shortest_exit,
            None,
        ));
    }
    crate::footing::uncrossable(s)
}

/// Feet of a plan's last stance `last` that stop before a crossable keep-out zone: the
/// allowed region nearest the foot's goal (its start moved with its biped's CoM
/// displacement) is reachable from its start by steps shorter than the reach, n_step is
/// not below [`stances_needed`], and the foot stands in another allowed region. Each with
/// its horizontal distance from that region (m).
pub fn stopped_before_crossable(s: &Scenario, last: &crate::scenario::Feet) -> Vec<(Foot, f64)> {
    if s.n_step < stances_needed(s).needed {
        return Vec::new();
    }
    let terrain = terrain::of(s);
    let regions = terrain.regions();
    let reach = s.step_radius_sq.sqrt();
    let goals = crate::gait::foot_goals(s);
    let mut out = Vec::new();
    for i in Foot::ALL {
        let (p, g, f) = (s.start.feet.get(i), goals.get(i), last.get(i));
        let Some(target) = (0..regions.len()).min_by(|&a, &b| {
            regions[a]
                .distance_to(g[0], g[1])
                .total_cmp(&regions[b].distance_to(g[0], g[1]))
        }) else {
            continue;
        };
        let d = regions[target].distance_to(f[0], f[1]);
        // A foot in the keep-out itself is the checker's `gap` finding, not this one.
        let standing = regions.iter().any(|r| r.contains(f[0], f[1], 1e-6));
        if standing
            && d > 1e-6
            && reachable(&*terrain, &regions, p[0], p[1], reach).contains(&target)
        {
            out.push((i, d));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default scenario's goal is reachable; its bound is below its 60 stances and
    /// equals the hand count: each foot starts 3.0822 m from its goal CoM
    /// (√(3² + 0.5² + 0.5²)), ρ = √0.5 + 0.05 = 0.7571, ⌈2.3251/0.3⌉ = 8 moves; and
    /// 3.0414 m horizontally (√(3² + 0.5²)), the ground is at most 0 high, so
    /// a = 0.5 − 0.05 = 0.45, ρ_h = √(0.5 − 0.2025) + 0.05 = 0.5954, ⌈2.4460/0.3⌉ = 9
    /// moves: 37 stances.
    #[test]
    fn default_bound_and_no_certificate() {
        let s = Scenario::default();
        assert_eq!(uncrossable(&s), None);
        let rho_h = horizontal_goal_radius(&s, 0.5, 0.0).unwrap();
        assert!((rho_h - (0.2975f64.sqrt() + 0.05)).abs() < 1e-15);
        let b = stances_needed(&s);
        assert_eq!(b.moves, [9, 9, 9, 9]);
        assert_eq!(b.needed, 37);
    }

    /// The horizontal bound follows the terrain's height bound: on a step 0.1 m up with
    /// the goal CoMs 0.6 m high (on the step), a = 0.45 again (9 moves); with them 0.5 m
    /// high, a = 0.35, ρ_h = 0.6644, ⌈2.3770/0.3⌉ = 8 moves (as the 3-D bound); a goal
    /// CoM less than 0.05 m above the highest ground gives no horizontal bound, and the
    /// 3-D one holds.
    #[test]
    fn horizontal_bound_follows_the_terrain_height() {
        let mut s = Scenario::default();
        s.apply_overrides(&[
            "terrain={kind=\"step\", edge=2.3, rise=0.1, steepness=1e6, margin=0.04}",
            "goal.B=[3.0, 0.5, 0.6]",
            "goal.F=[5.0, 0.5, 0.6]",
        ])
        .unwrap();
        assert_eq!(stances_needed(&s).moves, [9, 9, 9, 9]);
        s.goal.b[2] = 0.5;
        s.goal.f[2] = 0.5;
        let rho_h = horizontal_goal_radius(&s, 0.5, 0.1).unwrap();
        assert!((rho_h - (0.5f64 - 0.35 * 0.35).sqrt() - 0.05).abs() < 1e-15);
        assert_eq!(stances_needed(&s).moves, [8, 8, 8, 8]);
        assert_eq!(horizontal_goal_radius(&s, 0.14, 0.1), None);
        s.goal.b[2] = 0.12;
        s.goal.f[2] = 0.12;
        let d = (9.0f64 + 0.25 + 0.12 * 0.12).sqrt() - goal_radius(&s);
        assert_eq!(stances_needed(&s).moves[0], (d / 0.3).ceil() as usize);
    }

    /// A 0.25 m gap with 0.03 m margins is a 0.31 m keep-out: the front feet cannot reach
    /// the far side (0.31 ≥ 0.3); at 0.299 m they can.
    #[test]
    fn keep_out_at_the_reach() {
        let mut s = Scenario::default();
        s.gap.min = 2.5;
        s.gap.max = 2.75;
        let c = uncrossable(&s).expect("certificate");
        assert!((c.shortest_exit.unwrap() - 0.31).abs() < 1e-12, "{c}");
        assert!(c.to_string().contains("0.3100"), "{c}");
        s.gap.max = 2.5 + 0.299 - 0.06;
        assert_eq!(uncrossable(&s), None);
        // Keep-out exactly as wide as the reach (numbers exact in binary: 2.75 − 2.5 =
        // 0.25 = √0.0625): not crossable, as the spec says.
        s.gap.max = 2.75;
        s.gap.margin = 0.0;
        s.step_radius_sq = 0.0625;
        assert!(
            uncrossable(&s).is_some(),
            "keep-out = reach counts as not crossable"
        );
    }

    /// 4·F_thr above the weight (981 N) is a certificate: F_thr = 246 N (984 N) is
    /// refused, 245 N (980 N) is not (the ground's slope where feet stand is below
    /// 3.6e-4 on the default gap: cos θ − μ sin θ > 0.9998).
    #[test]
    fn force_threshold_against_the_weight() {
        let mut s = Scenario::default();
        let t = terrain::of(&s);
        s.friction.f_thr = 245.0;
        assert_eq!(force_threshold(&s, &*t), None);
        s.friction.f_thr = 246.0;
        let c = force_threshold(&s, &*t).expect("certificate");
        assert!(c.least_vertical > 981.0 && c.least_vertical < 984.0, "{c}");
        assert!(c.to_string().contains("981.0000"), "{c}");
    }

    /// A step up of 0.35 m with 0.01 m margins: the regions are 0.02 m apart
    /// horizontally and 0.35 − 2·1.1e-5 m apart vertically (the atan's tails at 0.01 m:
    /// 0.35/(π·1e4)), 0.3505 m in 3-D, beyond the 0.3 m reach; a rise of 0.25 m is
    /// within it.
    #[test]
    fn rise_beyond_the_reach() {
        let mut s = Scenario::default();
        s.apply_overrides(&[
            "terrain={kind=\"step\", edge=2.3, rise=0.35, steepness=1e6, margin=0.01}",
            "goal.B=[3.0, 0.5, 0.85]",
            "goal.F=[5.0, 0.5, 0.85]",
        ])
        .unwrap();
        let c = uncrossable(&s).expect("certificate");
        let d = c.shortest_exit.unwrap();
        let tail = 0.35 / (std::f64::consts::PI * 1e4);
        assert!((d - 0.02f64.hypot(0.35 - 2.0 * tail)).abs() < 1e-9, "{c}");
        s.apply_overrides(&["terrain.rise=0.25"]).unwrap();
        assert_eq!(uncrossable(&s), None);
    }

    /// The default scenario on a height map over x ∈ [−1, 9], y ∈ [−1, 2] (0.5 m grid):
    /// flat (0), nothing is certified and the stance bound is the default's 37 (the map's
    /// height bound is 0, exactly: the Bernstein coefficients of a flat map vanish);
    /// with the back goal CoM 1.5 m above the ground, every foot of the back biped must
    /// end within ρ = 0.7571 m of it but the ground is 1.5 m below it: certified, with
    /// 1.5000 in the message. A 0.6 m plateau from x = 4 on with the front goal CoM 0.5 m
    /// above it (1.1 m) is not certified (it can be climbed in short steps).
    #[test]
    fn height_map_certificates() {
        let map = |h: &dyn Fn(f64) -> f64| -> Scenario {
            let heights = (0..7)
                .map(|_| (0..21).map(|i| h(-1.0 + 0.5 * i as f64)).collect())
                .collect();
            let s = Scenario {
                terrain: crate::scenario::TerrainSpec::HeightMap {
                    file: "test".into(),
                    origin: [-1.0, -1.0],
                    spacing: [0.5, 0.5],
                    heights,
                },
                ..Scenario::default()
            };
            s.validate().unwrap();
            s
        };
        let mut s = map(&|_| 0.0);
        assert_eq!(terrain::of(&s).height_bound(), Some(0.0));
        assert_eq!(uncrossable(&s), None);
        assert_eq!(force_threshold(&s, &*terrain::of(&s)), None);
        assert_eq!(stances_needed(&s).needed, 37);
        s.goal.b[2] = 1.5;
        let c = uncrossable(&s).expect("certificate");
        assert!(matches!(c.foot, Foot::BR | Foot::BL), "{c}");
        assert!((c.nearest - 1.5).abs() < 1e-12, "{c}");
        assert!(c.to_string().contains("no closer than 1.5000 m"), "{c}");
        let mut s = map(&|x| if x >= 4.0 { 0.6 } else { 0.0 });
        s.goal.f[2] = 1.1;
        assert_eq!(uncrossable(&s), None);
    }

    /// Stepping stones out of reach of each other: a start pad x ∈ [−0.5, 2.5] and a goal
    /// pad from x = 2.5 + w on (y ∈ [−0.5, 1.5] both): with w = 0.35 m the front feet
    /// cannot leave the start pad (the next stone is 0.35 m away, beyond the 0.3 m reach):
    /// certified; with w = 0.29 m nothing is.
    #[test]
    fn stones_out_of_reach_of_each_other() {
        let stones = |w: f64| -> Scenario {
            let mut s = Scenario::default();
            s.apply_overrides(&[&format!(
                "terrain={{kind=\"stones\", stones=[[-0.5, 2.5, -0.5, 1.5], [{}, 9.0, -0.5, 1.5]]}}",
                2.5 + w
            )])
            .unwrap();
            s.validate().unwrap();
            s
        };
        let c = uncrossable(&stones(0.35)).expect("certificate");
        assert!((c.shortest_exit.unwrap() - 0.35).abs() < 1e-12, "{c}");
        assert!(c.reachable_x == [-0.5, 2.5], "{c}");
        assert!(c.to_string().contains("at least 0.3500 m away"), "{c}");
        assert_eq!(uncrossable(&stones(0.29)), None);
    }

    /// A keep-out typed as exactly the reach whose width rounds below it (2.74 − 2.5 +
    /// 0.06 = 0.2999999999999998 in binary) is not crossable; one 1e-4 m narrower is.
    #[test]
    fn keep_out_typed_as_the_reach() {
        let mut s = Scenario::default();
        s.gap.min = 2.5;
        s.gap.max = 2.74;
        let width = (s.gap.max + s.gap.margin) - (s.gap.min - s.gap.margin);
        assert!(width < 0.3, "the case of the issue: {width}");
        let c = uncrossable(&s).expect("certificate");
        assert!((c.shortest_exit.unwrap() - 0.3).abs() < 1e-12, "{c}");
        s.gap.max = 2.7399;
        assert_eq!(uncrossable(&s), None);
    }
}
