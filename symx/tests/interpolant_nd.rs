//! n-D lookup tables (`InterpolantN`, a call of a one-instruction lookup function):
//! values and derivatives on a 3-D grid against CasADi 3.8.2 (the output of
//! benches/reference/interpolant3_casadi.py, read from
//! benches/reference/results/interpolant3_casadi.txt), against finite differences, against
//! the 1-D and 2-D lookup nodes (an independent implementation path), polynomial
//! reproduction, sparsity, and bad input.
use symx::{
    gradient, hessian, jacobian, Expr, Function, Interpolant, Interpolant2, InterpolantN, SymxError,
};

const XG: [f64; 4] = [0.0, 0.5, 1.5, 2.0];
const YG: [f64; 5] = [-1.0, 0.0, 0.7, 2.0, 2.5];
const ZG: [f64; 4] = [0.0, 0.4, 1.0, 1.3];

/// V = sin(x) + cos(2y)·z + 0.3·x·y·z² at the grid points, x fastest (as in the script).
fn values() -> Vec<f64> {
    let mut v = Vec::new();
    for &z in &ZG {
        for &y in &YG {
            for &x in &XG {
                v.push(x.sin() + (2.0 * y).cos() * z + 0.3 * x * y * z * z);
            }
        }
    }
    v
}

fn grids() -> [&'static [f64]; 3] {
    [&XG, &YG, &ZG]
}

/// Value, gradient and upper Hessian [xx, xy, xz, yy, yz, zz], compiled.
fn derivatives(table: &InterpolantN) -> Function {
    let v: Vec<Expr> = ["x", "y", "z"].iter().map(|n| Expr::sym(n)).collect();
    let f = table.eval(&v).unwrap();
    let g = gradient(f, &v).unwrap();
    let h: Vec<Expr> = (0..3)
        .flat_map(|i| (i..3).map(move |j| (i, j)))
        .map(|(i, j)| gradient(g[i], &v).unwrap()[j])
        .collect();
    Function::new(&[&v], &[&[f], &g, &h]).unwrap()
}

fn close(got: f64, want: f64, tol: f64) -> bool {
    (got - want).abs() <= tol * (1.0 + want.abs())
}

/// The numbers in `[a, b, …]` after `key` in `line`.
fn list_after(line: &str, key: &str) -> Vec<f64> {
    let rest = &line[line.find(key).unwrap() + key.len()..];
    let inner = &rest[rest.find('[').unwrap() + 1..rest.find(']').unwrap()];
    inner.split(", ").map(|s| s.parse().unwrap()).collect()
}

#[test]
fn three_d_tables_match_casadi() {
    let reference = include_str!("../../benches/reference/results/interpolant3_casadi.txt");
    let linear = derivatives(&InterpolantN::linear(&grids(), &values()).unwrap());
    let spline = derivatives(&InterpolantN::bspline(&grids(), &values()).unwrap());
    let mut rows = 0;
    for line in reference.lines() {
        let (f, is_linear) = if line.starts_with("linear") {
            (&linear, true)
        } else {
            (&spline, false)
        };
        let p = list_after(line, "");
        let value: f64 = line
            .split("value ")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        let (grad, hess) = (list_after(line, "grad"), list_after(line, "hess"));
        let out = f.call(&[&p]).unwrap();
        // Same functions as CasADi's; they agree to rounding (1e-12 leaves room for a
        // different operation order; a wrong end condition or axis order fails by far more).
        assert!(
            close(out[0][0], value, 1e-12),
            "{line}: value {}",
            out[0][0]
        );
        for k in 0..3 {
            assert!(
                close(out[1][k], grad[k], 1e-12),
                "{line}: grad {k} {}",
                out[1][k]
            );
        }
        for k in 0..6 {
            // CasADi's 'linear' has zero second derivatives; the multilinear cell's mixed
            // derivatives are not (checked by finite differences below): compare the diagonal.
            if !is_linear || matches!(k, 0 | 3 | 5) {
                assert!(
                    close(out[2][k], hess[k], 1e-11),
                    "{line}: hess {k} {}",
                    out[2][k]
                );
            }
        }
        rows += 1;
    }
    assert_eq!(rows, 12);
}

