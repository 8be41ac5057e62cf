//! The Hock–Schittkowski problems, written with the `nlp::Problem` builder.
//!
//! Sources, cited per problem by number:
//! - \[HS81\] W. Hock, K. Schittkowski, "Test Examples for Nonlinear Programming Codes",
//!   Lecture Notes in Economics and Mathematical Systems 187, Springer 1981.
//! - \[S08\] K. Schittkowski, "An updated set of 306 test problems for nonlinear
//!   programming with validated optimal solutions", 2008 (corrections of \[HS81\]).
//!
//! Each builder uses the published starting point (feasible or not) and bounds. The
//! same formulations, in CasADi, are in `benches/reference/hs_casadi.py`: keep both in
//! sync. Variables are named as in the book: `x1` is `x[0]`.

use nlp::{bounded, BuildError, Problem, Relation};
use symx::{Expr, Matrix};

const INF: f64 = f64::INFINITY;
const SQRT2: f64 = std::f64::consts::SQRT_2;
const PI: f64 = std::f64::consts::PI;

fn sqrt3() -> f64 {
    3f64.sqrt()
}

/// A problem with its published optimum.
pub struct Case {
    pub problem: Problem,
    /// The published optimal objective value.
    pub f_star: f64,
    /// Other local minimisers' objective values that a local method may reach from the
    /// standard start (IPOPT does); each is explained where the problem is built.
    pub local: &'static [f64],
    /// Objective tolerance: relative to |f*|, absolute when f* = 0.
    pub tol: f64,
}

pub type Built = Result<Case, BuildError>;

/// The default objective tolerance: the solver stops at a scaled KKT error below
/// tol = 1e-8, which puts the objective far closer than 1e-6 (relative) to the optimum
/// of these well-scaled problems; absolute 1e-6 when f* = 0 (no scale to be relative to).
pub const TOL: f64 = 1e-6;

fn case(problem: Problem, f_star: f64) -> Built {
    Ok(Case {
        problem,
        f_star,
        local: &[],
        tol: TOL,
    })
}

/// Declares `x` (N entries) with its starting point; returns the vector and its entries.
fn vars<const N: usize>(pb: &mut Problem, x0: [f64; N]) -> Result<(Matrix, [Expr; N]), BuildError> {
    let x = pb.variable("x", N)?;
    pb.set_initial(&x, &x0)?;
    let entries = std::array::from_fn(|i| x[i]);
    Ok((x, entries))
}

/// Per-entry bounds `lo[i] ≤ x[i] ≤ hi[i]`.
fn bounds(pb: &mut Problem, x: &[Expr], lo: &[f64], hi: &[f64]) -> Result<(), BuildError> {
    pb.set_bounds(x, lo, hi)
}

fn rosenbrock(x1: Expr, x2: Expr) -> Expr {
    100.0 * (x2 - x1.sq()).sq() + (1.0 - x1).sq()
}

// ============================================================== bounds only
// (HS1–5 and friends are "unconstrained" in the book's sense: no general constraints.)

/// HS81 problem 1; f* = 0 at (1, 1). The bound x2 ≥ −1.5 is inactive.
pub fn hs001() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [-2.0, 1.0])?;
    bounds(&mut pb, &x, &[-INF, -1.5], &[INF, INF])?;
    pb.minimize(rosenbrock(x1, x2));
    case(pb, 0.0)
}

/// HS81 problem 2; f* = 4.9412293 at x* = (1.2243707, 1.5) as printed. \[S08\] notes that
/// this value belongs to the local minimiser x ≈ (−1.2244, 1.5), and that the global
/// one, f = 0.0504261879 at x1 ≈ +1.2244, is not reached from the standard start.
pub fn hs002() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [-2.0, 1.0])?;
    bounds(&mut pb, &x, &[-INF, 1.5], &[INF, INF])?;
    pb.minimize(rosenbrock(x1, x2));
    Ok(Case {
        local: &[0.0504261879],
        ..case(pb, 4.9412293)?
    })
}

/// HS81 problem 3; f* = 0 at (0, 0).
pub fn hs003() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [10.0, 1.0])?;
    bounds(&mut pb, &x, &[-INF, 0.0], &[INF, INF])?;
    pb.minimize(x2 + 1e-5 * (x2 - x1).sq());
    case(pb, 0.0)
}

/// HS81 problem 4; f* = 8/3 at (1, 0).
pub fn hs004() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [1.125, 0.125])?;
    bounds(&mut pb, &x, &[1.0, 0.0], &[INF, INF])?;
    pb.minimize((x1 + 1.0).powi(3) / 3.0 + x2);
    case(pb, 8.0 / 3.0)
}

/// HS81 problem 5; f* = −√3/2 − π/3 at (−π/3 + 1/2, −π/3 − 1/2).
pub fn hs005() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [0.0, 0.0])?;
    bounds(&mut pb, &x, &[-1.5, -3.0], &[4.0, 3.0])?;
    pb.minimize((x1 + x2).sin() + (x1 - x2).sq() - 1.5 * x1 + 2.5 * x2 + 1.0);
    case(pb, -sqrt3() / 2.0 - PI / 3.0)
}

/// HS81 problem 25; f* = 0 at (50, 25, 1.5).
pub fn hs025() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [100.0, 12.5, 3.0])?;
    bounds(&mut pb, &x, &[0.1, 0.0, 0.0], &[100.0, 25.6, 5.0])?;
    let f = (1..=99)
        .map(|i| {
            let i = i as f64;
            let u = 25.0 + (-50.0 * (0.01 * i).ln()).powf(2.0 / 3.0);
            (-0.01 * i + (-(u - x2).pow(x3) / x1).exp()).sq()
        })
        .sum();
    pb.minimize(f);
    case(pb, 0.0)
}

/// HS81 problem 38 (Colville 4); f* = 0 at (1, 1, 1, 1).
pub fn hs038() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4]) = vars(&mut pb, [-3.0, -1.0, -3.0, -1.0])?;
    pb.set_bounds(&x, -10.0, 10.0)?;
    pb.minimize(
        100.0 * (x2 - x1.sq()).sq()
            + (1.0 - x1).sq()
            + 90.0 * (x4 - x3.sq()).sq()
            + (1.0 - x3).sq()
            + 10.1 * ((x2 - 1.0).sq() + (x4 - 1.0).sq())
            + 19.8 * (x2 - 1.0) * (x4 - 1.0),
    );
    case(pb, 0.0)
}

/// HS81 problem 45; f* = 1 at (1, 2, 3, 4, 5).
pub fn hs045() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4, x5]) = vars(&mut pb, [2.0; 5])?;
    bounds(&mut pb, &x, &[0.0; 5], &[1.0, 2.0, 3.0, 4.0, 5.0])?;
    pb.minimize(2.0 - x1 * x2 * x3 * x4 * x5 / 120.0);
    case(pb, 1.0)
}

