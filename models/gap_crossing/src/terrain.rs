//! Terrains: ground height and its gradient as symbolic expressions, and the regions
//! where a foot may stand.
//!
//! Equation (3) of the model puts each foot on the surface `z = h(x, y)` and equation (4)
//! takes the contact normal from `∇h`. A [`Terrain`] provides `h` symbolically (for the
//! model) and numerically (for guesses, the checker and plots), and its allowed
//! [`Region`]s: axis-aligned boxes (possibly unbounded) whose union is where feet may
//! stand; the complement is the keep-out. The kinds, chosen by the scenario's `terrain`
//! table ([`of`]):
//! - [`GapTerrain`]: the specification's gap (the default);
//! - [`StepTerrain`]: a smoothed step up or down, feet `margin` away from its edge;
//! - [`GapsTerrain`]: several gaps, the sum of their heights;
//! - [`StonesTerrain`]: flat ground where only the given rectangles (stones) may be stood on;
//! - [`HeightMap`]: a grid of heights read from a CSV file, interpolated by the
//!   tensor-product Catmull-Rom spline (C¹), allowed on the grid's rectangle.
use crate::scenario::{Gap, Scenario, TerrainSpec};
use std::f64::consts::PI;
use std::sync::OnceLock;
use symx::{Expr, Interpolant2};

/// A closed axis-aligned box `x[0] ≤ x ≤ x[1]`, `y[0] ≤ y ≤ y[1]` (bounds may be infinite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// x range (m).
    pub x: [f64; 2],
    /// y range (m).
    pub y: [f64; 2],
}

impl Region {
    /// The strip `lo ≤ x ≤ hi` across the whole width.
    pub fn strip(lo: f64, hi: f64) -> Region {
        Region {
            x: [lo, hi],
            y: [f64::NEG_INFINITY, f64::INFINITY],
        }
    }

    /// Whether `(x, y)` lies in the box widened by `tol`.
    pub fn contains(&self, x: f64, y: f64, tol: f64) -> bool {
        x >= self.x[0] - tol && x <= self.x[1] + tol && y >= self.y[0] - tol && y <= self.y[1] + tol
    }

    /// The point of the box shrunk by `inset` (not past its centre) closest to `(x, y)`.
    pub fn clamp(&self, x: f64, y: f64, inset: f64) -> [f64; 2] {
        let c = |v: f64, [a, b]: [f64; 2]| {
            let (a2, b2) = (a + inset, b - inset);
            if a2 <= b2 {
                v.clamp(a2, b2)
            } else {
                (a + b) / 2.0
            }
        };
        [c(x, self.x), c(y, self.y)]
    }

    /// Horizontal (x–y) distance between two boxes: a lower bound on the 3-D distance
    /// between any two points standing on them.
    pub fn distance(&self, other: &Region) -> f64 {
        let gap = |[a0, a1]: [f64; 2], [b0, b1]: [f64; 2]| (b0 - a1).max(a0 - b1).max(0.0);
        gap(self.x, other.x).hypot(gap(self.y, other.y))
    }

    /// Horizontal distance from a point to the box.
    pub fn distance_to(&self, x: f64, y: f64) -> f64 {
        let [cx, cy] = self.clamp(x, y, 0.0);
        (x - cx).hypot(y - cy)
    }
}

/// Ground geometry as the model sees it.
pub trait Terrain: Send + Sync {
    /// Height `h(x, y)` as an expression of the foot's coordinates.
    fn height(&self, x: Expr, y: Expr) -> Expr;
    /// `(∂h/∂x, ∂h/∂y)` as expressions.
    fn gradient(&self, x: Expr, y: Expr) -> [Expr; 2];
    /// Height at a point, in plain numbers.
    fn height_at(&self, x: f64, y: f64) -> f64;
    /// `(∂h/∂x, ∂h/∂y)` at a point, in plain numbers.
    fn slope_at(&self, x: f64, y: f64) -> [f64; 2];
    /// The boxes where a foot may stand (their union; everything else is keep-out).
    fn regions(&self) -> Vec<Region>;
    /// An upper bound on the height `h(x, y)` over the whole plane, when one is known
    /// (`reach::stances_needed` uses it; `None`: no bound).
    fn height_bound(&self) -> Option<f64> {
        None
    }

    /// An upper bound on the slope `‖∇h‖` over the allowed regions, when one is known
    /// (`reach::force_threshold` uses it; `None`: no bound).
    fn slope_bound(&self) -> Option<f64> {
        None
    }
    /// The heights `[min, max]` of the ground over region `r` (or a range holding
    /// them), when known (`reach` uses it for rises and drops between regions; `None`:
    /// unknown, taken as no height difference).
    fn height_range(&self, _r: &Region) -> Option<[f64; 2]> {
        None
    }

    /// A lower bound on the 3-D distance from `p` to the points of the ground over region
    /// `r`: the horizontal distance to `r` and, when [`Terrain::height_range`] knows the
    /// heights there, the vertical distance from `p` to that range.
    fn distance_from(&self, r: &Region, p: [f64; 3]) -> f64 {
        let vertical = self.height_range(r).map_or(0.0, |h| outside(p[2], h));
        r.distance_to(p[0], p[1]).hypot(vertical)
    }

    /// Unit surface normal `(−h_x, −h_y, 1)/‖·‖` at a point (points up, out of the ground).
    fn normal_at(&self, x: f64, y: f64) -> [f64; 3] {
        let [hx, hy] = self.slope_at(x, y);
        let n = (1.0 + hx * hx + hy * hy).sqrt();
        [-hx / n, -hy / n, 1.0 / n]
    }

    /// How far `(x, y)` is from the nearest allowed region (0 when inside one).
    fn keep_out_depth(&self, x: f64, y: f64) -> f64 {
        self.regions()
            .iter()
            .map(|r| r.distance_to(x, y))
            .fold(f64::INFINITY, f64::min)
    }
}

/// The terrain a scenario describes (its `terrain` table; `gap` for the default).
pub fn of(s: &Scenario) -> Box<dyn Terrain> {
    match &s.terrain {
        TerrainSpec::Gap => Box::new(GapTerrain { gap: s.gap }),
        TerrainSpec::Step {
            edge,
            rise,
            steepness,
            margin,
        } => Box::new(StepTerrain {
            edge: *edge,
            rise: *rise,
            steepness: *steepness,
            margin: *margin,
        }),
        TerrainSpec::Gaps { gaps } => Box::new(GapsTerrain { gaps: gaps.clone() }),
        TerrainSpec::Stones { stones } => Box::new(StonesTerrain {
            stones: stones
                .iter()
                .map(|b| Region {
                    x: [b[0], b[1]],
                    y: [b[2], b[3]],
                })
                .collect(),
        }),
        TerrainSpec::HeightMap {
            origin,
            spacing,
            heights,
            ..
        } => Box::new(HeightMap::new(*origin, *spacing, heights.clone())),
    }
}

