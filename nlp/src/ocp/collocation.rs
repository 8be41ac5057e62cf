//! Collocation points and coefficients (Legendre and Radau, any degree) for direct
//! collocation.
//!
//! On one interval of unit length the state is the polynomial of degree `d` through
//! `τ₀ = 0, τ₁, …, τ_d`: Gauss–Legendre points (the roots of the shifted Legendre
//! polynomial of degree d) or right Gauss–Radau points (Radau IIA: 1 and the roots of the
//! Jacobi polynomial P^(1,0) of degree d − 1). The points are computed by the
//! Golub–Welsch method (eigenvalues of the Jacobi matrix of the recurrence, faer's
//! symmetric eigensolver), then polished by Newton's method on the polynomial
//! (Golub & Welsch, "Calculation of Gauss quadrature rules", Math. Comp. 23, 1969).
//! The coefficients are those of CasADi's `direct_collocation.py` example: `C[j][r]` =
//! `ℓⱼ'(τ_r)` (the derivative of the Lagrange basis polynomial `ℓⱼ` at `τ_r`), `D[j] = ℓⱼ(1)`
//! (continuity) and `B[j] = ∫₀¹ ℓⱼ` (quadrature).
use super::OcpError;
use faer::{Mat, Side};

/// Which collocation points.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum CollocationPoints {
    /// Gauss–Legendre points (order 2d; the interval end is not a point).
    Legendre,
    /// Right Gauss–Radau points (Radau IIA, order 2d − 1; τ_d = 1).
    Radau,
}

/// Collocation points and the coefficients of the collocation equations for one degree.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Collocation {
    /// Which points.
    pub points: CollocationPoints,
    /// `[0, τ₁, …, τ_d]` in `[0, 1]`.
    pub tau: Vec<f64>,
    /// `c[j][r] = ℓⱼ'(τ_r)`, `(d+1) × (d+1)`.
    pub c: Vec<Vec<f64>>,
    /// `d[j] = ℓⱼ(1)`, the state at the end of the interval is `Σⱼ d[j] xⱼ`.
    pub d: Vec<f64>,
    /// `b[j] = ∫₀¹ ℓⱼ(τ) dτ`, quadrature weights (`b[0] = 0` for these points).
    pub b: Vec<f64>,
}

impl Collocation {
    /// The points and coefficients of `degree` (1 ≤ degree ≤ 60).
    pub fn new(points: CollocationPoints, degree: usize) -> Result<Self, OcpError> {
        if !(1..=60).contains(&degree) {
            return Err(OcpError::Degree(degree));
        }
        let mut tau = vec![0.0];
        match points {
            CollocationPoints::Legendre => tau.extend(jacobi_roots(degree, 0.0, 0.0)?),
            CollocationPoints::Radau => {
                tau.extend(jacobi_roots(degree - 1, 1.0, 0.0)?);
                tau.push(1.0);
            }
        }
        let n = tau.len();
        // Differentiation matrix in barycentric form (Berrut & Trefethen, SIAM Rev. 46,
        // 2004, eq. 9.4): ℓⱼ'(τ_r) = (wⱼ/w_r)/(τ_r − τⱼ), r ≠ j; the diagonal makes rows sum to 0.
        let w = barycentric_weights(&tau);
        let mut c = vec![vec![0.0; n]; n];
        for r in 0..n {
            let mut diag = 0.0;
            for j in (0..n).filter(|&j| j != r) {
                let v = w[j] / w[r] / (tau[r] - tau[j]);
                c[j][r] = v;
                diag -= v;
            }
            c[r][r] = diag;
        }
        let d = (0..n).map(|j| lagrange(&tau, j, 1.0)).collect();
        let b = integrals(&tau)?;
        Ok(Collocation {
            points,
            tau,
            c,
            d,
            b,
        })
    }

    /// The degree d (number of collocation points).
    pub fn degree(&self) -> usize {
        self.tau.len() - 1
    }
}

