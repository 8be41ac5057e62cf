//! Function calls inside expression graphs (issue 13, item 2): a call node evaluates the
//! callee's tape; its derivatives go through the callee's Jacobian function. Every check
//! compares the call version with the same expressions inlined (an independent path:
//! ordinary scalar AD on the expanded graph) and with central finite differences.
use symx::sparsity::entries;
use symx::{gradient, gt, hessian, if_else, jacobian, Expr, Function, Matrix, SymxError};

/// A small nonlinear ODE right-hand side with 3 states and 1 control (a pendulum on a cart
/// with drag), written once as expressions.
fn ode(x: &[Expr], u: &[Expr]) -> Vec<Expr> {
    let (p, th, v) = (x[0], x[1], x[2]);
    vec![
        v,
        (th * 0.5).sin() * v + u[0] * p.cos(),
        u[0] - 0.1 * v * v.abs() + th.exp() * 0.01 - p.sq(),
    ]
}

/// A right-hand side `ẋ = f(x, u)` producing expressions.
type Rhs<'a> = &'a dyn Fn(&[Expr], &[Expr]) -> Vec<Expr>;

/// One RK4 step of `f` with step h.
fn rk4(f: Rhs, x: &[Expr], u: &[Expr], h: f64) -> Vec<Expr> {
    let add = |a: &[Expr], b: &[Expr], s: f64| -> Vec<Expr> {
        a.iter().zip(b).map(|(&a, &b)| a + s * b).collect()
    };
    let k1 = f(x, u);
    let k2 = f(&add(x, &k1, h / 2.0), u);
    let k3 = f(&add(x, &k2, h / 2.0), u);
    let k4 = f(&add(x, &k3, h), u);
    (0..x.len())
        .map(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
        .collect()
}

/// The ODE as a compiled function `f(x, u) -> xdot`.
fn ode_function() -> Function {
    let x = Matrix::sym_vec("x", 3);
    let u = Matrix::sym_vec("u", 1);
    let xdot = ode(&x, &u);
    Function::named("ode", &[("x", &x), ("u", &u)], &[("xdot", &xdot)]).unwrap()
}

/// A scalar objective over a chain of `n` RK4 steps from states w[0..3] with controls
/// w[3..3+n]: the dynamics either inlined or called through `f`.
fn chain(w: &[Expr], n: usize, f: Option<&Function>) -> (Expr, Vec<Expr>) {
    let call = |x: &[Expr], u: &[Expr]| -> Vec<Expr> {
        match f {
            Some(f) => f.apply(&[x, u]).unwrap().remove(0),
            None => ode(x, u),
        }
    };
    let mut x = w[..3].to_vec();
    let mut states = Vec::new();
    for k in 0..n {
        x = rk4(&call, &x, &w[3 + k..4 + k], 0.1);
        states.extend_from_slice(&x);
    }
    let obj = states.iter().map(|e| e.sq()).sum::<Expr>() + x[0] * x[1];
    (obj, states)
}

fn eval(inputs: &[Expr], outputs: &[&[Expr]], point: &[f64]) -> Vec<Vec<f64>> {
    Function::new(&[inputs], outputs)
        .unwrap()
        .call(&[point])
        .unwrap()
}

fn assert_close(what: &str, a: &[f64], b: &[f64], tol: f64) {
    assert_eq!(a.len(), b.len(), "{what}");
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= tol * y.abs().max(1.0),
            "{what}[{k}]: {x} vs {y}"
        );
    }
}

/// Call and inlined versions compute the same numbers, but not by the same operations
/// (operation order in the Jacobian contractions differs): 1e-12 relative.
const SAME_MATH: f64 = 1e-12;

fn point(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| 0.3 * ((i * 7 % 11) as f64 - 5.0) / 5.0 + 0.1)
        .collect()
}

