//! Two-link planar arm, minimum time: from rest at `q = (0, 0)` to rest at
//! `q = (π/2, −π/2)` with torques `|τᵢ| ≤ 1` N m, minimising `T + 0.01 ∫ (τ₁² + τ₂²) dt`
//! (the small torque penalty makes the bang-bang optimum unique). Two uniform links of
//! mass 1 kg and length 1 m (centre of mass at 0.5 m, inertia 1/12 kg m²) in a horizontal
//! plane: `M(q) q̈ + c(q, q̇) = τ`. Free final time; Legendre collocation of degree 3 on
//! N = 20 intervals. `benches/reference/ocp_examples.py` solves the identical NLP with
//! IPOPT; `tests/ocp_examples.rs` compares.
//!
//! Run: `cargo run --release -p symnlp-examples --example two_link_arm`
use std::f64::consts::PI;
use symnlp::nlp::ocp::{CollocationPoints, Horizon, Method, Ocp, Transcription};
use symnlp::symx::Matrix;

const MASS: f64 = 1.0;
const LENGTH: f64 = 1.0;
const COM: f64 = 0.5;
const INERTIA: f64 = 1.0 / 12.0;

/// `[q̇; M(q)⁻¹(τ − c(q, q̇))]` with the 2×2 inverse written out.
fn dynamics(x: &Matrix, u: &Matrix) -> Matrix {
    let (m, l, lc, i) = (MASS, LENGTH, COM, INERTIA);
    let (q2, dq1, dq2) = (x[1], x[2], x[3]);
    let m11 = m * lc * lc + i + m * (l * l + lc * lc + 2.0 * l * lc * q2.cos()) + i;
    let m12 = m * (lc * lc + l * lc * q2.cos()) + i;
    let m22 = m * lc * lc + i;
    let h = m * l * lc * q2.sin();
    let r1 = u[0] + h * (2.0 * dq1 * dq2 + dq2.sq());
    let r2 = u[1] - h * dq1.sq();
    let det = m11 * m22 - m12.sq();
    Matrix::from_vec(vec![
        dq1,
        dq2,
        (m22 * r1 - m12 * r2) / det,
        (m11 * r2 - m12 * r1) / det,
    ])
}

/// The optimal control problem (no transcription yet).
pub fn problem() -> Result<Ocp, Box<dyn std::error::Error>> {
    let mut ocp = Ocp::new(&["q1", "q2", "dq1", "dq2"], &["tau1", "tau2"]);
    ocp.set_dynamics(|x, u, _p| dynamics(x, u));
    ocp.set_stage_cost(|_x, u, _p| 0.01 * (u[0].sq() + u[1].sq()));
    ocp.set_terminal_cost(|_x, _p, t| t);
    ocp.set_horizon(Horizon::Free {
        lower: 0.1,
        upper: 10.0,
        guess: 3.0,
    })?;
    ocp.set_control_bounds(&[-1.0, -1.0], &[1.0, 1.0])?;
    let goal = [PI / 2.0, -PI / 2.0, 0.0, 0.0];
    ocp.set_initial_state(&[0.0; 4])?;
    ocp.set_final_state(&goal)?;
    ocp.set_state_guess_linear(&[0.0; 4], &goal)?;
    Ok(ocp)
}

/// The manoeuvre on `n` collocation intervals.
pub fn transcription(n: usize) -> Result<Transcription, Box<dyn std::error::Error>> {
    let ocp = problem()?;
    Ok(ocp.transcribe(&Method::collocation(CollocationPoints::Legendre, 3)?, n)?)
}

/// The example's program (`examples/examples/two_link_arm.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let tr = transcription(20)?;
    let mut compiled = tr.compile()?;
    let sol = symnlp::nlp::Ipm::default().solve(&mut compiled)?;
    let traj = tr.trajectory(&sol)?;
    eprintln!(
        "{:?}: T = {:.8} s, cost {:.8}",
        traj.status, traj.final_time, traj.objective
    );
    print!("{}", traj.to_csv());
    Ok(())
}
