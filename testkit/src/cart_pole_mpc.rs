//! Cart-pole swing-up MPC (issue 19's benchmark): the model of `examples/src/cart_pole.rs`
//! (Kelly 2017, appendix E), multiple shooting with one RK4 step per interval,
//! N = 40, dt = 0.05, the initial state a parameter `x0` entering through the equality
//! `X_0 − x0 = 0` (the first constraint block). Stage k's variables are `[X_k, U_k]`
//! (interleaved, so a shift moves every entry by one stage). Quadratic tracking cost to
//! the upright `[0, π, 0, 0]`, |u| ≤ 20, |cart position| ≤ 2.
//! `benches/reference/sqp_compare.py` builds the identical NLP for CasADi.
#![allow(dead_code)]

use nlp::{Compiled, Constraint, Problem, Relation, Solution};
use std::f64::consts::PI;
use symx::{Expr, Matrix};

pub const NX: usize = 4;
pub const NU: usize = 1;
pub const N: usize = 40;
pub const DT: f64 = 0.05;
pub const GOAL: [f64; NX] = [0.0, PI, 0.0, 0.0];
const Q: [f64; NX] = [10.0, 10.0, 0.1, 0.1];
const R: f64 = 0.01;

fn dynamics(x: &[Expr], u: Expr) -> Vec<Expr> {
    let (l, m1, m2, g) = (0.5, 1.0, 0.3, 9.81);
    let (s, c) = (x[1].sin(), x[1].cos());
    let ddq1 = (l * m2 * s * x[3].sq() + u + m2 * g * c * s) / (m1 + m2 * (1.0 - c.sq()));
    let ddq2 = -(l * m2 * c * s * x[3].sq() + u * c + (m1 + m2) * g * s)
        / (l * m1 + l * m2 * (1.0 - c.sq()));
    vec![x[2], x[3], ddq1, ddq2]
}

fn rk4(x: &[Expr], u: Expr, h: f64) -> Vec<Expr> {
    let add = |a: &[Expr], b: &[Expr], s: f64| -> Vec<Expr> {
        a.iter().zip(b).map(|(a, b)| *a + s * *b).collect()
    };
    let k1 = dynamics(x, u);
    let k2 = dynamics(&add(x, &k1, h / 2.0), u);
    let k3 = dynamics(&add(x, &k2, h / 2.0), u);
    let k4 = dynamics(&add(x, &k3, h), u);
    (0..x.len())
        .map(|i| x[i] + (h / 6.0) * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
        .collect()
}

/// The plant: one RK4 step of the same model, in f64 (through symx would be slower and
/// identical).
pub fn plant(x: &[f64; NX], u: f64) -> [f64; NX] {
    let f = |x: &[f64; NX]| -> [f64; NX] {
        let (l, m1, m2, g) = (0.5, 1.0, 0.3, 9.81);
        let (s, c) = (x[1].sin(), x[1].cos());
        let ddq1 = (l * m2 * s * x[3] * x[3] + u + m2 * g * c * s) / (m1 + m2 * (1.0 - c * c));
        let ddq2 = -(l * m2 * c * s * x[3] * x[3] + u * c + (m1 + m2) * g * s)
            / (l * m1 + l * m2 * (1.0 - c * c));
        [x[2], x[3], ddq1, ddq2]
    };
    let add = |a: &[f64; NX], b: &[f64; NX], s: f64| std::array::from_fn(|i| a[i] + s * b[i]);
    let h = DT;
    let k1 = f(x);
    let k2 = f(&add(x, &k1, h / 2.0));
    let k3 = f(&add(x, &k2, h / 2.0));
    let k4 = f(&add(x, &k3, h));
    std::array::from_fn(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// Stage cost of the closed loop (the same weights as the NLP's).
pub fn stage_cost(x: &[f64; NX], u: f64) -> f64 {
    (0..NX)
        .map(|i| Q[i] * (x[i] - GOAL[i]).powi(2))
        .sum::<f64>()
        * DT
        + R * u * u * DT
}

pub struct CartPoleMpc {
    pub problem: Problem,
    pub compiled: Compiled,
    pub x0: Matrix,
}

/// Variables per stage (X_k then U_k; the last stage has X_N only).
pub const STAGE: usize = NX + NU;

pub fn build() -> CartPoleMpc {
    let mut pb = Problem::new();
    let x0 = pb.parameter("x0", NX).unwrap();
    let mut xs = Vec::new();
    let mut us = Vec::new();
    for k in 0..=N {
        xs.push(pb.variable(&format!("X{k}"), NX).unwrap());
        if k < N {
            us.push(pb.variable(&format!("U{k}"), NU).unwrap());
        }
    }
    let mut cost = Expr::from(0.0);
    for k in 0..N {
        let x: Vec<Expr> = (0..NX).map(|i| xs[k][i]).collect();
        for i in 0..NX {
            cost += (Q[i] * DT) * (x[i] - GOAL[i]).sq();
        }
        cost += (R * DT) * us[k][0].sq();
    }
    for i in 0..NX {
        cost += (Q[i] * 10.0) * (xs[N][i] - GOAL[i]).sq();
    }
    pb.minimize(cost);
    let init = (0..NX).map(|i| (xs[0][i] - x0[i]).eq(0.0));
    pb.subject_to_named("init", Constraint::all(init)).unwrap();
    for k in 0..N {
        let x: Vec<Expr> = (0..NX).map(|i| xs[k][i]).collect();
        let next = rk4(&x, us[k][0], DT);
        let c = (0..NX).map(|i| (xs[k + 1][i] - next[i]).eq(0.0));
        pb.subject_to_named(&format!("dyn{k}"), Constraint::all(c))
            .unwrap();
    }
    for u in &us {
        pb.set_bounds(&[u[0]], &[-20.0], &[20.0]).unwrap();
    }
    for x in &xs {
        pb.set_bounds(&[x[0]], &[-2.0], &[2.0]).unwrap();
    }
    pb.set_value(&x0, &[0.0; NX]).unwrap();
    let compiled = pb.compile().unwrap();
    CartPoleMpc {
        problem: pb,
        compiled,
        x0,
    }
}

/// Shifts a solution one stage forward (primal and constraint multipliers; the last stage
/// repeated), in place.
pub fn shift(sol: &mut Solution) {
    let n = sol.x.len();
    sol.x.copy_within(STAGE..n, 0);
    for v in [&mut sol.z_l, &mut sol.z_u] {
        let n = v.len();
        v.copy_within(STAGE..n, 0);
    }
    // λ: [init (NX), dyn_0 (NX), ..., dyn_{N-1} (NX)]: dyn_k moves to dyn_{k-1}, the
    // init multiplier takes dyn_0's.
    let m = sol.lambda.len();
    sol.lambda.copy_within(NX..m, 0);
}
