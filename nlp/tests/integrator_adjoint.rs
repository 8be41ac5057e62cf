//! Adjoint sensitivities (`Integrator::simulate_with_adjoint`): against the transpose of
//! the forward sensitivities (the same derivative of the same numerical map, so equal up
//! to rounding) and against central finite differences, for both methods.
use nlp::integrator::{Integrator, IntegratorOptions, Method};
use symx::{Expr, Function, Matrix};
use testkit::ode::{robertson, van_der_pol};

/// A chain of `n` masses-free cells `ẋᵢ = a(xᵢ₋₁ − xᵢ) − 0.1xᵢ³` driven by `x₋₁ = u`,
/// parameters `(a, u)`: many states, one output of interest (the last cell).
fn chain(n: usize) -> Function {
    let x = Matrix::sym_vec("x", n);
    let p = Matrix::sym_vec("p", 2);
    let rhs: Vec<Expr> = (0..n)
        .map(|i| {
            let prev = if i == 0 { p[1] } else { x[i - 1] };
            p[0] * (prev - x[i]) - 0.1 * x[i] * x[i].sq()
        })
        .collect();
    Function::new(&[&x, &p], &[&rhs]).unwrap()
}

fn options(method: Method, rtol: f64) -> IntegratorOptions {
    IntegratorOptions {
        rtol,
        atol: rtol * 1e-2,
        method,
        ..Default::default()
    }
}

/// `vᵀ J` for a column-major `nx × m` Jacobian.
fn row(jac: &[f64], v: &[f64]) -> Vec<f64> {
    jac.chunks(v.len())
        .map(|col| col.iter().zip(v).map(|(a, b)| a * b).sum())
        .collect()
}

/// Checks the adjoint rows for `v` = each unit vector and one mixed vector against the
/// forward Jacobian: relative to the largest entry of `vᵀJ`, within `tol`.
fn check_against_forward(int: &Integrator, x0: &[f64], p: &[f64], tol: f64) {
    let (xf, jac) = int.simulate_with_jacobian(x0, p).unwrap();
    let n = x0.len();
    let mut seeds: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
        .collect();
    seeds.push((0..n).map(|j| 0.5 - j as f64 * 0.3).collect());
    for v in &seeds {
        let (xa, adj) = int.simulate_with_adjoint(x0, p, v).unwrap();
        // The adjoint integration takes `simulate`'s steps: the same x(tf), bit for bit.
        assert_eq!(xa, int.simulate(x0, p).unwrap().0);
        assert_eq!(xa, xf);
        let fwd = row(&jac, v);
        let scale = fwd.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let diff = adj
            .iter()
            .zip(&fwd)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        println!(
            "v {v:?}: adjoint {adj:?} forward {fwd:?} ({:.1e})",
            diff / scale
        );
        assert!(diff <= tol * scale, "{adj:?} vs {fwd:?}");
    }
}

#[test]
fn adjoint_is_the_transpose_of_the_forward_sensitivities() {
    // Rounding only: both are the exact derivative of the same steps, evaluated in a
    // different order; over ~10²–10³ steps 1e-10 relative leaves a wide margin above the
    // ~1e-13 measured.
    for method in [Method::Dopri5, Method::Sdirk4] {
        let int = Integrator::new(&van_der_pol(), 0.0, 5.0, options(method, 1e-8)).unwrap();
        check_against_forward(&int, &[2.0, 0.0], &[1.0], 1e-10);
    }
    let int = Integrator::new(&robertson(), 0.0, 40.0, options(Method::Sdirk4, 1e-6)).unwrap();
    check_against_forward(&int, &[1.0, 0.0, 0.0], &[0.04, 1e4, 3e7], 1e-10);
    let int = Integrator::new(&chain(6), 0.0, 3.0, options(Method::Sdirk4, 1e-6)).unwrap();
    check_against_forward(&int, &[0.5; 6], &[2.0, 1.0], 1e-10);
}

