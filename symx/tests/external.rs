//! External functions as call nodes: evaluation, derivatives through user-supplied
//! Jacobians (checked against central finite differences of the user's own evaluator),
//! the reverse hook (`with_vjp`) a gradient calls instead of the Jacobian, and the errors
//! when a derivative or native code is impossible.
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use symx::sparsity::pattern_from_entries;
use symx::{forward, gradient, hessian, jacobian, Function, Matrix, SymxError};

/// y = (x0·sin x1 + p, exp(x0·p)), inputs `x` (2) and `p` (1).
fn plant(x: &[f64], y: &mut [f64]) {
    y[0] = x[0] * x[1].sin() + x[2];
    y[1] = (x[0] * x[2]).exp();
}

/// Pattern of ∂y/∂(x, p): y0 depends on x0, x1, p; y1 on x0, p.
fn plant_pattern() -> symx::Sparsity {
    pattern_from_entries(2, 3, [(0, 0), (1, 0), (0, 1), (0, 2), (1, 2)])
}

/// The nonzeros of ∂y/∂(x, p) in column-major order: (0,0) (1,0) (0,1) (0,2) (1,2).
fn plant_jacobian(x: &[f64], j: &mut [f64]) {
    let e = (x[0] * x[2]).exp();
    j[0] = x[1].sin();
    j[1] = x[2] * e;
    j[2] = x[0] * x[1].cos();
    j[3] = 1.0;
    j[4] = x[0] * e;
}

/// Second derivatives: the Jacobian of `plant_jacobian`'s five outputs with respect to
/// (x0, x1, p), nonzeros in column-major order of the pattern below.
fn plant_jacobian_pattern() -> symx::Sparsity {
    // rows: the 5 nonzeros above; columns: x0, x1, p
    pattern_from_entries(
        5,
        3,
        [(1, 0), (2, 0), (4, 0), (0, 1), (2, 1), (1, 2), (4, 2)],
    )
}

fn plant_second(x: &[f64], h: &mut [f64]) {
    let e = (x[0] * x[2]).exp();
    // column x0: rows 1, 2, 4
    h[0] = x[2] * x[2] * e;
    h[1] = x[1].cos();
    h[2] = e + x[0] * x[2] * e;
    // column x1: rows 0, 2
    h[3] = x[1].cos();
    h[4] = -x[0] * x[1].sin();
    // column p: rows 1, 4
    h[5] = e + x[0] * x[2] * e;
    h[6] = x[0] * x[0] * e;
}

fn external_plant(order: usize) -> Function {
    let f = Function::external("plant", &[("x", 2), ("p", 1)], &[("y", 2)], plant).unwrap();
    if order == 0 {
        return f;
    }
    let nnz = plant_pattern().compute_nnz();
    let mut jac = Function::external(
        "jac_plant",
        &[("x", 2), ("p", 1)],
        &[("jac", nnz)],
        plant_jacobian,
    )
    .unwrap();
    if order >= 2 {
        let nnz2 = plant_jacobian_pattern().compute_nnz();
        let second = Function::external(
            "hess_plant",
            &[("x", 2), ("p", 1)],
            &[("jac", nnz2)],
            plant_second,
        )
        .unwrap();
        jac = jac
            .with_jacobian(&plant_jacobian_pattern(), &second)
            .unwrap();
    }
    f.with_jacobian(&plant_pattern(), &jac).unwrap()
}

/// The composed scalar s(z) = y0·y1 + y0² with y = plant((z0², z1), z0·z1), in plain Rust.
fn composed(z: &[f64]) -> f64 {
    let mut y = [0.0; 2];
    plant(&[z[0] * z[0], z[1], z[0] * z[1]], &mut y);
    y[0] * y[1] + y[0] * y[0]
}

fn composed_expr(f: &Function, z: &Matrix) -> symx::Expr {
    let x = [z[0] * z[0], z[1]];
    let p = [z[0] * z[1]];
    let y = f.apply(&[&x, &p]).unwrap();
    y[0][0] * y[0][1] + y[0][0] * y[0][0]
}

/// Central differences of `f` at `z` along each axis.
fn fd_gradient(f: impl Fn(&[f64]) -> f64, z: &[f64]) -> Vec<f64> {
    let h = 1e-6;
    (0..z.len())
        .map(|i| {
            let (mut a, mut b) = (z.to_vec(), z.to_vec());
            a[i] += h;
            b[i] -= h;
            (f(&a) - f(&b)) / (2.0 * h)
        })
        .collect()
}

