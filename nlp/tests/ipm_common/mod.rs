//! Shared helpers for the interior-point tests: a small dense `NumericNlp` built from
//! closures (dense Jacobian, dense lower-triangular Hessian).
#![allow(dead_code)]

use faer::sparse::SymbolicSparseColMat;
use nlp::NumericNlp;

type F = Box<dyn FnMut(&[f64]) -> f64>;
type V = Box<dyn FnMut(&[f64], &mut [f64])>;
type H = Box<dyn FnMut(&[f64], f64, &[f64], &mut [f64])>;

/// Dense test problem. Jacobian values are column-major (col j: rows 0..m); Hessian
/// values are the packed lower triangle by columns (col j: rows j..n).
pub struct DenseNlp {
    pub n: usize,
    pub m: usize,
    pub x_l: Vec<f64>,
    pub x_u: Vec<f64>,
    pub g_l: Vec<f64>,
    pub g_u: Vec<f64>,
    pub x0: Vec<f64>,
    pub f: F,
    pub grad: V,
    pub g: V,
    pub jac: V,
    pub hess: H,
    jac_pat: SymbolicSparseColMat<usize>,
    hess_pat: SymbolicSparseColMat<usize>,
}

impl DenseNlp {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        x_l: Vec<f64>,
        x_u: Vec<f64>,
        g_l: Vec<f64>,
        g_u: Vec<f64>,
        x0: Vec<f64>,
        f: F,
        grad: V,
        g: V,
        jac: V,
        hess: H,
    ) -> Self {
        let n = x_l.len();
        let m = g_l.len();
        let mut cp = vec![0];
        let mut ri = Vec::new();
        for _ in 0..n {
            ri.extend(0..m);
            cp.push(ri.len());
        }
        let jac_pat = SymbolicSparseColMat::new_checked(m, n, cp, None, ri);
        let mut cp = vec![0];
        let mut ri = Vec::new();
        for j in 0..n {
            ri.extend(j..n);
            cp.push(ri.len());
        }
        let hess_pat = SymbolicSparseColMat::new_checked(n, n, cp, None, ri);
        DenseNlp {
            n,
            m,
            x_l,
            x_u,
            g_l,
            g_u,
            x0,
            f,
            grad,
            g,
            jac,
            hess,
            jac_pat,
            hess_pat,
        }
    }
}

/// Index of (r, c), r ≥ c, in the packed lower triangle by columns.
pub fn lower(n: usize, r: usize, c: usize) -> usize {
    c * n - c * (c + 1) / 2 + r
}

impl NumericNlp for DenseNlp {
    fn n(&self) -> usize {
        self.n
    }
    fn m(&self) -> usize {
        self.m
    }
    fn bounds(&self, x_l: &mut [f64], x_u: &mut [f64], g_l: &mut [f64], g_u: &mut [f64]) {
        x_l.copy_from_slice(&self.x_l);
        x_u.copy_from_slice(&self.x_u);
        g_l.copy_from_slice(&self.g_l);
        g_u.copy_from_slice(&self.g_u);
    }
    fn initial_point(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.x0);
    }
    fn jac_g_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        &self.jac_pat
    }
    fn hess_l_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        &self.hess_pat
    }
    fn eval_f(&mut self, x: &[f64]) -> f64 {
        (self.f)(x)
    }
    fn eval_grad_f(&mut self, x: &[f64], grad: &mut [f64]) {
        (self.grad)(x, grad)
    }
    fn eval_g(&mut self, x: &[f64], g: &mut [f64]) {
        (self.g)(x, g)
    }
    fn eval_jac_g(&mut self, x: &[f64], values: &mut [f64]) {
        (self.jac)(x, values)
    }
    fn eval_hess_l(&mut self, x: &[f64], obj_factor: f64, lambda: &[f64], values: &mut [f64]) {
        (self.hess)(x, obj_factor, lambda, values)
    }
}

const INF: f64 = f64::INFINITY;

