//! Basic interior-point solves checked against published optima.

mod ipm_common;

use ipm_common::{hs071, rosenbrock};
use nlp::{CommonOptions, Ipm, IpmOptions, MuStrategy, Status};

fn print_opts() -> IpmOptions {
    IpmOptions {
        common: CommonOptions {
            print_level: if std::env::var("IPM_PRINT").is_ok() {
                5
            } else {
                0
            },
            ..CommonOptions::default()
        },
        ..IpmOptions::default()
    }
}

/// Rosenbrock's minimum is f = 0 at (1, 1) (Rosenbrock 1960). With tol = 1e-8 the
/// final point is accurate to ~1e-8 relative, so we allow 1e-6 on x.
#[test]
fn rosenbrock_unconstrained() {
    let mut p = rosenbrock();
    let sol = Ipm::new(print_opts()).solve(&mut p).unwrap();
    assert_eq!(sol.status, Status::SolveSucceeded, "{}", sol.message);
    assert!((sol.x[0] - 1.0).abs() < 1e-6, "{:?}", sol.x);
    assert!((sol.x[1] - 1.0).abs() < 1e-6, "{:?}", sol.x);
    assert!(sol.objective < 1e-12);
    eprintln!("rosenbrock iterations: {}", sol.stats.iterations);
}

/// hs071: f* = 17.0140172891516 at x* = (1, 4.74299963, 3.82114998, 1.37940829)
/// (Hock & Schittkowski 1981). IPOPT 3.14 with default options reports
/// f = 1.7014017145179164e+01 in 8 iterations: its bound_relax_factor = 1e-8 relaxes
/// g1 ≥ 25 by 2.5e-7, which lowers f by |λ1|·2.5e-7 ≈ 1.4e-7. So we compare with the true
/// optimum to 1e-6 and with IPOPT's relaxed value to 1e-9.
#[test]
fn hs071_monotone() {
    let mut p = hs071();
    let sol = Ipm::new(print_opts()).solve(&mut p).unwrap();
    assert_eq!(sol.status, Status::SolveSucceeded, "{}", sol.message);
    assert!(
        (sol.objective - 17.0140172891516).abs() < 1e-6,
        "{}",
        sol.objective
    );
    assert!(
        (sol.objective - 17.014017145179164).abs() < 1e-9,
        "{}",
        sol.objective
    );
    let xs = [1.0, 4.74299963, 3.82114998, 1.37940829];
    for (a, b) in sol.x.iter().zip(xs) {
        assert!((a - b).abs() < 1e-6, "{:?}", sol.x);
    }
    // IPOPT's multipliers for hs071: λ = (−0.55229366, 0.16146857) in the sign
    // convention ∇f + Jᵀλ − z_L + z_U = 0.
    assert!(
        (sol.lambda[0] + 0.55229366).abs() < 1e-6,
        "{:?}",
        sol.lambda
    );
    assert!(
        (sol.lambda[1] - 0.16146857).abs() < 1e-6,
        "{:?}",
        sol.lambda
    );
    // constr_viol is measured against the original bounds: the relaxation allows 2.5e-7.
    assert!(sol.dual_inf < 1e-7 && sol.constr_viol < 1e-6);
    eprintln!("hs071 monotone iterations: {}", sol.stats.iterations);
    assert!(sol.stats.iterations <= 15, "{}", sol.stats.iterations);
}

#[test]
fn hs071_adaptive() {
    for oracle in [nlp::MuOracle::Probing, nlp::MuOracle::Loqo] {
        let mut p = hs071();
        let opts = IpmOptions {
            mu_strategy: Some(MuStrategy::Adaptive),
            mu_oracle: oracle,
            ..print_opts()
        };
        let sol = Ipm::new(opts).solve(&mut p).unwrap();
        assert_eq!(
            sol.status,
            Status::SolveSucceeded,
            "{oracle:?} {}",
            sol.message
        );
        // See hs071_monotone for the tolerance.
        assert!((sol.objective - 17.0140172891516).abs() < 1e-6);
        assert!((sol.objective - 17.014017145179164).abs() < 1e-8);
        eprintln!(
            "hs071 adaptive {oracle:?} iterations: {}",
            sol.stats.iterations
        );
    }
}
