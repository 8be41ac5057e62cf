//! The operations added for optimal-control users (issue 13, item 1): scalar functions,
//! small dense linear algebra, matrix assembly and lookup tables. Each is checked
//! * against CasADi 3.8.2 SX: the numbers below are printed by
//!   `benches/reference/symx_ops_casadi.py` (saved in
//!   `benches/reference/results/symx_ops_casadi.txt`), case by case under the same names;
//! * against central finite differences of the compiled function itself.
use symx::{gradient, gt, hessian, if_else, logsumexp, Expr, Function, Interpolant, Matrix};

/// `|a − b| ≤ tol · max(1, |b|)`.
fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

fn assert_close(what: &str, got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (k, (&g, &w)) in got.iter().zip(want).enumerate() {
        assert!(close(g, w, tol), "{what}[{k}]: got {g:e}, want {w:e}");
    }
}

/// CasADi and symx evaluate the same formulas, up to operation order and the libm used
/// (`erf`, `asinh`...), which differ in the last bits; conditioning of the 3×3 and 4×4
/// solves multiplies that by at most ~10². Hence 1e-12 relative.
const CASADI_TOL: f64 = 1e-12;

/// Central differences with step h = 1e-5·max(1,|x|): truncation error ~h²·|f'''| ≈ 1e-10,
/// rounding ~ε·|f|/h ≈ 1e-11·|f|; 1e-6 relative leaves a wide margin while still failing for
/// any wrong derivative formula.
const FD_TOL: f64 = 1e-6;

/// Value, gradient and dense Hessian (column-major) of `e` at `point`.
fn eval_all(e: Expr, vars: &[Expr], point: &[f64]) -> (f64, Vec<f64>, Vec<f64>) {
    let g = gradient(e, vars).unwrap();
    let h = hessian(e, vars).unwrap();
    let f = Function::new(&[vars], &[&[e], &g, h.values()]).unwrap();
    let out = f.call(&[point]).unwrap();
    let n = vars.len();
    let mut dense = vec![0.0; n * n];
    for ((i, j, _), v) in h.triplets().into_iter().zip(&out[2]) {
        dense[i + j * n] = *v;
        dense[j + i * n] = *v;
    }
    (out[0][0], out[1].clone(), dense)
}

/// Checks the gradient and Hessian of `e` against central differences of compiled values.
fn check_fd(name: &str, e: Expr, vars: &[Expr], point: &[f64]) {
    let g = gradient(e, vars).unwrap();
    let f = Function::new(&[vars], &[&[e], &g]).unwrap();
    let (_, grad, hess) = eval_all(e, vars, point);
    let n = vars.len();
    for j in 0..n {
        let h = 1e-5 * point[j].abs().max(1.0);
        let (mut p, mut m) = (point.to_vec(), point.to_vec());
        p[j] += h;
        m[j] -= h;
        let (fp, fm) = (f.call(&[&p]).unwrap(), f.call(&[&m]).unwrap());
        let d = (fp[0][0] - fm[0][0]) / (2.0 * h);
        assert!(
            close(grad[j], d, FD_TOL),
            "{name}: ∂/∂x{j} {} vs FD {d}",
            grad[j]
        );
        for i in 0..n {
            let d2 = (fp[1][i] - fm[1][i]) / (2.0 * h);
            let got = hess[i + j * n];
            assert!(
                close(got, d2, FD_TOL),
                "{name}: H[{i},{j}] {got} vs FD {d2}"
            );
        }
    }
}

struct Scalar {
    name: &'static str,
    point: &'static [f64],
    value: f64,
    grad: &'static [f64],
    hess: &'static [f64],
}

const fn sc(
    name: &'static str,
    point: &'static [f64],
    value: f64,
    grad: &'static [f64],
    hess: &'static [f64],
) -> Scalar {
    Scalar {
        name,
        point,
        value,
        grad,
        hess,
    }
}

