//! The Hock–Schittkowski suite: every problem in `hs/problems.rs` solved by the
//! interior-point method with default options from the published starting point.
//!
//! Each problem is its own `#[test]` (module `solve`), asserting
//! - status `SolveSucceeded` (IPOPT 3.14 reaches `Solve_Succeeded` on all of them, see
//!   `benches/reference/results/hs_ipopt.json`);
//! - the published optimal objective to 1e-6, relative to |f*| (absolute when f* = 0,
//!   where there is no scale to be relative to). The solver stops when the scaled KKT
//!   error is below tol = 1e-8, which on these small, well-scaled problems puts the
//!   objective orders of magnitude closer than that. A few problems list other local
//!   minimisers that IPOPT reaches from the standard start, and hs013 (no KKT point at
//!   the solution) has a documented looser tolerance: see `Case` in `hs/problems.rs`;
//! - the final constraint violation within IPOPT's `constr_viol_tol` (1e-4).
//!
//! `hs_summary` (ignored) prints one JSON line per problem with status, iterations,
//! objective and time, for the comparison with IPOPT in docs/performance.md:
//!
//! ```text
//! cargo test --release -p nlp --test hs -- --ignored --nocapture hs_summary
//! ```
use nlp::ipm::Ipm;
use nlp::{CommonOptions, IpmOptions};

use testkit::hs::{harness, problems, SUITE};
use testkit::hs_suite;

use harness::Run;
use problems::Built;

hs_suite!();

fn run(name: &'static str, build: fn() -> Built) -> Run {
    harness::run(name, build, |nlp| {
        Ipm::new(IpmOptions::default()).solve(nlp)
    })
}

fn check(name: &'static str, build: fn() -> Built) {
    let run = run(name, build);
    match &run.result {
        Ok(sol) => run.assert_solved(sol),
        Err(e) => panic!("{name}: solve error: {e}"),
    }
}

/// Every builder produces a problem that compiles (cheap; runs in debug builds too).
#[test]
fn every_problem_compiles() {
    assert!(SUITE.len() >= 45, "the suite has {} problems", SUITE.len());
    for &(name, build) in SUITE {
        let case = build().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(case.f_star.is_finite(), "{name}");
        case.problem
            .compile()
            .unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

/// Prints one JSON line per problem (name, status, iterations, objective, f*, which
/// optimum it matches, constraint violation, times) and a summary line on stderr.
#[test]
#[ignore = "report for docs/performance.md: run with --release --ignored --nocapture"]
fn hs_summary() {
    harness::summary(SUITE, run);
}

/// Prints the IPOPT-style iteration table of the problems named in the environment
/// variable `HS` (comma-separated), for diagnosing a failure:
///
/// ```text
/// HS=hs013,hs061 cargo test --release -p nlp --test hs -- --ignored --nocapture hs_log
/// ```
#[test]
#[ignore = "diagnostics: run with HS=<names> --release --ignored --nocapture"]
fn hs_log() {
    for name in harness::names_from_env() {
        let (name, build) = harness::find(SUITE, &name);
        println!("==== {name}");
        let run = harness::run(name, build, |nlp| {
            let common = CommonOptions {
                print_level: 5,
                ..CommonOptions::default()
            };
            Ipm::new(IpmOptions {
                common,
                ..IpmOptions::default()
            })
            .solve(nlp)
        });
        match &run.result {
            Ok(sol) => println!(
                "{name}: {:?}, {} iterations, f = {:.12e} (f* = {}), x = {:?}",
                sol.status, sol.stats.iterations, sol.objective, run.f_star, sol.x
            ),
            Err(e) => println!("{name}: error {e}"),
        }
    }
}
