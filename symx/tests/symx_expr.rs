//! Expressions: local simplification and constant folding, `Display`/`parse` round trips,
//! error cases of `Function` and the derivative functions, threading and batch evaluation.
use testkit::trees;

use proptest::prelude::*;
use symx::{
    eq, forward, gradient, gt, if_else, jacobian, le, lt, ne, parse, reverse, Expr, Function,
    Matrix, Op, SymxError,
};

// ---------------------------------------------------------------------------------------
// Simplification
// ---------------------------------------------------------------------------------------

#[test]
fn identities_simplify_locally() {
    let x = Expr::sym("x");
    let y = Expr::sym("y");
    assert!((x + 0.0).is(x));
    assert!((0.0 + x).is(x));
    assert!((x - 0.0).is(x));
    assert!((0.0 - x).is(-x));
    assert!((x * 1.0).is(x));
    assert!((1.0 * x).is(x));
    assert!((x / 1.0).is(x));
    assert!((x * 0.0).is_constant_value(0.0));
    assert!((0.0 * x).is_constant_value(0.0));
    assert!((0.0 / x).is_constant_value(0.0));
    assert!((-(-x)).is(x));
    assert!((x - x).is_constant_value(0.0));
    assert!((x / x).is_constant_value(1.0));
    assert!((x * -1.0).is(-x));
    assert!((x + (-y)).is(x - y));
    assert!((x - (-y)).is(x + y));
    assert!((-(x - y)).is(y - x));
    assert!((x * x).is(x.sq()));
    assert!(((-x) * y).is(-(x * y)));
    assert!((x * (-y)).is(-(x * y)));
    assert!(((-x) * (-y)).is(x * y));
    assert!(((-x) / y).is(-(x / y)));
    assert!((2.0 * (-x) + 3.0 * x).is(3.0 * x - 2.0 * x));
    assert!(x.powi(2).is(x.sq()));
    assert!(x.powf(0.5).is(x.sqrt()));
    assert!(x.powi(1).is(x));
    assert!(x.powi(0).is_constant_value(1.0));
    assert!((-x).sq().is(x.sq()));
    assert!(x.sq().abs().is(x.sq()));
    assert!(x.min(x).is(x));
    assert!(le(x, x).is_constant_value(1.0));
    assert!(lt(x, x).is_constant_value(0.0));
    assert!(if_else(gt(x, 0.0), y, y).is(y));
}

