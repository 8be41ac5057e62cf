//! The Ocp helper's call-node routes: dynamics as a compiled `symx::Function`
//! (`Ocp::set_dynamics_function`) and multiple shooting with one call of the compiled
//! interval integration per interval (`Method::multiple_shooting_with_calls`). Each must
//! be the same NLP as the inlined transcription, with a parameter and a free final time
//! passed through the call, and bad functions must be clear errors.
use nlp::ocp::{ButcherTableau, CollocationPoints, Horizon, Method, Ocp, OcpError};
use nlp::Ipm;
use symx::{Function, Matrix};

/// ẋ = −a·x + u with a parameter a, the rate of the scalar LQR problem.
fn rhs(x: &Matrix, u: &Matrix, p: &Matrix) -> Matrix {
    Matrix::from_vec(vec![-p[0] * x[0] + u[0]])
}

/// min ∫₀ᵀ x² + u² dt + T, x(0) = 1, T free in [0.5, 3]: a free-time LQR with the rate as
/// a parameter, so both h = T/N and p go through the calls.
fn lqr(dynamics_function: bool) -> Ocp {
    let mut ocp = Ocp::new(&["x"], &["u"]);
    ocp.add_parameter("a", &[1.0]).unwrap();
    if dynamics_function {
        let (x, u, p) = (
            Matrix::sym_vec("x", 1),
            Matrix::sym_vec("u", 1),
            Matrix::sym_vec("p", 1),
        );
        let f = Function::named(
            "f",
            &[("x", &x), ("u", &u), ("p", &p)],
            &[("xdot", &rhs(&x, &u, &p))],
        )
        .unwrap();
        ocp.set_dynamics_function(f).unwrap();
    } else {
        ocp.set_dynamics(rhs);
    }
    ocp.set_stage_cost(|x, u, _p| x[0].sq() + u[0].sq());
    ocp.set_terminal_cost(|_x, _p, t| 0.1 * t);
    let free = Horizon::Free {
        lower: 0.5,
        upper: 3.0,
        guess: 1.0,
    };
    ocp.set_horizon(free).unwrap();
    ocp.set_initial_state(&[1.0]).unwrap();
    ocp
}

fn solve(ocp: &Ocp, method: &Method, n: usize) -> (f64, Vec<f64>, usize) {
    let tr = ocp.transcribe(method, n).unwrap();
    let mut compiled = tr.compile().unwrap();
    let sol = Ipm::default().solve(&mut compiled).unwrap();
    assert!(sol.status.is_success(), "{:?}", sol.status);
    (sol.objective, sol.x, sol.stats.iterations)
}

/// Same iterations and the same solution to rounding (1e-12: evaluations differ only in
/// summation order, O(1e-16), over ~10 Newton steps).
fn assert_same(a: &(f64, Vec<f64>, usize), b: &(f64, Vec<f64>, usize), what: &str) {
    assert_eq!(a.2, b.2, "{what}: iterations");
    assert!(
        ((a.0 - b.0) / a.0).abs() < 1e-12,
        "{what}: {} vs {}",
        a.0,
        b.0
    );
    let dx =
        a.1.iter()
            .zip(&b.1)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
    assert!(dx < 1e-10, "{what}: solutions differ by {dx:e}");
}

#[test]
fn call_routes_solve_the_inlined_problem() {
    let ms = Method::multiple_shooting(ButcherTableau::rk4(), 2);
    let ms_calls = Method::multiple_shooting_with_calls(ButcherTableau::rk4(), 2);
    let inlined = solve(&lqr(false), &ms, 15);
    assert_same(&inlined, &solve(&lqr(false), &ms_calls, 15), "step calls");
    assert_same(&inlined, &solve(&lqr(true), &ms, 15), "f calls");
    assert_same(
        &inlined,
        &solve(&lqr(true), &ms_calls, 15),
        "f and step calls",
    );
    let col = Method::collocation(CollocationPoints::Radau, 3).unwrap();
    assert_same(
        &solve(&lqr(false), &col, 15),
        &solve(&lqr(true), &col, 15),
        "collocation",
    );
}

#[test]
fn step_calls_hold_one_call_per_interval() {
    let ocp = lqr(false);
    let method = Method::multiple_shooting_with_calls(ButcherTableau::rk4(), 3);
    let tr = ocp.transcribe(&method, 4).unwrap();
    let shown: String = tr
        .problem()
        .constraint_expressions()
        .iter()
        .map(|e| e.to_string())
        .collect();
    let call = format!("{}_interval(", ButcherTableau::rk4().name());
    // 4 intervals, 3 steps each: 4 calls, no RK4 arithmetic of x repeated in the problem.
    assert_eq!(shown.matches(&call).count(), 4, "{shown}");
    // The dynamics function is the given one.
    let f = lqr(true).dynamics_function().unwrap();
    assert_eq!(f.name(), "f");
    assert_eq!(f.call(&[&[2.0], &[1.0], &[3.0]]).unwrap(), vec![vec![-5.0]]);
}

#[test]
fn bad_dynamics_functions_are_errors() {
    let (x, u, p) = (
        Matrix::sym_vec("x", 2),
        Matrix::sym_vec("u", 1),
        Matrix::sym_vec("p", 1),
    );
    let mut ocp = Ocp::new(&["x"], &["u"]);
    let two_inputs = Function::new(&[&x, &u], &[&[x[0]]]).unwrap();
    assert!(matches!(
        ocp.set_dynamics_function(two_inputs),
        Err(OcpError::Invalid { .. })
    ));
    let short = Function::new(&[&x, &u, &p], &[&[x[0]]]).unwrap();
    assert!(matches!(
        ocp.set_dynamics_function(short),
        Err(OcpError::Size {
            expected: 2,
            got: 1,
            ..
        })
    ));
    let wide_x = Function::new(&[&x, &u, &p], &[&[x[0], u[0]]]).unwrap();
    let err = ocp.set_dynamics_function(wide_x).unwrap_err();
    assert!(
        matches!(
            err,
            OcpError::Size {
                expected: 1,
                got: 2,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("input x"), "{err}");
    // p is checked when transcribing: the OCP declares no parameter, f takes one.
    let x1 = Matrix::sym_vec("x", 1);
    let f = Function::new(&[&x1, &u, &p], &[&[x1[0] * p[0]]]).unwrap();
    ocp.set_dynamics_function(f).unwrap();
    ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
    let err = ocp.transcribe(
        &Method::multiple_shooting_with_calls(ButcherTableau::rk4(), 1),
        3,
    );
    let err = err.err().expect("p has the wrong length");
    assert!(
        matches!(
            err,
            OcpError::Size {
                expected: 1,
                got: 0,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("input p"), "{err}");
}
