//! Where a foot cannot stand on a height map, and whether the ground it can stand on
//! joins its start to its goal: the height-map analogue of "gap wider than the reach".
//!
//! A height map is one continuous surface, so rises and drops alone never stop a foot (it
//! climbs anything in steps shorter than the reach). What can is friction: a foot on a
//! cell whose slope pushes it sideways harder than the other three feet's friction can
//! hold cannot bear its share of the normal force F_thr of (4). The test, per cell and
//! per horizontal direction `d` (±x, ±y), uses only bounds that hold over the whole cell
//! (the Bernstein ranges of `∂h/∂x`, `∂h/∂y` and `‖∇h‖`, `terrain::HeightMap`):
//!
//! - foot 1 on the cell, with normal `n₁` and normal force `f₁ ≥ F_thr`, pushes the body
//!   along `d` with at least `f₁ q₁`, `q₁ = p₁ − μ√(1 − p₁²)`, `p₁` a lower bound of
//!   `n₁·d` (its tangential force, at most `μ f₁`, cancels at most `μ f₁ √(1 − (n₁·d)²)`);
//!   and its vertical force is at least `f₁ c₁`, `c₁ = (1 − μ S₁)/√(1 + S₁²)`, `S₁` the
//!   cell's slope bound;
//! - any other foot j, on any cell of the map, pushes against `d` with at most `R` times
//!   its vertical force, `R` the largest over the map's cells of
//!   `(upper bound of n_j·(−d) + μ)/c_j` (0 for cells that cannot push against `d`); this
//!   needs `c_j > 0` on every cell (every slope below 1/μ, so every vertical force is
//!   positive): otherwise nothing is certified;
//! - the horizontal balance (2) along `d` then needs `f₁ q₁ ≤ R (W − f₁ c₁)` (the other
//!   feet carry the weight `W` less foot 1's vertical force), impossible with
//!   `f₁ ≥ F_thr` when `F_thr (q₁ + R c₁) > R W` (with `F_thr` less the checker's 1e-6 and
//!   [`SLACK`] on the right for its tolerances on (2) and (4)).
//!
//! The moment balance and the other feet's own thresholds are left out: the test only
//! gets weaker, never wrong. With the spec's μ = 0.5 and F_thr = 10 N it certifies no
//! cell (on flat ground around, R ≥ μ, so it needs F_thr above μW/(1 − μ²) ≈ 654 N, far
//! beyond the 245 N at which [`crate::reach::force_threshold`] already refuses): steep
//! ground is unstandable only with little friction and a high threshold (e.g. μ = 0.1,
//! F_thr ≥ 165 N on a 3.3 slope).
//!
//! The standable cells are then joined when the 3-D distance between their boxes, with
//! their height ranges, is below the step reach ([`crate::reach::within_reach`]); a foot
//! reaches the cells within the reach of its start, and their components. If none of
//! them comes within ρ of the foot's goal CoM, no plan exists ([`uncrossable`]).
use crate::check::TOL;
use crate::reach::{goal_radius, within_reach, Uncrossable};
use crate::scenario::{Foot, Scenario, TerrainSpec};
use crate::terrain::{CellBounds, HeightMap};
use std::fmt;

/// Slack (N) on the balance along a direction, for the checker's tolerance 1e-6 on each
/// of the equations (2) and the cones (4) it sums (a few times 1e-6 N); 1e-3 N is far
/// above those and far below the forces that decide (hundreds of newtons).
pub const SLACK: f64 = 1e-3;

/// The cells of a height map no foot can stand on, with the numbers that prove it.
#[derive(Clone, Debug, PartialEq)]
pub struct Unstandable {
    /// Cells of the map.
    pub cells: usize,
    /// Cells no foot can stand on.
    pub unstandable: usize,
    /// The least lower bound of the slope `‖∇h‖` over those cells.
    pub least_slope: f64,
    /// The friction coefficient μ.
    pub mu: f64,
    /// F_thr (N).
    pub f_thr: f64,
    /// The weight (m1 + m2)·g (N).
    pub weight: f64,
    /// The largest force (N per N of vertical force) the other feet can push with
    /// against a direction an unstandable cell pushes along (`R`, module docs).
    pub ratio: f64,
}

