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
//! the same quantities on the quadrotor OCP of testkit/src/quadrotor_ocp.rs (12 states,
//! 4 controls, N = 1000 stages, RK4, multiple shooting), with the RK4 step written out at
//! every stage or compiled once and called (call nodes); the build phase includes compiling
//! the step function, and its derivative functions are built inside the derivative phases.
//! benches/reference/ocp_chain_casadi.py does the same with CasADi SX (inlined). Graph
//! sizes (nodes) and tape sizes are printed first: the memory comparison.
//!
//! For the ocp groups criterion times only the evaluations; the set-up phases are printed
//! as medians of 3 runs (`{group} setup_ms {…}`), the statistic of the CasADi
//! script. `SYMX_OCP_MEMORY=inlined|calls|none` makes the binary build one version once and
//! exit, for peak-memory measurement (see `memory_run`). benches/reference/ocp_compare.sh
//! runs both sides and prints the ratios.
//!
//! `native_chain`, `native_gap`, `native_quadrotor`, `native_quadrotor_calls` (`cargo
//! bench --bench symx_eval -- native`): the tape against native code (`Function::jit`) on
//! ∇f, ∂g/∂x and the Hessian, with the JIT's compile times (benches/reference/native_casadi.py measures
//! CasADi's VM and its generated C on the same functions).
//!
//! `native_rust_chain`, `native_rust_gap`, `native_rust_quadrotor` (`cargo bench --bench
//! symx_eval -- native_rust`): tape, JIT and generated Rust (`Function::to_rust`) on the
//! same three functions. The generated modules are compiled by `rustc` with cargo's
//! `--release` settings when the group runs (so `cargo bench --no-run` stays fast) into a
//! program that criterion drives through a pipe (`iter_custom`: the program times its own
//! loop of calls); its outputs are checked bit for bit against the tape first. Run only when
//! a filter names them. With `SYMX_NATIVE_RUST_KEEP=1` the program is kept (its path is
//! printed) for callgrind: `echo "K CALLS" | valgrind --tool=callgrind DIR/main
//! DIR/inputs.bin DIR/out.bin` runs function K (0 ∇f, 1 Jacobian, 2 Hessian). See
//! [`GeneratedRust`].
//!
//! `native_compile` (`cargo bench --bench symx_eval -- native_compile`): the JIT's compile
//! time per 1000 instructions at several sizes (linear if flat).
//!
//! `map` (`cargo bench --bench symx_eval -- map`): 10 000 evaluations of the RK4 step F
//! with `Function::map`, serial and on 2 threads.
use criterion::{criterion_group, BenchmarkId, Criterion, SamplingMode};
use gap_crossing::model::{self, Formulation, Model};
use gap_crossing::scenario::Scenario;
use gap_crossing::{gait, terrain::GapTerrain};
use nlp::NumericNlp;
use std::hint::black_box;
use std::time::{Duration, Instant};
use symx::{gradient, jacobian, lagrangian_hessian, Expr, Function, Matrix, SparseMatrix};

use testkit::{hanging_chain, quadrotor_ocp};

const LINKS: usize = 1000;

/// Stages of the quadrotor OCP in the native groups (issue 24's size).
const NATIVE_STAGES: usize = 320;

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

