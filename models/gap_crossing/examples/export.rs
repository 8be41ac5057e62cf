//! Dumps the crawl-gait problem as JSON for `benches/reference/gap_crossing_casadi.py`,
//! optionally timing symnlp's own solve of the same problem in the same run.
//!
//! ```text
//! cargo run --release -p gap_crossing --example export -- \
//!     --set n_step=60 --set gap.depth=0 [--solve] [--repeat 3] [--out dump.json]
//! ```
//!
//! - `--set KEY=VALUE`: scenario overrides (as the CLI's `--set`); defaults are the spec's
//!   default scenario, whose goals (B 0 → 3 m, F 2 → 5 m in x) are 3 m ahead of the start.
//! - `--solve`: also solve with symnlp's interior-point method (default options, tol 1e-8)
//!   `--repeat` times, each time from scratch (guess, build, compile, solve), and add a
//!   `symnlp` object with the timings to the output.
//! - `--out FILE`: write there instead of standard output.
//!
//! Before writing, every printed expression is parsed back ([`symx::parse`]) and evaluated
//! at the initial point; the example fails if that differs from the compiled problem.
use gap_crossing::export::{self, NlpDump};
use gap_crossing::solve::status_name;
use nlp::{Ipm, IpmOptions, NumericNlp};
use serde_json::{json, Value};
use std::time::Instant;

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let k = s.len();
    if k % 2 == 1 {
        s[k / 2]
    } else {
        (s[k / 2 - 1] + s[k / 2]) / 2.0
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut overrides: Vec<String> = Vec::new();
    let mut solve = false;
    let mut repeat = 1usize;
    let mut out: Option<String> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--set" => overrides.push(args.next().ok_or("--set needs KEY=VALUE")?),
            "--solve" => solve = true,
            "--repeat" => repeat = args.next().ok_or("--repeat needs a number")?.parse()?,
            "--out" => out = Some(args.next().ok_or("--out needs a file")?),
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    let mut s = gap_crossing::scenario::Scenario::default();
    s.apply_overrides(&overrides)?;
    s.validate()?;

    let t = Instant::now();
    let (model, mut compiled) = export::crawl_model(&s)?;
    let build_compile_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let d: NlpDump = export::dump(&s, &model, &mut compiled);
    let dump_s = t.elapsed().as_secs_f64();
    let v = d.problem.verify()?;
    let tol = 1e-9 * (1.0 + d.problem.f0.abs());
    if v.objective_error > tol || v.constraint_error > 1e-9 {
        return Err(format!("parsed expressions disagree with the compiled problem: {v:?}").into());
    }
    eprintln!(
        "n {} m {}, f(x0) = {:.12e}; parse-back check: |Δf| {:.1e}, max |Δg| {:.1e}",
        d.problem.n, d.problem.m, d.problem.f0, v.objective_error, v.constraint_error
    );
    let mut value = serde_json::to_value(&d)?;
    value["verification"] = serde_json::to_value(v)?;
    value["export_seconds"] = json!({ "build_compile": build_compile_s, "dump": dump_s });

    if solve {
        let mut runs: Vec<Value> = Vec::new();
        let (mut total, mut solve_only) = (Vec::new(), Vec::new());
        for _ in 0..repeat.max(1) {
            // A fresh thread has a fresh (empty) expression graph, as a new program would.
            let sc = s.clone();
            let (sol, n, m, build, slv) = std::thread::spawn(move || {
                let t0 = Instant::now();
                let (model, mut compiled) = export::crawl_model(&sc).map_err(|e| e.to_string())?;
                let t1 = Instant::now();
                let sol = Ipm::new(IpmOptions::default())
                    .solve(&mut compiled)
                    .map_err(|e| e.to_string())?;
                let t2 = Instant::now();
                drop(model);
                Ok::<_, String>((
                    sol,
                    compiled.n(),
                    compiled.m(),
                    (t1 - t0).as_secs_f64(),
                    (t2 - t1).as_secs_f64(),
                ))
            })
            .join()
            .map_err(|_| "solver thread panicked")??;
            total.push(build + slv);
            solve_only.push(slv);
            eprintln!(
                "symnlp: {} in {} iterations, f = {:.12e}; build+compile {:.3} s, solve {:.3} s",
                status_name(sol.status),
                sol.stats.iterations,
                sol.objective,
                build,
                slv
            );
            runs.push(json!({
                "status": status_name(sol.status),
                "iterations": sol.stats.iterations,
                "objective": sol.objective,
                "constr_viol": sol.constr_viol,
                "build_compile_s": build,
                "solve_s": slv,
                "total_s": build + slv,
                "eval_s": sol.stats.eval_seconds,
                "factor_s": sol.stats.factor_seconds,
                "other_s": sol.stats.other_seconds,
                "factorizations": sol.stats.n_factorizations,
                "n": n,
                "m": m,
            }));
        }
        value["symnlp"] = json!({
            "runs": runs,
            "solve_s_median": median(&solve_only),
            "total_s_median": median(&total),
        });
    }

    let text = serde_json::to_string(&value)?;
    match out {
        Some(path) => std::fs::write(path, text)?,
        None => println!("{text}"),
    }
    Ok(())
}
