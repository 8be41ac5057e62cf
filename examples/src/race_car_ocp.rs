//! CasADi's race-car example (`examples/src/race_car.rs`, written line for line) restated
//! with the `Ocp` helper: minimum time `T` to drive 1 m from standstill, `ṗ = v`,
//! `v̇ = u − v`, `0 ≤ u ≤ 1`, speed limit `v ≤ 1 − sin(2πp)/2` at every grid point, RK4
//! over N = 100 intervals. The NLP is the one of `examples/src/race_car.rs`;
//! `tests/ocp_examples.rs` compares with IPOPT (`benches/reference/ocp_examples.py`).
//!
//! Run: `cargo run --release -p symnlp-examples --example race_car_ocp`
use std::f64::consts::PI;
use symnlp::nlp::ocp::{ButcherTableau, Horizon, Method, Ocp, Transcription};
use symnlp::nlp::Relation;
use symnlp::symx::Matrix;

/// The optimal control problem (no transcription yet).
pub fn problem() -> Result<Ocp, Box<dyn std::error::Error>> {
    let mut ocp = Ocp::new(&["position", "speed"], &["throttle"]);
    ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![x[1], u[0] - x[1]]));
    ocp.set_terminal_cost(|_x, _p, t| t); // minimum time
    ocp.set_horizon(Horizon::Free {
        lower: 0.0,
        upper: f64::INFINITY,
        guess: 1.0,
    })?;
    ocp.add_path_constraint("speed limit", |x, _u, _p| {
        x[1].le(1.0 - (2.0 * PI * x[0]).sin() / 2.0)
    });
    ocp.set_control_bounds(&[0.0], &[1.0])?;
    ocp.set_initial_state(&[0.0, 0.0])?;
    ocp.add_boundary_constraint("finish line", |_x0, x_t, _p, _t| x_t[0].eq(1.0));
    ocp.set_state_guess(|_t| vec![0.0, 1.0]);
    Ok(ocp)
}

/// The race car as an optimal control problem, transcribed on `n` RK4 intervals.
pub fn transcription(n: usize) -> Result<Transcription, Box<dyn std::error::Error>> {
    let ocp = problem()?;
    Ok(ocp.transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), n)?)
}

/// The example's program (`examples/examples/race_car_ocp.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let tr = transcription(100)?;
    let mut compiled = tr.compile()?;
    let sol = symnlp::nlp::Ipm::default().solve(&mut compiled)?;
    let traj = tr.trajectory(&sol)?;
    println!(
        "{:?}: minimum time T = {:.6} s",
        traj.status, traj.final_time
    );
    Ok(())
}