#[test]
fn external_call_evaluates_the_users_code() {
    let f = external_plant(0);
    let z = Matrix::sym_vec("z", 2);
    let s = composed_expr(&f, &z);
    let g = Function::new(&[&z], &[&[s]]).unwrap();
    for point in [[0.3, 1.2], [-0.7, 0.4], [1.1, -2.0]] {
        // Same operations in the same order as the plain Rust composition: bit-identical.
        assert_eq!(
            g.call(&[&point]).unwrap()[0][0].to_bits(),
            composed(&point).to_bits()
        );
    }
    // Direct evaluation of the external function itself.
    let out = f.call(&[&[2.0, 0.5], &[0.25]]).unwrap();
    let mut y = [0.0; 2];
    plant(&[2.0, 0.5, 0.25], &mut y);
    assert_eq!(out[0], y.to_vec());
}

#[test]
fn gradient_and_jacobian_match_finite_differences() {
    let f = external_plant(1);
    let z = Matrix::sym_vec("z", 2);
    let s = composed_expr(&f, &z);
    let grad = gradient(s, &z).unwrap();
    let g = Function::new(&[&z], &[&grad]).unwrap();
    // Forward mode (Jacobian-vector product with seed (1, 0) and (0, 1)).
    let t0 = forward(&[s], &z, &[1.0.into(), 0.0.into()]).unwrap();
    let t1 = forward(&[s], &z, &[0.0.into(), 1.0.into()]).unwrap();
    let fwd = Function::new(&[&z], &[&[t0[0], t1[0]]]).unwrap();
    for point in [[0.3, 1.2], [-0.7, 0.4], [0.9, -1.3]] {
        let exact = g.call(&[&point]).unwrap()[0].clone();
        let fd = fd_gradient(composed, &point);
        let tangent = fwd.call(&[&point]).unwrap()[0].clone();
        for i in 0..2 {
            // Central differences with h = 1e-6: truncation O(h²) plus rounding
            // O(ε·|s|/h) ≈ 1e-9 for values of order 1.
            assert!(
                (exact[i] - fd[i]).abs() < 1e-7 * (1.0 + fd[i].abs()),
                "{exact:?} vs {fd:?}"
            );
            assert!((tangent[i] - exact[i]).abs() < 1e-12 * (1.0 + exact[i].abs()));
        }
    }
    // The Jacobian of the call's outputs keeps the declared pattern.
    let x = Matrix::sym_vec("x", 2);
    let p = Matrix::sym_vec("p", 1);
    let y = f.apply(&[&x, &p]).unwrap();
    let all: Vec<symx::Expr> = x.iter().chain(p.iter()).copied().collect();
    let jac = jacobian(&y[0], &all).unwrap();
    assert_eq!(
        symx::sparsity::entries(jac.sparsity()),
        symx::sparsity::entries(&plant_pattern())
    );
    assert_eq!(
        f.dependency_sparsity(1, 0).unwrap().compute_nnz(),
        2,
        "y0 and y1 both depend on p"
    );
}

