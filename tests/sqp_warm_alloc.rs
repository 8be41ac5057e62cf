//! What an `Sqp` keeps between warm re-solves of the cart-pole MPC
//! (examples/src/mpc_cart_pole.rs): the iterates of `Sqp::solve_warm_into` are
//! bit-identical to a fresh solver's `solve_warm` at every step of the closed loop, and a
//! re-solve that takes no more iterations, QP solves and factorisations than an earlier
//! one, and hands no QP to clarabel, allocates nothing (counted by a counting global
//! allocator). The binary has no libtest harness (`harness = false`): the harness's main
//! thread allocates while a test runs (see symx/tests/map_alloc.rs).
use symnlp_examples::mpc_cart_pole;

use symnlp::nlp::ocp::Transcription;
use symnlp::nlp::{Compiled, Solution, Sqp};
use testkit::alloc::{check_warm_re_solves, Counting, ReSolveCount};

#[global_allocator]
static GLOBAL: Counting = Counting;

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn assert_identical(kept: &Solution, fresh: &Solution, step: usize) {
    assert_eq!(kept.status, fresh.status, "step {step}: status");
    let (k, f) = (&kept.stats, &fresh.stats);
    assert_eq!(k.iterations, f.iterations, "step {step}: iterations");
    assert_eq!(k.n_qp_solves, f.n_qp_solves, "step {step}: QP solves");
    for (what, a, b) in [
        ("x", &kept.x, &fresh.x),
        ("lambda", &kept.lambda, &fresh.lambda),
        ("z_l", &kept.z_l, &fresh.z_l),
        ("z_u", &kept.z_u, &fresh.z_u),
        ("g", &kept.g, &fresh.g),
    ] {
        assert!(
            same_bits(a, b),
            "step {step}: {what} differs from a fresh solver's"
        );
    }
}

/// The work of a re-solve that decides which kept vectors had to grow: iterations, QP
/// solves (active-set and clarabel), active-set iterations and factorisations.
fn work(sol: &Solution) -> [usize; 4] {
    let s = &sol.stats;
    [
        s.iterations,
        s.n_qp_solves,
        s.qp_iterations,
        s.n_factorizations,
    ]
}

fn main() {
    let example = mpc_cart_pole::example();
    let (tr, mut plant) = example.setup().expect("cart-pole MPC transcription");
    let mut compiled = tr.compile().expect("compile");
    let kept = Sqp::default();
    let mut x = example.x_init.clone();
    compiled.set_value("x0", &x).expect("x0 parameter");
    let mut sol = kept.solve(&mut compiled).expect("first solve");
    let mut counts = Vec::new();
    // The most work of a re-solve so far, per measure: the kept vectors have grown to it.
    let mut most = [0usize; 4];
    for step in 0..STEPS {
        if step > 0 {
            compiled.set_value("x0", &x).expect("x0 parameter");
            let shifted = tr.shift(&sol).expect("shift");
            let (a, n_fresh) = Counting::during(|| fresh_resolve(&mut compiled, &shifted));
            let ((), n_kept) =
                Counting::during(|| kept_resolve(&kept, &mut compiled, &shifted, &mut sol));
            assert_identical(&sol, &a, step);
            let w = work(&sol);
            let grown = (0..4).any(|k| w[k] > most[k]);
            for k in 0..4 {
                most[k] = most[k].max(w[k]);
            }
            // A QP handed to clarabel (counted in QP solves, not in active-set ones)
            // builds clarabel's solver: allowed to allocate.
            counts.push(ReSolveCount {
                kept: n_kept,
                fresh: n_fresh,
                grew: grown,
            });
        }
        assert!(sol.status.is_success(), "step {step}: {}", sol.status);
        let u = first_control(&tr, &sol);
        x = plant.step(&x, &u, example.dt).expect("plant");
    }
    check_warm_re_solves("sqp_warm_alloc", &counts);
}

/// A warm re-solve by a new solver (a function of its own for callgrind's per-function
/// counts).
#[inline(never)]
fn fresh_resolve(compiled: &mut Compiled, warm: &Solution) -> Solution {
    Sqp::default().solve_warm(compiled, warm).unwrap()
}

/// A warm re-solve by the solver that keeps its workspace, into `out`.
#[inline(never)]
fn kept_resolve(sqp: &Sqp, compiled: &mut Compiled, warm: &Solution, out: &mut Solution) {
    sqp.solve_warm_into(compiled, warm, out).unwrap()
}

/// Closed-loop steps checked.
const STEPS: usize = 30;

/// The first control of the plan.
fn first_control(tr: &Transcription, sol: &Solution) -> Vec<f64> {
    let u = tr.controls().column(0).expect("first control");
    let idx = tr.problem().variable_indices(&u).expect("control indices");
    idx.iter().map(|&j| sol.x[j]).collect()
}
