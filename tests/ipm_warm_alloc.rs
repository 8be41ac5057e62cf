//! What an `Ipm` keeps between warm re-solves of the cart-pole MPC
//! (examples/mpc_cart_pole.rs): the iterates are bit-identical to a fresh solver's at
//! every step of the closed loop, and a re-solve with the kept KKT analysis allocates
//! less than a fresh solver's (counted by a counting global allocator). The binary has
//! no libtest harness (`harness = false`): the harness's main thread allocates while a
//! test runs (see symx/tests/map_alloc.rs).
#![allow(dead_code)] // the example's `main` is not called here

#[path = "../examples/mpc_cart_pole.rs"]
mod mpc_cart_pole;

use symnlp::nlp::ocp::Transcription;
use symnlp::nlp::{Compiled, Ipm, Solution};
use testkit::alloc::Counting;

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_during<T>(f: impl FnOnce() -> T) -> (T, usize) {
    Counting::during(f)
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn assert_identical(kept: &Solution, fresh: &Solution, step: usize) {
    assert_eq!(kept.status, fresh.status, "step {step}: status");
    assert_eq!(
        kept.stats.iterations, fresh.stats.iterations,
        "step {step}: iterations"
    );
    for (what, a, b) in [
        ("x", &kept.x, &fresh.x),
        ("lambda", &kept.lambda, &fresh.lambda),
        ("z_l", &kept.z_l, &fresh.z_l),
        ("z_u", &kept.z_u, &fresh.z_u),
    ] {
        assert!(
            same_bits(a, b),
            "step {step}: {what} differs from a fresh solver's"
        );
    }
}

fn main() {
    let example = mpc_cart_pole::example();
    let (tr, mut plant) = example.setup().expect("cart-pole MPC transcription");
    let mut compiled = tr.compile().expect("compile");
    // The solver that keeps its workspace across the loop, and a fresh one every step.
    let kept = Ipm::default();
    let mut x = example.x_init.clone();
    let mut previous: Option<Solution> = None;
    let mut counts = Vec::new();
    for step in 0..STEPS {
        compiled.set_value("x0", &x).expect("x0 parameter");
        let sol = match &previous {
            None => kept.solve(&mut compiled).expect("first solve"),
            Some(prev) => {
                let shifted = tr.shift(prev).expect("shift");
                let (a, n_fresh) = allocations_during(|| fresh_resolve(&mut compiled, &shifted));
                let (b, n_kept) =
                    allocations_during(|| kept_resolve(&kept, &mut compiled, &shifted));
                assert_identical(&b, &a, step);
                counts.push((n_kept, n_fresh));
                b
            }
        };
        assert!(sol.status.is_success(), "step {step}: {}", sol.status);
        let u: Vec<f64> = first_control(&tr, &sol);
        x = plant.step(&x, &u, example.dt).expect("plant");
        previous = Some(sol);
    }
    // The kept analysis is used: every re-solve allocates less than a fresh solver's.
    for (step, &(n_kept, n_fresh)) in counts.iter().enumerate() {
        assert!(
            n_kept < n_fresh,
            "step {}: {n_kept} allocations with the kept workspace, {n_fresh} without",
            step + 1
        );
    }
    let median = |mut v: Vec<usize>| {
        v.sort_unstable();
        v[v.len() / 2]
    };
    println!(
        "ipm_warm_alloc: {STEPS} closed-loop steps bit-identical to a fresh solver's; \
         allocations per warm re-solve (median): {} kept, {} fresh",
        median(counts.iter().map(|c| c.0).collect()),
        median(counts.iter().map(|c| c.1).collect()),
    );
}

/// A warm re-solve by a new solver (a function of its own for callgrind's per-function
/// counts: `valgrind --tool=callgrind` on this binary).
#[inline(never)]
fn fresh_resolve(compiled: &mut Compiled, warm: &Solution) -> Solution {
    Ipm::default().solve_warm(compiled, warm).unwrap()
}

/// A warm re-solve by the solver that keeps its workspace.
#[inline(never)]
fn kept_resolve(ipm: &Ipm, compiled: &mut Compiled, warm: &Solution) -> Solution {
    ipm.solve_warm(compiled, warm).unwrap()
}

/// Closed-loop steps checked.
const STEPS: usize = 30;

/// The first control of the plan.
fn first_control(tr: &Transcription, sol: &Solution) -> Vec<f64> {
    let u = tr.controls().column(0).expect("first control");
    let idx = tr.problem().variable_indices(&u).expect("control indices");
    idx.iter().map(|&j| sol.x[j]).collect()
}