/// How far `z` lies outside `[lo, hi]` (0 inside).
fn outside(z: f64, [lo, hi]: [f64; 2]) -> f64 {
    (lo - z).max(z - hi).max(0.0)
}

/// `(D/π)·atan(k·(x − edge))`: a smoothed step of height `D` at `edge` (symbolic).
fn smooth_step(x: Expr, edge: f64, depth: f64, steepness: f64) -> Expr {
    depth / PI * (steepness * (x - edge)).atan()
}

/// Derivative of [`smooth_step`] in x: `(D/π)·k / (1 + (k(x − edge))²)`.
fn smooth_step_slope(x: Expr, edge: f64, depth: f64, steepness: f64) -> Expr {
    depth / PI * steepness / (1.0 + (steepness * (x - edge)).sq())
}

/// Bound on `|d/dx (D/π)·atan(k(x − e))|` at points at least `delta` from the edge `e`.
fn atan_slope_bound(depth: f64, steepness: f64, delta: f64) -> f64 {
    depth.abs() / PI * steepness / (1.0 + (steepness * delta).powi(2))
}

/// The heights of a monotone 1-D profile over a strip: between its values at the
/// strip's ends (the limits `at_minus`/`at_plus` at infinite ends).
fn monotone_range(h: impl Fn(f64) -> f64, r: &Region, at_minus: f64, at_plus: f64) -> [f64; 2] {
    let a = if r.x[0].is_finite() {
        h(r.x[0])
    } else {
        at_minus
    };
    let b = if r.x[1].is_finite() {
        h(r.x[1])
    } else {
        at_plus
    };
    [a.min(b), a.max(b)]
}

/// The specification's terrain: flat floor with a gap across the whole width,
/// `h(x) = (D/π)[atan(k(x − gap_max)) − atan(k(x − gap_min))]`.
#[derive(Clone, Copy, Debug)]
pub struct GapTerrain {
    /// The gap's edges, depth, steepness and margin.
    pub gap: Gap,
}

impl Terrain for GapTerrain {
    fn height(&self, x: Expr, _y: Expr) -> Expr {
        let g = &self.gap;
        if g.depth == 0.0 {
            return Expr::zero();
        }
        smooth_step(x, g.max, g.depth, g.steepness) - smooth_step(x, g.min, g.depth, g.steepness)
    }
    fn gradient(&self, x: Expr, _y: Expr) -> [Expr; 2] {
        let g = &self.gap;
        if g.depth == 0.0 {
            return [Expr::zero(), Expr::zero()];
        }
        let dx = smooth_step_slope(x, g.max, g.depth, g.steepness)
            - smooth_step_slope(x, g.min, g.depth, g.steepness);
        [dx, Expr::zero()]
    }
    fn height_at(&self, x: f64, _y: f64) -> f64 {
        self.gap.height(x)
    }
    fn slope_at(&self, x: f64, _y: f64) -> [f64; 2] {
        [self.gap.slope(x), 0.0]
    }
    /// h < 0 for a gap (depth > 0); a negative depth (a ridge) rises to at most −depth.
    fn height_bound(&self) -> Option<f64> {
        Some((-self.gap.depth).max(0.0))
    }
    /// Each edge's term at the margin's distance.
    fn slope_bound(&self) -> Option<f64> {
        let g = &self.gap;
        Some(2.0 * atan_slope_bound(g.depth, g.steepness, g.margin))
    }
    /// h is monotone on each side of the gap (between 0 at infinity and its value at
    /// the keep-out's edge).
    fn height_range(&self, r: &Region) -> Option<[f64; 2]> {
        Some(monotone_range(|x| self.gap.height(x), r, 0.0, 0.0))
    }
    fn regions(&self) -> Vec<Region> {
        let (lo, hi) = self.gap.keep_out();
        vec![
            Region::strip(f64::NEG_INFINITY, lo),
            Region::strip(hi, f64::INFINITY),
        ]
    }
}

/// Several gaps across the whole width: the sum of their [`GapTerrain`] heights; feet
/// stay out of every widened gap.
#[derive(Clone, Debug)]
pub struct GapsTerrain {
    /// The gaps (any order; widened gaps may overlap).
    pub gaps: Vec<Gap>,
}

impl Terrain for GapsTerrain {
    fn height(&self, x: Expr, y: Expr) -> Expr {
        self.gaps
            .iter()
            .map(|&gap| GapTerrain { gap }.height(x, y))
            .fold(Expr::zero(), |a, b| a + b)
    }
    fn gradient(&self, x: Expr, y: Expr) -> [Expr; 2] {
        let dx = self
            .gaps
            .iter()
            .map(|&gap| GapTerrain { gap }.gradient(x, y)[0])
            .fold(Expr::zero(), |a, b| a + b);
        [dx, Expr::zero()]
    }
    fn height_at(&self, x: f64, _y: f64) -> f64 {
        self.gaps.iter().map(|g| g.height(x)).sum()
    }
    fn slope_at(&self, x: f64, _y: f64) -> [f64; 2] {
        [self.gaps.iter().map(|g| g.slope(x)).sum(), 0.0]
    }
    /// Each gap's term is below 0, or below −depth for a ridge.
    fn height_bound(&self) -> Option<f64> {
        Some(self.gaps.iter().map(|g| (-g.depth).max(0.0)).sum())
    }
    /// The sum of each gap's bound.
    fn slope_bound(&self) -> Option<f64> {
        Some(
            self.gaps
                .iter()
                .map(|g| 2.0 * atan_slope_bound(g.depth, g.steepness, g.margin))
                .sum(),
        )
    }
    fn regions(&self) -> Vec<Region> {
        let mut outs: Vec<(f64, f64)> = self.gaps.iter().map(Gap::keep_out).collect();
        outs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut regions = Vec::new();
        let mut from = f64::NEG_INFINITY;
        for (lo, hi) in outs {
            if lo > from {
                regions.push(Region::strip(from, lo));
            }
            from = from.max(hi);
        }
        regions.push(Region::strip(from, f64::INFINITY));
        regions
    }
}

