//! The Ocp helper (nlp::ocp): transcriptions against hand-written ones, convergence to an
//! analytic optimum, guesses, trajectories and errors.
use nlp::ocp::{ButcherTableau, CollocationPoints, Horizon, Method, Ocp, OcpError};
use nlp::{BuildError, Ipm, NumericNlp, Relation};
use symx::Matrix;

/// ẋ = −x + u, min ∫₀¹ x² + u² dt, x(0) = 1: the scalar LQR problem.
fn lqr() -> Ocp {
    let mut ocp = Ocp::new(&["x"], &["u"]);
    ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![-x[0] + u[0]]));
    ocp.set_stage_cost(|x, u, _p| x[0].sq() + u[0].sq());
    ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
    ocp.set_initial_state(&[1.0]).unwrap();
    ocp
}

/// The LQR optimum P(0)·x(0)² from the Riccati equation Ṗ = P² + 2P − 1, P(1) = 0,
/// integrated backwards with 10⁵ RK4 steps in plain f64 (error ~1e-20).
fn riccati_value() -> f64 {
    let f = |p: f64| p * p + 2.0 * p - 1.0;
    let n = 100_000;
    let h = -1.0 / n as f64;
    let mut p = 0.0;
    for _ in 0..n {
        let k1 = f(p);
        let k2 = f(p + h / 2.0 * k1);
        let k3 = f(p + h / 2.0 * k2);
        let k4 = f(p + h * k3);
        p += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    p
}

fn solve(ocp: &Ocp, method: &Method, n: usize) -> nlp::Trajectory {
    let tr = ocp.transcribe(method, n).unwrap();
    let mut compiled = tr.compile().unwrap();
    let sol = Ipm::default().solve(&mut compiled).unwrap();
    assert!(sol.status.is_success(), "{:?}", sol.status);
    tr.trajectory(&sol).unwrap()
}

#[test]
fn transcriptions_converge_to_the_riccati_optimum() {
    let exact = riccati_value();
    for method in [
        Method::multiple_shooting(ButcherTableau::rk4(), 2),
        Method::collocation(CollocationPoints::Radau, 3).unwrap(),
        Method::collocation(CollocationPoints::Legendre, 2).unwrap(),
    ] {
        let e: Vec<f64> = [10, 20, 40]
            .iter()
            .map(|&n| (solve(&lqr(), &method, n).objective - exact).abs())
            .collect();
        // Piecewise-constant controls limit every method to O(h²) in the cost: doubling N
        // divides the error by ~4 (between 3 and 5 allows for higher-order terms).
        for w in e.windows(2) {
            let ratio = w[0] / w[1];
            assert!((3.0..5.0).contains(&ratio), "{method:?}: errors {e:?}");
        }
        assert!(e[2] < 1e-4, "{e:?}");
    }
}

#[test]
fn euler_shooting_rows_are_the_hand_written_ones() {
    // ẋ = (x₁, u − x₀·x₁), Euler with 1 step: X_{k+1} − (X_k + h f(X_k, U_k)) = 0.
    let mut ocp = Ocp::new(&["a", "b"], &["u"]);
    ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![x[1], u[0] - x[0] * x[1]]));
    ocp.set_horizon(Horizon::Fixed(2.0)).unwrap();
    let n = 4;
    let tr = ocp
        .transcribe(&Method::multiple_shooting(ButcherTableau::euler(), 1), n)
        .unwrap();
    let mut compiled = tr.compile().unwrap();
    let (nv, m) = (compiled.n(), compiled.m());
    assert_eq!((nv, m), (2 * (n + 1) + n, 2 * n));
    let w: Vec<f64> = (0..nv)
        .map(|i| ((i * 7 + 3) % 11) as f64 / 5.0 - 1.0)
        .collect();
    let mut g = vec![0.0; m];
    compiled.eval_g(&w, &mut g);
    let h = 2.0 / n as f64;
    let (x, u) = (
        |i: usize, k: usize| w[2 * k + i],
        |k: usize| w[2 * (n + 1) + k],
    );
    for k in 0..n {
        let expected = [
            x(0, k + 1) - (x(0, k) + h * x(1, k)),
            x(1, k + 1) - (x(1, k) + h * (u(k) - x(0, k) * x(1, k))),
        ];
        for i in 0..2 {
            assert!((g[2 * k + i] - expected[i]).abs() < 1e-14, "row {k},{i}");
        }
    }
}