/// (median of medians, minimum) of single-call wall times in µs: 7 repetitions of 300
/// calls (fewer, at least 10, when 300 would take over 0.3 s).
fn per_call(f: &Function, ins: &[&[f64]]) -> (f64, f64) {
    let mut out = vec![0.0; f.output_sizes()[0]];
    let mut work = vec![0.0; f.work_size()];
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut medians = Vec::new();
    let mut min = f64::INFINITY;
    let t = Instant::now();
    f.eval(ins, &mut [&mut out], &mut work).unwrap();
    let calls = ((0.3 / t.elapsed().as_secs_f64()) as usize).clamp(10, 300);
    for _ in 0..7 {
        let mut times: Vec<f64> = (0..calls)
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

/// How [`measure`] times the set-up.
struct SetupBench<'a> {
    /// Name of the first phase (building the expressions).
    build_name: &'a str,
    /// Criterion's measurement time for each set-up benchmark.
    time: Duration,
    /// Whether criterion times the phases too (six benchmarks of ≥ 10 samples, each
    /// re-running the whole set-up); if not, the printed medians of 3 runs are the figures.
    criterion: bool,
}

/// Runs the set-up `reps` times and prints the median of each phase and of the total
/// (ms), the statistic of the CasADi scripts (median over their repetitions), on one line
/// `{group} setup_ms {json}` that benches/reference/ocp_compare.sh reads.
fn print_setup_medians(
    group: &str,
    names: &[&str],
    reps: usize,
    setup: &impl Fn() -> [Duration; 5],
) {
    let runs: Vec<[Duration; 5]> = (0..reps).map(|_| setup()).collect();
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let mut fields: Vec<String> = (0..5)
        .map(|k| {
            format!(
                "\"{}\": {:.3}",
                names[k],
                median(runs.iter().map(|r| ms(r[k])).collect())
            )
        })
        .collect();
    let total = median(
        runs.iter()
            .map(|r| r.iter().copied().map(ms).sum())
            .collect(),
    );
    fields.push(format!("\"total\": {total:.3}"));
    eprintln!(
        "{group} setup_ms {{{}}} (median of {reps})",
        fields.join(", ")
    );
}

/// Prints checksums, per-call medians and set-up phase medians, then runs the criterion
/// groups `{group}/setup` and `{group}/eval` for one problem.
fn measure(
    c: &mut Criterion,
    group: &str,
    fns: &Compiled,
    hess_in: [&[f64]; 3],
    setup_bench: SetupBench,
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
        eprintln!("{group} {name:7} per-call median {median:8.3} us  min {min:8.3} us");
    }
    let names = [
        setup_bench.build_name,
        "grad_f",
        "jac_g",
        "hess_L",
        "functions",
        "total",
    ];
    print_setup_medians(group, &names, 3, &setup);
    if setup_bench.criterion {
        setup_criterion(c, group, &names, setup_bench.time, &setup);
    }
    eval_criterion(c, group, &functions);
}

/// The criterion group `{group}/setup`: one benchmark per phase and one for the total.
fn setup_criterion(
    c: &mut Criterion,
    group: &str,
    names: &[&str; 6],
    time: Duration,
    setup: &impl Fn() -> [Duration; 5],
) {
    let mut g = c.benchmark_group(format!("{group}/setup"));
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .measurement_time(time)
        .warm_up_time(Duration::from_millis(500));
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
}

