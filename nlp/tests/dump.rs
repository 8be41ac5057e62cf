//! `nlp::ProblemDump`: the printed problem parses back to what the compiled problem
//! computes, and a dump that does not describe it is caught.
use nlp::{DumpError, Problem, ProblemDump, Relation};

fn problem() -> Problem {
    let mut pb = Problem::new();
    let x = pb.variable("r^1", 2).unwrap(); // '^' as the planner's names use it
    let y = pb.scalar_variable("y").unwrap();
    pb.set_initial(&x, &[0.3, -1.2]).unwrap();
    pb.set_initial(&[y], &[2.0]).unwrap();
    pb.set_bounds(&x, -5.0, 5.0).unwrap();
    pb.minimize((x[0] - y).sq() + (x[1] * y).sin());
    pb.subject_to_named("ball", (x[0].sq() + x[1].sq() + y.sq()).le(9.0))
        .unwrap();
    pb.subject_to_named("curve", (x[0].exp() - y * x[1]).eq(1.0))
        .unwrap();
    pb
}

#[test]
fn the_printed_problem_evaluates_like_the_compiled_one() {
    let pb = problem();
    let mut compiled = pb.compile().unwrap();
    let d = ProblemDump::new(&pb, &mut compiled, "test".into());
    assert_eq!((d.n, d.m), (3, 2));
    assert_eq!(d.variables[0].name, "r^1[0]");
    assert_eq!(d.variables[0].lower, Some(-5.0));
    assert_eq!(d.variables[2].lower, None); // unbounded y
    assert_eq!(d.constraints[1].name, "curve");
    // f(x0) by hand: (0.3 − 2)² + sin(−1.2·2).
    let f0 = (0.3f64 - 2.0).powi(2) + (-2.4f64).sin();
    assert!((d.f0 - f0).abs() <= 1e-15);
    let v = d.verify().unwrap();
    // The same expressions evaluated by two compiled tapes: equal up to rounding.
    assert!(
        v.objective_error <= 1e-14 && v.constraint_error <= 1e-14,
        "{v:?}"
    );
    // A JSON round trip keeps every field.
    let back: ProblemDump = serde_json::from_str(&serde_json::to_string(&d).unwrap()).unwrap();
    assert_eq!(back.constraints[0].expr, d.constraints[0].expr);
}

#[test]
fn a_dump_that_does_not_describe_the_problem_is_caught() {
    let pb = problem();
    let mut compiled = pb.compile().unwrap();
    let mut d = ProblemDump::new(&pb, &mut compiled, "test".into());
    d.constraints[0].g0 += 1e-3;
    let v = d.verify().unwrap();
    assert!((v.constraint_error - 1e-3).abs() <= 1e-12, "{v:?}");
    d.constraints[1].expr = "(r^1[0]+".into();
    assert!(matches!(d.verify(), Err(DumpError::Parse { what, .. }) if what == "curve"));
    d.variables[2].name = "r^1[0]".into();
    assert!(matches!(d.verify(), Err(DumpError::DuplicateName(_))));
}
