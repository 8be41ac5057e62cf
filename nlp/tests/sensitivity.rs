//! Parametric sensitivities (nlp::sensitivity) against central finite differences of
//! warm-started re-solves, on problems with equality rows, active and inactive
//! inequalities, active bounds, and an optimal control problem.
use nlp::ocp::{ButcherTableau, Horizon, Method, Ocp};
use nlp::{
    Compiled, Ipm, IpmOptions, ParametricSensitivity, Problem, Relation, Sensitivity,
    SensitivityError, Solution,
};
use symx::Matrix;

fn tight() -> Ipm {
    // Re-solves to a KKT error of 1e-12 so that the finite differences (step 1e-4) carry
    // an error of ~1e-12/1e-4 = 1e-8, below the 1e-6 tolerance of the comparisons.
    Ipm::new(IpmOptions {
        common: nlp::CommonOptions {
            tol: 1e-10,
            ..nlp::CommonOptions::default()
        },
        ..IpmOptions::default()
    })
}

/// Central differences of x*, λ* and z* with respect to each parameter entry of the
/// block `name`, by warm-started re-solves from `sol`.
fn finite_differences(
    compiled: &mut Compiled,
    name: &str,
    p: &[f64],
    sol: &Solution,
) -> Vec<[Vec<f64>; 3]> {
    let h = 1e-4;
    (0..p.len())
        .map(|j| {
            let mut side = |s: f64| {
                let mut q = p.to_vec();
                q[j] += s * h;
                compiled.set_value(name, &q).unwrap();
                let r = tight().solve_warm(compiled, sol).unwrap();
                assert!(r.status.is_success(), "{:?}", r.status);
                r
            };
            let (a, b) = (side(1.0), side(-1.0));
            let d = |u: &[f64], v: &[f64]| -> Vec<f64> {
                u.iter().zip(v).map(|(u, v)| (u - v) / (2.0 * h)).collect()
            };
            let z = |r: &Solution| -> Vec<f64> {
                r.z_u.iter().zip(&r.z_l).map(|(u, l)| u - l).collect()
            };
            [d(&a.x, &b.x), d(&a.lambda, &b.lambda), d(&z(&a), &z(&b))]
        })
        .collect()
}

fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    let diff = a
        .iter()
        .zip(b)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let scale = b.iter().map(|v| v.abs()).fold(0.0, f64::max);
    diff / scale.max(1e-3)
}

/// Compares every column of `s` with the finite differences (relative, max-norm).
fn assert_matches(s: &Sensitivity, fd: &[[Vec<f64>; 3]], tol: f64) {
    for (j, [dx, dl, dz]) in fd.iter().enumerate() {
        let ex = rel_err(&s.dx_dp[j], dx);
        let el = rel_err(&s.dlambda_dp[j], dl);
        // Bound multipliers: only the active ones are differentiable (an inactive one is 0
        // in theory and μ/slack ~ 1e-11 in an interior-point solution).
        let at = |v: &[f64]| -> Vec<f64> { s.active_bounds.iter().map(|&i| v[i]).collect() };
        let net: Vec<f64> = s.dz_u_dp[j]
            .iter()
            .zip(&s.dz_l_dp[j])
            .map(|(u, l)| u - l)
            .collect();
        let ez = if s.active_bounds.is_empty() {
            0.0
        } else {
            rel_err(&at(&net), &at(dz))
        };
        assert!(
            ex < tol && el < tol && ez < tol,
            "parameter {j}: dx {ex:.1e}, dλ {el:.1e}, dz {ez:.1e}"
        );
    }
}

