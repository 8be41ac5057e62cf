//! The Goddard rocket of COPS 3.0 (Dolan, Moré, Munson, ANL/MCS-TM-246, 2004, problem 10)
//! with the `Ocp` helper: maximise the final height, trapezoidal collocation with the
//! thrust at the nodes, free final time, N = 100. The symnlp half of the first program of
//! docs/casadi.md; the CasADi half is `python/examples/casadi/goddard_rocket.py`. Both
//! print h(T) = 1.0128320 (COPS: 1.01283); `nlp/tests/ocp_transcriptions.rs` checks it.
//!
//! Run: `cargo run --release -p symnlp-examples --example goddard_rocket`
use symnlp::nlp::ocp::{ControlInterpolation, Horizon, Method, Ocp};
use symnlp::nlp::{CommonOptions, Ipm, IpmOptions, Relation};
use symnlp::symx::Matrix;

/// The example's program (`examples/examples/goddard_rocket.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (h0, m0, g0, hc, vc, inf) = (1.0f64, 1.0, 1.0, 500.0, 620.0, f64::INFINITY);
    let c = 0.5 * (g0 * h0).sqrt();
    let (mf, dc, tmax) = (0.6 * m0, 0.5 * vc * m0 / g0, 3.5 * g0 * m0);
    let mut ocp = Ocp::new(&["h", "v", "m"], &["T"]);
    ocp.set_dynamics(move |x, u, _p| {
        let drag = dc * x[1].sq() * (-hc * (x[0] - h0) / h0).exp();
        let gravity = g0 * (h0 / x[0]).sq();
        Matrix::from_vec(vec![x[1], (u[0] - drag) / x[2] - gravity, -u[0] / c])
    });
    ocp.set_terminal_cost(|x, _p, _t| -x[0]);
    ocp.set_horizon(Horizon::free(0.0, inf, 1.0))?;
    ocp.set_initial_state(&[h0, 0.0, m0])?;
    ocp.add_boundary_constraint("final mass", move |_x0, xt, _p, _t| xt[2].eq(mf));
    ocp.set_state_bounds(&[h0, 0.0, mf], &[inf, inf, m0])?;
    ocp.set_control_bounds(&[0.0], &[tmax])?;
    ocp.set_control_interpolation(ControlInterpolation::PiecewiseLinear);
    ocp.set_state_guess(move |t| vec![1.0, t * (1.0 - t), (mf - m0) * t + m0]);
    ocp.set_control_guess(move |_t| vec![tmax / 2.0]);
    let tr = ocp.transcribe(&Method::trapezoidal(), 100)?;
    let common = CommonOptions {
        tol: 1e-10,
        ..CommonOptions::default()
    };
    let sol = Ipm::new(IpmOptions {
        common,
        ..IpmOptions::default()
    })
    .solve(&mut tr.compile()?)?;
    let traj = tr.trajectory(&sol)?;
    println!(
        "{}: h(T) = {:.7}, T = {:.7}",
        traj.status, -traj.objective, traj.final_time
    );
    Ok(())
}
