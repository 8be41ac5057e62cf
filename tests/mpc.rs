//! MPC: the shift of a solution (indices checked against the compiled constraint blocks,
//! multipliers moved with their rows), the initial state as a parameter, the plant, and
//! the closed loops against CasADi 3.8.2 + IPOPT 3.14 on the identical transcription
//! (`python3 benches/reference/mpc_casadi.py cart_pole,car,quadrotor ipopt`, run 2026-11-27 on this
//! machine; output recorded in `benches/reference/results/mpc_casadi.jsonl`).
use symnlp_examples::{mpc_car, mpc_cart_pole, mpc_quadrotor};

use symnlp::nlp::mpc::{Mpc, MpcError};
use symnlp::nlp::ocp::{
    ButcherTableau, CollocationPoints, Horizon, Method, Ocp, OcpError, Simulator, Transcription,
};
use symnlp::nlp::{Compiled, Constraint, Ipm, Relation, Rti, Solution, SqpOptions, Status};
use symnlp::symx::{Evaluator, Matrix};
use testkit::rti_loop::{assert_every_feedback_corrected, rti_feedbacks};

const N: usize = 5;

/// ẋ₁ = x₂, ẋ₂ = u − x₁ with a path constraint of two rows per stage: `x₁ u ≤ 1` (a row
/// of g) and `u ≤ 5` (one variable: a simple bound, no row).
fn ocp() -> Ocp {
    let mut ocp = Ocp::new(&["x1", "x2"], &["u"]);
    ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![x[1], u[0] - x[0]]));
    ocp.set_stage_cost(|x, u, _p| x[0].sq() + x[1].sq() + u[0].sq());
    ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
    ocp.add_path_constraint("path", |x, u, _p| {
        Constraint::all([(x[0] * u[0]).le(1.0), u[0].le(5.0)])
    });
    ocp.set_initial_state_parameter("x0", &[1.0, 0.0]).unwrap();
    ocp
}

/// A solution whose every entry tells where it came from: x[j] = j, z_L = 1000 + j,
/// z_U = 2000 + j, λ[r] = 3000 + r, g[r] = 4000 + r.
fn labelled(c: &Compiled, tr: &Transcription) -> Solution {
    let (n, m) = (tr.problem().n_variables(), tr.problem().n_constraints());
    assert_eq!(
        m,
        c.constraint_blocks().iter().map(|b| b.len).sum::<usize>()
    );
    let seq = |off: f64, len: usize| (0..len).map(|i| off + i as f64).collect::<Vec<_>>();
    Solution {
        status: Status::SolveSucceeded,
        x: seq(0.0, n),
        z_l: seq(1000.0, n),
        z_u: seq(2000.0, n),
        lambda: seq(3000.0, m),
        g: seq(4000.0, m),
        objective: 0.0,
        constr_viol: 0.0,
        dual_inf: 0.0,
        compl: 0.0,
        parameters: c.parameter_values().to_vec(),
        message: String::new(),
        stats: Default::default(),
    }
}

fn block(c: &Compiled, name: &str) -> std::ops::Range<usize> {
    let b = c.constraint_blocks().iter().find(|b| b.name == name);
    b.unwrap_or_else(|| panic!("no block {name}")).range()
}

/// Checks that `rows` (a block of `stages` equal runs) moved one stage forward with the
/// last stage duplicated, for λ and g.
fn assert_rows_shifted(
    old: &Solution,
    new: &Solution,
    rows: std::ops::Range<usize>,
    stages: usize,
) {
    let per = rows.len() / stages;
    assert_eq!(per * stages, rows.len());
    for k in 0..stages {
        for r in 0..per {
            let to = rows.start + k * per + r;
            let from = rows.start + (k + 1).min(stages - 1) * per + r;
            assert_eq!(new.lambda[to], old.lambda[from], "λ row {to}");
            assert_eq!(new.g[to], old.g[from], "g row {to}");
        }
    }
}

