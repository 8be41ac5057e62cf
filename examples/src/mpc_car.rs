//! Kinematic car (bicycle model) parking by model-predictive control: states position
//! `(px, py)`, heading `θ`, speed `v`; controls acceleration `a` and steering angle `δ`:
//! `ṗx = v cos θ, ṗy = v sin θ, θ̇ = v tan δ / L, v̇ = a` with wheelbase `L = 1` m. From
//! rest at the origin to rest at `(5, 2)` m heading 0:
//! `l = (px − 5)² + (py − 2)² + θ² + 0.1 v² + 0.1 a² + 0.1 δ²`, `φ = 10 l(x(T), 0)`,
//! `|a| ≤ 2` m/s², `|δ| ≤ 0.6` rad, `−1 ≤ v ≤ 3` m/s. RK4 multiple shooting, N = 30
//! intervals of dt = 0.1 s, 80 closed-loop steps on the nominal plant.
//! `benches/reference/mpc_casadi.py car` runs the identical loop with CasADi.
//!
//! Run: `cargo run --release -p symnlp-examples --example mpc_car [-- sqp] [--json]`
use symnlp::nlp::ocp::{Horizon, Ocp};
use symnlp::symx::{Expr, Matrix};

pub use crate::mpc_common::MpcExample;

/// Wheelbase (m).
const WHEELBASE: f64 = 1.0;
/// Target position.
const TARGET: [f64; 2] = [5.0, 2.0];

/// The stage cost `l(x, u)`.
pub fn stage_cost(x: &Matrix, u: &Matrix) -> Expr {
    (x[0] - TARGET[0]).sq()
        + (x[1] - TARGET[1]).sq()
        + x[2].sq()
        + 0.1 * x[3].sq()
        + 0.1 * (u[0].sq() + u[1].sq())
}

/// The OCP solved at every step (initial state: the parameter `x0`).
pub fn problem() -> Result<Ocp, Box<dyn std::error::Error>> {
    let mut ocp = Ocp::new(&["px", "py", "theta", "v"], &["a", "delta"]);
    ocp.set_dynamics(|x, u, _p| {
        Matrix::from_vec(vec![
            x[3] * x[2].cos(),
            x[3] * x[2].sin(),
            x[3] * u[1].tan() / WHEELBASE,
            u[0],
        ])
    });
    ocp.set_stage_cost(|x, u, _p| stage_cost(x, u));
    let zero = Matrix::from_vec(vec![Expr::zero(); 2]);
    ocp.set_terminal_cost(move |x, _p, _t| 10.0 * stage_cost(x, &zero));
    ocp.set_horizon(Horizon::Fixed(3.0))?;
    let inf = f64::INFINITY;
    ocp.set_state_bounds(&[-inf, -inf, -inf, -1.0], &[inf, inf, inf, 3.0])?;
    ocp.set_control_bounds(&[-2.0, -0.6], &[2.0, 0.6])?;
    ocp.set_initial_state_parameter("x0", &[0.0; 4])?;
    Ok(ocp)
}

/// The example: 80 steps from rest at the origin.
pub fn example() -> MpcExample {
    MpcExample {
        name: "car",
        intervals: 30,
        dt: 0.1,
        steps: 80,
        x_init: vec![0.0; 4],
        stage_cost,
        ocp: problem,
    }
}

/// The example's program (`examples/examples/mpc_car.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    example().main()
}