/// `c·(2ᵏ·y)` becomes `(c·2ᵏ)·y` only where that is exact (`|c| ≥ 1`, `k ≥ 0`: see
/// `Graph::fold_scale`), and the folded function gives the bits of the unfolded product on
/// special values, at the overflow threshold and among subnormals.
#[test]
fn a_constant_times_a_doubling_folds_only_where_exact() {
    let x = Expr::sym("x");
    let y = x - 3.0;
    for (c, s) in [(1000.0, 2.0), (-3.0, 4.0), (1.5, -2.0), (1e300, 8.0)] {
        let folded = c * (s * y);
        assert!(folded.is((c * s) * y), "{c}·({s}·y) is {folded}");
        assert!(((s * y) * c).is((c * s) * y));
    }
    // |c| < 1, s not a power of two, s < 1, or c·s overflowing: kept as written.
    for (c, s) in [(0.001, 2.0), (1000.0, 3.0), (1000.0, 0.5), (1e308, 4.0)] {
        assert!(!(c * (s * y)).is((c * s) * y), "{c}·({s}·y) folded");
    }
    let mut ys = testkit::special::SPECIAL.to_vec();
    let max = f64::MAX;
    ys.extend([
        max,
        -max,
        max / 2.0,
        max / 1000.0,
        5e-324,
        -1.5e-323,
        2.2e-308,
    ]);
    ys.extend([
        f64::from_bits(0x7ff8_0000_0000_0007),
        f64::from_bits(0xfff8_0000_0000_0009),
    ]);
    for (c, s) in [
        (1000.0, 2.0),
        (-3.0, 4.0),
        (1.5, -2.0),
        (1.0 + f64::EPSILON, 1024.0),
    ] {
        let f = Function::new(&[&[x]], &[&[c * (s * x)]]).unwrap();
        assert_eq!(f.instruction_count(), 1);
        for &v in &ys {
            let got = f.call(&[&[v]]).unwrap()[0][0];
            let want = c * (s * std::hint::black_box(v));
            assert_eq!(got.to_bits(), want.to_bits(), "{c}·({s}·{v:e})");
        }
    }
    // Why |c| ≥ 1: 0.001·(2·y) overflows where 0.002·y does not.
    let y = std::hint::black_box(max);
    assert!((0.001 * (2.0 * y)).is_infinite() && (0.002 * y).is_finite());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20_000, max_global_rejects: 100_000, ..ProptestConfig::default() })]
    /// The rule of `Graph::fold_scale` on arbitrary bit patterns: `c·(s·y)` and `(c·s)·y`
    /// agree bit for bit for every `y` (NaN payloads, infinities, subnormals included),
    /// every `|c| ≥ 1` and `s = ±2ᵏ`, `k ≥ 0`, with `c·s` finite.
    #[test]
    fn a_constant_times_a_doubling_is_exact_for_every_operand(
        y in any::<u64>(),
        c_mantissa in 0u64..1 << 52,
        c_exponent in 1023u64..2047,
        c_negative in any::<bool>(),
        k in 0i32..1100,
        negative in any::<bool>(),
    ) {
        let y = f64::from_bits(y);
        // |c| ≥ 1, finite: any sign and mantissa, a biased exponent of at least 1023.
        let c = f64::from_bits((c_negative as u64) << 63 | c_exponent << 52 | c_mantissa);
        let s = if negative { -(2f64.powi(k)) } else { 2f64.powi(k) };
        prop_assume!(c.abs() >= 1.0 && s.is_finite() && (c * s).is_finite());
        let (c, s, y) = std::hint::black_box((c, s, y));
        prop_assert_eq!((c * (s * y)).to_bits(), ((c * s) * y).to_bits());
    }
}

#[test]
fn constants_fold() {
    let x = Expr::sym("x");
    let c = (Expr::constant(2.0) * 3.0 + 1.0).sqrt() - Expr::constant(7.0).sqrt();
    assert!(c.is_constant_value(0.0));
    assert_eq!(Expr::constant(0.5).sin().value(), Some(0.5f64.sin()));
    assert_eq!(
        Expr::constant(2.0).atan2(1.0).value(),
        Some(2f64.atan2(1.0))
    );
    assert_eq!(Expr::constant(-8.0).powi(3).value(), Some(-512.0));
    assert_eq!(gt(Expr::constant(2.0), 1.0).value(), Some(1.0));
    // A constant condition selects its branch at construction.
    assert!(if_else(lt(Expr::constant(1.0), 2.0), x, x.sin()).is(x));
    // Interning: equal constants are one node, -0 is 0, every NaN is one NaN.
    assert!(Expr::constant(3.5).is(Expr::constant(3.5)));
    assert!(Expr::constant(-0.0).is(Expr::zero()));
    let nan1 = Expr::constant(0.0) / 0.0;
    let nan2 = Expr::constant(-1.0).sqrt();
    assert!(nan1.value().unwrap().is_nan());
    assert!(nan1.is(nan2));
    assert!(nan1.is(Expr::constant(f64::NAN)));
}

#[test]
fn structurally_equal_expressions_share_nodes() {
    let x = Expr::sym("x");
    let y = Expr::sym("y");
    assert!((x * y + 1.0).sin().is((y * x + 1.0).sin()));
    assert!((x + y).is(y + x));
    assert!(!(x - y).is(y - x));
    // Symbols with equal names are still distinct.
    assert!(!Expr::sym("x").is(x));
    assert_eq!((x * y).op(), Op::Mul);
    assert_eq!((x * y).operands().len(), 2);
}