impl fmt::Display for Unstandable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} of the height map's {} cells cannot hold a foot: their slope is at least {:.4}, where a normal force of F_thr = {} N with μ = {} pushes the body sideways more than the other feet can hold back (at most {:.4} N per N of their vertical load, which is at most the weight {:.4} N)",
            self.unstandable, self.cells, self.least_slope, self.f_thr, self.mu, self.ratio, self.weight
        )
    }
}

/// Upper bound of `u/√(1 + u² + v²)` for `u ≤ u_hi` and `|v|` in `[v_lo, v_hi]`
/// (increasing in `u`; `|v|` lowers a positive value, raises a negative one).
fn upper_ratio(u_hi: f64, [v_lo, v_hi]: [f64; 2]) -> f64 {
    let v = if u_hi >= 0.0 { v_lo } else { v_hi };
    u_hi / (1.0 + u_hi * u_hi + v * v).sqrt()
}

/// `[min, max]` of `|v|` over `v ∈ [a, b]`.
fn abs_range([a, b]: [f64; 2]) -> [f64; 2] {
    let hi = a.abs().max(b.abs());
    let lo = if a <= 0.0 && b >= 0.0 {
        0.0
    } else {
        a.abs().min(b.abs())
    };
    [lo, hi]
}

/// Bounds on the unit normal's components along the four directions `+x, −x, +y, −y`
/// over a box where `∂h/∂x ∈ grad[0]`, `∂h/∂y ∈ grad[1]`: for each `d`,
/// `[lower bound of n·d, upper bound of n·d]`. With `n = (−∇h, 1)/N`, `n·(±e_x) = ∓h_x/N`.
fn normal_along([gx, gy]: [[f64; 2]; 2]) -> [[f64; 2]; 4] {
    let (ax, ay) = (abs_range(gx), abs_range(gy));
    // n·d takes the values u/√(1 + u² + v²) with u ∈ [lo, hi] and |v| in `other`.
    let along =
        |lo: f64, hi: f64, other: [f64; 2]| [-upper_ratio(-lo, other), upper_ratio(hi, other)];
    [
        along(-gx[1], -gx[0], ay),
        along(gx[0], gx[1], ay),
        along(-gy[1], -gy[0], ax),
        along(gy[0], gy[1], ax),
    ]
}

/// `c(S) = (1 − μS)/√(1 + S²)`: a lower bound of `n_z − μ√(1 − n_z²)` on a box with slope
/// bound `S` (decreasing in the slope).
fn least_vertical(mu: f64, slope: f64) -> f64 {
    (1.0 - mu * slope) / slope.hypot(1.0)
}

/// Whether the friction test can certify anything where some ground lets a foot push
/// back with μ per newton: `F_thr (1 + μ) > μ W` ([`unstandable_cells`]).
fn worth_trying(s: &Scenario) -> bool {
    let (mu, weight) = (s.friction.mu, s.masses.total() * s.gravity);
    (s.friction.f_thr - TOL) * (1.0 + mu) > mu * weight
}

/// Sub-cells per cell side for the friction test's bounds ([`HeightMap`]'s
/// `sub_cell_gradients`): 4 × 4, so that the Bernstein ranges of the gradient are 16
/// times tighter than the cell's own (at a ramp's foot a cell's own range of `∂h/∂x`
/// reaches −0.29 where the surface's is about −0.02).
pub const SUB_CELLS: usize = 4;

/// What the friction test knows of one sub-cell: the normal's bounds along each
/// direction ([`normal_along`]) and the least vertical force per newton of normal force.
struct Foothold {
    normal: [[f64; 2]; 4],
    vertical: f64,
}