/// A smoothed step of height `rise` (negative: a step down) at `x = edge`:
/// `h(x) = rise·(½ + atan(k(x − edge))/π)`; feet keep `margin` away from the edge.
#[derive(Clone, Copy, Debug)]
pub struct StepTerrain {
    /// x of the step edge (m).
    pub edge: f64,
    /// Height change across the edge (m).
    pub rise: f64,
    /// Steepness k of the edge (1/m).
    pub steepness: f64,
    /// Keep-out half-width around the edge (m).
    pub margin: f64,
}

impl Terrain for StepTerrain {
    fn height(&self, x: Expr, _y: Expr) -> Expr {
        self.rise * 0.5 + smooth_step(x, self.edge, self.rise, self.steepness)
    }
    fn gradient(&self, x: Expr, _y: Expr) -> [Expr; 2] {
        [
            smooth_step_slope(x, self.edge, self.rise, self.steepness),
            Expr::zero(),
        ]
    }
    fn height_at(&self, x: f64, _y: f64) -> f64 {
        self.rise * (0.5 + (self.steepness * (x - self.edge)).atan() / PI)
    }
    fn slope_at(&self, x: f64, _y: f64) -> [f64; 2] {
        let a = self.steepness * (x - self.edge);
        [self.rise / PI * self.steepness / (1.0 + a * a), 0.0]
    }
    /// h lies strictly between 0 and `rise`.
    fn height_bound(&self) -> Option<f64> {
        Some(self.rise.max(0.0))
    }
    fn slope_bound(&self) -> Option<f64> {
        Some(atan_slope_bound(self.rise, self.steepness, self.margin))
    }
    /// h is monotone, from 0 at −∞ to `rise` at +∞.
    fn height_range(&self, r: &Region) -> Option<[f64; 2]> {
        Some(monotone_range(
            |x| self.height_at(x, 0.0),
            r,
            0.0,
            self.rise,
        ))
    }
    fn regions(&self) -> Vec<Region> {
        vec![
            Region::strip(f64::NEG_INFINITY, self.edge - self.margin),
            Region::strip(self.edge + self.margin, f64::INFINITY),
        ]
    }
}

/// Stepping stones: flat ground `z = 0` on which only the given rectangles may be stood on.
#[derive(Clone, Debug)]
pub struct StonesTerrain {
    /// The stones.
    pub stones: Vec<Region>,
}

impl Terrain for StonesTerrain {
    fn height(&self, _x: Expr, _y: Expr) -> Expr {
        Expr::zero()
    }
    fn gradient(&self, _x: Expr, _y: Expr) -> [Expr; 2] {
        [Expr::zero(), Expr::zero()]
    }
    fn height_at(&self, _x: f64, _y: f64) -> f64 {
        0.0
    }
    fn slope_at(&self, _x: f64, _y: f64) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn height_bound(&self) -> Option<f64> {
        Some(0.0)
    }
    fn slope_bound(&self) -> Option<f64> {
        Some(0.0)
    }
    fn height_range(&self, _r: &Region) -> Option<[f64; 2]> {
        Some([0.0, 0.0])
    }
    fn regions(&self) -> Vec<Region> {
        self.stones.clone()
    }
}

/// Catmull-Rom kernel (Keys' cubic convolution kernel with a = −½): piecewise cubic, C¹,
/// 1 at 0, 0 at the other integers, support (−2, 2).
pub fn catmull_rom(t: f64) -> f64 {
    let a = t.abs();
    if a <= 1.0 {
        (1.5 * a - 2.5) * a * a + 1.0
    } else if a < 2.0 {
        ((-0.5 * a + 2.5) * a - 4.0) * a + 2.0
    } else {
        0.0
    }
}

/// Derivative of [`catmull_rom`].
pub fn catmull_rom_slope(t: f64) -> f64 {
    let a = t.abs();
    let d = if a <= 1.0 {
        (4.5 * a - 5.0) * a
    } else if a < 2.0 {
        (-1.5 * a + 5.0) * a - 4.0
    } else {
        0.0
    };
    d * t.signum()
}

/// A height map: `heights[j][i]` is the height at `x = origin[0] + i·spacing[0]`,
/// `y = origin[1] + j·spacing[1]`, interpolated by the tensor-product Catmull-Rom spline
/// `h(x, y) = Σ_i Σ_j z_ij K((x − x_i)/Δx) K((y − y_j)/Δy)`, with one ghost node beyond
/// each edge, linearly extrapolated (`z_{−1} = 2z_0 − z_1`), so that the surface is C¹,
/// passes through every node and reproduces planes exactly. Feet stay on the grid's
/// rectangle.
///
/// The spline is a bicubic polynomial on each cell, so the model states `h` as one
/// lookup node of a [`symx::Interpolant2`] holding those polynomials (its gradient and
/// higher derivatives are lookups of derivative tables): the model's size and the cost
/// of an evaluation do not depend on the grid's size. The numeric [`Terrain::height_at`]
/// sums the kernel over the at most 4 × 4 nodes around the point, an independent
/// computation of the same surface (equal to rounding).
#[derive(Clone, Debug)]
pub struct HeightMap {
    /// `(x, y)` of node `[0][0]` (m).
    pub origin: [f64; 2],
    /// Node spacing `(Δx, Δy)` (m), positive.
    pub spacing: [f64; 2],
    /// Heights, one row per y, one column per x (m); at least 2 × 2.
    pub heights: Vec<Vec<f64>>,
    /// The lookup table of `h`, built on first use.
    surface: OnceLock<Result<Interpolant2, String>>,
    /// Bounds on each cell of the rectangle, row by row, built on first use.
    bounds: OnceLock<Vec<CellBounds>>,
}

/// What is known of the surface on one grid cell: a range holding its heights and a bound
/// on its slope, from the Bernstein coefficients of the cell's bicubic and of its partial
/// derivatives (a polynomial lies within the range of its Bernstein coefficients; Farin,
/// *Curves and Surfaces for CAGD*, §5.3 and §16.2).
#[derive(Clone, Debug)]
pub(crate) struct CellBounds {
    /// The cell.
    pub(crate) box_: Region,
    /// `[min, max]` of the height over the cell (m), or a range holding them.
    pub(crate) h: [f64; 2],
    /// Ranges holding `∂h/∂x` and `∂h/∂y` over the cell.
    pub(crate) grad: [[f64; 2]; 2],
    /// A bound on `‖∇h‖` over the cell.
    pub(crate) slope: f64,
}

