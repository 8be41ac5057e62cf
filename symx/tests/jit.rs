//! Native evaluation ([`Function::jit`]) against the tape, bit for bit: every operation on
//! ordinary, signed-zero, infinite and NaN operands; random expression graphs (proptest);
//! derivatives; call nodes (nested), `map`, lookup tables; tapes longer than one chunk.
//! The tape is the reference: the JIT must perform the same IEEE operations in the same
//! order and call the same math functions, so no tolerance is allowed anywhere here.
use proptest::prelude::*;
use symx::{
    gradient, hessian, if_else, jacobian, parse, with_fresh_arena, Evaluator, Expr, Function,
    Interpolant, Interpolant2, InterpolantN, Matrix,
};
use testkit::special::SPECIAL;

/// Evaluates `f` and its JIT at `point` and asserts every output bit-identical (a NaN's
/// payload included); returns the outputs.
fn same_bits(f: &Function, inputs: &[&[f64]]) -> Vec<Vec<f64>> {
    let native = f.jit().expect("jit");
    assert_eq!(native.evaluator(), Evaluator::Jit);
    let want = f.call(inputs).unwrap();
    let got = native.call(inputs).unwrap();
    for (k, (w, g)) in want.iter().zip(&got).enumerate() {
        for (i, (a, b)) in w.iter().zip(g).enumerate() {
            assert_eq!(
                a.to_bits(),
                b.to_bits(),
                "output {k}[{i}]: tape {a:e}, jit {b:e}"
            );
        }
    }
    want
}

/// Every unary and binary operation, and `if_else`, on every pair of special operands.
#[test]
fn every_operation_matches_the_tape_on_special_values() {
    let x = Expr::sym("x");
    let y = Expr::sym("y");
    let z = Expr::sym("z");
    let unary = [
        "neg", "sq", "sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos", "atan", "sinh",
        "cosh", "tanh", "abs", "sign", "not", "floor", "ceil", "erf", "asinh", "acosh", "atanh",
        "log1p", "expm1",
    ];
    let binary = [
        "add",
        "sub",
        "mul",
        "div",
        "pow",
        "atan2",
        "min",
        "max",
        "lt",
        "le",
        "eq",
        "ne",
        "and",
        "or",
        "strong_mul",
        "fmod",
        "hypot",
    ];
    let syms = [x, y, z];
    let mut outs: Vec<Expr> = unary
        .iter()
        .map(|n| parse(&format!("{n}(x)"), &syms).unwrap())
        .chain(
            binary
                .iter()
                .map(|n| parse(&format!("{n}(x,y)"), &syms).unwrap()),
        )
        .collect();
    outs.push(if_else(x, y, z));
    // Each parsed name really is that operation (the simplifier folds none of them).
    for (e, n) in outs.iter().zip(unary.iter().chain(&binary)) {
        assert_eq!(e.op().name(), *n);
    }
    let f = Function::new(&[&[x, y, z]], &[&outs]).unwrap();
    for &a in &SPECIAL {
        for &b in &SPECIAL {
            same_bits(&f, &[&[a, b, -b]]);
        }
    }
}

/// A random straight-line program over three symbols: each step applies one of many
/// operations to earlier values (indices taken modulo the number of values so far).
fn program() -> impl Strategy<Value = Vec<(u8, usize, usize, usize)>> {
    prop::collection::vec(
        (0u8..24, any::<usize>(), any::<usize>(), any::<usize>()),
        1..200,
    )
}

