//! Problem::to_function: a solver as a function of its parameters and initial guesses,
//! with the Jacobian from the parametric sensitivities checked against central finite
//! differences of re-solves.
use nlp::ocp::{ButcherTableau, Horizon, Method, Ocp};
use nlp::{Problem, Relation, Sqp, SqpOptions, ToFunctionError};
use symx::Matrix;

/// Central differences of `f` (stacked outputs) in each stacked input entry.
fn finite_differences(
    f: &mut nlp::SolverFunction,
    inputs: &[Vec<f64>],
    step: f64,
) -> Vec<Vec<f64>> {
    let n_in: usize = inputs.iter().map(|v| v.len()).sum();
    let mut columns = Vec::new();
    for j in 0..n_in {
        let shifted = |s: f64| {
            let mut v = inputs.to_vec();
            let (mut k, mut jj) = (0, j);
            while jj >= v[k].len() {
                jj -= v[k].len();
                k += 1;
            }
            v[k][jj] += s;
            v
        };
        let call = |f: &mut nlp::SolverFunction, v: Vec<Vec<f64>>| {
            let refs: Vec<&[f64]> = v.iter().map(|v| v.as_slice()).collect();
            f.call(&refs).unwrap()
        };
        let (plus, minus) = (call(f, shifted(step)), call(f, shifted(-step)));
        columns.push(
            plus.iter()
                .zip(&minus)
                .map(|(a, b)| (a - b) / (2.0 * step))
                .collect::<Vec<f64>>(),
        );
    }
    // rows = outputs
    (0..columns[0].len())
        .map(|i| columns.iter().map(|c| c[i]).collect())
        .collect()
}

/// The hanging chain of docs/casadi.md: N links of length `L/N` between end heights a, b,
/// min potential energy; outputs the heights and the energy.
fn chain(n: usize) -> (Problem, Vec<symx::Expr>, Vec<symx::Expr>) {
    let mut pb = Problem::new();
    let x = pb.variable("x", n + 1).unwrap();
    let y = pb.variable("y", n + 1).unwrap();
    let p = pb.parameter("p", 3).unwrap(); // length, left and right end heights
    pb.set_value(&p, &[2.0, 1.0, 0.5]).unwrap();
    pb.minimize((0..=n).map(|i| y[i]).sum());
    pb.subject_to(x[0].eq(0.0)).unwrap();
    pb.subject_to(x[n].eq(1.0)).unwrap();
    pb.subject_to(y[0].eq(p[1])).unwrap();
    pb.subject_to(y[n].eq(p[2])).unwrap();
    for i in 0..n {
        let link = (x[i + 1] - x[i]).sq() + (y[i + 1] - y[i]).sq();
        pb.subject_to(link.eq((p[0] / n as f64).sq())).unwrap();
    }
    let guess: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
    pb.set_initial(&x, &guess).unwrap();
    let sag: Vec<f64> = guess
        .iter()
        .map(|t| 1.0 - 0.5 * t - t * (1.0 - t))
        .collect();
    pb.set_initial(&y, &sag).unwrap();
    (pb, p.to_vec(), y.to_vec())
}

#[test]
fn jacobian_matches_finite_differences_on_a_chain() {
    let (pb, p, y) = chain(10);
    let energy: symx::Expr = y.iter().copied().sum();
    let mut f = pb.to_function(&[&p], &[&y[3..6], &[energy]]).unwrap();
    assert_eq!(f.input_sizes(), [3]);
    assert_eq!(f.output_sizes(), [3, 1]);
    let inputs = vec![vec![2.0, 1.0, 0.5]];
    let (out, jac) = f.jacobian(&[&inputs[0]]).unwrap();
    assert_eq!(
        out,
        f.call(&[&inputs[0]]).unwrap(),
        "same inputs, same outputs"
    );
    // Step 1e-5: truncation O(h²·y''') ≈ 1e-10, rounding of the re-solves (tol 1e-8
    // converged far below: ~1e-12 / 1e-5 = 1e-7) dominates; agreement to 1e-6 relative.
    let fd = finite_differences(&mut f, &inputs, 1e-5);
    for (i, (a, b)) in jac.iter().zip(&fd).enumerate() {
        for (j, (a, b)) in a.iter().zip(b).enumerate() {
            assert!(
                (a - b).abs() <= 1e-6 * (1.0 + b.abs()),
                "d out[{i}] / d in[{j}]: sensitivity {a}, differences {b}"
            );
        }
    }
    // Energy is linear in the heights' sum: d/d(left end) is not 0 (the chain moves).
    assert!(jac[3][1].abs() > 0.1);
}