/// Checks that the variable `name` (`cols` columns of `per` entries... grouped in stages
/// of `group` columns) moved one stage forward, with its bound multipliers.
fn assert_variable_shifted(
    c: &Compiled,
    old: &Solution,
    new: &Solution,
    name: &str,
    stages: usize,
) {
    let b = c.variable_blocks().iter().find(|b| b.name == name).unwrap();
    let per = b.len / stages;
    assert_eq!(per * stages, b.len);
    for k in 0..stages {
        for r in 0..per {
            let (to, from) = (
                b.start + k * per + r,
                b.start + (k + 1).min(stages - 1) * per + r,
            );
            assert_eq!(new.x[to], old.x[from], "{name} entry {to}");
            assert_eq!(new.z_l[to], old.z_l[from]);
            assert_eq!(new.z_u[to], old.z_u[from]);
        }
    }
}

#[test]
fn shift_moves_multiple_shooting_stages_with_their_multipliers() {
    let tr = ocp()
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 2), N)
        .unwrap();
    let c = tr.compile().unwrap();
    let names: Vec<&str> = c
        .constraint_blocks()
        .iter()
        .map(|b| b.name.as_str())
        .collect();
    assert_eq!(names, ["initial state", "continuity", "path"]);
    // The path's simple-bound row left g: one row per stage remains.
    assert_eq!(block(&c, "path").len(), N + 1);
    assert_eq!(block(&c, "initial state").len(), 2);
    let old = labelled(&c, &tr);
    let new = tr.shift(&old).unwrap();
    assert_variable_shifted(&c, &old, &new, "X", N + 1);
    assert_variable_shifted(&c, &old, &new, "U", N);
    assert_rows_shifted(&old, &new, block(&c, "continuity"), N);
    assert_rows_shifted(&old, &new, block(&c, "path"), N + 1);
    // The initial state's rows are not per stage: unchanged.
    for r in block(&c, "initial state") {
        assert_eq!((new.lambda[r], new.g[r]), (old.lambda[r], old.g[r]));
    }
    // Every entry is accounted for: moved entries are exactly the checked ones.
    let plan = tr.shift_plan().unwrap();
    assert_eq!(plan.variable_moves().len(), 2 * N + (N - 1));
    assert_eq!(plan.row_moves().len(), 2 * (N - 1) + N);
}

#[test]
fn shift_moves_collocation_stages() {
    let tr = ocp()
        .transcribe(
            &Method::collocation(CollocationPoints::Radau, 2).unwrap(),
            N,
        )
        .unwrap();
    let c = tr.compile().unwrap();
    let old = labelled(&c, &tr);
    let new = tr.shift(&old).unwrap();
    assert_variable_shifted(&c, &old, &new, "X", N + 1);
    assert_variable_shifted(&c, &old, &new, "U", N);
    assert_variable_shifted(&c, &old, &new, "Xc", N); // d = 2 columns per stage
    assert_rows_shifted(&old, &new, block(&c, "collocation"), N);
    assert_rows_shifted(&old, &new, block(&c, "continuity"), N);
    assert_rows_shifted(&old, &new, block(&c, "path"), N + 1);
}

#[test]
fn shift_refuses_a_solution_of_another_size() {
    let tr = ocp()
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), N)
        .unwrap();
    let c = tr.compile().unwrap();
    let mut sol = labelled(&c, &tr);
    sol.lambda.pop();
    let err = tr.shift(&sol).unwrap_err();
    assert!(err.to_string().contains("solution lambda"), "{err}");
}

