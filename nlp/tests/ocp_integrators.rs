//! Butcher tableaus and collocation points/coefficients (nlp::ocp) against published
#![allow(clippy::needless_range_loop)] // index loops mirror the C[j][r] formulas
//! values, CasADi's own coefficients and convergence orders.
use nlp::ocp::{ButcherTableau, Collocation, CollocationPoints, OcpError};
use symx::{Expr, Function, Matrix};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

/// x(h) for ẋ = −x + sin(3x) + 1 from x(0) = 0.3, `m` steps of `tableau`.
fn integrate(tableau: &ButcherTableau, m: usize) -> f64 {
    let x = Expr::sym("x");
    let f = |z: &Matrix| z.map(|e| -e + (3.0 * e).sin() + 1.0);
    let end = tableau.integrate(&f, &Matrix::from_vec(vec![x]), Expr::constant(1.0), m);
    let fun = Function::new(&[&[x]], &[&end]).unwrap();
    fun.call(&[&[0.3]]).unwrap()[0][0]
}

#[test]
fn runge_kutta_methods_converge_at_their_order() {
    // Reference: RK4 with 4096 steps (error ~1e-16, far below the errors measured).
    let exact = integrate(&ButcherTableau::rk4(), 4096);
    for (name, order) in [
        ("euler", 1.0),
        ("midpoint", 2.0),
        ("rk2", 2.0),
        ("heun", 2.0),
        ("rk4", 4.0),
    ] {
        let t = ButcherTableau::by_name(name).unwrap();
        let e1 = (integrate(&t, 16) - exact).abs();
        let e2 = (integrate(&t, 32) - exact).abs();
        let observed = (e1 / e2).log2();
        // Halving h divides the error by 2^p up to higher-order terms; ±0.25 separates p
        // from p ± 1.
        assert!((observed - order).abs() < 0.25, "{name}: order {observed}");
    }
}

#[test]
fn rk4_step_is_the_textbook_formula() {
    // ẋ = x: one RK4 step multiplies by 1 + h + h²/2 + h³/6 + h⁴/24.
    let x = Expr::sym("x");
    let h = 0.1;
    let end = ButcherTableau::rk4().step(
        &|z: &Matrix| z.clone(),
        &Matrix::from_vec(vec![x]),
        Expr::constant(h),
    );
    let v = Function::new(&[&[x]], &[&end])
        .unwrap()
        .call(&[&[2.0]])
        .unwrap()[0][0];
    let factor = 1.0 + h + h * h / 2.0 + h.powi(3) / 6.0 + h.powi(4) / 24.0;
    assert!(close(v, 2.0 * factor, 1e-15), "{v}");
}

#[test]
fn invalid_tableaus_are_errors() {
    let implicit = ButcherTableau::new("implicit", &[vec![0.5]], &[1.0], &[0.5]);
    assert!(
        matches!(implicit, Err(OcpError::Tableau { .. })),
        "{implicit:?}"
    );
    let weights = ButcherTableau::new("w", &[vec![0.0]], &[0.9], &[0.0]);
    assert!(matches!(weights, Err(OcpError::Tableau { .. })));
    let shape = ButcherTableau::new("s", &[vec![0.0, 0.0]], &[0.5, 0.5], &[0.0, 1.0]);
    assert!(matches!(shape, Err(OcpError::Tableau { .. })));
    assert!(ButcherTableau::by_name("rk45").is_err());
    assert!(matches!(
        Collocation::new(CollocationPoints::Radau, 0),
        Err(OcpError::Degree(0))
    ));
}

#[test]
fn gauss_legendre_points_match_published_values() {
    // Abramowitz & Stegun, Table 25.4 (abscissae on [−1, 1]), mapped to [0, 1].
    let d3 = Collocation::new(CollocationPoints::Legendre, 3).unwrap();
    let s = 0.15f64.sqrt();
    for (a, b) in d3.tau.iter().zip([0.0, 0.5 - s, 0.5, 0.5 + s]) {
        assert!(close(*a, b, 1e-15), "{a} vs {b}");
    }
    for (a, b) in d3.b.iter().zip([0.0, 5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0]) {
        assert!(close(*a, b, 1e-15), "{a} vs {b}");
    }
    let d5 = Collocation::new(CollocationPoints::Legendre, 5).unwrap();
    let published = [
        -0.906179845938664,
        -0.5384693101056831,
        0.0,
        0.5384693101056831,
        0.906179845938664,
    ];
    for (a, b) in d5.tau[1..].iter().zip(published) {
        assert!(close(2.0 * a - 1.0, b, 2e-15), "{a} vs {b}");
    }
}

