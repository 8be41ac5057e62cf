//! Trapezoidal and Hermite–Simpson transcriptions, controls at the nodes and user-given
//! grids (nlp::ocp), on the COPS Goddard rocket, Bryson–Denham and the brachistochrone.
//!
//! IPOPT's optima come from `benches/reference/ocp_transcriptions_casadi.py`, which writes
//! the identical NLPs with CasADi Opti (casadi 3.8.2, IPOPT 3.14.19, tol 1e-10). symnlp's
//! interior point solves them with the same tol 1e-10; both find the same local optimum of
//! the same NLP, so the objectives agree to the convergence tolerance: the tests allow 1e-9
//! relative (observed: 1e-13 or better; at the default tol 1e-8 the Goddard objective,
//! flat along its singular arc, is only 3e-7 from the optimum).
use nlp::ocp::{ControlInterpolation, Grid, Horizon, Method, Ocp, Trajectory};
use nlp::{CommonOptions, Ipm, IpmOptions, Relation};
use std::f64::consts::PI;
use symx::Matrix;

const INF: f64 = f64::INFINITY;

fn solve(ocp: &Ocp, method: &Method, grid: &Grid) -> Trajectory {
    let tr = ocp.transcribe_on(method, grid).unwrap();
    let common = CommonOptions {
        tol: 1e-10,
        ..CommonOptions::default()
    };
    let ipm = Ipm::new(IpmOptions {
        common,
        ..IpmOptions::default()
    });
    let sol = ipm.solve(&mut tr.compile().unwrap()).unwrap();
    assert!(sol.status.is_success(), "{:?}", sol.status);
    tr.trajectory(&sol).unwrap()
}

fn close(got: f64, want: f64, rel: f64) {
    assert!(
        (got - want).abs() <= rel * want.abs(),
        "{got} vs {want} (rel {:.2e})",
        (got - want).abs() / want.abs()
    );
}

/// COPS 3.0 problem 10 (Dolan, Moré, Munson, ANL/MCS-TM-246, 2004): maximise the final
/// height, thrust at the nodes, free final time, COPS's constants and initial guess.
fn goddard() -> Ocp {
    let (h0, m0, g0, hc, vc) = (1.0f64, 1.0, 1.0, 500.0, 620.0);
    let c = 0.5 * (g0 * h0).sqrt();
    let (mf, dc, tmax) = (0.6 * m0, 0.5 * vc * m0 / g0, 3.5 * g0 * m0);
    let mut ocp = Ocp::new(&["h", "v", "m"], &["T"]);
    ocp.set_dynamics(move |x, u, _p| {
        let drag = dc * x[1].sq() * (-hc * (x[0] - h0) / h0).exp();
        let gravity = g0 * (h0 / x[0]).sq();
        Matrix::from_vec(vec![x[1], (u[0] - drag) / x[2] - gravity, -u[0] / c])
    });
    ocp.set_terminal_cost(|x, _p, _t| -x[0]);
    ocp.set_horizon(Horizon::free(0.0, INF, 1.0)).unwrap();
    ocp.set_initial_state(&[h0, 0.0, m0]).unwrap();
    ocp.add_boundary_constraint("final mass", move |_x0, xt, _p, _t| xt[2].eq(mf));
    ocp.set_state_bounds(&[h0, 0.0, mf], &[INF, INF, m0])
        .unwrap();
    ocp.set_control_bounds(&[0.0], &[tmax]).unwrap();
    ocp.set_control_interpolation(ControlInterpolation::PiecewiseLinear);
    ocp.set_state_guess(move |t| vec![1.0, t * (1.0 - t), (mf - m0) * t + m0]);
    ocp.set_control_guess(move |_t| vec![tmax / 2.0]);
    ocp
}

/// Bryson–Denham (Bryson & Ho 1975, §3.11): min ½∫₀¹u², ẍ = u, x ≤ 1/9; J* = 4/(9·(1/9)) = 4.
fn bryson_denham() -> Ocp {
    let mut ocp = Ocp::new(&["x", "v"], &["u"]);
    ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![x[1], u[0]]));
    ocp.set_stage_cost(|_x, u, _p| 0.5 * u[0].sq());
    ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
    ocp.set_initial_state(&[0.0, 1.0]).unwrap();
    ocp.set_final_state(&[0.0, -1.0]).unwrap();
    ocp.set_state_bounds(&[-INF, -INF], &[1.0 / 9.0, INF])
        .unwrap();
    ocp.set_control_interpolation(ControlInterpolation::PiecewiseLinear);
    ocp
}