/// From benches/reference/results/symx_ops_casadi.txt (unary ops are composed as
/// `op(x)·(1 + x²)`, `fmod(x,y)·y`, `hypot(x,y)·x`, `logsumexp(x,y,z)·x`).
const SCALAR_CASES: &[Scalar] = &[
    sc("floor", &[2.7], 16.580000000000002, &[10.8], &[4.0]),
    sc("floor", &[-1.3], -5.380000000000001, &[5.2], &[-4.0]),
    sc(
        "ceil",
        &[2.7],
        24.870000000000005,
        &[16.200000000000003],
        &[6.0],
    ),
    sc("ceil", &[-1.3], -2.6900000000000004, &[2.6], &[-2.0]),
    sc(
        "erf",
        &[0.3],
        0.35820316781044886,
        &[1.3212504471601463],
        &[1.2203219755702086],
    ),
    sc(
        "erf",
        &[-1.2],
        -2.22116610688031,
        &[2.83707375443976],
        &[-1.5383123260235332],
    ),
    sc(
        "asinh",
        &[0.7],
        0.9724731834627101,
        &[2.1343887540886683],
        &[3.0257201652546963],
    ),
    sc(
        "asinh",
        &[-2.0],
        -7.218177375894052,
        &[8.010609878215032],
        &[-5.570552523357368],
    ),
    sc(
        "acosh",
        &[1.5],
        3.1278768628874225,
        &[5.794159321107347],
        &[3.8031444013382383],
    ),
    sc(
        "acosh",
        &[3.0],
        17.62747174039086,
        &[14.112016950167254],
        &[6.442309820472681],
    ),
    sc(
        "atanh",
        &[0.3],
        0.33737636858139186,
        &[1.383513960324065],
        &[2.727480217946134],
    ),
    sc(
        "atanh",
        &[-0.8],
        -1.8017241534157002,
        &[6.313335217424533],
        &[-31.33302704647204],
    ),
    sc(
        "log1p",
        &[1e-3],
        0.0009995013325838661,
        &[0.9990039970026643],
        &[-0.9920089893458192],
    ),
    sc(
        "log1p",
        &[2.0],
        5.493061443340547,
        &[6.061115821339105],
        &[4.30833568844733],
    ),
    sc(
        "expm1",
        &[1e-3],
        0.0010005011672085083,
        &[1.0010035021675419],
        &[1.007006503501292],
    ),
    sc(
        "expm1",
        &[-1.5],
        -2.524826979517603,
        &[3.0557825400371077],
        &[-2.1673476201113226],
    ),
    sc(
        "fmod",
        &[5.3, 2.0],
        2.5999999999999996,
        &[2.0, -2.7],
        &[0.0, 1.0, 1.0, -4.0],
    ),
    sc(
        "fmod",
        &[-5.3, 2.0],
        -2.5999999999999996,
        &[2.0, 2.7],
        &[0.0, 1.0, 1.0, 4.0],
    ),
    sc(
        "fmod",
        &[7.5, -2.2],
        -1.979999999999999,
        &[-2.2, -5.700000000000001],
        &[0.0, 1.0, 1.0, 6.0],
    ),
    sc(
        "hypot",
        &[3.0, 4.0],
        15.0,
        &[6.8, 2.4000000000000004],
        &[1.584, 0.512, 0.512, 0.21600000000000003],
    ),
    sc(
        "hypot",
        &[-1.2, 0.5],
        -1.56,
        &[2.4076923076923076, -0.46153846153846145],
        &[
            -1.9827036868456984,
            0.05689576695493859,
            0.05689576695493859,
            -0.7865270823850705,
        ],
    ),
    sc(
        "logsumexp",
        &[1.0, 2.0, 3.0],
        3.4076059644443806,
        &[3.497636537614761, 0.2447284710547976, 0.6652409557748219],
        &[
            0.2619862154057542,
            0.22269542653462335,
            0.605348931230003,
            0.22269542653462335,
            0.18483644650997869,
            -0.16280340198980442,
            0.605348931230003,
            -0.16280340198980442,
            0.22269542653462335,
        ],
    ),
    sc(
        "logsumexp",
        &[100.0, 101.0, 99.0],
        10140.76059644444,
        &[125.88045306992416, 66.5240955774822, 9.003057317038046],
        &[
            18.97310159310747,
            -15.615099243205618,
            -2.113273878847049,
            -15.615099243205618,
            22.269542653462334,
            -5.9892024544818945,
            -2.113273878847049,
            -5.9892024544818945,
            8.192506906499323,
        ],
    ),
    sc(
        "logsumexp",
        &[-3.0, 0.5, 0.25],
        -3.2783195785973427,
        &[1.0426945626355772, -1.6583764735454247, -1.2915448962243716],
        &[
            -0.01585692034149005,
            0.5804752319155251,
            0.45207456516936617,
            0.5804752319155251,
            -0.7416389642091052,
            0.7139558901420551,
            0.45207456516936617,
            0.7139558901420551,
            -0.7355154899032974,
        ],
    ),
];

