//! Multiple shooting with the adaptive integrator as a call node reaches the optimum of the
//! Runge–Kutta transcription of the same OCP (CasADi's Van der Pol example,
//! `examples/src/vdp_multiple_shooting.rs`): minimise `∫₀¹⁰ x₁² + x₂² + u² dt`,
//! `ẋ₁ = (1 − x₂²)x₁ − x₂ + u`, `ẋ₂ = x₁`, `x(0) = (0, 1)`, `x₁ ≥ −0.25`, `|u| ≤ 1`,
//! N = 20 intervals, piecewise-constant control.
use nlp::integrator::{Integrator, IntegratorOptions};
use nlp::ocp::{ButcherTableau, Horizon, Method, Ocp};
use nlp::{bounded, Ipm, IpmOptions, Problem, Relation};
use symx::{Expr, Function, Matrix};

const N: usize = 20;
const T: f64 = 10.0;

fn vdp(x: &[Expr], u: Expr) -> Vec<Expr> {
    vec![(1.0 - x[1].sq()) * x[0] - x[1] + u, x[0]]
}

/// The RK transcription: RK4 with 40 steps per interval (h = 0.0125, global error of the
/// dynamics ~1e-8), the cost integrated by the same steps.
fn rk_solution() -> (f64, Vec<f64>) {
    let mut ocp = Ocp::new(&["x1", "x2"], &["u"]);
    ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vdp(x, u[0])));
    ocp.set_stage_cost(|x, u, _p| x[0].sq() + x[1].sq() + u[0].sq());
    ocp.set_horizon(Horizon::Fixed(T)).unwrap();
    ocp.set_initial_state(&[0.0, 1.0]).unwrap();
    ocp.set_state_bounds(&[-0.25, f64::NEG_INFINITY], &[f64::INFINITY, f64::INFINITY])
        .unwrap();
    ocp.set_control_bounds(&[-1.0], &[1.0]).unwrap();
    let tr = ocp
        .transcribe(
            &Method::multiple_shooting_with_calls(ButcherTableau::rk4(), 40),
            N,
        )
        .unwrap();
    let mut compiled = tr.compile().unwrap();
    let sol = Ipm::new(IpmOptions::default())
        .solve(&mut compiled)
        .unwrap();
    assert!(sol.status.is_success(), "{:?}", sol.status);
    let traj = tr.trajectory(&sol).unwrap();
    (traj.objective, traj.control("u").unwrap().to_vec())
}

#[test]
fn shooting_with_the_integrator_reaches_the_rk_optimum() {
    // One interval: states (x1, x2, q) with the running cost q̇, control u as parameter.
    let z = Matrix::sym_vec("z", 3);
    let u = Matrix::sym_vec("u", 1);
    let mut zdot = vdp(&z[..2], u[0]);
    zdot.push(z[0].sq() + z[1].sq() + u[0].sq());
    let ode = Function::named("vdp", &[("z", &z), ("u", &u)], &[("zdot", &zdot)]).unwrap();
    let options = IntegratorOptions {
        rtol: 1e-10,
        atol: 1e-12,
        ..Default::default()
    };
    let f = Integrator::new(&ode, 0.0, T / N as f64, options)
        .unwrap()
        .to_function()
        .unwrap();

    let mut pb = Problem::new();
    let x = pb.variable("x", 2 * (N + 1)).unwrap();
    let uu = pb.variable("u", N).unwrap();
    pb.subject_to(x[0].eq(0.0)).unwrap();
    pb.subject_to(x[1].eq(1.0)).unwrap();
    let mut cost = Expr::zero();
    for k in 0..N {
        let start = [x[2 * k], x[2 * k + 1], Expr::zero()];
        let end = f.apply(&[&start, &[uu[k]]]).unwrap().remove(0);
        pb.subject_to((end[0] - x[2 * k + 2]).eq(0.0)).unwrap();
        pb.subject_to((end[1] - x[2 * k + 3]).eq(0.0)).unwrap();
        cost += end[2];
        pb.subject_to(bounded(-1.0, uu[k], 1.0)).unwrap();
    }
    for k in 0..=N {
        pb.subject_to(x[2 * k].ge(-0.25)).unwrap();
    }
    pb.minimize(cost);
    let mut compiled = pb.compile().unwrap();
    let sol = Ipm::new(IpmOptions::default())
        .solve(&mut compiled)
        .unwrap();
    assert!(sol.status.is_success(), "{:?}", sol.status);

    let (objective, controls) = rk_solution();
    // Both transcriptions solve the same continuous problem up to their integration
    // errors (≲1e-8 for RK4 with h = 0.0125, ≲1e-9 for the adaptive method at rtol 1e-10)
    // and IPOPT's tolerance 1e-8: objectives agree to 1e-6, controls to 1e-4.
    assert!(
        (sol.objective - objective).abs() < 1e-6 * objective.abs(),
        "{} vs {objective}",
        sol.objective
    );
    let u_int = pb.values(&uu, &sol).unwrap();
    for (a, b) in u_int.iter().zip(&controls) {
        assert!((a - b).abs() < 1e-4, "{u_int:?} vs {controls:?}");
    }
    println!(
        "integrator shooting: objective {:.12}, {} iterations; RK4 (40 steps/interval) {:.12}",
        sol.objective, sol.stats.iterations, objective
    );
}