/// The brachistochrone to (2, 2), y downwards, g = 9.81: minimum time.
fn brachistochrone() -> Ocp {
    let g = 9.81;
    let mut ocp = Ocp::new(&["x", "y", "v"], &["theta"]);
    ocp.set_dynamics(move |x, u, _p| {
        let (s, c) = (u[0].sin(), u[0].cos());
        Matrix::from_vec(vec![x[2] * s, x[2] * c, g * c])
    });
    ocp.set_terminal_cost(|_x, _p, t| t);
    ocp.set_horizon(Horizon::free(0.1, 10.0, 1.0)).unwrap();
    ocp.set_initial_state(&[0.0; 3]).unwrap();
    ocp.add_boundary_constraint("end", |_x0, xt, _p, _t| {
        Matrix::from_vec(vec![xt[0], xt[1]]).eq(2.0)
    });
    ocp.set_control_bounds(&[0.0], &[PI]).unwrap();
    let end = [2.0, 2.0, (2.0 * g * 2.0f64).sqrt()];
    ocp.set_state_guess_linear(&[0.0; 3], &end).unwrap();
    ocp.set_control_guess(|_t| vec![PI / 4.0]);
    ocp.set_control_interpolation(ControlInterpolation::PiecewiseLinear);
    ocp
}

#[test]
fn goddard_rocket_trapezoidal_as_cops_writes_it() {
    let t = solve(
        &goddard(),
        &Method::trapezoidal(),
        &Grid::uniform(100).unwrap(),
    );
    // ocp_transcriptions_casadi.py: h(T) = 1.012832023909441, T = 0.1987691459257406
    // (COPS 3.0 reports 1.01283).
    close(-t.objective, 1.012832023909441, 1e-9);
    close(t.final_time, 0.1987691459257406, 1e-8); // observed 9e-11: the optimum is flat in T
    assert_eq!(t.controls[0].len(), 101, "thrust at the 101 nodes");
    close(t.state("h").unwrap()[100], 1.012832023909441, 1e-9);
}

#[test]
fn bryson_denham_by_each_method() {
    let grid = Grid::uniform(30).unwrap();
    // ocp_transcriptions_casadi.py, N = 30 (kinks of u* at t = 1/3, 2/3 on nodes).
    for (method, ipopt) in [
        (Method::trapezoidal(), 4.038475872103792),
        (Method::hermite_simpson(), 3.999999640224972),
        (Method::hermite_simpson_separated(), 3.9999996404934524),
    ] {
        let t = solve(&bryson_denham(), &method, &grid);
        close(t.objective, ipopt, 1e-9);
    }
    // Hermite–Simpson to the closed form J* = 4: the discrete optimum lies 9e-8 (relative)
    // below it, the bound x ≤ 1/9 holding at nodes and midpoints only.
    let t = solve(&bryson_denham(), &Method::hermite_simpson(), &grid);
    close(t.objective, 4.0, 2e-7);
}

#[test]
fn user_given_grid() {
    // 10 uniform intervals on [0, 0.25], 20 on [0.25, 1] (the script's `fr`).
    let mut s: Vec<f64> = (0..10).map(|k| 0.25 * k as f64 / 10.0).collect();
    s.extend((0..=20).map(|k| 0.25 + 0.75 * k as f64 / 20.0));
    let grid = Grid::new(&s).unwrap();
    let t = solve(&bryson_denham(), &Method::hermite_simpson(), &grid);
    close(t.objective, 3.9997756677774317, 1e-9);
    assert_eq!(t.time[10], 0.25);
    assert!((t.time[11] - 0.2875).abs() < 1e-15);
    // Shifting by one stage (MPC) needs equal stages: refused on this grid.
    let tr = bryson_denham()
        .transcribe_on(&Method::hermite_simpson(), &grid)
        .unwrap();
    let err = tr.shift_plan().unwrap_err().to_string();
    assert!(err.contains("uniform grid"), "{err}");
}

#[test]
fn brachistochrone_by_each_method() {
    // ocp_transcriptions_casadi.py; the cycloid's time is 0.8243386694391838.
    // To the cycloid: trapezoidal at N = 40 is 3.7e-5 off (second order), Hermite–Simpson
    // at N = 20 9e-9 (fourth order); the tolerances allow twice or ten times that.
    let cases = [
        (Method::trapezoidal(), 40, 0.8243687345937564, 1e-4),
        (Method::hermite_simpson(), 20, 0.8243386770105343, 1e-7),
        (
            Method::hermite_simpson_separated(),
            20,
            0.8243386770105342,
            1e-7,
        ),
    ];
    for (method, n, ipopt, to_cycloid) in cases {
        let t = solve(&brachistochrone(), &method, &Grid::uniform(n).unwrap());
        close(t.final_time, ipopt, 1e-9);
        close(t.objective, 0.8243386694391838, to_cycloid);
    }
}