/// Central differences (h = 1e-5: truncation ~h²|f'''| ≈ 1e-9, rounding ~1e-11; 1e-7
/// relative is a wide margin that a wrong derivative still fails).
#[test]
fn derivatives_match_finite_differences() {
    let h = 1e-5;
    for table in [
        InterpolantN::linear(&grids(), &values()).unwrap(),
        InterpolantN::bspline(&grids(), &values()).unwrap(),
    ] {
        let f = derivatives(&table);
        let at = |p: &[f64]| f.call(&[p]).unwrap();
        for p in [[0.2, -0.5, 0.1], [1.1, 0.4, 0.9], [1.8, 2.2, 1.25]] {
            let r = at(&p);
            for k in 0..3 {
                let (mut hi, mut lo) = (p, p);
                hi[k] += h;
                lo[k] -= h;
                let (hi, lo) = (at(&hi), at(&lo));
                let fd = (hi[0][0] - lo[0][0]) / (2.0 * h);
                assert!(
                    close(r[1][k], fd, 1e-7),
                    "grad {k} at {p:?}: {} vs {fd}",
                    r[1][k]
                );
                for j in 0..3 {
                    let fd = (hi[1][j] - lo[1][j]) / (2.0 * h);
                    let (a, b) = (j.min(k), j.max(k));
                    let got = r[2][a * 3 - a * (a + 1) / 2 + b];
                    assert!(
                        close(got, fd, 1e-7),
                        "hess ({j},{k}) at {p:?}: {got} vs {fd}"
                    );
                }
            }
        }
    }
}

/// In 1-D and 2-D an `InterpolantN` (a call) and the dedicated lookup nodes must give the
/// same values and derivatives: two implementation paths over the same tables.
#[test]
fn calls_agree_with_the_lookup_nodes() {
    let (x, y) = (Expr::sym("x"), Expr::sym("y"));
    let xs: [f64; 5] = [0.0, 0.5, 1.5, 2.0, 3.0];
    let ys: [f64; 5] = [-1.0, 0.0, 0.7, 2.0, 2.5];
    let vals: Vec<f64> = ys
        .iter()
        .flat_map(|&b| xs.iter().map(move |&a| (a * b).sin() + a))
        .collect();
    let pairs = [
        (
            Interpolant2::bspline(&xs, &ys, &vals).unwrap().eval(x, y),
            InterpolantN::bspline(&[&xs, &ys], &vals)
                .unwrap()
                .eval(&[x, y])
                .unwrap(),
        ),
        (
            Interpolant2::linear(&xs, &ys, &vals).unwrap().eval(x, y),
            InterpolantN::linear(&[&xs, &ys], &vals)
                .unwrap()
                .eval(&[x, y])
                .unwrap(),
        ),
        (
            Interpolant::bspline(&xs, &vals[..5]).unwrap().eval(x) * y,
            InterpolantN::bspline(&[&xs], &vals[..5])
                .unwrap()
                .eval(&[x])
                .unwrap()
                * y,
        ),
    ];
    for (node, call) in pairs {
        let all = |e: Expr| {
            let g = gradient(e, &[x, y]).unwrap();
            let h = hessian(e, &[x, y]).unwrap();
            Function::new(&[&[x, y]], &[&[e], &g, h.values()]).unwrap()
        };
        let (a, b) = (all(node), all(call));
        for p in [[0.3, -0.2], [1.7, 1.1], [2.6, 2.4], [3.5, 0.0]] {
            let (u, v) = (a.call(&[&p]).unwrap(), b.call(&[&p]).unwrap());
            for (ru, rv) in u.iter().zip(&v) {
                for (s, t) in ru.iter().zip(rv) {
                    assert!(close(*s, *t, 1e-14), "{p:?}: {s} vs {t}");
                }
            }
        }
    }
}

