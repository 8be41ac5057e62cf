//! The optimal-control examples (examples/src/*.rs built on nlp::ocp) against IPOPT on the
//! identical transcriptions: CasADi 3.8.2 + IPOPT 3.14.19 (MUMPS), tol 1e-8, values printed
//! by `python3 benches/reference/ocp_examples.py` (run 2026-11-25 on this machine; the
//! script mirrors nlp/src/ocp/transcription.rs variable by variable).
//!
//! Tolerance: both solvers stop at a scaled KKT error ≤ 1e-8, so the objectives of two
//! converged runs agree to O(1e-8) relative; 1e-7 relative tells "the same optimum" from
//! a different local minimum or a different formulation (which move the objective by far
//! more, e.g. RK4 M = 4 vs M = 1 changes the Van der Pol cost in the 5th digit).
//! Measured (2026-11-25): 1e-16…4e-13 relative with the interior point, 2e-8 with the SQP
//! (its own stopping tolerance), 6e-10 between the race car's two IPOPT formulations.
use symnlp_examples::{
    cart_pole, quadrotor, race_car_ocp, two_link_arm, vdp_collocation, vdp_multiple_shooting,
};

use symnlp::nlp::ocp::{Ocp, Trajectory, Transcription};
use symnlp::nlp::{Ipm, IpmOptions, Sqp, SqpOptions};

fn assert_matches_ipopt(name: &str, value: f64, ipopt: f64) {
    let rel = ((value - ipopt) / ipopt).abs();
    assert!(
        rel < 1e-7,
        "{name}: {value} vs IPOPT {ipopt} (relative {rel:.1e})"
    );
}