/// HS81 problem 110; f* = −45.77846971 at xᵢ = 9.35025655.
pub fn hs110() -> Built {
    let mut pb = Problem::new();
    let (x, _) = vars(&mut pb, [9.0; 10])?;
    pb.set_bounds(&x, 2.001, 9.999)?;
    let s: Expr = x
        .iter()
        .map(|&xi| (xi - 2.0).ln().sq() + (10.0 - xi).ln().sq())
        .sum();
    let p: Expr = x.iter().copied().product();
    pb.minimize(s - p.powf(0.2));
    case(pb, -45.77846971)
}

// ============================================================== equality constraints

/// HS81 problem 6; f* = 0 at (1, 1).
pub fn hs006() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2]) = vars(&mut pb, [-1.2, 1.0])?;
    pb.minimize((1.0 - x1).sq());
    pb.subject_to((10.0 * (x2 - x1.sq())).eq(0.0))?;
    case(pb, 0.0)
}

/// HS81 problem 7; f* = −√3 at (0, √3).
pub fn hs007() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2]) = vars(&mut pb, [2.0, 2.0])?;
    pb.minimize((1.0 + x1.sq()).ln() - x2);
    pb.subject_to(((1.0 + x1.sq()).sq() + x2.sq()).eq(4.0))?;
    case(pb, -sqrt3())
}

/// HS81 problem 8 (a feasibility problem: constant objective); f* = −1.
pub fn hs008() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2]) = vars(&mut pb, [2.0, 1.0])?;
    pb.minimize(Expr::constant(-1.0));
    pb.subject_to((x1.sq() + x2.sq()).eq(25.0))?;
    pb.subject_to((x1 * x2).eq(9.0))?;
    case(pb, -1.0)
}

/// HS81 problem 9; f* = −0.5 at (12k − 3, 16k − 4), k integer.
pub fn hs009() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2]) = vars(&mut pb, [0.0, 0.0])?;
    pb.minimize((PI * x1 / 12.0).sin() * (PI * x2 / 16.0).cos());
    pb.subject_to((4.0 * x1 - 3.0 * x2).eq(0.0))?;
    case(pb, -0.5)
}

/// HS81 problem 26; f* = 0 at (1, 1, 1).
pub fn hs026() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3]) = vars(&mut pb, [-2.6, 2.0, 2.0])?;
    pb.minimize((x1 - x2).sq() + (x2 - x3).powi(4));
    pb.subject_to(((1.0 + x2.sq()) * x1 + x3.powi(4)).eq(3.0))?;
    case(pb, 0.0)
}

/// HS81 problem 27; f* = 0.04 at (−1, 1, 0).
pub fn hs027() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3]) = vars(&mut pb, [2.0; 3])?;
    pb.minimize(0.01 * (x1 - 1.0).sq() + (x2 - x1.sq()).sq());
    pb.subject_to((x1 + x3.sq()).eq(-1.0))?;
    case(pb, 0.04)
}

/// HS81 problem 28; f* = 0 at (0.5, −0.5, 0.5).
pub fn hs028() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3]) = vars(&mut pb, [-4.0, 1.0, 1.0])?;
    pb.minimize((x1 + x2).sq() + (x2 + x3).sq());
    pb.subject_to((x1 + 2.0 * x2 + 3.0 * x3).eq(1.0))?;
    case(pb, 0.0)
}

/// HS81 problem 39; f* = −1 at (1, 1, 0, 0).
pub fn hs039() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4]) = vars(&mut pb, [2.0; 4])?;
    pb.minimize(-x1);
    pb.subject_to((x2 - x1.powi(3) - x3.sq()).eq(0.0))?;
    pb.subject_to((x1.sq() - x2 - x4.sq()).eq(0.0))?;
    case(pb, -1.0)
}

/// HS81 problem 40; f* = −0.25.
pub fn hs040() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4]) = vars(&mut pb, [0.8; 4])?;
    pb.minimize(-x1 * x2 * x3 * x4);
    pb.subject_to((x1.powi(3) + x2.sq()).eq(1.0))?;
    pb.subject_to((x1.sq() * x4 - x3).eq(0.0))?;
    pb.subject_to((x4.sq() - x2).eq(0.0))?;
    case(pb, -0.25)
}

/// HS81 problem 42; f* = 28 − 10√2 at (2, 2, 0.6√2, 0.8√2). The constraint x1 = 2 is on
/// one variable: the builder keeps it as the (fixed) bound 2 ≤ x1 ≤ 2.
pub fn hs042() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4]) = vars(&mut pb, [1.0; 4])?;
    pb.minimize((x1 - 1.0).sq() + (x2 - 2.0).sq() + (x3 - 3.0).sq() + (x4 - 4.0).sq());
    pb.subject_to(x1.eq(2.0))?;
    pb.subject_to((x3.sq() + x4.sq()).eq(2.0))?;
    case(pb, 28.0 - 10.0 * SQRT2)
}

/// HS81 problem 46; f* = 0 at (1, 1, 1, 1, 1).
pub fn hs046() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4, x5]) = vars(&mut pb, [SQRT2 / 2.0, 1.75, 0.5, 2.0, 2.0])?;
    pb.minimize((x1 - x2).sq() + (x3 - 1.0).sq() + (x4 - 1.0).powi(4) + (x5 - 1.0).powi(6));
    pb.subject_to((x1.sq() * x4 + (x4 - x5).sin()).eq(1.0))?;
    pb.subject_to((x2 + x3.powi(4) * x4.sq()).eq(2.0))?;
    case(pb, 0.0)
}

/// HS81 problem 47; f* = 0 at (1, 1, 1, 1, 1).
pub fn hs047() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4, x5]) = vars(&mut pb, [2.0, SQRT2, -1.0, 2.0 - SQRT2, 0.5])?;
    pb.minimize((x1 - x2).sq() + (x2 - x3).powi(3) + (x3 - x4).powi(4) + (x4 - x5).powi(4));
    pb.subject_to((x1 + x2.sq() + x3.powi(3)).eq(3.0))?;
    pb.subject_to((x2 - x3.sq() + x4).eq(1.0))?;
    pb.subject_to((x1 * x5).eq(1.0))?;
    case(pb, 0.0)
}

/// HS81 problem 48; f* = 0 at (1, 1, 1, 1, 1).
pub fn hs048() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4, x5]) = vars(&mut pb, [3.0, 5.0, -3.0, 2.0, -2.0])?;
    pb.minimize((x1 - 1.0).sq() + (x2 - x3).sq() + (x4 - x5).sq());
    pb.subject_to(x.sum().eq(5.0))?;
    pb.subject_to((x3 - 2.0 * (x4 + x5)).eq(-3.0))?;
    case(pb, 0.0)
}

