//! The flagship model's solve times (issue 5, Performance).
//!
//! * `gap_crossing/default_free_gait`: the spec's default scenario, free gait, the whole
//!   pipeline `solve::plan` (guesses, three build + compile + solve phases, reading back) in a
//!   fresh thread (a fresh expression graph, as a new process would have);
//! * `gap_crossing/crawl_flat60_solve` and `..._total`: crawl gait on flat ground (gap depth
//!   0), n_step 60, goals 3 m ahead (the default goals) — the problem that
//!   `benches/reference/gap_crossing_casadi.py` solves with IPOPT; `solve` is the IPM call
//!   only, `total` adds guess, build and compile (fresh thread);
//! * `gap_crossing/crawl_gap60_build_compile`: guess, build and compile (`Problem::compile`:
//!   derivatives and tapes) of the default scenario's crawl problem, n_step 60, in a fresh
//!   expression arena: what each of the planner's solves pays before its first iteration;
//! * `gap_crossing_scaling/crawl_gap/N`: crawl gait on the default gap, IPM call only, for
//!   n_step in `GAP_CROSSING_SIZES` (comma-separated, default `30,60,120`; the larger sizes
//!   240 and 480 are measured once by `examples/scaling.rs`).
//!
//! Run: `cargo bench --bench gap_crossing` (about three minutes on the 2-core machine; every
//! benchmark takes 10 samples of one iteration each).
use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, SamplingMode};
use gap_crossing::export::crawl_model;
use gap_crossing::scenario::Scenario;
use gap_crossing::solve::{self, Settings};
use nlp::{Ipm, IpmOptions};
use std::hint::black_box;
use std::time::Duration;

fn scenario(overrides: &[&str]) -> Scenario {
    let mut s = Scenario::default();
    s.apply_overrides(overrides).expect("valid overrides");
    s.validate().expect("valid scenario");
    s
}

/// Builds, compiles and solves the crawl problem of `s` in a fresh thread; returns the IPM's
/// success flag.
fn crawl_total(s: &Scenario) -> bool {
    let s = s.clone();
    std::thread::spawn(move || {
        let (_model, mut compiled) = crawl_model(&s).expect("model builds");
        let sol = Ipm::new(IpmOptions::default())
            .solve(&mut compiled)
            .expect("solver input");
        sol.status.is_success()
    })
    .join()
    .expect("solver thread")
}

fn crawl_solve_only(b: &mut criterion::Bencher<'_>, s: &Scenario) {
    b.iter_batched(
        || crawl_model(s).expect("model builds").1,
        |mut compiled| {
            let sol = Ipm::new(IpmOptions::default())
                .solve(&mut compiled)
                .expect("solver input");
            assert!(sol.status.is_success(), "{:?}", sol.status);
            black_box(sol.objective)
        },
        BatchSize::PerIteration,
    );
}

fn free_gait(s: &Scenario) -> f64 {
    let s = s.clone();
    std::thread::spawn(move || {
        let out = solve::plan(&s, &Settings::default()).expect("planning runs");
        assert!(out.status.is_solved(), "{}", out.status);
        out.file.solver.objective
    })
    .join()
    .expect("planning thread")
}

fn slow_group<'a>(
    c: &'a mut Criterion,
    name: &str,
) -> criterion::BenchmarkGroup<'a, criterion::measurement::WallTime> {
    let mut g = c.benchmark_group(name);
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    g
}

fn bench(c: &mut Criterion) {
    let default = Scenario::default();
    let flat = scenario(&["n_step=60", "gap.depth=0"]);
    eprintln!(
        "default scenario, free gait: objective {:.6e} (spec's crawl plan ≈ 1.985e5)",
        free_gait(&default)
    );
    {
        let mut g = slow_group(c, "gap_crossing");
        g.bench_function("default_free_gait", |b| {
            b.iter(|| black_box(free_gait(&default)))
        });
        g.bench_function("crawl_flat60_solve", |b| crawl_solve_only(b, &flat));
        g.bench_function("crawl_flat60_total", |b| {
            b.iter(|| assert!(crawl_total(&flat)))
        });
        g.bench_function("crawl_gap60_build_compile", |b| {
            b.iter(|| {
                symx::with_fresh_arena(|| black_box(crawl_model(&default).expect("model builds").1))
            })
        });
        g.finish();
    }
    let sizes: Vec<usize> = std::env::var("GAP_CROSSING_SIZES")
        .unwrap_or_else(|_| "30,60,120".into())
        .split(',')
        .map(|t| {
            t.trim()
                .parse()
                .expect("GAP_CROSSING_SIZES: comma-separated n_step")
        })
        .collect();
    let mut g = slow_group(c, "gap_crossing_scaling");
    for n in sizes {
        let s = scenario(&[&format!("n_step={n}")]);
        g.bench_with_input(BenchmarkId::new("crawl_gap", n), &s, crawl_solve_only);
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
