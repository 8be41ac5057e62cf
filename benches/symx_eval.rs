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
//!
//! `ocp_chain_inlined` and `ocp_chain_calls` (`cargo bench --bench symx_eval -- ocp_chain`):
//! the same quantities on the quadrotor OCP of benches/common/quadrotor_ocp.rs (12 states,
//! 4 controls, N = 1000 stages, RK4, multiple shooting), with the RK4 step written out at
//! every stage or compiled once and called (call nodes); the build phase includes compiling
//! the step function, and its derivative functions are built inside the derivative phases.
//! benches/reference/ocp_chain_casadi.py does the same with CasADi SX (inlined). Graph
//! sizes (nodes) and tape sizes are printed first: the memory comparison.
//!
//! `map` (`cargo bench --bench symx_eval -- map`): 10 000 evaluations of the RK4 step F
//! with `Function::map`, serial and on 2 threads.
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
#[path = "common/quadrotor_ocp.rs"]
mod quadrotor_ocp;

const LINKS: usize = 1000;

/// An NLP in symbolic form: objective, constraints, variables.
struct Symbolic {
    f: Expr,
    g: Vec<Expr>,
    x: Vec<Expr>,
}

/// ∇f, ∂g/∂x and the lower triangle of ∇²(σf + λᵀg) with σ, λ symbolic.
struct Derivatives {
    x: Vec<Expr>,
    grad: Vec<Expr>,
    jac: SparseMatrix,
    sigma: Expr,
    lambda: Matrix,
    hess: SparseMatrix,
}

fn gradient_of(p: &Symbolic) -> Vec<Expr> {
    gradient(p.f, &p.x).unwrap()
}

fn jacobian_of(p: &Symbolic) -> SparseMatrix {
    jacobian(&p.g, &p.x).unwrap()
}

fn hessian_of(p: &Symbolic) -> (Expr, Matrix, SparseMatrix) {
    let sigma = Expr::sym("sigma");
    let lambda = Matrix::sym_vec("lambda", p.g.len());
    let hess = lagrangian_hessian(p.f, &p.g, &p.x, sigma, &lambda).unwrap();
    (sigma, lambda, hess)
}

