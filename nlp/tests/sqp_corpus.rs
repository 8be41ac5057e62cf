//! The cold SQP against the IPM on the corpus's optimal-control set (issue 19's target:
//! solved as often as the IPM, total time ≤ 1.5× the IPM's): the smallest instance of
//! every optimal-control family (`corpus/tests/smallest.rs` checks the IPM there against
//! IPOPT), both back ends with default options from the instance's own guess (the SQP's
//! default starts from the IPM's solution, `cold_start_ipm`; its time includes the
//! IPM's). A report, not an assertion of the target: one JSON line per instance and a
//! total. `COLD_START_IPM=0` runs the SQP alone (it solves 11 of the 15).
//!
//! ```text
//! cargo test --release --workspace --test sqp_corpus -- --ignored --nocapture cold_ocp_set
//! ```
use std::time::Instant;

use nlp::{Ipm, Solver, Sqp, SqpOptions};
use testkit::corpus::{self, Kind};

#[test]
#[ignore = "report (minutes): cargo test --release -p nlp --test sqp_corpus -- --ignored --nocapture"]
fn cold_ocp_set_sqp_against_ipm() {
    let max_wall = std::env::var("MAX_WALL")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60.0);
    let mut sqp_options = SqpOptions::default();
    sqp_options.common.max_wall_time = max_wall;
    sqp_options.cold_start_ipm = std::env::var("COLD_START_IPM").map_or(true, |v| v != "0");
    let sqp = Sqp::new(sqp_options);
    let mut ipm = Ipm::default();
    ipm.options.common.max_wall_time = max_wall;
    let solvers: [(&str, &dyn Solver); 2] = [("ipm", &ipm), ("sqp", &sqp)];
    let mut totals = [(0usize, 0.0f64); 2];
    for family in corpus::families() {
        if family.kind != Kind::Ocp {
            continue;
        }
        let inst = corpus::Instance {
            family,
            size: family.sizes[0],
        };
        let mut c = inst.build().unwrap().compile().unwrap();
        for (k, (name, solver)) in solvers.iter().enumerate() {
            let t = Instant::now();
            let sol = solver.solve_dyn(&mut c, None, None).unwrap();
            let secs = t.elapsed().as_secs_f64();
            totals[k].0 += usize::from(sol.status.is_success());
            totals[k].1 += secs;
            println!(
                "{{\"instance\":\"{}\",\"solver\":\"{name}\",\"status\":\"{:?}\",\"iterations\":{},\"objective\":{:e},\"seconds\":{secs:.4}}}",
                inst.name(),
                sol.status,
                sol.stats.iterations,
                sol.objective
            );
        }
    }
    println!(
        "total: ipm solved {} in {:.3} s, sqp solved {} in {:.3} s",
        totals[0].0, totals[0].1, totals[1].0, totals[1].1
    );
}

/// One instance of the set (`INSTANCE`, e.g. `glider_trap_100`) solved by the SQP, cold
/// or (`WARM_FROM_IPM=1`) from the IPM's solution, with its iteration log (`SQP_PRINT`, default 5) and a wall-time cap (`MAX_WALL`, default
/// 10 s): the diagnostics behind the notebook's causes of the failures.
#[test]
#[ignore = "diagnostics: INSTANCE=glider_trap_100 cargo test --release --workspace --test sqp_corpus -- --ignored --nocapture one_instance_log"]
fn one_instance_log() {
    let env = |k: &str| std::env::var(k).ok();
    let name = env("INSTANCE").unwrap_or_else(|| "glider_trap_100".into());
    let mut o = SqpOptions {
        cold_start_ipm: false,
        ..SqpOptions::default()
    };
    o.common.max_wall_time = env("MAX_WALL").and_then(|s| s.parse().ok()).unwrap_or(10.0);
    o.common.print_level = env("SQP_PRINT").and_then(|s| s.parse().ok()).unwrap_or(5);
    let inst = corpus::instance(&name).expect("INSTANCE names a corpus instance");
    let mut c = inst.build().unwrap().compile().unwrap();
    // `WARM_FROM_IPM=1`: the SQP started from the IPM's solution (x and multipliers).
    let warm = env("WARM_FROM_IPM").map(|_| {
        let ipm = Ipm::default().solve_dyn(&mut c, None, None).unwrap();
        println!(
            "ipm: {:?} after {} iterations",
            ipm.status, ipm.stats.iterations
        );
        ipm
    });
    let t = Instant::now();
    let sol = Sqp::new(o).solve_dyn(&mut c, warm.as_ref(), None).unwrap();
    println!(
        "{}: {:?} after {} iterations, {} QPs, f = {:e}, {:.3} s",
        inst.name(),
        sol.status,
        sol.stats.iterations,
        sol.stats.n_qp_solves,
        sol.objective,
        t.elapsed().as_secs_f64()
    );
}
