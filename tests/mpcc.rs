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
use symnlp::nlp;

use nlp::{solve_mpcc, MpccBackend, MpccOptions, MpccSolution};

#[path = "mpcc/problems.rs"]
#[macro_use]
mod problems;

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
/// `cargo test --release --test mpcc -- --ignored --nocapture mpcc_summary`.
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
