//! The hanging chain of benches/solve.rs at one size (default 50 000 links), with the
//! iteration log. Ignored: `CHAIN_N=50000 cargo test --release -p nlp --test chain_large -- --ignored --nocapture`.

use nlp::{Ipm, IpmOptions, Problem, Relation};
use symx::{Expr, Matrix};

fn hanging_chain(links: usize) -> Problem {
    let n = 2 * (links + 1);
    let mut pb = Problem::new();
    let w = pb.variable("w", n);
    let x = |i: usize| w[2 * i];
    let y = |i: usize| w[2 * i + 1];
    let seg2 = (2.0 / links as f64).powi(2);
    let g: Vec<Expr> = (0..links)
        .map(|i| (x(i + 1) - x(i)).sq() + (y(i + 1) - y(i)).sq() - seg2)
        .collect();
    let mut f = y(0);
    for i in 1..=links {
        f += y(i);
    }
    f /= links as f64;
    pb.minimize(f);
    pb.subject_to_named("link", (&Matrix::from_vec(g)).eq(0.0))
        .expect("chain constraints");
    for (k, v) in [(0, 0.0), (1, 0.0), (2 * links, 1.0), (2 * links + 1, 0.0)] {
        pb.set_bounds(&[w[k]], v, v).expect("chain bounds");
    }
    let mut x0 = vec![0.0; n];
    for i in 0..=links {
        let t = i as f64 / links as f64;
        x0[2 * i] = t;
        x0[2 * i + 1] = -0.5 * (std::f64::consts::PI * t).sin();
    }
    pb.set_initial(&w, &x0).expect("chain start");
    pb
}

#[test]
#[ignore]
fn chain_one_size() {
    let links: usize = std::env::var("CHAIN_N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(50_000);
    let mut compiled = hanging_chain(links).compile().expect("compiles");
    let t = std::time::Instant::now();
    let sol = Ipm::new(IpmOptions {
        print_level: 5,
        max_wall_time: 120.0,
        ..IpmOptions::default()
    })
    .solve(&mut compiled)
    .expect("valid problem");
    eprintln!(
        "N={links}: {:?} in {} iterations, {:.2} s, f={}, viol={:e}",
        sol.status,
        sol.stats.iterations,
        t.elapsed().as_secs_f64(),
        sol.objective,
        sol.constr_viol
    );
}
