//! CasADi's `direct_collocation.py` example (Van der Pol oscillator, the problem of
//! `examples/src/vdp_multiple_shooting.rs`) with the `Ocp` helper: N = 20 intervals, Legendre
//! collocation of degree 3, the cost by the collocation quadrature, the state bounds also
//! at the collocation points. `benches/reference/ocp_examples.py` solves the identical
//! NLP with IPOPT; `tests/ocp_examples.rs` compares.
//!
//! Run: `cargo run --release -p symnlp-examples --example vdp_collocation`
use symnlp::nlp::ocp::{CollocationPoints, Horizon, Method, Ocp, Trajectory};
use symnlp::nlp::{Ipm, IpmOptions};
use symnlp::symx::Matrix;

/// Transcribes with Legendre collocation of `degree` on `n` intervals and solves.
pub fn solve(
    n: usize,
    degree: usize,
    options: IpmOptions,
) -> Result<Trajectory, Box<dyn std::error::Error>> {
    let mut ocp = Ocp::new(&["x1", "x2"], &["u"]);
    ocp.set_dynamics(|x, u, _p| {
        Matrix::from_vec(vec![(1.0 - x[1].sq()) * x[0] - x[1] + u[0], x[0]])
    });
    ocp.set_stage_cost(|x, u, _p| x[0].sq() + x[1].sq() + u[0].sq());
    ocp.set_horizon(Horizon::Fixed(10.0))?;
    ocp.set_initial_state(&[0.0, 1.0])?;
    ocp.set_state_bounds(&[-0.25, f64::NEG_INFINITY], &[f64::INFINITY, f64::INFINITY])?;
    ocp.set_control_bounds(&[-1.0], &[1.0])?;
    let method = Method::collocation(CollocationPoints::Legendre, degree)?;
    let tr = ocp.transcribe(&method, n)?;
    let mut compiled = tr.compile()?;
    let sol = Ipm::new(options).solve(&mut compiled)?;
    Ok(tr.trajectory(&sol)?)
}

/// The example's program (`examples/examples/vdp_collocation.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let traj = solve(20, 3, IpmOptions::default())?;
    println!("{:?}: objective {:.10}", traj.status, traj.objective);
    println!("{}", serde_json::to_string(&traj)?);
    Ok(())
}
