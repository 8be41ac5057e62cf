//! Quadrotor point-to-point: from hover at the origin to hover at (1, 1, 1) m in 2 s with
//! minimum `∫ Σᵢ (Fᵢ − F_hover)² dt`, rotor thrusts `0 ≤ Fᵢ ≤ 2.5` N, roll and pitch within
//! ±45°. Rigid body with Z-Y-X Euler angles and body rates; the parameters (mass 0.468 kg,
//! arm 0.225 m, inertia diag(4.856, 4.856, 8.801)·10⁻³ kg m², drag-to-thrust ratio
//! 0.03826 m) are those of Luukkonen, "Modelling and control of quadcopter" (Aalto
//! University, 2011). 12 states, 4 controls; RK4 multiple shooting on N = 20 intervals.
//! `benches/reference/ocp_examples.py` solves the identical NLP with IPOPT;
//! `tests/ocp_examples.rs` compares.
//!
//! With `--calls`, the call-node route: `Method::multiple_shooting_with_calls` compiles one
//! RK4 interval once and calls it at every interval — the same NLP and iterates with a
//! graph that holds the dynamics once (19× fewer nodes, 23× less peak heap at N = 1000:
//! `docs/performance.md`). `problem_with(true)` gives the dynamics as a compiled
//! `symx::Function` instead (`Ocp::set_dynamics_function`), also the same NLP.
//!
//! Run: `cargo run --release -p symnlp-examples --example quadrotor [-- --calls]`
use std::f64::consts::PI;
use symnlp::nlp::ocp::{ButcherTableau, Horizon, Method, Ocp, Transcription};
use symnlp::symx::{Expr, Function, Matrix};

const MASS: f64 = 0.468;
const ARM: f64 = 0.225;
const J: [f64; 3] = [4.856e-3, 4.856e-3, 8.801e-3];
const DRAG: f64 = 0.03826;
const GRAVITY: f64 = 9.81;
/// Thrust per rotor that holds the quadrotor in hover.
pub const HOVER: f64 = MASS * GRAVITY / 4.0;

/// `ẋ` for `x = [position, velocity, (roll, pitch, yaw), body rates]`, `u` = rotor thrusts.
pub fn dynamics(x: &Matrix, u: &Matrix) -> Matrix {
    let (phi, th, psi) = (x[6], x[7], x[8]);
    let (wx, wy, wz) = (x[9], x[10], x[11]);
    let f: Expr = u.sum();
    let ax = (psi.cos() * th.sin() * phi.cos() + psi.sin() * phi.sin()) * f / MASS;
    let ay = (psi.sin() * th.sin() * phi.cos() - psi.cos() * phi.sin()) * f / MASS;
    let az = th.cos() * phi.cos() * f / MASS - GRAVITY;
    let dphi = wx + phi.sin() * th.tan() * wy + phi.cos() * th.tan() * wz;
    let dth = phi.cos() * wy - phi.sin() * wz;
    let dpsi = (phi.sin() * wy + phi.cos() * wz) / th.cos();
    let tx = ARM * (u[3] - u[1]);
    let ty = ARM * (u[2] - u[0]);
    let tz = DRAG * (u[0] - u[1] + u[2] - u[3]);
    let dwx = (tx - (J[2] - J[1]) * wy * wz) / J[0];
    let dwy = (ty - (J[0] - J[2]) * wz * wx) / J[1];
    let dwz = (tz - (J[1] - J[0]) * wx * wy) / J[2];
    Matrix::from_vec(vec![
        x[3], x[4], x[5], ax, ay, az, dphi, dth, dpsi, dwx, dwy, dwz,
    ])
}

/// The optimal control problem (no transcription yet).
pub fn problem() -> Result<Ocp, Box<dyn std::error::Error>> {
    problem_with(false)
}

/// The optimal control problem; with `dynamics_function`, the dynamics is compiled once as
/// `f(x, u, p) -> ẋ` and called (`Ocp::set_dynamics_function`) instead of a closure.
pub fn problem_with(dynamics_function: bool) -> Result<Ocp, Box<dyn std::error::Error>> {
    let states = [
        "x", "y", "z", "vx", "vy", "vz", "roll", "pitch", "yaw", "wx", "wy", "wz",
    ];
    let mut ocp = Ocp::new(&states, &["F1", "F2", "F3", "F4"]);
    if dynamics_function {
        let (x, u) = (Matrix::sym_vec("x", 12), Matrix::sym_vec("u", 4));
        let p = Matrix::sym_vec("p", 0);
        let xdot = dynamics(&x, &u);
        let f = Function::named(
            "quadrotor",
            &[("x", &x), ("u", &u), ("p", &p)],
            &[("xdot", &xdot)],
        )?;
        ocp.set_dynamics_function(f)?;
    } else {
        ocp.set_dynamics(|x, u, _p| dynamics(x, u));
    }
    ocp.set_stage_cost(|_x, u, _p| u.iter().map(|&f| (f - HOVER).sq()).sum());
    ocp.set_horizon(Horizon::Fixed(2.0))?;
    let (inf, tilt) = (f64::INFINITY, PI / 4.0);
    let mut lower = [-inf; 12];
    let mut upper = [inf; 12];
    (lower[6], lower[7], upper[6], upper[7]) = (-tilt, -tilt, tilt, tilt);
    ocp.set_state_bounds(&lower, &upper)?;
    ocp.set_control_bounds(&[0.0; 4], &[2.5; 4])?;
    let mut goal = [0.0; 12];
    goal[..3].copy_from_slice(&[1.0, 1.0, 1.0]);
    ocp.set_initial_state(&[0.0; 12])?;
    ocp.set_final_state(&goal)?;
    ocp.set_state_guess_linear(&[0.0; 12], &goal)?;
    ocp.set_control_guess(|_t| vec![HOVER; 4]);
    Ok(ocp)
}

/// The manoeuvre on `n` RK4 intervals.
pub fn transcription(n: usize) -> Result<Transcription, Box<dyn std::error::Error>> {
    let ocp = problem()?;
    Ok(ocp.transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), n)?)
}

/// The same NLP through call nodes: one call per interval of the RK4 step compiled once
/// (the dynamics closure is inlined into that one step, which keeps the evaluation work
/// that of the inlined version; see `docs/ocp.md`, "Call nodes").
pub fn transcription_with_calls(n: usize) -> Result<Transcription, Box<dyn std::error::Error>> {
    let ocp = problem()?;
    let method = Method::multiple_shooting_with_calls(ButcherTableau::rk4(), 1);
    Ok(ocp.transcribe(&method, n)?)
}

/// The example's program (`examples/examples/quadrotor.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let tr = if std::env::args().any(|a| a == "--calls") {
        transcription_with_calls(20)?
    } else {
        transcription(20)?
    };
    let mut compiled = tr.compile()?;
    let sol = symnlp::nlp::Ipm::default().solve(&mut compiled)?;
    let traj = tr.trajectory(&sol)?;
    eprintln!("{:?}: cost {:.8}", traj.status, traj.objective);
    print!("{}", traj.to_csv());
    Ok(())
}