// ---------------------------------------------------------------------------------------
// Display and parse
// ---------------------------------------------------------------------------------------

fn round_trips(e: Expr, symbols: &[Expr]) {
    let text = e.to_string();
    let back = parse(&text, symbols).unwrap_or_else(|err| panic!("{err} parsing {text}"));
    assert!(back.is(e), "{text}\nparsed back as\n{back}");
}

#[test]
fn display_is_readable_and_round_trips() {
    let x = Matrix::sym_vec("x", 3);
    let y = Expr::sym("y");
    let syms: Vec<Expr> = x.iter().copied().chain([y]).collect();
    let e = (x[0] * y + 1.0).sin() / 2.0 - x[1].powi(3);
    assert_eq!(e.to_string(), "((sin((1+(x[0]*y)))/2)-pow(x[1],3))");
    round_trips(e, &syms);
    for e in [
        -x[0],
        x[0] * -2.5,
        x[0] - (-2.0),
        x[0] + 1e-300,
        x[0] * 1e20,
        x[0] * 0.1,
        x[0] + f64::INFINITY,
        x[0] - f64::INFINITY,
        x[0] * f64::NAN,
        Expr::constant(-3.0),
        if_else(gt(x[0], x[1]), x[2].sqrt(), y.atan2(x[0])),
        x[0].min(y).max(x[1].abs()).sign(),
        symx::and(ne(x[0], 1.0), symx::not(eq(y, 2.0))),
        symx::or(le(x[0], 1.0), lt(2.0, y)),
        x[0].tan()
            .asin()
            .acos()
            .atan()
            .sinh()
            .cosh()
            .tanh()
            .exp()
            .ln(),
        x[0].powf(1.5).pow(y),
    ] {
        round_trips(e, &syms);
    }
}

#[test]
fn display_binds_shared_subexpressions() {
    let x = Expr::sym("x");
    let y = Expr::sym("y");
    let s = (x * y).sin();
    let e = s * s.cos() + (s + x * y).sq();
    let text = e.to_string();
    assert!(text.starts_with("@1="), "{text}");
    assert!(text.contains("@2"), "{text}");
    round_trips(e, &[x, y]);
    // Derivatives share a lot.
    let g = gradient(e, &[x, y]).unwrap();
    round_trips(g[0], &[x, y]);
    round_trips(g[1], &[x, y]);
}

#[test]
fn parse_reports_errors() {
    let x = Expr::sym("x");
    for bad in [
        "",
        "x+",
        "(x",
        "foo(x)",
        "sin(x,x)",
        "x y",
        "@3",
        "z",
        "1.2.3",
        "if_else(x,x)",
    ] {
        match parse(bad, &[x]) {
            Err(SymxError::Parse { .. }) => {}
            other => panic!("{bad:?}: {other:?}"),
        }
    }
    // A symbol table entry that is not a symbol.
    assert!(matches!(
        parse("x", &[x * 2.0]),
        Err(SymxError::NotASymbol { .. })
    ));
}

#[test]
fn parse_of_deep_nesting_does_not_overflow_the_stack() {
    // The parser is iterative: this runs on the 2 MiB test thread.
    let x = Expr::sym("x");
    let n = 100_000;
    let deep = format!("{}x{}", "sin(".repeat(n), ")".repeat(n));
    let mut want = x;
    for _ in 0..n {
        want = want.sin();
    }
    assert!(parse(&deep, &[x]).unwrap().is(want));
    assert!(parse(&format!("{}x{}", "(".repeat(n), ")".repeat(n)), &[x])
        .unwrap()
        .is(x));
    assert!(parse(&format!("{}x", "-".repeat(n + 1)), &[x])
        .unwrap()
        .is(-x));
    assert!(parse(&format!("{}x{}", "sin(".repeat(n), ")".repeat(n - 1)), &[x]).is_err());
    // A printed chain round trips.
    let mut e = x;
    for _ in 0..20_000 {
        e = e.sin() * 0.5 + x;
    }
    round_trips(e, &[x]);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn random_trees_round_trip(t in trees::tree(3, 5)) {
        let x = Matrix::sym_vec("x", 3);
        let e = t.build(&x);
        let text = e.to_string();
        let back = parse(&text, &x);
        prop_assert!(back.is_ok(), "{:?} parsing {}", back, text);
        prop_assert!(back.unwrap().is(e), "{}", text);
    }
}

