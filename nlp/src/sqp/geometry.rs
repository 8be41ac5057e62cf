//! The constraint geometry of one SQP solve — bounds of x and of the scaled rows, the
//! affine cones — and the violation measures built on it (the merit's penalty term, the
//! max-norm infeasibility, scaled and in the user's units).

#![allow(clippy::needless_range_loop)]

use crate::frontend::scaled::ScaledNlp;
use crate::numeric::AffineCone;

/// Violation of `lo ≤ v ≤ hi`.
pub(super) fn viol(v: f64, lo: f64, hi: f64) -> f64 {
    (lo - v).max(v - hi).max(0.0)
}

/// Violation of an SOC: ‖v‖ − t (if positive).
pub(super) fn cone_viol(c: &[f64]) -> f64 {
    let nv = c[1..].iter().map(|v| v * v).sum::<f64>().sqrt();
    (nv - c[0]).max(0.0)
}

/// Constraint and cone data fixed for one solve (row bounds scaled).
pub(super) struct Geometry {
    pub x_l: Vec<f64>,
    pub x_u: Vec<f64>,
    pub g_l: Vec<f64>,
    pub g_u: Vec<f64>,
    pub cones: Vec<AffineCone>,
    /// Rows of g replaced by an exact cone.
    pub cone_row: Vec<bool>,
}

impl Geometry {
    /// Weighted ℓ1 penalty Σ w_i·viol_i(g) + ρ·Σ cone violations (the merit's
    /// infeasibility term; w = ρ everywhere is the classical ℓ1 penalty).
    pub fn penalty(&self, g: &[f64], cone: &[f64], w: &[f64], rho: f64) -> f64 {
        let mut s = 0.0;
        for i in 0..g.len() {
            if !self.cone_row[i] {
                s += w[i] * viol(g[i], self.g_l[i], self.g_u[i]);
            }
        }
        for c in &self.cones {
            s += rho * cone_viol(&cone[c.offset..c.offset + c.dim]);
        }
        s
    }

    /// Max-norm of the violation (g, cones, bounds).
    pub fn max(&self, x: &[f64], g: &[f64], cone: &[f64]) -> f64 {
        let mut s: f64 = 0.0;
        for i in 0..g.len() {
            if !self.cone_row[i] {
                s = s.max(viol(g[i], self.g_l[i], self.g_u[i]));
            }
        }
        for c in &self.cones {
            s = s.max(cone_viol(&cone[c.offset..c.offset + c.dim]));
        }
        for j in 0..x.len() {
            s = s.max(viol(x[j], self.x_l[j], self.x_u[j]));
        }
        s
    }

    /// Max-norm violation in the user's (unscaled) units (rows unscaled by `sc`).
    pub fn unscaled_max(&self, sc: &ScaledNlp<'_>, x: &[f64], g: &[f64], cone: &[f64]) -> f64 {
        let mut s: f64 = 0.0;
        for i in 0..g.len() {
            if !self.cone_row[i] {
                s = s.max(
                    sc.scaling
                        .row_to_user(i, viol(g[i], self.g_l[i], self.g_u[i])),
                );
            }
        }
        for c in &self.cones {
            s = s.max(cone_viol(&cone[c.offset..c.offset + c.dim]));
        }
        for j in 0..x.len() {
            s = s.max(viol(x[j], self.x_l[j], self.x_u[j]));
        }
        s
    }
}
