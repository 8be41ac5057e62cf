//! The SOCP test problems (their optima are derived in `nlp/tests/socp.rs`), shared with
//! `tests/golden.rs`.

use nlp::{Problem, Relation};
use symx::Expr;

/// min x + y  s.t.  ‖(x, y)‖ ≤ 1.
pub fn unit_disc() -> Problem {
    let mut pb = Problem::new();
    let x = pb.variable("x", 2).unwrap();
    pb.minimize(x[0] + x[1]);
    pb.subject_to_cone("disc", &[x[0], x[1]], Expr::constant(1.0))
        .unwrap();
    pb
}

/// min t  s.t.  ‖(x₁ − a₁, x₂ − a₂)‖ ≤ t,  3x₁ + 4x₂ = 0, a = (1, 2) a parameter.
pub fn distance_to_a_line() -> Problem {
    let mut pb = Problem::new();
    let x = pb.variable("x", 2).unwrap();
    let t = pb.scalar_variable("t").unwrap();
    let a = pb.parameter("a", 2).unwrap();
    pb.set_value(&a, &[1.0, 2.0]).unwrap();
    pb.set_initial(&[t], &[10.0]).unwrap();
    pb.minimize(t);
    pb.subject_to_cone("dist", &[x[0] - a[0], x[1] - a[1]], t)
        .unwrap();
    pb.subject_to_named("line", (3.0 * x[0] + 4.0 * x[1]).eq(0.0))
        .unwrap();
    pb
}

/// min t  s.t.  ‖x − a‖ ≤ t,  x₁ + x₂ + x₃ = 0, a = (1, 2, 3).
pub fn distance_to_a_plane() -> Problem {
    let mut pb = Problem::new();
    let x = pb.variable("x", 3).unwrap();
    let t = pb.scalar_variable("t").unwrap();
    let a = [1.0, 2.0, 3.0];
    pb.minimize(t);
    let v: Vec<Expr> = (0..3).map(|i| x[i] - a[i]).collect();
    pb.subject_to_cone("dist", &v, t).unwrap();
    pb.subject_to_named("plane", (x[0] + x[1] + x[2]).eq(0.0))
        .unwrap();
    pb
}

/// min −y  s.t.  ‖(x, y)‖ ≤ 2 − x² (a cone that is not affine).
pub fn non_affine_cone() -> Problem {
    let mut pb = Problem::new();
    let x = pb.variable("x", 2).unwrap();
    pb.minimize(-x[1]);
    pb.subject_to_cone("bowl", &[x[0], x[1]], 2.0 - x[0].sq())
        .unwrap();
    pb
}

/// A problem's name and builder.
pub type Entry = (&'static str, fn() -> Problem);

/// Every problem with its name, in order.
#[allow(dead_code)]
pub const ALL: &[Entry] = &[
    ("unit_disc", unit_disc),
    ("distance_to_a_line", distance_to_a_line),
    ("distance_to_a_plane", distance_to_a_plane),
    ("non_affine_cone", non_affine_cone),
];
