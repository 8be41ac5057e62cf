//! nlp::integrator on the problems of `benches/reference/integrator_casadi.py` at the same
//! tolerances (rtol 1e-6, atol 1e-8), with each method (DOPRI5 and SDIRK4): final state,
//! error against the CVODES reference
//! (rtol 1e-12), steps, and the median wall time of 15 integrations (3 for DOPRI5 on the
//! stiff problems). Run both with
//! `bash benches/reference/integrator_compare.sh`.
//!
//! Run: `cargo run --release -p symnlp-examples --example integrator_compare`
use std::time::Instant;
use symnlp::nlp::integrator::{Integrator, IntegratorOptions, Method};
use symnlp::symx::{Function, Matrix};

/// A test problem: name, right-hand side, x0, p, T, CVODES reference x(T).
type Case<'a> = (&'a str, &'a Function, Vec<f64>, Vec<f64>, f64, Vec<f64>);

/// The example's program (`examples/examples/integrator_compare.rs` runs it).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let x = Matrix::sym_vec("x", 2);
    let mu = Matrix::sym_vec("mu", 1);
    let vdp = Function::new(
        &[&x, &mu],
        &[&[x[1], mu[0] * (1.0 - x[0].sq()) * x[1] - x[0]]],
    )?;
    let y = Matrix::sym_vec("y", 3);
    let k = Matrix::sym_vec("k", 3);
    let rob = Function::new(
        &[&y, &k],
        &[&[
            -k[0] * y[0] + k[1] * y[1] * y[2],
            k[0] * y[0] - k[1] * y[1] * y[2] - k[2] * y[1].sq(),
            k[2] * y[1].sq(),
        ]],
    )?;
    // (name, ode, x0, p, T, CVODES reference x(T) from integrator_casadi.json)
    let problems: [Case; 5] = [
        (
            "vdp1",
            &vdp,
            vec![2.0, 0.0],
            vec![1.0],
            5.0,
            vec![-0.837077450319517, 1.307088937732762],
        ),
        (
            "vdp1000",
            &vdp,
            vec![2.0, 0.0],
            vec![1000.0],
            1000.0,
            vec![-1.863646254659922, 0.0007535430866519365],
        ),
        (
            "robertson",
            &rob,
            vec![1.0, 0.0, 0.0],
            vec![0.04, 1e4, 3e7],
            40.0,
            vec![0.715827068728157, 9.185534764897851e-06, 0.2841637457370807],
        ),
        (
            "robertson4e10",
            &rob,
            vec![1.0, 0.0, 0.0],
            vec![0.04, 1e4, 3e7],
            4e10,
            vec![
                5.208350619626837e-08,
                2.0833403550567559e-13,
                0.9999999479162838,
            ],
        ),
        (
            "vdp1000_2000",
            &vdp,
            vec![2.0, 0.0],
            vec![1000.0],
            2000.0,
            vec![1.70616773177563, -0.0008928097014476553],
        ),
    ];
    let options = IntegratorOptions {
        rtol: 1e-6,
        atol: 1e-8,
        max_steps: 10_000_000,
        ..IntegratorOptions::default()
    };
    for (name, ode, x0, p, t, reference) in problems {
        for method in [Method::Dopri5, Method::Sdirk4] {
            // DOPRI5 on the stiff problems takes seconds a run: 3 runs there, else 15; on
            // the two long stiff ones it does not finish in reasonable time: skipped.
            let runs = match (method, name) {
                (Method::Dopri5, "robertson4e10" | "vdp1000_2000") => continue,
                (Method::Dopri5, "vdp1000" | "robertson") => 3,
                _ => 15,
            };
            let int = Integrator::new(ode, 0.0, t, IntegratorOptions { method, ..options })?;
            let mut times = Vec::new();
            let mut last = None;
            for _ in 0..runs {
                let start = Instant::now();
                last = Some(int.simulate(&x0, &p)?);
                times.push(start.elapsed().as_secs_f64());
            }
            times.sort_by(f64::total_cmp);
            let (xf, stats) = last.expect("at least one run");
            let err = xf
                .iter()
                .zip(&reference)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            println!(
                "{name} {method:?}: xf {xf:?}, max |error| vs CVODES(1e-12) {err:.2e}, steps {} accepted + {} rejected, {} f evals, {} Jacobians, {} LU, median of {runs} {:.6} s",
                stats.accepted, stats.rejected, stats.rhs_evaluations, stats.jacobians, stats.factorizations, times[runs / 2]
            );
        }
    }
    Ok(())
}
