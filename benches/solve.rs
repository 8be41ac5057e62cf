//! Interior-point solves of the scalable problems (hanging chain, Van der Pol optimal
//! control), formulated exactly as benches/reference/{hanging_chain,ocp}.py, at about
//! 10², 10³, 10⁴ and 10⁵ variables.
//!
//! ```text
//! cargo bench --bench solve                 # criterion (10², 10³, 10⁴; 10⁵ timed once)
//! cargo bench --bench solve -- --json       # one JSON line per problem and size
//! ```
//! cargo bench --bench solve -- --small     # the small problems' per-iteration cost
//! ```
//! `--small` solves, 20 times each, the problems whose IPM cost is fixed costs rather
//! than linear algebra: the gap-crossing planner's single-stance problem (18 variables,
//! `gap_crossing::model::build_stance`, solved cold for each stance of the crawl guess,
//! as the schedule search does) and HS116/HS118 (13/15 variables). It prints the
//! iterations and the wall time per iteration; under
//! `valgrind --tool=callgrind --toggle-collect='*small_solve*'` it gives the
//! instructions per iteration (the numbers in docs/performance.md).
//!
//! ```text
//! `SOLVE_MAX_LOG_N=4` limits the JSON mode to sizes up to 10⁴ variables and
//! `SOLVE_PROBLEM=ocp` (or `hanging_chain`) to one problem (the 10⁵ chain runs into its
//! 120 s cap).
//!
//! The JSON mode prints what docs/performance.md compares with
//! `python3 benches/reference/solve_casadi.py`: iterations, status, objective, median
//! solve wall time (5 solves up to 10³ variables, 3 at 10⁴, 1 at 10⁵), compile time,
//! and the time split of the median solve.
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::Criterion;
use nlp::{CommonOptions, Compiled, Ipm, IpmOptions, Problem, Solution};
use testkit::solve_problems::{hanging_chain, van_der_pol, CHAIN_SIZES, OCP_SIZES};

type Builder = fn(usize) -> Problem;
type Sizes = [(u32, usize); 4];

const PROBLEMS: [(&str, Builder, Sizes); 2] = [
    ("hanging_chain", hanging_chain, CHAIN_SIZES),
    ("ocp", van_der_pol, OCP_SIZES),
];

fn solver() -> Ipm {
    // IPOPT's defaults (tol 1e-8), as the reference script, which caps IPOPT at 120 s
    // (`--cap 120`) as well.
    Ipm::new(IpmOptions {
        common: CommonOptions {
            max_wall_time: 120.0,
            ..CommonOptions::default()
        },
        ..IpmOptions::default()
    })
}

fn solve(compiled: &mut Compiled) -> Solution {
    solver().solve(compiled).expect("valid problem")
}