/// min ½∫₀¹ x² + u², ẋ = u, x(0) = 1: the Riccati solution P(t) = tanh(1 − t) gives the
/// closed form J* = ½ tanh 1, with a smooth, non-polynomial optimal trajectory.
fn scalar_lq() -> Ocp {
    let mut ocp = Ocp::new(&["x"], &["u"]);
    ocp.set_dynamics(|_x, u, _p| Matrix::from_vec(vec![u[0]]));
    ocp.set_stage_cost(|x, u, _p| 0.5 * (x[0].sq() + u[0].sq()));
    ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
    ocp.set_initial_state(&[1.0]).unwrap();
    ocp.set_control_interpolation(ControlInterpolation::PiecewiseLinear);
    ocp
}

/// Observed orders log2(e(N)/e(2N)) of the cost error for N = 4, 8, 16, 32.
fn orders(method: &Method) -> Vec<f64> {
    let exact = 0.5 * 1f64.tanh();
    let errors: Vec<f64> = [4, 8, 16, 32]
        .iter()
        .map(|&n| (solve(&scalar_lq(), method, &Grid::uniform(n).unwrap()).objective - exact).abs())
        .collect();
    errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect()
}

#[test]
fn error_orders_against_a_closed_form() {
    // Trapezoidal: second order. Hermite–Simpson: fourth order (Betts 2010, §4.5).
    // The observed orders settle within 0.2 of the theory once h ≤ 1/8.
    let trapezoidal = orders(&Method::trapezoidal());
    let hs = orders(&Method::hermite_simpson());
    for p in &trapezoidal[1..] {
        assert!((p - 2.0).abs() < 0.2, "trapezoidal orders {trapezoidal:?}");
    }
    for p in &hs[1..] {
        assert!((p - 4.0).abs() < 0.2, "Hermite–Simpson orders {hs:?}");
    }
}

#[test]
fn node_controls_with_multiple_shooting_and_collocation() {
    // A linear control integrated exactly inside RK4 steps (a clock state), and at the
    // collocation points: both converge to J* = ½ tanh 1.
    let exact = 0.5 * 1f64.tanh();
    let grid = Grid::uniform(20).unwrap();
    let rk4 = Method::multiple_shooting(nlp::ocp::ButcherTableau::rk4(), 2);
    let calls = Method::multiple_shooting_with_calls(nlp::ocp::ButcherTableau::rk4(), 2);
    let radau = Method::collocation(nlp::ocp::CollocationPoints::Radau, 3).unwrap();
    let a = solve(&scalar_lq(), &rk4, &grid);
    let b = solve(&scalar_lq(), &calls, &grid);
    let c = solve(&scalar_lq(), &radau, &grid);
    // Observed 5.7e-9 (RK4) and 2e-9 (Radau) relative to the closed form at N = 20.
    for t in [&a, &b, &c] {
        close(t.objective, exact, 2e-8);
        assert_eq!(t.controls[0].len(), 21);
    }
    close(a.objective, b.objective, 1e-12); // the same NLP, inlined or called
                                            // The trajectory interpolates node controls linearly.
    let u = &a.controls[0];
    let mid = a.controls_at(0.025)[0];
    assert!((mid - 0.5 * (u[0] + u[1])).abs() < 1e-14);
}

#[test]
fn bad_grids_and_a_missing_horizon_are_errors() {
    for bad in [
        &[0.0, 1.0, 1.0][..],
        &[0.1, 1.0],
        &[0.0, 0.5],
        &[0.0],
        &[0.0, f64::NAN, 1.0],
    ] {
        let err = Grid::new(bad).unwrap_err();
        assert!(err.to_string().starts_with("grid:"), "{err}");
    }
    let mut ocp = Ocp::new(&["x"], &["u"]);
    ocp.set_dynamics(|_x, u, _p| Matrix::from_vec(vec![u[0]]));
    let err = ocp.transcribe(&Method::trapezoidal(), 4).err().unwrap();
    assert_eq!(err, nlp::ocp::OcpError::NoHorizon);
}