fn scalar_expr(name: &str, v: &[Expr]) -> Expr {
    let x = v[0];
    let poly = 1.0 + x * x;
    match name {
        "floor" => x.floor() * poly,
        "ceil" => x.ceil() * poly,
        "erf" => x.erf() * poly,
        "asinh" => x.asinh() * poly,
        "acosh" => x.acosh() * poly,
        "atanh" => x.atanh() * poly,
        "log1p" => x.log1p() * poly,
        "expm1" => x.expm1() * poly,
        "fmod" => x.fmod(v[1]) * v[1],
        "hypot" => x.hypot(v[1]) * x,
        "logsumexp" => logsumexp(v) * x,
        other => panic!("unknown case {other}"),
    }
}

#[test]
fn scalar_operations_match_casadi_and_finite_differences() {
    for case in SCALAR_CASES {
        let vars: Vec<Expr> = (0..case.point.len())
            .map(|k| Expr::sym(&format!("v{k}")))
            .collect();
        let e = scalar_expr(case.name, &vars);
        let (value, grad, hess) = eval_all(e, &vars, case.point);
        let what = format!("{} at {:?}", case.name, case.point);
        assert_close(
            &format!("{what} value"),
            &[value],
            &[case.value],
            CASADI_TOL,
        );
        assert_close(&format!("{what} gradient"), &grad, case.grad, CASADI_TOL);
        assert_close(&format!("{what} Hessian"), &hess, case.hess, CASADI_TOL);
        check_fd(&what, e, &vars, case.point);
    }
}

#[test]
fn new_operations_fold_constants_and_print() {
    let x = Expr::sym("x");
    assert!(Expr::constant(2.5).floor().is_constant_value(2.0));
    assert!(Expr::constant(-5.5).fmod(2.0).is_constant_value(-1.5));
    assert!(Expr::constant(3.0).hypot(4.0).is_constant_value(5.0));
    assert_eq!(x.erf().to_string(), "erf(x)");
    assert_eq!(x.fmod(2.0).to_string(), "fmod(x,2)");
    let e = x.log1p() + x.expm1() * x.atanh();
    assert!(symx::parse(&e.to_string(), &[x]).unwrap().is(e));
    assert!(logsumexp(&[x]).is(x));
    assert_eq!(logsumexp(&[]).value(), Some(f64::NEG_INFINITY));
}

#[test]
fn floor_and_ceil_have_structurally_zero_derivatives() {
    let x = Expr::sym("x");
    let y = Expr::sym("y");
    let j = symx::jacobian(&[x.floor() * y + x.ceil()], &[x, y]).unwrap();
    assert_eq!(symx::sparsity::entries(j.sparsity()), vec![(0, 1)]);
    let f = Function::new(&[&[x, y]], &[&[x.floor() * y]]).unwrap();
    let dep = f.dependency_sparsity(0, 0).unwrap();
    assert_eq!(symx::sparsity::entries(&dep), vec![(0, 1)]);
}

/// The branch not taken never leaks NaN into derivatives (CasADi #1805), also for the new
/// operations whose derivatives are NaN or infinite outside their domain.
#[test]
fn untaken_branches_of_new_operations_do_not_poison_derivatives() {
    let x = Expr::sym("x");
    let y = Expr::sym("y");
    let cases: Vec<(Expr, f64)> = vec![
        (if_else(gt(x, 1.0), x.acosh(), x), 0.5),
        (if_else(gt(x, -1.0), x.log1p(), 2.0 * x), -3.0),
        (if_else(gt(1.0, x.abs()), x.atanh(), x), 2.0),
        (if_else(gt(x, 0.0), x.hypot(y), x), 0.0),
    ];
    for (k, (e, at)) in cases.into_iter().enumerate() {
        let (value, grad, hess) = eval_all(e, &[x, y], &[at, 0.0]);
        assert!(value.is_finite(), "case {k}: value {value}");
        assert!(
            grad.iter().chain(&hess).all(|v| v.is_finite()),
            "case {k}: {grad:?} {hess:?}"
        );
        // The untaken branch's only contribution is through x (or 2x): slope 1 or 2.
        assert!(grad[0] == 1.0 || grad[0] == 2.0, "case {k}: {grad:?}");
    }
}

