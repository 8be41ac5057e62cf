//! Cart-pole swing-up by model-predictive control (issue 19's benchmark): the cart-pole of
//! `examples/cart_pole.rs` (Kelly 2017), from hanging at rest to upright at the origin.
//! Each step solves, from the measured state, `min ∫₀ᵀ l dt + φ(x(T))` with
//! `l = 5 q1² + 10 (q2 − π)² + 0.1 (dq1² + dq2²) + 0.01 u²`, `φ = 100 l(x(T), 0)`,
//! `|u| ≤ 20` N, `|q1| ≤ 2` m, on a horizon of `T = 2` s: RK4 multiple shooting (one step
//! per interval), N = 40 intervals of dt = 0.05 s, the initial state a parameter. 100
//! closed-loop steps on the nominal plant (the same RK4 step), each warm-started from the
//! shifted previous solution ([`Mpc`]).
//!
//! `benches/reference/mpc_casadi.py` runs the identical loop with CasADi (IPOPT,
//! sqpmethod + qrqp, RTI); `tests/mpc.rs` compares the closed-loop cost.
//!
//! Run: `cargo run --release --example mpc_cart_pole [-- sqp]`
use std::f64::consts::PI;
use symnlp::nlp::mpc::{ClosedLoop, Mpc};
use symnlp::nlp::ocp::{ButcherTableau, Horizon, Method, Ocp, Simulator, Transcription};
use symnlp::nlp::{Ipm, Solver, Sqp};
use symnlp::symx::{Expr, Function, Matrix};

#[path = "cart_pole.rs"]
#[allow(dead_code)]
mod cart_pole;

/// Intervals of the horizon.
pub const N: usize = 40;
/// Sampling period (s).
pub const DT: f64 = 0.05;
/// Closed-loop steps.
pub const STEPS: usize = 100;
/// The hanging start.
pub const X_INIT: [f64; 4] = [0.0; 4];

/// The stage cost `l(x, u)`.
pub fn stage_cost(x: &Matrix, u: &Matrix) -> Expr {
    5.0 * x[0].sq() + 10.0 * (x[1] - PI).sq() + 0.1 * (x[2].sq() + x[3].sq()) + 0.01 * u[0].sq()
}

/// The OCP solved at every step (initial state: the parameter `x0`).
pub fn problem() -> Result<Ocp, Box<dyn std::error::Error>> {
    let mut ocp = Ocp::new(&["q1", "q2", "dq1", "dq2"], &["force"]);
    ocp.set_dynamics(|x, u, _p| cart_pole::dynamics(x, u));
    ocp.set_stage_cost(|x, u, _p| stage_cost(x, u));
    ocp.set_terminal_cost(|x, _p, _t| 100.0 * stage_cost(x, &Matrix::from_vec(vec![Expr::zero()])));
    ocp.set_horizon(Horizon::Fixed(N as f64 * DT))?;
    let inf = f64::INFINITY;
    ocp.set_state_bounds(&[-2.0, -inf, -inf, -inf], &[2.0, inf, inf, inf])?;
    ocp.set_control_bounds(&[-20.0], &[20.0])?;
    ocp.set_initial_state_parameter("x0", &X_INIT)?;
    ocp.set_state_guess_linear(&X_INIT, &[0.0, PI, 0.0, 0.0])?;
    Ok(ocp)
}

/// The transcription and the nominal plant.
pub fn setup() -> Result<(Transcription, Simulator), Box<dyn std::error::Error>> {
    let ocp = problem()?;
    let tr = ocp.transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), N)?;
    Ok((tr, Simulator::new(&ocp, ButcherTableau::rk4(), 1)?))
}

/// The closed loop with `solver`.
pub fn closed_loop(solver: Box<dyn Solver>) -> Result<ClosedLoop, Box<dyn std::error::Error>> {
    let (tr, mut plant) = setup()?;
    let mut mpc = Mpc::new(&tr, solver)?;
    Ok(mpc.run(&X_INIT, STEPS, |x, u, next| plant.step_into(x, u, DT, next))?)
}

/// The closed loop's cost `dt Σ_s l(x_s, u_s)`.
pub fn closed_loop_cost(run: &ClosedLoop) -> Result<f64, Box<dyn std::error::Error>> {
    let (x, u) = (Matrix::sym_vec("x", 4), Matrix::sym_vec("u", 1));
    let l = Function::new(&[&x, &u], &[&[stage_cost(&x, &u)]])?;
    let mut total = 0.0;
    for (x, u) in run.states.iter().zip(&run.controls) {
        total += l.call(&[x, u])?[0][0];
    }
    Ok(DT * total)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let solver: Box<dyn Solver> = match std::env::args().nth(1).as_deref() {
        Some("sqp") => Box::new(Sqp::default()),
        _ => Box::new(Ipm::default()),
    };
    let name = solver.name();
    let run = closed_loop(solver)?;
    let (median, max) = run.latency();
    let (mean_it, max_it) = run.iterations();
    println!("step,status,iterations,ms,q1,q2,dq1,dq2,u");
    for (s, r) in run.steps.iter().enumerate() {
        let x = &run.states[s];
        println!(
            "{s},{},{},{:.3},{:.6},{:.6},{:.6},{:.6},{:.6}",
            r.status,
            r.iterations,
            1e3 * r.seconds,
            x[0],
            x[1],
            x[2],
            x[3],
            run.controls[s][0]
        );
    }
    eprintln!(
        "{name}: all succeeded {}, closed-loop cost {:.10}, latency median {:.3} ms max {:.3} ms, iterations mean {mean_it:.2} max {max_it}; final state {:?}",
        run.all_succeeded(),
        closed_loop_cost(&run)?,
        1e3 * median,
        1e3 * max,
        run.states[STEPS]
    );
    Ok(())
}
