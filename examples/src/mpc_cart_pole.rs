//! Cart-pole swing-up by model-predictive control (issue 19's benchmark): the cart-pole of
//! `examples/src/cart_pole.rs` (Kelly 2017), from hanging at rest to upright at the origin.
//! Each step solves, from the measured state, `min ∫₀ᵀ l dt + φ(x(T))` with
//! `l = 5 q1² + 10 (q2 − π)² + 0.1 (dq1² + dq2²) + 0.01 u²`, `φ = 100 l(x(T), 0)`,
//! `|u| ≤ 20` N, `|q1| ≤ 2` m, on a horizon of `T = 2` s: RK4 multiple shooting (one step
//! per interval), N = 40 intervals of dt = 0.05 s, the initial state a parameter. 100
//! closed-loop steps on the nominal plant (the same RK4 step), each warm-started from the
//! shifted previous solution ([`Mpc`](symnlp::nlp::mpc::Mpc)).
//!
//! `benches/reference/mpc_casadi.py` runs the identical loop with CasADi (IPOPT,
//! sqpmethod + qrqp, RTI); `tests/mpc.rs` compares the closed-loop cost.
//!
//! Run: `cargo run --release -p symnlp-examples --example mpc_cart_pole [-- sqp] [--json]`
use std::f64::consts::PI;
use symnlp::nlp::ocp::{Horizon, Ocp};
use symnlp::symx::{Expr, Matrix};

pub use crate::mpc_common::MpcExample;

use crate::cart_pole;

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

/// The example: 100 steps from hanging at rest.
pub fn example() -> MpcExample {
    MpcExample {
        name: "cart_pole",
        intervals: N,
        dt: DT,
        steps: STEPS,
        x_init: X_INIT.to_vec(),
        stage_cost,
        ocp: problem,
    }
}

/// The example's program (`examples/examples/mpc_cart_pole.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    example().main()
}