struct MatrixCase {
    name: &'static str,
    value: &'static [f64],
    /// Gradient of `Σₖ (k+1)·outₖ` (column-major k) with respect to the inputs' entries.
    grad: &'static [f64],
}

/// From benches/reference/results/symx_ops_casadi.txt.
const MATRIX_CASES: &[MatrixCase] = &[
    MatrixCase {
        name: "solve_full",
        value: &[
            1.0972944849115505,
            -1.0145681581685746,
            0.45005202913631637,
            1.7190426638917795,
            -0.35900104058272636,
            0.19771071800208123,
        ],
        grad: &[
            -5.341210432681012,
            -1.5828389392336504,
            -3.5003751945001795,
            1.7235070994595687,
            0.6133374335829935,
            1.3031105952111544,
            -0.8650263502400056,
            -0.2986450768309545,
            -0.6384803377508477,
            0.7741935483870968,
            0.3600416233090531,
            0.72840790842872,
            2.6129032258064515,
            0.6909469302809573,
            1.571279916753382,
        ],
    },
    MatrixCase {
        name: "solve_zero_pivot",
        value: &[
            -1.5227272727272727,
            1.3181818181818181,
            -0.15909090909090912,
            -2.1818181818181817,
            1.5454545454545454,
            0.7272727272727272,
        ],
        grad: &[
            4.636363636363637,
            2.795454545454546,
            1.8636363636363642,
            -3.545454545454545,
            -2.0454545454545454,
            -1.3636363636363638,
            -0.8181818181818183,
            -0.7500000000000004,
            -0.49999999999999994,
            1.0909090909090908,
            0.27272727272727265,
            0.18181818181818182,
            1.3636363636363638,
            1.0909090909090906,
            0.7272727272727273,
        ],
    },
    MatrixCase {
        name: "inverse",
        value: &[
            0.6129032258064516,
            -0.16129032258064518,
            0.16129032258064518,
            -0.21227887617065558,
            0.39542143600416235,
            -0.07284079084287201,
            0.11966701352757546,
            -0.12486992715920918,
            0.2861602497398543,
        ],
        grad: &[
            -0.45255278439797264,
            -0.19627923999562524,
            -0.4017883729769005,
            -0.35245543956228376,
            -0.08754538337514828,
            -0.20237763949060172,
            -1.2084186499278307,
            -0.3001556001433643,
            -0.6938661925392062,
        ],
    },
    MatrixCase {
        name: "det3",
        value: &[19.22],
        grad: &[
            11.78,
            -4.08,
            2.3000000000000003,
            -3.1,
            7.6,
            -2.4000000000000004,
            3.1,
            -1.4,
            5.5,
        ],
    },
    MatrixCase {
        name: "det4",
        value: &[35.53679999999999],
        grad: &[
            26.077999999999996,
            -11.491999999999999,
            7.9559999999999995,
            -9.724000000000002,
            -8.074,
            16.204,
            -6.4559999999999995,
            5.300000000000001,
            8.622,
            -5.244,
            12.66,
            -6.540000000000001,
            -8.494000000000002,
            7.804,
            -7.32,
            19.22,
        ],
    },
    MatrixCase {
        name: "solve_upper",
        value: &[
            0.8812500000000001,
            -0.7125,
            0.125,
            1.4041666666666666,
            0.09166666666666667,
            -0.25,
        ],
        grad: &[
            -3.2489583333333334,
            0.0,
            0.0,
            0.17291666666666666,
            0.26458333333333334,
            0.0,
            0.4375,
            0.1875,
            0.2734375,
            0.5,
            0.5,
            0.6625000000000001,
            2.0,
            1.0,
            1.425,
        ],
    },
    MatrixCase {
        name: "solve_lower",
        value: &[0.5, -0.75, 0.2875, 1.5, -0.25, 0.1375],
        grad: &[
            -3.8979166666666667,
            -2.658333333333333,
            -2.625,
            0.0,
            0.8541666666666667,
            0.9375,
            0.0,
            0.0,
            -0.421875,
            0.7208333333333333,
            0.6166666666666667,
            0.75,
            2.3583333333333334,
            1.5666666666666667,
            1.5,
        ],
    },
    MatrixCase {
        name: "norm_1",
        value: &[10.1],
        grad: &[1.0, -1.0, 1.0, 1.0, -1.0, 1.0],
    },
    MatrixCase {
        name: "norm_inf",
        value: &[4.0],
        grad: &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
    },
    MatrixCase {
        name: "norm_fro",
        value: &[5.214403129793476],
        grad: &[
            0.287664755229504,
            -0.38355300697267203,
            0.0575329510459008,
            0.7671060139453441,
            -0.019177650348633602,
            0.42190830766993925,
        ],
    },
    MatrixCase {
        name: "kron",
        value: &[
            0.75, 1.5, -1.0, -2.0, -1.5, 3.0, 2.0, -4.0, 0.15, 0.3, 2.0, 4.0, -0.3, 0.6, -4.0, 8.0,
            -0.05, -0.1, 1.1, 2.2, 0.1, -0.2, -2.2, 4.4,
        ],
        grad: &[9.5, 14.5, 29.5, 34.5, 49.5, 54.5, 82.3, 88.2, 105.9, 111.8],
    },
    MatrixCase {
        name: "reshape",
        value: &[1.5, -2.0, 0.3, 4.0, -0.1, 2.2],
        grad: &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
    },
    MatrixCase {
        name: "repmat",
        value: &[
            0.5, 1.0, 0.5, 1.0, -1.0, 2.0, -1.0, 2.0, 0.5, 1.0, 0.5, 1.0, -1.0, 2.0, -1.0, 2.0,
            0.5, 1.0, 0.5, 1.0, -1.0, 2.0, -1.0, 2.0,
        ],
        grad: &[60.0, 66.0, 84.0, 90.0],
    },
    MatrixCase {
        name: "diagcat",
        value: &[
            1.5, -2.0, 0.0, 0.0, 0.3, 4.0, 0.0, 0.0, -0.1, 2.2, 0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 0.0,
            0.0, -1.0, 2.0,
        ],
        grad: &[1.0, 2.0, 5.0, 6.0, 9.0, 10.0, 15.0, 16.0, 19.0, 20.0],
    },
];

