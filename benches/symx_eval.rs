//! symx set-up and evaluation on the hanging chain with 1000 links (n = 2002, m = 1000),
//! the same problem and quantities as benches/reference/symx_eval_casadi.py:
//!
//! * set-up: build f and g, ∇f (gradient), ∂g/∂w (sparse Jacobian), the lower triangle of
//!   ∇²(σf + λᵀg) with σ and λ symbolic, and compile the three `Function`s; each phase is
//!   timed in a fresh thread (a fresh expression graph, as a new program would have);
//! * evaluation: one call of each compiled function at the initial guess with σ = 1,
//!   λᵢ = (i+1)/N, into preallocated outputs and work vector.
//!
//! Run: `cargo bench --bench symx_eval` (about a minute). The value checksums printed first
//! must match the CasADi script's `sum`/`norm2`.
//!
//! A second group, `symx_eval_gap` (`cargo bench --bench symx_eval -- gap`), measures the
//! same quantities on the gap-crossing equations: the crawl (scheduled) formulation of
//! `gap_crossing::model` on the default scenario (default gap, n_step 60), the problem that
//! `gap_crossing::export` dumps and benches/reference/symx_eval_gap_casadi.py parses into
//! CasADi SX. Set-up phases: build (crawl guess + `model::build`), ∇f, ∂g/∂x, the lower
//! triangle of ∇²(σf + λᵀg) (σ, λ symbolic) and the three `Function`s, taken directly on
//! `problem.objective()`, `problem.constraint_expressions()` and `problem.variables()`;
//! evaluation at the problem's initial point with σ = 1, λᵢ = (i+1)/m.
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use gap_crossing::model::{self, Formulation, Model};
use gap_crossing::scenario::Scenario;
use gap_crossing::{gait, terrain::GapTerrain};
use nlp::NumericNlp;
use std::hint::black_box;
use std::time::{Duration, Instant};
use symx::{gradient, jacobian, lagrangian_hessian, Expr, Function, Matrix, SparseMatrix};

#[path = "common/hanging_chain.rs"]
mod hanging_chain;

const LINKS: usize = 1000;

struct Derivatives {
    chain: hanging_chain::HangingChain,
    grad: Vec<Expr>,
    jac: SparseMatrix,
    sigma: Expr,
    lambda: Matrix,
    hess: SparseMatrix,
}

fn differentiate(chain: hanging_chain::HangingChain) -> Derivatives {
    let grad = gradient(chain.f, &chain.w).unwrap();
    let jac = jacobian(&chain.g, &chain.w).unwrap();
    let sigma = Expr::sym("sigma");
    let lambda = Matrix::sym_vec("lambda", chain.g.len());
    let hess = lagrangian_hessian(chain.f, &chain.g, &chain.w, sigma, &lambda).unwrap();
    Derivatives {
        chain,
        grad,
        jac,
        sigma,
        lambda,
        hess,
    }
}

struct Compiled {
    grad: Function,
    jac: Function,
    hess: Function,
}

fn compile(d: &Derivatives) -> Compiled {
    let w = &d.chain.w;
    Compiled {
        grad: Function::new(&[w], &[&d.grad]).unwrap(),
        jac: Function::new(&[w], &[d.jac.values()]).unwrap(),
        hess: Function::new(&[w, &[d.sigma], &d.lambda], &[d.hess.values()]).unwrap(),
    }
}

/// Set-up phases, timed in a fresh thread: (expr, grad_f, jac_g, hess_L, functions).
fn setup_phases() -> [Duration; 5] {
    std::thread::spawn(|| {
        let t0 = Instant::now();
        let chain = hanging_chain::build(LINKS);
        let t1 = Instant::now();
        let grad = gradient(chain.f, &chain.w).unwrap();
        let t2 = Instant::now();
        let jac = jacobian(&chain.g, &chain.w).unwrap();
        let t3 = Instant::now();
        let sigma = Expr::sym("sigma");
        let lambda = Matrix::sym_vec("lambda", chain.g.len());
        let hess = lagrangian_hessian(chain.f, &chain.g, &chain.w, sigma, &lambda).unwrap();
        let t4 = Instant::now();
        let d = Derivatives {
            chain,
            grad,
            jac,
            sigma,
            lambda,
            hess,
        };
        black_box(compile(&d));
        let t5 = Instant::now();
        [t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4]
    })
    .join()
    .unwrap()
}

