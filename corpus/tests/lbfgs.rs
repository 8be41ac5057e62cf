//! The limited-memory Hessian (`hessian_approximation = limited-memory`) on the smallest
//! instance of every optimal-control family, against the exact Hessian and against
//! IPOPT's limited-memory mode on the same exported formulation
//! (`benches/reference/corpus_lbfgs_ipopt.py`, results in
//! `benches/reference/results/corpus_lbfgs.jsonl`).
//!
//! ```text
//! cargo test --release -p corpus --test lbfgs -- --ignored --nocapture lbfgs_report
//! ```
use corpus::{ocp, run, Instance};
use nlp::{IpmHessian, IpmOptions};

fn lm_options(max_wall: f64) -> IpmOptions {
    IpmOptions {
        hessian_approximation: IpmHessian::LimitedMemory,
        ..run::options(max_wall)
    }
}

/// (instance, IPOPT 3.14 exact-Hessian objective (tests/smallest.rs), IPOPT
/// limited-memory iterations on the same formulation
/// (benches/reference/results/corpus_lbfgs_ipopt.jsonl)). The instances where symnlp is
/// within 1.5× of IPOPT; the others are listed in docs/solvers.md.
const CASES: &[(&str, f64, usize)] = &[
    ("robot_trap_200", 9.141396951323673, 22),
    ("vdp_rk4_20", 3.7324355529062423, 11),
    ("vdp_trap_50", 3.6734170050089268, 17),
    ("cartpole_rk4_50", 59.13194620767747, 28),
];

/// Solved, at IPOPT's exact-Hessian optimum to 1e-6 relative (the issue's criterion), in
/// at most 1.5× IPOPT's limited-memory iterations (the issue's target).
#[test]
fn limited_memory_solves_small_ocps_like_ipopt() {
    for &(name, f_ipopt, it_ipopt) in CASES {
        let inst = corpus::instance(name).expect("instance exists");
        let out = run::solve(&inst, &lm_options(120.0)).expect("solves");
        assert!(out.success, "{name}: {}", out.status);
        let gap = (out.objective - f_ipopt) / f_ipopt.abs().max(1.0);
        assert!(gap.abs() < 1e-6, "{name}: f = {:.12e}", out.objective);
        eprintln!("{name}: {} iterations (IPOPT {it_ipopt})", out.iterations);
        assert!(
            2 * out.iterations <= 3 * it_ipopt,
            "{name}: {} iterations",
            out.iterations
        );
    }
}

/// One JSON line per smallest OCP instance: exact and limited-memory outcomes.
#[test]
#[ignore = "report: run with --release --ignored --nocapture"]
fn lbfgs_report() {
    for family in ocp::FAMILIES {
        let inst = Instance {
            family,
            size: family.sizes[0],
        };
        let exact = run::solve(&inst, &run::options(300.0)).expect("exact solve");
        let lm = run::solve(&inst, &lm_options(300.0)).expect("limited-memory solve");
        println!(
            "{}",
            serde_json::json!({
                "instance": inst.name(),
                "n": exact.n,
                "m": exact.m,
                "exact": {"status": exact.status, "iterations": exact.iterations,
                          "objective": exact.objective, "solve_s": exact.solve_s},
                "limited_memory": {"status": lm.status, "iterations": lm.iterations,
                          "restoration_iterations": lm.restoration_iterations,
                          "objective": lm.objective, "solve_s": lm.solve_s},
            })
        );
    }
}