// ---------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------

#[test]
fn function_errors_are_errors_not_panics() {
    let x = Matrix::sym_vec("x", 2);
    let p = Expr::sym("p");
    match Function::new(&[&x], &[&[x[0] * p]]) {
        Err(SymxError::FreeSymbol { output: 0, name }) => assert_eq!(name, "p"),
        other => panic!("{other:?}"),
    }
    let err = Function::new(&[&x], &[&[x[0]], &[x[1] + p.sin()]]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "output 1 depends on symbol 'p', which is not an input"
    );
    assert!(matches!(
        Function::new(&[&[x[0] * 2.0]], &[&[x[0]]]),
        Err(SymxError::NotASymbol { index: 0, .. })
    ));
    assert!(matches!(
        Function::new(&[&x, &[x[1]]], &[&[x[0]]]),
        Err(SymxError::DuplicateSymbol { .. })
    ));

    let f = Function::new(&[&x, &[p]], &[&[x[0] * p], &[x[1], p]]).unwrap();
    assert_eq!(f.input_sizes(), &[2, 1]);
    assert_eq!(f.output_sizes(), &[1, 2]);
    let mut work = vec![0.0; f.work_size()];
    let (mut o0, mut o1) = ([0.0], [0.0; 2]);
    // Wrong number of inputs / outputs.
    assert!(matches!(
        f.call(&[&[1.0, 2.0]]),
        Err(SymxError::ArgumentCount { .. })
    ));
    assert!(f
        .eval(&[&[1.0, 2.0], &[3.0]], &mut [&mut o0], &mut work)
        .is_err());
    // Wrong lengths.
    assert!(matches!(
        f.call(&[&[1.0], &[3.0]]),
        Err(SymxError::Length {
            what: "input",
            index: 0,
            ..
        })
    ));
    assert!(f.call(&[&[1.0, 2.0], &[]]).is_err());
    let mut short = [0.0; 1];
    assert!(matches!(
        f.eval(
            &[&[1.0, 2.0], &[3.0]],
            &mut [&mut o0, &mut short],
            &mut work
        ),
        Err(SymxError::Length {
            what: "output",
            index: 1,
            ..
        })
    ));
    let mut small = vec![0.0; f.work_size().saturating_sub(1)];
    if f.work_size() > 0 {
        assert!(f
            .eval(&[&[1.0, 2.0], &[3.0]], &mut [&mut o0, &mut o1], &mut small)
            .is_err());
    }
    assert!(f
        .eval_batch(
            &[&[1.0, 2.0, 3.0], &[3.0, 4.0]],
            &mut [&mut [0.0; 2], &mut [0.0; 4]],
            &mut work,
            2
        )
        .is_err());
    f.eval(&[&[1.0, 2.0], &[3.0]], &mut [&mut o0, &mut o1], &mut work)
        .unwrap();
    assert_eq!((o0, o1), ([3.0], [2.0, 3.0]));
}