fn json_mode() {
    let max_log_n: u32 = std::env::var("SOLVE_MAX_LOG_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(u32::MAX);
    let only = std::env::var("SOLVE_PROBLEM").ok();
    for (name, build, sizes) in PROBLEMS {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        for (log_n, size) in sizes {
            if log_n > max_log_n {
                continue;
            }
            let pb = build(size);
            let t = Instant::now();
            let mut compiled = pb.compile().expect("compiles");
            let compile_s = t.elapsed().as_secs_f64();
            let reps = match log_n {
                0..=3 => 5,
                4 => 3,
                _ => 1,
            };
            let mut runs: Vec<(f64, Solution)> = (0..reps)
                .map(|_| {
                    let t = Instant::now();
                    let sol = solve(&mut compiled);
                    (t.elapsed().as_secs_f64(), sol)
                })
                .collect();
            runs.sort_by(|a, b| a.0.total_cmp(&b.0));
            let all: Vec<f64> = runs.iter().map(|r| r.0).collect();
            let (secs, sol) = &runs[runs.len() / 2];
            let s = &sol.stats;
            println!(
                "{}",
                serde_json::json!({
                    "problem": name,
                    "N": size,
                    "n": pb.n_variables(),
                    "m": pb.n_constraints(),
                    "status": format!("{:?}", sol.status),
                    "iterations": s.iterations,
                    "objective": sol.objective,
                    "constr_viol": sol.constr_viol,
                    "solve_s": secs,
                    "solve_s_all": all,
                    "compile_s": compile_s,
                    "eval_s": s.eval_seconds,
                    "factor_s": s.factor_seconds,
                    "other_s": s.other_seconds,
                    "n_factorizations": s.n_factorizations,
                })
            );
        }
    }
}

fn criterion_mode() {
    let mut c = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .configure_from_args();
    for (name, build, sizes) in PROBLEMS {
        let mut group = c.benchmark_group(format!("solve_{name}"));
        for (log_n, size) in sizes {
            let mut compiled = build(size).compile().expect("compiles");
            if log_n <= 4 {
                group.bench_function(format!("1e{log_n}"), |b| {
                    b.iter(|| black_box(solve(&mut compiled)))
                });
            } else {
                // 10⁵ variables: one timed solve instead of a sample.
                let t = Instant::now();
                let sol = solve(&mut compiled);
                println!(
                    "solve_{name}/1e{log_n}: one solve {:.3} s ({:?}, {} iterations)",
                    t.elapsed().as_secs_f64(),
                    sol.status,
                    sol.stats.iterations
                );
            }
        }
        group.finish();
    }
    c.final_summary();
}

/// One small problem of `--small`: a compiled problem and the starting points and
/// parameter values of its solves.
struct Small {
    name: &'static str,
    compiled: Compiled,
    /// (parameter values of `STANCE_FEET` or none, starting point) of each solve.
    starts: Vec<(Option<Vec<f64>>, Vec<f64>)>,
}

/// The gap-crossing planner's stance problem, solved for the feet of each stance of
/// the default scenario's crawl guess from the previous stance's CoMs and forces.
fn stance_problem() -> Small {
    use gap_crossing::model::{build_stance, STANCE_FEET};
    use gap_crossing::scenario::Scenario;
    use gap_crossing::terrain::GapTerrain;
    let s = Scenario::default();
    let problem = build_stance(&s, &GapTerrain { gap: s.gap }).expect("stance problem");
    let plan = gap_crossing::gait::crawl_plan(&s);
    let starts = plan
        .stances
        .windows(2)
        .map(|w| {
            let feet: Vec<f64> = w[1].feet.to_array().iter().flatten().copied().collect();
            let mut x0: Vec<f64> = w[0].com.b.iter().chain(&w[0].com.f).copied().collect();
            x0.extend(w[0].forces.to_array().iter().flatten());
            (Some(feet), x0)
        })
        .collect();
    assert_eq!(STANCE_FEET, "stance feet");
    Small {
        name: "gap_stance",
        compiled: problem.compile().expect("compiles"),
        starts,
    }
}

/// An HS problem solved from its published start.
fn hs_problem(name: &'static str, build: fn() -> testkit::hs::problems::Built) -> Small {
    let compiled = build()
        .expect("HS problem")
        .problem
        .compile()
        .expect("compiles");
    let x0 = case_x0(&compiled);
    Small {
        name,
        compiled,
        starts: vec![(None, x0)],
    }
}

/// Solves every start of `pb` with `ipm` (the solver keeps its workspace across
/// solves, as the planner's stance solver does); returns the total iterations.
#[inline(never)]
fn small_solve(ipm: &Ipm, pb: &mut Small) -> usize {
    let mut iterations = 0;
    for (feet, x0) in &pb.starts {
        if let Some(p) = feet {
            pb.compiled.set_value("stance feet", p).expect("feet");
        }
        pb.compiled.set_initial_point(x0).expect("start");
        let sol = ipm.solve(&mut pb.compiled).expect("valid problem");
        iterations += sol.stats.iterations;
    }
    iterations
}

/// `--small`: iterations and wall time per iteration of the small problems (20 rounds,
/// median round).
fn small_mode() {
    // The planner's stance-solver settings (`StanceSolver::with_settings`).
    let ipm = Ipm::new(IpmOptions {
        common: CommonOptions {
            max_iter: 100,
            print_level: 0,
            ..CommonOptions::default()
        },
        ..IpmOptions::default()
    });
    let rounds: usize = std::env::var("SMALL_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    let problems = [
        stance_problem(),
        hs_problem("hs116", testkit::hs::problems::hs116),
        hs_problem("hs118", testkit::hs::problems::hs118),
    ];
    for mut pb in problems {
        let mut times = Vec::new();
        let mut iterations = 0;
        for _ in 0..rounds {
            let t = Instant::now();
            iterations = small_solve(&ipm, &mut pb);
            times.push(t.elapsed().as_secs_f64());
        }
        times.sort_by(f64::total_cmp);
        let median = times[times.len() / 2];
        println!(
            "{}: {} solves, {iterations} iterations per round, median round {:.3} ms, \
             {:.2} µs per iteration",
            pb.name,
            pb.starts.len(),
            median * 1e3,
            median * 1e6 / iterations as f64
        );
    }
}

fn main() {
    if std::env::args().any(|a| a == "--small") {
        small_mode();
    } else if std::env::args().any(|a| a == "--json") {
        json_mode();
    } else {
        criterion_mode();
    }
}

/// The starting point stored in a compiled problem.
fn case_x0(compiled: &Compiled) -> Vec<f64> {
    use nlp::NumericNlp;
    let mut x0 = vec![0.0; compiled.n()];
    compiled.initial_point(&mut x0);
    x0
}
