//! Multi-phase optimal control (nlp::ocp::MultiPhaseOcp): phases with their own dynamics,
//! horizon, grid and transcription joined by linkage constraints, as one Problem.
//!
//! References:
//! * the brachistochrone split at x = 1 into two free-duration phases joined by state
//!   continuity: IPOPT's optimum of the identical NLP from
//!   `benches/reference/ocp_multi_phase_casadi.py` (casadi 3.8.2, IPOPT, tol 1e-10; the
//!   interior point here at tol 1e-10 too, so the optima agree to about that: 1e-9
//!   relative allowed), and the cycloid's closed form (the discretisation error of
//!   Hermite–Simpson on 10 + 10 intervals is 6e-8 relative in the script: 2e-7 allowed);
//! * a double integrator bouncing off a wall (an impact map as the linkage), whose optimum
//!   has a closed form (derived in `impact_map_linkage_against_the_closed_form`) that RK4
//!   and Hermite–Simpson reproduce exactly with controls at the nodes (the optimal states
//!   are cubics in time).
use nlp::ocp::{
    ButcherTableau, ControlInterpolation, Grid, Horizon, Method, MultiPhaseOcp,
    MultiPhaseTranscription, Ocp,
};
use nlp::{CommonOptions, Ipm, IpmOptions, Relation, Solution};
use std::f64::consts::PI;
use symx::Matrix;

const G: f64 = 9.81;

fn solve(tr: &MultiPhaseTranscription) -> Solution {
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
    sol
}

fn close(got: f64, want: f64, rel: f64) {
    assert!(
        (got - want).abs() <= rel * want.abs(),
        "{got} vs {want} (rel {:.2e})",
        (got - want).abs() / want.abs()
    );
}

/// One brachistochrone phase from `from` to `to` (the guess), minimum time.
fn brachistochrone_phase(from: [f64; 3], to: [f64; 3]) -> Ocp {
    let mut ocp = Ocp::new(&["x", "y", "v"], &["theta"]);
    ocp.set_dynamics(|x, u, _p| {
        let (s, c) = (u[0].sin(), u[0].cos());
        Matrix::from_vec(vec![x[2] * s, x[2] * c, G * c])
    });
    ocp.set_terminal_cost(|_x, _p, t| t);
    ocp.set_horizon(Horizon::free(0.05, 10.0, 0.5)).unwrap();
    ocp.set_control_bounds(&[0.0], &[PI]).unwrap();
    ocp.set_control_interpolation(ControlInterpolation::PiecewiseLinear);
    ocp.set_state_guess_linear(&from, &to).unwrap();
    ocp.set_control_guess(|_t| vec![PI / 4.0]);
    ocp
}

fn two_phase_brachistochrone() -> MultiPhaseOcp {
    let (vmid, vend) = ((2.0 * G).sqrt(), (4.0 * G).sqrt());
    let mut a = brachistochrone_phase([0.0; 3], [1.0, 1.0, vmid]);
    a.set_initial_state(&[0.0; 3]).unwrap();
    a.add_boundary_constraint("switch", |_x0, xt, _p, _t| xt[0].eq(1.0));
    let mut b = brachistochrone_phase([1.0, 1.0, vmid], [2.0, 2.0, vend]);
    b.add_boundary_constraint("end", |_x0, xt, _p, _t| {
        Matrix::from_vec(vec![xt[0], xt[1]]).eq(2.0)
    });
    let mut mp = MultiPhaseOcp::new();
    let grid = Grid::uniform(10).unwrap();
    let hs = Method::hermite_simpson();
    let a = mp.add_phase("a", a, hs.clone(), grid.clone()).unwrap();
    let b = mp.add_phase("b", b, hs, grid).unwrap();
    mp.link_states(a, b).unwrap();
    mp
}

