//! The Hock–Schittkowski suite with the limited-memory Hessian
//! (`hessian_approximation = limited-memory`, IPOPT's defaults: BFGS, 6 pairs, σ =
//! sᵀy/sᵀs), against IPOPT's own limited-memory mode.
//!
//! The reference numbers are IPOPT 3.14 via CasADi 3.8.2 on the same formulations
//! (`benches/reference/hs_lbfgs_ipopt.py`, stored in
//! `benches/reference/results/hs_lbfgs_ipopt.jsonl`). Success uses the criteria of
//! `tests/hs.rs` (status, published optimum to 1e-6, violation ≤ 1e-4).
//!
//! ```text
//! cargo test --release -p nlp --test lbfgs_hs -- --ignored --nocapture hs_lbfgs_summary \
//!     > benches/reference/results/hs_lbfgs_symnlp.jsonl
//! OPT=mu_strategy=monotone cargo test --release -p nlp --test lbfgs_hs -- --ignored --nocapture \
//!     hs_lbfgs_summary > benches/reference/results/hs_lbfgs_monotone_symnlp.jsonl
//! ```
use std::collections::HashMap;

use nlp::ipm::Ipm;
use nlp::{IpmHessian, IpmOptions, NamedOptions};

use testkit::hs::{harness, problems, SUITE};

use harness::Run;
use problems::Built;

fn lm_options() -> IpmOptions {
    IpmOptions {
        hessian_approximation: IpmHessian::LimitedMemory,
        ..IpmOptions::default()
    }
}

fn run(name: &'static str, build: fn() -> Built) -> Run {
    harness::run(name, build, |nlp| Ipm::new(lm_options()).solve(nlp))
}

/// As `run`, with the extra options `KEY=VALUE[,KEY=VALUE...]` given in the environment
/// variable `OPT` (e.g. `OPT=mu_strategy=monotone`, symnlp's limited-memory default
/// before s9-lbfgs).
fn run_with_env_option(name: &'static str, build: fn() -> Built) -> Run {
    let o = lm_options_with_env();
    harness::run(name, build, |nlp| Ipm::new(o).solve(nlp))
}

/// `lm_options` with the options of the environment variable `OPT`.
fn lm_options_with_env() -> IpmOptions {
    let mut o = lm_options();
    if let Ok(v) = std::env::var("OPT") {
        let kv: Vec<&str> = v.split(',').collect();
        o.set_by_name(&kv).expect("OPT=KEY=VALUE[,KEY=VALUE...]");
    }
    o
}

/// IPOPT's limited-memory results: name → (solved, iterations).
fn ipopt_results() -> HashMap<String, (bool, usize)> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../benches/reference/results/hs_lbfgs_ipopt.jsonl"
    );
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).expect("JSON line");
            (
                v["name"].as_str().expect("name").to_string(),
                (
                    v["success"].as_bool().expect("success"),
                    v["iterations"].as_u64().expect("iterations") as usize,
                ),
            )
        })
        .collect()
}

/// Solves every problem (each in a fresh thread, as `harness::summary` does); returns
/// name → iterations of the solved ones, and prints one line per problem.
fn solve_all() -> (Vec<(&'static str, Option<usize>)>, usize) {
    let mut out = Vec::new();
    let mut solved = 0;
    for &(name, build) in SUITE {
        let r = std::thread::spawn(move || run(name, build))
            .join()
            .expect("solve thread");
        let it = match &r.result {
            Ok(sol) if r.succeeded(sol) => {
                solved += 1;
                Some(sol.stats.iterations)
            }
            Ok(sol) => {
                eprintln!(
                    "{name}: not solved: {:?} after {} iterations, f = {:e}",
                    sol.status, sol.stats.iterations, sol.objective
                );
                None
            }
            Err(e) => {
                eprintln!("{name}: error {e}");
                None
            }
        };
        out.push((name, it));
    }
    (out, solved)
}

/// ≥ 90 % of the suite solved (the issue's target), and iterations within 1.5× of
/// IPOPT's limited-memory mode on every problem both solve (and in geometric mean).
#[test]
fn limited_memory_solves_hs_within_1_5x_of_ipopt() {
    let (runs, solved) = solve_all();
    let ipopt = ipopt_results();
    let mut log_ratio = 0.0;
    let mut both = 0usize;
    let mut above = Vec::new();
    for (name, it) in &runs {
        let (ok_i, it_i) = ipopt[*name];
        if let (Some(it), true) = (it, ok_i) {
            log_ratio += (*it as f64 / it_i as f64).ln();
            both += 1;
            if 2 * it > 3 * it_i {
                above.push(*name);
            }
        }
        eprintln!("{name}: symnlp {it:?}, IPOPT {it_i} (solved {ok_i})");
    }
    let geo = (log_ratio / both as f64).exp();
    eprintln!(
        "{solved}/{} solved; geometric mean of iteration ratios over {both}: {geo:.3}",
        runs.len()
    );
    assert!(
        solved * 10 >= runs.len() * 9,
        "{solved} of {} solved",
        runs.len()
    );
    assert!(geo <= 1.5, "geometric mean ratio {geo}");
    // Since the limited-memory default follows IPOPT (adaptive μ, quality-function
    // oracle) no problem is above 1.5× (hs100 was 63 vs 18, hs034 14 vs 8).
    assert!(above.is_empty(), "above 1.5x IPOPT's iterations: {above:?}");
}

/// One JSON line per problem (as `tests/hs.rs`'s `hs_summary`), for
/// `benches/reference/results/hs_lbfgs_symnlp.jsonl` (with `OPT` as in
/// `run_with_env_option`).
#[test]
#[ignore = "report: run with --release --ignored --nocapture"]
fn hs_lbfgs_summary() {
    harness::summary(SUITE, run_with_env_option);
}

/// The iteration table of the problems named in `HS` (comma-separated), for comparing
/// with IPOPT's log (`print_level` 5):
///
/// ```text
/// HS=hs034 cargo test --release -p nlp --test lbfgs_hs -- --ignored --nocapture hs_lbfgs_log
/// ```
#[test]
#[ignore = "diagnostics: run with HS=<names> --release --ignored --nocapture"]
fn hs_lbfgs_log() {
    for name in harness::names_from_env() {
        let (name, build) = harness::find(SUITE, &name);
        let r = harness::run(name, build, |nlp| {
            let mut o = lm_options_with_env();
            o.common.print_level = 5;
            Ipm::new(o).solve(nlp)
        });
        if let Ok(sol) = &r.result {
            println!(
                "{name}: {:?}, {} iterations",
                sol.status, sol.stats.iterations
            );
        }
    }
}
