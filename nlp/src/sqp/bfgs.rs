//! The quadratic model's curvature term dᵀBd, and the damped BFGS update of a dense B
//! (`HessianApproximation::DampedBfgs`).

#![allow(clippy::needless_range_loop)]

use faer::sparse::SymbolicSparseColMat;

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

/// Damped BFGS update (Powell 1978) of the dense n×n B (column-major) with the step
/// s = x⁺ − x and y = ∇L(x⁺) − ∇L(x), both gradients with the new multipliers.
pub(super) fn bfgs_update(b: &mut [f64], s: &[f64], y: &[f64]) {
    let n = s.len();
    let bs: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| b[i + j * n] * s[j]).sum())
        .collect();
    let sbs: f64 = s.iter().zip(&bs).map(|(a, c)| a * c).sum();
    if sbs <= 1e-20 {
        return;
    }
    let sy: f64 = s.iter().zip(y).map(|(a, c)| a * c).sum();
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