/// Trilinear tables reproduce a + bx + cy + dz + exy + fxz + gyz + hxyz everywhere; the
/// tensor spline reproduces products of cubics inside the grid.
#[test]
fn tables_reproduce_their_polynomials() {
    let sample = |f: &dyn Fn(f64, f64, f64) -> f64| -> Vec<f64> {
        let mut v = Vec::new();
        for &z in &ZG {
            for &y in &YG {
                for &x in &XG {
                    v.push(f(x, y, z));
                }
            }
        }
        v
    };
    let tri =
        |x: f64, y: f64, z: f64| 1.0 + x - 2.0 * y + 0.5 * z + x * y - y * z + 3.0 * x * y * z;
    let cub = |x: f64, y: f64, z: f64| (x * x * x - x) * (y * y + 1.0) * (z * z * z - 2.0 * z) + y;
    let lin = InterpolantN::linear(&grids(), &sample(&tri)).unwrap();
    let spl = InterpolantN::bspline(&grids(), &sample(&cub)).unwrap();
    for p in [
        [0.3, -0.7, 0.2],
        [1.2, 1.3, 1.1],
        [1.99, 2.49, 1.29],
        [-1.0, 4.0, 2.0],
    ] {
        assert!(
            close(lin.value(&p).unwrap(), tri(p[0], p[1], p[2]), 1e-12),
            "trilinear {p:?}"
        );
    }
    for p in [
        [0.3, -0.7, 0.2],
        [1.2, 1.3, 1.1],
        [1.99, 2.49, 1.29],
        [0.0, -1.0, 0.0],
    ] {
        assert!(
            close(spl.value(&p).unwrap(), cub(p[0], p[1], p[2]), 1e-11),
            "cubic {p:?}"
        );
        // ∂/∂z: (x³ − x)(y² + 1)(3z² − 2).
        let dz = (p[0].powi(3) - p[0]) * (p[1] * p[1] + 1.0) * (3.0 * p[2] * p[2] - 2.0);
        assert!(
            close(spl.derivative(2).unwrap().value(&p).unwrap(), dz, 1e-10),
            "dz {p:?}"
        );
    }
}

/// The lookup's Jacobian has the structural pattern of its arguments (an unused variable
/// gets no entry), and constants fold.
#[test]
fn sparsity_and_constant_folding() {
    let table = InterpolantN::linear(&grids(), &values()).unwrap();
    let v: Vec<Expr> = ["a", "b", "c", "d"].iter().map(|n| Expr::sym(n)).collect();
    let f = table.eval(&[v[0], v[2] * 2.0, v[3]]).unwrap();
    let j = jacobian(&[f], &v).unwrap();
    assert_eq!(j.nnz(), 3);
    let c = table
        .eval(&[
            Expr::constant(1.0),
            Expr::constant(0.5),
            Expr::constant(0.2),
        ])
        .unwrap();
    assert_eq!(c.value(), Some(table.value(&[1.0, 0.5, 0.2]).unwrap()));
    assert_eq!(table.function().input_sizes(), &[3]);
    assert_eq!(table.dims(), 3);
}

#[test]
fn bad_input_is_an_error_naming_it() {
    let msg = |r: Result<InterpolantN, SymxError>| match r {
        Err(SymxError::Table { reason }) => reason,
        other => panic!("expected a table error, got {other:?}"),
    };
    let v = values();
    assert!(msg(InterpolantN::linear(&[], &v)).contains("0 grid axes"));
    let nine: Vec<&[f64]> = vec![&[0.0, 1.0]; 9];
    assert!(msg(InterpolantN::linear(&nine, &[0.0; 512])).contains("9 grid axes"));
    assert!(
        msg(InterpolantN::bspline(&[&XG, &YG, &[0.0, 1.0]], &v[..40]))
            .contains("grid 2 has 2 points")
    );
    assert!(msg(InterpolantN::linear(&grids(), &v[..79])).contains("80 grid points but 79"));
    let table = InterpolantN::linear(&grids(), &v).unwrap();
    assert!(matches!(
        table.value(&[0.0, 1.0]),
        Err(SymxError::Length {
            expected: 3,
            got: 2,
            ..
        })
    ));
    assert!(table.eval(&[Expr::sym("x")]).is_err());
    assert!(matches!(table.derivative(3), Err(SymxError::Table { .. })));
}