#[test]
fn parameters_and_guesses_as_inputs_with_an_active_bound() {
    // min (x − a)² + (z − 1)² s.t. x ≤ b, z free: x* = min(a, b).
    let mut pb = Problem::new();
    let x = pb.scalar_variable("x").unwrap();
    let z = pb.scalar_variable("z").unwrap();
    let (a, b) = (
        pb.scalar_parameter("a").unwrap(),
        pb.scalar_parameter("b").unwrap(),
    );
    pb.set_value(a, &[0.0]).unwrap();
    pb.set_value(b, &[1.0]).unwrap();
    pb.minimize((x - a).sq() + (z - 1.0).sq());
    pb.subject_to(x.le(b)).unwrap();
    let mut f = pb
        .to_function(&[&[a, b], &[x, z]], &[&[x * b]])
        .unwrap()
        .with_solver(Box::new(Sqp::new(SqpOptions::default())));
    let inputs = vec![vec![0.5, 2.0], vec![7.0, -3.0]];
    let refs: Vec<&[f64]> = inputs.iter().map(|v| v.as_slice()).collect();
    let (y, jac) = f.jacobian(&refs).unwrap();
    // Inactive bound: x* = a, y = a·b, dy/d(a, b) = (b, a); guesses do not move x*.
    assert!((y[0] - 1.0).abs() < 1e-8);
    let fd = finite_differences(&mut f, &inputs, 1e-6);
    assert_eq!(jac[0][2..], [0.0, 0.0]);
    for j in 0..2 {
        assert!((jac[0][j] - fd[0][j]).abs() < 1e-6, "{jac:?} vs {fd:?}");
    }
    assert!((jac[0][0] - 2.0).abs() < 1e-8 && (jac[0][1] - 0.5).abs() < 1e-8);
    // Active bound (a = 3 > b = 2): x* = b, y = b², dy/d(a, b) = (0, 2b).
    let (_, jac) = f.jacobian(&[&[3.0, 2.0], &[0.0, 0.0]]).unwrap();
    assert!(
        jac[0][0].abs() < 1e-8 && (jac[0][1] - 4.0).abs() < 1e-7,
        "{jac:?}"
    );
}

#[test]
fn an_ocp_as_a_function_of_its_initial_state() {
    let mut ocp = Ocp::new(&["x"], &["u"]);
    ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![-x[0] + u[0]]));
    ocp.set_stage_cost(|x, u, _p| x[0].sq() + u[0].sq());
    ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
    ocp.set_control_bounds(&[-0.3], &[0.3]).unwrap();
    ocp.set_initial_state_parameter("x0", &[1.0]).unwrap();
    let tr = ocp
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 2), 10)
        .unwrap();
    let pb = tr.problem();
    let x0 = pb.parameters().to_vec();
    // The first control (an MPC feedback law u0(x0)) and the optimal cost.
    let mut f = pb
        .to_function(&[&x0], &[&[tr.controls()[0]], &[pb.objective()]])
        .unwrap();
    // No bound active at 0.2 and 0.5; the first controls on their bound at 2 and 3. (Near
    // x0 = 1 a later control reaches its bound: the active set changes there and the
    // sensitivity, which holds the active set fixed, does not apply.)
    for state in [0.2, 0.5, 2.0, 3.0] {
        let inputs = vec![vec![state]];
        let (_, jac) = f.jacobian(&[&inputs[0]]).unwrap();
        let fd = finite_differences(&mut f, &inputs, 1e-6);
        for i in 0..2 {
            assert!(
                (jac[i][0] - fd[i][0]).abs() <= 1e-6 * (1.0 + fd[i][0].abs()),
                "x0 = {state}: {jac:?} vs {fd:?}"
            );
        }
    }
}