/// HS81 problem 49; f* = 0 at (1, 1, 1, 1, 1).
pub fn hs049() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4, x5]) = vars(&mut pb, [10.0, 7.0, 2.0, -3.0, 0.8])?;
    pb.minimize((x1 - x2).sq() + (x3 - 1.0).sq() + (x4 - 1.0).powi(4) + (x5 - 1.0).powi(6));
    pb.subject_to((x1 + x2 + x3 + 4.0 * x4).eq(7.0))?;
    pb.subject_to((x3 + 5.0 * x5).eq(6.0))?;
    case(pb, 0.0)
}

/// HS81 problem 50; f* = 0 at (1, 1, 1, 1, 1).
pub fn hs050() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4, x5]) = vars(&mut pb, [35.0, -31.0, 11.0, 5.0, -5.0])?;
    pb.minimize((x1 - x2).sq() + (x2 - x3).sq() + (x3 - x4).powi(4) + (x4 - x5).sq());
    pb.subject_to((x1 + 2.0 * x2 + 3.0 * x3).eq(6.0))?;
    pb.subject_to((x2 + 2.0 * x3 + 3.0 * x4).eq(6.0))?;
    pb.subject_to((x3 + 2.0 * x4 + 3.0 * x5).eq(6.0))?;
    case(pb, 0.0)
}

/// HS81 problem 51; f* = 0 at (1, 1, 1, 1, 1).
pub fn hs051() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4, x5]) = vars(&mut pb, [2.5, 0.5, 2.0, -1.0, 0.5])?;
    pb.minimize((x1 - x2).sq() + (x2 + x3 - 2.0).sq() + (x4 - 1.0).sq() + (x5 - 1.0).sq());
    pb.subject_to((x1 + 3.0 * x2).eq(4.0))?;
    pb.subject_to((x3 + x4 - 2.0 * x5).eq(0.0))?;
    pb.subject_to((x2 - x5).eq(0.0))?;
    case(pb, 0.0)
}

/// HS81 problem 52; f* = 1859/349.
pub fn hs052() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4, x5]) = vars(&mut pb, [2.0; 5])?;
    pb.minimize((4.0 * x1 - x2).sq() + (x2 + x3 - 2.0).sq() + (x4 - 1.0).sq() + (x5 - 1.0).sq());
    pb.subject_to((x1 + 3.0 * x2).eq(0.0))?;
    pb.subject_to((x3 + x4 - 2.0 * x5).eq(0.0))?;
    pb.subject_to((x2 - x5).eq(0.0))?;
    case(pb, 1859.0 / 349.0)
}

/// HS81 problem 53; f* = 176/43.
pub fn hs053() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4, x5]) = vars(&mut pb, [2.0; 5])?;
    pb.set_bounds(&x, -10.0, 10.0)?;
    pb.minimize((x1 - x2).sq() + (x2 + x3 - 2.0).sq() + (x4 - 1.0).sq() + (x5 - 1.0).sq());
    pb.subject_to((x1 + 3.0 * x2).eq(0.0))?;
    pb.subject_to((x3 + x4 - 2.0 * x5).eq(0.0))?;
    pb.subject_to((x2 - x5).eq(0.0))?;
    case(pb, 176.0 / 43.0)
}

/// HS81 problem 56; f* = −3.456 at (2.4, 1.2, 1.2, …).
pub fn hs056() -> Built {
    let mut pb = Problem::new();
    let a = (1.0f64 / 4.2).sqrt().asin();
    let b = (5.0f64 / 7.2).sqrt().asin();
    let (_, [x1, x2, x3, x4, x5, x6, x7]) = vars(&mut pb, [1.0, 1.0, 1.0, a, a, a, b])?;
    pb.minimize(-x1 * x2 * x3);
    pb.subject_to((x1 - 4.2 * x4.sin().sq()).eq(0.0))?;
    pb.subject_to((x2 - 4.2 * x5.sin().sq()).eq(0.0))?;
    pb.subject_to((x3 - 4.2 * x6.sin().sq()).eq(0.0))?;
    pb.subject_to((x1 + 2.0 * x2 + 2.0 * x3 - 7.2 * x7.sin().sq()).eq(0.0))?;
    case(pb, -3.456)
}

/// HS81 problem 61; f* = −143.6461422.
pub fn hs061() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3]) = vars(&mut pb, [0.0; 3])?;
    pb.minimize(4.0 * x1.sq() + 2.0 * x2.sq() + 2.0 * x3.sq() - 33.0 * x1 + 16.0 * x2 - 24.0 * x3);
    pb.subject_to((3.0 * x1 - 2.0 * x2.sq()).eq(7.0))?;
    pb.subject_to((4.0 * x1 - x3.sq()).eq(11.0))?;
    case(pb, -143.6461422)
}

/// HS81 problem 77; f* = 0.24150513.
pub fn hs077() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4, x5]) = vars(&mut pb, [2.0; 5])?;
    pb.minimize(
        (x1 - 1.0).sq()
            + (x1 - x2).sq()
            + (x3 - 1.0).sq()
            + (x4 - 1.0).powi(4)
            + (x5 - 1.0).powi(6),
    );
    pb.subject_to((x1.sq() * x4 + (x4 - x5).sin()).eq(2.0 * SQRT2))?;
    pb.subject_to((x2 + x3.powi(4) * x4.sq()).eq(8.0 + SQRT2))?;
    case(pb, 0.24150513)
}

/// HS81 problem 78; f* = −2.91970041.
pub fn hs078() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4, x5]) = vars(&mut pb, [-2.0, 1.5, 2.0, -1.0, -1.0])?;
    pb.minimize(x1 * x2 * x3 * x4 * x5);
    pb.subject_to(x.sumsqr().eq(10.0))?;
    pb.subject_to((x2 * x3 - 5.0 * x4 * x5).eq(0.0))?;
    pb.subject_to((x1.powi(3) + x2.powi(3)).eq(-1.0))?;
    case(pb, -2.91970041)
}

/// HS81 problem 79; f* = 0.0787768209.
pub fn hs079() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4, x5]) = vars(&mut pb, [2.0; 5])?;
    pb.minimize(
        (x1 - 1.0).sq() + (x1 - x2).sq() + (x2 - x3).sq() + (x3 - x4).powi(4) + (x4 - x5).powi(4),
    );
    pb.subject_to((x1 + x2.sq() + x3.powi(3)).eq(2.0 + 3.0 * SQRT2))?;
    pb.subject_to((x2 - x3.sq() + x4).eq(-2.0 + 2.0 * SQRT2))?;
    pb.subject_to((x1 * x5).eq(2.0))?;
    case(pb, 0.0787768209)
}

// ============================================================== inequality constraints

/// HS81 problem 10; f* = −1 at (0, 1).
pub fn hs010() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2]) = vars(&mut pb, [-10.0, 10.0])?;
    pb.minimize(x1 - x2);
    pb.subject_to((-3.0 * x1.sq() + 2.0 * x1 * x2 - x2.sq() + 1.0).ge(0.0))?;
    case(pb, -1.0)
}

