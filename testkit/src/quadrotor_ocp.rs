//! A quadrotor optimal-control problem by multiple shooting, exactly as
//! benches/reference/ocp_chain_casadi.py formulates it for CasADi: 12 states
//! x = [p (3), v (3), Euler angles φ θ ψ (3), body rates ω (3)], 4 rotor thrusts u, N
//! stages of one RK4 step of length H.
//!
//! Variables w = [X_0, U_0, X_1, U_1, …, X_{N−1}, U_{N−1}, X_N]; constraints, stage by
//! stage, F(X_k, U_k) − X_{k+1} = 0 (12 each, F = one RK4 step), then X_0 − x_init = 0;
//! objective Σ_k (‖X_k − x_ref‖² + 0.1‖U_k‖²) + 10‖X_N − x_ref‖².
//!
//! `build(n, true)` compiles F once and calls it at every stage (call nodes);
//! `build(n, false)` writes the RK4 expressions at every stage (inlined, as SX does).
#![allow(dead_code)]

use symx::{Expr, Function, Matrix};

pub const NX: usize = 12;
pub const NU: usize = 4;
pub const H: f64 = 0.02;
const MASS: f64 = 1.0;
const GRAVITY: f64 = 9.81;
const ARM: f64 = 0.2;
const YAW_COEF: f64 = 0.05;
const DRAG: f64 = 0.1;
const INERTIA: [f64; 3] = [0.01, 0.012, 0.02];

/// ẋ = f(x, u).
pub fn ode(x: &[Expr], u: &[Expr]) -> Vec<Expr> {
    let (v, e, w) = (&x[3..6], &x[6..9], &x[9..12]);
    let thrust = u[0] + u[1] + u[2] + u[3];
    let tau = [
        ARM * (u[1] - u[3]),
        ARM * (u[2] - u[0]),
        YAW_COEF * (u[0] - u[1] + u[2] - u[3]),
    ];
    let (sf, cf) = (e[0].sin(), e[0].cos());
    let (st, ct, tt) = (e[1].sin(), e[1].cos(), e[1].tan());
    let (sp, cp) = (e[2].sin(), e[2].cos());
    let a = thrust / MASS;
    let mut dx = Vec::with_capacity(NX);
    dx.extend_from_slice(v);
    dx.push(a * (cf * st * cp + sf * sp) - DRAG * v[0]);
    dx.push(a * (cf * st * sp - sf * cp) - DRAG * v[1]);
    dx.push(a * (cf * ct) - GRAVITY - DRAG * v[2]);
    dx.push(w[0] + sf * tt * w[1] + cf * tt * w[2]);
    dx.push(cf * w[1] - sf * w[2]);
    dx.push(sf / ct * w[1] + cf / ct * w[2]);
    let [jx, jy, jz] = INERTIA;
    dx.push((tau[0] - (jz - jy) * w[1] * w[2]) / jx);
    dx.push((tau[1] - (jx - jz) * w[2] * w[0]) / jy);
    dx.push((tau[2] - (jy - jx) * w[0] * w[1]) / jz);
    dx
}

/// One RK4 step of length H.
pub fn rk4(x: &[Expr], u: &[Expr]) -> Vec<Expr> {
    let add = |a: &[Expr], b: &[Expr], s: f64| -> Vec<Expr> {
        a.iter().zip(b).map(|(&a, &b)| a + s * b).collect()
    };
    let k1 = ode(x, u);
    let k2 = ode(&add(x, &k1, H / 2.0), u);
    let k3 = ode(&add(x, &k2, H / 2.0), u);
    let k4 = ode(&add(x, &k3, H), u);
    (0..NX)
        .map(|i| x[i] + H / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
        .collect()
}

/// F(x, u) = one RK4 step, compiled.
pub fn step_function() -> Function {
    let x = Matrix::sym_vec("x", NX);
    let u = Matrix::sym_vec("u", NU);
    let xn = rk4(&x, &u);
    Function::named("F", &[("x", &x), ("u", &u)], &[("xf", &xn)]).unwrap()
}

pub fn x_ref() -> Vec<f64> {
    (0..NX).map(|i| if i < 3 { 1.0 } else { 0.0 }).collect()
}

pub fn x_init() -> Vec<f64> {
    vec![0.0; NX]
}

pub struct Ocp {
    pub w: Vec<Expr>,
    pub f: Expr,
    pub g: Vec<Expr>,
}

pub fn n_vars(n: usize) -> usize {
    n * (NX + NU) + NX
}

/// The problem with `n` stages; the dynamics called through one compiled F (`calls`) or
/// inlined at every stage.
pub fn build(n: usize, calls: bool) -> Ocp {
    let step = calls.then(step_function);
    let w = Matrix::sym_vec("w", n_vars(n));
    let xs = |k: usize| &w[k * (NX + NU)..k * (NX + NU) + NX];
    let us = |k: usize| &w[k * (NX + NU) + NX..(k + 1) * (NX + NU)];
    let (xr, x0) = (x_ref(), x_init());
    let dev = |x: &[Expr]| x.iter().zip(&xr).map(|(&a, &b)| (a - b).sq()).sum::<Expr>();
    let mut terms = Vec::with_capacity(n + 1);
    let mut g = Vec::with_capacity((n + 1) * NX);
    for k in 0..n {
        let next = match &step {
            Some(f) => f.apply(&[xs(k), us(k)]).unwrap().remove(0),
            None => rk4(xs(k), us(k)),
        };
        g.extend(next.iter().zip(xs(k + 1)).map(|(&a, &b)| a - b));
        terms.push(dev(xs(k)) + 0.1 * us(k).iter().map(|u| u.sq()).sum::<Expr>());
    }
    terms.push(10.0 * dev(xs(n)));
    g.extend(xs(0).iter().zip(&x0).map(|(&a, &b)| a - b));
    Ocp {
        w: w.to_vec(),
        f: terms.into_iter().sum(),
        g,
    }
}

/// A deterministic point: hover thrust, small angles and rates.
pub fn point(n: usize) -> Vec<f64> {
    (0..n_vars(n))
        .map(|i| {
            let j = i % (NX + NU);
            if j >= NX {
                GRAVITY * MASS / 4.0 + 0.01 * (i % 7) as f64
            } else {
                0.05 * ((i * 13 % 17) as f64 - 8.0) / 8.0
            }
        })
        .collect()
}
