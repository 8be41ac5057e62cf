//! The Hock–Schittkowski suite solved by the SQP back end ([`nlp::Sqp`]) alone (default
//! options but `cold_start_ipm` off: the SQP from the problem's start; the default, from
//! the IPM's solution, is `sqp_cold_start.rs`'s): the same problems (`hs/problems.rs`) and the same assertions as `tests/hs.rs`
//! (status `SolveSucceeded`, published f* to the problem's tolerance or a documented
//! local minimiser, final constraint violation ≤ 1e-4).
//!
//! `sqp_hs_summary` (ignored) prints one JSON line per problem for docs/performance.md:
//!
//! ```text
//! cargo test --release -p nlp --test sqp_hs -- --ignored --nocapture sqp_hs_summary
//! ```
use nlp::{CommonOptions, Sqp, SqpOptions, Status};

use testkit::hs::{harness, problems, SUITE};
use testkit::hs_suite;

use harness::Run;
use problems::Built;

hs_suite!();

/// Problems the SQP back end alone does not solve yet: (name, the status
/// it returns now, why). Their tests are honest known failures: they assert exactly this
/// status and that the run is *not* a success by the criteria of the other problems, so
/// a change of behaviour (better or worse) fails the test and the list must be updated.
/// The IPM solves all of them (`tests/hs.rs`).
const KNOWN_FAILURES: &[(&str, Status, &str)] = &[
    // No KKT point at the solution (degenerate constraints); f = 0.9989 ≈ f* but the
    // dual error never reaches tol. With clarabel's QP steps the run ended at the
    // acceptable level (41 iterations); with the active-set QP (issue 19) it runs into
    // the iteration limit near the cusp.
    (
        "hs013",
        Status::MaximumIterationsExceeded,
        "no KKT point at the solution",
    ),
    // The start x = (-2, 1) is clipped to the bound x1 <= 0.5 and SQP converges to the
    // KKT point f = 23.1447, not the global 0.25.
    (
        "hs016",
        Status::SolveSucceeded,
        "other local KKT point f = 23.1447",
    ),
    // Since the active-set QP (issue 19) the SQP converges in 10 iterations to the KKT
    // point x = (0, 0, 2), f = −4: first-order stationary (x1 ≥ 0, x2 ≥ 0 and
    // x1² + x2² + x3² ≥ 4 active) but a saddle of the problem (the curve x2 = 2√ε,
    // x3 = 2 − ε is feasible and lowers f); the convexified Hessian of the QP cannot see
    // the negative curvature. With clarabel's interior QP solutions it reached f* (31
    // iterations).
    ("hs033", Status::SolveSucceeded, "saddle KKT point f = -4"),
];

fn sqp(name: &'static str, build: fn() -> Built, print_level: u8) -> Run {
    harness::run(name, build, |nlp| {
        let common = CommonOptions {
            print_level,
            ..CommonOptions::default()
        };
        Sqp::new(SqpOptions {
            common,
            cold_start_ipm: false,
            ..SqpOptions::default()
        })
        .solve(nlp)
    })
}

fn run(name: &'static str, build: fn() -> Built) -> Run {
    sqp(name, build, 0)
}

fn check(name: &'static str, build: fn() -> Built) {
    let run = run(name, build);
    let sol = match &run.result {
        Ok(sol) => sol,
        Err(e) => panic!("{name}: solve error: {e}"),
    };
    let success = run.succeeded(sol);
    if let Some((_, expected, why)) = KNOWN_FAILURES.iter().find(|(n, _, _)| *n == name) {
        // Honest known failure: the current (failing) behaviour, exactly.
        assert_eq!(
            sol.status, *expected,
            "{name}: known SQP failure ({why}) changed status: now {:?}, f = {}; update KNOWN_FAILURES",
            sol.status, sol.objective
        );
        assert!(
            !success,
            "{name}: listed as a known SQP failure ({why}) but now solved: remove it from KNOWN_FAILURES"
        );
        return;
    }
    run.assert_solved(sol);
}

/// One JSON line per problem and a summary on stderr.
#[test]
#[ignore = "report for docs/performance.md: run with --release --ignored --nocapture"]
fn sqp_hs_summary() {
    harness::summary(SUITE, run);
}

/// Iteration tables of the problems named in `HS` (comma-separated).
#[test]
#[ignore = "diagnostics: run with HS=<names> --release --ignored --nocapture"]
fn sqp_hs_log() {
    for name in harness::names_from_env() {
        let (name, build) = harness::find(SUITE, &name);
        println!("==== {name}");
        let run = sqp(name, build, 5);
        if let Ok(sol) = &run.result {
            println!(
                "{:?} f = {} (f* = {}) {}",
                sol.status, sol.objective, run.f_star, sol.message
            );
        }
    }
}
