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
/// (benches/reference/results/corpus_lbfgs_ipopt.jsonl)): the twelve instances IPOPT's
/// limited-memory mode solves (rocket and glider end at max_iter in both; see
/// docs/solvers.md).
const CASES: &[(&str, f64, usize)] = &[
    ("steering_trap_200", 0.5545770161030464, 57),
    ("channel_colloc_100", 1.0, 5),
    ("pinene_colloc_100", 19.872170145335872, 15),
    ("race_car_rk4_100", 1.9046342735147384, 29),
    ("arm2_trap_50", 3.915687197194579, 25),
    ("robot_trap_200", 9.141396951323673, 22),
    ("catmix_colloc_100", -0.04805538299701119, 115),
    ("vdp_rk4_20", 3.7324355529062423, 11),
    ("vdp_trap_50", 3.6734170050089268, 17),
    ("cartpole_trap_50", 59.14775732337834, 32),
    ("cartpole_rk4_50", 59.13194620767747, 28),
    ("quadrotor_rk4_50", 194.8824168265576, 28),
];

/// IPOPT's `recalc_y` (on by default with the limited-memory Hessian): least-squares
/// multipliers after every step with constraint violation below `recalc_y_feas_tol`.
/// With monotone μ (set explicitly: the limited-memory default is adaptive μ since
/// s9-lbfgs, with which quadrotor_rk4_50 takes 22 iterations with and 26 without
/// `recalc_y`), quadrotor_rk4_50 took 421 iterations without it until session 18 (IPOPT's
/// limited-memory mode 28, benches/reference/results/corpus_lbfgs_ipopt.jsonl); since
/// `residual_ratio_floor` = 1e-13 (refinement of the low-rank KKT solves stops at 1e-13
/// instead of 1e-14) it takes 32 without it. With it or without it, at most 1.5× IPOPT's.
/// Set by name as IPOPT spells it.
#[test]
fn recalc_y_by_name_and_quadrotor_near_ipopt() {
    use nlp::NamedOptions;
    let inst = corpus::instance("quadrotor_rk4_50").expect("instance exists");
    let mut off = lm_options(120.0);
    off.set_by_name(&["recalc_y=no", "mu_strategy=monotone"])
        .unwrap();
    assert_eq!(off.recalc_y, Some(false));
    let mut on = lm_options(120.0);
    on.set_by_name(&[
        "recalc_y=yes",
        "recalc_y_feas_tol=1e-6",
        "mu_strategy=monotone",
    ])
    .unwrap();
    let mut default = lm_options(120.0);
    default.set_by_name(&["mu_strategy=monotone"]).unwrap();
    let off = run::solve(&inst, &off).expect("solves");
    let on_out = run::solve(&inst, &on).expect("solves");
    let default = run::solve(&inst, &default).expect("solves");
    assert!(on_out.success && off.success);
    assert_eq!(
        on_out.iterations, default.iterations,
        "default = on with limited memory"
    );
    assert!(
        2 * on_out.iterations <= 3 * 28,
        "{} iterations",
        on_out.iterations
    );
    assert!(
        2 * off.iterations <= 3 * 28,
        "off: {} (on: {})",
        off.iterations,
        on_out.iterations
    );
    // Never with the exact Hessian unless asked for.
    let exact = run::solve(&inst, &run::options(120.0)).expect("solves");
    assert_eq!(exact.iterations, 12);
}

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

/// One instance (`INST`) in limited-memory mode with extra options
/// `OPT=KEY=VALUE[,KEY=VALUE...]`: status and iterations, for diagnosis.
#[test]
#[ignore = "diagnostics: INST=<name> [OPT=...] --release --ignored --nocapture"]
fn lbfgs_one() {
    use nlp::NamedOptions;
    let name = std::env::var("INST").expect("INST=<instance>");
    let inst = corpus::instance(&name).expect("instance exists");
    let mut o = lm_options(300.0);
    if let Ok(v) = std::env::var("OPT") {
        let kv: Vec<&str> = v.split(',').collect();
        o.set_by_name(&kv).expect("OPT=KEY=VALUE[,KEY=VALUE...]");
    }
    let out = run::solve(&inst, &o).expect("solves");
    println!(
        "{name}: {} {} iterations, f = {:e}",
        out.status, out.iterations, out.objective
    );
}
