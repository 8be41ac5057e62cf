//! Automatic differentiation: forward (JVP), reverse (VJP), gradient, Jacobian, Hessian and
//! Lagrangian Hessian agree with each other, with the compiled evaluation and with central
//! finite differences on random expression trees; `if_else` derivatives never pick up NaN
//! from the untaken branch (CasADi #1805). The 10⁶-node chain is in symx/tests/symx_chain.rs.
//!
//! Tolerances. Finite differences use the central formula with step `h = 1e-5·max(1,|xⱼ|)`:
//! truncation error `h²|f'''|/6 ≈ 2·10⁻¹¹|f'''|` plus rounding `ε|f|/h ≈ 2·10⁻¹¹|f|`, so for
//! the moderate trees generated here (values below 10⁶, points 10⁻³ away from any kink)
//! `1e-5` relative (to `max(1, |derivative|)`) leaves ample margin while still catching any
//! wrong derivative formula. Exact methods compared with each other (forward vs reverse vs
//! Jacobian vs compiled) only differ by rounding and use `1e-10`.
#![allow(clippy::needless_range_loop)] // dense matrix indexing reads best with indices

use testkit::trees;

use proptest::prelude::*;
use symx::{
    forward, ge, gradient, gt, hessian, if_else, jacobian, lagrangian_hessian, lt, reverse, Expr,
    Function, Matrix, SparseMatrix,
};
use trees::{close, points, smooth_values, tree, Tree};

const NV: usize = 3;
const H: f64 = 1e-5;
const FD_TOL: f64 = 1e-5;
const EXACT_TOL: f64 = 1e-10;

/// Dense values of a sparse matrix of expressions whose entries were evaluated into `nz`.
fn dense(m: &SparseMatrix, nz: &[f64]) -> Vec<Vec<f64>> {
    let (r, c) = m.shape();
    let mut d = vec![vec![0.0; c]; r];
    for ((i, j, _), &v) in m.triplets().into_iter().zip(nz) {
        d[i][j] = v;
    }
    d
}

fn contains(m: &SparseMatrix, i: usize, j: usize) -> bool {
    symx::sparsity::contains(m.sparsity(), i, j)
}

fn check_derivatives(
    trees: &[&Tree],
    pts: &[Vec<f64>],
    v: &[f64],
    w: &[f64],
) -> Result<usize, TestCaseError> {
    let x = Matrix::sym_vec("x", NV);
    let vs = Matrix::sym_vec("v", NV);
    let ws = Matrix::sym_vec("w", trees.len());
    let y: Vec<Expr> = trees.iter().map(|t| t.build(&x)).collect();
    let jvp = forward(&y, &x, &vs).unwrap();
    let vjp = reverse(&y, &x, &ws).unwrap();
    let grad = gradient(y[0], &x).unwrap();
    let jac = jacobian(&y, &x).unwrap();
    let fun = Function::new(&[&x, &vs, &ws], &[&y, &jvp, &vjp, &grad, jac.values()]).unwrap();
    let values = Function::new(&[&x], &[&y]).unwrap();
    let mut checked = 0;
    for p in pts {
        let Some(reference) = smooth_values(trees, p, H) else {
            continue;
        };
        checked += 1;
        let out = fun.call(&[p, v, w]).unwrap();
        for (i, (&got, &want)) in out[0].iter().zip(&reference).enumerate() {
            prop_assert!(
                close(got, want, EXACT_TOL),
                "value {i} at {p:?}: compiled {got}, reference {want}"
            );
        }
        let j = dense(&jac, &out[4]);
        let mut f = |q: &[f64]| values.call(&[q]).unwrap().remove(0);
        for col in 0..NV {
            let fd = trees::central_difference(&mut f, p, col, H);
            for (row, &fd) in fd.iter().enumerate() {
                let ad = j[row][col];
                prop_assert!(
                    close(ad, fd, FD_TOL),
                    "d y{row}/d x{col} at {p:?}: AD {ad}, finite differences {fd}\n{}",
                    y[row]
                );
                // A derivative that finite differences see as non-zero is in the pattern.
                if fd.abs() > 10.0 * FD_TOL * reference[row].abs().max(1.0) {
                    prop_assert!(
                        contains(&jac, row, col),
                        "({row},{col}) missing from the pattern"
                    );
                }
            }
        }
        for (col, &g) in out[3].iter().enumerate() {
            prop_assert!(
                close(g, j[0][col], EXACT_TOL),
                "gradient {col}: {g} vs jacobian {}",
                j[0][col]
            );
        }
        for (row, &t) in out[1].iter().enumerate() {
            let want: f64 = (0..NV).map(|c| j[row][c] * v[c]).sum();
            let scale: f64 = (0..NV).map(|c| (j[row][c] * v[c]).abs()).sum();
            prop_assert!(
                (t - want).abs() <= EXACT_TOL * scale.max(1.0),
                "JVP {row}: {t} vs J·v {want}"
            );
        }
        for (col, &a) in out[2].iter().enumerate() {
            let want: f64 = (0..trees.len()).map(|r| j[r][col] * w[r]).sum();
            let scale: f64 = (0..trees.len()).map(|r| (j[r][col] * w[r]).abs()).sum();
            prop_assert!(
                (a - want).abs() <= EXACT_TOL * scale.max(1.0),
                "VJP {col}: {a} vs wᵀJ {want}"
            );
        }
    }
    Ok(checked)
}

