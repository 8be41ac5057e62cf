//! The SQP started from the interior-point method's solution (`cold_start_ipm`): the
//! Hock–Schittkowski problems the SQP alone does not solve to their published optimum
//! (`sqp_hs.rs`'s known failures) and two it does, checked against the published f* of
//! `testkit::hs::problems` (Hock and Schittkowski 1981, with the sources cited there),
//! with the same criteria as `tests/hs.rs` (status, violation ≤ 1e-4, f* to the
//! problem's tolerance).
use nlp::{NumericNlp, Relation, Solver, Sqp, SqpOptions, Status};
use testkit::hs::{harness, SUITE};

fn ipm_started() -> Sqp {
    Sqp::new(SqpOptions {
        cold_start_ipm: true,
        ..SqpOptions::default()
    })
}

#[test]
fn the_sqps_hs_failures_are_solved_from_the_ipms_solution() {
    // hs013 (the third known failure) has no KKT point at its solution: the SQP from the
    // IPM's point still ends in a failed QP. hs116: see the test below.
    for name in ["hs016", "hs033", "hs071"] {
        let (name, build) = harness::find(SUITE, name);
        let run = harness::run(name, build, |nlp| ipm_started().solve_dyn(nlp, None, None));
        let sol = run.result.as_ref().expect("solve");
        run.assert_solved(sol);
        // From a converged IPM point the SQP only confirms it: a few iterations at most.
        assert!(
            sol.stats.iterations <= 5,
            "{name}: {} SQP iterations after the IPM",
            sol.stats.iterations
        );
    }
}

/// A known failure, asserted as it is so that a change shows: from the IPM's optimum of
/// hs116 (f = 97.5875, published f* 97.588409) the SQP's first QP is elastic (its
/// linearised constraints at a feasible point judged infeasible), it takes a step of
/// length 74 and never returns (f ≈ 102.7 at the iteration limit), while the SQP alone
/// solves hs116 cold in 1 523 iterations. A defect of the SQP's elastic mode, not of
/// the start; when it is fixed this test fails and hs116 joins the list above.
#[test]
fn hs116_known_failure_from_the_ipms_optimum() {
    let (name, build) = harness::find(SUITE, "hs116");
    let run = harness::run(name, build, |nlp| ipm_started().solve_dyn(nlp, None, None));
    let sol = run.result.as_ref().expect("solve");
    assert_eq!(sol.status, Status::MaximumIterationsExceeded);
    assert!(!run.succeeded(sol));
}

#[test]
fn a_warm_start_given_by_the_caller_skips_the_ipm() {
    let (name, build) = harness::find(SUITE, "hs071");
    let cold = harness::run(name, build, |nlp| Sqp::default().solve_dyn(nlp, None, None));
    let cold = cold.result.expect("solve");
    // Same warm start, option on or off: the same iterates, bit for bit.
    let mut nlp = build().unwrap().problem.compile().unwrap();
    let off = Sqp::default()
        .solve_dyn(&mut nlp, Some(&cold), None)
        .unwrap();
    let on = ipm_started()
        .solve_dyn(&mut nlp, Some(&cold), None)
        .unwrap();
    assert_eq!(off.x, on.x);
    assert_eq!(off.stats.iterations, on.stats.iterations);
    assert_eq!(nlp.n(), on.x.len());
}

#[test]
fn an_infeasible_problem_ends_with_the_sqps_own_status() {
    // The unit disc and the half-plane x₀ + x₁ ≥ 3 do not meet: the IPM does not
    // succeed, so the SQP starts cold and must not report success either.
    let mut pb = nlp::Problem::new();
    let x = pb.variable("x", 2).unwrap();
    pb.minimize(x[0].sq() + x[1].sq());
    pb.subject_to((x[0].sq() + x[1].sq()).le(1.0)).unwrap();
    pb.subject_to((x[0] + x[1]).ge(3.0)).unwrap();
    let mut c = pb.compile().unwrap();
    let sol = ipm_started().solve_dyn(&mut c, None, None).unwrap();
    assert!(!sol.status.is_success(), "status {:?}", sol.status);
    assert_ne!(sol.status, Status::SolveSucceeded);
}

#[test]
fn the_option_is_set_by_name() {
    let mut sqp = Sqp::default();
    nlp::NamedOptions::set_by_name(&mut sqp.options, &["cold_start_ipm=true"]).unwrap();
    assert!(sqp.options.cold_start_ipm);
}

/// The whole HS suite with and without the option: which problems differ and the counts
/// (docs/solvers.md, CHANGELOG). `cargo test --release --workspace --test sqp_cold_start
/// -- --ignored --nocapture hs_suite_count` (5 s).
#[test]
#[ignore = "prints the counts of docs/solvers.md (5 s)"]
fn hs_suite_count() {
    let (mut ok_on, mut ok_off) = (0, 0);
    for &(name, build) in SUITE {
        let on = harness::run(name, build, |nlp| ipm_started().solve_dyn(nlp, None, None));
        let off = harness::run(name, build, |nlp| Sqp::default().solve_dyn(nlp, None, None));
        let a = on.result.as_ref().map(|s| on.succeeded(s)).unwrap_or(false);
        let b = off
            .result
            .as_ref()
            .map(|s| off.succeeded(s))
            .unwrap_or(false);
        ok_on += a as usize;
        ok_off += b as usize;
        if a != b {
            println!(
                "{name}: ipm-started {a} ({:.3}s) plain {b} ({:.3}s)",
                on.solve_seconds, off.solve_seconds
            );
        }
    }
    println!(
        "solved: ipm-started {ok_on}, plain {ok_off} of {}",
        SUITE.len()
    );
}
