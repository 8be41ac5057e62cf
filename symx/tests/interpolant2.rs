//! 2-D lookup tables (`Interpolant2`): values and derivatives against CasADi 3.8.2
//! (benches/reference/interpolant2_casadi.py, output in
//! benches/reference/results/interpolant2_casadi.txt), forward vs reverse mode, finite
//! differences, exact reproduction of the polynomials each method contains, calls, and
//! bad data.
use symx::{forward, reverse, Expr, Function, Interpolant2, SymxError};

const XG: [f64; 5] = [0.0, 0.5, 1.5, 2.0, 3.0];
const YG: [f64; 5] = [-1.0, 0.0, 0.7, 2.0, 2.5];

/// V[i + 5j] = sin(x_i) + cos(2 y_j) + 0.3 x_i y_j (x fastest), as in the script.
fn values() -> Vec<f64> {
    YG.iter()
        .flat_map(|&y| {
            XG.iter()
                .map(move |&x| x.sin() + (2.0 * y).cos() + 0.3 * x * y)
        })
        .collect()
}

/// (point, value, gradient, Hessian [xx, xy, yy]) from the CasADi script's output.
type Row = ([f64; 2], f64, [f64; 2], [f64; 3]);

const LINEAR: [Row; 9] = [
    (
        [0.2, -0.5],
        0.45369679716810996,
        [0.808851077208406, 1.4761468365471422],
        [0.0; 3],
    ),
    (
        [1.0, 1.0],
        1.0183633830973267,
        [0.8180694479998514, -0.33354674135681],
        [0.0; 3],
    ),
    (
        [2.9, 1.9],
        1.2806488032085175,
        [-0.19817741876581474, 0.23645325864319],
        [0.0; 3],
    ),
    (
        [0.7, 2.2],
        0.7663181298712969,
        [1.1780694479998515, 2.0846116126536764],
        [0.0; 3],
    ),
    (
        [1.7, -0.9],
        0.2286838098002772,
        [-0.4463951195567455, 1.9261468365471424],
        [0.0; 3],
    ),
    (
        [2.4, 0.35],
        1.4390100307694764,
        [-0.6631774187658145, -0.4657612244282271],
        [0.0; 3],
    ),
    (
        [-0.5, 0.5],
        -0.14730615081831655,
        [1.108851077208406, -1.3357612244282273],
        [0.0; 3],
    ),
    (
        [3.5, 2.6],
        2.9581546454055547,
        [0.01182258123418567, 2.9246116126536776],
        [0.0; 3],
    ),
    (
        [1.0, 3.0],
        2.859428254394193,
        [1.4180694479998515, 2.1746116126536768],
        [0.0; 3],
    ),
];

const BSPLINE: [Row; 9] = [
    (
        [0.2, -0.5],
        1.0480634571527558,
        [0.8313126346663388, 1.3079659682043359],
        [-0.3107534593723522, 0.30000000000001453, -4.675604643120833],
    ),
    (
        [1.0, 1.0],
        0.8886057243089243,
        [0.8427976068902382, -0.99214670715835],
        [-0.785534110067885, 0.2999999999999971, 0.9283122443048879],
    ),
    (
        [2.9, 1.9],
        1.1701207874322195,
        [-0.43828819009195025, 1.4397499495722836],
        [
            -0.46649121935750504,
            0.29999999999997945,
            3.2092358817631674,
        ],
    ),
    (
        [0.7, 2.2],
        0.7027923797451252,
        [1.4117514283089727, 1.8565668959741761],
        [-0.6074913660570409, 0.2999999999999964, 3.969543760915986],
    ),
    (
        [1.7, -0.9],
        0.4926933202976828,
        [-0.4018114596311802, 3.9511150926708645],
        [-0.9943033314104505, 0.2999999999999931, -6.290140979211823],
    ),
    (
        [2.4, 0.35],
        1.5940996246781474,
        [-0.61506215207436, -0.5481698499162074],
        [-0.68641293271291, 0.3000000000000091, -1.2447149289274906],
    ),
    ([-0.5, 0.5], 0.0, [0.0; 2], [0.0; 3]),
    ([3.5, 2.6], 0.0, [0.0; 2], [0.0; 3]),
    ([1.0, 3.0], 0.0, [0.0; 2], [0.0; 3]),
];

fn close(got: f64, want: f64, tol: f64) -> bool {
    (got - want).abs() <= tol * (1.0 + want.abs())
}

/// Value, gradient and Hessian [xx, xy, yx, yy] of the table at a point, compiled from
/// reverse mode (gradient), reverse over reverse (Hessian rows); and the same from forward
/// mode and forward over forward, which must agree to rounding.
struct Derivatives {
    reverse: Function,
    forward: Function,
}

