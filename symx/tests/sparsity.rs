//! Structural sparsity: detected Jacobian and Hessian patterns contain every nonzero seen
//! at random points, are not dense where the truth is sparse, and
//! `Function::dependency_sparsity` (bit-vector propagation on the tape) agrees with the
//! pattern of `jacobian()`.
use testkit::trees;

use proptest::prelude::*;
use symx::sparsity::{bandwidth, contains, entries, pattern_from_entries};
use symx::{gradient, hessian, if_else, jacobian, lt, Expr, Function, Matrix, Sparsity};
use trees::{points, smooth_values, tree};

const NV: usize = 4;
const H: f64 = 1e-5;

/// Every entry of `small` is in `big`.
fn subset(small: &Sparsity, big: &Sparsity) -> bool {
    entries(small).into_iter().all(|(i, j)| contains(big, i, j))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// Nonzeros observed by finite differences lie in the detected Jacobian pattern, the
    /// evaluated symbolic Jacobian is zero exactly off the pattern (by construction) and the
    /// tape's dependency pattern contains the Jacobian's.
    #[test]
    fn observed_jacobian_nonzeros_are_detected(
        f in prop::collection::vec(tree(NV, 3), 3),
        pts in points(NV, 3),
    ) {
        let x = Matrix::sym_vec("x", NV);
        let y: Vec<Expr> = f.iter().map(|t| t.build(&x)).collect();
        let jac = jacobian(&y, &x).unwrap();
        let values = Function::new(&[&x], &[&y]).unwrap();
        let dep = values.dependency_sparsity(0, 0).unwrap();
        prop_assert!(subset(jac.sparsity(), &dep), "jacobian {:?}\ndependency {:?}", jac.sparsity(), dep);
        let refs: Vec<&trees::Tree> = f.iter().collect();
        for p in &pts {
            let Some(v) = smooth_values(&refs, p, H) else { continue };
            let mut call = |q: &[f64]| values.call(&[q]).unwrap().remove(0);
            for j in 0..NV {
                let fd = trees::central_difference(&mut call, p, j, H);
                for (i, d) in fd.iter().enumerate() {
                    if d.abs() > 1e-4 * v[i].abs().max(1.0) {
                        prop_assert!(contains(jac.sparsity(), i, j), "({i},{j}): FD {d} not in pattern");
                        prop_assert!(contains(&dep, i, j));
                    }
                }
            }
        }
    }

    /// The same for Hessians: observed second derivatives (finite differences of the
    /// compiled gradient) lie in the detected lower-triangular pattern.
    #[test]
    fn observed_hessian_nonzeros_are_detected(f in tree(NV, 4), pts in points(NV, 3)) {
        let x = Matrix::sym_vec("x", NV);
        let e = f.build(&x);
        let grad = gradient(e, &x).unwrap();
        let h = hessian(e, &x).unwrap();
        prop_assert!(entries(h.sparsity()).iter().all(|&(i, j)| i >= j));
        let gfun = Function::new(&[&x], &[&grad]).unwrap();
        // The Hessian pattern lies inside the dependency pattern of the gradient.
        let dep = gfun.dependency_sparsity(0, 0).unwrap();
        prop_assert!(subset(h.sparsity(), &dep));
        for p in &pts {
            let Some(v) = smooth_values(&[&f], p, H) else { continue };
            let mut call = |q: &[f64]| gfun.call(&[q]).unwrap().remove(0);
            for j in 0..NV {
                let fd = trees::central_difference(&mut call, p, j, H);
                for (i, d) in fd.iter().enumerate() {
                    if d.abs() > 1e-4 * v[0].abs().max(1.0) {
                        let (r, c) = (i.max(j), i.min(j));
                        prop_assert!(contains(h.sparsity(), r, c), "({r},{c}): FD {d} not in pattern");
                    }
                }
            }
        }
    }
}

fn banded_chain(n: usize) -> (Matrix, Vec<Expr>) {
    let x = Matrix::sym_vec("x", n);
    let g = (0..n - 1).map(|i| x[i + 1] * x[i].sin()).collect();
    (x, g)
}

#[test]
fn banded_jacobian_is_detected_banded() {
    // n > 64 exercises several 64-column blocks of the bit-vector propagation.
    let n = 150;
    let (x, g) = banded_chain(n);
    let jac = jacobian(&g, &x).unwrap();
    let p = jac.sparsity();
    assert_eq!(p.compute_nnz(), 2 * (n - 1));
    let want = pattern_from_entries(n - 1, n, (0..n - 1).flat_map(|i| [(i, i), (i, i + 1)]));
    assert_eq!(entries(p), entries(&want));
    let fun = Function::new(&[&x], &[&g]).unwrap();
    let dep = fun.dependency_sparsity(0, 0).unwrap();
    assert_eq!(entries(&dep), entries(p));
}

