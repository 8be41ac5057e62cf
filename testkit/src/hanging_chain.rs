//! The hanging chain, exactly as benches/reference/hanging_chain.py formulates it for CasADi.
//!
//! N links, points p_i = (x_i, y_i), i = 0..N; variables ordered
//! w = [x_0, y_0, x_1, y_1, ..., x_N, y_N]; constraints, in order i = 0..N-1,
//! g_i = (x_{i+1} − x_i)² + (y_{i+1} − y_i)² − (L/N)² = 0 with L = 2; objective
//! f = (1/N) Σ_{i=0}^{N} y_i (summed left to right, then divided by N, as the script does);
//! fixed end points x_0 = y_0 = 0, x_N = 1, y_N = 0; initial guess x_i = i/N,
//! y_i = −0.5 sin(πi/N).
#![allow(dead_code)]

use symx::{Expr, Matrix};

pub const LENGTH: f64 = 2.0;

pub struct HangingChain {
    pub links: usize,
    /// The variables w (2(N+1) symbols).
    pub w: Matrix,
    pub f: Expr,
    pub g: Vec<Expr>,
    pub lbx: Vec<f64>,
    pub ubx: Vec<f64>,
    pub x0: Vec<f64>,
}

pub fn n_vars(links: usize) -> usize {
    2 * (links + 1)
}

pub fn build(links: usize) -> HangingChain {
    let n = n_vars(links);
    let w = Matrix::sym_vec("w", n);
    let x = |i: usize| w[2 * i];
    let y = |i: usize| w[2 * i + 1];
    let seg2 = (LENGTH / links as f64).powi(2);
    let g = (0..links)
        .map(|i| (x(i + 1) - x(i)).sq() + (y(i + 1) - y(i)).sq() - seg2)
        .collect();
    let mut f = y(0);
    for i in 1..=links {
        f += y(i);
    }
    f /= links as f64;

    let mut lbx = vec![f64::NEG_INFINITY; n];
    let mut ubx = vec![f64::INFINITY; n];
    for (k, v) in [(0, 0.0), (1, 0.0), (2 * links, 1.0), (2 * links + 1, 0.0)] {
        lbx[k] = v;
        ubx[k] = v;
    }
    let mut x0 = vec![0.0; n];
    for i in 0..=links {
        let t = i as f64 / links as f64;
        x0[2 * i] = t;
        x0[2 * i + 1] = -0.5 * (std::f64::consts::PI * t).sin();
    }
    HangingChain {
        links,
        w,
        f,
        g,
        lbx,
        ubx,
        x0,
    }
}
