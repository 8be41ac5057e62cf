//! CasADi's `direct_multiple_shooting.py` example (Van der Pol oscillator) with the `Ocp`
//! helper: minimise `∫₀¹⁰ x₁² + x₂² + u² dt` for `ẋ₁ = (1 − x₂²)x₁ − x₂ + u`, `ẋ₂ = x₁`,
//! `x(0) = (0, 1)`, `x₁ ≥ −0.25`, `|u| ≤ 1`; N = 20 intervals of RK4 with M = 4 steps each,
//! the cost integrated by the same steps. `benches/reference/ocp_examples.py` solves the
//! identical NLP with IPOPT; `tests/ocp_examples.rs` compares.
//!
//! The call-node route: `van_der_pol_with_calls` gives the same problem with the dynamics
//! as one compiled `symx::Function` (`Ocp::set_dynamics_function`), and
//! `Method::multiple_shooting_with_calls` compiles one interval's RK4 integration once and
//! calls it at every interval, so the NLP holds the dynamics once; same optimum, same
//! iterates (`tests/ocp_examples.rs`).
//!
//! Run: `cargo run --release -p symnlp-examples --example vdp_multiple_shooting [-- --calls]`
use symnlp::nlp::ocp::{ButcherTableau, Horizon, Method, Ocp, Trajectory};
use symnlp::nlp::{Ipm, IpmOptions};
use symnlp::symx::{Function, Matrix};

/// `ẋ` of the Van der Pol oscillator.
fn vdp(x: &Matrix, u: &Matrix) -> Matrix {
    Matrix::from_vec(vec![(1.0 - x[1].sq()) * x[0] - x[1] + u[0], x[0]])
}

/// The Van der Pol problem of CasADi's examples (dynamics, cost, bounds; no method yet).
pub fn van_der_pol() -> Result<Ocp, Box<dyn std::error::Error>> {
    let mut ocp = Ocp::new(&["x1", "x2"], &["u"]);
    ocp.set_dynamics(|x, u, _p| vdp(x, u));
    common(ocp)
}

/// The same problem with the dynamics compiled once as `f(x, u, p) -> ẋ` and called.
pub fn van_der_pol_with_calls() -> Result<Ocp, Box<dyn std::error::Error>> {
    let (x, u, p) = (
        Matrix::sym_vec("x", 2),
        Matrix::sym_vec("u", 1),
        Matrix::sym_vec("p", 0),
    );
    let f = Function::named(
        "vdp",
        &[("x", &x), ("u", &u), ("p", &p)],
        &[("xdot", &vdp(&x, &u))],
    )?;
    let mut ocp = Ocp::new(&["x1", "x2"], &["u"]);
    ocp.set_dynamics_function(f)?;
    common(ocp)
}

fn common(mut ocp: Ocp) -> Result<Ocp, Box<dyn std::error::Error>> {
    ocp.set_stage_cost(|x, u, _p| x[0].sq() + x[1].sq() + u[0].sq());
    ocp.set_horizon(Horizon::Fixed(10.0))?;
    ocp.set_initial_state(&[0.0, 1.0])?;
    ocp.set_state_bounds(&[-0.25, f64::NEG_INFINITY], &[f64::INFINITY, f64::INFINITY])?;
    ocp.set_control_bounds(&[-1.0], &[1.0])?;
    Ok(ocp)
}

/// Transcribes with RK4 multiple shooting (`n` intervals, 4 steps each) and solves.
pub fn solve(n: usize, options: IpmOptions) -> Result<Trajectory, Box<dyn std::error::Error>> {
    solve_with(n, options, false)
}

/// As [`solve`]; with `calls`, through the call-node route (dynamics function, one call
/// of the compiled interval integration per interval).
pub fn solve_with(
    n: usize,
    options: IpmOptions,
    calls: bool,
) -> Result<Trajectory, Box<dyn std::error::Error>> {
    let (ocp, method) = if calls {
        let m = Method::multiple_shooting_with_calls(ButcherTableau::rk4(), 4);
        (van_der_pol_with_calls()?, m)
    } else {
        (
            van_der_pol()?,
            Method::multiple_shooting(ButcherTableau::rk4(), 4),
        )
    };
    let tr = ocp.transcribe(&method, n)?;
    let mut compiled = tr.compile()?;
    let sol = Ipm::new(options).solve(&mut compiled)?;
    Ok(tr.trajectory(&sol)?)
}

/// The example's program (`examples/examples/vdp_multiple_shooting.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let calls = std::env::args().any(|a| a == "--calls");
    let traj = solve_with(20, IpmOptions::default(), calls)?;
    println!("{:?}: objective {:.10}", traj.status, traj.objective);
    print!("{}", traj.to_csv());
    Ok(())
}