#[test]
fn banded_hessian_is_detected_banded() {
    // Σ (x[i+1] − x[i]²)²: a tridiagonal Hessian (lower triangle: bandwidth 1).
    let n = 200;
    let x = Matrix::sym_vec("x", n);
    let f: Expr = (0..n - 1).map(|i| (x[i + 1] - x[i].sq()).sq()).sum();
    let h = hessian(f, &x).unwrap();
    assert_eq!(bandwidth(h.sparsity()), 1);
    assert_eq!(h.nnz(), n + (n - 1));
    // Values at a point agree with the hand-written Hessian.
    let fun = Function::new(&[&x], &[h.values()]).unwrap();
    let p: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
    let out = fun.call(&[&p]).unwrap().remove(0);
    for ((i, j, _), v) in h.triplets().into_iter().zip(out) {
        let want = if i == j {
            let mut d = 0.0;
            if i + 1 < n {
                d += 12.0 * p[i] * p[i] - 4.0 * p[i + 1];
            }
            if i > 0 {
                d += 2.0;
            }
            d
        } else {
            -4.0 * p[j]
        };
        assert!(
            (v - want).abs() < 1e-12 * want.abs().max(1.0),
            "({i},{j}): {v} vs {want}"
        );
    }
}

#[test]
fn lagrangian_hessian_of_chain_constraints_is_banded() {
    let n = 100;
    let (x, g) = banded_chain(n);
    let f = x.sumsqr();
    let s = Expr::sym("sigma");
    let l = Matrix::sym_vec("lambda", g.len());
    let h = symx::lagrangian_hessian(f, &g, &x, s, &l).unwrap();
    assert_eq!(bandwidth(h.sparsity()), 1);
    assert_eq!(h.nnz(), 2 * n - 1);
}

#[test]
fn dependency_sparsity_agrees_with_jacobian_pattern() {
    let n = 70;
    let x = Matrix::sym_vec("x", n);
    let mut y = Vec::new();
    for i in 0..n {
        let e = match i % 5 {
            0 => x[i].exp() * x[(i * 7) % n],
            1 => if_else(lt(x[i], 0.0), x[(i + 3) % n].sqrt(), x[(i + 5) % n]),
            2 => x[i].atan2(x[(i + 1) % n]).min(x[(i + 40) % n]),
            3 => x[i].sign() + x[(i + 2) % n].powi(3),
            _ => Expr::constant(i as f64),
        };
        y.push(e);
    }
    let jac = jacobian(&y, &x).unwrap();
    let fun = Function::new(&[&x], &[&y, &y[..10]]).unwrap();
    assert_eq!(
        entries(&fun.dependency_sparsity(0, 0).unwrap()),
        entries(jac.sparsity())
    );
    // Second output: the first ten rows.
    let dep1 = fun.dependency_sparsity(0, 1).unwrap();
    assert_eq!(dep1.nrows(), 10);
    assert!(entries(&dep1)
        .into_iter()
        .all(|(i, j)| contains(jac.sparsity(), i, j)));
    // Conditions and sign() carry no derivative.
    assert!(!contains(jac.sparsity(), 1, 1));
    assert!(contains(jac.sparsity(), 1, 4));
    assert!(!contains(jac.sparsity(), 3, 3));
    // Multiple inputs: dependence on the second input only.
    let p = Expr::sym("p");
    let fun2 = Function::new(&[&x, &[p]], &[&[x[0] * p, x[1]]]).unwrap();
    assert_eq!(
        entries(&fun2.dependency_sparsity(1, 0).unwrap()),
        vec![(0, 0)]
    );
    assert!(fun2.dependency_sparsity(2, 0).is_err());
    assert!(fun2.dependency_sparsity(0, 1).is_err());
}

#[test]
fn jacobian_pattern_is_not_dense_for_sparse_matrix_expressions() {
    // A 3×3 matrix with structural zeros times a vector: the zeros survive into the Jacobian.
    let x = Matrix::sym_vec("x", 3);
    let a = Matrix::from_rows_f64(&[&[1.0, 0.0, 0.0], &[0.0, 2.0, 3.0], &[0.0, 0.0, 4.0]]).unwrap();
    let y = a.matmul(&x).unwrap();
    let jac = jacobian(&y, &x).unwrap();
    assert_eq!(
        entries(jac.sparsity()),
        vec![(0, 0), (1, 1), (1, 2), (2, 2)]
    );
    let c = x.cross(&Matrix::from_f64(&[1.0, 0.0, 0.0])).unwrap();
    let jc = jacobian(&c, &x).unwrap();
    assert_eq!(jc.nnz(), 2);
}