/// Roots in (0, 1) of the Jacobi polynomial `P_n^(α,β)(2t − 1)`, ascending.
fn jacobi_roots(n: usize, alpha: f64, beta: f64) -> Result<Vec<f64>, OcpError> {
    if n == 0 {
        return Ok(Vec::new());
    }
    // Symmetric tridiagonal Jacobi matrix of the monic recurrence on [−1, 1].
    let ab = alpha + beta;
    let diag = |k: usize| {
        let k = k as f64;
        if k == 0.0 {
            (beta - alpha) / (ab + 2.0)
        } else {
            (beta * beta - alpha * alpha) / ((2.0 * k + ab) * (2.0 * k + ab + 2.0))
        }
    };
    let off = |k: usize| {
        let k = k as f64;
        let s = 2.0 * k + ab;
        (4.0 * k * (k + alpha) * (k + beta) * (k + ab) / (s * s * (s + 1.0) * (s - 1.0))).sqrt()
    };
    let m = Mat::<f64>::from_fn(n, n, |i, j| match i.abs_diff(j) {
        0 => diag(i),
        1 => off(i.max(j)),
        _ => 0.0,
    });
    let mut x = m
        .self_adjoint_eigenvalues(Side::Lower)
        .map_err(|e| OcpError::Numerical(format!("Golub–Welsch eigenvalues: {e:?}")))?;
    for xi in &mut x {
        // Newton polish: a few steps from an eigenvalue accurate to ~1e-15 already.
        for _ in 0..3 {
            let (p, dp) = (
                jacobi(n, alpha, beta, *xi),
                jacobi_derivative(n, alpha, beta, *xi),
            );
            if dp != 0.0 {
                *xi -= p / dp;
            }
        }
    }
    x.sort_by(f64::total_cmp);
    Ok(x.into_iter().map(|v| (v + 1.0) / 2.0).collect())
}

/// `P_n^(α,β)(x)` by the three-term recurrence (Szegő, *Orthogonal Polynomials*, eq. 4.5.1).
fn jacobi(n: usize, a: f64, b: f64, x: f64) -> f64 {
    if n == 0 {
        return 1.0;
    }
    let mut p0 = 1.0;
    let mut p1 = ((a + b + 2.0) * x + (a - b)) / 2.0;
    for k in 2..=n {
        let k = k as f64;
        let c = 2.0 * k + a + b;
        let a1 = 2.0 * k * (k + a + b) * (c - 2.0);
        let a2 = (c - 1.0) * (a * a - b * b);
        let a3 = (c - 2.0) * (c - 1.0) * c;
        let a4 = 2.0 * (k + a - 1.0) * (k + b - 1.0) * c;
        let p2 = ((a2 + a3 * x) * p1 - a4 * p0) / a1;
        p0 = p1;
        p1 = p2;
    }
    p1
}

/// `d/dx P_n^(α,β)(x) = (n + α + β + 1)/2 · P_{n−1}^(α+1,β+1)(x)`.
fn jacobi_derivative(n: usize, a: f64, b: f64, x: f64) -> f64 {
    if n == 0 {
        return 0.0;
    }
    (n as f64 + a + b + 1.0) / 2.0 * jacobi(n - 1, a + 1.0, b + 1.0, x)
}

/// Barycentric weights `wⱼ = 1 / Πₖ≠ⱼ (τⱼ − τₖ)`.
fn barycentric_weights(tau: &[f64]) -> Vec<f64> {
    (0..tau.len())
        .map(|j| {
            1.0 / (0..tau.len())
                .filter(|&k| k != j)
                .map(|k| tau[j] - tau[k])
                .product::<f64>()
        })
        .collect()
}

/// `ℓⱼ(t)` in product form.
fn lagrange(tau: &[f64], j: usize, t: f64) -> f64 {
    (0..tau.len())
        .filter(|&k| k != j)
        .map(|k| (t - tau[k]) / (tau[j] - tau[k]))
        .product()
}

/// `∫₀¹ ℓⱼ` by Gauss–Legendre quadrature with `tau.len()` points (exact for degree
/// `2·len − 1 ≥ len − 1`); weights `2 / ((1 − x²) P_n'(x)²)` on [−1, 1].
fn integrals(tau: &[f64]) -> Result<Vec<f64>, OcpError> {
    let n = tau.len();
    let nodes = jacobi_roots(n, 0.0, 0.0)?;
    let weights: Vec<f64> = nodes
        .iter()
        .map(|&t| {
            let x = 2.0 * t - 1.0;
            let dp = jacobi_derivative(n, 0.0, 0.0, x);
            1.0 / ((1.0 - x * x) * dp * dp) // 2/(…) on [−1, 1], halved for [0, 1]
        })
        .collect();
    Ok((0..n)
        .map(|j| {
            nodes
                .iter()
                .zip(&weights)
                .map(|(&t, &w)| w * lagrange(tau, j, t))
                .sum()
        })
        .collect())
}