#[test]
fn values_gradients_jacobians_hessians_match_the_inlined_graph() {
    let n = 6;
    let f = ode_function();
    let w = Matrix::sym_vec("w", 3 + n);
    let p = point(3 + n);
    let (obj_c, states_c) = chain(&w, n, Some(&f));
    let (obj_i, states_i) = chain(&w, n, None);
    let g_c = gradient(obj_c, &w).unwrap();
    let g_i = gradient(obj_i, &w).unwrap();
    let j_c = jacobian(&states_c, &w).unwrap();
    let j_i = jacobian(&states_i, &w).unwrap();
    let h_c = hessian(obj_c, &w).unwrap();
    let h_i = hessian(obj_i, &w).unwrap();
    // Exact sparsity: the same structural patterns.
    assert_eq!(entries(j_c.sparsity()), entries(j_i.sparsity()));
    assert_eq!(entries(h_c.sparsity()), entries(h_i.sparsity()));
    let c = eval(
        &w,
        &[&[obj_c], &states_c, &g_c, j_c.values(), h_c.values()],
        &p,
    );
    let i = eval(
        &w,
        &[&[obj_i], &states_i, &g_i, j_i.values(), h_i.values()],
        &p,
    );
    for (k, what) in ["objective", "states", "gradient", "jacobian", "hessian"]
        .iter()
        .enumerate()
    {
        assert_close(what, &c[k], &i[k], SAME_MATH);
    }
}

#[test]
fn derivatives_through_calls_match_finite_differences() {
    let n = 4;
    let f = ode_function();
    let w = Matrix::sym_vec("w", 3 + n);
    let (obj, _) = chain(&w, n, Some(&f));
    let g = gradient(obj, &w).unwrap();
    let fun = Function::new(&[&w], &[&[obj], &g]).unwrap();
    let p = point(3 + n);
    let g0 = fun.call(&[&p]).unwrap()[1].clone();
    for j in 0..p.len() {
        let h = 1e-6;
        let (mut a, mut b) = (p.clone(), p.clone());
        a[j] += h;
        b[j] -= h;
        let d = (fun.call(&[&a]).unwrap()[0][0] - fun.call(&[&b]).unwrap()[0][0]) / (2.0 * h);
        // Central differences: truncation ~h²·|f'''| and rounding ~1e-16·|f|/h: 1e-7 is wide.
        assert!(
            (g0[j] - d).abs() <= 1e-7 * d.abs().max(1.0),
            "∂/∂w{j}: {} vs {d}",
            g0[j]
        );
    }
}

#[test]
fn forward_mode_through_calls_matches_reverse_mode() {
    let f = ode_function();
    let w = Matrix::sym_vec("w", 5);
    let (_, states) = chain(&w, 2, Some(&f));
    let v = Matrix::sym_vec("v", 5);
    let jv = symx::forward(&states, &w, &v).unwrap();
    let j = jacobian(&states, &w).unwrap().to_dense();
    let jv_ref = &j * &v;
    let all: Vec<Expr> = [w.to_vec(), v.to_vec()].concat();
    let p = point(10);
    let out = eval(&all, &[&jv, &jv_ref], &p);
    assert_close("J·v", &out[0], &out[1], SAME_MATH);
}

#[test]
fn the_chain_holds_the_dynamics_once() {
    // A 50-stage chain with its Lagrangian-like Hessian, the RK4 step either inlined at
    // every stage or compiled once and called; graphs built on fresh threads to count.
    let count = |use_call: bool| {
        std::thread::spawn(move || {
            let x = Matrix::sym_vec("x", 3);
            let u = Matrix::sym_vec("u", 1);
            let step = Function::new(&[&x, &u], &[&rk4(&ode, &x, &u, 0.1)]).unwrap();
            let before = symx::node_count();
            let w = Matrix::sym_vec("w", 3 + 50);
            let mut s = w[..3].to_vec();
            let mut obj = Expr::zero();
            for k in 0..50 {
                s = if use_call {
                    step.apply(&[&s, &[w[3 + k]]]).unwrap().remove(0)
                } else {
                    rk4(&ode, &s, &[w[3 + k]], 0.1)
                };
                obj += s[0] * s[1] + s[2].sq();
            }
            let _ = hessian(obj, &w).unwrap();
            symx::node_count() - before
        })
        .join()
        .unwrap()
    };
    let (with_calls, inlined) = (count(true), count(false));
    eprintln!("50-stage Hessian graph: {with_calls} nodes with calls, {inlined} inlined");
    assert!(
        with_calls * 3 < inlined,
        "call graph {with_calls} nodes, inlined {inlined}"
    );
}