/// Simulates each interval from its grid state with its constant control by 200 RK4 steps
/// (plain f64 on the compiled dynamics, independent of the transcription) and returns the
/// largest deviation from the next grid state (restarting at every grid point keeps the
/// instability of an upswing from amplifying the local errors).
fn simulation_gap(ocp: &Ocp, t: &Trajectory) -> f64 {
    let f = ocp.dynamics_function().unwrap();
    let rhs = |x: &[f64], u: &[f64]| f.call(&[x, u, &[]]).unwrap().swap_remove(0);
    let axpy = |x: &[f64], a: f64, k: &[f64]| -> Vec<f64> {
        x.iter().zip(k).map(|(x, k)| x + a * k).collect()
    };
    let n = t.control_time.len();
    let h = t.final_time / n as f64 / 200.0;
    let mut gap: f64 = 0.0;
    for k in 0..n {
        let mut x = t.state_at_grid(k);
        let u: Vec<f64> = t.controls.iter().map(|c| c[k]).collect();
        for _ in 0..200 {
            let k1 = rhs(&x, &u);
            let k2 = rhs(&axpy(&x, h / 2.0, &k1), &u);
            let k3 = rhs(&axpy(&x, h / 2.0, &k2), &u);
            let k4 = rhs(&axpy(&x, h, &k3), &u);
            for i in 0..x.len() {
                x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        let grid = t.state_at_grid(k + 1);
        gap = x
            .iter()
            .zip(&grid)
            .map(|(a, b)| (a - b).abs())
            .fold(gap, f64::max);
    }
    gap
}

fn solve_ipm(tr: &Transcription) -> Trajectory {
    let mut compiled = tr.compile().expect("compiles");
    let sol = Ipm::default().solve(&mut compiled).expect("solves");
    assert!(sol.status.is_success(), "{:?}", sol.status);
    tr.trajectory(&sol).expect("reads back")
}

#[test]
fn vdp_multiple_shooting_matches_ipopt() {
    // {"objective": 3.732969410715394, "iterations": 9}
    let t = vdp_multiple_shooting::solve(20, IpmOptions::default()).unwrap();
    assert!(t.status.is_success());
    assert_matches_ipopt("vdp ms", t.objective, 3.732969410715394);
    assert_eq!((t.time.len(), t.controls[0].len()), (21, 20));
    assert_eq!(t.state("x1").unwrap()[0], 0.0);
    assert!(t.state("x1").unwrap().iter().all(|&v| v >= -0.25 - 1e-8));
}

#[test]
fn vdp_multiple_shooting_with_sqp_reaches_the_same_optimum() {
    let ocp = vdp_multiple_shooting::van_der_pol().unwrap();
    let method = symnlp::nlp::Method::multiple_shooting(symnlp::nlp::ocp::ButcherTableau::rk4(), 4);
    let tr = ocp.transcribe(&method, 20).unwrap();
    let mut compiled = tr.compile().unwrap();
    let sol = Sqp::new(SqpOptions::default())
        .solve(&mut compiled)
        .unwrap();
    assert!(sol.status.is_success(), "{:?}", sol.status);
    let t = tr.trajectory(&sol).unwrap();
    assert_matches_ipopt("vdp ms (sqp)", t.objective, 3.732969410715394);
}

#[test]
fn vdp_collocation_matches_ipopt() {
    // {"objective": 3.7774566843106947, "iterations": 16}
    let t = vdp_collocation::solve(20, 3, IpmOptions::default()).unwrap();
    assert!(t.status.is_success());
    assert_matches_ipopt("vdp collocation", t.objective, 3.7774566843106947);
    let c = t.collocation.as_ref().expect("collocation states");
    assert_eq!((c.time.len(), c.states[0].len()), (60, 60));
    // The trajectory serialises (plot-ready JSON) and reads back identical.
    let json = serde_json::to_string(&t).unwrap();
    assert_eq!(serde_json::from_str::<Trajectory>(&json).unwrap(), t);
}

#[test]
fn race_car_with_ocp_matches_ipopt_and_the_hand_written_example() {
    // ocp_examples.py: T = 1.904634273502346 (42 iterations); race_car.py (CasADi's own
    // Opti formulation): 1.9046342722764305, the value tests/race_car.rs checks.
    let t = solve_ipm(&race_car_ocp::transcription(100).unwrap());
    assert_matches_ipopt("race car", t.final_time, 1.904634273502346);
    assert_matches_ipopt("race car vs race_car.py", t.final_time, 1.9046342722764305);
    assert_eq!(t.time.last().copied(), Some(t.final_time));
    assert!((t.state("position").unwrap()[100] - 1.0).abs() < 1e-8);
}

#[test]
fn cart_pole_swing_up_matches_ipopt() {
    // {"objective": 60.80995090111304, "iterations": 13}
    let t = solve_ipm(&cart_pole::transcription(20).unwrap());
    assert_matches_ipopt("cart-pole", t.objective, 60.80995090111304);
    assert!((t.state("q2").unwrap()[20] - std::f64::consts::PI).abs() < 1e-8);
    // The controls, simulated accurately, reproduce the states up to the local error of
    // Radau IIA (order 5 at the interval ends): the gap shrinks by ≥ 16 from h = 0.1 to
    // h = 0.05 (measured 1.4e-3 → 4e-5); a wrong transcription would leave O(1) gaps.
    let ocp = cart_pole::problem().unwrap();
    let gap = simulation_gap(&ocp, &t);
    let fine = solve_ipm(&cart_pole::transcription(40).unwrap());
    let gap_fine = simulation_gap(&ocp, &fine);
    assert!(
        gap < 5e-3 && gap_fine < gap / 16.0,
        "simulation gaps {gap}, {gap_fine}"
    );
}

#[test]
fn quadrotor_point_to_point_matches_ipopt() {
    // {"objective": 0.08009187934345072, "iterations": 7}
    let t = solve_ipm(&quadrotor::transcription(20).unwrap());
    assert_matches_ipopt("quadrotor", t.objective, 0.08009187934345072);
    assert!(t
        .controls
        .iter()
        .flatten()
        .all(|&f| (-1e-8..=2.5 + 1e-8).contains(&f)));
    // One RK4 step per interval of 0.1 s against 200 steps: the local error of RK4
    // (measured 8.4e-5; a wrong transcription would leave O(1) gaps).
    let gap = simulation_gap(&quadrotor::problem().unwrap(), &t);
    assert!(gap < 1e-3, "simulation gap {gap}");
}

#[test]
fn two_link_arm_minimum_time_matches_ipopt() {
    // {"objective": 2.303220583549893, "T": 2.260260652913143, "iterations": 11}
    let t = solve_ipm(&two_link_arm::transcription(20).unwrap());
    assert_matches_ipopt("arm objective", t.objective, 2.303220583549893);
    assert_matches_ipopt("arm T", t.final_time, 2.260260652913143);
    // Legendre collocation (order 6) on h ≈ 0.11: local gap ~1e-5 (measured 2.2e-5).
    let gap = simulation_gap(&two_link_arm::problem().unwrap(), &t);
    assert!(gap < 1e-3, "simulation gap {gap}");
}

/// Largest relative objective difference and largest state/control difference of two
/// solutions of the same NLP.
fn differences(a: &Trajectory, b: &Trajectory) -> (f64, f64) {
    let rel = ((a.objective - b.objective) / a.objective).abs();
    let max = |x: &[Vec<f64>], y: &[Vec<f64>]| {
        x.iter()
            .flatten()
            .zip(y.iter().flatten())
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
    };
    (
        rel,
        max(&a.states, &b.states).max(max(&a.controls, &b.controls)),
    )
}

/// The call-node route (dynamics as a compiled function, one call of the compiled RK4
/// interval per interval) is the same NLP as the inlined transcription: the derivatives
/// are the same numbers up to summation order, so the interior point takes the same steps.
/// Tolerance 1e-10: rounding differences of O(1e-16) per evaluation, amplified by at most
/// the ~10–30 Newton steps of the solve (measured 2026-11-25: objectives 0 to 6.9e-16
/// relative, states and controls ≤ 4.4e-16).
#[test]
fn call_nodes_give_the_inlined_optimum() {
    use symnlp::nlp::ocp::{ButcherTableau, Method};
    let inlined = vdp_multiple_shooting::solve_with(20, IpmOptions::default(), false).unwrap();
    let calls = vdp_multiple_shooting::solve_with(20, IpmOptions::default(), true).unwrap();
    // Dynamics function without step calls: four calls of f per RK4 step.
    let ocp = vdp_multiple_shooting::van_der_pol_with_calls().unwrap();
    let tr = ocp
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 4), 20)
        .unwrap();
    let f_calls = solve_ipm(&tr);
    for (name, t) in [("vdp step calls", &calls), ("vdp f calls", &f_calls)] {
        let (rel, dx) = differences(&inlined, t);
        eprintln!("{name}: objective {rel:.1e} relative, states/controls {dx:.1e}");
        assert!(rel <= 1e-10 && dx <= 1e-8, "{name}: {rel:e} {dx:e}");
    }
    let q_inlined = solve_ipm(&quadrotor::transcription(20).unwrap());
    let q_calls = solve_ipm(&quadrotor::transcription_with_calls(20).unwrap());
    let both = quadrotor::problem_with(true)
        .unwrap()
        .transcribe(
            &Method::multiple_shooting_with_calls(ButcherTableau::rk4(), 1),
            20,
        )
        .unwrap();
    let q_both = solve_ipm(&both);
    for (name, t) in [
        ("quadrotor step calls", &q_calls),
        ("quadrotor f + step calls", &q_both),
    ] {
        let (rel, dx) = differences(&q_inlined, t);
        eprintln!("{name}: objective {rel:.1e} relative, states/controls {dx:.1e}");
        assert!(rel <= 1e-10 && dx <= 1e-8, "{name}: {rel:e} {dx:e}");
    }
    assert_matches_ipopt("quadrotor (calls)", q_calls.objective, 0.08009187934345072);
    // The call version's constraints are calls of the compiled interval, not RK4 expressions.
    let tr = quadrotor::transcription_with_calls(3).unwrap();
    let g = tr.problem().constraint_expressions();
    assert!(g.iter().any(|e| e.to_string().contains("rk4_interval(")));
}

