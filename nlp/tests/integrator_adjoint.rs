//! Adjoint sensitivities (`Integrator::simulate_with_adjoint`): against the transpose of
//! the forward sensitivities (the same derivative of the same numerical map, so equal up
//! to rounding) and against central finite differences, for both methods; and as the
//! reverse hook of the integrator's call node (`to_function`), used by reverse-mode AD.
use nlp::integrator::{Integrator, IntegratorOptions, Method};
use symx::{gradient, hessian, jacobian, Expr, Function, Matrix};
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

/// `φ(x0, μ) = x₁(T)² + 3x₂(T)` through the integrator's call node, as a function of
/// `(x0, μ)`: its gradient by reverse mode (`symx::gradient`, the node's reverse hook), its
/// Jacobian row (`symx::jacobian`, the node's Jacobian) and its Hessian.
fn phi_derivatives(int: &Integrator) -> (Function, Function, Function, Function) {
    let node = int.to_function().unwrap();
    let z = Matrix::sym_vec("z", 3);
    let xf = node.apply(&[&z[..2], &z[2..]]).unwrap().remove(0);
    let phi = xf[0].sq() + 3.0 * xf[1];
    let value = Function::new(&[&z], &[&[phi]]).unwrap();
    let grad = Function::new(&[&z], &[&gradient(phi, &z).unwrap()]).unwrap();
    let jac = jacobian(&[phi], &z).unwrap().to_dense();
    let row = Function::new(&[&z], &[&jac]).unwrap();
    let hess = hessian(phi, &z).unwrap().to_dense();
    let hess = Function::new(&[&z], &[&hess]).unwrap();
    (value, grad, row, hess)
}

#[test]
fn reverse_mode_through_the_node_uses_the_adjoint() {
    let z = [2.0, 0.0, 1.0];
    for method in [Method::Dopri5, Method::Sdirk4] {
        let int = Integrator::new(&van_der_pol(), 0.0, 2.0, options(method, 1e-10)).unwrap();
        let (value, grad, row, hess) = phi_derivatives(&int);
        let g = grad.call(&[&z]).unwrap().remove(0);
        let j = row.call(&[&z]).unwrap().remove(0);
        // The gradient is the adjoint's row for the seed (2x₁(T), 3), bit for bit: the
        // reverse sweep called the hook, not the Jacobian.
        let (xf, _) = int.simulate(&z[..2], &z[2..]).unwrap();
        let (_, adj) = int
            .simulate_with_adjoint(&z[..2], &z[2..], &[2.0 * xf[0], 3.0])
            .unwrap();
        assert_eq!(g, adj, "{method:?}");
        // The Jacobian row goes through the forward sensitivities: the same derivative to
        // rounding (1e-10 relative, as the transpose test above).
        let scale = j.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for (a, b) in g.iter().zip(&j) {
            assert!((a - b).abs() <= 1e-10 * scale, "{method:?}: {g:?} vs {j:?}");
        }
        // Central differences of φ with steps 1e-4 at rtol 1e-10: truncation ~1e-8,
        // integration noise ~1e-10/1e-4 = 1e-6 relative, hence 1e-5.
        let fd: Vec<f64> = (0..3)
            .map(|k| {
                let at = |d: f64| {
                    let mut w = z;
                    w[k] += d;
                    value.call(&[&w]).unwrap()[0][0]
                };
                (at(1e-4) - at(-1e-4)) / 2e-4
            })
            .collect();
        for (a, f) in g.iter().zip(&fd) {
            assert!(
                (a - f).abs() <= 1e-5 * scale,
                "{method:?}: {g:?} vs fd {fd:?}"
            );
        }
        // Second derivatives still work (the hook is differentiated as the product built
        // from the Jacobian): against central differences of the gradient, 1e-4 relative
        // (noise ~1e-10/1e-4 on a gradient of size ~10).
        let h = hess.call(&[&z]).unwrap().remove(0);
        let hscale = h.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for k in 0..3 {
            let at = |d: f64| {
                let mut w = z;
                w[k] += d;
                grad.call(&[&w]).unwrap().remove(0)
            };
            let (up, down) = (at(1e-4), at(-1e-4));
            for i in k..3 {
                let fd = (up[i] - down[i]) / 2e-4;
                assert!(
                    (h[i + 3 * k] - fd).abs() <= 1e-4 * hscale,
                    "{method:?}: H[{i},{k}] {} vs fd {fd}",
                    h[i + 3 * k]
                );
            }
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

/// The cost of the gradient of one output through the integrator's call node: reverse
/// mode (the node's reverse hook, the adjoint) against the Jacobian row (the node's
/// forward sensitivities, what reverse mode cost before the hook), on the 50-state chain.
/// Medians of 7 interleaved repetitions; no assertion on times. Run with
/// `cargo test --release -p nlp --test integrator_adjoint -- --ignored --nocapture node_`.
#[test]
#[ignore = "a measurement: run by hand"]
fn node_gradient_cost_on_a_chain() {
    let n = 50;
    let mut z = vec![0.0; n];
    z.extend([2.0, 1.0]);
    for method in [Method::Dopri5, Method::Sdirk4] {
        let int = Integrator::new(&chain(n), 0.0, 10.0, options(method, 1e-6)).unwrap();
        let node = int.to_function().unwrap();
        let w = Matrix::sym_vec("w", n + 2);
        let out = node.apply(&[&w[..n], &w[n..]]).unwrap()[0][n - 1];
        let grad = Function::new(&[&w], &[&gradient(out, &w).unwrap()]).unwrap();
        let jac = jacobian(&[out], &w).unwrap().to_dense();
        let row = Function::new(&[&w], &[&jac]).unwrap();
        let (g, r) = (grad.call(&[&z]).unwrap(), row.call(&[&z]).unwrap());
        let diff = g[0]
            .iter()
            .zip(&r[0])
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        let (mut tg, mut tr) = (Vec::new(), Vec::new());
        for _ in 0..7 {
            let t = std::time::Instant::now();
            std::hint::black_box(grad.call(&[&z]).unwrap());
            tg.push(t.elapsed().as_secs_f64());
            let t = std::time::Instant::now();
            std::hint::black_box(row.call(&[&z]).unwrap());
            tr.push(t.elapsed().as_secs_f64());
        }
        tg.sort_by(f64::total_cmp);
        tr.sort_by(f64::total_cmp);
        println!(
            "{method:?} chain {n}, node gradient: reverse (hook) {:.3e} s, Jacobian row {:.3e} s \
             (medians of 7, interleaved), ratio {:.1}; max |difference| {diff:.1e}",
            tg[3],
            tr[3],
            tr[3] / tg[3]
        );
    }
}
