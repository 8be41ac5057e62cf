//! CasADi's race-car example (examples/src/race_car.rs) against CasADi 3.8.2 + IPOPT 3.14.19
//! on the identical formulation (benches/reference/race_car.py, run 2026-11-25 on this
//! machine): `{"N": 100, "T": 1.9046342722764305, "iterations": 35}` with CasADi's
//! default Opti formulation, T = 1.9046342735147381 (39 iterations) with
//! `detect_simple_bounds`, which is the formulation symnlp solves (single-variable rows
//! become bounds).
use symnlp_examples::race_car;

use symnlp::nlp::IpmOptions;

#[test]
fn race_car_reaches_ipopts_minimum_time() {
    let (sol, t) = race_car::solve(100, IpmOptions::default()).expect("builds and solves");
    assert!(sol.status.is_success(), "{:?}", sol.status);
    // Both runs stop at tol = 1e-8 (scaled KKT error); the two IPOPT formulations agree to
    // 7e-10 relative, so 1e-8 relative separates "same optimum" from anything else.
    let t_ipopt = 1.9046342722764305;
    assert!(
        ((sol.x[t] - t_ipopt) / t_ipopt).abs() < 1e-8,
        "T = {} vs IPOPT {t_ipopt}",
        sol.x[t]
    );
}