#[test]
fn initial_state_parameter_is_exclusive_with_a_fixed_initial_state() {
    let mut o = ocp();
    let err = o.set_initial_state(&[0.0, 0.0]).unwrap_err();
    assert!(err.to_string().contains("parameter 'x0'"), "{err}");
    let mut o = Ocp::new(&["x"], &["u"]);
    o.set_initial_state(&[1.0]).unwrap();
    assert!(matches!(
        o.set_initial_state_parameter("x0", &[1.0]),
        Err(OcpError::Invalid { .. })
    ));
    let mut o = Ocp::new(&["x"], &["u"]);
    assert!(matches!(
        o.set_initial_state_parameter("x0", &[1.0, 2.0]),
        Err(OcpError::Size { .. })
    ));
}

#[test]
fn mpc_refuses_a_fixed_initial_state_and_a_free_horizon() {
    let mut o = Ocp::new(&["x"], &["u"]);
    o.set_dynamics(|x, u, _p| Matrix::from_vec(vec![u[0] - x[0]]));
    o.set_initial_state(&[1.0]).unwrap();
    o.set_horizon(Horizon::Fixed(1.0)).unwrap();
    let tr = o
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), 4)
        .unwrap();
    let err = Mpc::new(&tr, Box::new(Ipm::default())).err().unwrap();
    assert!(matches!(err, MpcError::NoInitialStateParameter), "{err}");
    let mut o = Ocp::new(&["x"], &["u"]);
    o.set_dynamics(|x, u, _p| Matrix::from_vec(vec![u[0] - x[0]]));
    o.set_initial_state_parameter("x0", &[1.0]).unwrap();
    let free = Horizon::Free {
        lower: 0.5,
        upper: 2.0,
        guess: 1.0,
    };
    o.set_horizon(free).unwrap();
    let tr = o
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), 4)
        .unwrap();
    let err = Mpc::new(&tr, Box::new(Ipm::default())).err().unwrap();
    assert!(matches!(err, MpcError::FreeHorizon), "{err}");
    // A measured state of the wrong length is an error naming the parameter.
    let mut o = ocp();
    o.set_horizon(Horizon::Fixed(1.0)).unwrap();
    let tr = o
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), 4)
        .unwrap();
    let mut mpc = Mpc::new(&tr, Box::new(Ipm::default())).unwrap();
    let err = mpc.step(&[1.0]).unwrap_err();
    assert!(err.to_string().contains("x0"), "{err}");
}

/// The plant is the transcription's integrator: one RK4 step from a solved plan's `X_k`
/// with `U_k` lands on `X_{k+1}` to the solve's feasibility tolerance.
#[test]
fn simulator_matches_the_transcription() {
    let o = ocp();
    let tr = o
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 2), N)
        .unwrap();
    let sol = Ipm::default().solve(&mut tr.compile().unwrap()).unwrap();
    assert!(sol.status.is_success());
    let traj = tr.trajectory(&sol).unwrap();
    let mut plant = Simulator::new(&o, ButcherTableau::rk4(), 2).unwrap();
    let h = 1.0 / N as f64;
    for k in 0..N {
        let x: Vec<f64> = traj.states.iter().map(|s| s[k]).collect();
        let next = plant.step(&x, &[traj.controls[0][k]], h).unwrap();
        for (i, v) in next.iter().enumerate() {
            // IPOPT's default constr_viol_tol is 1e-4; the solve reaches ~1e-12.
            assert!((v - traj.states[i][k + 1]).abs() < 1e-9, "k {k} state {i}");
        }
    }
}

/// CasADi + IPOPT's closed loop on the identical transcription, plant and warm start
/// (benches/reference/results/mpc_casadi.jsonl): Σ l dt over the 100 steps.
const IPOPT_CART_POLE_LOOP_COST: f64 = 40.42107528932347;

