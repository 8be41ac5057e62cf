//! The Hock–Schittkowski suite solved by the SQP back end ([`nlp::Sqp`]) with default
//! options: the same problems (`hs/problems.rs`) and the same assertions as `tests/hs.rs`
//! (status `SolveSucceeded`, published f* to the problem's tolerance or a documented
//! local minimiser, final constraint violation ≤ 1e-4).
//!
//! `sqp_hs_summary` (ignored) prints one JSON line per problem for docs/performance.md:
//!
//! ```text
//! cargo test --release --test sqp_hs -- --ignored --nocapture sqp_hs_summary
//! ```
use std::time::Instant;

use symnlp::nlp;

use nlp::{Solution, SolveError, Sqp, SqpOptions, Status};

#[path = "hs/problems.rs"]
#[allow(dead_code)]
mod problems;

use problems::Built;

/// The registry and one test per problem (the list of `tests/hs.rs`).
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
    hs001, hs002, hs003, hs004, hs005, hs025, hs038, hs045, hs110,
    hs006, hs007, hs008, hs009, hs026, hs027, hs028, hs039, hs040, hs042, hs046, hs047,
    hs048, hs049, hs050, hs051, hs052, hs053, hs056, hs061, hs077, hs078, hs079,
    hs010, hs011, hs012, hs013, hs014, hs015, hs016, hs017, hs018, hs019, hs020, hs021,
    hs022, hs023, hs024, hs029, hs030, hs031, hs032, hs033, hs034, hs035, hs036, hs037,
    hs043, hs044, hs064, hs065, hs066, hs076, hs100, hs113,
    hs071, hs073, hs080, hs081, hs106, hs108, hs114, hs116, hs118,
}

const CONSTR_VIOL_TOL: f64 = 1e-4;

/// Problems the SQP back end does not solve yet with default options: (name, the status
/// it returns now, why). Their tests are honest known failures: they assert exactly this
/// status and that the run is *not* a success by the criteria of the other problems, so
/// a change of behaviour (better or worse) fails the test and the list must be updated.
/// The IPM solves all of them (`tests/hs.rs`).
const KNOWN_FAILURES: &[(&str, Status, &str)] = &[
    // No KKT point at the solution (degenerate constraints); f = 0.99837 ≈ f* but the
    // dual error never reaches tol.
    (
        "hs013",
        Status::SolvedToAcceptableLevel,
        "no KKT point at the solution",
    ),
    // The start x = (-2, 1) is clipped to the bound x1 <= 0.5 and SQP converges to the
    // KKT point f = 23.1447, not the global 0.25.
    (
        "hs016",
        Status::SolveSucceeded,
        "other local KKT point f = 23.1447",
    ),
    // Badly scaled (x up to 5000). With the individual merit weights (Powell 1978) the
    // iterates stall at f ≈ 2100 (infeasible) within 3000 iterations; before them the
    // shifted Hessian reached f* at a linear rate (SolvedToAcceptableLevel).
    (
        "hs106",
        Status::MaximumIterationsExceeded,
        "badly scaled, stalls with individual merit weights",
    ),
    // Reaches f* = 97.5875 (violation 1e-13) but stops at the acceptable level: dual
    // error 2.7e-7 after 365 iterations; the merit's rounding allowance (which lets the
    // gap-crossing planner finish) also accepts its noise-level steps.
    (
        "hs116",
        Status::SolvedToAcceptableLevel,
        "f* reached, dual error stalls at 3e-7",
    ),
];

/// Problems observed with two outcomes between runs of the same binary: the listed
/// failure, or a full success. The cause is not isolated yet (suspected: rounding of the
/// parallel faer factorisation behind the inertia test of the Hessian convexification,
/// which picks δ and ρ_a). Their tests accept exactly these two outcomes, nothing else.
const UNSTABLE: &[(&str, Status, &str)] = &[
    (
        "hs056",
        Status::ErrorInStepComputation,
        "clarabel InsufficientProgress at iteration 7",
    ),
    (
        "hs061",
        Status::MaximumIterationsExceeded,
        "line search stalls at f = -121.35",
    ),
    (
        "hs078",
        Status::SolvedToAcceptableLevel,
        "final steps cut by the merit test",
    ),
];