#[test]
fn parameters_change_the_solution_without_recompiling() {
    let mut ocp = lqr();
    ocp.add_parameter("weight", &[1.0]).unwrap();
    ocp.set_stage_cost(|x, u, p| p[0] * x[0].sq() + u[0].sq());
    let method = Method::collocation(CollocationPoints::Radau, 2).unwrap();
    let tr = ocp.transcribe(&method, 10).unwrap();
    let mut compiled = tr.compile().unwrap();
    let a = Ipm::default().solve(&mut compiled).unwrap();
    compiled.set_value("weight", &[4.0]).unwrap();
    let b = Ipm::default().solve(&mut compiled).unwrap();
    let (ta, tb) = (tr.trajectory(&a).unwrap(), tr.trajectory(&b).unwrap());
    // A heavier state weight drives x to zero faster.
    assert!(tb.state("x").unwrap()[10] < ta.state("x").unwrap()[10]);
    assert!(tb.objective > ta.objective);
}

#[test]
fn guesses_reach_the_initial_point() {
    let mut ocp = lqr();
    ocp.set_state_guess_linear(&[1.0], &[0.0]).unwrap();
    ocp.set_control_guess(|t| vec![-t]);
    let method = Method::collocation(CollocationPoints::Legendre, 2).unwrap();
    let tr = ocp.transcribe(&method, 4).unwrap();
    let compiled = tr.compile().unwrap();
    let mut x0 = vec![0.0; compiled.n()];
    compiled.initial_point(&mut x0);
    let xs = compiled.variable_values("X", &x0).unwrap();
    assert_eq!(xs, &[1.0, 0.75, 0.5, 0.25, 0.0]);
    assert_eq!(
        compiled.variable_values("U", &x0).unwrap(),
        &[0.0, -0.25, -0.5, -0.75]
    );
    let xc = compiled.variable_values("Xc", &x0).unwrap();
    let tau = 0.5 - (1.0f64 / 12.0).sqrt(); // first Legendre point of degree 2
    assert!((xc[0] - (1.0 - tau / 4.0)).abs() < 1e-15);

    // A linear guess follows a horizon set afterwards.
    let mut late = lqr();
    late.set_state_guess_linear(&[1.0], &[0.0]).unwrap();
    late.set_horizon(Horizon::Fixed(3.0)).unwrap();
    let tr = late
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), 4)
        .unwrap();
    let compiled = tr.compile().unwrap();
    let mut x0 = vec![0.0; compiled.n()];
    compiled.initial_point(&mut x0);
    assert_eq!(
        compiled.variable_values("X", &x0).unwrap(),
        &[1.0, 0.75, 0.5, 0.25, 0.0]
    );

    // A coarse solution as the guess of a finer grid.
    let coarse = solve(
        &lqr(),
        &Method::multiple_shooting(ButcherTableau::rk4(), 1),
        5,
    );
    let mut fine = lqr();
    fine.set_guess_from(&coarse);
    let tr = fine
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), 10)
        .unwrap();
    let compiled = tr.compile().unwrap();
    let mut x0 = vec![0.0; compiled.n()];
    compiled.initial_point(&mut x0);
    let xs = compiled.variable_values("X", &x0).unwrap();
    let s = coarse.state("x").unwrap();
    assert_eq!((xs[2], xs[10]), (s[1], s[5]));
    assert!((xs[1] - (s[0] + s[1]) / 2.0).abs() < 1e-15);
}

#[test]
fn trajectory_helpers_and_determinism() {
    let method = Method::multiple_shooting(ButcherTableau::midpoint(), 3);
    let a = solve(&lqr(), &method, 8);
    let b = solve(&lqr(), &method, 8);
    assert_eq!(a, b, "same input, bit-identical trajectory");
    assert_eq!(a.time, (0..=8).map(|k| k as f64 / 8.0).collect::<Vec<_>>());
    let x = a.state("x").unwrap();
    let mid = a.states_at(1.5 / 8.0)[0];
    assert!((mid - (x[1] + x[2]) / 2.0).abs() < 1e-15);
    assert_eq!(a.controls_at(1.0), vec![a.controls[0][7]]);
    assert_eq!(a.controls_at(0.13), vec![a.controls[0][1]]);
    let csv = a.to_csv();
    assert!(csv.starts_with("t,x,u\n0,1,"));
    assert_eq!(csv.lines().count(), 10);
    assert!(a.control("u").is_some() && a.state("nope").is_none());
}

#[test]
fn path_and_boundary_constraints_hold() {
    let mut ocp = lqr();
    ocp.add_path_constraint("floor", |x, _u, _p| x[0].ge(0.5));
    ocp.add_boundary_constraint("end", |_x0, xt, _p, _t| xt[0].eq(0.6));
    let t = solve(
        &ocp,
        &Method::collocation(CollocationPoints::Radau, 3).unwrap(),
        10,
    );
    let x = t.state("x").unwrap();
    assert!(x.iter().all(|&v| v >= 0.5 - 1e-8));
    assert!((x[10] - 0.6).abs() < 1e-8);
}

