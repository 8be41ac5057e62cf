//! Saving and loading compiled functions (symx::serialize): a loaded function evaluates
//! bit-identically to the one saved — values and derivatives — in a fresh graph and from a
//! file checked in (`tests/fixtures/function_v1.json`, written by an earlier build: it
//! catches a change of the format); damaged files, other versions and external functions
//! are clear errors.
use symx::{
    if_else, jacobian, with_fresh_arena, Expr, Function, FunctionFileError, Interpolant,
    Interpolant2, InterpolantN, Matrix, FUNCTION_FILE_VERSION,
};

/// A function exercising every kind of instruction: arithmetic and transcendental
/// operations, comparisons and `if_else`, 1-D, 2-D and N-D lookup tables, a call of a
/// compiled function, and constants ±∞ and an irrational one.
fn sample() -> Function {
    let x = Matrix::sym_vec("x", 3);
    let p = Matrix::sym_vec("p", 1);
    let inner = {
        let z = Matrix::sym_vec("z", 2);
        let out = [z[0].sin() * z[1].exp() - z[1].atan2(z[0]), z[0].hypot(z[1])];
        Function::named("inner", &[("z", &z)], &[("w", &out)]).unwrap()
    };
    let called = inner.apply(&[&[x[0], x[1] * p[0]]]).unwrap();
    let grid = [0.0, 0.5, 1.5, 3.0];
    let t1 = Interpolant::bspline(&grid, &[1.0, 0.3, -0.2, 2.0]).unwrap();
    let t2 =
        Interpolant2::linear(&grid, &grid, &(0..16).map(f64::from).collect::<Vec<_>>()).unwrap();
    let g3 = [0.0, 1.0, 2.0];
    let t3 = InterpolantN::linear(
        &[&g3, &g3, &g3],
        &(0..27).map(|k| (k * k) as f64).collect::<Vec<_>>(),
    )
    .unwrap();
    let y0 = x[0].sq() * x[1].cos() + x[2].sqrt().ln() / (1.0 + x[0].tanh()) + called[0][0];
    let y1 = if_else(symx::lt(x[0], x[1]), x[2].pow(1.0 / 3.0), x[1].asinh())
        + x[0].erf()
        + x[2].fmod(0.7);
    let y2 =
        t1.eval(x[0]) * t2.eval(x[1], x[2]) + t3.eval(&[x[0], x[1], x[2]]).unwrap() + called[0][1];
    let y3 = x[0].max(x[1]).min(Expr::constant(f64::INFINITY))
        + x[2].abs().floor()
        + p[0] * std::f64::consts::PI;
    let inf = Expr::constant(f64::INFINITY);
    let y4 = if_else(symx::lt(x[1], 1.0), inf, -inf).atan() + x[2].log1p() - x[0].expm1();
    let ys = [y0, y1, y2, y3, y4];
    Function::named(
        "sample",
        &[("x", &x), ("p", &p)],
        &[("y", &ys), ("z", &[x[0] * x[1]])],
    )
    .unwrap()
}

const POINTS: [[f64; 4]; 4] = [
    [0.3, 1.2, 2.5, 0.7],
    [1.9, 0.1, 0.2, -1.3],
    [-0.4, -0.4, 2.9, 3.0],
    [0.0, 2.5, 1e-3, 1e7],
];

/// Outputs (then the Jacobian's entries) at every point, as bit patterns.
fn bits(f: &Function) -> Vec<u64> {
    let mut out = Vec::new();
    for pt in POINTS {
        for y in f.call(&[&pt[..3], &pt[3..]]).unwrap() {
            out.extend(y.iter().map(|v| v.to_bits()));
        }
    }
    out
}

/// The Jacobian of `f`'s first output with respect to `x`, through a call node (so the
/// loaded function's derivatives are built from its tape).
fn jacobian_bits(f: &Function) -> Vec<u64> {
    let x = Matrix::sym_vec("x", 3);
    let p = Matrix::sym_vec("p", 1);
    let y = f.apply(&[&x, &p]).unwrap().remove(0);
    let j = jacobian(&y, &x).unwrap();
    let jf = Function::new(&[&x, &p], &[j.values()]).unwrap();
    bits(&jf)
}

#[test]
fn a_loaded_function_evaluates_bit_identically() {
    let f = sample();
    let text = f.to_json().unwrap();
    let (want, want_jac) = (bits(&f), jacobian_bits(&f));
    // In a fresh graph: nothing of the original's expressions exists there.
    let (got, got_jac, again) = with_fresh_arena(|| {
        let g = Function::from_json(&text).unwrap();
        (bits(&g), jacobian_bits(&g), g.to_json().unwrap())
    });
    assert_eq!(got, want);
    assert_eq!(got_jac, want_jac);
    assert_eq!(again, text, "saving a loaded function writes the same file");
    assert!(
        text.contains("\"-inf\"") && text.contains("\"inf\""),
        "non-finite constants"
    );
}

#[test]
fn the_checked_in_file_loads_and_evaluates_as_the_function_built_now() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/function_v1.json"
    );
    if std::env::var_os("SYMX_WRITE_FIXTURE").is_some() {
        sample().save(path).unwrap();
    }
    let g = Function::load(path).unwrap();
    assert_eq!(bits(&g), bits(&sample()));
    assert_eq!(jacobian_bits(&g), jacobian_bits(&sample()));
    assert_eq!(g.output_names(), ["y", "z"]);
}

#[test]
fn other_versions_and_damaged_files_are_refused() {
    let text = sample().to_json().unwrap();
    let v = format!("\"version\":{FUNCTION_FILE_VERSION}");
    let err = Function::from_json(&text.replacen(&v, "\"version\":7", 1)).unwrap_err();
    assert!(matches!(err, FunctionFileError::Version { found: 7, .. }));
    let msg = err.to_string();
    assert!(
        msg.contains("version 7") && msg.contains(&format!("version {FUNCTION_FILE_VERSION}")),
        "{msg}"
    );
    let err = Function::from_json("{\"format\":\"symnlp.solution\",\"version\":1}").unwrap_err();
    assert!(err.to_string().contains("\"format\""), "{err}");
    assert!(Function::from_json("not json").is_err());
    // A register beyond the work vector: an error, not an out-of-bounds access.
    let damaged = text.replacen(
        "\"tape\":[[\"",
        "\"tape\":[[\"Sin\",4000000000,0,0,0],[\"",
        1,
    );
    let err = Function::from_json(&damaged).unwrap_err().to_string();
    assert!(err.contains("out of range"), "{err}");
    let err = Function::load("/nonexistent/f.json")
        .unwrap_err()
        .to_string();
    assert!(err.contains("/nonexistent/f.json"), "{err}");
}

#[test]
fn external_functions_cannot_be_saved() {
    let ext = Function::external(
        "plant",
        &[("x", 1)],
        &[("y", 1)],
        |x: &[f64], y: &mut [f64]| y[0] = 2.0 * x[0],
    )
    .unwrap();
    let err = ext.to_json().unwrap_err();
    assert!(err.to_string().contains("'plant' is external"), "{err}");
    // Also when called from a compiled function.
    let x = Matrix::sym_vec("x", 1);
    let y = ext.apply(&[&x]).unwrap().remove(0);
    let f = Function::new(&[&x], &[&y]).unwrap();
    assert!(matches!(f.to_json(), Err(FunctionFileError::External { name }) if name == "plant"));
}