#[test]
fn derivative_errors() {
    let x = Matrix::sym_vec("x", 2);
    let f = x[0] * x[1];
    assert!(matches!(
        gradient(f, &[x[0] + 1.0]),
        Err(SymxError::NotASymbol { .. })
    ));
    assert!(matches!(
        gradient(f, &[x[0], x[0]]),
        Err(SymxError::DuplicateSymbol { .. })
    ));
    assert!(matches!(
        forward(&[f], &x, &[Expr::one()]),
        Err(SymxError::ArgumentCount { .. })
    ));
    assert!(matches!(
        reverse(&[f], &x, &[]),
        Err(SymxError::ArgumentCount { .. })
    ));
    assert!(jacobian(&[f], &[f]).is_err());
    let s = Expr::sym("s");
    assert!(symx::lagrangian_hessian(f, &[f], &x, s, &[]).is_err());
}

#[test]
fn matrix_errors() {
    let a = Matrix::sym("a", 2, 3);
    let b = Matrix::sym("b", 2, 3);
    assert!(a.matmul(&b).is_err());
    assert!(a.matmul(&b.t()).is_ok());
    assert!(Matrix::vertcat(&[&a, &b.t()]).is_err());
    assert!(Matrix::horzcat(&[&a, &b.t()]).is_err());
    assert!(a.dot(&b.t()).is_err());
    assert!(a.cross(&b).is_err());
    assert!(a.skew().is_err());
    assert!(a.slice(0..3, 0..1).is_err());
    assert!(a.get(2, 0).is_none());
    assert!(Matrix::from_column_major(2, 2, vec![Expr::one(); 3]).is_err());
    assert!(Matrix::from_rows_f64(&[&[1.0], &[1.0, 2.0]]).is_err());
    assert!(
        symx::SparseMatrix::new(symx::sparsity::pattern_from_entries(2, 2, [(0, 0)]), vec![])
            .is_err()
    );
}

#[test]
fn matrix_operations() {
    let v = Matrix::sym_vec("v", 3);
    let w = Matrix::sym_vec("w", 3);
    let vw = v.cross(&w).unwrap();
    let sk = v.skew().unwrap().matmul(&w).unwrap();
    let all: Vec<Expr> = v.iter().chain(w.iter()).copied().collect();
    let f = Function::new(
        &[&all],
        &[&vw, &sk, &[v.dot(&w).unwrap(), v.norm_2(), v.sum()]],
    )
    .unwrap();
    let out = f.call(&[&[1.0, 2.0, 3.0, -1.0, 0.5, 2.0]]).unwrap();
    assert_eq!(out[0], vec![2.5, -5.0, 2.5]);
    assert_eq!(out[0], out[1]);
    assert_eq!(out[2], vec![6.0, 14f64.sqrt(), 6.0]);
    let m = Matrix::sym("m", 2, 3);
    assert_eq!(m.t().shape(), (3, 2));
    assert!(m.t()[(2, 1)].is(m[(1, 2)]));
    let st = Matrix::vertcat(&[&m, &m.row(0).unwrap()]).unwrap();
    assert_eq!(st.shape(), (3, 3));
    assert!(st[(2, 2)].is(m[(0, 2)]));
    let hz = Matrix::horzcat(&[&m, &m.column(1).unwrap()]).unwrap();
    assert!(hz[(1, 3)].is(m[(1, 1)]));
    assert!(m.slice(1..2, 1..3).unwrap()[(0, 1)].is(m[(1, 2)]));
    assert!((&Matrix::eye(2) * &m)[(1, 2)].is(m[(1, 2)]));
    assert!(m.map(|e| e * 0.0).iter().all(|e| e.is_constant_value(0.0)));
    // Owned and borrowed operands give the same (hash-consed) nodes.
    let s = Expr::sym("s");
    let by_ref = &v + &(s * &w);
    for (a, b) in by_ref.iter().zip((&v + s * w.clone()).iter()) {
        assert!(a.is(*b));
    }
    let diff = &v - 2.0 * w.clone();
    assert!(diff[1].is(v[1] - 2.0 * w[1]));
}

// ---------------------------------------------------------------------------------------
// Threads and batches
// ---------------------------------------------------------------------------------------