const A_FULL: [f64; 9] = [2.0, 0.5, -1.0, 1.0, 3.0, 0.2, -0.4, 1.1, 4.0];
const A_ZERO_PIVOT: [f64; 9] = [0.0, 1.0, 4.0, 1.0, 0.0, 5.0, 2.0, 3.0, 0.0];
const B_VALS: [f64; 6] = [1.0, -2.0, 0.5, 3.0, 0.0, -1.0];
const A4: [f64; 16] = [
    2.0, 0.5, -1.0, 0.3, 1.0, 3.0, 0.2, -0.7, -0.4, 1.1, 4.0, 0.9, 0.6, -0.2, 0.8, 2.5,
];
const M_VALS: [f64; 6] = [1.5, -2.0, 0.3, 4.0, -0.1, 2.2];
const N_VALS: [f64; 4] = [0.5, 1.0, -1.0, 2.0];

fn triangle(a: &Matrix, upper: bool) -> Matrix {
    Matrix::from_fn(3, 3, |i, j| {
        if (upper && i <= j) || (!upper && i >= j) {
            a[(i, j)]
        } else {
            Expr::zero()
        }
    })
}

/// The symbolic output, its inputs (entries, column-major) and the point of a case.
fn matrix_case(name: &str) -> (Matrix, Vec<Expr>, Vec<f64>) {
    let a = Matrix::sym("A", 3, 3);
    let b = Matrix::sym("B", 3, 2);
    let m = Matrix::sym("M", 2, 3);
    let n = Matrix::sym("N", 2, 2);
    let cat = |x: &Matrix, y: &Matrix| [x.to_vec(), y.to_vec()].concat();
    let ab = cat(&a, &b);
    let mn = cat(&m, &n);
    let with_b = |p: &[f64]| [p, &B_VALS[..]].concat();
    let mn_vals = [&M_VALS[..], &N_VALS[..]].concat();
    match name {
        "solve_full" => (a.solve(&b).unwrap(), ab, with_b(&A_FULL)),
        "solve_zero_pivot" => (a.solve(&b).unwrap(), ab, with_b(&A_ZERO_PIVOT)),
        "solve_upper" => (triangle(&a, true).solve(&b).unwrap(), ab, with_b(&A_FULL)),
        "solve_lower" => (triangle(&a, false).solve(&b).unwrap(), ab, with_b(&A_FULL)),
        "inverse" => (a.inverse().unwrap(), a.to_vec(), A_FULL.to_vec()),
        "det3" => (a.det().unwrap().into(), a.to_vec(), A_FULL.to_vec()),
        "det4" => {
            let a4 = Matrix::sym("A4", 4, 4);
            (a4.det().unwrap().into(), a4.to_vec(), A4.to_vec())
        }
        "norm_1" => (m.norm_1().into(), m.to_vec(), M_VALS.to_vec()),
        "norm_inf" => (m.norm_inf().into(), m.to_vec(), M_VALS.to_vec()),
        "norm_fro" => (m.norm_fro().into(), m.to_vec(), M_VALS.to_vec()),
        "kron" => (m.kron(&n), mn, mn_vals),
        "reshape" => (m.reshape(3, 2).unwrap(), m.to_vec(), M_VALS.to_vec()),
        "repmat" => (n.repmat(2, 3), n.to_vec(), N_VALS.to_vec()),
        "diagcat" => (Matrix::diagcat(&[&m, &n]), mn, mn_vals),
        other => panic!("unknown case {other}"),
    }
}

