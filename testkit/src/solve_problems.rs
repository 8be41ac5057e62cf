//! The scalable benchmark problems of `benches/solve.rs`, written with `nlp::Problem`
//! exactly as `benches/reference/hanging_chain.py` and `benches/reference/ocp.py`
//! formulate them for CasADi + IPOPT (same variable order, bounds, constraint order,
//! objective and initial guess). Keep both sides in sync.
#![allow(dead_code)]

use nlp::{Problem, Relation};
use symx::{Expr, Matrix};

/// Hanging chain (benches/reference/hanging_chain.py): N links, points
/// p_i = (x_i, y_i), i = 0..N, w = [x_0, y_0, …, x_N, y_N]; constraints
/// g_i = (x_{i+1} − x_i)² + (y_{i+1} − y_i)² − (L/N)² = 0 (L = 2), i = 0..N−1; objective
/// (1/N) Σ y_i; x_0 = y_0 = 0, x_N = 1, y_N = 0 fixed; start x_i = i/N,
/// y_i = −0.5 sin(πi/N).
pub fn hanging_chain(links: usize) -> Problem {
    let n = 2 * (links + 1);
    let mut pb = Problem::new();
    let w = pb.variable("w", n).expect("w");
    let x = |i: usize| w[2 * i];
    let y = |i: usize| w[2 * i + 1];
    let seg2 = (2.0 / links as f64).powi(2);
    let g: Vec<Expr> = (0..links)
        .map(|i| (x(i + 1) - x(i)).sq() + (y(i + 1) - y(i)).sq() - seg2)
        .collect();
    let mut f = y(0);
    for i in 1..=links {
        f += y(i);
    }
    f /= links as f64;
    pb.minimize(f);
    pb.subject_to_named("link", (&Matrix::from_vec(g)).eq(0.0))
        .expect("chain constraints");
    for (k, v) in [(0, 0.0), (1, 0.0), (2 * links, 1.0), (2 * links + 1, 0.0)] {
        pb.set_bounds(&[w[k]], v, v).expect("chain bounds");
    }
    let mut x0 = vec![0.0; n];
    for i in 0..=links {
        let t = i as f64 / links as f64;
        x0[2 * i] = t;
        x0[2 * i + 1] = -0.5 * (std::f64::consts::PI * t).sin();
    }
    pb.set_initial(&w, &x0).expect("chain start");
    pb
}

/// Van der Pol optimal control (benches/reference/ocp.py): N intervals, T = 10,
/// h = T/N, implicit midpoint rule for ẋ = ((1 − x₂²)x₁ − x₂ + u, x₁);
/// w = [x1_0, x2_0, u_0, …, x1_{N−1}, x2_{N−1}, u_{N−1}, x1_N, x2_N];
/// x_0 = (0, 1) fixed, −1 ≤ u_k ≤ 1, x1_k ≥ −0.25 for k ≥ 1; constraints per interval,
/// first component then second; J = h Σ (x1_k² + x2_k² + u_k²); start all zero except
/// x2_0 = 1.
pub fn van_der_pol(intervals: usize) -> Problem {
    let nn = intervals;
    let n = 3 * nn + 2;
    let h = 10.0 / nn as f64;
    let mut pb = Problem::new();
    let w = pb.variable("w", n).expect("w");
    let x1 = |k: usize| w[3 * k];
    let x2 = |k: usize| w[3 * k + 1];
    let u = |k: usize| w[3 * k + 2];
    let mut g = Vec::with_capacity(2 * nn);
    let mut j = Expr::from(0.0);
    for k in 0..nn {
        let m1 = (x1(k) + x1(k + 1)) / 2.0;
        let m2 = (x2(k) + x2(k + 1)) / 2.0;
        let f1 = (1.0 - m2.sq()) * m1 - m2 + u(k);
        let f2 = m1;
        g.push(x1(k + 1) - x1(k) - h * f1);
        g.push(x2(k + 1) - x2(k) - h * f2);
        j += x1(k).sq() + x2(k).sq() + u(k).sq();
    }
    pb.minimize(h * j);
    pb.subject_to_named("dynamics", (&Matrix::from_vec(g)).eq(0.0))
        .expect("dynamics");
    pb.set_bounds(&[x1(0)], 0.0, 0.0).expect("x1_0");
    pb.set_bounds(&[x2(0)], 1.0, 1.0).expect("x2_0");
    let us: Vec<Expr> = (0..nn).map(u).collect();
    pb.set_bounds(&us, -1.0, 1.0).expect("u bounds");
    let x1s: Vec<Expr> = (1..=nn).map(x1).collect();
    pb.set_bounds(&x1s, -0.25, f64::INFINITY)
        .expect("x1 bounds");
    let mut x0 = vec![0.0; n];
    x0[1] = 1.0;
    pb.set_initial(&w, &x0).expect("ocp start");
    pb
}

/// Sizes of benches/reference/solve_casadi.py, keyed by log10 of the variable count:
/// chain N = 50 … 50000 links (n = 2(N+1)), OCP N = 33 … 33333 intervals (n = 3N+2).
pub const CHAIN_SIZES: [(u32, usize); 4] = [(2, 50), (3, 500), (4, 5000), (5, 50000)];
/// See [`CHAIN_SIZES`].
pub const OCP_SIZES: [(u32, usize); 4] = [(2, 33), (3, 333), (4, 3333), (5, 33333)];