#[test]
fn brachistochrone_split_at_a_switching_point() {
    let tr = two_phase_brachistochrone().transcribe().unwrap();
    let sol = solve(&tr);
    // ocp_multi_phase_casadi.py: T = Ta + Tb = 0.8243387207941983, Ta = 0.6279567857152533,
    // y(Ta) = 1.447710426368205.
    close(sol.objective, 0.8243387207941983, 1e-9);
    let trajs = tr.trajectories(&sol).unwrap();
    assert_eq!(trajs.len(), 2);
    close(trajs[0].final_time, 0.6279567857152533, 1e-8);
    close(trajs[0].state("y").unwrap()[10], 1.447710426368205, 1e-8);
    // Absolute time: phase b starts where a ends and ends at Ta + Tb.
    assert_eq!(trajs[1].time[0], trajs[0].final_time);
    close(trajs[1].final_time, 0.8243387207941983, 1e-9);
    // Continuity of all three states at the switch (the linkage rows).
    for i in 0..3 {
        assert!((trajs[0].states[i][10] - trajs[1].states[i][0]).abs() < 1e-9);
    }
    // The joint optimum is the one-phase cycloid's (closed form in the script).
    close(sol.objective, 0.8243386694391838, 2e-7);
    close(trajs[0].final_time, 0.6279566900712206, 2e-7);
    // Duration and start-time expressions evaluate to the same.
    let b = tr.phase_id("b").unwrap();
    let start = tr.start_time(b).unwrap();
    close(
        tr.problem().value(start, &sol).unwrap(),
        trajs[0].final_time,
        1e-15,
    );
    assert!(tr
        .problem()
        .variable_indices(&[tr.duration(b).unwrap()])
        .is_ok());
}

/// ẍ = u, min ½∫u² over two phases of fixed durations: from (0, 0) to the wall x = 1 in
/// `ta`, an impact reverses and scales the velocity by −e, then back to (0, 0) in `tb`.
fn bouncing(ta: f64, tb: f64, e: f64, a: Method, b: Method) -> MultiPhaseOcp {
    let phase = |t: f64| {
        let mut ocp = Ocp::new(&["x", "v"], &["u"]);
        ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![x[1], u[0]]));
        ocp.set_stage_cost(|_x, u, _p| 0.5 * u[0].sq());
        ocp.set_horizon(Horizon::Fixed(t)).unwrap();
        ocp.set_control_interpolation(ControlInterpolation::PiecewiseLinear);
        ocp
    };
    let mut approach = phase(ta);
    approach.set_initial_state(&[0.0, 0.0]).unwrap();
    approach.add_boundary_constraint("wall", |_x0, xt, _p, _t| xt[0].eq(1.0));
    let mut back = phase(tb);
    back.set_final_state(&[0.0, 0.0]).unwrap();
    let mut mp = MultiPhaseOcp::new();
    let pa = mp
        .add_phase("approach", approach, a, Grid::uniform(5).unwrap())
        .unwrap();
    let pb = mp
        .add_phase("back", back, b, Grid::uniform(4).unwrap())
        .unwrap();
    mp.add_linkage("impact", pa, pb, move |end, start, _p| {
        Matrix::from_vec(vec![start[0] - end[0], start[1] + e * end[1]]).eq(0.0)
    })
    .unwrap();
    mp
}

#[test]
fn impact_map_linkage_against_the_closed_form() {
    // Closed form. On one phase of length T from (x0, v0) to (x1, v1), min ∫u² =
    // 12 (Δx − (v0 + v1) T/2)² / T³ + (v1 − v0)² / T (u linear in t). With T = 1, the
    // impact velocity w and e = 1/2: J(w) = ½ [12 (1 − w/2)² + w² + 12 (1 − w/4)² + w²/4],
    // J'(w) = 5w − 9 = 0 ⇒ w = 1.8, J* = 3.9.
    let rk4 = Method::multiple_shooting(ButcherTableau::rk4(), 1);
    for (a, b) in [
        (rk4.clone(), Method::hermite_simpson()),
        (Method::hermite_simpson_separated(), rk4),
    ] {
        let tr = bouncing(1.0, 1.0, 0.5, a, b).transcribe().unwrap();
        let sol = solve(&tr);
        // The optimal states are cubics and u linear: both methods are exact, the
        // difference is the solver's tolerance.
        close(sol.objective, 3.9, 1e-8);
        let trajs = tr.trajectories(&sol).unwrap();
        close(trajs[0].state("v").unwrap()[5], 1.8, 1e-7);
        close(trajs[1].state("v").unwrap()[0], -0.9, 1e-7);
        assert_eq!(trajs[1].time, vec![1.0, 1.25, 1.5, 1.75, 2.0]);
    }
}