/// Heap use of the measuring thread: a counting global allocator that, while `ACTIVE` is
/// set on a thread, adds that thread's allocations and subtracts its deallocations and
/// keeps the peak (the graph is thread-local, so a build on a fresh thread is counted
/// whole; allocations of other threads are not counted).
mod heap {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;

    pub struct Counting;

    thread_local! {
        pub static ACTIVE: Cell<bool> = const { Cell::new(false) };
        static LIVE: Cell<isize> = const { Cell::new(0) };
        static PEAK: Cell<isize> = const { Cell::new(0) };
    }

    unsafe impl GlobalAlloc for Counting {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            if ACTIVE.with(Cell::get) {
                let live = LIVE.with(|l| {
                    l.set(l.get() + layout.size() as isize);
                    l.get()
                });
                PEAK.with(|p| p.set(p.get().max(live)));
            }
            unsafe { System.alloc(layout) }
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            if ACTIVE.with(Cell::get) {
                LIVE.with(|l| l.set(l.get() - layout.size() as isize));
            }
            unsafe { System.dealloc(ptr, layout) }
        }
    }

    /// Runs `f` counting; returns its result and the peak of live bytes allocated by it.
    pub fn peak_during<R>(f: impl FnOnce() -> R) -> (R, usize) {
        LIVE.with(|l| l.set(0));
        PEAK.with(|p| p.set(0));
        ACTIVE.with(|a| a.set(true));
        let r = f();
        ACTIVE.with(|a| a.set(false));
        (r, PEAK.with(Cell::get).max(0) as usize)
    }
}

#[global_allocator]
static GLOBAL: heap::Counting = heap::Counting;