/// Issue 19's cart-pole swing-up loop with the interior point: every step succeeds and the
/// closed-loop cost equals IPOPT's loop. Tolerance 1e-6 relative: both solvers stop every
/// step at a KKT error ≤ 1e-8 and the loop is stabilising, so converged loops agree to
/// ~1e-8 (measured 1e-13); a loop that took another local solution at some step or
/// applied a different control moves the cost by far more.
#[test]
fn cart_pole_closed_loop_matches_ipopt() {
    let example = mpc_cart_pole::example();
    let run = example.closed_loop(Box::new(Ipm::default())).unwrap();
    assert_eq!(run.steps.len(), mpc_cart_pole::STEPS);
    assert!(
        run.all_succeeded(),
        "{:?}",
        run.steps.iter().map(|s| s.status).collect::<Vec<_>>()
    );
    assert!(run.steps[1..].iter().all(|s| s.warm) && !run.steps[0].warm);
    // The warm latency is over the warm steps alone: the cold first step left out.
    let mut warm = run.clone();
    warm.steps.remove(0);
    assert_eq!(run.warm_latency(), warm.latency());
    let cost = example.cost(&run).unwrap();
    let rel = ((cost - IPOPT_CART_POLE_LOOP_COST) / IPOPT_CART_POLE_LOOP_COST).abs();
    assert!(
        rel < 1e-6,
        "closed-loop cost {cost} vs IPOPT {IPOPT_CART_POLE_LOOP_COST}"
    );
    // Swung up: upright at the origin at the end.
    let x = &run.states[mpc_cart_pole::STEPS];
    assert!(
        x[0].abs() < 1e-2 && (x[1] - std::f64::consts::PI).abs() < 1e-2,
        "{x:?}"
    );
}

/// CasADi + IPOPT's closed loops of the car and the quadrotor (same script and file).
const IPOPT_CAR_LOOP_COST: f64 = 40.9501029836042;
const IPOPT_QUADROTOR_LOOP_COST: f64 = 17.549770607539823;

/// Every step succeeds and the loop cost equals IPOPT's (tolerance as for the cart-pole;
/// measured 1e-15 and 2e-16). A macro: each example includes its own copy of
/// `mpc_common`, so their `MpcExample`s are distinct types.
macro_rules! assert_loop_matches_ipopt {
    ($example:expr, $ipopt:expr) => {{
        let example = $example;
        let run = example.closed_loop(Box::new(Ipm::default())).unwrap();
        assert!(run.all_succeeded(), "{}", example.name);
        let cost = example.cost(&run).unwrap();
        let rel = ((cost - $ipopt) / $ipopt).abs();
        assert!(
            rel < 1e-6,
            "{}: closed-loop cost {cost} vs IPOPT {}",
            example.name,
            $ipopt
        );
    }};
}

#[test]
fn car_closed_loop_matches_ipopt() {
    assert_loop_matches_ipopt!(mpc_car::example(), IPOPT_CAR_LOOP_COST);
}

#[test]
fn quadrotor_closed_loop_matches_ipopt() {
    assert_loop_matches_ipopt!(mpc_quadrotor::example(), IPOPT_QUADROTOR_LOOP_COST);
}

/// Real-time iterations (`Mpc::with_rti`: the first step converged by the interior
/// point, then one SQP iteration per step) on the cart-pole swing-up and the car: the
/// closed-loop cost within 2 % of the converged loop's (the interior point every step,
/// computed here; issue 19's target; measured 1e-8 relative on both), every later step a
/// full step (`RealTimeIterationTaken`, one iteration — not a failed QP), and the
/// cart-pole swung up.
macro_rules! assert_rti_loop_near_converged {
    ($example:expr) => {{
        let example = $example;
        let converged = example.closed_loop(Box::new(Ipm::default())).unwrap();
        let rti = example.closed_loop_rti().unwrap();
        assert!(rti.steps[0].status.is_success(), "{}", example.name);
        for (s, r) in rti.steps.iter().enumerate().skip(1) {
            assert_eq!(
                r.status,
                Status::RealTimeIterationTaken,
                "{} step {s}",
                example.name
            );
            assert_eq!(r.iterations, 1);
            assert!(r.feedback_seconds <= r.solve_seconds);
        }
        assert!(rti.all_succeeded(), "{}", example.name);
        let (a, b) = (
            example.cost(&rti).unwrap(),
            example.cost(&converged).unwrap(),
        );
        assert!(
            (a - b).abs() <= 0.02 * b,
            "{}: RTI loop cost {a} vs converged {b}",
            example.name
        );
        rti
    }};
}

