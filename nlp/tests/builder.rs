//! The Opti-like builder: reading values at a solution, setting parameters (by handle or
//! name, on a `Problem` or a `Compiled`), unique names, cloning a `Compiled`, per-entry
//! bounds and simple bound detection.
//!
//! Expected values are computed here by hand or with plain f64 arithmetic on the solution
//! vector, independent of symx's evaluator. Solver tolerances: the IPM stops at a scaled
//! KKT error of 1e-8 (the default `tol`), so on these small, well-scaled problems optima
//! are compared to 1e-6.
use nlp::{
    bounded, BuildError, Compiled, Ipm, NumericNlp, Problem, Relation, Solution, SolveError,
    Solver, Sqp, Status,
};
use symx::{Expr, Matrix};

const INF: f64 = f64::INFINITY;

fn solve(c: &mut Compiled) -> Solution {
    let sol = Ipm::default().solve(c).expect("valid problem");
    assert_eq!(sol.status, Status::SolveSucceeded);
    sol
}

fn bounds_of(c: &Compiled) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let (n, m) = (c.n(), c.m());
    let (mut xl, mut xu, mut gl, mut gu) = (vec![0.0; n], vec![0.0; n], vec![0.0; m], vec![0.0; m]);
    c.bounds(&mut xl, &mut xu, &mut gl, &mut gu);
    (xl, xu, gl, gu)
}

/// min (x₀ − p₀)² + (x₁ − p₁)² s.t. x₀ + x₁ = 1: x* = p + (1 − p₀ − p₁)/2 · (1, 1).
fn projection() -> (Problem, Matrix, Matrix) {
    let mut pb = Problem::new();
    let x = pb.variable("x", 2).unwrap();
    let p = pb.parameter("p", 2).unwrap();
    pb.set_value(&p, &[0.2, 0.4]).unwrap();
    pb.minimize((x[0] - p[0]).sq() + (x[1] - p[1]).sq());
    pb.subject_to_named("sum", (x[0] + x[1]).eq(1.0)).unwrap();
    (pb, x, p)
}

fn projection_optimum(p: [f64; 2]) -> [f64; 2] {
    let shift = (1.0 - p[0] - p[1]) / 2.0;
    [p[0] + shift, p[1] + shift]
}

// ---- value ----

#[test]
fn value_reads_expressions_at_a_solution() {
    let (pb, x, p) = projection();
    let sol = solve(&mut pb.compile().unwrap());
    let [a, b] = projection_optimum([0.2, 0.4]);
    assert!((sol.x[0] - a).abs() < 1e-6 && (sol.x[1] - b).abs() < 1e-6);
    // A variable reads back exactly its entry of x.
    assert_eq!(pb.value(x[1], &sol).unwrap(), sol.x[1]);
    // An expression of variables and parameters: same arithmetic on sol.x by hand.
    let e = x[0] * x[1] + (3.0 * p[1]).sin() - x[0] / p[0];
    let want = sol.x[0] * sol.x[1] + (3.0 * 0.4f64).sin() - sol.x[0] / 0.2;
    assert!((pb.value(e, &sol).unwrap() - want).abs() <= 1e-14 * want.abs().max(1.0));
    assert_eq!(pb.values(&x, &sol).unwrap(), sol.x);
}

#[test]
fn value_matrix_is_indexed_row_then_column() {
    let (pb, x, p) = projection();
    let sol = solve(&mut pb.compile().unwrap());
    // A 2×3 matrix with distinct entries, so a transposition would show.
    let m = Matrix::from_fn(2, 3, |i, j| {
        (i as f64 + 1.0) * x[0] + (j as f64) * x[1] + p[0]
    });
    let v = pb.value_matrix(&m, &sol).unwrap();
    assert_eq!((v.len(), v[0].len()), (2, 3));
    for (i, row) in v.iter().enumerate() {
        for (j, &got) in row.iter().enumerate() {
            let want = (i as f64 + 1.0) * sol.x[0] + j as f64 * sol.x[1] + 0.2;
            assert!(
                (got - want).abs() <= 1e-15 * want.abs().max(1.0),
                "({i}, {j})"
            );
        }
    }
}

#[test]
fn value_rejects_symbols_of_other_problems_and_wrong_solutions() {
    let (pb, x, _) = projection();
    let sol = solve(&mut pb.compile().unwrap());
    let stranger = Expr::sym("y");
    let err = pb.value(x[0] + stranger, &sol).unwrap_err();
    assert_eq!(
        err,
        BuildError::FreeSymbol {
            location: "value".into(),
            name: "y".into()
        }
    );
    assert!(err.to_string().contains("'y'"), "{err}");
    let mut short = sol.clone();
    short.x.pop();
    assert!(matches!(
        pb.value(x[0], &short),
        Err(BuildError::Size {
            expected: 2,
            got: 1,
            ..
        })
    ));
}