#[test]
fn radau_points_match_radau_iia() {
    // Hairer & Wanner, Solving ODEs II, Table IV.5.6 (Radau IIA of order 5).
    let r = Collocation::new(CollocationPoints::Radau, 3).unwrap();
    let s6 = 6f64.sqrt();
    for (a, b) in r
        .tau
        .iter()
        .zip([0.0, (4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0])
    {
        assert!(close(*a, b, 1e-15), "{a} vs {b}");
    }
    for (a, b) in
        r.b.iter()
            .zip([0.0, (16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0])
    {
        assert!(close(*a, b, 1e-15), "{a} vs {b}");
    }
    // Radau: the end of the interval is the last point, so D = (0, …, 0, 1).
    for (j, &dj) in r.d.iter().enumerate() {
        assert!(
            close(dj, if j == 3 { 1.0 } else { 0.0 }, 1e-14),
            "D[{j}] = {dj}"
        );
    }
    let r2 = Collocation::new(CollocationPoints::Radau, 2).unwrap();
    assert!(close(r2.tau[1], 1.0 / 3.0, 1e-15) && close(r2.b[1], 0.75, 1e-15));
}

#[test]
fn coefficients_match_casadis_direct_collocation_example() {
    // Printed by the coefficient loop of CasADi 3.8.2's direct_collocation.py (numpy
    // poly1d in monomials, accurate to ~1e-14) for d = 3, Legendre.
    let c_casadi = [
        [
            -12.000000000000005,
            -6.000000000000005,
            3.0000000000000018,
            -6.000000000000001,
        ],
        [
            13.121638910345698,
            5.000000000000005,
            -5.727486121839515,
            10.16397779494323,
        ],
        [
            -1.3333333333333321,
            1.1639777949432215,
            1.9999999999999982,
            -9.163977794943227,
        ],
        [
            0.2116944229876384,
            -0.16397779494322234,
            0.7274861218395144,
            5.000000000000001,
        ],
    ];
    let d_casadi = [
        -1.0000000000000018,
        1.6666666666666679,
        -1.333333333333334,
        1.666666666666667,
    ];
    let col = Collocation::new(CollocationPoints::Legendre, 3).unwrap();
    for j in 0..4 {
        assert!(close(col.d[j], d_casadi[j], 1e-13));
        for r in 0..4 {
            assert!(close(col.c[j][r], c_casadi[j][r], 1e-12), "C[{j}][{r}]");
        }
    }
}

#[test]
fn high_degree_rules_are_exact_for_their_polynomials() {
    for (points, degree, exact_to) in [
        (CollocationPoints::Legendre, 20, 39), // Gauss: degree 2d − 1
        (CollocationPoints::Radau, 20, 38),    // Radau: degree 2d − 2
        (CollocationPoints::Legendre, 1, 1),
        (CollocationPoints::Radau, 1, 0),
    ] {
        let c = Collocation::new(points, degree).unwrap();
        for k in 0..=exact_to {
            let q: f64 = c.tau.iter().zip(&c.b).map(|(t, b)| b * t.powi(k)).sum();
            // Sums of d positive weights times values ≤ 1: rounding ~d·1e-16.
            assert!(
                close(q, 1.0 / (k as f64 + 1.0), 1e-13),
                "{points:?} d={degree} k={k}: {q}"
            );
        }
        // The differentiation coefficients are exact for t^k, k ≤ d.
        for k in 1..=degree.min(8) as i32 {
            for r in 0..=degree {
                let dv: f64 = (0..=degree).map(|j| c.c[j][r] * c.tau[j].powi(k)).sum();
                let exact = k as f64 * c.tau[r].powi(k - 1);
                assert!(
                    close(dv, exact, 1e-8 * (1.0 + exact.abs())),
                    "{points:?} d={degree} k={k} r={r}"
                );
            }
        }
    }
}
