//! Saving and loading problems (nlp::problem::file): a loaded problem — in a fresh
//! expression graph, or from a file checked in (`tests/fixtures/problem_v1.json`, written
//! by an earlier build so that a change of the format is caught) — evaluates its objective
//! and constraints bit-identically and solves to the same optimum (bit for bit on HS071,
//! to rounding on a Van der Pol OCP: see the first test); other versions and what the
//! format cannot hold are named errors.
use nlp::ocp::{ButcherTableau, Horizon, Method, Ocp};
use nlp::{Ipm, Problem, ProblemFileError, Relation, Solution, PROBLEM_FILE_VERSION};
use symx::{with_fresh_arena, Matrix};

/// CasADi's Van der Pol OCP by RK4 multiple shooting, with the initial state a parameter.
fn van_der_pol() -> Problem {
    let mut ocp = Ocp::new(&["x1", "x2"], &["u"]);
    ocp.set_dynamics(|x, u, _p| {
        Matrix::from_vec(vec![(1.0 - x[1].sq()) * x[0] - x[1] + u[0], x[0]])
    });
    ocp.set_stage_cost(|x, u, _p| x[0].sq() + x[1].sq() + u[0].sq());
    ocp.set_horizon(Horizon::Fixed(10.0)).unwrap();
    ocp.set_initial_state_parameter("x0", &[0.0, 1.0]).unwrap();
    ocp.set_state_bounds(&[-0.25, f64::NEG_INFINITY], &[f64::INFINITY; 2])
        .unwrap();
    ocp.set_control_bounds(&[-1.0], &[1.0]).unwrap();
    let tr = ocp
        .transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 4), 20)
        .unwrap();
    tr.problem().clone()
}

/// HS071 (Hock & Schittkowski 1981), as in IPOPT's tutorial.
fn hs071() -> Problem {
    let mut pb = Problem::new();
    let x = pb.variable("x", 4).unwrap();
    pb.set_bounds(&x, 1.0, 5.0).unwrap();
    pb.set_initial(&x, &[1.0, 5.0, 5.0, 1.0]).unwrap();
    pb.minimize(x[0] * x[3] * (x[0] + x[1] + x[2]) + x[2]);
    pb.subject_to_named("product", (x[0] * x[1] * x[2] * x[3]).ge(25.0))
        .unwrap();
    pb.subject_to_named("sphere", x.sumsqr().eq(40.0)).unwrap();
    pb
}

fn solve(pb: &Problem) -> Solution {
    let sol = Ipm::default().solve(&mut pb.compile().unwrap()).unwrap();
    assert!(sol.status.is_success(), "{:?}", sol.status);
    sol
}

fn same(a: &Solution, b: &Solution) {
    let bits = |s: &Solution| s.x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(a), bits(b));
    assert_eq!(a.objective.to_bits(), b.objective.to_bits());
    assert_eq!(a.stats.iterations, b.stats.iterations);
    let lam = |s: &Solution| s.lambda.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(lam(a), lam(b));
}

/// The objective and every constraint row at `x`, as bit patterns.
fn values_bits(pb: &Problem, x: &[f64]) -> Vec<u64> {
    let mut e = vec![pb.objective()];
    e.extend(pb.constraint_expressions());
    pb.evaluate(&e, x)
        .unwrap()
        .iter()
        .map(|v| v.to_bits())
        .collect()
}

#[test]
fn a_loaded_problem_evaluates_bit_identically_in_a_fresh_graph() {
    let pb = van_der_pol();
    let text = pb.to_json().unwrap();
    let want = solve(&pb);
    let points = [want.x.clone(), pb.initial_point().to_vec()];
    let want_values: Vec<Vec<u64>> = points.iter().map(|x| values_bits(&pb, x)).collect();
    let (got, got_values) = with_fresh_arena(|| {
        let loaded = Problem::from_json(&text).unwrap();
        let values: Vec<Vec<u64>> = points.iter().map(|x| values_bits(&loaded, x)).collect();
        // The parameter kept its name and value and still changes without recompiling.
        let mut c = loaded.compile().unwrap();
        let sol = Ipm::default().solve(&mut c).unwrap();
        c.set_value("x0", &[0.1, 0.9]).unwrap();
        (sol, values)
    });
    // f and g: the same operations in the same order, so the same bits.
    assert_eq!(got_values, want_values);
    // Derivatives are built again by AD on the loaded graph, whose node numbering differs
    // (constants first): sums of adjoints may associate differently, so the iterates agree
    // to rounding, not bit for bit (observed: a few ulps; same iteration count).
    assert_eq!(got.stats.iterations, want.stats.iterations);
    assert!((got.objective - want.objective).abs() <= 1e-12 * want.objective.abs());
    for (a, b) in got.x.iter().zip(&want.x) {
        assert!((a - b).abs() <= 1e-10 * (1.0 + b.abs()), "{a} vs {b}");
    }
}

#[test]
fn the_checked_in_file_solves_as_the_problem_built_now() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/problem_v1.json"
    );
    if std::env::var_os("NLP_WRITE_FIXTURE").is_some() {
        hs071().save(path).unwrap();
    }
    let loaded = Problem::load(path).unwrap();
    let want = solve(&hs071());
    same(&want, &solve(&loaded));
    // HS071's optimum (Hock & Schittkowski 1981, problem 71): f* = 17.0140173.
    assert!((want.objective - 17.0140173).abs() < 1e-6);
    let names: Vec<_> = loaded
        .compile()
        .unwrap()
        .constraint_blocks()
        .iter()
        .map(|b| b.name.clone())
        .collect();
    assert_eq!(names, ["product", "sphere"]);
}

#[test]
fn other_versions_and_unsupported_content_are_named_errors() {
    let text = hs071().to_json().unwrap();
    let v = format!("\"version\":{PROBLEM_FILE_VERSION}");
    let err = Problem::from_json(&text.replacen(&v, "\"version\":9", 1))
        .err()
        .unwrap();
    let msg = err.to_string();
    assert!(matches!(err, ProblemFileError::Version { found: 9, .. }));
    assert!(
        msg.contains("version 9") && msg.contains(&format!("version {PROBLEM_FILE_VERSION}")),
        "{msg}"
    );
    let err = Problem::from_json(r#"{"format":"symx.function","version":1}"#)
        .err()
        .unwrap();
    assert!(err.to_string().contains("symnlp.problem"), "{err}");
    let damaged = text.replacen("\"initial\":[", "\"initial\":[0.5,", 1);
    assert!(Problem::from_json(&damaged)
        .err()
        .unwrap()
        .to_string()
        .contains("sizes"));
    let mut pb = hs071();
    let y = pb.variable("y", 2).unwrap();
    pb.complementarity("switch", y[0], y[1]).unwrap();
    let err = pb.to_json().unwrap_err().to_string();
    assert!(err.contains("complementarity constraint 'switch'"), "{err}");
}