fn build(prog: &[(u8, usize, usize, usize)], v: &mut Vec<Expr>) {
    for &(op, i, j, k) in prog {
        let n = v.len();
        let (a, b, c) = (v[i % n], v[j % n], v[k % n]);
        v.push(match op {
            0 => a + b,
            1 => a * b,
            2 => a - b,
            3 => a / b,
            4 => a.sin(),
            5 => a.exp(),
            6 => a.sqrt(),
            7 => a.ln(),
            8 => a.powi(3),
            9 => a.pow(b),
            10 => a.min(b),
            11 => a.max(b),
            12 => if_else(symx::lt(a, b), b, c),
            13 => a.abs(),
            14 => a.tanh(),
            15 => a.atan2(b),
            16 => -a,
            17 => a * 0.5 + 1.0,
            18 => a.sq(),
            19 => a.sign() * b,
            20 => a.floor() + c,
            21 => a.hypot(b),
            22 => a.cos() * c,
            _ => (a * b).cos(),
        });
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// Values, gradient and Hessian of random programs: the JIT equals the tape bit for bit
    /// at random points (NaN and inf arise freely from log, sqrt, division, pow).
    #[test]
    fn random_graphs_match_the_tape(prog in program(), p in prop::array::uniform3(-3.0f64..3.0)) {
        with_fresh_arena(|| {
            let xs = Matrix::sym_vec("x", 3);
            let mut v = xs.entries().to_vec();
            build(&prog, &mut v);
            let last = *v.last().unwrap();
            let g = gradient(last, &xs).unwrap();
            let h = hessian(last, &xs).unwrap();
            let f = Function::new(&[&xs], &[&v, &g, h.values()]).unwrap();
            same_bits(&f, &[&p]);
        });
    }
}

/// Derivative functions are functions too: a Jacobian and a Hessian of a model with
/// transcendental functions, equal bit for bit.
#[test]
fn derivatives_match_the_tape() {
    let x = Matrix::sym_vec("x", 6);
    let mut g = Vec::new();
    for i in 0..5 {
        g.push((x[i] * x[i + 1]).sin() + x[i].exp() / (1.0 + x[i + 1].sq()));
    }
    let f = g.iter().fold(Expr::zero(), |s, &e| s + e.sq());
    let j = jacobian(&g, &x).unwrap();
    let h = hessian(f, &x).unwrap();
    let fun = Function::new(&[&x], &[&[f], j.values(), h.values()]).unwrap();
    let p = [0.1, -0.3, 0.7, 1.1, -2.0, 0.25];
    same_bits(&fun, &[&p]);
}

/// Calls of compiled functions (nested two deep, with outputs that are call outputs and
/// inputs), their derivatives (Jacobian and vector-Jacobian functions called in turn), and
/// `map` over a JIT-compiled function.
#[test]
fn calls_and_maps_match_the_tape() {
    let x = Matrix::sym_vec("x", 2);
    let inner = Function::named(
        "inner",
        &[("x", &x)],
        &[("y", &[x[0] * x[1].sin(), x[1].exp() - x[0]])],
    )
    .unwrap();
    let z = Matrix::sym_vec("z", 2);
    let once = inner.apply(&[&z]).unwrap().remove(0);
    let twice = inner.apply(&[&once]).unwrap().remove(0);
    let outer = Function::named(
        "outer",
        &[("z", &z)],
        &[("w", &[twice[0] + once[1], twice[1] * z[0]])],
    )
    .unwrap();
    let u = Matrix::sym_vec("u", 2);
    let w = outer.apply(&[&u]).unwrap().remove(0);
    let s = w[0] * w[1] + w[0].sq();
    let gs = gradient(s, &u).unwrap();
    let hs = hessian(s, &u).unwrap();
    let top = Function::new(&[&u], &[&w, &[s], &gs, hs.values(), &[w[0], u[1]]]).unwrap();
    for p in [
        [0.3, -0.8],
        [0.0, -0.0],
        [f64::NAN, 1.0],
        [1e3, f64::INFINITY],
    ] {
        same_bits(&top, &[&p]);
    }
    // map: 5 points, serial and on 2 threads.
    let native = top.jit().unwrap();
    let xs: Vec<f64> = (0..10).map(|k| 0.1 * k as f64 - 0.4).collect();
    let n_out: usize = top.output_sizes().iter().sum();
    let run = |f: &Function, threads| {
        let map = f.map(5).parallel(threads).unwrap();
        let mut outs: Vec<Vec<f64>> = f.output_sizes().iter().map(|&n| vec![0.0; 5 * n]).collect();
        let mut refs: Vec<&mut [f64]> = outs.iter_mut().map(|v| v.as_mut_slice()).collect();
        let mut work = vec![0.0; map.work_size()];
        map.eval(&[&xs], &mut refs, &mut work).unwrap();
        outs.concat()
    };
    let want = run(&top, 1);
    assert_eq!(want.len(), 5 * n_out);
    for threads in [1, 2] {
        let got = run(&native, threads);
        assert!(want
            .iter()
            .zip(&got)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}

/// Lookup tables of one, two and three dimensions (inside and outside their grids) and
/// their derivatives.
#[test]
fn lookup_tables_match_the_tape() {
    let grid: Vec<f64> = (0..6).map(|k| k as f64 * 0.5).collect();
    let vals: Vec<f64> = grid.iter().map(|g| (g * 1.3).sin()).collect();
    let t1 = Interpolant::bspline(&grid, &vals).unwrap();
    let vals2: Vec<f64> = (0..36).map(|k| (k as f64 * 0.37).cos()).collect();
    let t2 = Interpolant2::bspline(&grid, &grid, &vals2).unwrap();
    let vals3: Vec<f64> = (0..216).map(|k| (k as f64 * 0.11).sin()).collect();
    let t3 = InterpolantN::linear(&[&grid, &grid, &grid], &vals3).unwrap();
    let x = Matrix::sym_vec("x", 3);
    let e = t1.eval(x[0]) * t2.eval(x[1], x[2]) + t3.eval(&x).unwrap();
    let g = gradient(e, &x).unwrap();
    let f = Function::new(&[&x], &[&[e], &g]).unwrap();
    for p in [[0.3, 1.2, 2.2], [-1.0, 0.0, 5.0], [2.6, 2.4, 0.1]] {
        same_bits(&f, &[&p]);
    }
}

/// A tape several chunks long (a long chain: values computed in one chunk and read in later
/// ones, outputs written in every chunk); evaluating twice gives the same bits (no state).
#[test]
fn long_tapes_match_the_tape() {
    let x = Matrix::sym_vec("x", 4);
    let mut outs = Vec::new();
    let mut s = x[0];
    for k in 0..20_000 {
        s = (s * 0.999 + x[k % 4]).sin() + s.sq() * 1e-3;
        if k % 997 == 0 {
            outs.push(s);
        }
    }
    outs.push(s);
    outs.push(x[1]);
    let f = Function::new(&[&x], &[&outs]).unwrap();
    assert!(f.instruction_count() > 50_000);
    let p = [0.1, 0.2, -0.3, 0.4];
    let first = same_bits(&f, &[&p]);
    let native = f.jit().unwrap();
    let mut work = vec![f64::NAN; native.work_size()];
    let mut out = vec![0.0; outs.len()];
    native.eval(&[&p], &mut [&mut out], &mut work).unwrap();
    assert_eq!(out, first[0]);
    assert_eq!(native.tape().evaluator(), Evaluator::Tape);
}

/// [`SPECIAL`] and NaNs of both signs with different payloads (x86 returns the first
/// operand's NaN, so a swapped operand would show).
fn special_with_nan_payloads() -> Vec<f64> {
    let mut special = SPECIAL.to_vec();
    special.push(f64::from_bits(0x7ff8_0000_0000_0001));
    special.push(f64::from_bits(0xfff8_0000_0000_0002));
    special.push(-f64::NAN);
    special
}

/// The binary operations the JIT pairs into SIMD instructions.
fn pairable_binary() -> [fn(Expr, Expr) -> Expr; 4] {
    [|a, b| a + b, |a, b| a - b, |a, b| a * b, |a, b| a / b]
}

/// Independent isomorphic lanes, which the JIT evaluates two at a time in SIMD registers
/// (`f64x2`): every pairable operation (`+ − × ÷`, negation, square, square root, absolute
/// value) on every pair of special operands, NaNs of different signs and payloads in both
/// operands included (x86 returns the first operand's NaN, so swapped operands would show),
/// with constants, results reused by later scalar code, and outputs both side by side and
/// scattered.
#[test]
fn paired_lanes_match_the_tape_on_special_values() {
    let special = special_with_nan_payloads();
    let n = special.len();
    let x = Matrix::sym_vec("x", n);
    let y = Matrix::sym_vec("y", n);
    let binary = pairable_binary();
    let unary: [fn(Expr) -> Expr; 4] = [|a| -a, |a| a.sq(), |a| a.sqrt(), |a| a.abs()];
    for (k, op) in binary.iter().enumerate() {
        for (u, un) in unary.iter().enumerate() {
            // Lane i: a group of a few instructions on x[i], y[i] and constants.
            let lanes: Vec<Expr> = (0..n)
                .map(|i| {
                    let c = 0.5 + i as f64;
                    let t = op(x[i], y[i]);
                    let s = op(un(t), c.into());
                    op(s, x[i]) + op(y[i], t)
                })
                .collect();
            // Scalar code reading the lanes' results: a chain across the lanes.
            let mut tail = lanes.clone();
            let chain = lanes.iter().fold(Expr::from(0.0), |acc, &l| acc * 0.5 + l);
            tail.push(chain);
            let scattered: Vec<Expr> = lanes.iter().rev().step_by(2).copied().collect();
            let f = Function::new(&[&x, &y], &[&tail, &scattered]).unwrap();
            for shift in 0..n {
                let xs: Vec<f64> = (0..n).map(|i| special[(i + shift) % n]).collect();
                let ys: Vec<f64> = (0..n).map(|i| special[(i * 7 + k + u) % n]).collect();
                same_bits(&f, &[&xs, &ys]);
            }
        }
    }
}

/// Constants as the first operand of `+` and `×` (the JIT swaps them to second place so
/// that their load folds into the instruction, which must not change a bit): every special
/// operand, NaNs of both signs and several payloads included, against ordinary, signed-zero,
/// infinite and NaN constants (a NaN constant is never swapped, conservatively: with two
/// NaN operands the result's payload depends on the order), alone and in paired lanes; and
/// negations reusing the sign mask.
#[test]
fn constants_first_match_the_tape_on_special_values() {
    let special = special_with_nan_payloads();
    let n = special.len();
    let x = Matrix::sym_vec("x", n);
    let constants = [
        2.5,
        -0.0,
        0.0,
        f64::INFINITY,
        f64::from_bits(0x7ff8_0000_0000_0003),
        f64::from_bits(0xfff8_0000_0000_0004),
    ];
    let mut outs = Vec::new();
    for &c in &constants {
        let c = Expr::from(c);
        // Consecutive alike instructions (paired into lanes) and a lone one.
        outs.extend((0..n).map(|i| c * x[i]));
        outs.extend((0..n).map(|i| c + x[i]));
        outs.push(-(c * x[0]) + -(c + x[n - 1]));
    }
    let f = Function::new(&[&x], &[&outs]).unwrap();
    for shift in 0..n {
        let xs: Vec<f64> = (0..n).map(|i| special[(i + shift) % n]).collect();
        same_bits(&f, &[&xs]);
    }
}

/// A NaN constant (the graph keeps one, `f64::NAN`) made before the variables is the first
/// operand of `c + x` and `c · x` on the tape (commutative operands are ordered by node),
/// and x86 returns the first operand's NaN when both are NaN: the JIT must not move such a
/// constant second (as it does other constants), or `x`'s payload would come out instead
/// of `c`'s. Lone and paired (lanes) instructions both.
#[test]
fn a_nan_constant_first_keeps_its_place() {
    with_fresh_arena(|| {
        let cs = [Expr::from(f64::NAN)];
        let n = 4;
        let x = Matrix::sym_vec("x", n);
        let mut outs = Vec::new();
        for &c in &cs {
            outs.extend((0..n).map(|i| c * x[i]));
            outs.extend((0..n).map(|i| c + x[i]));
            outs.push(-(c * x[0]) + -(c + x[n - 1]));
        }
        let f = Function::new(&[&x], &[&outs]).unwrap();
        let xs = [
            f64::from_bits(0x7ff8_0000_0000_0001),
            f64::from_bits(0xfff8_0000_0000_0002),
            f64::NAN,
            1.5,
        ];
        let out = same_bits(&f, &[&xs]);
        // The tape itself returns the constant's NaN, not x₀'s (the test's premise).
        assert_eq!(out[0][0].to_bits(), f64::NAN.to_bits());
        assert_ne!(xs[0].to_bits(), f64::NAN.to_bits());
    });
}

/// Paired instructions whose second operand is a pair of different constants, which the
/// JIT loads from its pool of constant pairs (folded into the SIMD instruction): each lane
/// must get its own constant, special values and NaN payloads included, for `+ − × ÷` on
/// every special operand.
#[test]
fn constant_pairs_keep_their_lanes() {
    let special = special_with_nan_payloads();
    let n = special.len();
    let x = Matrix::sym_vec("x", n);
    let binary = pairable_binary();
    for shift in [0, 1, 5] {
        let mut outs = Vec::new();
        for op in binary {
            // Consecutive alike instructions: paired, each pair with two constants.
            outs.extend((0..n).map(|i| op(x[i], Expr::from(special[(i + shift) % n]))));
            outs.extend((0..n).map(|i| op(x[i], Expr::from(0.25 + i as f64))));
        }
        let f = Function::new(&[&x], &[&outs]).unwrap();
        for s in 0..n {
            let xs: Vec<f64> = (0..n).map(|i| special[(i * 3 + s) % n]).collect();
            same_bits(&f, &[&xs]);
        }
    }
}

/// `strong_mul(a, b)` (`a ⊛ b`: `+0` where `a = ±0`, else `a · b`), which the JIT computes
/// without a branch (the product and-ed with the mask of `a ≠ 0`), on every pair of special
/// operands, NaNs of different signs and payloads included, with loaded and computed
/// operands, alone and in paired lanes, and results read again by later instructions.
#[test]
fn guarded_products_match_the_tape_on_special_values() {
    let special = special_with_nan_payloads();
    let n = special.len();
    let x = Matrix::sym_vec("x", n);
    let y = Matrix::sym_vec("y", n);
    let syms: Vec<Expr> = x.iter().chain(y.iter()).copied().collect();
    // (Built from its printed form: the graph has no public constructor for it.)
    let strong = |a: Expr, b: Expr| parse(&format!("strong_mul({a},{b})"), &syms).unwrap();
    // Independent alike lanes first (paired into SIMD instructions), then scalar code.
    let mut outs: Vec<Expr> = (0..n).map(|i| strong(x[i], y[i])).collect();
    outs.extend((0..n).map(|i| strong(x[i] - y[i], y[i] * 0.5)));
    for i in 0..n {
        let p = strong(x[i], y[i]);
        let q = strong(p, y[(i + 1) % n]);
        let r = strong(x[i] * y[i], p + 1.0);
        outs.extend([p, q, r, strong(q, Expr::from(2.5)) + strong(r, p)]);
    }
    let f = Function::new(&[&x, &y], &[&outs]).unwrap();
    assert_eq!(outs[0].op().name(), "strong_mul");
    for shift in 0..n {
        let xs: Vec<f64> = (0..n).map(|i| special[(i + shift) % n]).collect();
        let ys: Vec<f64> = (0..n).map(|i| special[(i * 5 + 3) % n]).collect();
        same_bits(&f, &[&xs, &ys]);
    }
}

/// The first operand of `+` and `·` loaded from memory (used once) while the second is
/// computed: x86 returns the first operand's NaN when both are NaN, so the load must not be
/// folded into the instruction with the operands swapped (the JIT keeps it in a register).
/// One chain (nothing pairs into lanes, every value used once), NaNs of different signs and
/// payloads in both operands.
#[test]
fn a_loaded_first_operand_keeps_its_nan() {
    let special = special_with_nan_payloads();
    let n = special.len();
    let x = Matrix::sym_vec("x", n);
    let y = Matrix::sym_vec("y", n);
    // `x[i] ∘ (…)`: `x[i]` (made first, so the first operand) is loaded, the second
    // operand computed.
    let mut acc = y[0];
    for i in 0..n {
        acc = if i % 2 == 0 {
            x[i] + y[i] * acc
        } else {
            x[i] * (y[i] - acc)
        };
    }
    let f = Function::new(&[&x, &y], &[&[acc]]).unwrap();
    for shift in 0..n {
        for s in 0..n {
            let xs: Vec<f64> = (0..n).map(|i| special[(i + shift) % n]).collect();
            let ys: Vec<f64> = (0..n).map(|i| special[(i * 3 + s) % n]).collect();
            same_bits(&f, &[&xs, &ys]);
        }
    }
}

/// Constant outputs, which the JIT writes at every call from integer registers holding
/// their bits (shared by repeated constants): scattered among computed outputs, repeated,
/// signed zeros, infinities and NaN payloads, and more constants than one register's
/// reuse window.
#[test]
fn constant_outputs_keep_their_bits() {
    let x = Matrix::sym_vec("x", 2);
    let constants = [
        1.0,
        -1.0,
        0.5,
        -0.0,
        0.0,
        f64::INFINITY,
        f64::from_bits(0x7ff8_0000_0000_0005),
        f64::from_bits(0xfff8_0000_0000_0006),
        1e-310,
    ];
    let mut outs = Vec::new();
    for k in 0..200 {
        outs.push(Expr::from(constants[k % constants.len()]));
        if k % 3 == 0 {
            outs.push(x[0] * (k as f64) + x[1]);
        }
    }
    // Distinct constants beyond the reuse window.
    outs.extend((0..100).map(|k| Expr::from(0.125 * k as f64 + 3.0)));
    let f = Function::new(&[&x], &[&outs]).unwrap();
    let out = same_bits(&f, &[&[1.5, -2.0]]);
    assert_eq!(out[0][0], 1.0);
}

/// Outputs read back by later instructions: the JIT keeps such a value in the caller's
/// output (not also in the work vector) and reloads it from there when it is read far
/// later or in another chunk; also as the coordinates of a lookup table, and inside a
/// called function (whose outputs live in the caller's scratch). Evaluated with a work
/// vector and output buffers full of NaN: every output read back must have been written
/// first.
#[test]
fn outputs_read_back_match_the_tape() {
    let x = Matrix::sym_vec("x", 3);
    let grid: Vec<f64> = (0..5).map(|k| k as f64 * 0.5).collect();
    let vals: Vec<f64> = (0..125).map(|k| (k as f64 * 0.13).sin()).collect();
    let table = InterpolantN::linear(&[&grid, &grid, &grid], &vals).unwrap();
    // Early outputs, then a long chain (several chunks), then reads of the early outputs.
    let early: Vec<Expr> = (0..6)
        .map(|k| x[k % 3] * (k as f64 + 1.5) - x[(k + 1) % 3])
        .collect();
    let mut s = x[2];
    for k in 0..3_000 {
        s = s * 0.999 + (early[k % 6] * 1e-3).sin();
    }
    let looked_up = table.eval(&early[..3]).unwrap();
    let late: Vec<Expr> = early.iter().map(|&e| e * s + looked_up).collect();
    let inner = Function::named("inner", &[("x", &x)], &[("e", &early), ("l", &late)]).unwrap();
    let z = Matrix::sym_vec("z", 3);
    let called = inner.apply(&[&z]).unwrap();
    let top_outs: Vec<Expr> = called[0]
        .iter()
        .zip(&called[1])
        .map(|(&a, &b)| a * b + a)
        .collect();
    for f in [
        inner.clone(),
        Function::new(&[&z], &[&called[0], &top_outs, &called[1]]).unwrap(),
    ] {
        assert!(f.instruction_count() > 1024 || f.name() != "inner");
        for p in [[0.3, -0.8, 0.5], [1.0, 0.0, -0.0], [f64::NAN, 2.0, 0.25]] {
            let want = same_bits(&f, &[&p]);
            let native = f.jit().unwrap();
            let mut work = vec![f64::NAN; native.work_size()];
            let mut outs: Vec<Vec<f64>> = f
                .output_sizes()
                .iter()
                .map(|&n| vec![f64::NAN; n])
                .collect();
            let mut refs: Vec<&mut [f64]> = outs.iter_mut().map(|v| v.as_mut_slice()).collect();
            native.eval(&[&p], &mut refs, &mut work).unwrap();
            for (w, g) in want.iter().zip(&outs) {
                assert!(w.iter().zip(g).all(|(a, b)| a.to_bits() == b.to_bits()));
            }
        }
    }
}

/// Two operations in a row, the first's result read only by the second (`(x ∘ y) • z`,
/// `z • (x ∘ y)`, `−(x ∘ y)`), which the tape's interpreter runs as one fused step: on
/// every triple of special operands, NaNs of different signs and payloads in every
/// position, the same bits as the JIT (which runs the two instructions).
#[test]
fn fused_pairs_match_the_jit_on_special_values() {
    let special = special_with_nan_payloads();
    let (x, y, z) = (Expr::sym("x"), Expr::sym("y"), Expr::sym("z"));
    for first in pairable_binary() {
        let t = first(x, y);
        let mut pairs: Vec<Expr> = vec![-t];
        for second in pairable_binary() {
            pairs.push(second(t, z));
            pairs.push(second(z, t));
        }
        for e in pairs {
            let f = Function::new(&[&[x, y, z]], &[&[e]]).unwrap();
            for &a in &special {
                for &b in &special {
                    for &c in &special {
                        same_bits(&f, &[&[a, b, c]]);
                    }
                }
            }
        }
    }
}