#[test]
fn mistakes_are_reported() {
    let m = Method::multiple_shooting(ButcherTableau::rk4(), 1);
    let bare = Ocp::new(&["x"], &["u"]);
    assert!(matches!(bare.transcribe(&m, 5), Err(OcpError::NoDynamics)));

    let mut wrong = Ocp::new(&["x", "y"], &["u"]);
    wrong.set_dynamics(|x, _u, _p| Matrix::from_vec(vec![x[0]]));
    // No final time: an error naming set_horizon, not a silent T = 1.
    let err = wrong.transcribe(&m, 5).err().unwrap();
    assert_eq!(err, OcpError::NoHorizon);
    assert!(err.to_string().contains("set_horizon"), "{err}");
    wrong.set_horizon(Horizon::Fixed(1.0)).unwrap();
    assert!(matches!(
        wrong.transcribe(&m, 5),
        Err(OcpError::Size {
            expected: 2,
            got: 1,
            ..
        })
    ));

    let mut ocp = lqr();
    assert!(matches!(
        ocp.transcribe(&m, 0),
        Err(OcpError::Invalid { .. })
    ));
    let zero_steps = Method::multiple_shooting(ButcherTableau::rk4(), 0);
    assert!(matches!(
        ocp.transcribe(&zero_steps, 4),
        Err(OcpError::Invalid { .. })
    ));
    assert!(matches!(
        ocp.set_state_bounds(&[0.0, 1.0], &[1.0]),
        Err(OcpError::Size { .. })
    ));
    assert!(matches!(
        ocp.set_control_bounds(&[2.0], &[1.0]),
        Err(OcpError::Invalid { .. })
    ));
    assert!(matches!(
        ocp.set_horizon(Horizon::Fixed(-1.0)),
        Err(OcpError::Invalid { .. })
    ));
    let bad_free = Horizon::Free {
        lower: 2.0,
        upper: 3.0,
        guess: 1.0,
    };
    assert!(matches!(
        ocp.set_horizon(bad_free),
        Err(OcpError::Invalid { .. })
    ));
    assert!(matches!(
        ocp.set_initial_state(&[f64::NAN]),
        Err(OcpError::Invalid { .. })
    ));
    assert!(matches!(ocp.add_parameter("X", &[1.0]), Ok(())));
    assert!(matches!(
        ocp.transcribe(&m, 4),
        Err(OcpError::Invalid { .. })
    ));

    let mut outside = lqr();
    outside.set_state_bounds(&[2.0], &[3.0]).unwrap(); // x(0) = 1 is outside
                                                       // The fixed initial state is a single-variable row; it meets the bounds (and is
                                                       // found disjoint from them) when simple bounds are detected, at compile time.
    let outside = outside.transcribe(&m, 4).unwrap();
    assert!(matches!(
        outside.compile(),
        Err(OcpError::Build(BuildError::InvertedBounds { .. }))
    ));
    let mut guess = lqr();
    guess.set_state_guess(|_t| vec![0.0, 0.0]);
    assert!(matches!(
        guess.transcribe(&m, 4),
        Err(OcpError::Size { .. })
    ));
    let mut dup = lqr();
    dup.add_parameter("a", &[1.0]).unwrap();
    assert!(matches!(
        dup.add_parameter("a", &[1.0]),
        Err(OcpError::Build(BuildError::DuplicateName { .. }))
    ));

    let tr = lqr().transcribe(&m, 4).unwrap();
    let mut compiled = tr.compile().unwrap();
    let mut sol = Ipm::default().solve(&mut compiled).unwrap();
    sol.x.pop();
    assert!(matches!(tr.trajectory(&sol), Err(OcpError::Size { .. })));
}

#[test]
fn free_final_time_without_controls() {
    // ẋ = −x, x(0) = 1, min (x(T) − 1/2)²: T* = ln 2 up to the RK4 error of the grid.
    let mut ocp = Ocp::new(&["x"], &[]);
    ocp.set_dynamics(|x, _u, _p| Matrix::from_vec(vec![-x[0]]));
    ocp.set_terminal_cost(|x, _p, _t| (x[0] - 0.5).sq());
    ocp.set_horizon(Horizon::Free {
        lower: 0.1,
        upper: 5.0,
        guess: 1.0,
    })
    .unwrap();
    ocp.set_initial_state(&[1.0]).unwrap();
    ocp.set_state_guess(|t| vec![(-t).exp()]);
    let t = solve(
        &ocp,
        &Method::multiple_shooting(ButcherTableau::rk4(), 1),
        10,
    );
    // RK4 with h ≈ 0.07: relative error of e^{−h} per step ~h⁵/120 ≈ 1.4e-8, times 10.
    assert!(
        (t.final_time - 2f64.ln()).abs() < 1e-6,
        "T = {}",
        t.final_time
    );
    assert!(t.controls.is_empty() && t.control_names.is_empty());
}