/// `B[k][a] = C(k, a)/C(3, a)`: the power coefficient `a` of a cubic on [0, 1] contributes
/// `B[k][a]` times itself to Bernstein coefficient `k`.
const POWER_TO_BERNSTEIN: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [1.0, 1.0 / 3.0, 0.0, 0.0],
    [1.0, 2.0 / 3.0, 1.0 / 3.0, 0.0],
    [1.0, 1.0, 1.0, 1.0],
];

/// `[min, max]` of the Bernstein coefficients of `Σ c[a + 4b] s^a t^b` on
/// `[0, size[0]] × [0, size[1]]`: a range holding its values there.
fn bernstein_range(c: &[f64; 16], size: [f64; 2]) -> [f64; 2] {
    let mut range = [f64::INFINITY, f64::NEG_INFINITY];
    for bk in &POWER_TO_BERNSTEIN {
        for bl in &POWER_TO_BERNSTEIN {
            let mut v = 0.0;
            for b in 0..4 {
                for a in 0..4 {
                    let d = c[a + 4 * b] * size[0].powi(a as i32) * size[1].powi(b as i32);
                    v += bk[a] * bl[b] * d;
                }
            }
            range = [range[0].min(v), range[1].max(v)];
        }
    }
    range
}

/// `Σ c[a + 4b] s^a t^b` as a polynomial of `(s − s0, t − t0)` (Taylor shift, exact up to
/// rounding).
fn shifted(c: &[f64; 16], [s0, t0]: [f64; 2]) -> [f64; 16] {
    const BINOMIAL: [[f64; 4]; 4] = [
        [1.0, 0.0, 0.0, 0.0],
        [1.0, 1.0, 0.0, 0.0],
        [1.0, 2.0, 1.0, 0.0],
        [1.0, 3.0, 3.0, 1.0],
    ];
    let shift4 = |v: [f64; 4], x0: f64| -> [f64; 4] {
        std::array::from_fn(|k| {
            (k..4)
                .map(|a| BINOMIAL[a][k] * v[a] * x0.powi((a - k) as i32))
                .sum()
        })
    };
    let mut out = *c;
    for b in 0..4 {
        let row = shift4(std::array::from_fn(|a| out[a + 4 * b]), s0);
        (0..4).for_each(|a| out[a + 4 * b] = row[a]);
    }
    for a in 0..4 {
        let col = shift4(std::array::from_fn(|b| out[a + 4 * b]), t0);
        (0..4).for_each(|b| out[a + 4 * b] = col[b]);
    }
    out
}

/// `∂/∂s` and `∂/∂t` of `Σ h[a + 4b] s^a t^b`, again as bicubics (top powers zero).
fn partials(h: &[f64; 16]) -> [[f64; 16]; 2] {
    let (mut hs, mut ht) = ([0.0; 16], [0.0; 16]);
    for b in 0..4 {
        for a in 0..3 {
            hs[a + 4 * b] = (a + 1) as f64 * h[a + 1 + 4 * b];
            ht[b + 4 * a] = (a + 1) as f64 * h[b + 4 * (a + 1)];
        }
    }
    [hs, ht]
}

/// Ranges holding `∂h/∂x` and `∂h/∂y` over the box `[0, size[0]] × [0, size[1]]` of the
/// cell polynomial `h`, and a bound on `‖∇h‖` there.
pub(crate) fn gradient_bounds(h: &[f64; 16], size: [f64; 2]) -> ([[f64; 2]; 2], f64) {
    let [hs, ht] = partials(h);
    let abs_max = |r: [f64; 2]| r[0].abs().max(r[1].abs());
    let grad = [bernstein_range(&hs, size), bernstein_range(&ht, size)];
    (grad, abs_max(grad[0]).hypot(abs_max(grad[1])))
}

impl CellBounds {
    fn of(c: &[f64], corner: [f64; 2], size: [f64; 2]) -> CellBounds {
        let mut h = [0.0; 16];
        h.copy_from_slice(c);
        let (grad, slope) = gradient_bounds(&h, size);
        CellBounds {
            box_: Region {
                x: [corner[0], corner[0] + size[0]],
                y: [corner[1], corner[1] + size[1]],
            },
            h: bernstein_range(&h, size),
            grad,
            slope,
        }
    }
}

/// Nodes of zero height added beyond each ghost node, so that the table covers the whole
/// support of the kernel sum (which vanishes 2 spacings beyond the ghost nodes).
const PAD: isize = 2;

/// The Catmull-Rom segment between nodes `k` and `k + 1` in powers of `u = (x − x_k)/Δ`:
/// `p(u) = Σ_a Σ_o CATMULL_ROM[a][o] · z_{k−1+o} · u^a` (the kernel's pieces, regrouped).
const CATMULL_ROM: [[f64; 4]; 4] = [
    [0.0, 1.0, 0.0, 0.0],
    [-0.5, 0.0, 0.5, 0.0],
    [1.0, -2.5, 2.0, -0.5],
    [-0.5, 1.5, -1.5, 0.5],
];

impl HeightMap {
    fn nx(&self) -> usize {
        self.heights.first().map_or(0, Vec::len)
    }

    /// Cells of the grid's rectangle along x and along y (one less than the nodes).
    pub fn cell_counts(&self) -> [usize; 2] {
        [
            self.nx().saturating_sub(1),
            self.heights.len().saturating_sub(1),
        ]
    }

    /// Height of node `(i, j)`, ghost nodes (index −1 or n) included.
    fn node(&self, i: isize, j: isize) -> f64 {
        let (nx, ny) = (self.nx() as isize, self.heights.len() as isize);
        let col = |j: usize| -> f64 {
            let row = &self.heights[j];
            match i {
                -1 => 2.0 * row[0] - row[1],
                i if i == nx => 2.0 * row[(nx - 1) as usize] - row[(nx - 2) as usize],
                i => row[i as usize],
            }
        };
        match j {
            -1 => 2.0 * col(0) - col(1),
            j if j == ny => 2.0 * col((ny - 1) as usize) - col((ny - 2) as usize),
            j => col(j as usize),
        }
    }

    /// Node indices −1 ..= n (ghosts included) along each axis.
    fn indices(
        &self,
    ) -> (
        std::ops::RangeInclusive<isize>,
        std::ops::RangeInclusive<isize>,
    ) {
        (-1..=self.nx() as isize, -1..=self.heights.len() as isize)
    }

