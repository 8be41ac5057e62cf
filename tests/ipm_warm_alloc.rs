//! What an `Ipm` keeps between warm re-solves of the cart-pole MPC
//! (examples/src/mpc_cart_pole.rs): the iterates of `Ipm::solve_warm_into` are
//! bit-identical to a fresh solver's `solve_warm` at every step of the closed loop, and
//! once the kept buffers (and the reused `Solution`'s vectors) have grown to the largest
//! iteration count seen, a re-solve allocates nothing (counted by a counting global
//! allocator). The binary has no libtest harness (`harness = false`): the harness's main
//! thread allocates while a test runs (see symx/tests/map_alloc.rs).
//!
//! Then the same through `Mpc::step`: its closed loop is bit-identical to the loop
//! written out with `Transcription::shift` and `Ipm::solve_warm` (what `Mpc::step` did
//! before it re-solved into kept vectors), and a step that takes no more iterations
//! than an earlier one allocates nothing.
use symnlp_examples::mpc_cart_pole;

use symnlp::nlp::mpc::Mpc;
use symnlp::nlp::ocp::Transcription;
use symnlp::nlp::{Compiled, Ipm, Solution};
use testkit::alloc::{check_warm_re_solves, Counting, ReSolveCount};

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
    compiled.set_value("x0", &x).expect("x0 parameter");
    // The solution the kept solver writes into at every step.
    let mut sol = kept.solve(&mut compiled).expect("first solve");
    let mut counts = Vec::new();
    // The most iterations of a re-solve so far: the kept vectors have grown to it.
    let mut most_iterations = 0;
    for step in 0..STEPS {
        if step > 0 {
            compiled.set_value("x0", &x).expect("x0 parameter");
            let shifted = tr.shift(&sol).expect("shift");
            let (a, n_fresh) = allocations_during(|| fresh_resolve(&mut compiled, &shifted));
            let ((), n_kept) =
                allocations_during(|| kept_resolve(&kept, &mut compiled, &shifted, &mut sol));
            assert_identical(&sol, &a, step);
            let grown = sol.stats.iterations > most_iterations;
            most_iterations = most_iterations.max(sol.stats.iterations);
            counts.push(ReSolveCount {
                kept: n_kept,
                fresh: n_fresh,
                grew: grown,
            });
        }
        assert!(sol.status.is_success(), "step {step}: {}", sol.status);
        let u: Vec<f64> = first_control(&tr, &sol);
        x = plant.step(&x, &u, example.dt).expect("plant");
    }
    // From the second re-solve on, a re-solve that takes no more iterations than an
    // earlier one allocates nothing; one that takes more may only grow the vectors
    // whose length follows the iteration count (iteration records, filter), and still
    // allocates less than a fresh solver.
    check_warm_re_solves("ipm_warm_alloc", &counts);
    mpc_steps();
}

/// `Mpc::step` with the IPM over the closed loop: bit-identical to the loop written out
/// with a new `Solution` per step, and allocation-free in the steady state.
fn mpc_steps() {
    let example = mpc_cart_pole::example();
    let (tr, mut plant) = example.setup().expect("cart-pole MPC transcription");
    let mut mpc = Mpc::new(&tr, Box::new(Ipm::default())).expect("controller");
    // The reference: the step as written before, a fresh `Solution` from `solve_warm`.
    let mut compiled = tr.compile().expect("compile");
    let shift = tr.shift_plan().expect("shift plan");
    let ipm = Ipm::default();
    let mut reference: Option<Solution> = None;
    let mut x = example.x_init.clone();
    let (mut most_iterations, mut zero_steps) = (0, 0);
    for step in 0..STEPS {
        let (report, count) = allocations_during(|| mpc.step(&x).expect("MPC step"));
        compiled.set_value("x0", &x).expect("x0 parameter");
        let expected = match reference.take() {
            Some(mut prev) => {
                shift.apply(&mut prev).expect("shift");
                ipm.solve_warm(&mut compiled, &prev).expect("warm re-solve")
            }
            None => ipm.solve(&mut compiled).expect("first solve"),
        };
        assert_identical(mpc.solution().expect("a plan"), &expected, step);
        assert_eq!(
            report.status, expected.status,
            "step {step}: reported status"
        );
        let u = first_control(&tr, &expected);
        assert!(same_bits(mpc.control(), &u), "step {step}: control");
        // Step 0 solves cold, step 1 is the first into the kept vectors.
        if step >= 2 && report.iterations <= most_iterations {
            assert_eq!(count, 0, "step {step}: allocations in Mpc::step");
            zero_steps += 1;
        }
        if step >= 1 {
            most_iterations = most_iterations.max(report.iterations);
        }
        x = plant.step(&x, &u, example.dt).expect("plant");
        reference = Some(expected);
    }
    assert!(
        zero_steps >= STEPS / 2,
        "only {zero_steps} allocation-free MPC steps"
    );
    println!(
        "ipm_warm_alloc: {STEPS} Mpc::step steps bit-identical to the written-out loop; \
         {zero_steps} steady-state steps with 0 allocations"
    );
}

/// A warm re-solve by a new solver (a function of its own for callgrind's per-function
/// counts: `valgrind --tool=callgrind` on this binary).
#[inline(never)]
fn fresh_resolve(compiled: &mut Compiled, warm: &Solution) -> Solution {
    Ipm::default().solve_warm(compiled, warm).unwrap()
}

/// A warm re-solve by the solver that keeps its workspace, into `out`.
#[inline(never)]
fn kept_resolve(ipm: &Ipm, compiled: &mut Compiled, warm: &Solution, out: &mut Solution) {
    ipm.solve_warm_into(compiled, warm, out).unwrap()
}

/// Closed-loop steps checked.
const STEPS: usize = 30;

/// The first control of the plan.
fn first_control(tr: &Transcription, sol: &Solution) -> Vec<f64> {
    let u = tr.controls().column(0).expect("first control");
    let idx = tr.problem().variable_indices(&u).expect("control indices");
    idx.iter().map(|&j| sol.x[j]).collect()
}