/// The criterion group `{group}/eval`: one call of each function.
fn eval_criterion(c: &mut Criterion, group: &str, functions: &[(&str, &Function, &[&[f64]]); 3]) {
    let mut g = c.benchmark_group(format!("{group}/eval"));
    g.sample_size(20)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    for &(name, f, ins) in functions {
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

/// Whether the benchmarks named in `ids` (space-separated) pass the command line's filter
/// (criterion's filter is a regular expression searched in a benchmark's id; here its
/// `|`-separated alternatives are taken as plain substrings, enough for `ocp_chain|map`):
/// the printed figures, which criterion does not filter, are computed only for the
/// selected groups.
fn selected(ids: &str) -> bool {
    let filters: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    filters.is_empty()
        || filters
            .iter()
            .flat_map(|f| f.split('|'))
            .any(|f| ids.contains(f))
}

fn bench(c: &mut Criterion) {
    if !selected("symx_eval/setup/expr symx_eval/eval/hess_L") {
        return;
    }
    let (p, x0) = chain(LINKS);
    let fns = compile(&differentiate(p));
    let (x, sigma, lambda) = inputs(LINKS, &x0);
    measure(
        c,
        "symx_eval",
        &fns,
        [&x, &sigma, &lambda],
        SetupBench {
            build_name: "expr",
            time: Duration::from_secs(3),
            criterion: true,
        },
        || setup_phases(|| chain(LINKS).0),
    );
}

fn bench_gap(c: &mut Criterion) {
    if !selected("symx_eval_gap/setup/build symx_eval_gap/eval/hess_L") {
        return;
    }
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
        SetupBench {
            build_name: "build",
            time: Duration::from_secs(5),
            criterion: true,
        },
        || {
            let s = s.clone();
            setup_phases(move || gap_symbolic(&gap_model(&s)))
        },
    );
}

/// Stages of the ocp_chain problem: 1000 (issue 13's size), or `SYMX_OCP_STAGES` from
/// the environment (a quick check of benches/reference/ocp_compare.sh at a small size).
fn ocp_stages() -> usize {
    std::env::var("SYMX_OCP_STAGES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1000)
}

fn ocp_symbolic(calls: bool) -> Symbolic {
    let o = quadrotor_ocp::build(ocp_stages(), calls);
    Symbolic {
        f: o.f,
        g: o.g,
        x: o.w,
    }
}

fn bench_ocp(c: &mut Criterion) {
    for (calls, group) in [(false, "ocp_chain_inlined"), (true, "ocp_chain_calls")] {
        if !selected(&format!("{group}/eval/hess_L")) {
            continue;
        }
        // Built on a fresh thread so that the node count is this problem's alone.
        let (fns, nodes) = std::thread::spawn(move || {
            let fns = compile(&differentiate(ocp_symbolic(calls)));
            (fns, symx::node_count())
        })
        .join()
        .unwrap();
        eprintln!("{group}: graph after build + derivatives + compile: {nodes} nodes");
        let m = (ocp_stages() + 1) * quadrotor_ocp::NX;
        let (x, sigma, lambda) = inputs(m, &quadrotor_ocp::point(ocp_stages()));
        measure(
            c,
            group,
            &fns,
            [&x, &sigma, &lambda],
            // Not criterion here: its ≥ 10 samples of the ~12 s inlined set-up per phase
            // took ~15 min; the printed medians of 3 runs are the figures (as the CasADi
            // script's median of 3).
            SetupBench {
                build_name: "build",
                time: Duration::from_secs(5),
                criterion: false,
            },
            move || setup_phases(move || ocp_symbolic(calls)),
        );
    }
}

fn bench_map(c: &mut Criterion) {
    if !selected("map/rk4_step_10000/1") {
        return;
    }
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

/// Tape vs native code (`Function::jit`) on ∇f, ∂g/∂x and the Hessian of one problem:
/// prints the instruction counts, the JIT's compile time per function and the per-call
/// medians of both evaluators measured alternately (3 rounds of [`per_call`] each, the
/// median of the rounds), then times both in the criterion group `{group}/eval`.
fn native_versus_tape(c: &mut Criterion, group: &str, fns: &Compiled, ins: [&[f64]; 3]) {
    let all: [(&str, &Function, &[&[f64]]); 3] = [
        ("grad_f", &fns.grad, &ins[..1]),
        ("jac_g", &fns.jac, &ins[..1]),
        ("hess_L", &fns.hess, &ins[..]),
    ];
    let mut g = c.benchmark_group(format!("{group}/eval"));
    g.sample_size(20)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    for (name, f, args) in all {
        let t = Instant::now();
        let native = f.jit().unwrap();
        let compile = t.elapsed().as_secs_f64();
        let (mut tape_us, mut jit_us) = (Vec::new(), Vec::new());
        for _ in 0..3 {
            tape_us.push(per_call(f, args).0);
            jit_us.push(per_call(&native, args).0);
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[1]
        };
        let (t_tape, t_jit) = (median(&mut tape_us), median(&mut jit_us));
        eprintln!(
            "{group} {name:6} instructions {:7}  jit compile {:8.1} ms  tape {t_tape:9.2} us  jit {t_jit:8.2} us  jit/tape {:.3}",
            f.instruction_count(),
            1e3 * compile,
            t_jit / t_tape
        );
        for (evaluator, f) in [("tape", f), ("jit", &native)] {
            let mut out = vec![0.0; f.output_sizes()[0]];
            let mut work = vec![0.0; f.work_size()];
            g.bench_function(BenchmarkId::new(name, evaluator), |b| {
                b.iter(|| {
                    f.eval(black_box(args), &mut [&mut out], &mut work).unwrap();
                    black_box(&out);
                })
            });
        }
    }
    g.finish();
}

/// `native_chain`, `native_gap`, `native_quadrotor`, `native_quadrotor_calls` (`cargo
/// bench --bench symx_eval -- native`): tape vs JIT on the hanging chain (1000 links), the
/// gap-crossing model and the quadrotor OCP at N = 320 (the issue's size; RK4 inlined, or
/// called through one compiled step).
fn bench_native(c: &mut Criterion) {
    native_problems("native", NATIVE_STAGES, |group, fns, ins| {
        native_versus_tape(c, group, fns, ins)
    });
}

/// Builds each of the native groups' problems that the filter selects — `{prefix}_chain`
/// (1000 links), `{prefix}_gap` (the gap-crossing model at its initial point) and
/// `{prefix}_quadrotor` and `{prefix}_quadrotor_calls` (`stages` stages, RK4 inlined or
/// called) — and runs `bench` on its group
/// name, its compiled ∇f, J and H, and their inputs `[x, σ, λ]`.
fn native_problems(
    prefix: &str,
    stages: usize,
    mut bench: impl FnMut(&str, &Compiled, [&[f64]; 3]),
) {
    let group = |problem: &str| format!("{prefix}_{problem}");
    if selected(&format!("{}/eval/hess_L", group("chain"))) {
        let (p, x0) = chain(LINKS);
        let fns = compile(&differentiate(p));
        let (x, sigma, lambda) = inputs(LINKS, &x0);
        bench(&group("chain"), &fns, [&x, &sigma, &lambda]);
    }
    if selected(&format!("{}/eval/hess_L", group("gap"))) {
        let m = gap_model(&gap_scenario());
        let fns = compile(&differentiate(gap_symbolic(&m)));
        let compiled = m.problem.compile().unwrap();
        let mut x0 = vec![0.0; compiled.n()];
        compiled.initial_point(&mut x0);
        let (x, sigma, lambda) = inputs(compiled.m(), &x0);
        bench(&group("gap"), &fns, [&x, &sigma, &lambda]);
    }
    for (problem, calls) in [("quadrotor", false), ("quadrotor_calls", true)] {
        if selected(&format!("{}/eval/hess_L", group(problem))) {
            let (fns, x, sigma, lambda) = quadrotor_native(stages, calls);
            bench(&group(problem), &fns, [&x, &sigma, &lambda]);
        }
    }
}

/// The quadrotor OCP with `stages` stages — the RK4 step inlined at every stage, or
/// (`calls`) one compiled step called at every stage, as CasADi's `F.map` form of
/// `native_casadi.py --problem quadrotor_calls` — its compiled ∇f, J and H, and the
/// inputs `[x, σ, λ]`.
fn quadrotor_native(stages: usize, calls: bool) -> (Compiled, Vec<f64>, [f64; 1], Vec<f64>) {
    let o = quadrotor_ocp::build(stages, calls);
    let fns = compile(&differentiate(Symbolic {
        f: o.f,
        g: o.g,
        x: o.w,
    }));
    let m = (stages + 1) * quadrotor_ocp::NX;
    let (x, sigma, lambda) = inputs(m, &quadrotor_ocp::point(stages));
    (fns, x, sigma, lambda)
}

/// Rustc's flags for the generated programs: what `cargo build --release` passes for this
/// workspace's release profile (opt-level 3, 16 codegen units, no debug info).
const RELEASE_FLAGS: [&str; 8] = [
    "--edition",
    "2021",
    "-C",
    "opt-level=3",
    "-C",
    "codegen-units=16",
    "-C",
    "debuginfo=0",
];

/// The `main` of a generated program: reads every function's inputs (the binary file
/// `argv[1]`, the functions' inputs one after the other), writes every output once to
/// `argv[2]`, then answers each stdin line `k iters` with the nanoseconds that `iters`
/// calls of function `k` took.
const PROGRAM_MAIN: &str = r#"
type Eval = fn(&[&[f64]], &mut [&mut [f64]], &mut [f64]) -> Result<(), &'static str>;

fn main() {
    use std::io::{BufRead, Write};
    let args: Vec<String> = std::env::args().collect();
    let bytes = std::fs::read(&args[1]).expect("inputs");
    let data: Vec<f64> = bytes.chunks(8).map(|b| f64::from_le_bytes(b.try_into().unwrap())).collect();
    let mut at = 0;
    let mut runs = Vec::new();
    let mut written = Vec::new();
    for (eval, ins, outs, work) in FUNCTIONS {
        let inputs: Vec<Vec<f64>> = ins.iter().map(|&n| { at += n; data[at - n..at].to_vec() }).collect();
        let mut outputs: Vec<Vec<f64>> = outs.iter().map(|&n| vec![0.0; n]).collect();
        let mut work = vec![0.0; work];
        {
            let i: Vec<&[f64]> = inputs.iter().map(|v| v.as_slice()).collect();
            let mut o: Vec<&mut [f64]> = outputs.iter_mut().map(|v| v.as_mut_slice()).collect();
            eval(&i, &mut o, &mut work).expect("eval");
        }
        for v in &outputs { for x in v { written.extend_from_slice(&x.to_le_bytes()); } }
        runs.push((eval, inputs, outputs, work));
    }
    std::fs::write(&args[2], written).expect("outputs");
    let stdout = std::io::stdout();
    for line in std::io::stdin().lock().lines() {
        let line = line.unwrap();
        let mut it = line.split_whitespace().map(|t| t.parse::<usize>().unwrap());
        let (k, iters) = (it.next().unwrap(), it.next().unwrap());
        let (eval, inputs, outputs, work) = &mut runs[k];
        let i: Vec<&[f64]> = inputs.iter().map(|v| v.as_slice()).collect();
        let mut o: Vec<&mut [f64]> = outputs.iter_mut().map(|v| v.as_mut_slice()).collect();
        let t = std::time::Instant::now();
        for _ in 0..iters {
            eval(std::hint::black_box(&i), &mut o, work).unwrap();
            std::hint::black_box(&o);
        }
        writeln!(stdout.lock(), "{}", t.elapsed().as_nanos()).unwrap();
    }
}
"#;

/// Generated Rust (`Function::to_rust`) of several functions compiled into one program
/// that runs as a child process: `time(k, iters)` is the wall time of `iters` calls of
/// function `k` measured inside the program (no process or pipe cost), for criterion's
/// `iter_custom`.
struct GeneratedRust {
    child: std::process::Child,
    stdin: std::process::ChildStdin,
    stdout: std::io::BufReader<std::process::ChildStdout>,
    /// Rustc's wall time (s).
    compile: f64,
    /// Bytes of generated Rust.
    bytes: usize,
}

impl GeneratedRust {
    /// Generates and compiles the program for `fns` (each with its inputs), starts it and
    /// checks its outputs against the tape bit for bit (no NaN occurs at the bench points).
    fn start(tag: &str, fns: &[(&Function, &[&[f64]])]) -> GeneratedRust {
        use std::fmt::Write as _;
        use std::process::{Command, Stdio};
        let dir =
            std::env::temp_dir().join(format!("symx_native_rust_{}_{tag}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut src = String::from("#![allow(clippy::all, unused)]\n");
        let mut table = String::new();
        let mut inputs = Vec::new();
        for (k, (f, ins)) in fns.iter().enumerate() {
            writeln!(src, "mod f{k} {{\n{}\n}}", f.to_rust().unwrap()).unwrap();
            write!(
                table,
                "(f{k}::eval as Eval, &f{k}::INPUT_SIZES, &f{k}::OUTPUT_SIZES, f{k}::WORK_SIZE), "
            )
            .unwrap();
            inputs.extend(
                ins.iter()
                    .flat_map(|v| v.iter())
                    .flat_map(|v| v.to_le_bytes()),
            );
        }
        writeln!(
            src,
            "const FUNCTIONS: [(Eval, &[usize], &[usize], usize); {}] = [{table}];",
            fns.len()
        )
        .unwrap();
        src.push_str(PROGRAM_MAIN);
        std::fs::write(dir.join("main.rs"), &src).unwrap();
        std::fs::write(dir.join("inputs.bin"), inputs).unwrap();
        let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
        let t = Instant::now();
        let status = Command::new(rustc)
            .args(RELEASE_FLAGS)
            .arg("-o")
            .arg(dir.join("main"))
            .arg(dir.join("main.rs"))
            .status()
            .expect("rustc runs");
        assert!(
            status.success(),
            "{tag}: the generated Rust does not compile"
        );
        let compile = t.elapsed().as_secs_f64();
        let mut child = Command::new(dir.join("main"))
            .arg(dir.join("inputs.bin"))
            .arg(dir.join("outputs.bin"))
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let (stdin, stdout) = (child.stdin.take().unwrap(), child.stdout.take().unwrap());
        let mut run = GeneratedRust {
            child,
            stdin,
            stdout: std::io::BufReader::new(stdout),
            compile,
            bytes: src.len(),
        };
        run.time(0, 1); // the outputs file is complete once the program answers
        let bits: Vec<u64> = std::fs::read(dir.join("outputs.bin"))
            .unwrap()
            .chunks(8)
            .map(|b| u64::from_le_bytes(b.try_into().unwrap()))
            .collect();
        let want: Vec<u64> = fns
            .iter()
            .flat_map(|(f, ins)| f.call(ins).unwrap().concat())
            .map(f64::to_bits)
            .collect();
        assert!(
            bits == want,
            "{tag}: the generated Rust's outputs differ from the tape's"
        );
        if std::env::var_os("SYMX_NATIVE_RUST_KEEP").is_some() {
            eprintln!("{tag}: generated program kept in {}", dir.display());
        } else {
            let _ = std::fs::remove_dir_all(&dir);
        }
        run
    }

    /// Wall time of `iters` calls of function `k`, measured by the program.
    fn time(&mut self, k: usize, iters: u64) -> Duration {
        use std::io::{BufRead, Write};
        writeln!(self.stdin, "{k} {iters}").unwrap();
        self.stdin.flush().unwrap();
        let mut line = String::new();
        self.stdout.read_line(&mut line).unwrap();
        Duration::from_nanos(line.trim().parse().unwrap())
    }

    /// Per-call median (µs) of 7 repetitions of `calls` calls each (as [`per_call`]
    /// but timed per repetition, not per call).
    fn per_call(&mut self, k: usize, calls: u64) -> f64 {
        let mut v: Vec<f64> = (0..7)
            .map(|_| self.time(k, calls).as_secs_f64() * 1e6 / calls as f64)
            .collect();
        v.sort_by(f64::total_cmp);
        v[3]
    }
}

impl Drop for GeneratedRust {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The same per-call median as [`GeneratedRust::per_call`] for a symx evaluator.
fn per_call_batch(f: &Function, ins: &[&[f64]], calls: u64) -> f64 {
    let mut out = vec![0.0; f.output_sizes()[0]];
    let mut work = vec![0.0; f.work_size()];
    let mut v: Vec<f64> = (0..7)
        .map(|_| {
            let t = Instant::now();
            hot_loop(f, ins, &mut out, &mut work, calls as usize);
            t.elapsed().as_secs_f64() * 1e6 / calls as f64
        })
        .collect();
    v.sort_by(f64::total_cmp);
    v[3]
}

/// Tape, JIT and generated Rust on ∇f, ∂g/∂x and the Hessian of one problem: prints the
/// rustc and JIT compile times, the per-call medians of the three measured alternately
/// (3 rounds, median of rounds) and generated Rust / JIT, then times the three in the
/// criterion group `{group}/eval`.
fn native_rust_versus_jit(c: &mut Criterion, group: &str, fns: &Compiled, ins: [&[f64]; 3]) {
    let all: [(&str, &Function, &[&[f64]]); 3] = [
        ("grad_f", &fns.grad, &ins[..1]),
        ("jac_g", &fns.jac, &ins[..1]),
        ("hess_L", &fns.hess, &ins[..]),
    ];
    let pairs: Vec<(&Function, &[&[f64]])> = all.iter().map(|&(_, f, a)| (f, a)).collect();
    let mut rust = GeneratedRust::start(group, &pairs);
    eprintln!(
        "{group} generated Rust {:.1} MB, rustc (release settings) {:.1} s",
        rust.bytes as f64 / 1e6,
        rust.compile
    );
    let mut g = c.benchmark_group(format!("{group}/eval"));
    g.sample_size(20)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_secs(1));
    for (k, (name, f, args)) in all.into_iter().enumerate() {
        let t = Instant::now();
        let native = f.jit().unwrap();
        let compile = t.elapsed().as_secs_f64();
        let t = Instant::now();
        f.call(args).unwrap();
        let calls = ((0.05 / t.elapsed().as_secs_f64()) as u64).clamp(10, 2000);
        let mut rounds = [Vec::new(), Vec::new(), Vec::new()];
        for _ in 0..3 {
            rounds[0].push(per_call_batch(f, args, calls));
            rounds[1].push(per_call_batch(&native, args, calls));
            rounds[2].push(rust.per_call(k, calls));
        }
        let [tape, jit, gen] = rounds.map(|mut v| {
            v.sort_by(f64::total_cmp);
            v[1]
        });
        eprintln!(
            "{group} {name:6} jit compile {:8.1} ms  tape {tape:9.2} us  jit {jit:8.2} us  rust {gen:8.2} us  rust/jit {:.3}",
            1e3 * compile,
            gen / jit
        );
        for (evaluator, f) in [("tape", f), ("jit", &native)] {
            let mut out = vec![0.0; f.output_sizes()[0]];
            let mut work = vec![0.0; f.work_size()];
            g.bench_function(BenchmarkId::new(name, evaluator), |b| {
                b.iter(|| {
                    f.eval(black_box(args), &mut [&mut out], &mut work).unwrap();
                    black_box(&out);
                })
            });
        }
        g.bench_function(BenchmarkId::new(name, "rust"), |b| {
            b.iter_custom(|iters| rust.time(k, iters))
        });
    }
    g.finish();
}

/// `native_rust_chain`, `native_rust_gap`, `native_rust_quadrotor` (`cargo bench --bench
/// symx_eval -- native_rust`): tape, JIT and generated Rust on the problems of
/// [`bench_native`] (the quadrotor at `SYMX_NATIVE_RUST_STAGES` stages, default
/// [`NATIVE_STAGES`]). Run only when a filter names them: rustc takes minutes on the
/// larger problems.
fn bench_native_rust(c: &mut Criterion) {
    // Only when named (rustc takes minutes on the larger problems).
    if !std::env::args().skip(1).any(|a| a.contains("native_rust")) {
        return;
    }
    let stages = std::env::var("SYMX_NATIVE_RUST_STAGES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(NATIVE_STAGES);
    native_problems("native_rust", stages, |group, fns, ins| {
        native_rust_versus_jit(c, group, fns, ins)
    });
}

/// `native_compile` (`cargo bench --bench symx_eval -- native_compile`): the JIT's
/// compile time of ∇f, ∂g/∂x and the Hessian against their size, on the hanging chain and
/// the quadrotor OCP (inlined RK4) at several sizes and on the gap model: one line per
/// function with the instructions, the compile time (median of 3) and the time per 1000
/// instructions, which stays flat when compile time is linear in the size.
fn bench_native_compile(_c: &mut Criterion) {
    if !selected("native_compile") {
        return;
    }
    let report = |problem: String, fns: &Compiled| {
        for (name, f) in [
            ("grad_f", &fns.grad),
            ("jac_g", &fns.jac),
            ("hess_L", &fns.hess),
        ] {
            let mut ms: Vec<f64> = (0..3)
                .map(|_| {
                    let t = Instant::now();
                    black_box(f.jit().unwrap());
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect();
            ms.sort_by(f64::total_cmp);
            let n = f.instruction_count();
            eprintln!(
                "native_compile {problem:16} {name:6} instructions {n:8}  compile {:9.2} ms  {:6.3} ms per 1000 instructions",
                ms[1],
                1e3 * ms[1] / n as f64
            );
        }
    };
    for links in [125, 250, 500, 1000, 2000] {
        report(
            format!("chain_{links}"),
            &compile(&differentiate(chain(links).0)),
        );
    }
    for stages in [10, 20, 40, 80] {
        let o = quadrotor_ocp::build(stages, false);
        let fns = compile(&differentiate(Symbolic {
            f: o.f,
            g: o.g,
            x: o.w,
        }));
        report(format!("quadrotor_{stages}"), &fns);
    }
    let m = gap_model(&gap_scenario());
    report("gap".into(), &compile(&differentiate(gap_symbolic(&m))));
}

criterion_group!(
    benches,
    bench,
    bench_gap,
    bench_ocp,
    bench_map,
    bench_native,
    bench_native_rust,
    bench_native_compile
);

/// With `SYMX_OCP_MEMORY=inlined | calls | none` in the environment the binary builds,
/// differentiates and compiles the `ocp_chain` problem once (or, for `none`, nothing),
/// prints the sizes and exits without benchmarking: run under `/usr/bin/time -v`, its
/// maximum resident set is the peak memory of one set-up (`none`: the binary's baseline).
/// benches/reference/ocp_compare.sh does this.
fn memory_run(mode: &str) {
    let calls = match mode {
        "inlined" => false,
        "calls" => true,
        "none" => return,
        other => {
            eprintln!("SYMX_OCP_MEMORY={other}: expected inlined, calls or none");
            std::process::exit(2);
        }
    };
    let fns = compile(&differentiate(ocp_symbolic(calls)));
    eprintln!(
        "ocp_chain {mode}: {} graph nodes; instructions grad_f {} jac_g {} hess_L {}",
        symx::node_count(),
        fns.grad.instruction_count(),
        fns.jac.instruction_count(),
        fns.hess.instruction_count()
    );
}

/// With `SYMX_NATIVE_PROFILE=problem:function:evaluator:calls` in the environment
/// (`problem` one of `gap`, `quadrotor`, `quadrotor_calls`, `chain`; `function` one of `grad_f`, `jac_g`,
/// `hess_L`; `evaluator` `tape` or `jit`), the binary calls that function `calls` times
/// inside [`hot_loop`] and exits: run under `valgrind --tool=callgrind
/// --collect-atstart=no --toggle-collect='*hot_loop*'`, the instructions counted divided by
/// `calls` are the instructions per call (benches/reference/native_side_by_side.sh). It
/// then prints the per-call median wall time of [`per_call`]. With `SYMX_NATIVE_SAVE=DIR`
/// it first saves the function's tape to `DIR/{problem}_{function}.json`
/// (`Function::save`); with `SYMX_NATIVE_PAUSE=S` it prints `ready` and sleeps `S`
/// seconds before the loop, so that a long JIT compilation can run under `valgrind
/// --instr-atstart=no` and instrumentation be switched on (`callgrind_control -i on`)
/// only then.
fn profile_run(spec: &str) {
    let parts: Vec<&str> = spec.split(':').collect();
    let [problem, function, evaluator, calls] = parts[..] else {
        eprintln!("SYMX_NATIVE_PROFILE={spec}: expected problem:function:evaluator:calls");
        std::process::exit(2);
    };
    let (fns, x, sigma, lambda) = match problem {
        "gap" => {
            let m = gap_model(&gap_scenario());
            let fns = compile(&differentiate(gap_symbolic(&m)));
            let compiled = m.problem.compile().unwrap();
            let mut x0 = vec![0.0; compiled.n()];
            compiled.initial_point(&mut x0);
            let (x, s, l) = inputs(compiled.m(), &x0);
            (fns, x, s, l)
        }
        "quadrotor" => quadrotor_native(NATIVE_STAGES, false),
        "quadrotor_calls" => quadrotor_native(NATIVE_STAGES, true),
        "chain" => {
            let (p, x0) = chain(LINKS);
            let fns = compile(&differentiate(p));
            let (x, s, l) = inputs(LINKS, &x0);
            (fns, x, s, l)
        }
        other => {
            eprintln!(
                "SYMX_NATIVE_PROFILE: unknown problem '{other}' (gap, quadrotor, quadrotor_calls, chain)"
            );
            std::process::exit(2);
        }
    };
    let all = [&x[..], &sigma[..], &lambda[..]];
    let (f, args) = match function {
        "grad_f" => (&fns.grad, &all[..1]),
        "jac_g" => (&fns.jac, &all[..1]),
        "hess_L" => (&fns.hess, &all[..]),
        other => {
            eprintln!("SYMX_NATIVE_PROFILE: unknown function '{other}' (grad_f, jac_g, hess_L)");
            std::process::exit(2);
        }
    };
    let native;
    let f = match evaluator {
        "tape" => f,
        "jit" => {
            let t = Instant::now();
            native = f.jit().unwrap();
            let (n, ms) = (f.instruction_count(), t.elapsed().as_secs_f64() * 1e3);
            eprintln!("{problem} {function}: {n} instructions, jit compile {ms:.1} ms");
            &native
        }
        other => {
            eprintln!("SYMX_NATIVE_PROFILE: unknown evaluator '{other}' (tape, jit)");
            std::process::exit(2);
        }
    };
    if let Ok(dir) = std::env::var("SYMX_NATIVE_SAVE") {
        let path = std::path::Path::new(&dir).join(format!("{problem}_{function}.json"));
        f.save(&path).unwrap();
        eprintln!("saved {}", path.display());
    }
    let calls: usize = calls.parse().unwrap_or(100);
    let mut out = vec![0.0; f.output_sizes()[0]];
    let mut work = vec![0.0; f.work_size()];
    if let Ok(seconds) = std::env::var("SYMX_NATIVE_PAUSE") {
        // For valgrind --instr-atstart=no: time to run `callgrind_control -i on`.
        eprintln!("ready");
        std::thread::sleep(Duration::from_secs(seconds.parse().unwrap_or(10)));
    }
    hot_loop(f, args, &mut out, &mut work, calls);
    let sum: f64 = out.iter().sum();
    let (median, _) = per_call(f, args);
    eprintln!(
        "{problem} {function} {evaluator}: {calls} calls, sum {sum:.16e}, per-call median {median:.3} us"
    );
}

/// `calls` evaluations of `f` (the region callgrind counts in [`profile_run`]).
#[inline(never)]
fn hot_loop(f: &Function, args: &[&[f64]], out: &mut [f64], work: &mut [f64], calls: usize) {
    for _ in 0..calls {
        f.eval(black_box(args), &mut [&mut *out], work).unwrap();
        black_box(&out);
    }
}

fn main() {
    if let Ok(mode) = std::env::var("SYMX_OCP_MEMORY") {
        memory_run(&mode);
        return;
    }
    if let Ok(spec) = std::env::var("SYMX_NATIVE_PROFILE") {
        profile_run(&spec);
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