    /// Height and gradient at a point (plain numbers), from the at most 4 × 4 nodes whose
    /// kernel reaches the point (the kernel vanishes beyond 2 spacings): O(1) in the
    /// grid's size.
    fn eval(&self, x: f64, y: f64) -> (f64, [f64; 2]) {
        let (is, js) = self.indices();
        let [dx, dy] = self.spacing;
        let (is, js) = (
            support(is, (x - self.origin[0]) / dx),
            support(js, (y - self.origin[1]) / dy),
        );
        let (mut h, mut hx, mut hy) = (0.0, 0.0, 0.0);
        for j in js {
            let ty = (y - self.origin[1]) / dy - j as f64;
            let (ky, dky) = (catmull_rom(ty), catmull_rom_slope(ty) / dy);
            if ky == 0.0 && dky == 0.0 {
                continue;
            }
            for i in is.clone() {
                let tx = (x - self.origin[0]) / dx - i as f64;
                let (kx, dkx) = (catmull_rom(tx), catmull_rom_slope(tx) / dx);
                let z = self.node(i, j);
                h += z * kx * ky;
                hx += z * dkx * ky;
                hy += z * kx * dky;
            }
        }
        (h, [hx, hy])
    }

    /// The height map of `heights` on the grid at `origin` with `spacing`.
    pub fn new(origin: [f64; 2], spacing: [f64; 2], heights: Vec<Vec<f64>>) -> HeightMap {
        HeightMap {
            origin,
            spacing,
            heights,
            surface: OnceLock::new(),
            bounds: OnceLock::new(),
        }
    }

    /// The grid's points along one axis (`n` nodes, `origin`, `spacing`) with the ghost
    /// node and [`PAD`] zero nodes beyond each end.
    fn padded_axis(origin: f64, spacing: f64, n: usize) -> Vec<f64> {
        (-1 - PAD..=n as isize + PAD)
            .map(|p| origin + p as f64 * spacing)
            .collect()
    }

    /// Why a grid of `n = [nx, ny]` nodes at `origin` with `spacing` and heights up to
    /// `max_abs` cannot be tabulated, if it cannot: its points (ghost and padding nodes
    /// included) must be distinct numbers, and the polynomial coefficients (up to
    /// 144·max|z|/(Δx³Δy³), the bound of the Catmull-Rom segment matrix's rows times the ghost nodes'
    /// 3·max|z|, with a 1e6 margin for derivative tables) finite.
    pub fn grid_problem(
        origin: [f64; 2],
        spacing: [f64; 2],
        n: [usize; 2],
        max_abs: f64,
    ) -> Option<String> {
        for k in 0..2 {
            let axis = HeightMap::padded_axis(origin[k], spacing[k], n[k]);
            if axis.windows(2).any(|w| w[1] <= w[0]) || axis.iter().any(|v| !v.is_finite()) {
                return Some(format!(
                    "spacing {} is too fine for coordinates near {}: the grid's points are not distinct numbers",
                    spacing[k], origin[k]
                ));
            }
        }
        let bound = 144e6 * max_abs / (spacing[0].powi(3) * spacing[1].powi(3));
        (!bound.is_finite()).then(|| {
            format!(
                "heights up to {max_abs} m on a spacing of {spacing:?} m overflow the spline's coefficients"
            )
        })
    }

    /// The lookup table of the spline (see the type's doc), or why it cannot be built
    /// (a grid too fine for its coordinates, heights too large for the coefficients;
    /// [`TerrainSpec::validate`] reports it).
    pub fn surface(&self) -> Result<&Interpolant2, &str> {
        self.surface
            .get_or_init(|| self.build_surface())
            .as_ref()
            .map_err(String::as_str)
    }

    fn build_surface(&self) -> Result<Interpolant2, String> {
        let (xs, ys, coeffs) = self.cell_polynomials();
        Interpolant2::from_cells(&xs, &ys, &coeffs, false).map_err(|e| e.to_string())
    }

    /// The padded grid's points and the 16 coefficients of each padded cell's bicubic
    /// (the layout of [`Interpolant2::from_cells`]).
    fn cell_polynomials(&self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let (nx, ny) = (self.nx(), self.heights.len());
        let [dx, dy] = self.spacing;
        let xs = HeightMap::padded_axis(self.origin[0], dx, nx);
        let ys = HeightMap::padded_axis(self.origin[1], dy, ny);
        let z = |i: isize, j: isize| {
            let inside = |k: isize, n: usize| (-1..=n as isize).contains(&k);
            if inside(i, nx) && inside(j, ny) {
                self.node(i, j)
            } else {
                0.0
            }
        };
        // Weights of each node in each power of s = x − x_k: CATMULL_ROM[a][o] / Δ^a.
        let weights = |d: f64| {
            let mut w = CATMULL_ROM;
            for (a, row) in w.iter_mut().enumerate() {
                row.iter_mut().for_each(|v| *v /= d.powi(a as i32));
            }
            w
        };
        let (wx, wy) = (weights(dx), weights(dy));
        let (cx, cy) = (xs.len() - 1, ys.len() - 1);
        let mut coeffs = vec![0.0; 16 * cx * cy];
        for l in 0..cy {
            for k in 0..cx {
                // Padded cell (k, l) starts at node (k − 1 − PAD, l − 1 − PAD).
                let (i0, j0) = (k as isize - 1 - PAD, l as isize - 1 - PAD);
                let mut rows = [[0.0; 4]; 4];
                for (q, row) in rows.iter_mut().enumerate() {
                    for (a, r) in row.iter_mut().enumerate() {
                        *r = (0..4)
                            .map(|o| wx[a][o] * z(i0 - 1 + o as isize, j0 - 1 + q as isize))
                            .sum();
                    }
                }
                let c = &mut coeffs[16 * (k + cx * l)..16 * (k + cx * l + 1)];
                for b in 0..4 {
                    for a in 0..4 {
                        c[a + 4 * b] = (0..4).map(|q| wy[b][q] * rows[q][a]).sum();
                    }
                }
            }
        }
        (xs, ys, coeffs)
    }

