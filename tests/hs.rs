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
//! cargo test --release --test hs -- --ignored --nocapture hs_summary
//! ```
use std::time::Instant;

use symnlp::nlp;

use nlp::ipm::Ipm;
use nlp::{IpmOptions, Solution, SolveError, Status};

#[path = "hs/problems.rs"]
mod problems;

use problems::Built;

/// Generates the registry `SUITE` and one test per problem from one list of builders.
macro_rules! hs_suite {
    ($($name:ident),* $(,)?) => {
        /// Every problem of the suite with its name, in order.
        pub const SUITE: &[(&str, fn() -> Built)] = &[$((stringify!($name), problems::$name)),*];

        mod solve {
            $(
                #[test]
                fn $name() {
                    super::check(stringify!($name), super::problems::$name);
                }
            )*
        }
    };
}

hs_suite! {
    // bounds only
    hs001, hs002, hs003, hs004, hs005, hs025, hs038, hs045, hs110,
    // equality constraints
    hs006, hs007, hs008, hs009, hs026, hs027, hs028, hs039, hs040, hs042, hs046, hs047,
    hs048, hs049, hs050, hs051, hs052, hs053, hs056, hs061, hs077, hs078, hs079,
    // inequality constraints (hs013: degenerate, no constraint qualification)
    hs010, hs011, hs012, hs013, hs014, hs015, hs016, hs017, hs018, hs019, hs020, hs021,
    hs022, hs023, hs024, hs029, hs030, hs031, hs032, hs033, hs034, hs035, hs036, hs037,
    hs043, hs044, hs064, hs065, hs066, hs076, hs100, hs113,
    // mixed equalities and inequalities
    hs071, hs073, hs080, hs081, hs106, hs108, hs114, hs116, hs118,
}

/// IPOPT's default `constr_viol_tol`: the largest final violation a success may have.
const CONSTR_VIOL_TOL: f64 = 1e-4;

/// One solve of one problem.
struct Run {
    name: &'static str,
    f_star: f64,
    local: &'static [f64],
    tol: f64,
    compile_seconds: f64,
    solve_seconds: f64,
    result: Result<Solution, SolveError>,
}

fn run(name: &'static str, build: fn() -> Built) -> Run {
    let case = build().unwrap_or_else(|e| panic!("{name}: building the problem failed: {e}"));
    let t0 = Instant::now();
    let mut compiled = case
        .problem
        .compile()
        .unwrap_or_else(|e| panic!("{name}: compile failed: {e}"));
    let compile_seconds = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let result = Ipm::new(IpmOptions::default()).solve(&mut compiled);
    let solve_seconds = t1.elapsed().as_secs_f64();
    Run {
        name,
        f_star: case.f_star,
        local: case.local,
        tol: case.tol,
        compile_seconds,
        solve_seconds,
        result,
    }
}

/// Error of `f` against an optimal value: relative, or absolute when it is 0.
fn objective_error(f: f64, f_star: f64) -> f64 {
    if f_star == 0.0 {
        f.abs()
    } else {
        (f - f_star).abs() / f_star.abs()
    }
}

/// Which optimum `f` matches within `tol`: "f*", "local" (a documented local
/// minimiser), or `None`.
fn matched(run: &Run, f: f64) -> Option<&'static str> {
    if objective_error(f, run.f_star) <= run.tol {
        Some("f*")
    } else if run.local.iter().any(|&l| objective_error(f, l) <= run.tol) {
        Some("local")
    } else {
        None
    }
}

fn check(name: &'static str, build: fn() -> Built) {
    let run = run(name, build);
    let sol = match &run.result {
        Ok(sol) => sol,
        Err(e) => panic!("{name}: solve error: {e}"),
    };
    assert_eq!(
        sol.status,
        Status::SolveSucceeded,
        "{name}: status {:?} after {} iterations, f = {}, constr_viol = {:e}, dual_inf = {:e}: {}",
        sol.status,
        sol.stats.iterations,
        sol.objective,
        sol.constr_viol,
        sol.dual_inf,
        sol.message
    );
    assert!(
        sol.constr_viol <= CONSTR_VIOL_TOL,
        "{name}: constraint violation {:e} at the solution",
        sol.constr_viol
    );
    assert!(
        matched(&run, sol.objective).is_some(),
        "{name}: f = {:.12e}, published f* = {:.12e} (error {:.1e} > {:.0e}){}",
        sol.objective,
        run.f_star,
        objective_error(sol.objective, run.f_star),
        run.tol,
        if run.local.is_empty() {
            String::new()
        } else {
            format!(", nor a known local minimum {:?}", run.local)
        }
    );
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
    let mut iterations = Vec::new();
    let mut failed = Vec::new();
    for &(name, build) in SUITE {
        let run = run(name, build);
        let line = match &run.result {
            Ok(sol) => {
                let m = matched(&run, sol.objective);
                if sol.status == Status::SolveSucceeded
                    && m.is_some()
                    && sol.constr_viol <= CONSTR_VIOL_TOL
                {
                    iterations.push(sol.stats.iterations);
                } else {
                    failed.push(name);
                }
                serde_json::json!({
                    "name": run.name,
                    "status": sol.status,
                    "iterations": sol.stats.iterations,
                    "objective": sol.objective,
                    "f_star": run.f_star,
                    "matches": m,
                    "constr_viol": sol.constr_viol,
                    "seconds": run.solve_seconds,
                    "compile_seconds": run.compile_seconds,
                    "message": sol.message,
                })
            }
            Err(e) => {
                failed.push(name);
                serde_json::json!({
                    "name": run.name,
                    "status": "Error",
                    "error": e.to_string(),
                    "f_star": run.f_star,
                    "seconds": run.solve_seconds,
                    "compile_seconds": run.compile_seconds,
                })
            }
        };
        println!("{line}");
    }
    iterations.sort_unstable();
    let median = if iterations.is_empty() {
        f64::NAN
    } else {
        let n = iterations.len();
        if n % 2 == 1 {
            iterations[n / 2] as f64
        } else {
            (iterations[n / 2 - 1] + iterations[n / 2]) as f64 / 2.0
        }
    };
    eprintln!(
        "{} problems: {} solved, median iterations of the solved {median}; failed: {failed:?}",
        SUITE.len(),
        iterations.len()
    );
}

/// Prints the IPOPT-style iteration table of the problems named in the environment
/// variable `HS` (comma-separated), for diagnosing a failure:
///
/// ```text
/// HS=hs013,hs061 cargo test --release --test hs -- --ignored --nocapture hs_log
/// ```
#[test]
#[ignore = "diagnostics: run with HS=<names> --release --ignored --nocapture"]
fn hs_log() {
    let wanted = std::env::var("HS").unwrap_or_default();
    for name in wanted.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let &(name, build) = SUITE
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("no problem named {name}"));
        let case = build().unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut compiled = case
            .problem
            .compile()
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let options = IpmOptions {
            print_level: 5,
            ..IpmOptions::default()
        };
        println!("==== {name} (f* = {})", case.f_star);
        match Ipm::new(options).solve(&mut compiled) {
            Ok(sol) => println!(
                "{name}: {:?}, {} iterations, f = {:.12e}, x = {:?}",
                sol.status, sol.stats.iterations, sol.objective, sol.x
            ),
            Err(e) => println!("{name}: error {e}"),
        }
    }
}