fn check_hessian(
    f: &Tree,
    g: &Tree,
    pts: &[Vec<f64>],
    sigma: f64,
    lambda: f64,
) -> Result<usize, TestCaseError> {
    let x = Matrix::sym_vec("x", NV);
    let (fe, ge) = (f.build(&x), g.build(&x));
    let grad = gradient(fe, &x).unwrap();
    let hf = hessian(fe, &x).unwrap();
    let hg = hessian(ge, &x).unwrap();
    for (i, j, _) in hf.triplets() {
        prop_assert!(i >= j, "Hessian entry ({i},{j}) above the diagonal");
    }
    let (s, l) = (Expr::sym("sigma"), Expr::sym("lambda"));
    let hl = lagrangian_hessian(fe, &[ge], &x, s, &[l]).unwrap();
    let fun = Function::new(&[&x, &[s], &[l]], &[hf.values(), hg.values(), hl.values()]).unwrap();
    let grad_fun = Function::new(&[&x], &[&grad]).unwrap();
    let mut checked = 0;
    for p in pts {
        if smooth_values(&[f, g], p, H).is_none() {
            continue;
        }
        checked += 1;
        let out = fun.call(&[p, &[sigma], &[lambda]]).unwrap();
        let (dh, dg, dl) = (
            dense(&hf, &out[0]),
            dense(&hg, &out[1]),
            dense(&hl, &out[2]),
        );
        let gref = grad_fun.call(&[p]).unwrap().remove(0);
        let gscale = gref.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        let mut df = |q: &[f64]| grad_fun.call(&[q]).unwrap().remove(0);
        for col in 0..NV {
            let fd = trees::central_difference(&mut df, p, col, H);
            for (row, &fd) in fd.iter().enumerate() {
                // Only the lower triangle is stored; the upper entry is its mirror.
                let ad = if row >= col {
                    dh[row][col]
                } else {
                    dh[col][row]
                };
                prop_assert!(
                    close(ad, fd, FD_TOL * gscale),
                    "d²f/dx{row}dx{col} at {p:?}: AD {ad}, FD of gradient {fd}\n{fe}"
                );
                if fd.abs() > 10.0 * FD_TOL * gscale {
                    let (a, b) = if row >= col { (row, col) } else { (col, row) };
                    prop_assert!(
                        contains(&hf, a, b),
                        "({a},{b}) missing from Hessian pattern"
                    );
                }
            }
        }
        for r in 0..NV {
            for c in 0..=r {
                let want = sigma * dh[r][c] + lambda * dg[r][c];
                let scale = (sigma * dh[r][c]).abs() + (lambda * dg[r][c]).abs();
                prop_assert!(
                    (dl[r][c] - want).abs() <= EXACT_TOL * scale.max(1.0),
                    "Lagrangian Hessian ({r},{c}): {} vs σ∇²f+λ∇²g {want}",
                    dl[r][c]
                );
            }
        }
    }
    Ok(checked)
}

proptest! {
    // Each case builds and compiles a few dozen-node graph: ~1 ms in debug builds.
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn forward_reverse_compiled_and_finite_differences_agree(
        f1 in tree(NV, 4),
        f2 in tree(NV, 4),
        pts in points(NV, 4),
        v in prop::collection::vec(-1.0..1.0f64, NV),
        w in prop::collection::vec(-1.0..1.0f64, 2),
    ) {
        check_derivatives(&[&f1, &f2], &pts, &v, &w)?;
    }

    #[test]
    fn hessian_matches_finite_differences_of_gradient(
        f in tree(NV, 4),
        g in tree(NV, 3),
        pts in points(NV, 3),
        sigma in -2.0..2.0f64,
        lambda in -2.0..2.0f64,
    ) {
        check_hessian(&f, &g, &pts, sigma, lambda)?;
    }
}

