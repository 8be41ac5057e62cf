//! One warm interior-point re-solve of the cart-pole MPC (examples/src/mpc_cart_pole.rs,
//! N = 40, 204 variables, 164 rows) after 50 closed-loop steps: the plan shifted and
//! re-solved warm from the new state — the work of a typical step of the loop.
//! `mpc_cart_pole_ipm_warm_resolve`: by one `Ipm` across the loop, as `Mpc` does (its KKT
//! symbolic analysis kept between solves); `mpc_cart_pole_ipm_warm_resolve_fresh_solver`:
//! by a new `Ipm` each time (the analysis rebuilt), for the ratio.
//! `mpc_cart_pole_sqp_warm_resolve`: the same re-solve by the SQP.
//! `mpc_cart_pole_rti_prepare` / `mpc_cart_pole_rti_feedback`: the two phases of one
//! real-time iteration (`nlp::Rti`) at the same state, from the same plan.
//! The `_jit` variants: the IPM re-solve and the two RTI phases on native evaluators
//! (`Evaluator::Jit`, the same iterates).
//!
//! ```text
//! cargo bench --bench mpc
//! ```
use symnlp_examples::mpc_cart_pole;

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::Criterion;
use nlp::mpc::Mpc;
use nlp::ocp::Transcription;
use nlp::{Ipm, Rti, Solution, Sqp, SqpOptions};
use symx::Evaluator;

/// Closed-loop steps taken before the benchmarked re-solve (mid swing-up stabilisation,
/// where a warm step takes 2–3 iterations as most of the loop's steps do).
const STEPS_BEFORE: usize = 50;

fn warm_resolve(c: &mut Criterion) {
    let example = mpc_cart_pole::example();
    let (tr, mut plant) = example.setup().expect("cart-pole MPC transcription");
    let mut mpc = Mpc::new(&tr, Box::new(Ipm::default())).expect("MPC");
    let mut x = example.x_init.clone();
    for _ in 0..STEPS_BEFORE {
        assert!(mpc.step(&x).expect("step").status.is_success());
        x = plant.step(&x, mpc.control(), example.dt).expect("plant");
    }
    let shifted = tr.shift(mpc.solution().expect("solved")).expect("shift");
    let compiled = mpc.compiled_mut();
    compiled.set_value("x0", &x).expect("x0 parameter");
    let ipm = Ipm::default();
    let warm = ipm.solve_warm(compiled, &shifted).expect("warm solve");
    assert!(warm.status.is_success(), "warm solve: {}", warm.status);
    eprintln!(
        "warm re-solve at step {STEPS_BEFORE}: {} iterations",
        warm.stats.iterations
    );
    c.bench_function("mpc_cart_pole_ipm_warm_resolve", |b| {
        b.iter(|| black_box(ipm.solve_warm(compiled, &shifted).expect("warm solve")))
    });
    c.bench_function("mpc_cart_pole_ipm_warm_resolve_fresh_solver", |b| {
        b.iter(|| {
            black_box(
                Ipm::default()
                    .solve_warm(compiled, &shifted)
                    .expect("warm solve"),
            )
        })
    });
    let sqp = Sqp::default();
    let warm = sqp.solve_warm(compiled, &shifted).expect("warm SQP solve");
    assert!(warm.status.is_success(), "warm SQP solve: {}", warm.status);
    c.bench_function("mpc_cart_pole_sqp_warm_resolve", |b| {
        b.iter(|| black_box(sqp.solve_warm(compiled, &shifted).expect("warm solve")))
    });
    let mut native = compiled
        .clone()
        .with_evaluator(Evaluator::Jit)
        .expect("jit");
    c.bench_function("mpc_cart_pole_ipm_warm_resolve_jit", |b| {
        b.iter(|| black_box(ipm.solve_warm(&mut native, &shifted).expect("warm solve")))
    });
    rti_phases(c, &tr, &shifted, &x, Evaluator::Tape);
    rti_phases(c, &tr, &shifted, &x, Evaluator::Jit);
}

/// RTI: the plan of step STEPS_BEFORE − 1 shifted is the linearisation point, x the
/// measured state; prepare and feedback from the same plan each time.
fn rti_phases(c: &mut Criterion, tr: &Transcription, shifted: &Solution, x: &[f64], e: Evaluator) {
    let suffix = if e == Evaluator::Jit { "_jit" } else { "" };
    let mut rti = Rti::from_transcription(tr, SqpOptions::default())
        .expect("RTI")
        .with_evaluator(e)
        .expect("evaluator");
    rti.initialize(shifted).expect("plan");
    c.bench_function(&format!("mpc_cart_pole_rti_prepare{suffix}"), |b| {
        b.iter(|| {
            rti.initialize(shifted).expect("plan");
            rti.prepare().expect("prepare");
        })
    });
    // The feedback alone: each repetition prepares untimed, then times the feedback.
    c.bench_function(&format!("mpc_cart_pole_rti_feedback{suffix}"), |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                rti.initialize(shifted).expect("plan");
                rti.prepare().expect("prepare");
                let t = Instant::now();
                black_box(rti.feedback(x).expect("feedback"));
                total += t.elapsed();
            }
            total
        })
    });
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    warm_resolve(&mut c);
    c.final_summary();
}