/// HS81 problem 11; f* = −8.498464223.
pub fn hs011() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2]) = vars(&mut pb, [4.9, 0.1])?;
    pb.minimize((x1 - 5.0).sq() + x2.sq() - 25.0);
    pb.subject_to((x2 - x1.sq()).ge(0.0))?;
    case(pb, -8.498464223)
}

/// HS81 problem 12; f* = −30 at (2, 3).
pub fn hs012() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2]) = vars(&mut pb, [0.0, 0.0])?;
    pb.minimize(0.5 * x1.sq() + x2.sq() - x1 * x2 - 7.0 * x1 - 7.0 * x2);
    pb.subject_to((25.0 - 4.0 * x1.sq() - x2.sq()).ge(0.0))?;
    case(pb, -30.0)
}

/// HS81 problem 13; f* = 1 at (1, 0). Degenerate: at x* the active constraints
/// (1 − x1)³ − x2 ≥ 0 and x2 ≥ 0 have gradients (0, −1) and (0, 1) (LICQ and MFCQ
/// fail) and ∇f = (−2, 0) is not in their span, so x* is not a KKT point: an
/// interior-point method only approaches it as its multipliers grow. The start (−2, −2)
/// violates the bounds x ≥ 0.
///
/// Tolerance 1e-2 instead of 1e-6: IPOPT 3.14 itself stops ("Optimal Solution Found",
/// 55 iterations) at f = 0.99458, x1 = 1.0027; the KKT error cannot measure the
/// distance to a non-KKT minimiser, so no tolerance on it gives 1e-6 in f.
pub fn hs013() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [-2.0, -2.0])?;
    pb.set_bounds(&x, 0.0, INF)?;
    pb.minimize((x1 - 2.0).sq() + x2.sq());
    pb.subject_to(((1.0 - x1).powi(3) - x2).ge(0.0))?;
    Ok(Case {
        tol: 1e-2,
        ..case(pb, 1.0)?
    })
}

/// HS81 problem 14; f* = 9 − 2.875√7 at (0.5(√7 − 1), 0.25(√7 + 1)).
pub fn hs014() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2]) = vars(&mut pb, [2.0, 2.0])?;
    pb.minimize((x1 - 2.0).sq() + (x2 - 1.0).sq());
    pb.subject_to((-0.25 * x1.sq() - x2.sq() + 1.0).ge(0.0))?;
    pb.subject_to((x1 - 2.0 * x2).eq(-1.0))?;
    case(pb, 9.0 - 2.875 * 7f64.sqrt())
}

/// HS81 problem 15; f* = 306.5 at (0.5, 2).
pub fn hs015() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [-2.0, 1.0])?;
    bounds(&mut pb, &x, &[-INF, -INF], &[0.5, INF])?;
    pb.minimize(rosenbrock(x1, x2));
    pb.subject_to((x1 * x2).ge(1.0))?;
    pb.subject_to((x1 + x2.sq()).ge(0.0))?;
    case(pb, 306.5)
}

/// HS81 problem 16; f* = 0.25 at (0.5, 0.25).
pub fn hs016() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [-2.0, 1.0])?;
    bounds(&mut pb, &x, &[-0.5, -INF], &[0.5, 1.0])?;
    pb.minimize(rosenbrock(x1, x2));
    pb.subject_to((x1 + x2.sq()).ge(0.0))?;
    pb.subject_to((x1.sq() + x2).ge(0.0))?;
    case(pb, 0.25)
}

/// HS81 problem 17; f* = 1 at (0, 0).
pub fn hs017() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [-2.0, 1.0])?;
    bounds(&mut pb, &x, &[-0.5, -INF], &[0.5, 1.0])?;
    pb.minimize(rosenbrock(x1, x2));
    pb.subject_to((x2.sq() - x1).ge(0.0))?;
    pb.subject_to((x1.sq() - x2).ge(0.0))?;
    case(pb, 1.0)
}

/// HS81 problem 18; f* = 5 at (√250, √2.5).
pub fn hs018() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [2.0, 2.0])?;
    bounds(&mut pb, &x, &[2.0, 0.0], &[50.0, 50.0])?;
    pb.minimize(0.01 * x1.sq() + x2.sq());
    pb.subject_to((x1 * x2).ge(25.0))?;
    pb.subject_to((x1.sq() + x2.sq()).ge(25.0))?;
    case(pb, 5.0)
}

/// HS81 problem 19; f* = −6961.81381 at x* = (14.095, 0.84296079), here evaluated at x*
/// in full precision (x2 = 5 − √(82.81 − 8.095²)).
pub fn hs019() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [20.1, 5.84])?;
    bounds(&mut pb, &x, &[13.0, 0.0], &[100.0, 100.0])?;
    pb.minimize((x1 - 10.0).powi(3) + (x2 - 20.0).powi(3));
    pb.subject_to(((x1 - 5.0).sq() + (x2 - 5.0).sq()).ge(100.0))?;
    pb.subject_to(((x2 - 5.0).sq() + (x1 - 6.0).sq()).le(82.81))?;
    let xs2 = 5.0 - (82.81f64 - 8.095f64.powi(2)).sqrt();
    case(pb, 4.095f64.powi(3) + (xs2 - 20.0).powi(3))
}

/// HS81 problem 20; f* = 40.19873 = 83.5 − 25√3, printed with x* = (0.5, √3/2), where f
/// is in fact 81.5 − 25√3 = 38.19873 (\[S08\] corrects f*). 40.19873 is the local
/// minimiser (−0.5, √3/2), which is where the standard start (−2, 1) leads (IPOPT too).
pub fn hs020() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [-2.0, 1.0])?;
    bounds(&mut pb, &x, &[-0.5, -INF], &[0.5, INF])?;
    pb.minimize(rosenbrock(x1, x2));
    pb.subject_to((x1 + x2.sq()).ge(0.0))?;
    pb.subject_to((x1.sq() + x2).ge(0.0))?;
    pb.subject_to((x1.sq() + x2.sq()).ge(1.0))?;
    Ok(Case {
        local: &[81.5 - 25.0 * 1.7320508075688772],
        ..case(pb, 83.5 - 25.0 * sqrt3())?
    })
}

/// HS81 problem 21; f* = −99.96 at (2, 0).
pub fn hs021() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [-1.0, -1.0])?;
    bounds(&mut pb, &x, &[2.0, -50.0], &[50.0, 50.0])?;
    pb.minimize(0.01 * x1.sq() + x2.sq() - 100.0);
    pb.subject_to((10.0 * x1 - x2).ge(10.0))?;
    case(pb, -99.96)
}

/// HS81 problem 22; f* = 1 at (1, 1).
pub fn hs022() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2]) = vars(&mut pb, [2.0, 2.0])?;
    pb.minimize((x1 - 2.0).sq() + (x2 - 1.0).sq());
    pb.subject_to((-x1 - x2 + 2.0).ge(0.0))?;
    pb.subject_to((x2 - x1.sq()).ge(0.0))?;
    case(pb, 1.0)
}