#[test]
fn matrix_operations_match_casadi_and_finite_differences() {
    for case in MATRIX_CASES {
        let (out, vars, point) = matrix_case(case.name);
        let weighted: Expr = out
            .iter()
            .enumerate()
            .map(|(k, &e)| (k as f64 + 1.0) * e)
            .sum();
        let grad = gradient(weighted, &vars).unwrap();
        let f = Function::new(&[&vars], &[&out, &grad]).unwrap();
        let got = f.call(&[&point]).unwrap();
        assert_close(
            &format!("{} value", case.name),
            &got[0],
            case.value,
            CASADI_TOL,
        );
        assert_close(
            &format!("{} gradient", case.name),
            &got[1],
            case.grad,
            CASADI_TOL,
        );
        if case.name != "norm_1" && case.name != "norm_inf" {
            // (|·| and max are not smooth; their derivatives are checked against CasADi only.)
            check_fd(case.name, weighted, &vars, &point);
        }
    }
}

#[test]
fn structure_is_kept_by_solve_and_det() {
    // Triangular systems use substitution: x₂ of an upper-triangular solve is b₂/a₂₂.
    let a = Matrix::sym("A", 3, 3);
    let b = Matrix::sym_vec("b", 3);
    let x = triangle(&a, true).solve(&b).unwrap();
    assert!(x[2].is(b[2] / a[(2, 2)]));
    // A diagonal determinant is the product of the diagonal (zeros are skipped).
    let d = Matrix::from_fn(3, 3, |i, j| if i == j { a[(i, j)] } else { Expr::zero() });
    let det = d.det().unwrap();
    let f = Function::new(&[&a], &[&[det]]).unwrap();
    assert_eq!(f.instruction_count(), 2);
    assert!(Matrix::eye(0).det().unwrap().is_constant_value(1.0));
    // A x = b holds at a point for the QR path, to rounding.
    let ax = a.matmul(&a.solve(&b).unwrap()).unwrap();
    let f = Function::new(&[&a, &b], &[&ax]).unwrap();
    let out = f.call(&[&A_FULL, &[1.0, 2.0, 3.0]]).unwrap();
    assert_close("A·solve(A,b)", &out[0], &[1.0, 2.0, 3.0], 1e-14);
}

#[test]
fn matrix_operations_reject_bad_shapes() {
    use symx::SymxError;
    let m = Matrix::sym("M", 2, 3);
    let is_dim = |r: Result<Matrix, SymxError>| matches!(r, Err(SymxError::Dimension { .. }));
    assert!(is_dim(m.solve(&Matrix::sym_vec("b", 2))));
    assert!(is_dim(m.inverse()));
    assert!(matches!(
        m.det(),
        Err(SymxError::Dimension { op: "det", .. })
    ));
    assert!(is_dim(
        Matrix::sym("A", 2, 2).solve(&Matrix::sym_vec("b", 3))
    ));
    assert!(is_dim(m.reshape(4, 2)));
}

const TS: [f64; 8] = [-1.0, 0.5, 1.0 + 1e-9, 2.5, 3.7, 5.0, 6.9, 8.0];
const GRID: [f64; 7] = [0.0, 1.0, 2.0, 3.0, 4.0, 5.5, 7.0];
const VALS: [f64; 7] = [0.0, 1.0, 4.0, 2.0, 1.0, 3.0, -1.0];