fn derivatives(table: &Interpolant2) -> Derivatives {
    let (x, y) = (Expr::sym("x"), Expr::sym("y"));
    let v = [x, y];
    let f = table.eval(x, y);
    let (one, zero) = (Expr::constant(1.0), Expr::constant(0.0));
    let g = reverse(&[f], &v, &[one]).unwrap();
    let h_xrow = reverse(&[g[0]], &v, &[one]).unwrap();
    let h_yrow = reverse(&[g[1]], &v, &[one]).unwrap();
    let rev = Function::new(
        &[&v],
        &[&[f], &g, &[h_xrow[0], h_xrow[1], h_yrow[0], h_yrow[1]]],
    )
    .unwrap();
    let gx = forward(&[f], &v, &[one, zero]).unwrap()[0];
    let gy = forward(&[f], &v, &[zero, one]).unwrap()[0];
    let hxx = forward(&[gx], &v, &[one, zero]).unwrap()[0];
    let hxy = forward(&[gx], &v, &[zero, one]).unwrap()[0];
    let hyx = forward(&[gy], &v, &[one, zero]).unwrap()[0];
    let hyy = forward(&[gy], &v, &[zero, one]).unwrap()[0];
    let fwd = Function::new(&[&v], &[&[f], &[gx, gy], &[hxx, hxy, hyx, hyy]]).unwrap();
    Derivatives {
        reverse: rev,
        forward: fwd,
    }
}

/// Checks value, gradient and Hessian against a row of CasADi's output; CasADi's 'linear'
/// has zero second derivatives (it does not differentiate the bilinear cross term), so
/// with `cross_from_casadi` false the mixed derivative is checked elsewhere (finite
/// differences) and only the diagonal (0 on bilinear cells) is compared.
fn check_rows(table: &Interpolant2, rows: &[Row], tol: f64, cross_from_casadi: bool) {
    let d = derivatives(table);
    for (p, value, grad, hess) in rows {
        let r = d.reverse.call(&[p]).unwrap();
        let f = d.forward.call(&[p]).unwrap();
        assert!(
            close(r[0][0], *value, tol),
            "value at {p:?}: {} vs {value}",
            r[0][0]
        );
        assert_eq!(
            table.value(p[0], p[1]),
            r[0][0],
            "value() vs compiled at {p:?}"
        );
        for k in 0..2 {
            assert!(
                close(r[1][k], grad[k], tol),
                "grad {k} at {p:?}: {} vs {}",
                r[1][k],
                grad[k]
            );
            assert!(
                close(f[1][k], r[1][k], 1e-14),
                "forward vs reverse grad at {p:?}"
            );
        }
        let want = [hess[0], hess[1], hess[1], hess[2]];
        for k in 0..4 {
            if cross_from_casadi || k == 0 || k == 3 {
                assert!(
                    close(r[2][k], want[k], tol),
                    "hess {k} at {p:?}: {} vs {}",
                    r[2][k],
                    want[k]
                );
            }
            assert!(
                close(f[2][k], r[2][k], 1e-13),
                "forward vs reverse Hessian at {p:?}"
            );
        }
        assert!(close(r[2][1], r[2][2], 1e-13), "symmetric Hessian at {p:?}");
    }
}

#[test]
fn linear_matches_casadi() {
    let table = Interpolant2::linear(&XG, &YG, &values()).unwrap();
    // Same formula as CasADi, different operation order: agreement to rounding.
    check_rows(&table, &LINEAR, 1e-13, false);
}

#[test]
fn bspline_matches_casadi() {
    let table = Interpolant2::bspline(&XG, &YG, &values()).unwrap();
    // CasADi fits a B-spline by a linear solve and differentiates the B-spline basis;
    // symx solves the not-a-knot system per axis: the same function, so values and
    // derivatives agree to rounding (they pass at 1e-13; 1e-12 leaves room for a
    // different operation order, while a different end condition fails by ~1e-2).
    check_rows(&table, &BSPLINE, 1e-12, true);
}

/// Central differences of the compiled value (gradient) and gradient (Hessian) at points
/// inside cells: with h = 1e-5 the truncation error is ~h²·|f'''| ≈ 1e-9 and rounding
/// ~1e-16/h ≈ 1e-11, so 1e-7 relative is a wide margin that a wrong formula still fails.
#[test]
fn derivatives_match_finite_differences() {
    let vals = values();
    let tables = [
        Interpolant2::linear(&XG, &YG, &vals).unwrap(),
        Interpolant2::bspline(&XG, &YG, &vals).unwrap(),
    ];
    let points = [[0.2, -0.5], [1.1, 0.4], [2.9, 1.9], [1.7, 2.3], [0.6, 0.05]];
    let h = 1e-5;
    for table in &tables {
        let d = derivatives(table);
        let at = |p: [f64; 2]| d.reverse.call(&[&p]).unwrap();
        for p in points {
            let r = at(p);
            for (k, e) in [[h, 0.0], [0.0, h]].iter().enumerate() {
                let plus = at([p[0] + e[0], p[1] + e[1]]);
                let minus = at([p[0] - e[0], p[1] - e[1]]);
                let fd = (plus[0][0] - minus[0][0]) / (2.0 * h);
                assert!(
                    close(r[1][k], fd, 1e-7),
                    "grad {k} at {p:?}: {} vs {fd}",
                    r[1][k]
                );
                for j in 0..2 {
                    let fd = (plus[1][j] - minus[1][j]) / (2.0 * h);
                    let got = r[2][2 * j + k];
                    assert!(
                        close(got, fd, 1e-7),
                        "hess ({j},{k}) at {p:?}: {got} vs {fd}"
                    );
                }
            }
        }
    }
}

