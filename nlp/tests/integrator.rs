//! nlp::integrator against closed forms and against CasADi 3.8.2 / CVODES reference values
//! (`benches/reference/integrator_casadi.py`, output kept in
//! `benches/reference/results/integrator_casadi.json`, CVODES at rtol 1e-12, atol 1e-14).
use nlp::integrator::{Integrator, IntegratorError, IntegratorOptions, Method};
use symx::{gradient, hessian, Function, Matrix, SymxError};
use testkit::ode::van_der_pol;

fn tight() -> IntegratorOptions {
    IntegratorOptions {
        rtol: 1e-11,
        atol: 1e-13,
        ..Default::default()
    }
}

/// ẋ = −k·x.
fn decay() -> Function {
    let x = Matrix::sym_vec("x", 1);
    let k = Matrix::sym_vec("k", 1);
    Function::new(&[&x, &k], &[&[-k[0] * x[0]]]).unwrap()
}

/// Harmonic oscillator ẋ₀ = x₁, ẋ₁ = −ω²x₀.
fn oscillator() -> Function {
    let x = Matrix::sym_vec("x", 2);
    let w = Matrix::sym_vec("w", 1);
    Function::new(&[&x, &w], &[&[x[1], -w[0].sq() * x[0]]]).unwrap()
}

/// Van der Pol ẋ₀ = x₁, ẋ₁ = μ(1 − x₀²)x₁ − x₀.
#[test]
fn exponential_decay_matches_the_closed_form() {
    let int = Integrator::new(&decay(), 0.0, 3.0, tight()).unwrap();
    let times = [0.0, 0.5, 1.0, 2.25, 3.0];
    let xs = int.simulate_at(&[2.0], &[0.7], &times).unwrap();
    for (t, x) in times.iter().zip(&xs) {
        let exact = 2.0 * (-0.7 * t).exp();
        // rtol 1e-11 per step, global error a few times that over ~30 steps.
        assert!(
            (x[0] - exact).abs() < 1e-9 * exact,
            "t={t}: {} vs {exact}",
            x[0]
        );
    }
    let (xf, jac) = int.simulate_with_jacobian(&[2.0], &[0.7]).unwrap();
    let e = (-0.7f64 * 3.0).exp();
    assert!((xf[0] - 2.0 * e).abs() < 1e-9);
    // ∂x/∂x0 = e^{−kT}, ∂x/∂k = −T·x0·e^{−kT}
    assert!(
        (jac[0] - e).abs() < 1e-9 && (jac[1] + 3.0 * 2.0 * e).abs() < 1e-8,
        "{jac:?}"
    );
}

#[test]
fn oscillator_state_transition_matrix() {
    let (w, t) = (1.3f64, 2.0f64);
    let int = Integrator::new(&oscillator(), 0.0, t, tight()).unwrap();
    let x0 = [0.4, -0.2];
    let (xf, jac) = int.simulate_with_jacobian(&x0, &[w]).unwrap();
    let (c, s) = ((w * t).cos(), (w * t).sin());
    let exact = [x0[0] * c + x0[1] * s / w, -x0[0] * w * s + x0[1] * c];
    // Φ = [[c, s/w], [−w s, c]], column-major: Φ00, Φ10, Φ01, Φ11
    let phi = [c, -w * s, s / w, c];
    // ∂x(T)/∂w by differentiating the closed form.
    let dx0 = -x0[0] * t * s + x0[1] * (t * c / w - s / (w * w));
    let dx1 = -x0[0] * (s + w * t * c) - x0[1] * t * s;
    for i in 0..2 {
        assert!((xf[i] - exact[i]).abs() < 1e-9, "{xf:?} vs {exact:?}");
    }
    for (a, b) in jac.iter().zip(phi.iter().chain(&[dx0, dx1])) {
        assert!((a - b).abs() < 1e-8, "{jac:?}");
    }
}

#[test]
fn van_der_pol_matches_cvodes() {
    // CVODES reference (integrator_casadi.py, "vdp1"): μ = 1, x0 = (2, 0), T = 5.
    let xf_ref = [-0.837077450319517, 1.307088937732762];
    let jac_ref = [
        -1.7727534974631634,
        -1.6626262661253832,
        -0.6535444687569124,
        -0.6141454617125838,
        -1.3140408873534164,
        -1.5690063312114468,
    ];
    let int = Integrator::new(&van_der_pol(), 0.0, 5.0, tight()).unwrap();
    let (xf, jac) = int.simulate_with_jacobian(&[2.0, 0.0], &[1.0]).unwrap();
    // Both solutions carry global errors of order 1e-10 (ours at rtol 1e-11).
    for (a, b) in xf.iter().zip(&xf_ref) {
        assert!((a - b).abs() < 1e-8, "{xf:?}");
    }
    for (a, b) in jac.iter().zip(&jac_ref) {
        assert!((a - b).abs() < 1e-7, "{jac:?}");
    }
    // At the comparison tolerances (rtol 1e-6, atol 1e-8) both agree to about 1e-5.
    let loose = IntegratorOptions {
        rtol: 1e-6,
        atol: 1e-8,
        ..Default::default()
    };
    let (xf, stats) = Integrator::new(&van_der_pol(), 0.0, 5.0, loose)
        .unwrap()
        .simulate(&[2.0, 0.0], &[1.0])
        .unwrap();
    assert!(stats.accepted > 10 && stats.rejected < stats.accepted);
    for (a, b) in xf.iter().zip(&xf_ref) {
        assert!((a - b).abs() < 1e-4, "{xf:?}");
    }
}