/// HS81 problem 23; f* = 2 at (1, 1).
pub fn hs023() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [3.0, 1.0])?;
    pb.set_bounds(&x, -50.0, 50.0)?;
    pb.minimize(x1.sq() + x2.sq());
    pb.subject_to((x1 + x2).ge(1.0))?;
    pb.subject_to((x1.sq() + x2.sq()).ge(1.0))?;
    pb.subject_to((9.0 * x1.sq() + x2.sq()).ge(9.0))?;
    pb.subject_to((x1.sq() - x2).ge(0.0))?;
    pb.subject_to((x2.sq() - x1).ge(0.0))?;
    case(pb, 2.0)
}

/// HS81 problem 24; f* = −1 at (3, √3).
pub fn hs024() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2]) = vars(&mut pb, [1.0, 0.5])?;
    pb.set_bounds(&x, 0.0, INF)?;
    let s3 = sqrt3();
    pb.minimize(((x1 - 3.0).sq() - 9.0) * x2.powi(3) / (27.0 * s3));
    pb.subject_to((x1 / s3 - x2).ge(0.0))?;
    pb.subject_to((x1 + s3 * x2).ge(0.0))?;
    pb.subject_to((-x1 - s3 * x2 + 6.0).ge(0.0))?;
    case(pb, -1.0)
}

/// HS81 problem 29; f* = −16√2 at (4, 2√2, 2).
pub fn hs029() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3]) = vars(&mut pb, [1.0; 3])?;
    pb.minimize(-x1 * x2 * x3);
    pb.subject_to((x1.sq() + 2.0 * x2.sq() + 4.0 * x3.sq()).le(48.0))?;
    case(pb, -16.0 * SQRT2)
}

/// HS81 problem 30; f* = 1 at (1, 0, 0).
pub fn hs030() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [1.0; 3])?;
    bounds(&mut pb, &x, &[1.0, -10.0, -10.0], &[10.0; 3])?;
    pb.minimize(x1.sq() + x2.sq() + x3.sq());
    pb.subject_to((x1.sq() + x2.sq()).ge(1.0))?;
    case(pb, 1.0)
}

/// HS81 problem 31; f* = 6 at (1/√3, √3, 0).
pub fn hs031() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [1.0; 3])?;
    bounds(&mut pb, &x, &[-10.0, 1.0, -10.0], &[10.0, 10.0, 1.0])?;
    pb.minimize(9.0 * x1.sq() + x2.sq() + 9.0 * x3.sq());
    pb.subject_to((x1 * x2).ge(1.0))?;
    case(pb, 6.0)
}

/// HS81 problem 32; f* = 1 at (0, 0, 1).
pub fn hs032() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [0.1, 0.7, 0.2])?;
    pb.set_bounds(&x, 0.0, INF)?;
    pb.minimize((x1 + 3.0 * x2 + x3).sq() + 4.0 * (x1 - x2).sq());
    pb.subject_to((6.0 * x2 + 4.0 * x3 - x1.powi(3)).ge(3.0))?;
    pb.subject_to((x1 + x2 + x3).eq(1.0))?;
    case(pb, 1.0)
}

/// HS81 problem 33; f* = √2 − 6 at (0, √2, √2).
pub fn hs033() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [0.0, 0.0, 3.0])?;
    bounds(&mut pb, &x, &[0.0; 3], &[INF, INF, 5.0])?;
    pb.minimize((x1 - 1.0) * (x1 - 2.0) * (x1 - 3.0) + x3);
    pb.subject_to((x3.sq() - x1.sq() - x2.sq()).ge(0.0))?;
    pb.subject_to((x1.sq() + x2.sq() + x3.sq()).ge(4.0))?;
    case(pb, SQRT2 - 6.0)
}

/// HS81 problem 34; f* = −ln(ln 10) at (ln ln 10, ln 10, 10).
pub fn hs034() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [0.0, 1.05, 2.9])?;
    bounds(&mut pb, &x, &[0.0; 3], &[100.0, 100.0, 10.0])?;
    pb.minimize(-x1);
    pb.subject_to((x2 - x1.exp()).ge(0.0))?;
    pb.subject_to((x3 - x2.exp()).ge(0.0))?;
    case(pb, -(10f64.ln().ln()))
}

/// HS81 problem 35 (Beale); f* = 1/9 at (4/3, 7/9, 4/9).
pub fn hs035() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [0.5; 3])?;
    pb.set_bounds(&x, 0.0, INF)?;
    pb.minimize(
        9.0 - 8.0 * x1 - 6.0 * x2 - 4.0 * x3
            + 2.0 * x1.sq()
            + 2.0 * x2.sq()
            + x3.sq()
            + 2.0 * x1 * x2
            + 2.0 * x1 * x3,
    );
    pb.subject_to((x1 + x2 + 2.0 * x3).le(3.0))?;
    case(pb, 1.0 / 9.0)
}

/// HS81 problem 36; f* = −3300 at (20, 11, 15).
pub fn hs036() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [10.0; 3])?;
    bounds(&mut pb, &x, &[0.0; 3], &[20.0, 11.0, 42.0])?;
    pb.minimize(-x1 * x2 * x3);
    pb.subject_to((x1 + 2.0 * x2 + 2.0 * x3).le(72.0))?;
    case(pb, -3300.0)
}

/// HS81 problem 37; f* = −3456 at (24, 12, 12).
pub fn hs037() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [10.0; 3])?;
    pb.set_bounds(&x, 0.0, 42.0)?;
    pb.minimize(-x1 * x2 * x3);
    pb.subject_to((72.0 - x1 - 2.0 * x2 - 2.0 * x3).ge(0.0))?;
    pb.subject_to((x1 + 2.0 * x2 + 2.0 * x3).ge(0.0))?;
    case(pb, -3456.0)
}

/// HS81 problem 43 (Rosen–Suzuki); f* = −44 at (0, 1, 2, −1).
pub fn hs043() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4]) = vars(&mut pb, [0.0; 4])?;
    pb.minimize(
        x1.sq() + x2.sq() + 2.0 * x3.sq() + x4.sq() - 5.0 * x1 - 5.0 * x2 - 21.0 * x3 + 7.0 * x4,
    );
    pb.subject_to((8.0 - x1.sq() - x2.sq() - x3.sq() - x4.sq() - x1 + x2 - x3 + x4).ge(0.0))?;
    pb.subject_to((10.0 - x1.sq() - 2.0 * x2.sq() - x3.sq() - 2.0 * x4.sq() + x1 + x4).ge(0.0))?;
    pb.subject_to((5.0 - 2.0 * x1.sq() - x2.sq() - x3.sq() - 2.0 * x1 + x2 + x4).ge(0.0))?;
    case(pb, -44.0)
}