/// The property tests are not vacuous: most random points are accepted as smooth test points.
#[test]
fn most_random_points_are_tested() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let (mut tested, mut total) = (0, 0);
    for _ in 0..100 {
        let f1 = tree(NV, 4).new_tree(&mut runner).unwrap().current();
        let f2 = tree(NV, 4).new_tree(&mut runner).unwrap().current();
        let pts = points(NV, 4).new_tree(&mut runner).unwrap().current();
        tested += check_derivatives(&[&f1, &f2], &pts, &[0.3, -0.2, 0.7], &[1.0, -0.5]).unwrap();
        total += pts.len();
    }
    assert!(tested * 2 > total, "only {tested} of {total} points tested");
}

// ---------------------------------------------------------------------------------------
// if_else and selections: no NaN from the branch not taken (CasADi #1805)
// ---------------------------------------------------------------------------------------

/// Value, gradient, Hessian and forward derivative of a scalar function of one variable.
fn derivatives_1d(build: impl Fn(Expr) -> Expr, at: &[f64]) -> Vec<[f64; 4]> {
    let x = Expr::sym("x");
    let f = build(x);
    let g = gradient(f, &[x]).unwrap();
    let h = hessian(f, &[x]).unwrap().to_dense();
    let t = forward(&[f], &[x], &[Expr::one()]).unwrap();
    let fun = Function::new(&[&[x]], &[&[f, g[0], h[(0, 0)], t[0]]]).unwrap();
    at.iter()
        .map(|&a| {
            let o = fun.call(&[&[a]]).unwrap().remove(0);
            [o[0], o[1], o[2], o[3]]
        })
        .collect()
}

fn assert_derivatives(build: impl Fn(Expr) -> Expr, cases: &[(f64, [f64; 3])]) {
    let at: Vec<f64> = cases.iter().map(|c| c.0).collect();
    for ((x, [v, d, dd]), got) in cases.iter().zip(derivatives_1d(build, &at)) {
        let want = [*v, *d, *dd, *d];
        for (k, (g, w)) in got.iter().zip(want).enumerate() {
            assert!(g.is_finite(), "quantity {k} at x = {x} is {g}");
            assert!(
                close(*g, w, 1e-12),
                "quantity {k} at x = {x}: got {g}, want {w}"
            );
        }
    }
}

#[test]
fn if_else_sqrt_untaken_branch_does_not_poison_derivatives() {
    // f = if_else(x > 0, sqrt(x), -x)  (CasADi #1805)
    assert_derivatives(
        |x| if_else(gt(x, 0.0), x.sqrt(), -x),
        &[
            (-4.0, [4.0, -1.0, 0.0]),
            (4.0, [2.0, 0.25, -1.0 / 32.0]),
            (-1e-300, [1e-300, -1.0, 0.0]),
        ],
    );
}

#[test]
fn if_else_log_untaken_branch_does_not_poison_derivatives() {
    assert_derivatives(
        |x| if_else(gt(x, 0.0), x.ln() * x, x.sq()),
        &[
            (-2.0, [4.0, -4.0, 2.0]),
            (0.0, [0.0, 0.0, 2.0]),
            (2.0, [2.0 * 2f64.ln(), 2f64.ln() + 1.0, 0.5]),
        ],
    );
    // The derivative of log itself is infinite at 0 and NaN below: still not taken.
    assert_derivatives(
        |x| if_else(lt(x, 1.0), 3.0 * x, (x - 1.0).ln()),
        &[
            (0.0, [0.0, 3.0, 0.0]),
            (-5.0, [-15.0, 3.0, 0.0]),
            (2.0, [0.0, 1.0, -1.0]),
        ],
    );
}

#[test]
fn nested_if_else() {
    // x ≥ 2: log(x−1); 0 < x < 2: sqrt(x); x ≤ 0: x²/2.
    let f = |x: Expr| {
        if_else(
            ge(x, 2.0),
            (x - 1.0).ln(),
            if_else(gt(x, 0.0), x.sqrt(), 0.5 * x.sq()),
        )
    };
    assert_derivatives(
        f,
        &[
            (3.0, [2f64.ln(), 0.5, -0.25]),
            (1.0, [1.0, 0.5, -0.25]),
            (-3.0, [4.5, -3.0, 1.0]),
            (0.0, [0.0, 0.0, 1.0]),
        ],
    );
    // The same inside arithmetic and a second level of derivatives through a product.
    assert_derivatives(
        |x| 2.0 * f(x) * x.exp(),
        &[(-1.0, [(-1f64).exp(), -(-1f64).exp(), -(-1f64).exp()])],
    );
}

