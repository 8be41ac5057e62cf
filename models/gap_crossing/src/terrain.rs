//! Terrains: ground height and its gradient as symbolic expressions, plus keep-out zones.
//!
//! Equation (3) of the model puts each foot on the surface `z = h(x, y)` and equation (4)
//! takes the contact normal from `∇h`. A [`Terrain`] provides `h` symbolically (for the
//! model) and numerically (for guesses and plots), and the x-intervals where no foot may
//! stand. [`GapTerrain`] is the specification's terrain; [`StepTerrain`] (a smoothed step up
//! or down) shows that the model is written against the abstraction, not the gap.
use crate::scenario::Gap;
use std::f64::consts::PI;
use symx::Expr;

/// Ground geometry as the model sees it.
pub trait Terrain {
    /// Height `h(x, y)` as an expression of the foot's coordinates.
    fn height(&self, x: Expr, y: Expr) -> Expr;
    /// `(∂h/∂x, ∂h/∂y)` as expressions.
    fn gradient(&self, x: Expr, y: Expr) -> [Expr; 2];
    /// Height at a point, in plain numbers.
    fn height_at(&self, x: f64, y: f64) -> f64;
    /// Open x-intervals `(lo, hi)` where no foot may stand (edges widened by the safety margin).
    fn keep_out(&self) -> Vec<(f64, f64)>;
}

/// `(D/π)·atan(k·(x − edge))`: a smoothed step of height `D` at `edge` (symbolic).
fn smooth_step(x: Expr, edge: f64, depth: f64, steepness: f64) -> Expr {
    depth / PI * (steepness * (x - edge)).atan()
}

/// Derivative of [`smooth_step`] in x: `(D/π)·k / (1 + (k(x − edge))²)`.
fn smooth_step_slope(x: Expr, edge: f64, depth: f64, steepness: f64) -> Expr {
    depth / PI * steepness / (1.0 + (steepness * (x - edge)).sq())
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
    fn keep_out(&self) -> Vec<(f64, f64)> {
        vec![self.gap.keep_out()]
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
    fn keep_out(&self) -> Vec<(f64, f64)> {
        vec![(self.edge - self.margin, self.edge + self.margin)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use symx::Function;

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
        ];
        let (x, y) = (Expr::sym("x"), Expr::sym("y"));
        for t in &terrains {
            let [gx, gy] = t.gradient(x, y);
            let f = Function::new(&[&[x, y]], &[&[t.height(x, y), gx, gy]]).unwrap();
            for &px in &[0.0, 0.9, 1.05, 2.0, 2.2, 2.4, 3.0] {
                let out = f.call(&[&[px, 0.3]]).unwrap()[0].clone();
                assert!((out[0] - t.height_at(px, 0.3)).abs() < 1e-12);
                let d = 1e-6;
                let fd = (t.height_at(px + d, 0.3) - t.height_at(px - d, 0.3)) / (2.0 * d);
                assert!(
                    (out[1] - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                    "slope at {px}: {} vs {fd}",
                    out[1]
                );
                assert_eq!(out[2], 0.0);
            }
        }
    }
}