/// The gap-crossing problem with the derivatives of the chain group.
struct GapDerivatives {
    x: Vec<Expr>,
    grad: Vec<Expr>,
    jac: SparseMatrix,
    sigma: Expr,
    lambda: Matrix,
    hess: SparseMatrix,
}

/// The default scenario (n_step 60, default gap), crawl schedule and crawl guess.
fn gap_scenario() -> Scenario {
    let s = Scenario::default();
    assert_eq!(s.n_step, 60);
    s
}

fn gap_model(s: &Scenario) -> Model {
    model::build(
        s,
        &GapTerrain { gap: s.gap },
        &Formulation::Scheduled(gait::crawl_schedule(s.n_step)),
        &gait::crawl(s),
    )
    .unwrap()
}

fn gap_differentiate(m: &Model) -> GapDerivatives {
    let x = m.problem.variables().to_vec();
    let f = m.problem.objective();
    let g = m.problem.constraint_expressions();
    let grad = gradient(f, &x).unwrap();
    let jac = jacobian(&g, &x).unwrap();
    let sigma = Expr::sym("sigma");
    let lambda = Matrix::sym_vec("lambda", g.len());
    let hess = lagrangian_hessian(f, &g, &x, sigma, &lambda).unwrap();
    GapDerivatives {
        x,
        grad,
        jac,
        sigma,
        lambda,
        hess,
    }
}

fn gap_compile(d: &GapDerivatives) -> Compiled {
    let x = &d.x;
    Compiled {
        grad: Function::new(&[x], &[&d.grad]).unwrap(),
        jac: Function::new(&[x], &[d.jac.values()]).unwrap(),
        hess: Function::new(&[x, &[d.sigma], &d.lambda], &[d.hess.values()]).unwrap(),
    }
}

/// Gap-crossing set-up phases, timed in a fresh thread: (build, grad_f, jac_g, hess_L,
/// functions).
fn gap_setup_phases(s: &Scenario) -> [Duration; 5] {
    let s = s.clone();
    std::thread::spawn(move || {
        let t0 = Instant::now();
        let m = gap_model(&s);
        let x = m.problem.variables().to_vec();
        let f = m.problem.objective();
        let g = m.problem.constraint_expressions();
        let t1 = Instant::now();
        let grad = gradient(f, &x).unwrap();
        let t2 = Instant::now();
        let jac = jacobian(&g, &x).unwrap();
        let t3 = Instant::now();
        let sigma = Expr::sym("sigma");
        let lambda = Matrix::sym_vec("lambda", g.len());
        let hess = lagrangian_hessian(f, &g, &x, sigma, &lambda).unwrap();
        let t4 = Instant::now();
        let d = GapDerivatives {
            x,
            grad,
            jac,
            sigma,
            lambda,
            hess,
        };
        black_box(gap_compile(&d));
        let t5 = Instant::now();
        [t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4]
    })
    .join()
    .unwrap()
}

fn inputs(links: usize, x0: &[f64]) -> (Vec<f64>, [f64; 1], Vec<f64>) {
    let lambda = (0..links).map(|i| (i + 1) as f64 / links as f64).collect();
    (x0.to_vec(), [1.0], lambda)
}

fn checksums(name: &str, f: &Function, ins: &[&[f64]]) {
    let out = f.call(ins).unwrap().remove(0);
    let sum: f64 = out.iter().sum();
    let norm2 = out.iter().map(|v| v * v).sum::<f64>().sqrt();
    eprintln!(
        "{name:7} nnz {:5}  instructions {:6}  work {:6}  sum {sum:.16e}  norm2 {norm2:.16e}",
        out.len(),
        f.instruction_count(),
        f.work_size()
    );
}

/// (median of medians, minimum) of single-call wall times in µs.
fn per_call(f: &Function, ins: &[&[f64]]) -> (f64, f64) {
    let mut out = vec![0.0; f.output_sizes()[0]];
    let mut work = vec![0.0; f.work_size()];
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut medians = Vec::new();
    let mut min = f64::INFINITY;
    for _ in 0..7 {
        let mut times: Vec<f64> = (0..300)
            .map(|_| {
                let t = Instant::now();
                f.eval(black_box(ins), &mut [&mut out], &mut work).unwrap();
                black_box(&out);
                t.elapsed().as_secs_f64() * 1e6
            })
            .collect();
        min = times.iter().fold(min, |m, &t| m.min(t));
        medians.push(median(&mut times));
    }
    (median(&mut medians), min)
}