/// A symbol that is neither a variable nor a parameter is named with where it is
/// used: in the objective, or in which constraint (the bulk compilation does not say).
#[test]
fn compile_names_the_expression_with_a_free_symbol() {
    let (mut pb, x, _) = projection();
    let stranger = Expr::sym("q");
    pb.subject_to_named("tilt", (x[0] - stranger).le(2.0))
        .unwrap();
    assert_eq!(
        pb.compile().unwrap_err(),
        BuildError::FreeSymbol {
            location: "constraint 'tilt'".into(),
            name: "q".into()
        }
    );
    let (mut pb, x, _) = projection();
    pb.minimize(x[0] * Expr::sym("r"));
    pb.subject_to_named("tilt", (x[0] - Expr::sym("q")).le(2.0))
        .unwrap();
    let err = pb.compile().unwrap_err();
    assert_eq!(
        err,
        BuildError::FreeSymbol {
            location: "the objective".into(),
            name: "r".into()
        },
        "the objective is checked first"
    );
    assert!(err.to_string().contains("'r'"), "{err}");
}

// ---- parameters ----

#[test]
fn parameters_are_set_the_same_way_on_problem_and_compiled() {
    let (mut pb, x, p) = projection();
    // On the problem: a whole block by handle, one entry by handle, a block by name.
    pb.set_value(&p, &[1.0, 2.0]).unwrap();
    pb.set_value(p[0], &[3.0]).unwrap();
    assert_eq!(pb.compile().unwrap().parameter_values(), &[3.0, 2.0]);
    pb.set_value("p", &[-1.0, 0.5]).unwrap();
    let mut c = pb.compile().unwrap();
    assert_eq!(c.parameter_values(), &[-1.0, 0.5]);
    let sol = solve(&mut c);
    let want = projection_optimum([-1.0, 0.5]);
    assert!((sol.x[0] - want[0]).abs() < 1e-6 && (sol.x[1] - want[1]).abs() < 1e-6);
    // On the compiled problem, without recompiling: same calls.
    c.set_value(&[p[1], p[0]], &[0.25, 0.75]).unwrap();
    assert_eq!(c.parameter_values(), &[0.75, 0.25]);
    c.set_value("p", &[0.0, 3.0]).unwrap();
    let sol = solve(&mut c);
    let want = projection_optimum([0.0, 3.0]);
    assert!((sol.x[0] - want[0]).abs() < 1e-6 && (sol.x[1] - want[1]).abs() < 1e-6);
    // value() reads with the problem's parameters: set them there too.
    pb.set_value("p", &[0.0, 3.0]).unwrap();
    let d = pb.value(x[1] - p[1], &sol).unwrap();
    assert!((d - (want[1] - 3.0)).abs() < 1e-6);
}

#[test]
fn parameter_errors_name_the_culprit() {
    let (mut pb, x, p) = projection();
    let mut c = pb.compile().unwrap();
    for result in [pb.set_value("q", &[1.0]), c.set_value("q", &[1.0])] {
        let err = result.unwrap_err();
        assert_eq!(
            err,
            BuildError::UnknownName {
                kind: "parameter",
                name: "q".into()
            }
        );
        assert_eq!(err.to_string(), "no parameter is named 'q'");
    }
    for result in [pb.set_value(x[0], &[1.0]), c.set_value(x[0], &[1.0])] {
        let err = result.unwrap_err();
        assert!(
            matches!(
                err,
                BuildError::NotDeclared {
                    kind: "parameter",
                    ..
                }
            ),
            "{err}"
        );
        assert!(err.to_string().contains("x[0]"), "{err}");
    }
    for result in [pb.set_value(&p, &[1.0]), c.set_value("p", &[1.0, 2.0, 3.0])] {
        assert!(matches!(result, Err(BuildError::Size { expected: 2, .. })));
    }
    let err = c.set_value(&p, &[1.0, f64::NAN]).unwrap_err();
    assert!(err.to_string().contains("'p[1]'"), "{err}");
    // Nothing was written by the failed calls.
    assert_eq!(c.parameter_values(), &[0.2, 0.4]);
}