#[test]
fn min_max_derivatives_follow_the_selected_operand() {
    // min(sqrt(x), 1): for x < 0 the value and derivative come from the constant.
    assert_derivatives(
        |x| x.sqrt().min(1.0),
        &[
            (4.0, [1.0, 0.0, 0.0]),
            (0.25, [0.5, 1.0, -2.0]),
            (-1.0, [1.0, 0.0, 0.0]),
        ],
    );
    // max(log(x), -x) at x < 0 takes -x although log(x) is NaN there.
    assert_derivatives(
        |x| x.ln().max(-x),
        &[
            (-1.0, [1.0, -1.0, 0.0]),
            (3.0, [3f64.ln(), 1.0 / 3.0, -1.0 / 9.0]),
        ],
    );
    assert_derivatives(
        |x| x.sq().max(x) + x.min(0.0),
        &[(-2.0, [2.0, -3.0, 2.0]), (0.5, [0.5, 1.0, 0.0])],
    );
}

#[test]
fn lagrangian_hessian_of_if_else_is_finite() {
    let x = Matrix::sym_vec("x", 2);
    let f = if_else(gt(x[0], 0.0), x[0].sqrt() * x[1], -x[0] * x[1]);
    let g = [if_else(gt(x[1], 0.0), x[1].ln(), x[1]) + x[0].sq()];
    let (s, l) = (Expr::sym("s"), Matrix::sym_vec("l", 1));
    let h = lagrangian_hessian(f, &g, &x, s, &l).unwrap();
    let fun = Function::new(&[&x, &[s], &l], &[h.values()]).unwrap();
    for p in [[-1.0, -1.0], [-1.0, 2.0], [4.0, -3.0], [4.0, 2.0]] {
        let out = fun.call(&[&p, &[1.0], &[2.0]]).unwrap().remove(0);
        assert!(out.iter().all(|v| v.is_finite()), "{out:?} at {p:?}");
    }
    let d = dense(&h, &fun.call(&[&[-1.0, -1.0], &[1.0], &[2.0]]).unwrap()[0]);
    // σ·f = −x0·x1 → ∂²/∂x1∂x0 = −1; λ·g → 2λ on (0,0); log branch untaken.
    assert_eq!(d, vec![vec![4.0, 0.0], vec![-1.0, 0.0]]);
}

// ---------------------------------------------------------------------------------------
// Simple exact derivatives of every operation
// ---------------------------------------------------------------------------------------

#[test]
fn derivatives_of_each_operation() {
    let a: f64 = 0.3;
    type Case = (fn(Expr) -> Expr, f64);
    let cases: [Case; 14] = [
        (|x| x.tan(), 1.0 + a.tan().powi(2)),
        (|x| x.asin(), 1.0 / (1.0 - a * a).sqrt()),
        (|x| x.acos(), -1.0 / (1.0 - a * a).sqrt()),
        (|x| x.atan(), 1.0 / (1.0 + a * a)),
        (|x| x.sinh(), a.cosh()),
        (|x| x.cosh(), a.sinh()),
        (|x| x.tanh(), 1.0 - a.tanh().powi(2)),
        (|x| x.abs(), 1.0),
        (|x| x.sign(), 0.0),
        (|x| x.powf(2.5), 2.5 * a.powf(1.5)),
        (|x| 2f64.pow_expr(x), 2f64.powf(a) * 2f64.ln()),
        (|x| x.atan2(2.0), 2.0 / (a * a + 4.0)),
        (|x| Expr::constant(2.0).atan2(x), -2.0 / (a * a + 4.0)),
        (|x| x.powi(-3), -3.0 * a.powi(-4)),
    ];
    for (k, (f, want)) in cases.iter().enumerate() {
        let x = Expr::sym("x");
        let d = gradient(f(x), &[x]).unwrap();
        let got = Function::new(&[&[x]], &[&d])
            .unwrap()
            .call(&[&[a]])
            .unwrap()[0][0];
        assert!(close(got, *want, 1e-14), "case {k}: {got} vs {want}");
    }
}

trait PowExpr {
    fn pow_expr(self, e: Expr) -> Expr;
}
impl PowExpr for f64 {
    fn pow_expr(self, e: Expr) -> Expr {
        Expr::constant(self).pow(e)
    }
}