    /// Bounds of the height and slope on each cell of the grid's rectangle (built once),
    /// row by row ([`HeightMap::cell_counts`] cells per row and rows).
    pub(crate) fn cells(&self) -> &[CellBounds] {
        self.bounds.get_or_init(|| {
            let (xs, ys, coeffs) = self.cell_polynomials();
            let (cx, n) = (xs.len() - 1, [self.nx() - 1, self.heights.len() - 1]);
            let first = (PAD + 1) as usize;
            let mut out = Vec::with_capacity(n[0] * n[1]);
            for l in first..first + n[1] {
                for k in first..first + n[0] {
                    let c = &coeffs[16 * (k + cx * l)..16 * (k + cx * l + 1)];
                    let size = [xs[k + 1] - xs[k], ys[l + 1] - ys[l]];
                    out.push(CellBounds::of(c, [xs[k], ys[l]], size));
                }
            }
            out
        })
    }

    /// For each cell of the grid's rectangle (the order of [`HeightMap::cells`]), the
    /// gradient ranges and slope bound ([`gradient_bounds`]) of its `parts × parts`
    /// sub-cells: tighter than the cell's own (a Bernstein range converges to the true
    /// range quadratically in the box's size).
    pub(crate) fn sub_cell_gradients(&self, parts: usize) -> Vec<Vec<([[f64; 2]; 2], f64)>> {
        let (xs, ys, coeffs) = self.cell_polynomials();
        let (cx, n) = (xs.len() - 1, self.cell_counts());
        let first = (PAD + 1) as usize;
        let mut out = Vec::with_capacity(n[0] * n[1]);
        for l in first..first + n[1] {
            for k in first..first + n[0] {
                let mut c = [0.0; 16];
                c.copy_from_slice(&coeffs[16 * (k + cx * l)..16 * (k + cx * l + 1)]);
                let size = [
                    (xs[k + 1] - xs[k]) / parts as f64,
                    (ys[l + 1] - ys[l]) / parts as f64,
                ];
                let subs = (0..parts * parts)
                    .map(|q| {
                        let at = [(q % parts) as f64 * size[0], (q / parts) as f64 * size[1]];
                        gradient_bounds(&shifted(&c, at), size)
                    })
                    .collect();
                out.push(subs);
            }
        }
        out
    }

    /// The cells of the grid's rectangle meeting region `r`, each with its box cut to `r`.
    fn cells_in<'a>(&'a self, r: &'a Region) -> impl Iterator<Item = (Region, &'a CellBounds)> {
        self.cells().iter().filter_map(move |c| {
            let cut = Region {
                x: [c.box_.x[0].max(r.x[0]), c.box_.x[1].min(r.x[1])],
                y: [c.box_.y[0].max(r.y[0]), c.box_.y[1].min(r.y[1])],
            };
            (cut.x[0] <= cut.x[1] && cut.y[0] <= cut.y[1]).then_some((cut, c))
        })
    }

    /// Height and gradient as expressions: lookups of the table and of its derivative
    /// tables (NaN if the table cannot be built, which validation rules out).
    fn expr(&self, x: Expr, y: Expr) -> (Expr, [Expr; 2]) {
        match self.surface() {
            Ok(table) => {
                let partial = |axis| table.eval_partial(axis, x, y).expect("axis 0 or 1");
                (table.eval(x, y), [partial(0), partial(1)])
            }
            Err(_) => {
                let nan = Expr::constant(f64::NAN);
                (nan, [nan, nan])
            }
        }
    }
}

/// The node indices of `all` whose Catmull-Rom kernel is non-zero at grid coordinate `u`
/// (`|u − i| < 2`); all of them when `u` is not finite (the sum is then NaN, as it was).
fn support(all: std::ops::RangeInclusive<isize>, u: f64) -> std::ops::RangeInclusive<isize> {
    if !u.is_finite() {
        return all;
    }
    let (lo, hi) = (*all.start() as f64, *all.end() as f64);
    let a = (u - 2.0).floor().clamp(lo, hi) as isize;
    let b = (u + 2.0).ceil().clamp(lo, hi) as isize;
    a..=b
}

