//! The implicit method (`Method::Sdirk4`) on stiff systems: closed forms, CVODES reference
//! values (CasADi 3.8.2, rtol 1e-12, atol 1e-14, from `benches/reference/integrator_casadi.py`,
//! kept in `benches/reference/results/integrator_casadi.json`) and finite differences.
use nlp::integrator::{Integrator, IntegratorError, IntegratorOptions, Method};
use symx::{Function, Matrix};
use testkit::ode::{robertson, van_der_pol};

fn options(rtol: f64, atol: f64) -> IntegratorOptions {
    IntegratorOptions {
        rtol,
        atol,
        method: Method::Sdirk4,
        ..Default::default()
    }
}

/// ẋ = A(a)x with eigenvalues −a (eigenvector (1, 1)) and −1e5 (eigenvector (1, −1)).
fn linear_stiff() -> Function {
    let x = Matrix::sym_vec("x", 2);
    let a = Matrix::sym_vec("a", 1);
    let b = 1e5;
    let d = -(a[0] + b) * 0.5;
    let o = (b - a[0]) * 0.5;
    Function::new(&[&x, &a], &[&[d * x[0] + o * x[1], o * x[0] + d * x[1]]]).unwrap()
}

const ROBERTSON_K: [f64; 3] = [0.04, 1e4, 3e7];

fn max_rel(a: &[f64], b: &[f64], floor: f64) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / y.abs().max(floor))
        .fold(0.0, f64::max)
}

#[test]
fn linear_stiff_system_matches_the_exponentials() {
    let (a, t) = (0.8, 3.0);
    let x0 = [1.5, -0.5];
    let int = Integrator::new(&linear_stiff(), 0.0, t, options(1e-10, 1e-12)).unwrap();
    let (xf, stats) = int.simulate(&x0, &[a]).unwrap();
    let (c1, c2) = ((x0[0] + x0[1]) / 2.0, (x0[0] - x0[1]) / 2.0);
    let (e1, e2) = ((-a * t).exp(), (-1e5 * t).exp());
    let exact = [c1 * e1 + c2 * e2, c1 * e1 - c2 * e2];
    println!("linear: {xf:?} vs {exact:?}, {stats:?}");
    assert!(max_rel(&xf, &exact, 1e-3) < 1e-8, "{xf:?} vs {exact:?}");
    // Stiffness handled: an explicit method needs h ≲ 3.3/1e5, i.e. ≳ 90 000 steps here.
    assert!(stats.accepted < 2000, "{stats:?}");
    let (_, jac) = int.simulate_with_jacobian(&x0, &[a]).unwrap();
    let phi = [
        (e1 + e2) / 2.0,
        (e1 - e2) / 2.0,
        (e1 - e2) / 2.0,
        (e1 + e2) / 2.0,
    ];
    let dxda = [-t * c1 * e1, -t * c1 * e1];
    let exact_jac: Vec<f64> = phi.iter().chain(&dxda).copied().collect();
    println!("jac {jac:?} vs {exact_jac:?}");
    assert!(max_rel(&jac, &exact_jac, 1e-3) < 1e-7, "{jac:?}");
}

/// (x0, p, T, CVODES x(T), CVODES ∂x(T)/∂(x0, p) column-major) from integrator_casadi.json.
type Reference = (Vec<f64>, Vec<f64>, f64, Vec<f64>, Vec<f64>);