/// Rosenbrock: f = 100 (x2 − x1²)² + (1 − x1)², unconstrained, x0 = (−1.2, 1).
pub fn rosenbrock() -> DenseNlp {
    DenseNlp::new(
        vec![-INF, -INF],
        vec![INF, INF],
        vec![],
        vec![],
        vec![-1.2, 1.0],
        Box::new(|x| 100.0 * (x[1] - x[0] * x[0]).powi(2) + (1.0 - x[0]).powi(2)),
        Box::new(|x, g| {
            g[0] = -400.0 * x[0] * (x[1] - x[0] * x[0]) - 2.0 * (1.0 - x[0]);
            g[1] = 200.0 * (x[1] - x[0] * x[0]);
        }),
        Box::new(|_, _| {}),
        Box::new(|_, _| {}),
        Box::new(|x, s, _, h| {
            h[0] = s * (1200.0 * x[0] * x[0] - 400.0 * x[1] + 2.0);
            h[1] = s * (-400.0 * x[0]);
            h[2] = s * 200.0;
        }),
    )
}

/// hs071 (Hock & Schittkowski 1981, problem 71; the IPOPT tutorial problem):
/// min x1 x4 (x1 + x2 + x3) + x3  s.t. x1 x2 x3 x4 ≥ 25, Σ xi² = 40, 1 ≤ x ≤ 5,
/// x0 = (1, 5, 5, 1).
pub fn hs071() -> DenseNlp {
    DenseNlp::new(
        vec![1.0; 4],
        vec![5.0; 4],
        vec![25.0, 40.0],
        vec![INF, 40.0],
        vec![1.0, 5.0, 5.0, 1.0],
        Box::new(|x| x[0] * x[3] * (x[0] + x[1] + x[2]) + x[2]),
        Box::new(|x, g| {
            g[0] = x[0] * x[3] + x[3] * (x[0] + x[1] + x[2]);
            g[1] = x[0] * x[3];
            g[2] = x[0] * x[3] + 1.0;
            g[3] = x[0] * (x[0] + x[1] + x[2]);
        }),
        Box::new(|x, g| {
            g[0] = x[0] * x[1] * x[2] * x[3];
            g[1] = x.iter().map(|v| v * v).sum();
        }),
        Box::new(|x, j| {
            // column-major 2x4
            j[0] = x[1] * x[2] * x[3];
            j[1] = 2.0 * x[0];
            j[2] = x[0] * x[2] * x[3];
            j[3] = 2.0 * x[1];
            j[4] = x[0] * x[1] * x[3];
            j[5] = 2.0 * x[2];
            j[6] = x[0] * x[1] * x[2];
            j[7] = 2.0 * x[3];
        }),
        Box::new(|x, s, l, h| {
            let n = 4;
            h.iter_mut().for_each(|v| *v = 0.0);
            // objective
            h[lower(n, 0, 0)] += s * 2.0 * x[3];
            h[lower(n, 1, 0)] += s * x[3];
            h[lower(n, 2, 0)] += s * x[3];
            h[lower(n, 3, 0)] += s * (2.0 * x[0] + x[1] + x[2]);
            h[lower(n, 3, 1)] += s * x[0];
            h[lower(n, 3, 2)] += s * x[0];
            // g0 = x1 x2 x3 x4
            h[lower(n, 1, 0)] += l[0] * x[2] * x[3];
            h[lower(n, 2, 0)] += l[0] * x[1] * x[3];
            h[lower(n, 3, 0)] += l[0] * x[1] * x[2];
            h[lower(n, 2, 1)] += l[0] * x[0] * x[3];
            h[lower(n, 3, 1)] += l[0] * x[0] * x[2];
            h[lower(n, 3, 2)] += l[0] * x[0] * x[1];
            // g1 = Σ x²
            for i in 0..n {
                h[lower(n, i, i)] += l[1] * 2.0;
            }
        }),
    )
}
