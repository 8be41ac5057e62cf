//! Complementarity constraints (`Problem::complementarity`) solved by both back ends
//! through the MPCC driver [`nlp::solve_mpcc`]: the SQP on Fletcher & Leyffer's NLP form
//! (products as constraints, elastic mode), the IPM on the ℓ1 penalty form with π updates
//! (Leyffer, López-Calva & Nocedal 2006), each followed by the exact final phase.
//!
//! Problems of MacMPEC (S. Leyffer's collection of MPCCs in AMPL, Argonne; the f* are the
//! values of its table, also reported by Fletcher & Leyffer 2004, Optim. Methods Softw.
//! 19(1):15–40, Table 1) and small problems derived by hand. Every case asserts, per back
//! end, either success — objective within 1e-6 relative (absolute when f* = 0) of f*, or
//! to the published digits (outrata31: 1e-4) —
//! and complementarity residual ≤ 1e-8 — or its listed known failure (the failure is
//! asserted, so a change of behaviour fails the test).
use nlp::{solve_mpcc, MpccBackend, MpccOptions, MpccSolution};

use testkit::mpcc as problems;
use testkit::mpcc_names;

use problems::Case;

fn objective_error(f: f64, f_star: f64) -> f64 {
    (f - f_star).abs() / f_star.abs().max(1.0)
}

pub fn solved(case: &Case, s: &MpccSolution) -> bool {
    s.solution.status.is_success()
        && objective_error(s.solution.objective, case.f_star) <= case.f_tol
        && s.report.residual <= 1e-8
}

fn check(case: Case, backend: MpccBackend) {
    let pb = (case.build)();
    let s = solve_mpcc(&pb, backend, &MpccOptions::default())
        .unwrap_or_else(|e| panic!("{}: {backend:?}: {e}", case.name));
    let ok = solved(&case, &s);
    let known = case.known_failures.iter().find(|(b, _)| *b == backend);
    let detail = format!(
        "{} ({}) {backend:?}: status {:?}, f = {:.10e} (f* = {}), residual {:.1e}, biactive {:?}, phases {:?}",
        case.name,
        case.source,
        s.solution.status,
        s.solution.objective,
        case.f_star,
        s.report.residual,
        s.report.biactive,
        s.phases
    );
    match known {
        None => assert!(ok, "{detail}"),
        Some((_, why)) => assert!(
            !ok,
            "{detail}: listed as a known failure ({why}) but now solved: update the list"
        ),
    }
}