/// HS81 problem 44; f* = −15 at (0, 3, 0, 4). An indefinite quadratic with several
/// local minimisers at vertices: from the standard start x = 0, IPOPT stops at the
/// local minimiser (3, 0, 4, 0) with f = −13, also accepted here.
pub fn hs044() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4]) = vars(&mut pb, [0.0; 4])?;
    pb.set_bounds(&x, 0.0, INF)?;
    pb.minimize(x1 - x2 - x3 - x1 * x3 + x1 * x4 + x2 * x3 - x2 * x4);
    pb.subject_to((x1 + 2.0 * x2).le(8.0))?;
    pb.subject_to((4.0 * x1 + x2).le(12.0))?;
    pb.subject_to((3.0 * x1 + 4.0 * x2).le(12.0))?;
    pb.subject_to((2.0 * x3 + x4).le(8.0))?;
    pb.subject_to((x3 + 2.0 * x4).le(8.0))?;
    pb.subject_to((x3 + x4).le(5.0))?;
    Ok(Case {
        local: &[-13.0],
        ..case(pb, -15.0)?
    })
}

/// HS81 problem 64; f* = 6299.842428.
pub fn hs064() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [1.0; 3])?;
    pb.set_bounds(&x, 1e-5, INF)?;
    pb.minimize(5.0 * x1 + 50000.0 / x1 + 20.0 * x2 + 72000.0 / x2 + 10.0 * x3 + 144000.0 / x3);
    pb.subject_to((1.0 - 4.0 / x1 - 32.0 / x2 - 120.0 / x3).ge(0.0))?;
    case(pb, 6299.842428)
}

/// HS81 problem 65; f* = 0.9535288567.
pub fn hs065() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [-5.0, 5.0, 0.0])?;
    bounds(&mut pb, &x, &[-4.5, -4.5, -5.0], &[4.5, 4.5, 5.0])?;
    pb.minimize((x1 - x2).sq() + (x1 + x2 - 10.0).sq() / 9.0 + (x3 - 5.0).sq());
    pb.subject_to((x1.sq() + x2.sq() + x3.sq()).le(48.0))?;
    case(pb, 0.9535288567)
}

/// HS81 problem 66; f* = 0.5181632741.
pub fn hs066() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3]) = vars(&mut pb, [0.0, 1.05, 2.9])?;
    bounds(&mut pb, &x, &[0.0; 3], &[100.0, 100.0, 10.0])?;
    pb.minimize(0.2 * x3 - 0.8 * x1);
    pb.subject_to((x2 - x1.exp()).ge(0.0))?;
    pb.subject_to((x3 - x2.exp()).ge(0.0))?;
    case(pb, 0.5181632741)
}

/// HS81 problem 76; f* = −4.681818181 (= −103/22).
pub fn hs076() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4]) = vars(&mut pb, [0.5; 4])?;
    pb.set_bounds(&x, 0.0, INF)?;
    pb.minimize(
        x1.sq() + 0.5 * x2.sq() + x3.sq() + 0.5 * x4.sq() - x1 * x3 + x3 * x4 - x1 - 3.0 * x2 + x3
            - x4,
    );
    pb.subject_to((x1 + 2.0 * x2 + x3 + x4).le(5.0))?;
    pb.subject_to((3.0 * x1 + x2 + 2.0 * x3 - x4).le(4.0))?;
    pb.subject_to((x2 + 4.0 * x3).ge(1.5))?;
    case(pb, -103.0 / 22.0)
}

/// HS81 problem 100; f* = 680.6300573.
pub fn hs100() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4, x5, x6, x7]) = vars(&mut pb, [1.0, 2.0, 0.0, 4.0, 0.0, 1.0, 1.0])?;
    pb.minimize(
        (x1 - 10.0).sq()
            + 5.0 * (x2 - 12.0).sq()
            + x3.powi(4)
            + 3.0 * (x4 - 11.0).sq()
            + 10.0 * x5.powi(6)
            + 7.0 * x6.sq()
            + x7.powi(4)
            - 4.0 * x6 * x7
            - 10.0 * x6
            - 8.0 * x7,
    );
    pb.subject_to(
        (127.0 - 2.0 * x1.sq() - 3.0 * x2.powi(4) - x3 - 4.0 * x4.sq() - 5.0 * x5).ge(0.0),
    )?;
    pb.subject_to((282.0 - 7.0 * x1 - 3.0 * x2 - 10.0 * x3.sq() - x4 + x5).ge(0.0))?;
    pb.subject_to((196.0 - 23.0 * x1 - x2.sq() - 6.0 * x6.sq() + 8.0 * x7).ge(0.0))?;
    pb.subject_to(
        (-4.0 * x1.sq() - x2.sq() + 3.0 * x1 * x2 - 2.0 * x3.sq() - 5.0 * x6 + 11.0 * x7).ge(0.0),
    )?;
    case(pb, 680.6300573)
}

/// HS81 problem 113 (Wong 2); f* = 24.3062091.
pub fn hs113() -> Built {
    let mut pb = Problem::new();
    let (_, [x1, x2, x3, x4, x5, x6, x7, x8, x9, x10]) =
        vars(&mut pb, [2.0, 3.0, 5.0, 5.0, 1.0, 2.0, 7.0, 3.0, 6.0, 10.0])?;
    pb.minimize(
        x1.sq() + x2.sq() + x1 * x2 - 14.0 * x1 - 16.0 * x2
            + (x3 - 10.0).sq()
            + 4.0 * (x4 - 5.0).sq()
            + (x5 - 3.0).sq()
            + 2.0 * (x6 - 1.0).sq()
            + 5.0 * x7.sq()
            + 7.0 * (x8 - 11.0).sq()
            + 2.0 * (x9 - 10.0).sq()
            + (x10 - 7.0).sq()
            + 45.0,
    );
    pb.subject_to((105.0 - 4.0 * x1 - 5.0 * x2 + 3.0 * x7 - 9.0 * x8).ge(0.0))?;
    pb.subject_to((-10.0 * x1 + 8.0 * x2 + 17.0 * x7 - 2.0 * x8).ge(0.0))?;
    pb.subject_to((8.0 * x1 - 2.0 * x2 - 5.0 * x9 + 2.0 * x10 + 12.0).ge(0.0))?;
    pb.subject_to(
        (-3.0 * (x1 - 2.0).sq() - 4.0 * (x2 - 3.0).sq() - 2.0 * x3.sq() + 7.0 * x4 + 120.0).ge(0.0),
    )?;
    pb.subject_to((-5.0 * x1.sq() - 8.0 * x2 - (x3 - 6.0).sq() + 2.0 * x4 + 40.0).ge(0.0))?;
    pb.subject_to(
        (-0.5 * (x1 - 8.0).sq() - 2.0 * (x2 - 4.0).sq() - 3.0 * x5.sq() + x6 + 30.0).ge(0.0),
    )?;
    pb.subject_to(
        (-x1.sq() - 2.0 * (x2 - 2.0).sq() + 2.0 * x1 * x2 - 14.0 * x5 + 6.0 * x6).ge(0.0),
    )?;
    pb.subject_to((3.0 * x1 - 6.0 * x2 - 12.0 * (x9 - 8.0).sq() + 7.0 * x10).ge(0.0))?;
    case(pb, 24.3062091)
}