/// Compiling needs no parameter values (as Opti); a solve with one unset fails naming it,
/// by either back end and through `to_function`; setting it after compiling solves.
#[test]
fn parameters_unset_at_compile_fail_at_solve_naming_the_entry() {
    let mut unset = Problem::new();
    let y = unset.scalar_variable("y").unwrap();
    let q = unset.parameter("q", 2).unwrap();
    unset.minimize((y - q[0] - q[1]).sq());
    unset.set_value(q[1], &[1.0]).unwrap();
    let mut c = unset.compile().expect("compiles without q[0]");
    assert_eq!(c.unset_parameter(), Some("q[0]"));
    assert!(c.parameter_values()[0].is_nan());
    let missing = SolveError::MissingParameterValue {
        name: "q[0]".into(),
    };
    for solver in [&Ipm::default() as &dyn Solver, &Sqp::default()] {
        assert_eq!(
            solver.solve(&mut c).unwrap_err(),
            missing,
            "{}",
            solver.name()
        );
    }
    assert!(missing.to_string().contains("'q[0]'"), "{missing}");
    // The problem still has no value for q[0]: reading an expression without a solution's
    // parameters is refused, naming it.
    assert_eq!(
        unset.evaluate(&[y - q[0]], &[0.0]).unwrap_err(),
        BuildError::MissingParameterValue {
            name: "q[0]".into()
        }
    );
    // A solver as a function of q[1] only still needs q[0].
    let mut f = unset.to_function(&[&[q[1]]], &[&[y]]).unwrap();
    let err = f.call(&[&[2.0]]).unwrap_err();
    assert!(err.to_string().contains("'q[0]'"), "{err}");
    // Set after compiling: y* = q0 + q1 = 0.5 + 1 (exact optimum of the square).
    c.set_value(q[0], &[0.5]).unwrap();
    assert_eq!(c.unset_parameter(), None);
    let sol = solve(&mut c);
    assert!((sol.x[0] - 1.5).abs() < 1e-6);
    assert_eq!(sol.parameters, [0.5, 1.0]);
    // Setting only a subset on the problem, then the rest on the compiled one by name.
    let mut c2 = unset.compile().unwrap();
    c2.set_value("q", &[2.0, 3.0]).unwrap();
    assert!((solve(&mut c2).x[0] - 5.0).abs() < 1e-6);
}

#[test]
fn handles_only_on_the_building_thread_names_everywhere() {
    let (pb, _, _) = projection();
    let c = pb.compile().unwrap();
    let sol = std::thread::spawn(move || {
        let mut c = c;
        // A handle of this thread's graph is refused (it could alias another symbol).
        let foreign = Expr::sym("p");
        assert!(matches!(
            c.set_value(foreign, &[1.0]),
            Err(BuildError::ForeignThread { .. })
        ));
        c.set_value("p", &[1.0, 1.0]).unwrap();
        solve(&mut c)
    })
    .join()
    .unwrap();
    let want = projection_optimum([1.0, 1.0]);
    assert!((sol.x[0] - want[0]).abs() < 1e-6 && (sol.x[1] - want[1]).abs() < 1e-6);
}

// ---- names ----

#[test]
fn duplicate_names_are_rejected() {
    let mut pb = Problem::new();
    pb.variable("x", 2).unwrap();
    let dup = |name: &str| BuildError::DuplicateName { name: name.into() };
    assert_eq!(pb.variable("x", 3).unwrap_err(), dup("x"));
    assert_eq!(pb.scalar_variable("x").unwrap_err(), dup("x"));
    assert_eq!(pb.variable_matrix("x", 1, 1).unwrap_err(), dup("x"));
    assert_eq!(pb.parameter("x", 1).unwrap_err(), dup("x"));
    pb.scalar_parameter("p").unwrap();
    assert_eq!(pb.scalar_variable("p").unwrap_err(), dup("p"));
    assert!(pb.variable("x", 3).unwrap_err().to_string().contains("'x'"));
    // The rejected declarations left nothing behind.
    assert_eq!(pb.n_variables(), 2);
    assert_eq!(pb.parameters().len(), 1);
}

// ---- Compiled: Clone + Debug ----

#[test]
fn a_clone_solves_independently() {
    let (pb, _, _) = projection();
    let mut original = pb.compile().unwrap();
    let mut clone = original.clone();
    clone.set_value("p", &[2.0, -1.0]).unwrap();
    clone.set_initial_point(&[5.0, 5.0]).unwrap();
    let handle = std::thread::spawn(move || solve(&mut clone));
    let from_original = solve(&mut original);
    let from_clone = handle.join().unwrap();
    // The original kept its parameters and start: same iterates as a fresh compile.
    let fresh = solve(&mut pb.compile().unwrap());
    assert_eq!(from_original.x, fresh.x);
    assert_eq!(from_original.stats.iterations, fresh.stats.iterations);
    let want = projection_optimum([2.0, -1.0]);
    assert!((from_clone.x[0] - want[0]).abs() < 1e-6);
    assert!((from_clone.x[1] - want[1]).abs() < 1e-6);
    let shown = format!("{original:?}");
    for part in ["n: 2", "m: 1", "\"x\"", "\"p\"", "\"sum\"", "[0.2, 0.4]"] {
        assert!(shown.contains(part), "{part} not in {shown}");
    }
}