fn bench(c: &mut Criterion) {
    let d = differentiate(hanging_chain::build(LINKS));
    let fns = compile(&d);
    let (x, sigma, lambda) = inputs(LINKS, &d.chain.x0);
    let hess_in: [&[f64]; 3] = [&x, &sigma, &lambda];
    checksums("grad_f", &fns.grad, &[&x]);
    checksums("jac_g", &fns.jac, &[&x]);
    checksums("hess_L", &fns.hess, &hess_in);

    // The same statistic as the CasADi script's `internal_us`: the wall time of single
    // calls, median over 300 calls, median of 7 repetitions (robust to preemption on a
    // shared machine, unlike a mean over batches).
    for (name, f, ins) in [
        ("grad_f", &fns.grad, &hess_in[..1]),
        ("jac_g", &fns.jac, &hess_in[..1]),
        ("hess_L", &fns.hess, &hess_in[..]),
    ] {
        let (median, min) = per_call(f, ins);
        eprintln!("{name:7} per-call median {median:8.3} us  min {min:8.3} us");
    }

    let mut group = c.benchmark_group("symx_eval/setup");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_millis(500));
    let names = ["expr", "grad_f", "jac_g", "hess_L", "functions", "total"];
    for (k, name) in names.iter().enumerate() {
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter_custom(|iters| {
                (0..iters)
                    .map(|_| {
                        let p = setup_phases();
                        if k < 5 {
                            p[k]
                        } else {
                            p.iter().sum()
                        }
                    })
                    .sum()
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group("symx_eval/eval");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    for (name, f, ins) in [
        ("grad_f", &fns.grad, &hess_in[..1]),
        ("jac_g", &fns.jac, &hess_in[..1]),
        ("hess_L", &fns.hess, &hess_in[..]),
    ] {
        let mut out = vec![0.0; f.output_sizes()[0]];
        let mut work = vec![0.0; f.work_size()];
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                f.eval(black_box(ins), &mut [&mut out], &mut work).unwrap();
                black_box(&out);
            })
        });
    }
    group.finish();
}

fn bench_gap(c: &mut Criterion) {
    let s = gap_scenario();
    let m = gap_model(&s);
    let d = gap_differentiate(&m);
    let fns = gap_compile(&d);
    let compiled = m.problem.compile().unwrap();
    let (n, rows) = (compiled.n(), compiled.m());
    assert_eq!((n, rows), (d.x.len(), d.lambda.len()));
    let mut x0 = vec![0.0; n];
    compiled.initial_point(&mut x0);
    let (x, sigma, lambda) = inputs(rows, &x0);
    let hess_in: [&[f64]; 3] = [&x, &sigma, &lambda];
    eprintln!(
        "gap crossing (crawl, default scenario, n_step {}): n {n}, m {rows}",
        s.n_step
    );
    checksums("grad_f", &fns.grad, &[&x]);
    checksums("jac_g", &fns.jac, &[&x]);
    checksums("hess_L", &fns.hess, &hess_in);
    for (name, f, ins) in [
        ("grad_f", &fns.grad, &hess_in[..1]),
        ("jac_g", &fns.jac, &hess_in[..1]),
        ("hess_L", &fns.hess, &hess_in[..]),
    ] {
        let (median, min) = per_call(f, ins);
        eprintln!("{name:7} per-call median {median:8.3} us  min {min:8.3} us");
    }

    let mut group = c.benchmark_group("symx_eval_gap/setup");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(5))
        .warm_up_time(Duration::from_millis(500));
    let names = ["build", "grad_f", "jac_g", "hess_L", "functions", "total"];
    for (k, name) in names.iter().enumerate() {
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter_custom(|iters| {
                (0..iters)
                    .map(|_| {
                        let p = gap_setup_phases(&s);
                        if k < 5 {
                            p[k]
                        } else {
                            p.iter().sum()
                        }
                    })
                    .sum()
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group("symx_eval_gap/eval");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    for (name, f, ins) in [
        ("grad_f", &fns.grad, &hess_in[..1]),
        ("jac_g", &fns.jac, &hess_in[..1]),
        ("hess_L", &fns.hess, &hess_in[..]),
    ] {
        let mut out = vec![0.0; f.output_sizes()[0]];
        let mut work = vec![0.0; f.work_size()];
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                f.eval(black_box(ins), &mut [&mut out], &mut work).unwrap();
                black_box(&out);
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench, bench_gap);
criterion_main!(benches);