// ============================================================== mixed

/// HS81 problem 71 (IPOPT's tutorial problem); f* = 17.0140173.
pub fn hs071() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4]) = vars(&mut pb, [1.0, 5.0, 5.0, 1.0])?;
    pb.set_bounds(&x, 1.0, 5.0)?;
    pb.minimize(x1 * x4 * (x1 + x2 + x3) + x3);
    pb.subject_to((x1 * x2 * x3 * x4).ge(25.0))?;
    pb.subject_to(x.sumsqr().eq(40.0))?;
    case(pb, 17.0140173)
}

/// HS81 problem 73 (cattle feed); f* = 29.894378.
pub fn hs073() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4]) = vars(&mut pb, [1.0; 4])?;
    pb.set_bounds(&x, 0.0, INF)?;
    pb.minimize(24.55 * x1 + 26.75 * x2 + 39.0 * x3 + 40.5 * x4);
    pb.subject_to((2.3 * x1 + 5.6 * x2 + 11.1 * x3 + 1.3 * x4).ge(5.0))?;
    let sd = (0.28 * x1.sq() + 0.19 * x2.sq() + 20.5 * x3.sq() + 0.62 * x4.sq()).sqrt();
    pb.subject_to((12.0 * x1 + 11.9 * x2 + 41.8 * x3 + 52.1 * x4 - 21.0 - 1.645 * sd).ge(0.0))?;
    pb.subject_to(x.sum().eq(1.0))?;
    case(pb, 29.894378)
}

fn hs080_81(extra: impl Fn(Expr, Expr) -> Expr) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4, x5]) = vars(&mut pb, [-2.0, 2.0, 2.0, -1.0, -1.0])?;
    bounds(
        &mut pb,
        &x,
        &[-2.3, -2.3, -3.2, -3.2, -3.2],
        &[2.3, 2.3, 3.2, 3.2, 3.2],
    )?;
    pb.minimize((x1 * x2 * x3 * x4 * x5).exp() + extra(x1, x2));
    pb.subject_to(x.sumsqr().eq(10.0))?;
    pb.subject_to((x2 * x3 - 5.0 * x4 * x5).eq(0.0))?;
    pb.subject_to((x1.powi(3) + x2.powi(3)).eq(-1.0))?;
    Ok(pb)
}

/// HS81 problem 80; f* = 0.0539498478.
pub fn hs080() -> Built {
    case(hs080_81(|_, _| Expr::zero())?, 0.0539498478)
}

/// HS81 problem 81 (HS80 plus a term that vanishes on the feasible set); f* = 0.0539498478.
pub fn hs081() -> Built {
    case(
        hs080_81(|x1, x2| -0.5 * (x1.powi(3) + x2.powi(3) + 1.0).sq())?,
        0.0539498478,
    )
}

/// HS81 problem 106 (heat exchanger design); f* = 7049.24802 \[S08\] (printed 7049.330923
/// in \[HS81\]).
pub fn hs106() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4, x5, x6, x7, x8]) = vars(
        &mut pb,
        [5000.0, 5000.0, 5000.0, 200.0, 350.0, 150.0, 225.0, 425.0],
    )?;
    bounds(
        &mut pb,
        &x,
        &[100.0, 1000.0, 1000.0, 10.0, 10.0, 10.0, 10.0, 10.0],
        &[
            10000.0, 10000.0, 10000.0, 1000.0, 1000.0, 1000.0, 1000.0, 1000.0,
        ],
    )?;
    pb.minimize(x1 + x2 + x3);
    pb.subject_to((1.0 - 0.0025 * (x4 + x6)).ge(0.0))?;
    pb.subject_to((1.0 - 0.0025 * (x5 + x7 - x4)).ge(0.0))?;
    pb.subject_to((1.0 - 0.01 * (x8 - x5)).ge(0.0))?;
    pb.subject_to((x1 * x6 - 833.33252 * x4 - 100.0 * x1 + 83333.333).ge(0.0))?;
    pb.subject_to((x2 * x7 - 1250.0 * x5 - x2 * x4 + 1250.0 * x4).ge(0.0))?;
    pb.subject_to((x3 * x8 - 1250000.0 - x3 * x5 + 2500.0 * x5).ge(0.0))?;
    case(pb, 7049.24802)
}

/// HS81 problem 108 (largest hexagon of diameter 1); f* = −√3/2 = −0.8660254038. Many
/// local maxima of the area: from the standard start (all ones) IPOPT stops at the
/// KKT point with f = −0.6749814497 (a smaller hexagon), also accepted here.
pub fn hs108() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4, x5, x6, x7, x8, x9]) = vars(&mut pb, [1.0; 9])?;
    pb.set_bounds(&x[8..9], 0.0, INF)?;
    pb.minimize(-0.5 * (x1 * x4 - x2 * x3 + x3 * x9 - x5 * x9 + x5 * x8 - x6 * x7));
    pb.subject_to((1.0 - x3.sq() - x4.sq()).ge(0.0))?;
    pb.subject_to((1.0 - x9.sq()).ge(0.0))?;
    pb.subject_to((1.0 - x5.sq() - x6.sq()).ge(0.0))?;
    pb.subject_to((1.0 - x1.sq() - (x2 - x9).sq()).ge(0.0))?;
    pb.subject_to((1.0 - (x1 - x5).sq() - (x2 - x6).sq()).ge(0.0))?;
    pb.subject_to((1.0 - (x1 - x7).sq() - (x2 - x8).sq()).ge(0.0))?;
    pb.subject_to((1.0 - (x3 - x5).sq() - (x4 - x6).sq()).ge(0.0))?;
    pb.subject_to((1.0 - (x3 - x7).sq() - (x4 - x8).sq()).ge(0.0))?;
    pb.subject_to((1.0 - x7.sq() - (x8 - x9).sq()).ge(0.0))?;
    pb.subject_to((x1 * x4 - x2 * x3).ge(0.0))?;
    pb.subject_to((x3 * x9).ge(0.0))?;
    pb.subject_to((-x5 * x9).ge(0.0))?;
    pb.subject_to((x5 * x8 - x6 * x7).ge(0.0))?;
    Ok(Case {
        local: &[-0.6749814497],
        ..case(pb, -0.75f64.sqrt())?
    })
}

