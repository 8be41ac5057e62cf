//! CasADi's Opti race-car example, line for line in symnlp.
//!
//! Minimum time `T` to drive a car 1 m from standstill with a throttle `u ∈ [0, 1]`
//! (dynamics `ṗ = v`, `v̇ = u − v`) under the speed limit `v ≤ 1 − sin(2πp)/2`,
//! integrated with RK4 over `N` control intervals. The Python original is
//! `casadi/docs/examples/python/race_car.py`; `benches/reference/race_car.py` is the same
//! problem and `tests/race_car.rs` checks both give the same `T`.
//!
//! Run: `cargo run --release -p symnlp-examples --example race_car`
use std::f64::consts::PI;
use symnlp::nlp::{bounded, CommonOptions, Ipm, IpmOptions, Problem, Relation, Solution};
use symnlp::symx::{Expr, Matrix};

/// Builds the race-car problem with `n` control intervals and solves it with the
/// interior-point method; returns the solution and the index of `T` in `x`.
pub fn solve(
    n: usize,
    options: IpmOptions,
) -> Result<(Solution, usize), Box<dyn std::error::Error>> {
    let mut opti = Problem::new();
    let x = opti.variable_matrix("X", 2, n + 1)?; // state trajectory: position, speed
    let u = opti.variable("U", n)?; // control trajectory (throttle)
    let t = opti.scalar_variable("T")?; // final time
    opti.minimize(t);

    let f = |x: &Matrix, u: Expr| Matrix::from_vec(vec![x[1], u - x[1]]); // dx/dt = f(x, u)
    let dt = t / n as f64;
    for k in 0..n {
        let xk = x.column(k)?;
        let k1 = f(&xk, u[k]);
        let k2 = f(&(&xk + dt / 2.0 * &k1), u[k]);
        let k3 = f(&(&xk + dt / 2.0 * &k2), u[k]);
        let k4 = f(&(&xk + dt * &k3), u[k]);
        let x_next = &xk + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        opti.subject_to(x.column(k + 1)?.eq(&x_next))?; // close the gaps
    }
    for k in 0..=n {
        let (pos, speed) = (x[(0, k)], x[(1, k)]);
        opti.subject_to(speed.le(1.0 - (2.0 * PI * pos).sin() / 2.0))?; // track speed limit
    }
    opti.subject_to(bounded(0.0, u.clone(), 1.0))?; // control is limited
    opti.subject_to(x[(0, 0)].eq(0.0))?; // start at position 0 ...
    opti.subject_to(x[(1, 0)].eq(0.0))?; // ... from stand-still
    opti.subject_to(x[(0, n)].eq(1.0))?; // finish line at position 1
    opti.subject_to(t.ge(0.0))?; // time must be positive

    let speeds: Vec<Expr> = (0..=n).map(|k| x[(1, k)]).collect();
    opti.set_initial(&speeds, &vec![1.0; n + 1])?;
    opti.set_initial(&[t], &[1.0])?;

    let index_of_t = opti.variable_indices(&[t])?[0];
    let mut compiled = opti.compile()?;
    Ok((Ipm::new(options).solve(&mut compiled)?, index_of_t))
}

/// The example's program (`examples/examples/race_car.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = IpmOptions {
        common: CommonOptions {
            print_level: 5,
            ..CommonOptions::default()
        },
        ..IpmOptions::default()
    };
    let (sol, t) = solve(100, options)?;
    println!("{:?}: minimum time T = {:.6} s", sol.status, sol.x[t]);
    Ok(())
}
