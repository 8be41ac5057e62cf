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

/// The 20-link chain of `python/tests/problems.py` (`build_chain`): masses (x_i, y_i),
/// min Σ y_i, every link at most 1.25/19 long (an inequality), the ends fixed by
/// equality rows with parameter values; the guess a straight line between the ends.
fn chain20() -> Problem {
    let n = 20;
    let mut pb = Problem::new();
    let xs = pb.variable("px", n).unwrap();
    let ys = pb.variable("py", n).unwrap();
    let ends = pb.parameter("ends", 4).unwrap();
    pb.minimize((0..n).fold(Expr::from(0.0), |a, i| a + ys[i]));
    let seg = 1.25 / (n - 1) as f64;
    for i in 0..n - 1 {
        let len2 = (xs[i + 1] - xs[i]).sq() + (ys[i + 1] - ys[i]).sq();
        pb.subject_to(len2.le(seg * seg)).unwrap();
    }
    for (v, k) in [(xs[0], 0), (ys[0], 1), (xs[n - 1], 2), (ys[n - 1], 3)] {
        pb.subject_to((v - ends[k]).eq(0.0)).unwrap();
    }
    let t = |i: usize| i as f64 / (n - 1) as f64;
    let x0: Vec<f64> = (0..n).map(t).collect();
    let y0: Vec<f64> = (0..n).map(|i| 1.0 - 0.5 * t(i)).collect();
    pb.set_initial(&xs, &x0).unwrap();
    pb.set_initial(&ys, &y0).unwrap();
    pb.set_value(&ends, &[0.0, 1.0, 1.0, 0.5]).unwrap();
    pb
}

/// Found by the Python suite (`python/tests/test_casadi_compare.py`, marked xfail there):
/// at tol 1e-10 the SQP stops at f = 12.2632967, 1.58e-5 above IPOPT's and the IPM's
/// 12.2632810. The cause is not the SQP: IPOPT and the IPM relax every bound by
/// `bound_relax_factor`·max(1, |bound|) = 1e-8 (the links' bound is seg² ≈ 0.0043), so
/// they solve a problem whose links may be longer, and its optimum is lower by
/// Σ λ_i·1e-8 ≈ 1577·1e-8 (first-order sensitivity of f* to the bounds). The SQP keeps
/// the bounds exact. Checked: the SQP agrees with the IPM without the relaxation to 1e-9
/// relative (both at tol 1e-10 on the scaled KKT error; measured 1e-12), and the default
/// IPM's gap is the first-order estimate to 2 % (second-order terms are 1e-8 smaller).
#[test]
fn chain20_tight_tolerance_reaches_the_exact_optimum() {
    let mut c = chain20().compile().unwrap();
    let common = CommonOptions {
        tol: 1e-10,
        print_level: std::env::var("SQP_PRINT")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(0),
        ..CommonOptions::default()
    };
    let sqp = Sqp::new(SqpOptions {
        common: common.clone(),
        ..SqpOptions::default()
    });
    let sol = sqp.solve(&mut c).unwrap();
    assert_eq!(sol.status, Status::SolveSucceeded, "{}", sol.message);
    let mut ipm = Ipm::default();
    ipm.options.common.tol = 1e-10;
    ipm.options.bound_relax_factor = 0.0;
    let exact = ipm.solve(&mut c).unwrap();
    assert_eq!(exact.status, Status::SolveSucceeded, "{}", exact.message);
    let rel = (sol.objective - exact.objective).abs() / exact.objective.abs();
    assert!(
        rel <= 1e-9,
        "SQP f = {}, IPM without relaxation f = {} (rel. {rel:e})",
        sol.objective,
        exact.objective
    );
    ipm.options.bound_relax_factor = 1e-8;
    let relaxed = ipm.solve(&mut c).unwrap();
    assert_eq!(relaxed.status, Status::SolveSucceeded);
    let links: f64 = sol.lambda[..19].iter().sum();
    let predicted = 1e-8 * links;
    let gap = sol.objective - relaxed.objective;
    assert!(
        (gap - predicted).abs() <= 0.02 * predicted,
        "gap to the relaxed optimum {gap:e}, predicted Σλ·1e-8 = {predicted:e}"
    );
}

/// One solver re-used along a warm sequence keeps its KKT matrix and QP layouts between
/// solves (`nlp/src/sqp/workspace.rs`); nothing numeric is carried over, so every solve
/// must be bit-identical to the same warm solve by a new solver. The sequence includes
/// a change of structure (another problem) in the middle, after which the parts are
/// rebuilt.
#[test]
fn warm_sequence_with_kept_parts_is_bit_identical() {
    let (pb, p) = chain_with_moving_end(40);
    let mut c = pb.compile().unwrap();
    let mut other = hanging_chain(30).compile().unwrap();
    let kept = sqp(0);
    let mut prev = kept.solve(&mut c).unwrap();
    assert_eq!(prev.status, Status::SolveSucceeded, "{}", prev.message);
    for k in 1..=6 {
        if k == 3 {
            let a = kept.solve(&mut other).unwrap();
            let b = sqp(0).solve(&mut other).unwrap();
            assert_eq!(a.x, b.x, "other structure");
        }
        c.set_value(&[p], &[1.0 - 0.03 * k as f64]).unwrap();
        let a = kept.solve_warm(&mut c, &prev).unwrap();
        let b = sqp(0).solve_warm(&mut c, &prev).unwrap();
        assert_eq!(a.status, Status::SolveSucceeded, "step {k}: {}", a.message);
        assert_eq!(a.stats.iterations, b.stats.iterations, "step {k}");
        assert_eq!(a.x, b.x, "step {k}");
        assert_eq!(a.lambda, b.lambda, "step {k}");
        assert_eq!(a.z_l, b.z_l, "step {k}");
        assert_eq!(a.z_u, b.z_u, "step {k}");
        prev = a;
    }
}
