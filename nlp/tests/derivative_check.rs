//! The derivative checker (nlp::derivative_check) on a hand-written NumericNlp: it passes
//! on correct callbacks, and names the entry of a deliberately wrong Jacobian, Hessian or
//! sparsity pattern.
use faer::sparse::SymbolicSparseColMat;
use nlp::derivative_check::{
    check_derivatives, Derivative, DerivativeCheckError, DerivativeCheckOptions,
};
use nlp::{Compiled, NumericNlp, Problem, Relation};

#[derive(Clone, Copy, PartialEq)]
enum Bug {
    None,
    /// ∂wave/∂vel written as vel instead of 2·vel.
    Jacobian,
    /// The (time, vel) entry of product's Hessian written as time instead of pos.
    Hessian,
    /// ∂product/∂time left out of the Jacobian pattern.
    Pattern,
}

/// f = pos²·vel + exp(time), product = pos·vel·time, wave = sin(pos) + vel².
struct Hand {
    bug: Bug,
    jac: SymbolicSparseColMat<usize>,
    hess: SymbolicSparseColMat<usize>,
}

impl Hand {
    fn new(bug: Bug) -> Hand {
        let (cp, ri) = if bug == Bug::Pattern {
            (vec![0, 2, 4, 4], vec![0, 1, 0, 1])
        } else {
            (vec![0, 2, 4, 5], vec![0, 1, 0, 1, 0])
        };
        Hand {
            bug,
            jac: SymbolicSparseColMat::new_checked(2, 3, cp, None, ri),
            hess: SymbolicSparseColMat::new_checked(
                3,
                3,
                vec![0, 3, 5, 6],
                None,
                vec![0, 1, 2, 1, 2, 2],
            ),
        }
    }
}

impl NumericNlp for Hand {
    fn n(&self) -> usize {
        3
    }
    fn m(&self) -> usize {
        2
    }
    fn bounds(&self, x_l: &mut [f64], x_u: &mut [f64], g_l: &mut [f64], g_u: &mut [f64]) {
        x_l.fill(f64::NEG_INFINITY);
        x_u.fill(f64::INFINITY);
        g_l.fill(0.0);
        g_u.fill(0.0);
    }
    fn initial_point(&self, x: &mut [f64]) {
        x.copy_from_slice(&[0.7, -1.3, 0.4]);
    }
    fn jac_g_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        &self.jac
    }
    fn hess_l_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        &self.hess
    }
    fn eval_f(&mut self, x: &[f64]) -> f64 {
        x[0] * x[0] * x[1] + x[2].exp()
    }
    fn eval_grad_f(&mut self, x: &[f64], grad: &mut [f64]) {
        grad.copy_from_slice(&[2.0 * x[0] * x[1], x[0] * x[0], x[2].exp()]);
    }
    fn eval_g(&mut self, x: &[f64], g: &mut [f64]) {
        g[0] = x[0] * x[1] * x[2];
        g[1] = x[0].sin() + x[1] * x[1];
    }
    fn eval_jac_g(&mut self, x: &[f64], v: &mut [f64]) {
        let dwave_dvel = if self.bug == Bug::Jacobian {
            x[1]
        } else {
            2.0 * x[1]
        };
        v[..4].copy_from_slice(&[x[1] * x[2], x[0].cos(), x[0] * x[2], dwave_dvel]);
        if self.bug != Bug::Pattern {
            v[4] = x[0] * x[1];
        }
    }
    fn eval_hess_l(&mut self, x: &[f64], s: f64, l: &[f64], v: &mut [f64]) {
        let product_time_vel = if self.bug == Bug::Hessian { x[2] } else { x[0] };
        v.copy_from_slice(&[
            s * 2.0 * x[1] - l[1] * x[0].sin(),
            s * 2.0 * x[0] + l[0] * x[2],
            l[0] * x[1],
            2.0 * l[1],
            l[0] * product_time_vel,
            s * x[2].exp(),
        ]);
    }
    fn variable_name(&self, i: usize) -> String {
        ["pos", "vel", "time"][i].to_string()
    }
    fn constraint_name(&self, i: usize) -> String {
        ["product", "wave"][i].to_string()
    }
}