#[test]
fn equality_constrained_example_of_sipopt() {
    // The parametric example shipped with sIPOPT (Ipopt/contrib/sIPOPT/examples/
    // parametric_cpp): min ‖x‖² s.t. 6x₁ + 3x₂ + 2x₃ = p₁, p₂x₁ + x₂ − x₃ = 1, x ≥ 0, at
    // p = (5, 1), where x* = (62, 38, 2)/98 (bounds inactive).
    let mut pb = Problem::new();
    let x = pb.variable("x", 3).unwrap();
    let p = pb.parameter("p", 2).unwrap();
    pb.set_value(&p, &[5.0, 1.0]).unwrap();
    pb.set_bounds(&x, 0.0, f64::INFINITY).unwrap();
    pb.minimize(x.sumsqr());
    pb.subject_to((6.0 * x[0] + 3.0 * x[1] + 2.0 * x[2]).eq(p[0]))
        .unwrap();
    pb.subject_to((p[1] * x[0] + x[1] - x[2]).eq(1.0)).unwrap();
    let mut compiled = pb.compile().unwrap();
    let sol = tight().solve(&mut compiled).unwrap();
    for (a, b) in sol.x.iter().zip([62.0 / 98.0, 38.0 / 98.0, 2.0 / 98.0]) {
        assert!((a - b).abs() < 1e-9);
    }
    let s = ParametricSensitivity::new(&pb)
        .unwrap()
        .compute(&sol, &[5.0, 1.0])
        .unwrap();
    assert_eq!((s.active_rows.len(), s.active_bounds.len()), (2, 0));
    // Closed form: x* = Aᵀ(AAᵀ)⁻¹b, so ∂x*/∂p₁ = Aᵀ(AAᵀ)⁻¹e₁ = (6·3 − 7, 3·3 − 7, 2·3 + 7)/98.
    for (a, b) in s.dx_dp[0]
        .iter()
        .zip([11.0 / 98.0, 2.0 / 98.0, 13.0 / 98.0])
    {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
    let fd = finite_differences(&mut compiled, "p", &[5.0, 1.0], &sol);
    assert_matches(&s, &fd, 1e-6);
}

#[test]
fn active_inequality_and_bound_are_held_fixed() {
    let mut pb = Problem::new();
    let x = pb.variable("x", 4).unwrap();
    let p = pb.parameter("p", 2).unwrap();
    let pv = [1.0, 1.0];
    pb.set_value(&p, &pv).unwrap();
    pb.minimize(
        (x[0] - p[0]).sq()
            + (x[1] - 2.0 * p[1]).sq()
            + (x[2] + 1.0).sq()
            + x[0] * x[1] / 4.0
            + (x[3] - 1.0).sq(),
    );
    pb.subject_to_named("active", (x[0] + x[1]).le(1.0 + p[1]))
        .unwrap();
    pb.subject_to_named("inactive", (x[0].sq() + x[1].sq()).le(100.0))
        .unwrap();
    pb.subject_to_named("link", (x[3] - p[0] * x[0] - x[2]).eq(0.0))
        .unwrap();
    pb.set_bounds(&[x[2]], 0.0, 5.0).unwrap(); // x₂ rests on its lower bound
    pb.set_bounds(&[x[1]], f64::NEG_INFINITY, 10.0).unwrap(); // never reached
    let mut compiled = pb.compile().unwrap();
    let sol = tight().solve(&mut compiled).unwrap();
    assert!(sol.status.is_success());
    let s = ParametricSensitivity::new(&pb)
        .unwrap()
        .compute(&sol, &pv)
        .unwrap();
    assert_eq!(s.active_rows, vec![0, 2]);
    assert_eq!(s.active_bounds, vec![2]);
    assert!(s.dx_dp.iter().all(|c| c[2] == 0.0));
    assert!(s.dlambda_dp.iter().all(|c| c[1] == 0.0));
    let fd = finite_differences(&mut compiled, "p", &pv, &sol);
    assert_matches(&s, &fd, 1e-6);
    // The first-order prediction is second-order accurate.
    let dp = [1e-3, -2e-3];
    compiled
        .set_value("p", &[pv[0] + dp[0], pv[1] + dp[1]])
        .unwrap();
    let moved = tight().solve_warm(&mut compiled, &sol).unwrap();
    let predicted = s.predict_x(&sol.x, &dp);
    assert!(rel_err(&predicted, &moved.x) < 1e-5);
}

#[test]
fn optimal_control_sensitivity_to_a_model_parameter() {
    // Van der Pol (examples/src/vdp_multiple_shooting.rs) with the damping coefficient μ of
    // ẋ₁ = (μ − x₂²)x₁ − x₂ + u as a parameter; x₁ ≥ −0.25 and |u| ≤ 1 are active on arcs.
    let mut ocp = Ocp::new(&["x1", "x2"], &["u"]);
    ocp.add_parameter("mu", &[1.0]).unwrap();
    ocp.set_dynamics(|x, u, p| {
        Matrix::from_vec(vec![(p[0] - x[1].sq()) * x[0] - x[1] + u[0], x[0]])
    });
    ocp.set_stage_cost(|x, u, _p| x[0].sq() + x[1].sq() + u[0].sq());
    ocp.set_horizon(Horizon::Fixed(10.0)).unwrap();
    ocp.set_initial_state(&[0.0, 1.0]).unwrap();
    ocp.set_state_bounds(&[-0.25, f64::NEG_INFINITY], &[f64::INFINITY; 2])
        .unwrap();
    ocp.set_control_bounds(&[-1.0], &[1.0]).unwrap();
    let tr = ocp
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 2), 20)
        .unwrap();
    let mut compiled = tr.compile().unwrap();
    let sol = tight().solve(&mut compiled).unwrap();
    assert!(sol.status.is_success());
    let s = ParametricSensitivity::new(tr.problem())
        .unwrap()
        .compute(&sol, &[1.0])
        .unwrap();
    assert!(
        s.active_bounds.len() > 2,
        "fixed initial state plus active arcs"
    );
    let fd = finite_differences(&mut compiled, "mu", &[1.0], &sol);
    assert_matches(&s, &fd, 1e-6);
}

