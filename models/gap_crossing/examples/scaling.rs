//! Scaling of the crawl-gait solve with the number of stances, measured once per size.
//!
//! ```text
//! cargo run --release -p gap_crossing --example scaling -- [N ...] [--set KEY=VALUE ...]
//! ```
//!
//! For each `n_step` (default 30 60 120 240 480) on the default scenario (gap terrain,
//! goals 3 m ahead) with the overrides applied: guess + build + compile, then one solve
//! with symnlp's interior-point method (default options, tol 1e-8). Prints one JSON object
//! per line: size, status, iterations, objective, and where the time went.
use gap_crossing::export;
use gap_crossing::scenario::Scenario;
use gap_crossing::solve::status_name;
use nlp::{Ipm, IpmOptions, NumericNlp};
use serde_json::json;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut sizes: Vec<usize> = Vec::new();
    let mut overrides: Vec<String> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--set" {
            overrides.push(args.next().ok_or("--set needs KEY=VALUE")?);
        } else {
            sizes.push(a.parse()?);
        }
    }
    if sizes.is_empty() {
        sizes = vec![30, 60, 120, 240, 480];
    }
    for n in sizes {
        let mut s = Scenario::default();
        s.apply_overrides(&overrides)?;
        s.n_step = n;
        s.validate()?;
        let t0 = Instant::now();
        let (model, mut compiled) = export::crawl_model(&s)?;
        let t1 = Instant::now();
        let sol = Ipm::new(IpmOptions::default()).solve(&mut compiled)?;
        let t2 = Instant::now();
        drop(model);
        let st = &sol.stats;
        let line = json!({
            "n_step": n,
            "n": compiled.n(),
            "m": compiled.m(),
            "status": status_name(sol.status),
            "iterations": st.iterations,
            "objective": sol.objective,
            "constr_viol": sol.constr_viol,
            "build_compile_s": (t1 - t0).as_secs_f64(),
            "solve_s": (t2 - t1).as_secs_f64(),
            "eval_s": st.eval_seconds,
            "factor_s": st.factor_seconds,
            "other_s": st.other_seconds,
            "factorizations": st.n_factorizations,
        });
        println!("{line}");
    }
    Ok(())
}
