//! The SQP on the hanging chain (issue 19, where the SQP was reported to fail from the
//! cold parabola guess): 200 links from the guess of `benches/reference/hanging_chain.py`,
//! then a sequence of warm re-solves with the right end point moved, each checked
//! against the IPM solved cold on the same problem (both stop at the scaled KKT error
//! 1e-8; the IPM's chain is checked against the exact discrete catenary and IPOPT in
//! `chain_large.rs`).
use nlp::{CommonOptions, Ipm, Problem, Relation, Solver, Sqp, SqpOptions, Status};
use symx::{Expr, Matrix};
use testkit::solve_problems::hanging_chain;

fn sqp(print_level: u8) -> Sqp {
    Sqp::new(SqpOptions {
        common: CommonOptions {
            print_level,
            ..CommonOptions::default()
        },
        ..SqpOptions::default()
    })
}

/// Objectives of two solves that both met tol = 1e-8: agreement to 1e-8 relative (the
/// objective is O(1) and first-order insensitive to the KKT error; measured ≤ 1e-10).
fn assert_same_objective(what: &str, a: f64, b: f64) {
    let rel = (a - b).abs() / b.abs().max(1.0);
    assert!(
        rel <= 1e-8,
        "{what}: SQP f = {a}, IPM f = {b} (rel. {rel:e})"
    );
}

#[test]
fn chain_200_cold_from_parabola() {
    let mut c = hanging_chain(200).compile().unwrap();
    let sol = sqp(0).solve(&mut c).unwrap();
    assert_eq!(sol.status, Status::SolveSucceeded, "{}", sol.message);
    let ipm = Ipm::default().solve_dyn(&mut c, None, None).unwrap();
    assert_eq!(ipm.status, Status::SolveSucceeded);
    assert_same_objective("cold", sol.objective, ipm.objective);
    assert!(sol.constr_viol <= 1e-8, "‖g‖∞ = {:e}", sol.constr_viol);
}

/// The chain with its right end point x_N = p a parameter (an equality row, so the
/// point can move between solves).
fn chain_with_moving_end(links: usize) -> (Problem, Expr) {
    let n = 2 * (links + 1);
    let mut pb = Problem::new();
    let w = pb.variable("w", n).unwrap();
    let p = pb.scalar_parameter("x_end").unwrap();
    let x = |i: usize| w[2 * i];
    let y = |i: usize| w[2 * i + 1];
    let seg2 = (2.0 / links as f64).powi(2);
    let g: Vec<Expr> = (0..links)
        .map(|i| (x(i + 1) - x(i)).sq() + (y(i + 1) - y(i)).sq() - seg2)
        .collect();
    let f = (0..=links).fold(Expr::from(0.0), |a, i| a + y(i)) / links as f64;
    pb.minimize(f);
    pb.subject_to_named("link", (&Matrix::from_vec(g)).eq(0.0))
        .unwrap();
    pb.subject_to_named("end", (x(links) - p).eq(0.0)).unwrap();
    for k in [0, 1, 2 * links + 1] {
        pb.set_bounds(&[w[k]], 0.0, 0.0).unwrap();
    }
    let mut x0 = vec![0.0; n];
    for i in 0..=links {
        let t = i as f64 / links as f64;
        x0[2 * i] = t;
        x0[2 * i + 1] = -0.5 * (std::f64::consts::PI * t).sin();
    }
    pb.set_initial(&w, &x0).unwrap();
    pb.set_value(&[p], &[1.0]).unwrap();
    (pb, p)
}

#[test]
fn chain_200_warm_sequence() {
    let (pb, p) = chain_with_moving_end(200);
    let mut c = pb.compile().unwrap();
    let solver = sqp(0);
    let mut prev = solver.solve(&mut c).unwrap();
    assert_eq!(prev.status, Status::SolveSucceeded, "{}", prev.message);
    for k in 1..=20 {
        let end = 1.0 - 0.02 * k as f64;
        c.set_value(&[p], &[end]).unwrap();
        let sol = solver.solve_warm(&mut c, &prev).unwrap();
        assert_eq!(
            sol.status,
            Status::SolveSucceeded,
            "step {k}: {}",
            sol.message
        );
        let ipm = Ipm::default().solve_dyn(&mut c, None, None).unwrap();
        assert_eq!(ipm.status, Status::SolveSucceeded, "IPM step {k}");
        assert_same_objective(&format!("step {k}"), sol.objective, ipm.objective);
        prev = sol;
    }
}

#[test]
#[ignore = "diagnostics: LINKS=<n> cargo test --release -p nlp --test sqp_chain -- --ignored --nocapture"]
fn chain_cold_log() {
    let links = std::env::var("LINKS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200);
    let mut c = hanging_chain(links).compile().unwrap();
    let sol = sqp(5).solve(&mut c).unwrap();
    println!("sqp {} {}", sol.status, sol.objective);
}