macro_rules! mpcc_tests {
    ($($name:ident),* $(,)?) => {
        mod sqp { $( #[test] fn $name() { super::check(super::problems::$name(), super::MpccBackend::Sqp); } )* }
        mod ipm { $( #[test] fn $name() { super::check(super::problems::$name(), super::MpccBackend::Ipm); } )* }
        /// Every case, for the summary.
        pub const ALL: &[fn() -> Case] = &[$(problems::$name),*];
    };
}

mpcc_names!(mpcc_tests);

/// One JSON line per case and back end (for docs/performance.md):
/// `cargo test --release -p nlp --test mpcc -- --ignored --nocapture mpcc_summary`.
#[test]
#[ignore = "report: run with --release --ignored --nocapture"]
fn mpcc_summary() {
    for case in ALL.iter().map(|c| c()) {
        for backend in [MpccBackend::Sqp, MpccBackend::Ipm] {
            let pb = (case.build)();
            let s = solve_mpcc(&pb, backend, &MpccOptions::default()).unwrap();
            println!(
                "{}",
                serde_json::json!({
                    "name": case.name, "backend": format!("{backend:?}"),
                    "status": s.solution.status, "objective": s.solution.objective,
                    "f_star": case.f_star, "residual": s.report.residual,
                    "biactive": s.report.biactive, "iterations": s.iterations,
                    "seconds": s.seconds, "solved": solved(&case, &s),
                    "phases": s.phases.iter().map(|p| format!("{}:{:?}:{}", p.kind, p.status, p.iterations)).collect::<Vec<_>>(),
                })
            );
        }
    }
}

/// Iteration tables of one case (`MPCC=<name> BACKEND=sqp|ipm`).
#[test]
#[ignore = "diagnostics: run with MPCC=<name> --release --ignored --nocapture"]
fn mpcc_log() {
    let wanted = std::env::var("MPCC").unwrap_or_default();
    let backend = match std::env::var("BACKEND").as_deref() {
        Ok("ipm") => MpccBackend::Ipm,
        _ => MpccBackend::Sqp,
    };
    for case in ALL.iter().map(|c| c()).filter(|c| c.name == wanted) {
        let mut o = MpccOptions::default();
        o.sqp.print_level = 5;
        o.ipm.print_level = 5;
        let s = solve_mpcc(&(case.build)(), backend, &o).unwrap();
        println!("{:?}\n{:?}", s.phases, s.report);
    }
}

/// One budget over all phases (issue 23 item 6): dempe's SQP main phase does not converge
/// (it runs to its own 3000 iterations; golden record mpcc/sqp/dempe), so a run budget of
/// 500 ends inside it: no final phase starts, the status says the limit was hit, and the
/// summary says the run's budget was spent. (ralph1 served until its SQP phase converged,
/// issue 19 s17: 19 iterations.)
#[test]
fn one_budget_bounds_every_phase() {
    let case = problems::dempe();
    let mut o = MpccOptions {
        max_iter: 500,
        ..MpccOptions::default()
    };
    let s = solve_mpcc(&(case.build)(), MpccBackend::Sqp, &o).unwrap();
    assert_eq!(s.phases.len(), 1, "{}", s.summary());
    assert_eq!(s.iterations, 500);
    assert_eq!(s.solution.status, nlp::Status::MaximumIterationsExceeded);
    assert!(s.budget_exhausted && s.rescue.is_none());
    assert!(
        s.summary().contains("budget of 500 iterations"),
        "{}",
        s.summary()
    );

    // The IPM's penalty phases share the budget the same way: qpec2 takes 132 iterations
    // over its phases with the default budget (golden record); 40 stops it in the
    // penalty loop, with every phase's iterations counted.
    let case = problems::qpec2();
    o.max_iter = 40;
    let s = solve_mpcc(&(case.build)(), MpccBackend::Ipm, &o).unwrap();
    assert!(s.budget_exhausted, "{}", s.summary());
    assert!(s.iterations <= 40, "{}", s.summary());
    assert_eq!(
        s.iterations,
        s.phases.iter().map(|p| p.iterations).sum::<usize>()
    );
    assert!(s.phases.iter().all(|p| p.kind == "penalty"));
}

/// A rescue is reported, not hidden behind the final status: dempe's SQP phase stops at
/// `MaximumIterationsExceeded` (3000 iterations) and the exact final phase solves the
/// branch problem from its point (to the acceptable level at f = 28.25000008, MacMPEC's
/// infimum 28.25, asserted by `dempe` above). (ralph1 served until its SQP phase
/// converged, issue 19 s17.)
#[test]
fn a_rescue_by_the_final_phase_is_reported() {
    let case = problems::dempe();
    let s = solve_mpcc(&(case.build)(), MpccBackend::Sqp, &MpccOptions::default()).unwrap();
    let rescue = s.rescue.expect("the final phase rescued the sqp phase");
    assert_eq!(rescue.failed_phase, 0);
    assert_eq!(rescue.failed_status, nlp::Status::MaximumIterationsExceeded);
    assert_eq!(s.phases[rescue.rescued_by].kind, "final");
    assert!(s.solution.status.is_success() && !s.budget_exhausted);
    assert!(
        s.summary()
            .ends_with("the final phase rescued a failed sqp phase (MaximumIterationsExceeded)"),
        "{}",
        s.summary()
    );
    // A run whose main phase converges has no rescue (bard1: sqp 3, final 1).
    let case = problems::bard1();
    let s = solve_mpcc(&(case.build)(), MpccBackend::Sqp, &MpccOptions::default()).unwrap();
    assert!(
        s.rescue.is_none() && s.solution.status.is_success(),
        "{}",
        s.summary()
    );
}

/// Bad driver options are refused by name before any solve; names are set like a back
/// end's, with a prefix for the back ends'.
#[test]
fn driver_options_are_checked_and_set_by_name() {
    let pb = (problems::bard1().build)();
    let o = MpccOptions {
        penalty_increase: 1.0,
        ..MpccOptions::default()
    };
    let err = solve_mpcc(&pb, MpccBackend::Ipm, &o)
        .unwrap_err()
        .to_string();
    assert!(err.contains("penalty_increase"), "{err}");

    let mut o = MpccOptions::default();
    o.set_options_by_name(&["max_iter=7", "ipm.max_iter=5", "sqp.tol=1e-9"])
        .unwrap();
    assert_eq!((o.max_iter, o.ipm.max_iter, o.sqp.tol), (7, 5, 1e-9));
    let before = o.clone();
    let err = o
        .set_options_by_name(&["penalty_init=5", "ipm.mu_innit=1"])
        .unwrap_err()
        .to_string();
    assert!(err.contains("mu_init"), "{err}");
    assert_eq!(o, before, "a refused assignment list changes nothing");
    let err = o
        .set_options_by_name(&["max_iter=0"])
        .unwrap_err()
        .to_string();
    assert!(err.contains("max_iter"), "{err}");
}