#[test]
fn mistakes_are_errors() {
    let (pb, p, y) = chain(4);
    // An input mixing a parameter and a variable.
    let err = pb.to_function(&[&[p[0], y[0]]], &[&y]).err().unwrap();
    assert!(err.to_string().contains("to_function input 0"), "{err}");
    // An output with a foreign symbol.
    let err = pb
        .to_function(&[&p], &[&[symx::Expr::sym("w")]])
        .err()
        .unwrap();
    assert!(err.to_string().contains("'w'"), "{err}");
    let mut f = pb.to_function(&[&p], &[&y]).unwrap();
    let err = f.call(&[&[1.0, 2.0]]).unwrap_err();
    assert!(err.to_string().contains("input 0"), "{err}");
    let err = f.call(&[]).unwrap_err();
    assert!(err.to_string().contains("number of inputs"), "{err}");
    // An infeasible chain (too short to span the ends): the status, no value.
    let err = f.call(&[&[0.5, 1.0, 0.5]]).unwrap_err();
    assert!(matches!(err, ToFunctionError::NotSolved { .. }), "{err}");
}

/// Inner QP with an affine solution map: min (y1 − a)² + (y2 − 2a)² s.t. y1 + y2 = b has
/// y1* = (b − a)/2, y2* = (b + a)/2 (Lagrange: y1 − a = y2 − 2a, y1 + y2 = b). As an
/// external call node with inputs (a, b) and outputs (y1, y2).
fn affine_inner_node() -> symx::Function {
    let mut pb = Problem::new();
    let y = pb.variable("y", 2).unwrap();
    let a = pb.scalar_parameter("a").unwrap();
    let b = pb.scalar_parameter("b").unwrap();
    pb.set_value(a, &[0.0]).unwrap();
    pb.set_value(b, &[0.0]).unwrap();
    pb.minimize((y[0] - a).sq() + (y[1] - a * 2.0).sq());
    pb.subject_to((y[0] + y[1]).eq(b)).unwrap();
    pb.to_function(&[&[a, b]], &[&[y[0], y[1]]])
        .unwrap()
        .into_external("inner_qp")
        .unwrap()
}

/// Outer: min_{a,b} (y1* − 1)² + (y2* − 2)² + 0.1(a² + b²), optionally with y1* ≥ 1.
/// With u = y1* = (b − a)/2, v = y2* = (b + a)/2: a² + b² = 2(u² + v²), so the objective
/// is (u − 1)² + (v − 2)² + 0.2(u² + v²): u = 1/1.2, v = 2/1.2 (a = v − u = 1/1.2,
/// b = u + v = 2.5); with u ≥ 1 active, u = 1, v = 2/1.2 (a = 2/3, b = 8/3).
fn bilevel(with_constraint: bool, options: nlp::IpmOptions) -> nlp::Solution {
    let node = affine_inner_node();
    let mut outer = Problem::new();
    let ab = outer.variable("ab", 2).unwrap();
    outer.set_initial(&ab, &[0.3, 0.7]).unwrap();
    let y = &node.apply(&[&[ab[0], ab[1]]]).unwrap()[0];
    outer.minimize((y[0] - 1.0).sq() + (y[1] - 2.0).sq() + (ab[0].sq() + ab[1].sq()) * 0.1);
    if with_constraint {
        outer.subject_to(y[0].ge(1.0)).unwrap();
    }
    let sol = nlp::Ipm::new(options)
        .solve(&mut outer.compile().unwrap())
        .unwrap();
    assert!(sol.status.is_success(), "{}", sol.message);
    sol
}

#[test]
fn a_solver_node_inside_an_outer_problem_matches_the_closed_form() {
    let exact = nlp::IpmOptions::default();
    let quasi_newton = nlp::IpmOptions {
        hessian_approximation: nlp::IpmHessian::LimitedMemory,
        ..Default::default()
    };
    // Tolerances: the outer IPM stops at tol 1e-8 on a strongly convex problem, and the
    // inner solves are accurate to about 1e-9; 1e-6 leaves margin for both.
    for options in [exact, quasi_newton] {
        let sol = bilevel(false, options.clone());
        assert!((sol.x[0] - 1.0 / 1.2).abs() < 1e-6, "{:?}", sol.x);
        assert!((sol.x[1] - 2.5).abs() < 1e-6, "{:?}", sol.x);
        let sol = bilevel(true, options);
        assert!((sol.x[0] - 2.0 / 3.0).abs() < 1e-6, "{:?}", sol.x);
        assert!((sol.x[1] - 8.0 / 3.0).abs() < 1e-6, "{:?}", sol.x);
    }
}