fn reference(name: &str) -> Reference {
    let text = include_str!("../../benches/reference/results/integrator_casadi.json");
    let all: serde_json::Value = serde_json::from_str(text).unwrap();
    let case = &all[name];
    let vec = |key: &str| -> Vec<f64> {
        case[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let t = case["T"].as_f64().unwrap();
    (
        vec("x0"),
        vec("p"),
        t,
        vec("xf_ref"),
        vec("jac_ref_colmajor"),
    )
}

/// Runs `name` at (rtol, atol); returns the relative errors of x(T) and of the Jacobian
/// (entries below `floor` compared absolutely) and the accepted steps.
fn against_cvodes(
    ode: &Function,
    name: &str,
    rtol: f64,
    atol: f64,
    floor: f64,
) -> (f64, f64, usize) {
    let (x0, p, t, xf_ref, jac_ref) = reference(name);
    let int = Integrator::new(ode, 0.0, t, options(rtol, atol)).unwrap();
    let (xf, stats) = int.simulate(&x0, &p).unwrap();
    let (xs, jac) = int.simulate_with_jacobian(&x0, &p).unwrap();
    // The states integrated with their sensitivities take the very same steps.
    assert_eq!(xs, xf, "{name}");
    let ex = max_rel(&xf, &xf_ref, floor);
    let ej = max_rel(&jac, &jac_ref, floor);
    println!("{name} rtol {rtol}: x err {ex:.2e}, jac err {ej:.2e}, {stats:?}");
    (ex, ej, stats.accepted)
}

#[test]
fn robertson_matches_cvodes() {
    // At rtol 1e-9 our global error is ~1e-9 relative (measured 8.7e-10 on x, 1.6e-8 on the
    // Jacobian, whose small entries carry more relative error); the reference is ~1e-12.
    let (ex, ej, _) = against_cvodes(&robertson(), "robertson", 1e-9, 1e-14, 1e-12);
    assert!(ex < 1e-8 && ej < 1e-7, "{ex:e} {ej:e}");
    // To T = 4e10, y1 ≈ 5e-8: the reference's atol 1e-14 limits its own relative accuracy
    // there to ~1e-6 (measured difference 1.0e-6 on x, 1.1e-6 on the Jacobian).
    let (ex, ej, steps) = against_cvodes(&robertson(), "robertson4e10", 1e-9, 1e-20, 1e-12);
    assert!(ex < 1e-5 && ej < 1e-5, "{ex:e} {ej:e}");
    // Large steps in the slow phase: CVODES takes 590 at rtol 1e-6, DOPRI5 cannot finish.
    assert!(steps < 20_000, "{steps}");
}

#[test]
fn van_der_pol_stiff_states_match_cvodes() {
    // The states, through the relaxation jump (T = 1000) and over a whole period (T = 2000),
    // at rtol 1e-9: measured 7.8e-10 and 6.9e-9 relative, global error over ~10⁴ steps.
    for name in ["vdp1000", "vdp1000_2000"] {
        let (x0, p, t, xf_ref, _) = reference(name);
        let int = Integrator::new(&van_der_pol(), 0.0, t, options(1e-9, 1e-12)).unwrap();
        let (xf, stats) = int.simulate(&x0, &p).unwrap();
        let err = max_rel(&xf, &xf_ref, 1e-9);
        println!("{name}: {err:e} {stats:?}");
        assert!(err < 1e-7, "{name}: {xf:?} vs {xf_ref:?}");
        // At the comparison tolerances (rtol 1e-6, atol 1e-8): measured 2.6e-8 and 6.9e-8; the
        // bound leaves room for a global error of 100·rtol.
        let int = Integrator::new(&van_der_pol(), 0.0, t, options(1e-6, 1e-8)).unwrap();
        let (xf, stats) = int.simulate(&x0, &p).unwrap();
        let err = max_rel(&xf, &xf_ref, 1e-3);
        println!("{name} loose: {err:e} {stats:?}");
        assert!(
            err < 1e-4 && stats.accepted < 5000,
            "{name}: {xf:?} {stats:?}"
        );
    }
}

#[test]
fn sensitivities_match_finite_differences() {
    // Van der Pol μ = 1000 over its slow phase (T = 500, before the relaxation jump; see
    // docs/ocp.md §7 for sensitivities across the jump). Central differences of `simulate`
    // at rtol 1e-11 with steps 1e-4: truncation ~1e-8, integration noise ~1e-11/1e-4 = 1e-7.
    let (x0, p, t) = ([2.0, 0.0], [1000.0], 500.0);
    let int = Integrator::new(&van_der_pol(), 0.0, t, options(1e-11, 1e-14)).unwrap();
    let (_, jac) = int.simulate_with_jacobian(&x0, &p).unwrap();
    let point: Vec<f64> = x0.iter().chain(&p).copied().collect();
    for j in 0..3 {
        let step = 1e-4 * point[j].abs().max(1.0);
        let run = |d: f64| {
            let mut w = point.clone();
            w[j] += d;
            int.simulate(&w[..2], &w[2..]).unwrap().0
        };
        let (up, down) = (run(step), run(-step));
        let fd: Vec<f64> = (0..2).map(|i| (up[i] - down[i]) / (2.0 * step)).collect();
        // Relative to the column's largest entry: both errors scale with the column.
        let scale = fd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for i in 0..2 {
            let ad = jac[j * 2 + i];
            println!("d x{i}/d w{j}: {ad} vs fd {}", fd[i]);
            assert!((ad - fd[i]).abs() <= 1e-5 * scale, "{ad} vs {}", fd[i]);
        }
    }
}

#[test]
fn results_are_bit_identical_and_steps_shared() {
    let int = Integrator::new(&robertson(), 0.0, 40.0, options(1e-6, 1e-8)).unwrap();
    let x0 = [1.0, 0.0, 0.0];
    let a = int.simulate_with_jacobian(&x0, &ROBERTSON_K).unwrap();
    let b = int.simulate_with_jacobian(&x0, &ROBERTSON_K).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.0, int.simulate(&x0, &ROBERTSON_K).unwrap().0);
    let times = [0.0, 1e-3, 0.4, 4.0, 40.0];
    let xs = int.simulate_at(&x0, &ROBERTSON_K, &times).unwrap();
    assert_eq!(xs[0], x0);
    // Mass is conserved by every Runge–Kutta method (a linear invariant), to rounding.
    for x in &xs {
        assert!((x.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{x:?}");
    }
}

#[test]
fn failures_are_errors() {
    // ẋ = x², x(0) = 1 blows up at t = 1.
    let y = Matrix::sym_vec("y", 1);
    let blow = Function::new(&[&y], &[&[y[0].sq()]]).unwrap();
    let int = Integrator::new(&blow, 0.0, 2.0, options(1e-8, 1e-10)).unwrap();
    let err = int.simulate(&[1.0], &[]).unwrap_err();
    assert!(
        matches!(err, IntegratorError::StepTooSmall { t, .. } | IntegratorError::NewtonFailure { t, .. } | IntegratorError::NonFinite { t } | IntegratorError::MaxSteps { t, .. } if (t - 1.0).abs() < 1e-3),
        "{err:?}"
    );
    // A step budget too small for the problem.
    let o = IntegratorOptions {
        max_steps: 10,
        ..options(1e-6, 1e-8)
    };
    let int = Integrator::new(&robertson(), 0.0, 40.0, o).unwrap();
    assert!(matches!(
        int.simulate(&[1.0, 0.0, 0.0], &ROBERTSON_K),
        Err(IntegratorError::MaxSteps { steps: 10, .. })
    ));
}