// ---- per-entry bounds ----

#[test]
fn per_entry_bounds() {
    let mut pb = Problem::new();
    let x = pb.variable("x", 3).unwrap();
    pb.minimize(x.sumsqr());
    pb.set_bounds(&x, &[0.0, -1.0, -INF], 4.0).unwrap();
    pb.set_bounds(&x[1..], -2.0, &[3.0, 5.0]).unwrap();
    let (xl, xu, _, _) = bounds_of(&pb.compile().unwrap());
    assert_eq!((xl, xu), (vec![0.0, -2.0, -2.0], vec![4.0, 3.0, 5.0]));

    let err = pb.set_bounds(&x, &[0.0, 1.0], 4.0).unwrap_err();
    assert_eq!(
        err,
        BuildError::Size {
            what: "set_bounds: lower bounds".into(),
            expected: 3,
            got: 2
        }
    );
    let err = pb.set_bounds(&x, 0.0, &vec![1.0; 4]).unwrap_err();
    assert!(err.to_string().contains("upper bounds"), "{err}");
    let err = pb
        .set_bounds(&x, &[0.0, 2.0, 0.0], &[1.0, 1.0, 1.0])
        .unwrap_err();
    assert!(err.to_string().contains("'x[1]'"), "{err}");
    // A failed call changes no bound.
    let (xl, xu, _, _) = bounds_of(&pb.compile().unwrap());
    assert_eq!((xl, xu), (vec![0.0, -2.0, -2.0], vec![4.0, 3.0, 5.0]));
}

// ---- simple bound detection ----

/// min x₀ + x₁ s.t. x₀ − 0 ≥ 1 (simplifies to x₀ ≥ 1), 0 ≤ x₁ ≤ 2 (one group), x₀² + x₁² ≤ 9,
/// and the cone ‖(x₀, x₁)‖ ≤ 3 written after them: f* = 1 at (1, 0).
fn with_single_variable_rows(detect: bool) -> (Problem, Matrix) {
    let mut pb = Problem::new();
    pb.set_detect_simple_bounds(detect);
    let x = pb.variable("x", 2).unwrap();
    pb.set_initial(&x, &[2.0, 1.0]).unwrap();
    pb.minimize(x[0] + x[1]);
    pb.subject_to_named("x0 low", (x[0] - 0.0).ge(1.0)).unwrap();
    pb.subject_to_named("x1 box", bounded(0.0, x[1], 2.0))
        .unwrap();
    pb.subject_to_named("disc", (x[0].sq() + x[1].sq()).le(9.0))
        .unwrap();
    pb.subject_to_cone("cone", &[x[0], x[1]], Expr::from(3.0))
        .unwrap();
    (pb, x)
}

#[test]
fn detection_is_on_by_default() {
    // The default chosen by measurement (docs/problem.md).
    const { assert!(nlp::problem::DETECT_SIMPLE_BOUNDS) };
    assert!(Problem::new().detect_simple_bounds());
}

#[test]
fn without_detection_single_variable_rows_stay_rows() {
    let (pb, _) = with_single_variable_rows(false);
    let mut c = pb.compile().unwrap();
    let (xl, xu, gl, gu) = bounds_of(&c);
    assert_eq!((xl, xu), (vec![-INF; 2], vec![INF; 2]));
    assert_eq!(c.m(), 4);
    assert_eq!(pb.n_constraints(), 4);
    assert_eq!((gl[0], gu[0]), (1.0, INF));
    assert_eq!((gl[1], gu[1]), (0.0, 2.0));
    let names: Vec<String> = (0..4).map(|i| c.constraint_name(i)).collect();
    assert_eq!(names, ["x0 low", "x1 box", "disc", "cone"]);
    assert_eq!(c.affine_cones()[0].row, 3);
    let sol = solve(&mut c);
    assert!((sol.objective - 1.0).abs() < 1e-6, "{}", sol.objective);
}