/// Sizes of one transcription of the quadrotor at N intervals, built and compiled on a
/// fresh thread (so the thread-local graph starts empty).
#[derive(Debug)]
struct Sizes {
    /// Printed (through `Debug`) for information, not asserted.
    #[allow(dead_code)]
    nodes_after_transcription: usize,
    nodes_after_compilation: usize,
    peak_heap_bytes: usize,
    /// Tape instructions of ∂g/∂w and of the Lagrangian Hessian, and instructions
    /// executed per evaluation (callees' tapes included).
    jac_instructions: (usize, usize),
    hess_instructions: (usize, usize),
}

fn quadrotor_sizes(n: usize, dynamics_function: bool, step_calls: bool) -> Sizes {
    use symnlp::nlp::ocp::{ButcherTableau, Method};
    std::thread::spawn(move || {
        let ((tr, nodes_t, compiled), peak) = heap::peak_during(|| {
            let ocp = quadrotor::problem_with(dynamics_function).unwrap();
            let method = match step_calls {
                true => Method::multiple_shooting_with_calls(ButcherTableau::rk4(), 1),
                false => Method::multiple_shooting(ButcherTableau::rk4(), 1),
            };
            let tr = ocp.transcribe(&method, n).unwrap();
            let nodes_t = symnlp::symx::node_count();
            let compiled = tr.compile().unwrap();
            (tr, nodes_t, compiled)
        });
        let nodes_c = symnlp::symx::node_count();
        drop(compiled);
        // The derivative functions exactly as Compiled::new (nlp/src/compiled.rs) builds
        // them; on the same graph, so the expressions are the compiled problem's.
        use symnlp::symx::{jacobian, lagrangian_hessian, Expr, Function, Matrix};
        let pb = tr.problem();
        let (x, p, g) = (pb.variables(), pb.parameters(), pb.constraint_expressions());
        let jac = jacobian(&g, x).unwrap();
        let sigma = Expr::sym("obj_factor");
        let lambda = Matrix::sym_vec("lambda", g.len());
        let hess = lagrangian_hessian(pb.objective(), &g, x, sigma, &lambda).unwrap();
        let jac_fn = Function::new(&[x, p], &[jac.values()]).unwrap();
        let hess_fn = Function::new(&[x, p, &[sigma], &lambda], &[hess.values()]).unwrap();
        let count = |f: &Function| (f.instruction_count(), f.executed_instruction_count());
        Sizes {
            nodes_after_transcription: nodes_t,
            nodes_after_compilation: nodes_c,
            peak_heap_bytes: peak,
            jac_instructions: count(&jac_fn),
            hess_instructions: count(&hess_fn),
        }
    })
    .join()
    .unwrap()
}

/// Issue 13's size target: with call nodes, the quadrotor OCP at N = 1000 (RK4 multiple
/// shooting through the Ocp helper) builds and compiles with at least 5× fewer graph nodes
/// and 5× less peak heap than inlined (the figures of docs/performance.md come from this
/// test's output: `cargo test --release --test ocp_examples quadrotor_sizes -- --nocapture`).
/// Sizes are deterministic; times are not measured here.
#[test]
fn quadrotor_sizes_with_calls_vs_inlined() {
    const N: usize = 1000;
    let inlined = quadrotor_sizes(N, false, false);
    let calls = quadrotor_sizes(N, false, true);
    let f_calls = quadrotor_sizes(N, true, false);
    let both = quadrotor_sizes(N, true, true);
    eprintln!("N = {N}\ninlined: {inlined:?}\nstep calls: {calls:?}");
    eprintln!("f calls: {f_calls:?}\nboth: {both:?}");
    assert!(inlined.nodes_after_compilation >= 5 * calls.nodes_after_compilation);
    assert!(inlined.peak_heap_bytes >= 5 * calls.peak_heap_bytes);
    assert!(inlined.hess_instructions.0 >= 5 * calls.hess_instructions.0);
    // With the closure inlined into the one compiled step, the work per evaluation stays
    // within 1.5× of the inlined version (measured 1.09× for ∂g/∂w, 1.25× for the Hessian).
    assert!(2 * calls.jac_instructions.1 <= 3 * inlined.jac_instructions.1);
    assert!(2 * calls.hess_instructions.1 <= 3 * inlined.hess_instructions.1);
    // A dynamics function alone is called 4× per interval: fewer nodes, not 5× fewer.
    assert!(f_calls.nodes_after_compilation < inlined.nodes_after_compilation);
    assert!(both.nodes_after_compilation * 5 <= inlined.nodes_after_compilation);
}
