//! Second-order cones in the DSL ([`nlp::Problem::subject_to_cone`]): small SOCPs with
//! optima derived by hand, solved by both back ends. The interior-point method sees the
//! smooth form `√(‖v‖² + ε²) − t ≤ ε` (ε = 1e-8, an outer approximation: ‖v‖ − t ≤ ε);
//! the SQP hands affine cones to clarabel as exact second-order cones and linearises the
//! smooth row of the others.
use nlp::{Ipm, IpmOptions, NumericNlp, Problem, Solution, Sqp, SqpOptions, Status};

use testkit::socp as problems;

/// Tolerance on the cone residual max(0, ‖v‖ − t) at a solution: the smoothing ε of the
/// interior-point form plus solver tolerances.
const CONE_TOL: f64 = 1e-7;

fn solve_both(pb: &Problem, affine_cones: usize) -> [Solution; 2] {
    let mut c = pb.compile().unwrap();
    assert_eq!(c.affine_cones().len(), affine_cones);
    let ipm = Ipm::new(IpmOptions::default()).solve(&mut c).unwrap();
    let mut c = pb.compile().unwrap();
    let sqp = Sqp::new(SqpOptions::default()).solve(&mut c).unwrap();
    for (name, s) in [("ipm", &ipm), ("sqp", &sqp)] {
        assert_eq!(s.status, Status::SolveSucceeded, "{name}: {}", s.message);
        let r = pb.cone_residual(&s.x).unwrap();
        assert!(r <= CONE_TOL, "{name}: cone residual {r:e} at {:?}", s.x);
    }
    [ipm, sqp]
}

fn assert_close(what: &str, got: f64, want: f64, tol: f64) {
    assert!(
        (got - want).abs() <= tol,
        "{what}: got {got}, want {want} (|diff| = {:e})",
        (got - want).abs()
    );
}

/// min x + y  s.t.  ‖(x, y)‖ ≤ 1.
///
/// By Cauchy–Schwarz x + y = (1, 1)·(x, y) ≥ −‖(1, 1)‖·‖(x, y)‖ ≥ −√2, with equality iff
/// (x, y) is a non-positive multiple of (1, 1) of norm 1: the optimum is −√2 at
/// (−1/√2, −1/√2). (The smooth form shifts it by O(ε): its boundary is at ‖v‖ = √(1 + 2ε).)
#[test]
fn unit_disc_linear_objective() {
    let pb = problems::unit_disc();
    for s in solve_both(&pb, 1) {
        assert_close("objective", s.objective, -std::f64::consts::SQRT_2, 1e-6);
        for &xi in &s.x {
            assert_close("x", xi, -std::f64::consts::FRAC_1_SQRT_2, 1e-6);
        }
    }
}

/// min t  s.t.  ‖(x₁ − a₁, x₂ − a₂)‖ ≤ t,  3x₁ + 4x₂ = 0, with the parameter a = (1, 2):
/// a cone of dimension 3 (t and a 2-vector) with a variable t, and a linear constraint.
///
/// The optimum is the distance from a to the line c·x = 0, c = (3, 4):
/// t* = |c·a|/‖c‖ = 11/5, reached at the projection x* = a − (c·a/‖c‖²) c
/// = (1, 2) − (11/25)(3, 4) = (−8/25, 6/25) (check: 3·(−8) + 4·6 = 0). The cone is active
/// with v ≠ 0 there.
#[test]
fn distance_to_a_line() {
    let pb = problems::distance_to_a_line();
    for s in solve_both(&pb, 1) {
        assert_close("objective", s.objective, 11.0 / 5.0, 1e-6);
        assert_close("x1", s.x[0], -8.0 / 25.0, 1e-6);
        assert_close("x2", s.x[1], 6.0 / 25.0, 1e-6);
        assert_close("t", s.x[2], 11.0 / 5.0, 1e-6);
        // The line holds exactly (to the solvers' tolerance).
        assert!((3.0 * s.x[0] + 4.0 * s.x[1]).abs() <= 1e-8);
    }
}

/// min t  s.t.  ‖x − a‖ ≤ t,  x₁ + x₂ + x₃ = 0, a = (1, 2, 3): a cone of dimension 4.
///
/// As above, t* is the distance from a to the plane c·x = 0, c = (1, 1, 1):
/// t* = |c·a|/‖c‖ = 6/√3 = 2√3, at x* = a − (c·a/‖c‖²) c = (1, 2, 3) − 2·(1, 1, 1)
/// = (−1, 0, 1).
#[test]
fn distance_to_a_plane() {
    let pb = problems::distance_to_a_plane();
    for s in solve_both(&pb, 1) {
        assert_close("objective", s.objective, 2.0 * 3f64.sqrt(), 1e-6);
        for (i, want) in [-1.0, 0.0, 1.0].into_iter().enumerate() {
            assert_close("x", s.x[i], want, 1e-6);
        }
    }
}

/// A cone that is not affine: min −y  s.t.  ‖(x, y)‖ ≤ 2 − x² (a convex set: ‖(x, y)‖ + x²
/// is convex). Both back ends see the smooth row. On the boundary y² = (2 − x²)² − x²
/// = 4 − 5x² + x⁴, decreasing in x² on [0, 2] (derivative −5 + 2x² < 0), so the largest y
/// is 2 at x = 0: the optimum is −2 at (0, 2).
#[test]
fn non_affine_cone() {
    let pb = problems::non_affine_cone();
    assert!(!pb.cones()[0].affine);
    for s in solve_both(&pb, 0) {
        assert_close("objective", s.objective, -2.0, 1e-6);
        assert_close("x", s.x[0], 0.0, 1e-6);
        assert_close("y", s.x[1], 2.0, 1e-6);
    }
}

/// Building errors: an empty v.
#[test]
fn empty_cone_is_rejected() {
    let mut pb = Problem::new();
    let t = pb.scalar_variable("t").unwrap();
    assert!(pb.subject_to_cone("c", &[], t).is_err());
}
