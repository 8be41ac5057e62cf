//! The quadratic model's curvature term dᵀBd, and the damped BFGS update of a dense B
//! (`HessianApproximation::DampedBfgs`).

#![allow(clippy::needless_range_loop)]

use faer::sparse::SymbolicSparseColMat;

use super::iterate::{lagrangian_gradient, Mult};

/// ½-less quadratic form dᵀBd for B = lower-triangular H + δI (or dense B).
pub(super) fn quad(
    hp: &SymbolicSparseColMat<usize>,
    hv: &[f64],
    delta: f64,
    dense: Option<&[f64]>,
    d: &[f64],
) -> f64 {
    let n = d.len();
    if let Some(b) = dense {
        let mut s = 0.0;
        for j in 0..n {
            for i in 0..n {
                s += d[i] * b[i + j * n] * d[j];
            }
        }
        return s;
    }
    let mut s = delta * d.iter().map(|v| v * v).sum::<f64>();
    for c in 0..n {
        for p in hp.col_range(c) {
            let r = hp.row_idx()[p];
            let w = if r == c { 1.0 } else { 2.0 };
            s += w * hv[p] * d[r] * d[c];
        }
    }
    s
}

/// Damped BFGS update (Powell) of the dense B with s = x⁺ − x, y = ∇L(x⁺) − ∇L(x) (both
/// with the new multipliers).
#[allow(clippy::too_many_arguments)]
pub(super) fn bfgs_update(
    b: &mut [f64],
    n: usize,
    x0: &[f64],
    x1: &[f64],
    g0: &[f64],
    j0: &[f64],
    c0: &[f64],
    g1: &[f64],
    j1: &[f64],
    c1: &[f64],
    jp: &SymbolicSparseColMat<usize>,
    cp: Option<&SymbolicSparseColMat<usize>>,
    mult: &Mult,
    cone_row: &[bool],
) {
    let mut l0 = vec![0.0; n];
    let mut l1 = vec![0.0; n];
    lagrangian_gradient(g0, jp, j0, cp, c0, mult, cone_row, &mut l0);
    lagrangian_gradient(g1, jp, j1, cp, c1, mult, cone_row, &mut l1);
    let s: Vec<f64> = (0..n).map(|i| x1[i] - x0[i]).collect();
    let y: Vec<f64> = (0..n).map(|i| l1[i] - l0[i]).collect();
    let bs: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| b[i + j * n] * s[j]).sum())
        .collect();
    let sbs: f64 = s.iter().zip(&bs).map(|(a, c)| a * c).sum();
    if sbs <= 1e-20 {
        return;
    }
    let sy: f64 = s.iter().zip(&y).map(|(a, c)| a * c).sum();
    let theta = if sy >= 0.2 * sbs {
        1.0
    } else {
        0.8 * sbs / (sbs - sy)
    };
    let r: Vec<f64> = (0..n)
        .map(|i| theta * y[i] + (1.0 - theta) * bs[i])
        .collect();
    let sr: f64 = s.iter().zip(&r).map(|(a, c)| a * c).sum();
    if sr <= 1e-20 {
        return;
    }
    for j in 0..n {
        for i in 0..n {
            b[i + j * n] += -bs[i] * bs[j] / sbs + r[i] * r[j] / sr;
        }
    }
}