fn lookup(table: &Interpolant, orders: usize) -> Vec<Vec<f64>> {
    let x = Expr::sym("x");
    let mut outs = vec![table.eval(x)];
    for _ in 1..orders {
        let d = gradient(*outs.last().unwrap(), &[x]).unwrap()[0];
        outs.push(d);
    }
    let rows: Vec<&[Expr]> = outs.iter().map(std::slice::from_ref).collect();
    let f = Function::new(&[&[x]], &rows).unwrap();
    (0..orders)
        .map(|k| TS.iter().map(|&t| f.call(&[&[t]]).unwrap()[k][0]).collect())
        .collect()
}

#[test]
fn interpolants_match_casadi() {
    // From benches/reference/results/symx_ops_casadi.txt (CasADi 'linear' and 'bspline').
    let linear = Interpolant::linear(&GRID, &VALS).unwrap();
    let got = lookup(&linear, 2);
    assert_close(
        "linear value",
        &got[0],
        &[
            -1.0,
            0.5,
            1.0000000030000002,
            3.0,
            1.2999999999999998,
            2.3333333333333335,
            -0.7333333333333343,
            -3.666666666666667,
        ],
        CASADI_TOL,
    );
    assert_close(
        "linear derivative",
        &got[1],
        &[
            1.0,
            1.0,
            3.0,
            -2.0,
            -1.0,
            1.3333333333333333,
            -2.6666666666666665,
            -2.6666666666666665,
        ],
        CASADI_TOL,
    );
    let spline = Interpolant::bspline(&GRID, &VALS).unwrap();
    let got = lookup(&spline, 3);
    assert_close(
        "bspline value",
        &got[0],
        &[
            0.0,
            -0.42077464788732377,
            1.0000000037887327,
            3.3626760563380285,
            0.9873661971830987,
            2.3688054251434525,
            -0.29040166927491073,
            0.0,
        ],
        CASADI_TOL,
    );
    // CasADi's derivative of its B-spline is itself a fitted spline: agreement to 1e-9.
    assert_close(
        "bspline derivative",
        &got[1],
        &[
            0.0,
            1.4471830985915486,
            3.7887323963661954,
            -2.485915492957745,
            -0.4074647887323948,
            1.6134585289514862,
            -6.691236306729265,
            0.0,
        ],
        1e-9,
    );
    assert_close(
        "bspline 2nd derivative",
        &got[2],
        &[
            0.0,
            7.366197183098588,
            1.9999999892676046,
            -2.901408450704225,
            2.9887323943661963,
            -0.7730829420970253,
            -7.9687010954616575,
            0.0,
        ],
        1e-9,
    );
}

#[test]
fn interpolants_interpolate_and_differentiate() {
    let spline = Interpolant::bspline(&GRID, &VALS).unwrap();
    for (&g, &v) in GRID.iter().zip(&VALS) {
        assert!(
            close(spline.value(g), v, 1e-14),
            "spline({g}) = {}",
            spline.value(g)
        );
    }
    // Derivatives against central differences of the table itself, inside intervals.
    let x = Expr::sym("x");
    let y = spline.eval(x.sin() * 3.0 + 3.5);
    for t in [-0.9, 0.1, 0.4, 1.2] {
        check_fd("spline∘sin", y, &[x], &[t]);
    }
    // The same table in one graph is one node; a constant argument folds.
    assert!(spline.eval(x).is(spline.eval(x)));
    assert!(spline.eval(2.0).is_constant_value(4.0));
    assert!(spline.eval(x).to_string().starts_with("interpolant#"));
    assert!(symx::parse(&spline.eval(x).to_string(), &[x]).is_err());
}

#[test]
fn interpolants_reject_bad_data() {
    use symx::SymxError;
    let bad = |r: Result<Interpolant, SymxError>| match r {
        Err(SymxError::Table { reason }) => reason,
        other => panic!("expected a table error, got {other:?}"),
    };
    assert!(bad(Interpolant::linear(&[0.0, 1.0], &[1.0])).contains("2 grid points but 1 values"));
    assert!(bad(Interpolant::linear(&[0.0, 2.0, 1.0], &[0.0; 3])).contains("index 2"));
    assert!(bad(Interpolant::linear(&[0.0, f64::NAN], &[0.0; 2])).contains("grid point 1"));
    assert!(bad(Interpolant::linear(&[0.0, 1.0], &[0.0, f64::INFINITY])).contains("value 1"));
    assert!(bad(Interpolant::bspline(&[0.0, 1.0, 2.0], &[0.0; 3])).contains("at least 4"));
}
