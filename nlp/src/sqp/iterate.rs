//! The SQP iterate: the point with its (scaled) function values, derivatives and
//! multipliers, and the KKT error measured at it.

#![allow(clippy::needless_range_loop)]

use faer::sparse::SymbolicSparseColMat;

use super::geometry::Geometry;
use super::qp::QpResult;
use super::shape::Shape;

/// Multipliers of the current iterate.
#[derive(Clone)]
pub(super) struct Mult {
    pub lambda: Vec<f64>,
    pub z_l: Vec<f64>,
    pub z_u: Vec<f64>,
    pub z_cone: Vec<f64>,
}

impl Mult {
    /// All zero.
    pub fn zeros(n: usize, m: usize, n_cone: usize) -> Mult {
        Mult {
            lambda: vec![0.0; m],
            z_l: vec![0.0; n],
            z_u: vec![0.0; n],
            z_cone: vec![0.0; n_cone],
        }
    }

    /// The QP's multipliers; with the augmented term ½ρ_a‖J_A d‖² the row multiplier is
    /// λ_i + ρ_a·J_i d (the dual of `J_i d − w_i = 0`), which tends to λ_i as d → 0.
    /// Written into these vectors (no allocation once they have the sizes).
    pub fn set_from_qp(&mut self, r: &QpResult) {
        self.lambda.clear();
        self.lambda
            .extend(r.lambda.iter().zip(&r.z_w).map(|(l, w)| l + w));
        self.z_l.clone_from(&r.z_l);
        self.z_u.clone_from(&r.z_u);
        self.z_cone.clone_from(&r.z_cone);
    }
}

/// The point x_k of the scaled problem with everything evaluated there.
pub(super) struct Iterate {
    pub x: Vec<f64>,
    /// Scaled objective.
    pub f: f64,
    /// Scaled constraint values.
    pub g: Vec<f64>,
    /// Stacked cone entries [t; v].
    pub cone: Vec<f64>,
    pub grad: Vec<f64>,
    /// Scaled Jacobian values.
    pub jv: Vec<f64>,
    /// Cone Jacobian values.
    pub cv: Vec<f64>,
    pub mult: Mult,
    /// Whether `mult` are multipliers (a warm start's or a QP's) rather than the zeros
    /// of a cold start.
    pub have_mult: bool,
}

/// A trial point x + αd clamped to the bounds, evaluated (scaled).
#[derive(Default)]
pub(super) struct TrialPoint {
    pub x: Vec<f64>,
    pub f: f64,
    pub g: Vec<f64>,
    pub cone: Vec<f64>,
}

/// KKT errors of a (scaled) iterate.
pub(super) struct Errors {
    /// Scaled overall error (IPOPT's E_0 with s_d, s_c).
    pub scaled: f64,
    pub inf_pr: f64,
    pub inf_du: f64,
    pub compl: f64,
}

/// ∇f + Jᵀλ − J_coneᵀz_cone (rows replaced by a cone excluded from the λ term).
#[allow(clippy::too_many_arguments)]
pub(super) fn lagrangian_gradient(
    grad: &[f64],
    jp: &SymbolicSparseColMat<usize>,
    jv: &[f64],
    cp: Option<&SymbolicSparseColMat<usize>>,
    cv: &[f64],
    mult: &Mult,
    cone_row: &[bool],
    out: &mut [f64],
) {
    out.copy_from_slice(grad);
    for c in 0..grad.len() {
        for p in jp.col_range(c) {
            let r = jp.row_idx()[p];
            if !cone_row[r] {
                out[c] += jv[p] * mult.lambda[r];
            }
        }
        if let Some(cp) = cp {
            for p in cp.col_range(c) {
                out[c] -= cv[p] * mult.z_cone[cp.row_idx()[p]];
            }
        }
    }
}

impl Iterate {
    /// Gradient of the Lagrangian at this iterate with `mult`, into `out`.
    pub fn lagrangian_gradient(
        &self,
        shape: &Shape,
        cone_row: &[bool],
        mult: &Mult,
        out: &mut [f64],
    ) {
        lagrangian_gradient(
            &self.grad,
            &shape.jp,
            &self.jv,
            shape.cp.as_ref(),
            &self.cv,
            mult,
            cone_row,
            out,
        );
    }

    /// The IPM's scaled KKT error on the scaled problem (`lgrad`: scratch of length n).
    /// Complementarity takes an inequality side's slack clamped at 0: a violation is
    /// inf_pr's, not complementarity's (IPOPT's slacks are ≥ 0 by construction).
    /// Unclamped, a rounding-level violation (5e-11) times a large multiplier (1e4) kept
    /// the error above tol for good, and the MPCC phases of qpec2 and ralph1 ran to their
    /// iteration limits.
    pub fn kkt_errors(
        &self,
        s_max: f64,
        geo: &Geometry,
        shape: &Shape,
        lgrad: &mut [f64],
    ) -> Errors {
        let (x, g, cone, mult) = (&self.x, &self.g, &self.cone, &self.mult);
        let n = x.len();
        self.lagrangian_gradient(shape, &geo.cone_row, mult, lgrad);
        let mut inf_du: f64 = 0.0;
        for j in 0..n {
            inf_du = inf_du.max((lgrad[j] - mult.z_l[j] + mult.z_u[j]).abs());
        }
        let inf_pr = geo.max(x, g, cone);
        let mut compl: f64 = 0.0;
        let mut ysum = 0.0;
        let mut zsum = 0.0;
        let mut nz = 0usize;
        let mut ny = 0usize;
        for i in 0..g.len() {
            if geo.cone_row[i] {
                continue;
            }
            ny += 1;
            ysum += mult.lambda[i].abs();
            if geo.g_l[i] != geo.g_u[i] {
                if geo.g_l[i].is_finite() {
                    compl = compl.max((g[i] - geo.g_l[i]).max(0.0) * (-mult.lambda[i]).max(0.0));
                }
                if geo.g_u[i].is_finite() {
                    compl = compl.max((geo.g_u[i] - g[i]).max(0.0) * mult.lambda[i].max(0.0));
                }
            }
        }
        for j in 0..n {
            if geo.x_l[j] == geo.x_u[j] {
                continue;
            }
            if geo.x_l[j].is_finite() {
                nz += 1;
                zsum += mult.z_l[j].abs();
                compl = compl.max(((x[j] - geo.x_l[j]) * mult.z_l[j]).abs());
            }
            if geo.x_u[j].is_finite() {
                nz += 1;
                zsum += mult.z_u[j].abs();
                compl = compl.max(((geo.x_u[j] - x[j]) * mult.z_u[j]).abs());
            }
        }
        for c in &geo.cones {
            let r = c.offset..c.offset + c.dim;
            let sz: f64 = cone[r.clone()]
                .iter()
                .zip(&mult.z_cone[r.clone()])
                .map(|(a, b)| a * b)
                .sum();
            compl = compl.max(sz.abs());
            nz += 1;
            zsum += mult.z_cone[c.offset].abs();
        }
        let s_d = if ny + nz == 0 {
            1.0
        } else {
            s_max.max((ysum + zsum) / (ny + nz) as f64) / s_max
        };
        let s_c = if nz == 0 {
            1.0
        } else {
            s_max.max(zsum / nz as f64) / s_max
        };
        Errors {
            scaled: (inf_du / s_d).max(inf_pr).max(compl / s_c),
            inf_pr,
            inf_du,
            compl,
        }
    }
}