/// HS81 problem 114 (alkylation process); f* = −1768.80696.
pub fn hs114() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4, x5, x6, x7, x8, x9, x10]) = vars(
        &mut pb,
        [
            1745.0, 12000.0, 110.0, 3048.0, 1974.0, 89.2, 92.8, 8.0, 3.6, 145.0,
        ],
    )?;
    bounds(
        &mut pb,
        &x,
        &[1e-5, 1e-5, 1e-5, 1e-5, 1e-5, 85.0, 90.0, 3.0, 1.2, 145.0],
        &[
            2000.0, 16000.0, 120.0, 5000.0, 2000.0, 93.0, 95.0, 12.0, 4.0, 162.0,
        ],
    )?;
    let (a, b) = (0.99, 0.9);
    let g1 = 35.82 - 0.222 * x10 - b * x9;
    let g2 = -133.0 + 3.0 * x7 - a * x10;
    let g5 = 1.12 * x1 + 0.13167 * x1 * x8 - 0.00667 * x1 * x8.sq() - a * x4;
    let g6 = 57.425 + 1.098 * x8 - 0.038 * x8.sq() + 0.325 * x6 - a * x7;
    pb.minimize(5.04 * x1 + 0.035 * x2 + 10.0 * x3 + 3.36 * x5 - 0.063 * x4 * x7);
    pb.subject_to(g1.ge(0.0))?;
    pb.subject_to(g2.ge(0.0))?;
    pb.subject_to((-g1 + x9 * (1.0 / b - b)).ge(0.0))?;
    pb.subject_to((-g2 + (1.0 / a - a) * x10).ge(0.0))?;
    pb.subject_to(g5.ge(0.0))?;
    pb.subject_to(g6.ge(0.0))?;
    pb.subject_to((-g5 + (1.0 / a - a) * x4).ge(0.0))?;
    pb.subject_to((-g6 + (1.0 / a - a) * x7).ge(0.0))?;
    pb.subject_to((1.22 * x4 - x1 - x5).eq(0.0))?;
    pb.subject_to((98000.0 * x3 / (x4 * x9 + 1000.0 * x3) - x6).eq(0.0))?;
    pb.subject_to(((x2 + x5) / x1 - x8).eq(0.0))?;
    case(pb, -1768.80696)
}

/// HS81 problem 116 (3-stage membrane separation); f* = 97.5874731. \[HS81\] prints
/// f* = 97.588409 with an x* at which f = x11 + x12 + x13 = 97.58743 (to its printed
/// digits): the printed f* is off in the 5th digit. 97.5874731 is f at the same x* to
/// full precision (IPOPT with tol 1e-13).
pub fn hs116() -> Built {
    let mut pb = Problem::new();
    let (x, [x1, x2, x3, x4, x5, x6, x7, x8, x9, x10, x11, x12, x13]) = vars(
        &mut pb,
        [
            0.5, 0.8, 0.9, 0.1, 0.14, 0.5, 489.0, 80.0, 650.0, 450.0, 150.0, 150.0, 150.0,
        ],
    )?;
    bounds(
        &mut pb,
        &x,
        &[
            0.1, 0.1, 0.1, 1e-4, 0.1, 0.1, 0.1, 0.1, 500.0, 0.1, 1.0, 1e-4, 1e-4,
        ],
        &[
            1.0, 1.0, 1.0, 0.1, 0.9, 0.9, 1000.0, 1000.0, 1000.0, 500.0, 150.0, 150.0, 150.0,
        ],
    )?;
    let (a, b, c, d, e, f) = (0.002, 1.262626, 1.231059, 0.03475, 0.975, 0.00975);
    pb.minimize(x11 + x12 + x13);
    pb.subject_to((x3 - x2).ge(0.0))?;
    pb.subject_to((x2 - x1).ge(0.0))?;
    pb.subject_to((1.0 - a * x7 + a * x8).ge(0.0))?;
    pb.subject_to((x11 + x12 + x13).ge(50.0))?;
    pb.subject_to((x13 - b * x10 + c * x3 * x10).ge(0.0))?;
    pb.subject_to((x5 - d * x2 - e * x2 * x5 + f * x2.sq()).ge(0.0))?;
    pb.subject_to((x6 - d * x3 - e * x3 * x6 + f * x3.sq()).ge(0.0))?;
    pb.subject_to((x4 - d * x1 - e * x1 * x4 + f * x1.sq()).ge(0.0))?;
    pb.subject_to((x12 - b * x9 + c * x2 * x9).ge(0.0))?;
    pb.subject_to((x11 - b * x8 + c * x1 * x8).ge(0.0))?;
    pb.subject_to((x5 * x7 - x1 * x8 - x4 * x7 + x4 * x8).ge(0.0))?;
    pb.subject_to((1.0 - a * (x2 * x9 + x5 * x8 - x1 * x8 - x6 * x9) - x5 - x6).ge(0.0))?;
    pb.subject_to((x2 * x9 - x3 * x10 - x6 * x9 - 500.0 * x2 + 500.0 * x6 + x2 * x10).ge(0.0))?;
    pb.subject_to((x2 - 0.9 - a * (x2 * x10 - x3 * x10)).ge(0.0))?;
    pb.subject_to((x11 + x12 + x13).le(250.0))?;
    case(pb, 97.5874731)
}

/// HS81 problem 118; f* = 664.8204500. Ranged constraints −7 ≤ x_{3j+k} − x_{3j−3+k} ≤ 6
/// (k = 1, 3) or 7 (k = 2), j = 1..4, and demands 60, 50, 70, 85, 100 per period.
pub fn hs118() -> Built {
    let mut pb = Problem::new();
    let mut x0 = [0.0; 15];
    x0[..3].copy_from_slice(&[20.0, 55.0, 15.0]);
    for k in 1..5 {
        x0[3 * k..3 * k + 3].copy_from_slice(&[20.0, 60.0, 20.0]);
    }
    let (x, _) = vars(&mut pb, x0)?;
    let mut lo = [0.0; 15];
    let mut hi = [0.0; 15];
    lo[..3].copy_from_slice(&[8.0, 43.0, 3.0]);
    hi[..3].copy_from_slice(&[21.0, 57.0, 16.0]);
    for k in 1..5 {
        hi[3 * k..3 * k + 3].copy_from_slice(&[90.0, 120.0, 60.0]);
    }
    bounds(&mut pb, &x, &lo, &hi)?;
    let f = (0..5)
        .map(|k| {
            let (a, b, c) = (x[3 * k], x[3 * k + 1], x[3 * k + 2]);
            2.3 * a + 1e-4 * a.sq() + 1.7 * b + 1e-4 * b.sq() + 2.2 * c + 1.5e-4 * c.sq()
        })
        .sum();
    pb.minimize(f);
    for j in 1..5 {
        pb.subject_to(bounded(0.0, x[3 * j] - x[3 * j - 3] + 7.0, 13.0))?;
        pb.subject_to(bounded(0.0, x[3 * j + 1] - x[3 * j - 2] + 7.0, 14.0))?;
        pb.subject_to(bounded(0.0, x[3 * j + 2] - x[3 * j - 1] + 7.0, 13.0))?;
    }
    for (k, demand) in [60.0, 50.0, 70.0, 85.0, 100.0].into_iter().enumerate() {
        pb.subject_to((x[3 * k] + x[3 * k + 1] + x[3 * k + 2]).ge(demand))?;
    }
    case(pb, 664.82045)
}
