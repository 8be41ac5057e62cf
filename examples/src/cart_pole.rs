//! Cart-pole swing-up (Kelly, "An introduction to trajectory optimization", SIAM Review
//! 59(4), 2017, §6 and appendix E): move the cart by `d = 1` m and swing the pole from
//! hanging (`θ = 0`) to upright (`θ = π`) in `T = 2` s with minimum `∫ u² dt`, `|u| ≤ 20` N,
//! `|cart position| ≤ 2` m. Radau collocation of degree 3 on N = 20 intervals.
//! `benches/reference/ocp_examples.py` solves the identical NLP with IPOPT;
//! `tests/ocp_examples.rs` compares.
//!
//! Run: `cargo run --release -p symnlp-examples --example cart_pole > cart_pole.csv`
use std::f64::consts::PI;
use symnlp::nlp::ocp::{CollocationPoints, Horizon, Method, Ocp, Transcription};
use symnlp::symx::Matrix;

const M_CART: f64 = 1.0;
const M_POLE: f64 = 0.3;
const LENGTH: f64 = 0.5;
const GRAVITY: f64 = 9.81;

/// `ẋ` for `x = [cart position, angle (0 hanging), cart speed, angular rate]`, `u` = force.
pub fn dynamics(x: &Matrix, u: &Matrix) -> Matrix {
    let (s, c) = (x[1].sin(), x[1].cos());
    let (l, m1, m2, g) = (LENGTH, M_CART, M_POLE, GRAVITY);
    let ddq1 = (l * m2 * s * x[3].sq() + u[0] + m2 * g * c * s) / (m1 + m2 * (1.0 - c.sq()));
    let ddq2 = -(l * m2 * c * s * x[3].sq() + u[0] * c + (m1 + m2) * g * s)
        / (l * m1 + l * m2 * (1.0 - c.sq()));
    Matrix::from_vec(vec![x[2], x[3], ddq1, ddq2])
}

/// The optimal control problem (no transcription yet).
pub fn problem() -> Result<Ocp, Box<dyn std::error::Error>> {
    let mut ocp = Ocp::new(&["q1", "q2", "dq1", "dq2"], &["force"]);
    ocp.set_dynamics(|x, u, _p| dynamics(x, u));
    ocp.set_stage_cost(|_x, u, _p| u[0].sq());
    ocp.set_horizon(Horizon::Fixed(2.0))?;
    let inf = f64::INFINITY;
    ocp.set_state_bounds(&[-2.0, -inf, -inf, -inf], &[2.0, inf, inf, inf])?;
    ocp.set_control_bounds(&[-20.0], &[20.0])?;
    ocp.set_initial_state(&[0.0; 4])?;
    let goal = [1.0, PI, 0.0, 0.0];
    ocp.set_final_state(&goal)?;
    ocp.set_state_guess_linear(&[0.0; 4], &goal)?;
    Ok(ocp)
}

/// The swing-up on `n` intervals (`x = [cart position, angle, cart speed, angular rate]`).
pub fn transcription(n: usize) -> Result<Transcription, Box<dyn std::error::Error>> {
    let ocp = problem()?;
    Ok(ocp.transcribe(&Method::collocation(CollocationPoints::Radau, 3)?, n)?)
}

/// The example's program (`examples/examples/cart_pole.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let tr = transcription(20)?;
    let mut compiled = tr.compile()?;
    let sol = symnlp::nlp::Ipm::default().solve(&mut compiled)?;
    let traj = tr.trajectory(&sol)?;
    eprintln!("{:?}: ∫u² = {:.8}", traj.status, traj.objective);
    print!("{}", traj.to_csv());
    Ok(())
}