#[test]
fn identical_calls_are_one_node_and_print_by_name() {
    let f = ode_function();
    let x = Matrix::sym_vec("x", 3);
    let u = Expr::sym("u");
    let a = f.apply(&[&x, &[u]]).unwrap();
    let b = f.apply(&[&x, &[u]]).unwrap();
    assert!(a[0][1].is(b[0][1]));
    assert_eq!(a[0][2].to_string(), "ode(x[0],x[1],x[2],u)[2]");
    assert_eq!(f.input_names(), ["x".to_string(), "u".to_string()]);
    assert_eq!(f.output_index("xdot"), Some(0));
    let plain = Function::new(&[&x], &[&[x[0]]]).unwrap();
    assert_eq!((plain.name(), &plain.input_names()[0][..]), ("f", "i0"));
}

#[test]
fn nested_calls_evaluate_and_differentiate() {
    let f = ode_function();
    // g(x, u) = one RK4 step calling f; then h chains g.
    let x = Matrix::sym_vec("x", 3);
    let u = Matrix::sym_vec("u", 1);
    let call_f = |x: &[Expr], u: &[Expr]| f.apply(&[x, u]).unwrap().remove(0);
    let step = rk4(&call_f, &x, &u, 0.1);
    let g = Function::named("step", &[("x", &x), ("u", &u)], &[("xn", &step)]).unwrap();
    let w = Matrix::sym_vec("w", 5);
    let mut s = w[..3].to_vec();
    for k in 0..2 {
        s = g.apply(&[&s, &[w[3 + k]]]).unwrap().remove(0);
    }
    let obj: Expr = s.iter().map(|e| e.sq()).sum();
    let mut r = w[..3].to_vec();
    for k in 0..2 {
        r = rk4(&ode, &r, &[w[3 + k]], 0.1);
    }
    let obj_ref: Expr = r.iter().map(|e| e.sq()).sum();
    let hc = hessian(obj, &w).unwrap();
    let hr = hessian(obj_ref, &w).unwrap();
    assert_eq!(entries(hc.sparsity()), entries(hr.sparsity()));
    let p = point(5);
    let gc = gradient(obj, &w).unwrap();
    let gr = gradient(obj_ref, &w).unwrap();
    let c = eval(&w, &[&[obj], &gc, hc.values()], &p);
    let i = eval(&w, &[&[obj_ref], &gr, hr.values()], &p);
    for k in 0..3 {
        assert_close("nested", &c[k], &i[k], SAME_MATH);
    }
}

#[test]
fn sparsity_propagates_through_call_nodes() {
    let f = ode_function();
    let w = Matrix::sym_vec("w", 3 + 5);
    let (_, states) = chain(&w, 5, Some(&f));
    let j = jacobian(&states, &w).unwrap();
    let fun = Function::new(&[&w], &[&states]).unwrap();
    assert_eq!(
        entries(&fun.dependency_sparsity(0, 0).unwrap()),
        entries(j.sparsity())
    );
    // A callee output that ignores an input: ẋ₀ = v does not depend on u or p.
    let x = Matrix::sym_vec("x", 3);
    let u = Expr::sym("u");
    let y = f.apply(&[&x, &[u]]).unwrap().remove(0);
    let j = jacobian(&y[..1], &[x[0], x[1], x[2], u]).unwrap();
    assert_eq!(entries(j.sparsity()), vec![(0, 2)]);
}

#[test]
fn branches_inside_and_around_calls_never_leak_nan() {
    // Inside: the callee selects sqrt(x) only for x > 0.
    let x = Expr::sym("x");
    let inner = if_else(gt(x, 0.0), x.sqrt(), -x);
    let f = Function::new(&[&[x]], &[&[inner]]).unwrap();
    let z = Expr::sym("z");
    let y = f.apply(&[&[z]]).unwrap()[0][0];
    // Around: the call's branch (log of a negative number) is not taken.
    let l = Function::new(&[&[x]], &[&[x.ln()]]).unwrap();
    let y2 = if_else(gt(z, 0.0), l.apply(&[&[z]]).unwrap()[0][0], z);
    let e = y + y2;
    let g = gradient(e, &[z]).unwrap();
    let h = hessian(e, &[z]).unwrap();
    let out = eval(&[z], &[&[e], &g, h.values()], &[-4.0]);
    assert_eq!(out, vec![vec![0.0], vec![0.0], vec![0.0]]);
    let out = eval(&[z], &[&[e], &g, h.values()], &[4.0]);
    assert_close("z=4", &out[1], &[0.25 + 0.25], 1e-15);
}