#[test]
fn adjoint_matches_finite_differences() {
    // Central differences of `simulate` at rtol 1e-11 with steps 1e-4: truncation ~1e-8,
    // integration noise ~1e-11/1e-4 = 1e-7, hence 1e-5 relative to the row's largest entry.
    for method in [Method::Dopri5, Method::Sdirk4] {
        let int = Integrator::new(&van_der_pol(), 0.0, 5.0, options(method, 1e-11)).unwrap();
        let (x0, p, v) = ([2.0, 0.0], [1.0], [0.3, -1.2]);
        let (_, adj) = int.simulate_with_adjoint(&x0, &p, &v).unwrap();
        let point = [x0[0], x0[1], p[0]];
        let fd: Vec<f64> = (0..3)
            .map(|j| {
                let step = 1e-4;
                let run = |d: f64| {
                    let mut w = point;
                    w[j] += d;
                    let xf = int.simulate(&w[..2], &w[2..]).unwrap().0;
                    v[0] * xf[0] + v[1] * xf[1]
                };
                (run(step) - run(-step)) / (2.0 * step)
            })
            .collect();
        let scale = fd.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        println!("{method:?}: adjoint {adj:?} vs fd {fd:?}");
        for (a, f) in adj.iter().zip(&fd) {
            assert!((a - f).abs() <= 1e-5 * scale, "{method:?}: {a} vs {f}");
        }
    }
}

#[test]
fn bad_seed_is_an_error() {
    let int = Integrator::new(&van_der_pol(), 0.0, 1.0, IntegratorOptions::default()).unwrap();
    let err = int
        .simulate_with_adjoint(&[2.0, 0.0], &[1.0], &[1.0])
        .unwrap_err();
    assert_eq!(err.to_string(), "v has length 1, expected 2");
}

/// The cost of one output's gradient by the adjoint against the forward sensitivities, on
/// a 50-state chain (52 sensitivity columns). Prints medians of interleaved repetitions
/// and the f-evaluation counts; timings only, no assertion on them. Run with
/// `cargo test --release -p nlp --test integrator_adjoint -- --ignored --nocapture`.
#[test]
#[ignore = "a measurement: run by hand"]
fn adjoint_cost_against_forward_on_a_chain() {
    let n = 50;
    let (x0, p) = (vec![0.0; n], [2.0, 1.0]);
    let mut v = vec![0.0; n];
    v[n - 1] = 1.0;
    for method in [Method::Dopri5, Method::Sdirk4] {
        let int = Integrator::new(&chain(n), 0.0, 10.0, options(method, 1e-6)).unwrap();
        let (_, stats) = int.simulate(&x0, &p).unwrap();
        let (_, jac) = int.simulate_with_jacobian(&x0, &p).unwrap();
        let (_, adj) = int.simulate_with_adjoint(&x0, &p, &v).unwrap();
        let fwd = row(&jac, &v);
        let diff = adj
            .iter()
            .zip(&fwd)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        let (mut tf, mut ta) = (Vec::new(), Vec::new());
        for _ in 0..7 {
            let t = std::time::Instant::now();
            std::hint::black_box(int.simulate_with_jacobian(&x0, &p).unwrap());
            tf.push(t.elapsed().as_secs_f64());
            let t = std::time::Instant::now();
            std::hint::black_box(int.simulate_with_adjoint(&x0, &p, &v).unwrap());
            ta.push(t.elapsed().as_secs_f64());
        }
        tf.sort_by(f64::total_cmp);
        ta.sort_by(f64::total_cmp);
        println!(
            "{method:?} chain {n}: {stats:?}; forward sensitivities {:.3e} s, adjoint {:.3e} s \
             (medians of 7, interleaved), ratio {:.1}; max |adjoint − forward| {diff:.1e}",
            tf[3],
            ta[3],
            tf[3] / ta[3]
        );
    }
}