#[test]
fn cart_pole_rti_loop_within_2_percent_of_the_converged_loop() {
    let rti = assert_rti_loop_near_converged!(mpc_cart_pole::example());
    let x = &rti.states[mpc_cart_pole::STEPS];
    assert!(
        x[0].abs() < 1e-2 && (x[1] - std::f64::consts::PI).abs() < 1e-2,
        "{x:?}"
    );
}

#[test]
fn car_rti_loop_within_2_percent_of_the_converged_loop() {
    assert_rti_loop_near_converged!(mpc_car::example());
}

/// The car's loop (first 20 steps) with the tape and with native evaluators
/// (`Mpc::with_evaluator(Evaluator::Jit)`) for the IPM, the SQP and real-time iterations:
/// the same states, controls, statuses and iteration counts bit for bit (the JIT performs
/// the tape's operations in the tape's order, so no tolerance applies).
#[test]
fn jit_closed_loops_are_bit_identical_to_the_tape() {
    let example = mpc_car::example();
    for solver in ["ipm", "sqp", "rti"] {
        let runs: Vec<_> = [false, true]
            .into_iter()
            .map(|jit| {
                let (tr, mut plant) = example.setup().unwrap();
                let (mut mpc, _) = example.controller(&tr, solver, jit).unwrap();
                let want = if jit { Evaluator::Jit } else { Evaluator::Tape };
                assert_eq!(mpc.compiled_mut().evaluator(), want);
                let dt = example.dt;
                mpc.run(&example.x_init, 20, |x, u, next| {
                    plant.step_into(x, u, dt, next)
                })
                .unwrap()
            })
            .collect();
        let (tape, jit) = (&runs[0], &runs[1]);
        assert!(tape.all_succeeded(), "{solver}");
        let bits =
            |v: &[Vec<f64>]| -> Vec<u64> { v.concat().iter().map(|a| a.to_bits()).collect() };
        assert_eq!(bits(&tape.states), bits(&jit.states), "{solver}: states");
        assert_eq!(
            bits(&tape.controls),
            bits(&jit.controls),
            "{solver}: controls"
        );
        for (a, b) in tape.steps.iter().zip(&jit.steps) {
            assert_eq!(
                (a.status, a.iterations),
                (b.status, b.iterations),
                "{solver}"
            );
            assert_eq!(a.objective.to_bits(), b.objective.to_bits(), "{solver}");
        }
    }
}

/// The RTI's predictor-corrector (docs/mpc.md §5.1) carries the cart-pole loop: from the
/// converged first plan, every one of 30 feedbacks is the step prepared for the plan's
/// own initial state corrected for the measured one by a single back-substitution
/// (`Feedback::corrected`), with no factorisation and no clarabel. (When the measured state
/// leaves the prediction by more than ≈ 1e-6–1e-5, the unrefined correction misses its
/// 1e-12 accuracy test and the feedback solves from the prepared working set instead:
/// docs/mpc.md §5.1.)
#[test]
fn cart_pole_rti_feedbacks_are_corrected_prepared_steps() {
    let ex = mpc_cart_pole::example();
    let (tr, mut plant) = ex.setup().unwrap();
    let mut c = tr.compile().unwrap();
    c.set_value("x0", &ex.x_init).unwrap();
    let first = Ipm::default().solve(&mut c).unwrap();
    assert!(first.status.is_success());
    let mut rti = Rti::from_transcription(&tr, SqpOptions::default()).unwrap();
    rti.initialize(&first).unwrap();
    let steps = rti_feedbacks(&tr, &mut rti, &mut plant, (&ex.x_init, ex.dt), 30);
    assert_every_feedback_corrected(&steps);
}
