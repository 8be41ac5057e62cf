//! The terrain as drawn, in data coordinates (m): what `plan.svg` and `plan.html` both
//! draw, computed once here from the scenario's terrain ([`crate::terrain::of`]), so
//! that the two figures show the same world for every terrain kind (gap, several gaps,
//! step, stepping stones, height map).
//!
//! - Top view (x–y): [`top_rects`], rectangles painted in order: the keep-out everywhere
//!   (pale red), the allowed regions over it (white; stones sand-coloured), the gaps
//!   (dark red), a height map's cells shaded by height; and [`step_edge`], a step's edge.
//! - Side view (x–z): [`profile`], the terrain's height along the line y = [`side_y`]
//!   (the mean y of the start feet), sampled densely at steep edges
//!   ([`profile_xs`]); [`keep_out_bands`], the x intervals of that line outside every
//!   allowed region; [`stone_blocks`], the stones' x extents (stones are drawn as
//!   blocks).
use crate::scenario::{Gap, Scenario, TerrainSpec};
use crate::terrain::Terrain;
use serde::Serialize;

/// A filled rectangle of the top view, in data coordinates (bounds may be infinite).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TopRect {
    /// x range (m).
    pub x: [f64; 2],
    /// y range (m).
    pub y: [f64; 2],
    /// Fill colour (CSS).
    pub fill: &'static str,
    /// Fill opacity, when not opaque.
    pub opacity: Option<f64>,
    /// Outline colour and width (px), if any.
    pub stroke: Option<(&'static str, f64)>,
}

/// Colour of the keep-out.
pub const KEEP_OUT: &str = "#d62728";
/// Colour of a gap.
pub const GAP: &str = "#7f1d1d";
/// Colour of a stone.
pub const STONE: &str = "#e8dcc0";
/// Colour of a height map cell (its opacity grows with its height).
pub const CELL: &str = "#8c6d3f";

/// Cells of a height map's shading in the top view (x × y).
pub const CELLS: (usize, usize) = (60, 24);

/// The top view's rectangles, in painting order (see the module docs).
pub fn top_rects(s: &Scenario, t: &dyn Terrain) -> Vec<TopRect> {
    let all = [f64::NEG_INFINITY, f64::INFINITY];
    let rect = |x, y, fill, opacity, stroke| TopRect {
        x,
        y,
        fill,
        opacity,
        stroke,
    };
    let mut out = vec![rect(all, all, KEEP_OUT, Some(0.15), None)];
    let stones = matches!(s.terrain, TerrainSpec::Stones { .. });
    for r in t.regions() {
        out.push(if stones {
            rect(r.x, r.y, STONE, None, Some(("#8c7a55", 0.8)))
        } else {
            rect(r.x, r.y, "white", None, None)
        });
    }
    let dark = |g: &Gap| rect([g.min, g.max], all, GAP, Some(0.45), None);
    match &s.terrain {
        TerrainSpec::Gap => out.push(dark(&s.gap)),
        TerrainSpec::Gaps { gaps } => out.extend(gaps.iter().map(dark)),
        TerrainSpec::HeightMap { .. } => {
            let r = t.regions()[0];
            let (nx, ny) = CELLS;
            let (lo, hi) = height_range(s, t);
            let at = |b: [f64; 2], a: usize, n: usize| b[0] + (b[1] - b[0]) * a as f64 / n as f64;
            for a in 0..nx {
                for b in 0..ny {
                    let x = [at(r.x, a, nx), at(r.x, a + 1, nx)];
                    let y = [at(r.y, b, ny), at(r.y, b + 1, ny)];
                    let h = t.height_at((x[0] + x[1]) / 2.0, (y[0] + y[1]) / 2.0);
                    let u = ((h - lo) / (hi - lo).max(1e-9)).clamp(0.0, 1.0);
                    let opacity = ((0.05 + 0.5 * u) * 100.0).round() / 100.0;
                    out.push(rect(x, y, CELL, Some(opacity), None));
                }
            }
        }
        TerrainSpec::Step { .. } | TerrainSpec::Stones { .. } => {}
    }
    out
}