fn differentiate(p: Symbolic) -> Derivatives {
    let (grad, jac) = (gradient_of(&p), jacobian_of(&p));
    let (sigma, lambda, hess) = hessian_of(&p);
    Derivatives {
        x: p.x,
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
    let x = &d.x;
    Compiled {
        grad: Function::new(&[x], &[&d.grad]).unwrap(),
        jac: Function::new(&[x], &[d.jac.values()]).unwrap(),
        hess: Function::new(&[x, &[d.sigma], &d.lambda], &[d.hess.values()]).unwrap(),
    }
}

/// Set-up phases timed in a fresh thread (a fresh expression graph, as a new program
/// would have): (build, grad_f, jac_g, hess_L, functions).
fn setup_phases(build: impl FnOnce() -> Symbolic + Send + 'static) -> [Duration; 5] {
    std::thread::spawn(|| {
        let t0 = Instant::now();
        let p = build();
        let t1 = Instant::now();
        let grad = gradient_of(&p);
        let t2 = Instant::now();
        let jac = jacobian_of(&p);
        let t3 = Instant::now();
        let (sigma, lambda, hess) = hessian_of(&p);
        let t4 = Instant::now();
        let d = Derivatives {
            x: p.x,
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

fn chain(links: usize) -> (Symbolic, Vec<f64>) {
    let c = hanging_chain::build(links);
    let p = Symbolic {
        f: c.f,
        g: c.g,
        x: c.w.to_vec(),
    };
    (p, c.x0)
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

fn gap_symbolic(m: &Model) -> Symbolic {
    Symbolic {
        f: m.problem.objective(),
        g: m.problem.constraint_expressions(),
        x: m.problem.variables().to_vec(),
    }
}

fn inputs(rows: usize, x0: &[f64]) -> (Vec<f64>, [f64; 1], Vec<f64>) {
    let lambda = (0..rows).map(|i| (i + 1) as f64 / rows as f64).collect();
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

/// Prints checksums and per-call medians, then runs the criterion groups
/// `{group}/setup` (phases of `setup`, named by `build_name` for the first) and
/// `{group}/eval` for one problem.
fn measure(
    c: &mut Criterion,
    group: &str,
    fns: &Compiled,
    hess_in: [&[f64]; 3],
    build_name: &str,
    setup_time: Duration,
    setup: impl Fn() -> [Duration; 5],
) {
    let functions = [
        ("grad_f", &fns.grad, &hess_in[..1]),
        ("jac_g", &fns.jac, &hess_in[..1]),
        ("hess_L", &fns.hess, &hess_in[..]),
    ];
    for (name, f, ins) in functions {
        checksums(name, f, ins);
    }
    // The same statistic as the CasADi scripts' `internal_us`: the wall time of single
    // calls, median over 300 calls, median of 7 repetitions (robust to preemption on a
    // shared machine, unlike a mean over batches).
    for (name, f, ins) in functions {
        let (median, min) = per_call(f, ins);
        eprintln!("{name:7} per-call median {median:8.3} us  min {min:8.3} us");
    }

    let mut g = c.benchmark_group(format!("{group}/setup"));
    g.sample_size(10)
        .measurement_time(setup_time)
        .warm_up_time(Duration::from_millis(500));
    let names = [
        build_name,
        "grad_f",
        "jac_g",
        "hess_L",
        "functions",
        "total",
    ];
    for (k, name) in names.iter().enumerate() {
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter_custom(|iters| {
                (0..iters)
                    .map(|_| {
                        let p = setup();
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
    g.finish();

    let mut g = c.benchmark_group(format!("{group}/eval"));
    g.sample_size(20)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    for (name, f, ins) in functions {
        let mut out = vec![0.0; f.output_sizes()[0]];
        let mut work = vec![0.0; f.work_size()];
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                f.eval(black_box(ins), &mut [&mut out], &mut work).unwrap();
                black_box(&out);
            })
        });
    }
    g.finish();
}

fn bench(c: &mut Criterion) {
    let (p, x0) = chain(LINKS);
    let fns = compile(&differentiate(p));
    let (x, sigma, lambda) = inputs(LINKS, &x0);
    measure(
        c,
        "symx_eval",
        &fns,
        [&x, &sigma, &lambda],
        "expr",
        Duration::from_secs(3),
        || setup_phases(|| chain(LINKS).0),
    );
}

fn bench_gap(c: &mut Criterion) {
    let s = gap_scenario();
    let m = gap_model(&s);
    let sym = gap_symbolic(&m);
    let (nx, ng) = (sym.x.len(), sym.g.len());
    let fns = compile(&differentiate(sym));
    let compiled = m.problem.compile().unwrap();
    let (n, rows) = (compiled.n(), compiled.m());
    assert_eq!((n, rows), (nx, ng));
    let mut x0 = vec![0.0; n];
    compiled.initial_point(&mut x0);
    let (x, sigma, lambda) = inputs(rows, &x0);
    eprintln!(
        "gap crossing (crawl, default scenario, n_step {}): n {n}, m {rows}",
        s.n_step
    );
    measure(
        c,
        "symx_eval_gap",
        &fns,
        [&x, &sigma, &lambda],
        "build",
        Duration::from_secs(5),
        || {
            let s = s.clone();
            setup_phases(move || gap_symbolic(&gap_model(&s)))
        },
    );
}

const OCP_STAGES: usize = 1000;

fn ocp_symbolic(calls: bool) -> Symbolic {
    let o = quadrotor_ocp::build(OCP_STAGES, calls);
    Symbolic {
        f: o.f,
        g: o.g,
        x: o.w,
    }
}

fn bench_ocp(c: &mut Criterion) {
    for (calls, group) in [(false, "ocp_chain_inlined"), (true, "ocp_chain_calls")] {
        // Built on a fresh thread so that the node count is this problem's alone.
        let (fns, nodes) = std::thread::spawn(move || {
            let fns = compile(&differentiate(ocp_symbolic(calls)));
            (fns, symx::node_count())
        })
        .join()
        .unwrap();
        eprintln!("{group}: graph after build + derivatives + compile: {nodes} nodes");
        let m = (OCP_STAGES + 1) * quadrotor_ocp::NX;
        let (x, sigma, lambda) = inputs(m, &quadrotor_ocp::point(OCP_STAGES));
        measure(
            c,
            group,
            &fns,
            [&x, &sigma, &lambda],
            "build",
            Duration::from_secs(20),
            move || setup_phases(move || ocp_symbolic(calls)),
        );
    }
}

fn bench_map(c: &mut Criterion) {
    const COPIES: usize = 10_000;
    let f = quadrotor_ocp::step_function();
    let (nx, nu) = (quadrotor_ocp::NX, quadrotor_ocp::NU);
    let p = quadrotor_ocp::point(COPIES);
    let xs: Vec<f64> = (0..COPIES)
        .flat_map(|k| p[k * (nx + nu)..k * (nx + nu) + nx].to_vec())
        .collect();
    let us: Vec<f64> = (0..COPIES)
        .flat_map(|k| p[k * (nx + nu) + nx..(k + 1) * (nx + nu)].to_vec())
        .collect();
    let mut g = c.benchmark_group("map");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    for threads in [1usize, 2] {
        let map = f.map(COPIES).parallel(threads).unwrap();
        let mut out = vec![0.0; COPIES * nx];
        let mut work = vec![0.0; map.work_size()];
        g.bench_function(BenchmarkId::new("rk4_step_10000", threads), |b| {
            b.iter(|| {
                map.eval(black_box(&[&xs, &us]), &mut [&mut out], &mut work)
                    .unwrap();
                black_box(&out);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench, bench_gap, bench_ocp, bench_map);
criterion_main!(benches);
