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

#[cfg(test)]
mod tests {
    use super::bfgs_update;
    use crate::{HessianApproximation, Problem, Relation, Sqp, SqpOptions, Status};

    /// The update keeps B symmetric positive definite and, with θ = 1 (sᵀy ≥ 0.2 sᵀBs),
    /// satisfies the secant equation B⁺s = y.
    #[test]
    fn update_satisfies_the_secant_equation() {
        let mut b = vec![2.0, 0.0, 0.0, 1.0];
        let (s, y) = ([1.0, 1.0], [3.0, 2.0]);
        bfgs_update(&mut b, &s, &y);
        let bs = [b[0] * s[0] + b[2] * s[1], b[1] * s[0] + b[3] * s[1]];
        // Rounding of a few flops on O(1) numbers.
        assert!(
            (bs[0] - y[0]).abs() < 1e-14 && (bs[1] - y[1]).abs() < 1e-14,
            "{bs:?}"
        );
        assert_eq!(b[1], b[2]);
        assert!(b[0] > 0.0 && b[0] * b[3] - b[1] * b[2] > 0.0, "{b:?}");
    }

    /// hs071 (Hock & Schittkowski 1981): f* = 17.0140172891516 at
    /// x* = (1, 4.74299963, 3.82114998, 1.37940829), solved with damped BFGS.
    #[test]
    fn damped_bfgs_solves_hs071() {
        let mut pb = Problem::new();
        let x = pb.variable("x", 4).unwrap();
        pb.set_bounds(&x, 1.0, 5.0).unwrap();
        pb.set_initial(&x, &[1.0, 5.0, 5.0, 1.0]).unwrap();
        pb.minimize(x[0] * x[3] * (x[0] + x[1] + x[2]) + x[2]);
        pb.subject_to((x[0] * x[1] * x[2] * x[3]).ge(25.0)).unwrap();
        let sq = x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3];
        pb.subject_to(sq.eq(40.0)).unwrap();
        let o = SqpOptions {
            hessian_approximation: HessianApproximation::DampedBfgs,
            ..SqpOptions::default()
        };
        let sol = Sqp::new(o).solve(&mut pb.compile().unwrap()).unwrap();
        assert_eq!(sol.status, Status::SolveSucceeded, "{}", sol.message);
        // tol = 1e-8 on the KKT error bounds the objective error well below 1e-6.
        assert!(
            (sol.objective - 17.0140172891516).abs() < 1e-6,
            "{}",
            sol.objective
        );
    }
}