#[test]
fn detected_rows_become_bounds() {
    let (mut pb, x) = with_single_variable_rows(true);
    // A bound set after the row intersects with it (detection happens at compile).
    pb.set_bounds(&x, -5.0, &[1.5, 1.5]).unwrap();
    let mut c = pb.compile().unwrap();
    let (xl, xu, gl, gu) = bounds_of(&c);
    assert_eq!((xl, xu), (vec![1.0, 0.0], vec![1.5, 1.5]));
    assert_eq!((c.m(), pb.n_constraints()), (2, 2));
    assert_eq!(
        (gl, gu),
        (vec![-INF; 2], vec![9.0, nlp::problem::CONE_SMOOTHING])
    );
    let names: Vec<String> = (0..2).map(|i| c.constraint_name(i)).collect();
    assert_eq!(names, ["disc", "cone"]);
    assert_eq!(c.constraint_blocks()[1].start, 1);
    assert_eq!(c.affine_cones()[0].row, 1);
    assert_eq!(pb.constraint_expressions().len(), 2);
    let sol = solve(&mut c);
    assert!((sol.objective - 1.0).abs() < 1e-6, "{}", sol.objective);

    // An empty intersection names the variable and the constraint.
    pb.set_bounds(&x[..1], -5.0, 0.5).unwrap();
    let err = pb.compile().unwrap_err();
    assert!(
        matches!(err, BuildError::InvertedBounds { lower, upper, .. } if lower == 1.0 && upper == 0.5)
    );
    let text = err.to_string();
    assert!(
        text.contains("'x[0]'") && text.contains("'x0 low'"),
        "{text}"
    );
}

#[test]
fn affine_single_variable_rows_become_bounds() {
    // As CasADi's detect_simple_bounds: a row a·xⱼ + b with constant a ≠ 0, b is the bound
    // (lo − b)/a ≤ xⱼ ≤ (hi − b)/a (sides swapped when a < 0). Values worked by hand.
    let mut pb = Problem::new();
    let x = pb.variable("x", 4).unwrap();
    let p = pb.parameter("p", 1).unwrap();
    pb.set_value(&p, &[1.0]).unwrap();
    pb.minimize(x[0].sq() + x[1].sq() + x[2].sq() + x[3].sq());
    pb.subject_to_named("shifted", (x[0] - 1.0).eq(0.0))
        .unwrap(); // x₀ = 1
    pb.subject_to_named("scaled", bounded(1.0, 2.0 * x[1] - 1.0, 3.0))
        .unwrap(); // 1 ≤ x₁ ≤ 2
    pb.subject_to_named("flipped", (3.0 - x[2] / 2.0).le(1.0))
        .unwrap(); // x₂ ≥ 4
    pb.subject_to_named("cancelled", (x[3] + x[0] - x[0]).ge(0.0))
        .unwrap(); // a row: two variables written (no symbolic cancellation is assumed)
    pb.subject_to_named("parametric", (x[3] - p[0]).ge(0.0))
        .unwrap(); // a row: involves a parameter
    pb.subject_to_named("nonlinear", x[3].sq().le(4.0)).unwrap(); // a row
    let c = pb.compile().unwrap();
    let (xl, xu, _, _) = bounds_of(&c);
    assert_eq!(xl[..3], [1.0, 1.0, 4.0]);
    assert_eq!(xu[..3], [1.0, 2.0, INF]);
    let names: Vec<String> = (0..c.m()).map(|i| c.constraint_name(i)).collect();
    assert_eq!(names, ["cancelled", "parametric", "nonlinear"]);
    // With detection off every row stays a row.
    pb.set_detect_simple_bounds(false);
    assert_eq!(pb.compile().unwrap().m(), 6);
}

#[test]
fn both_settings_reach_the_same_optimum() {
    // Rosenbrock with x₀ ≤ 0.5 written as a row: f* = 0.25 at (0.5, 0.25) (the constrained
    // minimiser of (1 − x₀)² + 100(x₁ − x₀²)² is on x₀ = 0.5 with x₁ = x₀²).
    let mut objectives = Vec::new();
    for detect in [false, true] {
        let mut pb = Problem::new();
        pb.set_detect_simple_bounds(detect);
        let x = pb.variable("x", 2).unwrap();
        pb.set_initial(&x, &[-1.2, 1.0]).unwrap();
        pb.minimize((1.0 - x[0]).sq() + 100.0 * (x[1] - x[0].sq()).sq());
        pb.subject_to(x[0].le(0.5)).unwrap();
        let mut c = pb.compile().unwrap();
        assert_eq!(c.m(), usize::from(!detect));
        let sol = solve(&mut c);
        assert!((sol.x[0] - 0.5).abs() < 1e-6 && (sol.x[1] - 0.25).abs() < 1e-6);
        objectives.push(sol.objective);
    }
    assert!((objectives[0] - 0.25).abs() < 1e-6 && (objectives[1] - 0.25).abs() < 1e-6);
}