#[test]
fn a_solver_node_differentiates_like_finite_differences() {
    // The chain's energy and a middle height as functions of (length, end heights),
    // through the node: its Jacobian (sensitivities) against central differences of its
    // values, and its second derivatives (differences of sensitivities) against central
    // differences of the Jacobian.
    let (pb, p, y) = chain(10);
    let energy: symx::Expr = y.iter().copied().sum();
    let node = pb
        .to_function(&[&p], &[&[y[5], energy]])
        .unwrap()
        .into_external("chain")
        .unwrap();
    let q = Matrix::sym_vec("q", 3);
    let out = &node.apply(&[q.entries()]).unwrap()[0];
    let value = symx::Function::new(&[&q], &[&[out[0] + out[1] * 0.5]]).unwrap();
    let grad = symx::gradient(out[0] + out[1] * 0.5, &q).unwrap();
    let gradient = symx::Function::new(&[&q], &[&grad]).unwrap();
    let at = [2.0, 1.0, 0.5];
    let g = gradient.call(&[&at]).unwrap().swap_remove(0);
    let h = 1e-5; // as in jacobian_matches_finite_differences_on_a_chain
    for j in 0..3 {
        let mut plus = at;
        plus[j] += h;
        let mut minus = at;
        minus[j] -= h;
        let fd = (value.call(&[&plus]).unwrap()[0][0] - value.call(&[&minus]).unwrap()[0][0])
            / (2.0 * h);
        assert!(
            (g[j] - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
            "{j}: {} vs {fd}",
            g[j]
        );
    }
    // Hessian of the node's output (central differences of sensitivities, step 1e-4)
    // against central differences of the gradient with step 1e-3: both err by O(h²) and
    // by the sensitivities' accuracy over h; 1e-4 relative covers both.
    let hess = symx::hessian(out[0] + out[1] * 0.5, &q).unwrap().to_dense();
    let hessian = symx::Function::new(&[&q], &[&hess]).unwrap();
    let hv = hessian.call(&[&at]).unwrap().swap_remove(0);
    let h = 1e-3;
    for j in 0..3 {
        let mut plus = at;
        plus[j] += h;
        let mut minus = at;
        minus[j] -= h;
        let (gp, gm) = (
            gradient.call(&[&plus]).unwrap().swap_remove(0),
            gradient.call(&[&minus]).unwrap().swap_remove(0),
        );
        for i in j..3 {
            // symx::hessian stores the lower triangle (i ≥ j).
            let fd = (gp[i] - gm[i]) / (2.0 * h);
            let a = hv[i + 3 * j];
            assert!(
                (a - fd).abs() <= 1e-4 * (1.0 + fd.abs()),
                "({i},{j}): {a} vs {fd}"
            );
        }
    }
}

#[test]
fn a_solver_node_is_nan_where_the_solve_fails_and_safe_across_threads() {
    let (pb, p, y) = chain(4);
    let node = pb
        .to_function(&[&p], &[&y])
        .unwrap()
        .into_external("chain")
        .unwrap();
    // Too short to span the ends: the solve fails, the outputs are NaN.
    let bad = node.call(&[&[0.5, 1.0, 0.5]]).unwrap().swap_remove(0);
    assert!(bad.iter().all(|v| v.is_nan()), "{bad:?}");
    // Concurrent callers get the serial values, bit for bit.
    let inputs = [
        [2.0, 1.0, 0.5],
        [2.5, 0.8, 0.4],
        [1.8, 1.1, 0.9],
        [3.0, 0.0, 0.0],
    ];
    let serial: Vec<Vec<f64>> = inputs
        .iter()
        .map(|i| node.call(&[i]).unwrap().swap_remove(0))
        .collect();
    let parallel: Vec<Vec<f64>> = std::thread::scope(|s| {
        let handles: Vec<_> = inputs
            .iter()
            .map(|i| s.spawn(|| node.call(&[i]).unwrap().swap_remove(0)))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(serial, parallel);
    // Third derivatives do not exist: a clear error naming the function.
    let q = Matrix::sym_vec("q", 3);
    let y4 = node.apply(&[q.entries()]).unwrap()[0][1];
    let h = symx::hessian(y4, &q).unwrap();
    let err = symx::jacobian(h.values(), &q).unwrap_err();
    assert!(err.to_string().contains("jac_jac_chain"), "{err}");
}
