//! The traps of issue 22 item 3, each now an error or a documented, tested behaviour:
//! parameter values travel with a solution, single-variable rows with a parameter stay
//! rows, `Compiled::set_initial_point` cold-starts. (An `Ocp` without a horizon is an
//! error: `nlp/tests/ocp.rs`, `mistakes_are_reported`.)
use nlp::{Ipm, NumericNlp, Problem, Relation, Sqp, SqpOptions};

/// min (x − p)²: x* = p.
fn shifted() -> (Problem, symx::Expr, symx::Expr) {
    let mut pb = Problem::new();
    let x = pb.scalar_variable("x").unwrap();
    let p = pb.scalar_parameter("p").unwrap();
    pb.set_value(p, &[2.0]).unwrap();
    pb.minimize((x - p).sq());
    (pb, x, p)
}

#[test]
fn value_uses_the_parameters_the_solution_was_solved_with() {
    let (pb, x, p) = shifted();
    let mut compiled = pb.compile().unwrap();
    compiled.set_value("p", &[4.0]).unwrap();
    for sol in [
        Ipm::default().solve(&mut compiled).unwrap(),
        Sqp::new(SqpOptions::default())
            .solve(&mut compiled)
            .unwrap(),
    ] {
        assert_eq!(sol.parameters, [4.0]);
        assert!((sol.x[0] - 4.0).abs() < 1e-8);
        // Before: evaluated with the problem's p = 2 and returned 4 instead of 0.
        assert!(pb.value((x - p).sq(), &sol).unwrap() < 1e-12);
        assert_eq!(pb.value(p, &sol).unwrap(), 4.0);
        assert_eq!(pb.values(&[x, p], &sol).unwrap()[1], 4.0);
    }
    // A solution without parameter values (hand-built, older file) uses the problem's.
    let mut sol = Ipm::default().solve(&mut compiled).unwrap();
    sol.parameters.clear();
    assert_eq!(pb.value(p, &sol).unwrap(), 2.0);
    // One of the wrong length is an error naming it.
    sol.parameters = vec![1.0, 2.0];
    let err = pb.value(p, &sol).unwrap_err().to_string();
    assert!(err.contains("solution parameters"), "{err}");
    // A problem without parameters: an empty vector.
    let mut plain = Problem::new();
    let y = plain.scalar_variable("y").unwrap();
    plain.minimize((y - 1.0).sq());
    let sol = Ipm::default().solve(&mut plain.compile().unwrap()).unwrap();
    assert!(sol.parameters.is_empty());
    // The field round-trips through JSON; files without it still load.
    let json = serde_json::to_string(&sol).unwrap();
    let old = json.replace(",\"parameters\":[]", "");
    assert_ne!(json, old);
    let back: nlp::Solution = serde_json::from_str(&old).unwrap();
    assert_eq!(back, sol);
}

#[test]
fn a_single_variable_row_with_a_parameter_stays_a_row() {
    let mut pb = Problem::new();
    let x = pb.scalar_variable("x").unwrap();
    let p = pb.scalar_parameter("p").unwrap();
    pb.set_value(p, &[1.0]).unwrap();
    pb.minimize(x.sq());
    pb.subject_to(x.ge(p)).unwrap();
    pb.subject_to(x.le(5.0)).unwrap();
    let mut compiled = pb.compile().unwrap();
    assert_eq!(compiled.m(), 1, "x ≥ p is a row, x ≤ 5 a bound");
    for p in [1.0, 3.0] {
        compiled.set_value("p", &[p]).unwrap();
        let sol = Ipm::default().solve(&mut compiled).unwrap();
        assert!((sol.x[0] - p).abs() < 1e-8);
        // The row's multiplier: d f*/dp = 2p (IPOPT's sign: λ = −2p for g = x − p ≥ 0).
        assert!((sol.lambda[0] + 2.0 * p).abs() < 1e-6, "{:?}", sol.lambda);
    }
}

#[test]
fn set_initial_point_cold_starts_from_a_new_guess() {
    let mut pb = Problem::new();
    let x = pb.scalar_variable("x").unwrap();
    pb.minimize((x.sq() - 1.0).sq());
    let mut compiled = pb.compile().unwrap();
    for (start, minimum) in [(-3.0, -1.0), (3.0, 1.0)] {
        compiled.set_initial_point(&[start]).unwrap();
        let sol = Ipm::default().solve(&mut compiled).unwrap();
        assert!((sol.x[0] - minimum).abs() < 1e-8, "{start}: {:?}", sol.x);
    }
    let err = compiled
        .set_initial_point(&[1.0, 2.0])
        .unwrap_err()
        .to_string();
    assert!(err.contains("initial point"), "{err}");
}
