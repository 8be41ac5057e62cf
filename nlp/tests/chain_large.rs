//! The hanging chain of benches/solve.rs at one size (default 50 000 links), with the
//! iteration log. Ignored: `CHAIN_N=50000 cargo test --release -p nlp --test chain_large -- --ignored --nocapture`.

// The benchmark's own builder, so the test and benches/solve.rs cannot drift apart.
#[path = "../../benches/common/solve_problems.rs"]
mod solve_problems;

use nlp::{Ipm, IpmOptions};
use solve_problems::hanging_chain;

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
