//! IPOPT's handling of the objective scaling in the barrier parameter's floor: the
//! termination tests bound the *unscaled* complementarity by `compl_inf_tol`, so μ must
//! be allowed to go below `compl_inf_tol` times the objective scale (IPOPT's
//! IpMonotoneMuUpdate and IpAdaptiveMuUpdate apply the objective scaling to
//! `compl_inf_tol` before using it in the floor).

use nlp::{Ipm, IpmOptions, MuStrategy, Problem, Status};

/// min 1e8·(x + 1)² subject to x ≥ 0, from x0 = 1.25. The solution is x = 0, f = 1e8,
/// with bound multiplier z = 2e8 (∂f/∂x at 0). The gradient at x0 is 4.5e8, so
/// gradient-based scaling multiplies f by 100/4.5e8 ≈ 2.2e-7. With a floor of
/// min(tol, compl_inf_tol)/(κ_ε + 1) = 9.1e-10 on the *scaled* μ, the unscaled
/// complementarity x·z could not fall below 9.1e-10/2.2e-7 ≈ 4e-3 > compl_inf_tol = 1e-4
/// and the solve ended without success.
fn scaled_bound_problem() -> nlp::Compiled {
    let mut pb = Problem::new();
    let x = pb.variable("x", 1).unwrap();
    pb.set_initial(&x, &[1.25]).unwrap();
    pb.set_bounds(&x, 0.0, f64::INFINITY).unwrap();
    pb.minimize(1e8 * (x[0] + 1.0).sq());
    pb.compile().unwrap()
}

fn check(strategy: MuStrategy) {
    let mut c = scaled_bound_problem();
    let opts = IpmOptions {
        mu_strategy: Some(strategy),
        ..IpmOptions::default()
    };
    let sol = Ipm::new(opts).solve(&mut c).unwrap();
    assert_eq!(
        sol.status,
        Status::SolveSucceeded,
        "{:?}: {}",
        strategy,
        sol.message
    );
    // The objective scale IPOPT's gradient-based scaling would choose (100 / 4.5e8).
    assert!((sol.stats.obj_scaling - 100.0 / 4.5e8).abs() < 1e-12);
    // x·z ≤ compl_inf_tol = 1e-4 with z ≈ 2e8 puts x within 5e-13 of its bound (plus
    // bound_relax_factor's relaxation 1e-8).
    assert!(sol.x[0].abs() < 1e-8 + 1e-12, "x = {}", sol.x[0]);
    // f* = 1e8 at x = 0; the bound is relaxed to −1e-8 (bound_relax_factor), where
    // f = 1e8·(1 − 1e-8)² ≈ 1e8 − 2: allow that, plus 1e-6 relative.
    assert!(
        (sol.objective - 1e8).abs() < 2.0 + 1e2,
        "f = {}",
        sol.objective
    );
    // (SolveSucceeded already says that the unscaled complementarity, measured to the
    // relaxed bound, is ≤ compl_inf_tol; `sol.compl` is measured to the original bound
    // 0, 1e-8 away, where it is 1e-8·2e8 = 2.)
}

#[test]
fn monotone_mu_reaches_the_unscaled_tolerance() {
    check(MuStrategy::Monotone);
}

#[test]
fn adaptive_mu_reaches_the_unscaled_tolerance() {
    check(MuStrategy::Adaptive);
}