#[test]
fn compiled_functions_with_calls_are_shared_across_threads() {
    let f = ode_function();
    let w = Matrix::sym_vec("w", 3 + 3);
    let (obj, _) = chain(&w, 3, Some(&f));
    let fun = Function::new(&[&w], &[&[obj]]).unwrap();
    let reference = fun.call(&[&point(6)]).unwrap()[0][0];
    let from_threads: Vec<f64> = std::thread::scope(|s| {
        let hs: Vec<_> = (0..3)
            .map(|_| s.spawn(|| fun.call(&[&point(6)]).unwrap()[0][0]))
            .collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert!(from_threads
        .iter()
        .all(|&v| v.to_bits() == reference.to_bits()));
}

#[test]
fn bad_calls_are_errors() {
    let f = ode_function();
    let x = Matrix::sym_vec("x", 3);
    assert!(matches!(
        f.apply(&[&x]),
        Err(SymxError::ArgumentCount {
            expected: 2,
            got: 1,
            ..
        })
    ));
    assert!(matches!(
        f.apply(&[&x[..2], &[x[0]]]),
        Err(SymxError::Length {
            index: 0,
            expected: 3,
            got: 2,
            ..
        })
    ));
    let dup = Function::named("g", &[("a", &x), ("a", &x[..1])], &[]);
    assert!(matches!(
        dup,
        Err(SymxError::DuplicateName { what: "input", .. })
    ));
}

/// An output the caller does not use may have NaN derivatives at the point (`√x` at
/// x < 0); its zero adjoint must not turn them into NaN in a multiplier-weighted gradient
/// (the vector-Jacobian-product path) or in the Hessian built from it.
#[test]
fn unused_outputs_with_nan_derivatives_do_not_leak() {
    let x = Expr::sym("x");
    let f = Function::new(&[&[x]], &[&[x.sqrt(), x.sq() * x]]).unwrap();
    let z = Expr::sym("z");
    let lambda = Expr::sym("lambda");
    let y = f.apply(&[&[z]]).unwrap().remove(0);
    let l = lambda * y[1];
    let g = gradient(l, &[z]).unwrap();
    let h = hessian(l, &[z]).unwrap();
    let fun = Function::new(&[&[z], &[lambda]], &[&g, h.values()]).unwrap();
    let out = fun.call(&[&[-2.0], &[0.5]]).unwrap();
    // ∂(λz³)/∂z = 3λz² = 6, ∂² = 6λz = −6.
    assert_eq!(out, vec![vec![6.0], vec![-6.0]]);
}

/// Call output registers are reused by later calls once no step reads them; outputs of
/// every stage that are also read by the next stage (and copied out at the end) must
/// survive. Compared with the same chain inlined.
#[test]
fn call_output_blocks_are_reused_safely() {
    let x = Matrix::sym_vec("x", 3);
    let u = Matrix::sym_vec("u", 1);
    let step = Function::new(&[&x, &u], &[&rk4(&ode, &x, &u, 0.1)]).unwrap();
    let w = Matrix::sym_vec("w", 3 + 8);
    let (mut s, mut r) = (w[..3].to_vec(), w[..3].to_vec());
    let (mut with_calls, mut inlined) = (Vec::new(), Vec::new());
    for k in 0..8 {
        s = step.apply(&[&s, &[w[3 + k]]]).unwrap().remove(0);
        r = rk4(&ode, &r, &[w[3 + k]], 0.1);
        // Raw call outputs as function outputs, plus arithmetic reading them.
        with_calls.extend_from_slice(&s);
        with_calls.push(s[0] * s[2]);
        inlined.extend_from_slice(&r);
        inlined.push(r[0] * r[2]);
    }
    let fc = Function::new(&[&w], &[&with_calls]).unwrap();
    let p = point(11);
    let c = fc.call(&[&p]).unwrap();
    let i = eval(&w, &[&inlined], &p);
    assert_close("chain outputs", &c[0], &i[0], SAME_MATH);
    // And the gradient, whose tape reuses the blocks of the Jacobian calls.
    let g = gradient(with_calls.iter().copied().sum(), &w).unwrap();
    let fg = Function::new(&[&w], &[&g]).unwrap();
    let gi = gradient(inlined.iter().copied().sum(), &w).unwrap();
    assert_close(
        "gradient",
        &fg.call(&[&p]).unwrap()[0],
        &eval(&w, &[&gi], &p)[0],
        SAME_MATH,
    );
}
