//! Growth of the symbolic set-up phases with the number of stages, on the inlined
//! quadrotor OCP of testkit/src/quadrotor_ocp.rs (issue 13): each phase (build, ∇f,
//! ∂g/∂w, the lower triangle of ∇²(σf + λᵀg), the three `Function`s) is timed at
//! N = 100, 200, 400, 800 (or the sizes given as arguments), each size in a fresh
//! expression graph (thread CPU time, not wall time), with the graph's node count after each phase; then the growth
//! exponent log(t₂/t₁)/log(N₂/N₁) between consecutive sizes. An exponent near 1 is
//! linear; clearly above 1 is a superlinear phase.
//!
//! Run: `cargo run --release -p symx --example ocp_setup_scaling [N…]`.
use symx::{gradient, jacobian, lagrangian_hessian, node_count, Expr, Function, Matrix};
use testkit::quadrotor_ocp;

const PHASES: [&str; 5] = ["build", "grad_f", "jac_g", "hess_L", "functions"];

/// This thread's CPU time in seconds (the first field of /proc/thread-self/schedstat, in
/// ns): on a shared machine, wall time also counts the waits for a core.
fn cpu_seconds() -> f64 {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").expect("Linux schedstat");
    let ns: f64 = s.split_whitespace().next().unwrap().parse().unwrap();
    ns * 1e-9
}

/// CPU seconds of each phase and nodes after it, for `n` stages, in a fresh graph.
fn phases(n: usize) -> ([f64; 5], [usize; 5]) {
    symx::with_fresh_arena(move || {
        let mut t = [0.0; 5];
        let mut nodes = [0; 5];
        let mut clock = cpu_seconds();
        let mut lap = |k: usize, clock: &mut f64| {
            let now = cpu_seconds();
            t[k] = now - *clock;
            nodes[k] = node_count();
            *clock = now;
        };
        let o = quadrotor_ocp::build(n, false);
        lap(0, &mut clock);
        let grad = gradient(o.f, &o.w).unwrap();
        lap(1, &mut clock);
        let jac = jacobian(&o.g, &o.w).unwrap();
        lap(2, &mut clock);
        let sigma = Expr::sym("sigma");
        let lambda = Matrix::sym_vec("lambda", o.g.len());
        let hess = lagrangian_hessian(o.f, &o.g, &o.w, sigma, &lambda).unwrap();
        lap(3, &mut clock);
        let fns = [
            Function::new(&[&o.w], &[&grad]).unwrap(),
            Function::new(&[&o.w], &[jac.values()]).unwrap(),
            Function::new(&[&o.w, &[sigma], &lambda], &[hess.values()]).unwrap(),
        ];
        lap(4, &mut clock);
        std::hint::black_box(fns);
        (t, nodes)
    })
}

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("stage counts"))
        .collect();
    let sizes = if sizes.is_empty() {
        vec![100, 200, 400, 800]
    } else {
        sizes
    };
    let runs: Vec<_> = sizes.iter().map(|&n| phases(n)).collect();
    println!("{:>6} {}", "N", PHASES.map(|p| format!("{p:>22}")).join(""));
    for (&n, (t, nodes)) in sizes.iter().zip(&runs) {
        let cols: String = (0..5)
            .map(|k| format!("{:>10.1} ms {:>8}k", t[k] * 1e3, nodes[k] / 1000))
            .collect();
        println!("{n:>6} {cols}  total {:.1} ms", t.iter().sum::<f64>() * 1e3);
    }
    println!("growth exponents between consecutive sizes:");
    for w in 0..sizes.len().saturating_sub(1) {
        let r = (sizes[w + 1] as f64 / sizes[w] as f64).ln();
        let e: String = (0..5)
            .map(|k| format!("{:>22.2}", (runs[w + 1].0[k] / runs[w].0[k]).ln() / r))
            .collect();
        let tot = |i: usize| runs[i].0.iter().sum::<f64>();
        println!(
            "{:>6} {e}  total {:.2}",
            format!("{}→{}", sizes[w], sizes[w + 1]),
            (tot(w + 1) / tot(w)).ln() / r
        );
    }
}
