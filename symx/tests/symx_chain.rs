//! Long chains: every traversal in symx is iterative, so a 10⁶-node graph builds,
//! differentiates, compiles, evaluates and prints on the default 2 MiB test thread.
use symx::{forward, gradient, hessian, jacobian, Expr, Function, Matrix};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1.0)
}

// ---------------------------------------------------------------------------------------
// A 10⁶-node chain: iterative traversals only (this runs on the 2 MiB test thread)
// ---------------------------------------------------------------------------------------

#[test]
fn million_node_chain_builds_differentiates_compiles_and_evaluates() {
    let before = symx::node_count();
    let x = Expr::sym("x");
    let links = 340_000;
    let mut y = x;
    for _ in 0..links {
        y = y.sin() * 0.5 + x;
    }
    let built = symx::node_count() - before;
    assert!(built >= 1_000_000, "chain has only {built} nodes");

    let g = gradient(y, &[x]).unwrap();
    let t = forward(&[y], &[x], &[Expr::one()]).unwrap();
    let fun = Function::new(&[&[x]], &[&[y], &g, &t]).unwrap();
    // Registers are reused: the value alone needs a handful; the reverse sweep must keep
    // every link's partial derivative until the adjoint reaches it (O(links), inherent).
    let value_only = Function::new(&[&[x]], &[&[y]]).unwrap();
    assert!(
        value_only.work_size() < 10,
        "work size {}",
        value_only.work_size()
    );
    assert!(
        fun.work_size() < links + 100,
        "work size {}",
        fun.work_size()
    );
    let out = fun.call(&[&[0.3]]).unwrap();

    // Plain f64 reference with forward-mode derivative.
    let (mut v, mut d) = (0.3f64, 1.0f64);
    for _ in 0..links {
        d = 0.5 * v.cos() * d + 1.0;
        v = 0.5 * v.sin() + 0.3;
    }
    assert!(close(out[0][0], v, 1e-12), "{} vs {v}", out[0][0]);
    assert!(close(out[1][0], d, 1e-12), "{} vs {d}", out[1][0]);
    assert!(close(out[2][0], d, 1e-12), "{} vs {d}", out[2][0]);

    let dep = fun.dependency_sparsity(0, 0).unwrap();
    assert_eq!(dep.compute_nnz(), 1);
    let text = y.to_string();
    assert!(text.len() > 1_000_000);
}

#[test]
fn deep_chain_hessian_and_jacobian() {
    // Second-order derivatives through a long chain (smaller: the Hessian graph is ~10× larger).
    let x = Matrix::sym_vec("x", 2);
    let mut y = x[0];
    for _ in 0..5_000 {
        y = (y * x[1]).sin() + x[0];
    }
    let h = hessian(y, &x).unwrap();
    assert_eq!(h.nnz(), 3);
    let j = jacobian(&[y, y.sq()], &x).unwrap();
    let fun = Function::new(&[&x], &[h.values(), j.values()]).unwrap();
    let out = fun.call(&[&[0.1, 0.2]]).unwrap();
    assert!(out.iter().flatten().all(|v| v.is_finite()));
}
