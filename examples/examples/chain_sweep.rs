//! The hanging chain with its length and end heights as parameters, re-solved 20 times,
//! each solve warm-started from the last: the symnlp half of the second line-count pair
//! of docs/casadi.md (issue 22 item 6); the CasADi half is
//! `benches/reference/chain_sweep_casadi.py`. Both print the same energies.
//!
//! Run: `cargo run --release -p symnlp-examples --example chain_sweep`
use symnlp::nlp::{linspace, Ipm, Problem, Relation};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n = 20;
    let mut pb = Problem::new();
    let (x, y) = (pb.variable("x", n + 1)?, pb.variable("y", n + 1)?);
    let p = pb.parameter("p", 3)?; // length, left and right end heights
    pb.minimize(y.sum()); // potential energy of equal masses
    pb.subject_to_all([x[0].eq(0.0), x[n].eq(1.0), y[0].eq(p[1]), y[n].eq(p[2])])?;
    let link = p[0] / n as f64;
    for i in 0..n {
        pb.subject_to(((x[i + 1] - x[i]).sq() + (y[i + 1] - y[i]).sq()).eq(link.sq()))?;
    }
    pb.set_initial(&x, &linspace(0.0, 1.0, n + 1))?;
    pb.set_initial(&y, &linspace(1.0, 0.5, n + 1))?;
    let mut compiled = pb.compile()?;
    for k in 0..20 {
        let (l, b) = (1.5 + 0.05 * k as f64, 0.5 + 0.02 * k as f64);
        compiled.set_value(&p, &[l, 1.0, b])?;
        let sol = Ipm::default().solve(&mut compiled)?;
        println!("L = {l:.2}, b = {b:.2}: energy {:.8}", sol.objective);
        compiled.set_initial_point(&sol.x)?; // warm start the next solve
    }
    Ok(())
}