/// Which cells of `map` no foot can stand on under `s`'s friction, F_thr and weight
/// (module docs), with the certificate's numbers; `None` when no cell is certified. The
/// test is tried only when `F_thr (1 + μ) > μ W`, the least it needs wherever some
/// ground lets a foot push back with μ per newton (below it, it certifies nothing on
/// such maps and is skipped: the spec's μ = 0.5, F_thr = 10 N never pay for it).
pub fn unstandable_cells(s: &Scenario, map: &HeightMap) -> Option<(Vec<bool>, Unstandable)> {
    if !worth_trying(s) {
        return None;
    }
    let (mu, weight) = (s.friction.mu, s.masses.total() * s.gravity);
    let f_thr = s.friction.f_thr - TOL;
    let holds: Vec<Vec<Foothold>> = map
        .sub_cell_gradients(SUB_CELLS)
        .into_iter()
        .map(|subs| {
            subs.into_iter()
                .map(|(grad, slope)| Foothold {
                    normal: normal_along(grad),
                    vertical: least_vertical(mu, slope),
                })
                .collect()
        })
        .collect();
    if holds.iter().flatten().any(|h| h.vertical <= 0.0) {
        return None;
    }
    // R per direction d: the others push against d (along −d, whose index is d ^ 1).
    let ratio: [f64; 4] = std::array::from_fn(|d| {
        holds
            .iter()
            .flatten()
            .map(|h| (h.normal[d ^ 1][1] + mu) / h.vertical)
            .fold(0.0, f64::max)
    });
    // Foot 1 cannot stand on the sub-cell when, along some d, the balance fails.
    let fails = |h: &Foothold| {
        (0..4).find(|&d| {
            let (p, r) = (h.normal[d][0], ratio[d]);
            let q = p - mu * (1.0 - p * p).max(0.0).sqrt();
            p > 0.0 && q > 0.0 && f_thr * (q + r * h.vertical) > r * weight + SLACK * (1.0 + r)
        })
    };
    let cells = map.cells();
    let mut out = vec![false; cells.len()];
    let (mut count, mut least_slope, mut used) = (0, f64::INFINITY, 0.0f64);
    for (k, subs) in holds.iter().enumerate() {
        let dirs: Option<Vec<usize>> = subs.iter().map(fails).collect();
        if let Some(dirs) = dirs {
            out[k] = true;
            count += 1;
            let [gx, gy] = cells[k].grad;
            least_slope = least_slope.min(abs_range(gx)[0].hypot(abs_range(gy)[0]));
            used = dirs.iter().fold(used, |u, &d| u.max(ratio[d]));
        }
    }
    (count > 0).then(|| {
        let cert = Unstandable {
            cells: cells.len(),
            unstandable: count,
            least_slope,
            mu,
            f_thr: s.friction.f_thr,
            weight,
            ratio: used,
        };
        (out, cert)
    })
}

/// A lower bound on the 3-D distance between points standing on cells `a` and `b`.
fn cell_distance(a: &CellBounds, b: &CellBounds) -> f64 {
    let vertical = (b.h[0] - a.h[1]).max(a.h[0] - b.h[1]).max(0.0);
    a.box_.distance(&b.box_).hypot(vertical)
}

/// A lower bound on the 3-D distance from `p` to the ground over cell `c`.
fn point_distance(c: &CellBounds, p: [f64; 3]) -> f64 {
    let vertical = (c.h[0] - p[2]).max(p[2] - c.h[1]).max(0.0);
    c.box_.distance_to(p[0], p[1]).hypot(vertical)
}

/// The standable cells joined by steps shorter than `reach`: a component label per cell
/// (`usize::MAX` for unstandable ones).
struct Components {
    label: Vec<usize>,
    window: Window,
    /// The least horizontal distance between cells farther apart than the window (m).
    beyond: f64,
}

/// The cells a step from a cell can reach at most: a window of cells around it.
#[derive(Clone, Copy)]
struct Window {
    /// Cells along x and y.
    n: [usize; 2],
    /// Half-width of the window along x and y (cells).
    half: [usize; 2],
}

impl Window {
    /// The cells within the window around cell `a` (row-major index).
    fn around(self, a: usize) -> impl Iterator<Item = usize> {
        let (k, l) = (a % self.n[0], a / self.n[0]);
        let [wx, wy] = self.half;
        let ls = l.saturating_sub(wy)..(l + wy + 1).min(self.n[1]);
        let ks = k.saturating_sub(wx)..(k + wx + 1).min(self.n[0]);
        let nx = self.n[0];
        ls.flat_map(move |l2| ks.clone().map(move |k2| k2 + nx * l2))
    }
}

