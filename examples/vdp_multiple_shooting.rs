//! CasADi's `direct_multiple_shooting.py` example (Van der Pol oscillator) with the `Ocp`
//! helper: minimise `∫₀¹⁰ x₁² + x₂² + u² dt` for `ẋ₁ = (1 − x₂²)x₁ − x₂ + u`, `ẋ₂ = x₁`,
//! `x(0) = (0, 1)`, `x₁ ≥ −0.25`, `|u| ≤ 1`; N = 20 intervals of RK4 with M = 4 steps each,
//! the cost integrated by the same steps. `benches/reference/ocp_examples.py` solves the
//! identical NLP with IPOPT; `tests/ocp_examples.rs` compares.
//!
//! Run: `cargo run --release --example vdp_multiple_shooting`
use symnlp::nlp::ocp::{ButcherTableau, Horizon, Method, Ocp, Trajectory};
use symnlp::nlp::{Ipm, IpmOptions};
use symnlp::symx::Matrix;

/// The Van der Pol problem of CasADi's examples (dynamics, cost, bounds; no method yet).
pub fn van_der_pol() -> Result<Ocp, Box<dyn std::error::Error>> {
    let mut ocp = Ocp::new(&["x1", "x2"], &["u"]);
    ocp.set_dynamics(|x, u, _p| {
        Matrix::from_vec(vec![(1.0 - x[1].sq()) * x[0] - x[1] + u[0], x[0]])
    });
    ocp.set_stage_cost(|x, u, _p| x[0].sq() + x[1].sq() + u[0].sq());
    ocp.set_horizon(Horizon::Fixed(10.0))?;
    ocp.set_initial_state(&[0.0, 1.0])?;
    ocp.set_state_bounds(&[-0.25, f64::NEG_INFINITY], &[f64::INFINITY, f64::INFINITY])?;
    ocp.set_control_bounds(&[-1.0], &[1.0])?;
    Ok(ocp)
}

/// Transcribes with RK4 multiple shooting (`n` intervals, 4 steps each) and solves.
pub fn solve(n: usize, options: IpmOptions) -> Result<Trajectory, Box<dyn std::error::Error>> {
    let ocp = van_der_pol()?;
    let tr = ocp.transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 4), n)?;
    let mut compiled = tr.compile()?;
    let sol = Ipm::new(options).solve(&mut compiled)?;
    Ok(tr.trajectory(&sol)?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let traj = solve(20, IpmOptions::default())?;
    println!("{:?}: objective {:.10}", traj.status, traj.objective);
    print!("{}", traj.to_csv());
    Ok(())
}