/// Each method contains a polynomial space it must reproduce exactly (to rounding): the
/// bilinear interpolant reproduces a + bx + cy + dxy everywhere (extrapolation included),
/// the tensor-product not-a-knot spline any product of cubics inside the grid.
#[test]
fn tables_reproduce_their_polynomials() {
    let at = |f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
        YG.iter()
            .flat_map(|&y| XG.iter().map(move |&x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect()
    };
    let bilinear = |x: f64, y: f64| 1.0 - 2.0 * x + 0.5 * y + 3.0 * x * y;
    let cubic = |x: f64, y: f64| {
        (x * x * x - 2.0 * x + 1.0) * (0.5 * y * y * y + y * y - 1.0) + x * x * y - 3.0 * y
    };
    let lin = Interpolant2::linear(&XG, &YG, &at(&bilinear)).unwrap();
    let spl = Interpolant2::bspline(&XG, &YG, &at(&cubic)).unwrap();
    for (x, y) in [
        (0.3, -0.7),
        (1.2, 1.3),
        (2.99, 2.49),
        (-1.0, 4.0),
        (0.0, -1.0),
    ] {
        assert!(
            close(lin.value(x, y), bilinear(x, y), 1e-13),
            "bilinear at ({x}, {y})"
        );
    }
    for (x, y) in [
        (0.3, -0.7),
        (1.2, 1.3),
        (2.99, 2.49),
        (0.0, -1.0),
        (3.0, 2.5),
    ] {
        assert!(
            close(spl.value(x, y), cubic(x, y), 1e-12),
            "cubic at ({x}, {y})"
        );
        // ∂/∂y of the cubic: (x³ − 2x + 1)(1.5y² + 2y) + x² − 3.
        let dy = (x * x * x - 2.0 * x + 1.0) * (1.5 * y * y + 2.0 * y) + x * x - 3.0;
        let got = spl.derivative(1).unwrap().value(x, y);
        assert!(close(got, dy, 1e-11), "∂/∂y at ({x}, {y}): {got} vs {dy}");
    }
    assert!(matches!(spl.derivative(2), Err(SymxError::Table { .. })));
}

/// A table inside a function called from another graph: the call is differentiated
/// through the callee's instantiated lookup nodes; constants fold.
#[test]
fn tables_work_in_calls_and_fold_constants() {
    let table = Interpolant2::bspline(&XG, &YG, &values()).unwrap();
    let (x, y) = (Expr::sym("x"), Expr::sym("y"));
    let inner = Function::new(&[&[x, y]], &[&[table.eval(x, y) * x]]).unwrap();
    let (a, b) = (Expr::sym("a"), Expr::sym("b"));
    let out = inner.apply(&[&[a, b]]).unwrap()[0][0];
    let g = reverse(&[out], &[a, b], &[Expr::constant(1.0)]).unwrap();
    let outer = Function::new(&[&[a, b]], &[&g]).unwrap();
    let direct = derivatives(&table).reverse;
    let p = [1.3, 0.4];
    let d = direct.call(&[&p]).unwrap();
    let got = outer.call(&[&p]).unwrap()[0].clone();
    // ∂(T·a)/∂a = T + a·T_x, ∂(T·a)/∂b = a·T_y.
    assert!(close(got[0], d[0][0] + p[0] * d[1][0], 1e-14));
    assert!(close(got[1], p[0] * d[1][1], 1e-14));
    let folded = table.eval(Expr::constant(1.0), Expr::constant(1.0));
    assert_eq!(folded.to_string(), format!("{}", table.value(1.0, 1.0)));
    assert!(table.eval(x, 2.0).to_string().starts_with("interpolant#"));
}

#[test]
fn bad_tables_are_errors_naming_the_problem() {
    let msg = |r: Result<Interpolant2, SymxError>| match r {
        Err(SymxError::Table { reason }) => reason,
        other => panic!("expected a table error, got {other:?}"),
    };
    let v = values();
    assert!(msg(Interpolant2::linear(&XG, &YG, &v[..24])).contains("25 grid points but 24"));
    assert!(msg(Interpolant2::linear(&XG, &[0.0], &v[..5])).contains("y grid has 1 points"));
    assert!(msg(Interpolant2::bspline(&XG[..3], &YG, &v[..15])).contains("x grid has 3"));
    assert!(msg(Interpolant2::linear(&[0.0, 0.0], &YG, &v[..10])).contains("x grid not strictly"));
    let mut nan = v.clone();
    nan[7] = f64::NAN;
    assert!(msg(Interpolant2::linear(&XG, &YG, &nan)).contains("value 7"));
}