impl Components {
    fn new(map: &HeightMap, standable: &[bool], reach: f64) -> Components {
        let n = map.cell_counts();
        // Cells k and k' are at least (|k − k'| − 1)·Δ apart horizontally.
        let window = [0, 1].map(|a| (reach / map.spacing[a]).ceil() as usize + 1);
        let mut c = Components {
            label: vec![usize::MAX; standable.len()],
            window: Window { n, half: window },
            beyond: (window[0] as f64 * map.spacing[0]).min(window[1] as f64 * map.spacing[1]),
        };
        let cells = map.cells();
        let mut next = 0;
        for start in 0..cells.len() {
            if !standable[start] || c.label[start] != usize::MAX {
                continue;
            }
            c.label[start] = next;
            let mut stack = vec![start];
            while let Some(a) = stack.pop() {
                for b in c.window.around(a) {
                    if standable[b]
                        && c.label[b] == usize::MAX
                        && within_reach(cell_distance(&cells[a], &cells[b]), reach)
                    {
                        c.label[b] = next;
                        stack.push(b);
                    }
                }
            }
            next += 1;
        }
        c
    }
}

/// The height map of `s`, if its terrain is one.
fn height_map(s: &Scenario) -> Option<HeightMap> {
    match &s.terrain {
        TerrainSpec::HeightMap {
            origin,
            spacing,
            heights,
            ..
        } => Some(HeightMap::new(*origin, *spacing, heights.clone())),
        _ => None,
    }
}

/// The certificate that some foot cannot reach its goal on `s`'s height map because the
/// ground it can stand on (module docs) does not join its start to its goal, or `None`
/// (not a height map, no cell certified unstandable, or every foot's ground reaches).
pub fn uncrossable(s: &Scenario) -> Option<Uncrossable> {
    if !worth_trying(s) {
        return None;
    }
    let map = height_map(s)?;
    let (unstandable, cert) = unstandable_cells(s, &map)?;
    let standable: Vec<bool> = unstandable.iter().map(|u| !u).collect();
    let reach = s.step_radius_sq.sqrt();
    let rho = goal_radius(s);
    let comps = Components::new(&map, &standable, reach);
    let cells = map.cells();
    for i in Foot::ALL {
        let (p, g) = (s.start.feet.get(i), s.goal.get(i.biped()));
        let mut reached = vec![false; cells.len()];
        let seeds: Vec<usize> = (0..cells.len())
            .filter(|&k| standable[k] && within_reach(point_distance(&cells[k], p), reach))
            .map(|k| comps.label[k])
            .collect();
        for k in 0..cells.len() {
            reached[k] = standable[k] && seeds.contains(&comps.label[k]);
        }
        let start = (0..3).map(|d| (p[d] - g[d]).powi(2)).sum::<f64>().sqrt();
        let nearest = (0..cells.len())
            .filter(|&k| reached[k])
            .map(|k| point_distance(&cells[k], g))
            .fold(start, f64::min);
        if nearest <= rho {
            continue;
        }
        let reachable_x = (0..cells.len())
            .filter(|&k| reached[k])
            .fold([p[0], p[0]], |a, k| {
                [a[0].min(cells[k].box_.x[0]), a[1].max(cells[k].box_.x[1])]
            });
        return Some(Uncrossable::for_foot(
            s,
            i,
            nearest,
            reachable_x,
            shortest_exit(&comps, cells, &standable, &reached),
            Some(cert),
        ));
    }
    None
}

/// A lower bound on the 3-D distance from a reached cell to a standable cell not reached
/// (at least `reach`): the least over the cells within the window, else the window's
/// width; `None` when every standable cell is reached.
fn shortest_exit(
    comps: &Components,
    cells: &[CellBounds],
    standable: &[bool],
    reached: &[bool],
) -> Option<f64> {
    if (0..cells.len()).all(|k| reached[k] || !standable[k]) {
        return None;
    }
    let within = (0..cells.len())
        .filter(|&a| reached[a])
        .flat_map(|a| comps.window.around(a).map(move |b| (a, b)))
        .filter(|&(_, b)| standable[b] && !reached[b])
        .map(|(a, b)| cell_distance(&cells[a], &cells[b]))
        .fold(f64::INFINITY, f64::min);
    Some(if within.is_finite() {
        within
    } else {
        comps.beyond
    })
}