#[test]
fn correct_derivatives_pass() {
    let report = check_derivatives(
        &mut Hand::new(Bug::None),
        &DerivativeCheckOptions::default(),
    )
    .unwrap();
    assert!(report.passed(), "{report}");
    // Central differences with h = 1e-6: truncation ~h²·|f'''| ≈ 1e-12, rounding
    // ~eps·|f|/h ≈ 1e-10; 1e-7 leaves room and is far below the 1e-4 tolerance.
    assert!(
        report.max_first_order_error < 1e-7,
        "{}",
        report.max_first_order_error
    );
    // Differences of analytic gradients: the same error orders.
    assert!(
        report.max_second_order_error < 1e-7,
        "{}",
        report.max_second_order_error
    );
}

#[test]
fn wrong_jacobian_entry_is_named() {
    let report = check_derivatives(
        &mut Hand::new(Bug::Jacobian),
        &DerivativeCheckOptions::default(),
    )
    .unwrap();
    assert!(!report.passed());
    assert_eq!(report.n_first_order_wrong, 1, "{report}");
    let m = &report.first_order[0];
    assert_eq!(m.derivative, Derivative::Jacobian);
    assert_eq!((m.row_name.as_str(), m.col_name.as_str()), ("wave", "vel"));
    assert_eq!(m.analytic, -1.3);
    // The true derivative 2·vel = −2.6, to the finite-difference accuracy above.
    assert!(
        (m.finite_difference + 2.6).abs() < 1e-7,
        "{}",
        m.finite_difference
    );
    assert!(m.to_string().contains("jac_g[wave, vel]"), "{m}");
    eprintln!("{m}");
}

#[test]
fn wrong_hessian_entry_is_named_with_its_constraint() {
    let report = check_derivatives(
        &mut Hand::new(Bug::Hessian),
        &DerivativeCheckOptions::default(),
    )
    .unwrap();
    assert_eq!(report.n_first_order_wrong, 0, "{report}");
    assert_eq!(report.n_second_order_wrong, 1, "{report}");
    let m = &report.second_order[0];
    assert_eq!(m.derivative, Derivative::Hessian);
    assert_eq!((m.row_name.as_str(), m.col_name.as_str()), ("time", "vel"));
    // λ = 1: analytic time = 0.4 against the true ∂²product/∂time∂vel = pos = 0.7.
    assert_eq!(m.analytic, 0.4);
    assert!(
        (m.finite_difference - 0.7).abs() < 1e-7,
        "{}",
        m.finite_difference
    );
    assert_eq!(m.culprits, vec!["product".to_string()]);
    eprintln!("{m}");
}

#[test]
fn entry_missing_from_the_pattern_is_reported() {
    let options = DerivativeCheckOptions {
        second_order: false,
        ..Default::default()
    };
    let report = check_derivatives(&mut Hand::new(Bug::Pattern), &options).unwrap();
    assert_eq!(report.n_first_order_wrong, 1, "{report}");
    let m = &report.first_order[0];
    assert_eq!(
        (m.row_name.as_str(), m.col_name.as_str(), m.in_pattern),
        ("product", "time", false)
    );
    assert!((m.finite_difference - 0.7 * -1.3).abs() < 1e-7);
}

#[test]
fn bad_arguments_are_errors() {
    let options = DerivativeCheckOptions {
        lambda: Some(vec![1.0]),
        ..Default::default()
    };
    let err = check_derivatives(&mut Hand::new(Bug::None), &options).unwrap_err();
    assert_eq!(
        err,
        DerivativeCheckError::WrongSize {
            what: "lambda",
            got: 1,
            expected: 2
        }
    );
    let options = DerivativeCheckOptions {
        perturbation: 0.0,
        ..Default::default()
    };
    assert!(matches!(
        check_derivatives(&mut Hand::new(Bug::None), &options),
        Err(DerivativeCheckError::BadSetting {
            what: "perturbation",
            ..
        })
    ));
}

#[test]
fn compiled_problem_passes() {
    // symx's exact derivatives of a problem with every kind of row.
    let mut pb = Problem::new();
    let x = pb.variable("x", 4).unwrap();
    pb.minimize((x[0] - x[1]).sq() * x[2].exp() + (x[3] * x[0]).sin());
    pb.subject_to_named("ball", (x[0].sq() + x[1].sq() + x[2].sq()).le(4.0))
        .unwrap();
    pb.subject_to_named("link", (x[1] * x[2] - x[3].cos()).eq(0.5))
        .unwrap();
    pb.set_initial(&x, &[0.3, -0.8, 1.1, 0.5]).unwrap();
    let mut compiled: Compiled = pb.compile().unwrap();
    let report = check_derivatives(&mut compiled, &DerivativeCheckOptions::default()).unwrap();
    assert!(report.passed(), "{report}");
    assert!(report.max_second_order_error < 1e-7, "{report}");
}