#[test]
fn bad_inputs_are_errors() {
    let mut pb = Problem::new();
    let x = pb.variable("x", 1).unwrap();
    pb.minimize(x[0].sq());
    assert!(matches!(
        ParametricSensitivity::new(&pb),
        Err(SensitivityError::NoParameters)
    ));
    let p = pb.scalar_parameter("p").unwrap();
    pb.set_value(&[p], &[2.0]).unwrap();
    pb.minimize((x[0] - p).sq());
    let mut compiled = pb.compile().unwrap();
    let sol = Ipm::default().solve(&mut compiled).unwrap();
    let mut sens = ParametricSensitivity::new(&pb).unwrap();
    assert!(matches!(
        sens.compute(&sol, &[1.0, 2.0]),
        Err(SensitivityError::Size { .. })
    ));
    assert!(matches!(
        sens.compute(&sol, &[f64::NAN]),
        Err(SensitivityError::NotFinite { .. })
    ));
    let mut failed = sol.clone();
    failed.status = nlp::Status::MaximumIterationsExceeded;
    assert!(matches!(
        sens.compute(&failed, &[2.0]),
        Err(SensitivityError::NotConverged(_))
    ));
    // A maximum (negative curvature) is not a KKT point of a minimisation: wrong inertia.
    let mut pb2 = Problem::new();
    let y = pb2.variable("y", 2).unwrap();
    let q = pb2.scalar_parameter("q").unwrap();
    pb2.set_value(&[q], &[0.0]).unwrap();
    pb2.minimize(-(y[0].sq()) + y[1].sq() + q * y[0]);
    let fake = Solution {
        x: vec![0.0, 0.0],
        lambda: vec![],
        z_l: vec![0.0; 2],
        z_u: vec![0.0; 2],
        g: vec![],
        ..sol.clone()
    };
    let err = ParametricSensitivity::new(&pb2)
        .unwrap()
        .compute(&fake, &[0.0]);
    assert!(
        matches!(err, Err(SensitivityError::Inertia { .. })),
        "{err:?}"
    );
    assert_eq!(sens.compute(&sol, &[2.0]).unwrap().dx_dp, vec![vec![1.0]]);
}

#[test]
fn sensitivities_at_an_sqp_solution() {
    // The SQP's multipliers of inactive constraints are exactly zero; the same
    // sensitivities follow (compared with the interior point's at the same optimum).
    let mut pb = Problem::new();
    let x = pb.variable("x", 2).unwrap();
    let p = pb.scalar_parameter("p").unwrap();
    pb.set_value(&[p], &[1.0]).unwrap();
    pb.minimize((x[0] - 2.0 * p).sq() + (x[1] - p).sq() + x[0] * x[1]);
    pb.subject_to((x[0] + 2.0 * x[1]).le(1.0)).unwrap();
    pb.subject_to((x[0] - x[1]).le(10.0)).unwrap();
    let mut compiled = pb.compile().unwrap();
    let a = nlp::Sqp::new(nlp::SqpOptions::default())
        .solve(&mut compiled)
        .unwrap();
    let b = tight().solve(&mut compiled).unwrap();
    let mut sens = ParametricSensitivity::new(&pb).unwrap();
    let (sa, sb) = (
        sens.compute(&a, &[1.0]).unwrap(),
        sens.compute(&b, &[1.0]).unwrap(),
    );
    assert_eq!(sa.active_rows, vec![0]);
    assert_eq!(sa.active_rows, sb.active_rows);
    assert!(rel_err(&sa.dx_dp[0], &sb.dx_dp[0]) < 1e-6);
    let fd = finite_differences(&mut compiled, "p", &[1.0], &b);
    assert_matches(&sa, &fd, 1e-6);
    assert!(sa.weakly_active.is_empty() && sb.weakly_active.is_empty());

    // At p = 1/2 the unconstrained minimiser (1, 0) lies exactly on x₀ + 2x₁ = 1 with a
    // zero multiplier: weakly active, and reported as such.
    compiled.set_value("p", &[0.5]).unwrap();
    let c = tight().solve(&mut compiled).unwrap();
    let sc = sens.compute(&c, &[0.5]).unwrap();
    assert_eq!(sc.weakly_active, vec!["g[0] upper".to_string()]);
}