#[test]
fn results_are_bit_identical_across_runs() {
    let int = Integrator::new(&van_der_pol(), 0.0, 5.0, IntegratorOptions::default()).unwrap();
    let a = int.simulate_with_jacobian(&[2.0, 0.0], &[1.0]).unwrap();
    let b = int.simulate_with_jacobian(&[2.0, 0.0], &[1.0]).unwrap();
    let c = int.simulate(&[2.0, 0.0], &[1.0]).unwrap().0;
    assert_eq!(a, b);
    // The states integrated with their sensitivities take the very same steps.
    assert_eq!(a.0, c);
}

#[test]
fn integrator_function_derivatives_match_closed_forms() {
    // Both methods; with SDIRK4 the second-order sensitivities use its exactly solved
    // linear stages twice over.
    for method in [Method::Dopri5, Method::Sdirk4] {
        function_derivatives_match_closed_forms(method);
    }
}

fn function_derivatives_match_closed_forms(method: Method) {
    // xf = x0·e^{−kT}: gradient and Hessian through the call node.
    let t = 1.5;
    let options = IntegratorOptions { method, ..tight() };
    let f = Integrator::new(&decay(), 0.0, t, options)
        .unwrap()
        .to_function()
        .unwrap();
    let w = Matrix::sym_vec("w", 2);
    let xf = f.apply(&[&w[..1], &w[1..]]).unwrap()[0][0];
    let obj = xf * xf; // x0²·e^{−2kT}
    let g = gradient(obj, &w).unwrap();
    let h = hessian(obj, &w).unwrap();
    let fun = Function::new(&[&w], &[&[obj], &g, h.values()]).unwrap();
    let (x0, k) = (1.7, 0.4);
    let out = fun.call(&[&[x0, k]]).unwrap();
    let e = (-2.0 * k * t).exp();
    assert!((out[0][0] - x0 * x0 * e).abs() < 1e-9);
    assert!((out[1][0] - 2.0 * x0 * e).abs() < 1e-8);
    assert!((out[1][1] + 2.0 * t * x0 * x0 * e).abs() < 1e-8);
    let entries = symx::sparsity::entries(h.sparsity());
    let exact = |i: usize, j: usize| match (i, j) {
        (0, 0) => 2.0 * e,
        (1, 0) | (0, 1) => -4.0 * t * x0 * e,
        _ => 4.0 * t * t * x0 * x0 * e,
    };
    assert_eq!(entries.len(), 3);
    for (v, &(i, j)) in out[2].iter().zip(&entries) {
        assert!((v - exact(i, j)).abs() < 1e-7, "H[{i},{j}] = {v}");
    }
    // Third derivatives are refused, naming the deepest level.
    let hf = h.values()[0];
    match gradient(hf, &w) {
        Err(SymxError::NoDerivative { name }) => assert_eq!(name, "jac2_integrator"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn bad_input_is_refused_with_clear_errors() {
    let ode = decay();
    let o = IntegratorOptions::default();
    assert!(matches!(
        Integrator::new(&ode, 1.0, 1.0, o),
        Err(IntegratorError::BadOption {
            name: "tf - t0",
            ..
        })
    ));
    let bad = IntegratorOptions { rtol: 0.0, ..o };
    assert!(matches!(
        Integrator::new(&ode, 0.0, 1.0, bad),
        Err(IntegratorError::BadOption { name: "rtol", .. })
    ));
    let x = Matrix::sym_vec("x", 2);
    let wrong = Function::new(&[&x], &[&[x[0]]]).unwrap();
    let msg = Integrator::new(&wrong, 0.0, 1.0, o)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("ẋ has length 1, x has length 2"), "{msg}");
    let int = Integrator::new(&ode, 0.0, 1.0, o).unwrap();
    assert!(matches!(
        int.simulate(&[1.0, 2.0], &[0.1]),
        Err(IntegratorError::Length { what: "x0", .. })
    ));
    assert!(matches!(
        int.simulate_at(&[1.0], &[0.1], &[0.5, 0.2]),
        Err(IntegratorError::BadTimes { .. })
    ));
    // A stiff system exhausts max_steps with an explicit method: an error, not a wrong state.
    let stiff = IntegratorOptions {
        max_steps: 2000,
        rtol: 1e-6,
        atol: 1e-8,
        ..o
    };
    let int = Integrator::new(&van_der_pol(), 0.0, 1000.0, stiff).unwrap();
    assert!(matches!(
        int.simulate(&[2.0, 0.0], &[1000.0]),
        Err(IntegratorError::MaxSteps { steps: 2000, .. })
    ));
    // ẋ = x², x(0) = 1 blows up at t = 1 (reached to within the tolerances).
    let y = Matrix::sym_vec("y", 1);
    let blow = Function::new(&[&y], &[&[y[0].sq()]]).unwrap();
    let int = Integrator::new(&blow, 0.0, 2.0, o).unwrap();
    let err = int.simulate(&[1.0], &[]).unwrap_err();
    assert!(
        matches!(err, IntegratorError::StepTooSmall { t, .. } | IntegratorError::NonFinite { t } | IntegratorError::MaxSteps { t, .. } if (t - 1.0).abs() < 1e-6),
        "{err:?}"
    );
}