/// A step's edge x and rise (m), drawn as a line across the top view.
pub fn step_edge(s: &Scenario) -> Option<(f64, f64)> {
    match &s.terrain {
        TerrainSpec::Step { edge, rise, .. } => Some((*edge, *rise)),
        _ => None,
    }
}

/// Steep edges of the terrain: `(x, width)` with width ≈ the edge's 1/k scale.
pub fn edges(s: &Scenario) -> Vec<(f64, f64)> {
    let gap = |g: &Gap| {
        let w = 5.0 / g.steepness.max(1e-9);
        [(g.min, w), (g.max, w)]
    };
    match &s.terrain {
        TerrainSpec::Gap => gap(&s.gap).to_vec(),
        TerrainSpec::Gaps { gaps } => gaps.iter().flat_map(gap).collect(),
        TerrainSpec::Step {
            edge, steepness, ..
        } => vec![(*edge, 5.0 / steepness.max(1e-9))],
        _ => Vec::new(),
    }
}

/// The side view's sample points in [lo, hi]: uniform, plus points hugging each steep
/// edge so that the atan edges are drawn as edges.
pub fn profile_xs(s: &Scenario, lo: f64, hi: f64) -> Vec<f64> {
    let mut xs: Vec<f64> = (0..=400)
        .map(|i| lo + (hi - lo) * i as f64 / 400.0)
        .collect();
    for (e, w) in edges(s) {
        for d in [-20.0, -5.0, -1.0, 0.0, 1.0, 5.0, 20.0] {
            let x = e + d * w;
            if x > lo && x < hi {
                xs.push(x);
            }
        }
    }
    xs.sort_by(f64::total_cmp);
    xs
}

/// The terrain's profile along y = [`side_y`] at `xs`: `(x, height)`.
pub fn profile(s: &Scenario, t: &dyn Terrain, xs: &[f64]) -> Vec<[f64; 2]> {
    let y = side_y(s);
    xs.iter().map(|&x| [x, t.height_at(x, y)]).collect()
}

/// The x intervals of the side view's line (at `xs`) outside every allowed region
/// (none for stones, which are drawn as blocks).
pub fn keep_out_bands(s: &Scenario, t: &dyn Terrain, xs: &[f64]) -> Vec<[f64; 2]> {
    if matches!(s.terrain, TerrainSpec::Stones { .. }) {
        return Vec::new();
    }
    let (y, regions) = (side_y(s), t.regions());
    let mut bands = Vec::new();
    let mut out_from: Option<f64> = None;
    for &x in xs {
        let out = !regions.iter().any(|r| r.contains(x, y, 0.0));
        match (out, out_from) {
            (true, None) => out_from = Some(x),
            (false, Some(a)) => {
                bands.push([a, x]);
                out_from = None;
            }
            _ => {}
        }
    }
    if let (Some(a), Some(&b)) = (out_from, xs.last()) {
        bands.push([a, b]);
    }
    bands
}

/// The stones' x extents (stepping stones only), drawn as blocks under z = 0.
pub fn stone_blocks(s: &Scenario) -> Vec<[f64; 2]> {
    match &s.terrain {
        TerrainSpec::Stones { stones } => stones.iter().map(|b| [b[0], b[1]]).collect(),
        _ => Vec::new(),
    }
}

/// Lowest and highest terrain height along the side view's line over the allowed
/// regions' x extent (clipped to ±50 m), sampled at 201 points (m).
pub fn height_range(s: &Scenario, t: &dyn Terrain) -> (f64, f64) {
    let r = t.regions();
    let (x0, x1) = (
        r.iter()
            .map(|r| r.x[0])
            .fold(f64::INFINITY, f64::min)
            .max(-50.0),
        r.iter()
            .map(|r| r.x[1])
            .fold(f64::NEG_INFINITY, f64::max)
            .min(50.0),
    );
    let y = side_y(s);
    (0..=200)
        .map(|k| t.height_at(x0 + (x1 - x0) * k as f64 / 200.0, y))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), h| {
            (a.min(h), b.max(h))
        })
}

/// The y of the side view's terrain profile: the mean y of the start feet.
pub fn side_y(s: &Scenario) -> f64 {
    s.start.feet.to_array().iter().map(|p| p[1]).sum::<f64>() / 4.0
}
