//! Quadrotor repositioning by model-predictive control: the 12-state rigid body of
//! `examples/src/quadrotor.rs` (Luukkonen 2011), from hover at the origin to hover at
//! `(1, 1, 1)` m: `l = 10 |p − p*|² + |v|² + |angles|² + 0.1 |rates|² + 0.1 Σᵢ (Fᵢ − F_hover)²`,
//! `φ = 10 l(x(T), F_hover)`, thrusts `0 ≤ Fᵢ ≤ 2.5` N, roll and pitch within ±45°. RK4
//! multiple shooting, N = 20 intervals of dt = 0.1 s, 50 closed-loop steps on the nominal
//! plant. `benches/reference/mpc_casadi.py quadrotor` runs the identical loop with CasADi.
//!
//! Run: `cargo run --release -p symnlp-examples --example mpc_quadrotor [-- sqp] [--json]`
use std::f64::consts::PI;
use symnlp::nlp::ocp::{Horizon, Ocp};
use symnlp::symx::{Expr, Matrix};

pub use crate::mpc_common::MpcExample;

use crate::quadrotor;

/// The stage cost `l(x, u)`.
pub fn stage_cost(x: &Matrix, u: &Matrix) -> Expr {
    let target = [1.0, 1.0, 1.0];
    let mut l = Expr::zero();
    for i in 0..3 {
        l += 10.0 * (x[i] - target[i]).sq() + x[3 + i].sq() + x[6 + i].sq() + 0.1 * x[9 + i].sq();
    }
    for j in 0..4 {
        l += 0.1 * (u[j] - quadrotor::HOVER).sq();
    }
    l
}

/// The OCP solved at every step (initial state: the parameter `x0`).
pub fn problem() -> Result<Ocp, Box<dyn std::error::Error>> {
    let states = [
        "x", "y", "z", "vx", "vy", "vz", "roll", "pitch", "yaw", "wx", "wy", "wz",
    ];
    let mut ocp = Ocp::new(&states, &["F1", "F2", "F3", "F4"]);
    ocp.set_dynamics(|x, u, _p| quadrotor::dynamics(x, u));
    ocp.set_stage_cost(|x, u, _p| stage_cost(x, u));
    let hover = Matrix::from_f64(&[quadrotor::HOVER; 4]);
    ocp.set_terminal_cost(move |x, _p, _t| 10.0 * stage_cost(x, &hover));
    ocp.set_horizon(Horizon::Fixed(2.0))?;
    let (inf, tilt) = (f64::INFINITY, PI / 4.0);
    let (mut lower, mut upper) = ([-inf; 12], [inf; 12]);
    (lower[6], lower[7], upper[6], upper[7]) = (-tilt, -tilt, tilt, tilt);
    ocp.set_state_bounds(&lower, &upper)?;
    ocp.set_control_bounds(&[0.0; 4], &[2.5; 4])?;
    ocp.set_initial_state_parameter("x0", &[0.0; 12])?;
    ocp.set_control_guess(|_| vec![quadrotor::HOVER; 4]);
    Ok(ocp)
}

/// The example: 50 steps from hover at the origin.
pub fn example() -> MpcExample {
    MpcExample {
        name: "quadrotor",
        intervals: 20,
        dt: 0.1,
        steps: 50,
        x_init: vec![0.0; 12],
        stage_cost,
        ocp: problem,
    }
}

/// The example's program (`examples/examples/mpc_quadrotor.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    example().main()
}