struct Run {
    f_star: f64,
    local: &'static [f64],
    tol: f64,
    seconds: f64,
    result: Result<Solution, SolveError>,
}

fn run(name: &str, build: fn() -> Built, print_level: u8) -> Run {
    let case = build().unwrap_or_else(|e| panic!("{name}: building the problem failed: {e}"));
    let mut compiled = case
        .problem
        .compile()
        .unwrap_or_else(|e| panic!("{name}: compile failed: {e}"));
    let t = Instant::now();
    let result = Sqp::new(SqpOptions {
        print_level,
        ..SqpOptions::default()
    })
    .solve(&mut compiled);
    Run {
        f_star: case.f_star,
        local: case.local,
        tol: case.tol,
        seconds: t.elapsed().as_secs_f64(),
        result,
    }
}

fn objective_error(f: f64, f_star: f64) -> f64 {
    if f_star == 0.0 {
        f.abs()
    } else {
        (f - f_star).abs() / f_star.abs()
    }
}

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
    let run = run(name, build, 0);
    let sol = match &run.result {
        Ok(sol) => sol,
        Err(e) => panic!("{name}: solve error: {e}"),
    };
    let success = sol.status == Status::SolveSucceeded
        && sol.constr_viol <= CONSTR_VIOL_TOL
        && matched(&run, sol.objective).is_some();
    if let Some((_, failure, why)) = UNSTABLE.iter().find(|(n, _, _)| *n == name) {
        assert!(
            success || sol.status == *failure,
            "{name}: unstable case ({why}) has a third outcome: {:?}, f = {}; update UNSTABLE",
            sol.status,
            sol.objective
        );
        return;
    }
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
        "{name}: constraint violation {:e}",
        sol.constr_viol
    );
    assert!(
        matched(&run, sol.objective).is_some(),
        "{name}: f = {:.12e}, published f* = {:.12e} (error {:.1e} > {:.0e}), local {:?}",
        sol.objective,
        run.f_star,
        objective_error(sol.objective, run.f_star),
        run.tol,
        run.local
    );
}

/// One JSON line per problem and a summary on stderr.
#[test]
#[ignore = "report for docs/performance.md: run with --release --ignored --nocapture"]
fn sqp_hs_summary() {
    let mut iterations = Vec::new();
    let mut failed = Vec::new();
    let mut total = 0.0;
    for &(name, build) in SUITE {
        // A fresh thread per problem, as each `#[test]` runs: symx's expression arena is
        // per thread, and the node order (hence the sparsity orderings and the rounding)
        // of a problem built after others differs, which changes some SQP runs.
        let run = std::thread::spawn(move || run(name, build, 0))
            .join()
            .expect("solve thread");
        total += run.seconds;
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
                    "name": name, "status": sol.status, "iterations": sol.stats.iterations,
                    "objective": sol.objective, "f_star": run.f_star, "matches": m,
                    "constr_viol": sol.constr_viol, "seconds": run.seconds, "message": sol.message,
                })
            }
            Err(e) => {
                failed.push(name);
                serde_json::json!({"name": name, "status": "Error", "error": e.to_string()})
            }
        };
        println!("{line}");
    }
    iterations.sort_unstable();
    let median = if iterations.is_empty() {
        f64::NAN
    } else {
        iterations[iterations.len() / 2] as f64
    };
    eprintln!(
        "{} problems: {} solved, median iterations {median}, total iterations {}, total seconds {total:.3}; failed: {failed:?}",
        SUITE.len(),
        iterations.len(),
        iterations.iter().sum::<usize>()
    );
}

/// Iteration tables of the problems named in `HS` (comma-separated).
#[test]
#[ignore = "diagnostics: run with HS=<names> --release --ignored --nocapture"]
fn sqp_hs_log() {
    let wanted = std::env::var("HS").unwrap_or_default();
    for name in wanted.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let &(name, build) = SUITE
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("no problem {name}"));
        println!("==== {name}");
        let run = run(name, build, 5);
        if let Ok(sol) = &run.result {
            println!(
                "{:?} f = {} (f* = {}) {}",
                sol.status, sol.objective, run.f_star, sol.message
            );
        }
    }
}