const fn assert_send_sync<T: Send + Sync>() {}
const _: () = assert_send_sync::<Function>();
const _: () = assert_send_sync::<SymxError>();

fn sample_function() -> Function {
    let x = Matrix::sym_vec("x", 3);
    let f = (x[0] * x[1]).sin() + x[2].exp() * x[0];
    let g = gradient(f, &x).unwrap();
    let h = symx::hessian(f, &x).unwrap();
    Function::new(&[&x], &[&[f], &g, h.values()]).unwrap()
}

fn point(k: usize) -> [f64; 3] {
    let t = k as f64;
    [(0.3 * t).sin(), (0.7 * t).cos(), 0.01 * t]
}

#[test]
fn evaluation_from_several_threads_is_identical() {
    let fun = sample_function();
    let serial: Vec<Vec<Vec<f64>>> = (0..200).map(|k| fun.call(&[&point(k)]).unwrap()).collect();
    let results: Vec<Vec<Vec<Vec<f64>>>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|_| {
                s.spawn(|| {
                    (0..200)
                        .map(|k| fun.call(&[&point(k)]).unwrap())
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for r in results {
        assert_eq!(r, serial);
    }
    // A function compiled on another thread works here (it is independent of the graph).
    let moved = std::thread::spawn(sample_function).join().unwrap();
    assert_eq!(moved.call(&[&point(3)]).unwrap(), serial[3]);
}

#[test]
fn eval_batch_equals_repeated_eval() {
    let fun = sample_function();
    let points = 37;
    let xs: Vec<f64> = (0..points).flat_map(point).collect();
    let sizes = fun.output_sizes().to_vec();
    let mut outs: Vec<Vec<f64>> = sizes.iter().map(|&n| vec![0.0; n * points]).collect();
    let mut work = vec![0.0; fun.work_size()];
    {
        let mut refs: Vec<&mut [f64]> = outs.iter_mut().map(|v| v.as_mut_slice()).collect();
        fun.eval_batch(&[&xs], &mut refs, &mut work, points)
            .unwrap();
    }
    for p in 0..points {
        let single = fun.call(&[&xs[3 * p..3 * p + 3]]).unwrap();
        for (k, n) in sizes.iter().enumerate() {
            assert_eq!(
                &outs[k][p * n..(p + 1) * n],
                single[k].as_slice(),
                "point {p} output {k}"
            );
        }
    }
    // Zero points is a valid (empty) batch.
    let mut empty: Vec<&mut [f64]> = vec![&mut [], &mut [], &mut []];
    fun.eval_batch(&[&[]], &mut empty, &mut work, 0).unwrap();
}

#[test]
fn compiled_function_evaluates_common_subexpressions_once() {
    let x = Expr::sym("x");
    let s = (x.sin() * x.cos()).exp();
    let f = Function::new(&[&[x]], &[&[s + s.sq(), s * 2.0]]).unwrap();
    // sin, cos, mul, exp, sq, add, mul: inputs are copied in and outputs out in bulk.
    assert_eq!(f.instruction_count(), 7);
    // 1 input, 1 constant, 2 output slots and at most 2 temporaries.
    assert!(f.work_size() <= 6, "work size {}", f.work_size());
    assert_eq!(
        f.call(&[&[0.5]]).unwrap()[0][1],
        2.0 * (0.5f64.sin() * 0.5f64.cos()).exp()
    );
}

/// Names with a superscript and an index, as the gap-crossing model prints them
/// (`r_BR^3[0]`), parse back to the same node.
#[test]
fn superscripted_indexed_names_round_trip() {
    let x = symx::Matrix::sym_vec("r_BR^3", 2);
    let e = (x[0] - x[1]).sq() + x[0].sin();
    let back = symx::parse(&e.to_string(), &x).unwrap();
    assert!(back.is(e), "{e} parsed as {back}");
}