#[test]
fn hessian_uses_the_jacobians_own_jacobian() {
    let f = external_plant(2);
    let z = Matrix::sym_vec("z", 2);
    let s = composed_expr(&f, &z);
    let h = hessian(s, &z).unwrap();
    let hf = Function::new(&[&z], &[h.values()]).unwrap();
    let grad = gradient(s, &z).unwrap();
    let gf = Function::new(&[&z], &[&grad]).unwrap();
    let entries = symx::sparsity::entries(h.sparsity());
    for point in [[0.3, 1.2], [-0.7, 0.4]] {
        let values = hf.call(&[&point]).unwrap()[0].clone();
        for (k, &(i, j)) in entries.iter().enumerate() {
            // ∂gᵢ/∂zⱼ by central differences of the (exact) gradient.
            let fd = fd_gradient(|w| gf.call(&[w]).unwrap()[0][i], &point)[j];
            assert!(
                (values[k] - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                "H[{i},{j}] = {} vs {fd}",
                values[k]
            );
        }
    }
}

#[test]
fn missing_derivatives_are_errors_naming_the_function() {
    let z = Matrix::sym_vec("z", 2);
    let s = composed_expr(&external_plant(0), &z);
    match gradient(s, &z) {
        Err(SymxError::NoDerivative { name }) => assert_eq!(name, "plant"),
        other => panic!("expected NoDerivative, got {other:?}"),
    }
    // First derivatives exist, second ones do not: the Hessian names the Jacobian.
    let s = composed_expr(&external_plant(1), &z);
    assert!(gradient(s, &z).is_ok());
    match hessian(s, &z) {
        Err(SymxError::NoDerivative { name }) => assert_eq!(name, "jac_plant"),
        other => panic!("expected NoDerivative, got {other:?}"),
    }
    // A later, valid derivative on the same thread is not affected.
    assert!(gradient(s, &z).is_ok());
}

#[test]
fn bad_jacobian_declarations_and_native_code_are_refused() {
    let f = external_plant(0);
    let jac = Function::external("j", &[("x", 2), ("p", 1)], &[("jac", 4)], |_, _| {}).unwrap();
    // 5 nonzeros declared, 4 returned.
    assert!(matches!(
        f.with_jacobian(&plant_pattern(), &jac),
        Err(SymxError::Length {
            expected: 5,
            got: 4,
            ..
        })
    ));
    let wrong_inputs = Function::external("j", &[("x", 3)], &[("jac", 5)], |_, _| {}).unwrap();
    assert!(f.with_jacobian(&plant_pattern(), &wrong_inputs).is_err());
    assert!(f
        .with_jacobian(&pattern_from_entries(3, 3, [(0, 0)]), &jac)
        .is_err());
    let x = Matrix::sym_vec("x", 1);
    let tape = Function::new(&[&x], &[&[x[0]]]).unwrap();
    assert!(matches!(
        tape.with_jacobian(&pattern_from_entries(1, 1, [(0, 0)]), &tape),
        Err(SymxError::NotExternal { .. })
    ));
    // A function calling an external one has no native code.
    let z = Matrix::sym_vec("z", 2);
    let g = Function::new(&[&z], &[&[composed_expr(&f, &z)]]).unwrap();
    let err = g.jit().unwrap_err().to_string();
    assert!(err.contains("'plant' is external"), "{err}");
    assert!(g.to_rust().unwrap_err().to_string().contains("'plant'"));
    assert!(g.to_c().unwrap_err().to_string().contains("'plant'"));
    assert!(Function::external("e", &[("x", 1), ("x", 2)], &[("y", 1)], |_, _| {}).is_err());
}

/// `x̄ = Jᵀȳ` of the plant, inputs `(x, p, ȳ)` stacked: written out from the same
/// partial derivatives as `plant_jacobian`.
fn plant_vjp(a: &[f64], xbar: &mut [f64]) {
    let mut j = [0.0; 5];
    plant_jacobian(&a[..3], &mut j);
    let (y0, y1) = (a[3], a[4]);
    xbar[0] = y0 * j[0] + y1 * j[1];
    xbar[1] = y0 * j[2];
    xbar[2] = y0 * j[3] + y1 * j[4];
}

/// The plant with Jacobians to `order` and a reverse hook, counting the calls of its
/// first-order Jacobian and of the hook.
fn hooked_plant(order: usize) -> (Function, Arc<AtomicUsize>, Arc<AtomicUsize>) {
    let (jac_calls, vjp_calls) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
    let counted = jac_calls.clone();
    let nnz = plant_pattern().compute_nnz();
    let mut jac = Function::external(
        "jac_plant",
        &[("x", 2), ("p", 1)],
        &[("jac", nnz)],
        move |x, j| {
            counted.fetch_add(1, Ordering::Relaxed);
            plant_jacobian(x, j)
        },
    )
    .unwrap();
    if order >= 2 {
        let nnz2 = plant_jacobian_pattern().compute_nnz();
        let second = Function::external(
            "hess_plant",
            &[("x", 2), ("p", 1)],
            &[("jac", nnz2)],
            plant_second,
        )
        .unwrap();
        jac = jac
            .with_jacobian(&plant_jacobian_pattern(), &second)
            .unwrap();
    }
    let counted = vjp_calls.clone();
    let vjp = Function::external(
        "adj_plant",
        &[("x", 2), ("p", 1), ("adj", 2)],
        &[("adj_in", 3)],
        move |a, xb| {
            counted.fetch_add(1, Ordering::Relaxed);
            plant_vjp(a, xb)
        },
    )
    .unwrap();
    let f = Function::external("plant", &[("x", 2), ("p", 1)], &[("y", 2)], plant)
        .unwrap()
        .with_jacobian(&plant_pattern(), &jac)
        .unwrap()
        .with_vjp(&vjp)
        .unwrap();
    (f, jac_calls, vjp_calls)
}

#[test]
fn a_gradient_calls_the_reverse_hook_a_jacobian_the_jacobian() {
    let (f, jac_calls, vjp_calls) = hooked_plant(2);
    let calls = || {
        (
            jac_calls.load(Ordering::Relaxed),
            vjp_calls.load(Ordering::Relaxed),
        )
    };
    let z = Matrix::sym_vec("z", 2);
    let s = composed_expr(&f, &z);
    let g = Function::new(&[&z], &[&gradient(s, &z).unwrap()]).unwrap();
    // A linear combination of the outputs: constant adjoints at the node, which a
    // gradient sends through the hook too (before the hook: the Jacobian's entries).
    let x = [z[0] * z[0], z[1]];
    let y = f.apply(&[&x, &[z[0] * z[1]]]).unwrap().remove(0);
    let lin = Function::new(&[&z], &[&gradient(2.0 * y[0] - y[1], &z).unwrap()]).unwrap();
    // The Jacobian of the outputs (unit adjoints, row by row) calls the Jacobian.
    let jy = jacobian(&y, &z).unwrap().to_dense();
    let jy = Function::new(&[&z], &[&jy]).unwrap();
    let h_hooked = hessian(s, &z).unwrap();
    let h_plain = hessian(composed_expr(&external_plant(2), &z), &z).unwrap();
    let hh = Function::new(&[&z], &[h_hooked.values()]).unwrap();
    let hp = Function::new(&[&z], &[h_plain.values()]).unwrap();
    for point in [[0.3, 1.2], [-0.7, 0.4]] {
        let before = calls();
        let grad = g.call(&[&point]).unwrap().remove(0);
        assert_eq!(
            calls(),
            (before.0, before.1 + 1),
            "the gradient: one hook call, no Jacobian"
        );
        let lg = lin.call(&[&point]).unwrap().remove(0);
        assert_eq!(
            calls(),
            (before.0, before.1 + 2),
            "constant adjoints: the hook"
        );
        let jac = jy.call(&[&point]).unwrap().remove(0);
        assert_eq!(
            calls(),
            (before.0 + 1, before.1 + 2),
            "a Jacobian: the Jacobian, no hook"
        );
        // Same partial derivatives, contracted in another order: equal to rounding
        // (1e-12), against the Jacobian and central differences as in
        // `gradient_and_jacobian_match_finite_differences`.
        let fd = fd_gradient(composed, &point);
        for i in 0..2 {
            assert!(
                (grad[i] - fd[i]).abs() < 1e-7 * (1.0 + fd[i].abs()),
                "{grad:?} vs {fd:?}"
            );
            let by_jac = 2.0 * jac[2 * i] - jac[2 * i + 1];
            assert!(
                (lg[i] - by_jac).abs() < 1e-12 * (1.0 + by_jac.abs()),
                "{lg:?} vs {jac:?}"
            );
        }
        // Second derivatives are those without the hook, bit for bit.
        assert_eq!(hh.call(&[&point]).unwrap(), hp.call(&[&point]).unwrap());
    }
}

#[test]
fn bad_reverse_hooks_are_refused() {
    let vjp = Function::external(
        "adj",
        &[("x", 2), ("p", 1), ("adj", 2)],
        &[("adj_in", 3)],
        plant_vjp,
    )
    .unwrap();
    // No Jacobian: the hook alone cannot give a Jacobian's rows or forward mode.
    assert!(matches!(
        external_plant(0).with_vjp(&vjp),
        Err(SymxError::NoDerivative { name }) if name == "plant"
    ));
    let tape = Function::new(&[&Matrix::sym_vec("a", 1)], &[&[symx::Expr::from(1.0)]]).unwrap();
    assert!(matches!(
        tape.with_vjp(&vjp),
        Err(SymxError::NotExternal { .. })
    ));
    let short = Function::external(
        "adj",
        &[("x", 2), ("p", 1), ("adj", 1)],
        &[("adj_in", 3)],
        |_, _| {},
    )
    .unwrap();
    let err = external_plant(1).with_vjp(&short).unwrap_err();
    assert!(
        matches!(
            err,
            SymxError::Length {
                index: 2,
                expected: 2,
                got: 1,
                ..
            }
        ),
        "{err}"
    );
    let narrow = Function::external(
        "adj",
        &[("x", 2), ("p", 1), ("adj", 2)],
        &[("adj_in", 2)],
        |_, _| {},
    )
    .unwrap();
    let err = external_plant(1).with_vjp(&narrow).unwrap_err();
    assert!(
        matches!(
            err,
            SymxError::Length {
                expected: 3,
                got: 2,
                ..
            }
        ),
        "{err}"
    );
}