#[test]
fn phases_are_named_in_the_problem() {
    let tr = bouncing(1.0, 1.0, 0.5, Method::trapezoidal(), Method::trapezoidal())
        .transcribe()
        .unwrap();
    let c = tr.compile().unwrap();
    let names: Vec<&str> = c
        .constraint_blocks()
        .iter()
        .map(|b| b.name.as_str())
        .collect();
    for want in ["approach.continuity", "back.continuity", "impact"] {
        assert!(names.contains(&want), "{want} not in {names:?}");
    }
    assert_eq!(tr.n_phases(), 2);
    assert_eq!(tr.states(tr.phase_id("back").unwrap()).unwrap().ncols(), 5);
    assert!(tr.phase_id("flight").is_none());
}

#[test]
fn shared_parameters_and_their_conflicts() {
    // The wall's position as a parameter of both phases: one problem parameter.
    let build = |w2: f64| {
        let mut mp = bouncing(1.0, 1.0, 0.5, Method::trapezoidal(), Method::trapezoidal());
        let mut a = Ocp::new(&["x"], &["u"]);
        a.set_dynamics(|_x, u, _p| Matrix::from_vec(vec![u[0]]));
        a.set_horizon(Horizon::Fixed(1.0)).unwrap();
        a.add_parameter("wall", &[1.0]).unwrap();
        a.add_boundary_constraint("at wall", |_x0, xt, p, _t| xt[0].eq(p[0]));
        let mut b = Ocp::new(&["x"], &["u"]);
        b.set_dynamics(|_x, u, _p| Matrix::from_vec(vec![u[0]]));
        b.set_horizon(Horizon::Fixed(1.0)).unwrap();
        b.add_parameter("wall", &[w2]).unwrap();
        let grid = Grid::uniform(2).unwrap();
        mp.add_phase("c", a, Method::trapezoidal(), grid.clone())
            .unwrap();
        mp.add_phase("d", b, Method::trapezoidal(), grid).unwrap();
        mp
    };
    let tr = build(1.0).transcribe().unwrap();
    assert_eq!(tr.problem().parameters().len(), 1);
    let err = build(2.0).transcribe().err().unwrap().to_string();
    assert!(
        err.contains("parameter 'wall' of phase 'd'") && err.contains("phase 'c'"),
        "{err}"
    );
}

#[test]
fn mistakes_are_named_errors() {
    let ocp = || {
        let mut ocp = Ocp::new(&["x"], &["u"]);
        ocp.set_dynamics(|_x, u, _p| Matrix::from_vec(vec![u[0]]));
        ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
        ocp
    };
    let grid = Grid::uniform(2).unwrap();
    let tz = Method::trapezoidal();
    let err = |e: nlp::ocp::OcpError| e.to_string();
    let mut mp = MultiPhaseOcp::new();
    assert!(err(mp.transcribe().err().unwrap()).contains("no phase"));
    let a = mp.add_phase("a", ocp(), tz.clone(), grid.clone()).unwrap();
    let e = mp
        .add_phase("a", ocp(), tz.clone(), grid.clone())
        .unwrap_err();
    assert!(err(e).contains("already used"));
    let e = mp
        .add_phase("a.b", ocp(), tz.clone(), grid.clone())
        .unwrap_err();
    assert!(err(e).contains("no '.'"));
    let mut two = Ocp::new(&["x", "v"], &["u"]);
    two.set_dynamics(|x, u, _p| Matrix::from_vec(vec![x[1], u[0]]));
    two.set_horizon(Horizon::Fixed(1.0)).unwrap();
    let b = mp.add_phase("b", two, tz.clone(), grid.clone()).unwrap();
    let e = mp.link_states(a, b).unwrap_err();
    assert!(err(e).contains("states of phase 'b' linked to phase 'a'"));
    let e = mp.link_states(a, a).unwrap_err();
    assert!(err(e).contains("itself"));
    let e = mp.link_states(a, nlp::ocp::PhaseId(7)).unwrap_err();
    assert!(err(e).contains("phase 7"));
    // A phase without a horizon: the phase's own error.
    let mut c = Ocp::new(&["x"], &["u"]);
    c.set_dynamics(|_x, u, _p| Matrix::from_vec(vec![u[0]]));
    mp.add_phase("c", c, tz, grid).unwrap();
    assert!(err(mp.transcribe().err().unwrap()).contains("no final time"));
}