impl Terrain for HeightMap {
    fn height(&self, x: Expr, y: Expr) -> Expr {
        self.expr(x, y).0
    }
    fn gradient(&self, x: Expr, y: Expr) -> [Expr; 2] {
        self.expr(x, y).1
    }
    fn height_at(&self, x: f64, y: f64) -> f64 {
        self.eval(x, y).0
    }
    fn slope_at(&self, x: f64, y: f64) -> [f64; 2] {
        self.eval(x, y).1
    }
    /// The largest upper Bernstein bound over the rectangle's cells (feet stand only there).
    fn height_bound(&self) -> Option<f64> {
        Some(
            self.cells()
                .iter()
                .map(|c| c.h[1])
                .fold(f64::NEG_INFINITY, f64::max),
        )
    }
    /// The largest slope bound over the rectangle's cells.
    fn slope_bound(&self) -> Option<f64> {
        Some(self.cells().iter().map(|c| c.slope).fold(0.0, f64::max))
    }
    /// The union of the cells' height ranges over the cells meeting `r` (`None` when `r`
    /// is off the grid).
    fn height_range(&self, r: &Region) -> Option<[f64; 2]> {
        self.cells_in(r)
            .map(|(_, c)| c.h)
            .reduce(|a, b| [a[0].min(b[0]), a[1].max(b[1])])
    }
    /// Cell by cell: the distance from `p` to the cell's box cut to `r`, times the cell's
    /// height range.
    fn distance_from(&self, r: &Region, p: [f64; 3]) -> f64 {
        self.cells_in(r)
            .map(|(cut, c)| cut.distance_to(p[0], p[1]).hypot(outside(p[2], c.h)))
            .fold(f64::INFINITY, f64::min)
    }
    fn regions(&self) -> Vec<Region> {
        let [x0, y0] = self.origin;
        let x1 = x0 + (self.nx().max(1) - 1) as f64 * self.spacing[0];
        let y1 = y0 + (self.heights.len().max(1) - 1) as f64 * self.spacing[1];
        vec![Region {
            x: [x0, x1],
            y: [y0, y1],
        }]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use symx::Function;

    fn hills() -> HeightMap {
        HeightMap::new(
            [-0.5, -0.5],
            [0.5, 0.4],
            (0..5)
                .map(|j| {
                    (0..8)
                        .map(|i| 0.1 * ((i as f64) * 0.9).sin() * ((j as f64) * 0.7).cos())
                        .collect()
                })
                .collect(),
        )
    }

    /// The symbolic height and gradient agree with the numeric height and its central
    /// difference (h = 1e-7 on a slope of order k·D/π ≈ 3e5 near the edge is too coarse,
    /// so points are taken where the slope is moderate; tolerance 1e-6 relative).
    #[test]
    fn symbolic_and_numeric_terrain_agree() {
        let gap = crate::scenario::Scenario::default().gap;
        let terrains: Vec<Box<dyn Terrain>> = vec![
            Box::new(GapTerrain { gap }),
            Box::new(StepTerrain {
                edge: 1.0,
                rise: 0.2,
                steepness: 50.0,
                margin: 0.03,
            }),
            Box::new(GapsTerrain {
                gaps: vec![
                    gap,
                    Gap {
                        min: 1.0,
                        max: 1.1,
                        steepness: 30.0,
                        ..gap
                    },
                ],
            }),
            Box::new(hills()),
        ];
        let (x, y) = (Expr::sym("x"), Expr::sym("y"));
        for t in &terrains {
            let [gx, gy] = t.gradient(x, y);
            let f = Function::new(&[&[x, y]], &[&[t.height(x, y), gx, gy]]).unwrap();
            for &px in &[0.0, 0.9, 1.05, 1.3, 2.0, 2.2, 2.4, 3.0] {
                for &py in &[0.3, 0.77] {
                    let out = f.call(&[&[px, py]]).unwrap()[0].clone();
                    assert!((out[0] - t.height_at(px, py)).abs() < 1e-12);
                    let d = 1e-6;
                    let fdx = (t.height_at(px + d, py) - t.height_at(px - d, py)) / (2.0 * d);
                    let fdy = (t.height_at(px, py + d) - t.height_at(px, py - d)) / (2.0 * d);
                    for (got, fd) in [(out[1], fdx), (out[2], fdy)] {
                        assert!(
                            (got - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                            "slope at ({px}, {py}): {got} vs {fd}"
                        );
                    }
                    let [sx, sy] = t.slope_at(px, py);
                    assert!((sx - out[1]).abs() < 1e-9 && (sy - out[2]).abs() < 1e-9);
                }
            }
        }
    }

    /// The height map passes through its nodes, reproduces a plane exactly (ghost nodes
    /// linearly extrapolated), and is C¹: at the cell boundaries (integer t, where the
    /// kernel's pieces meet) the one-sided difference quotients of h and of its gradient
    /// agree to O(step).
    /// The local evaluation (at most 4 × 4 nodes) gives exactly the sum over the whole
    /// grid (every other term is a zero kernel value), inside the grid, on its edges and
    /// beyond them.
    #[test]
    fn height_map_local_evaluation_equals_the_full_sum() {
        let heights: Vec<Vec<f64>> = (0..20)
            .map(|j| {
                (0..30)
                    .map(|i| ((i * 7 + j * 13) % 11) as f64 * 0.01 - 0.03)
                    .collect()
            })
            .collect();
        let m = HeightMap::new([-1.0, 0.5], [0.1, 0.2], heights);
        let full = |x: f64, y: f64| {
            let (is, js) = m.indices();
            let (mut h, mut hx, mut hy) = (0.0, 0.0, 0.0);
            for j in js {
                let ty = (y - m.origin[1]) / m.spacing[1] - j as f64;
                let (ky, dky) = (catmull_rom(ty), catmull_rom_slope(ty) / m.spacing[1]);
                for i in is.clone() {
                    let tx = (x - m.origin[0]) / m.spacing[0] - i as f64;
                    let (kx, dkx) = (catmull_rom(tx), catmull_rom_slope(tx) / m.spacing[0]);
                    let z = m.node(i, j);
                    h += z * kx * ky;
                    hx += z * dkx * ky;
                    hy += z * kx * dky;
                }
            }
            (h, [hx, hy])
        };
        for a in 0..=70 {
            for b in 0..=50 {
                let (x, y) = (-1.3 + 0.0471 * a as f64, 0.2 + 0.0853 * b as f64);
                let (h, g) = m.eval(x, y);
                let (h0, g0) = full(x, y);
                assert!(
                    (h - h0).abs() <= 1e-15
                        && (g[0] - g0[0]).abs() <= 1e-13
                        && (g[1] - g0[1]).abs() <= 1e-13,
                    "({x}, {y}): {h} {g:?} vs {h0} {g0:?}"
                );
            }
        }
        // Grid nodes and cell corners exactly.
        assert_eq!(
            m.eval(-1.0 + 0.1 * 4.0, 0.5 + 0.2 * 3.0).0,
            full(-1.0 + 0.1 * 4.0, 0.5 + 0.2 * 3.0).0
        );
    }

    /// The model's lookup tables (value and both partial derivatives, compiled) equal the
    /// kernel sum and its gradient to rounding, at pseudo-random points over the grid, its
    /// ghost cells and beyond them (where both vanish), on node lines and cell corners;
    /// tolerance 1e-12 absolute (the terms are of order max|z|/Δ ≈ 3 m/m, so a few ulps of
    /// each, Horner in metres against the kernel in grid units, stay below 1e-14). The second derivatives (lookups of derivative
    /// tables) match central differences of the numeric gradient (step 1e-6 m; the
    /// spline's third derivative is bounded by ≈ 3·max|z|/Δ³ ≈ 10⁴ here, so the error is
    /// below 1e-7; tolerance 1e-5).
    #[test]
    fn height_map_table_equals_the_kernel_sum() {
        let heights: Vec<Vec<f64>> = (0..6)
            .map(|j| {
                (0..9)
                    .map(|i| 0.05 * ((i * 5 + j * 3) % 7) as f64 - 0.1 + 0.01 * i as f64)
                    .collect()
            })
            .collect();
        let m = HeightMap::new([0.3, -0.7], [0.25, 0.15], heights);
        let (x, y) = (Expr::sym("x"), Expr::sym("y"));
        let [hx, hy] = m.gradient(x, y);
        let hess = symx::gradient(hx, &[x, y]).unwrap();
        let hyy = symx::gradient(hy, &[y]).unwrap()[0];
        let f = Function::new(
            &[&[x, y]],
            &[&[m.height(x, y), hx, hy, hess[0], hess[1], hyy]],
        )
        .unwrap();
        let mut seed = 12345u64;
        let mut rand = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        // Grid x from 0.3 to 2.3, y from −0.7 to 0.05; ghost cells one spacing beyond,
        // the support ends three spacings beyond.
        let mut points: Vec<(f64, f64)> = (0..400)
            .map(|_| (-0.6 + 3.8 * rand(), -1.3 + 2.0 * rand()))
            .collect();
        for i in -4..=12 {
            for j in -4..=9 {
                points.push((0.3 + 0.25 * i as f64, -0.7 + 0.15 * j as f64));
                points.push((0.3 + 0.25 * i as f64, -0.7 + 0.15 * (j as f64 + 0.37)));
            }
        }
        for (px, py) in points {
            let out = f.call(&[&[px, py]]).unwrap()[0].clone();
            let (h, [gx, gy]) = m.eval(px, py);
            for (got, want) in [(out[0], h), (out[1], gx), (out[2], gy)] {
                assert!(
                    (got - want).abs() <= 1e-12,
                    "({px}, {py}): table {got} vs kernel {want}"
                );
            }
            // The spline is C¹ only: its second derivatives jump on node lines, where a
            // central difference averages the two sides; test them off those lines.
            let off_nodes =
                |v: f64, o: f64, dv: f64| ((v - o) / dv - ((v - o) / dv).round()).abs() > 1e-4;
            if !(off_nodes(px, 0.3, 0.25) && off_nodes(py, -0.7, 0.15)) {
                continue;
            }
            let d = 1e-6;
            let fd = |dx: f64, dy: f64, k: usize| {
                (m.eval(px + dx, py + dy).1[k] - m.eval(px - dx, py - dy).1[k]) / (2.0 * d)
            };
            for (got, want) in [
                (out[3], fd(d, 0.0, 0)),
                (out[4], fd(0.0, d, 0)),
                (out[5], fd(0.0, d, 1)),
            ] {
                assert!(
                    (got - want).abs() <= 1e-5 * (1.0 + want.abs()),
                    "second derivative at ({px}, {py}): {got} vs {want}"
                );
            }
        }
    }

    /// The model's expression of a height map has the same size on any grid: a lookup
    /// node (the tables hold the grid).
    #[test]
    fn height_map_expression_size_does_not_depend_on_the_grid() {
        let (x, y) = (Expr::sym("x"), Expr::sym("y"));
        let size = |n: usize| {
            let m = HeightMap::new([0.0, 0.0], [0.1, 0.1], vec![vec![0.01; n]; n]);
            let [gx, gy] = m.gradient(x, y);
            Function::new(&[&[x, y]], &[&[m.height(x, y), gx, gy]])
                .unwrap()
                .instruction_count()
        };
        assert_eq!(size(4), size(200));
    }

    /// The cell bounds hold: at pseudo-random points of every cell the height lies in the
    /// cell's range and the slope below its bound, and the ranges are not loose (within
    /// 0.05 m of the node heights on this 0.1 m-amplitude map); the height bound is the
    /// largest range's top, at least the highest node.
    #[test]
    fn height_map_cell_bounds_hold() {
        let m = hills();
        let mut seed = 99u64;
        let mut rand = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let cells = m.cells();
        assert_eq!(cells.len(), 7 * 4);
        for c in cells {
            for _ in 0..50 {
                let x = c.box_.x[0] + rand() * (c.box_.x[1] - c.box_.x[0]);
                let y = c.box_.y[0] + rand() * (c.box_.y[1] - c.box_.y[0]);
                let (h, [gx, gy]) = m.eval(x, y);
                assert!(
                    h >= c.h[0] - 1e-15 && h <= c.h[1] + 1e-15,
                    "{h} not in {:?}",
                    c.h
                );
                assert!(gx.hypot(gy) <= c.slope + 1e-12);
            }
            assert!(c.h[1] - c.h[0] < 0.25, "{:?}", c.h);
        }
        let top = m
            .heights
            .iter()
            .flatten()
            .fold(f64::NEG_INFINITY, |a, &b| a.max(b));
        let bound = m.height_bound().unwrap();
        assert!(bound >= top && bound < top + 0.05, "{bound} vs {top}");
        let r = m.regions()[0];
        let all = m.height_range(&r).unwrap();
        assert_eq!(all[1], bound);
        // Off the grid: no heights known.
        assert_eq!(m.height_range(&Region::strip(10.0, 11.0)), None);
    }

    #[test]
    fn height_map_interpolates_and_is_c1() {
        let m = hills();
        for (j, row) in m.heights.iter().enumerate() {
            for (i, &z) in row.iter().enumerate() {
                let (x, y) = (-0.5 + 0.5 * i as f64, -0.5 + 0.4 * j as f64);
                assert!((m.height_at(x, y) - z).abs() < 1e-12, "node ({i}, {j})");
            }
        }
        let plane = HeightMap::new(
            m.origin,
            m.spacing,
            (0..4)
                .map(|j| (0..5).map(|i| 0.3 * i as f64 - 0.2 * j as f64).collect())
                .collect(),
        );
        for &(x, y) in &[(-0.4, -0.3), (0.13, 0.61), (1.45, 0.7)] {
            let want = 0.3 * (x + 0.5) / 0.5 - 0.2 * (y + 0.5) / 0.4;
            assert!((plane.height_at(x, y) - want).abs() < 1e-12);
        }
        // Across x = 0.5 (a node column): gradient continuous from both sides.
        let e = 1e-7;
        for y in [0.1, 0.33] {
            let (l, r) = (m.slope_at(0.5 - e, y), m.slope_at(0.5 + e, y));
            assert!((l[0] - r[0]).abs() < 1e-5 && (l[1] - r[1]).abs() < 1e-5);
        }
        // The kernel itself: value and slope continuous at |t| = 1 and 2.
        for t in [1.0f64, 2.0] {
            assert!((catmull_rom(t - e) - catmull_rom(t + e)).abs() < 1e-6);
            assert!((catmull_rom_slope(t - e) - catmull_rom_slope(t + e)).abs() < 1e-5);
        }
    }

    #[test]
    fn regions_of_gaps_and_distances() {
        let g = |min: f64, max: f64| Gap {
            min,
            max,
            depth: 1.0,
            steepness: 1e6,
            margin: 0.03,
        };
        let t = GapsTerrain {
            gaps: vec![g(2.0, 2.1), g(1.0, 1.1)],
        };
        let r = t.regions();
        assert_eq!(r.len(), 3);
        assert!((r[0].x[1] - 0.97).abs() < 1e-12 && (r[1].x[0] - 1.13).abs() < 1e-12);
        assert!((r[0].distance(&r[1]) - 0.16).abs() < 1e-12);
        assert!(t.keep_out_depth(1.05, 0.0) > 0.0 && t.keep_out_depth(1.5, 3.0) == 0.0);
    }
}
