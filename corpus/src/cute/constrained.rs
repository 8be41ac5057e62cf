//! Constrained CUTEst and COPS problems (none from Hock–Schittkowski), following the
//! statements read in JuliaSmoothOptimizers/OptimizationProblems.jl (`src/PureJuMP/<name>.jl`).
//! Rows on a single variable become bounds (the builder's rule), as in AMPL and JuMP.
use super::unconstrained::vars;
use nlp::{bounded, BuildError, Constraint, Problem, Relation};
use std::f64::consts::PI;
use symx::Expr;

fn sum(range: impl Iterator<Item = usize>, f: impl Fn(usize) -> Expr) -> Expr {
    range.fold(Expr::zero(), |acc, i| acc + f(i))
}

/// BT1 (Byrd and Tapia).
pub fn bt1(_: usize) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let v = vars(&mut pb, 2, |i| [0.08, 0.06][i - 1])?;
    pb.minimize(100.0 * v[0].sq() + 100.0 * v[1].sq() - v[0] - 100.0);
    pb.subject_to_named("circle", (v[0].sq() + v[1].sq() - 1.0).eq(0.0))?;
    Ok(pb)
}

/// CATENARY: a chain of N + 1 unit links in 3-D, n = 3(N + 2) variables.
pub fn catenary(n: usize) -> Result<Problem, BuildError> {
    let big_n = n / 3 - 2;
    let d = (big_n + 1) as f64 * 0.6;
    let mg = 9.81 * 500.0 / (big_n + 1) as f64;
    let mut pb = Problem::new();
    let v = vars(&mut pb, n, |i| {
        let (k, c) = ((i - 1) / 3, (i - 1) % 3);
        match c {
            0 => k as f64 * d / (big_n + 1) as f64,
            1 => -(k as f64) * d / (big_n + 1) as f64,
            _ => 0.0,
        }
    })?;
    let x = |i: usize| v[i - 1];
    pb.set_bounds(&[x(1), x(2), x(3)], 0.0, 0.0)?;
    pb.set_bounds(&[x(n - 2)], d, d)?;
    pb.minimize(
        mg * x(2) / 2.0 + sum(1..big_n + 1, |i| mg * x(2 + 3 * i)) + mg * x(3 * big_n + 5) / 2.0,
    );
    let rows = (1..=big_n + 1).map(|i| {
        ((x(1 + 3 * i) - x(3 * i - 2)).sq()
            + (x(2 + 3 * i) - x(3 * i - 1)).sq()
            + (x(3 + 3 * i) - x(3 * i)).sq()
            - 1.0)
            .eq(0.0)
    });
    pb.subject_to_named("link", Constraint::all(rows))?;
    Ok(pb)
}

/// CLNLBEAM: clamped nonlinear beam, n = 3(N + 1) variables, trapezoidal.
pub fn clnlbeam(n: usize) -> Result<Problem, BuildError> {
    let big_n = n / 3 - 1;
    let (h, alpha) = (1.0 / big_n as f64, 350.0);
    let mut pb = Problem::new();
    let t = pb.variable("t", big_n + 1)?;
    let x = pb.variable("x", big_n + 1)?;
    let u = pb.variable("u", big_n + 1)?;
    pb.set_bounds(&t, -1.0, 1.0)?;
    pb.set_bounds(&x, -0.05, 0.05)?;
    pb.minimize(sum(0..big_n, |i| {
        0.5 * h * (u[i + 1].sq() + u[i].sq()) + 0.5 * alpha * h * (t[i + 1].cos() + t[i].cos())
    }));
    let rows =
        (0..big_n).map(|i| (x[i + 1] - x[i] - 0.5 * h * (t[i + 1].sin() + t[i].sin())).eq(0.0));
    pb.subject_to_named("x_dynamics", Constraint::all(rows))?;
    let rows = (0..big_n).map(|i| (t[i + 1] - t[i] - 0.5 * h * u[i + 1] - 0.5 * h * u[i]).eq(0.0));
    pb.subject_to_named("t_dynamics", Constraint::all(rows))?;
    Ok(pb)
}

/// HOVERCRAFT1D: minimum-energy double integrator over T = n/3 steps.
pub fn hovercraft1d(n: usize) -> Result<Problem, BuildError> {
    let t = n / 3;
    let mut pb = Problem::new();
    let x = pb.variable("x", t)?;
    let v = pb.variable("v", t)?;
    let u = pb.variable("u", t - 1)?;
    pb.set_bounds(&[x[0], v[0], v[t - 1]], 0.0, 0.0)?;
    pb.set_bounds(&[x[t - 1]], 100.0, 100.0)?;
    pb.subject_to_named(
        "position",
        Constraint::all((0..t - 1).map(|i| (x[i + 1] - x[i] - v[i]).eq(0.0))),
    )?;
    pb.subject_to_named(
        "velocity",
        Constraint::all((0..t - 1).map(|i| (v[i + 1] - v[i] - u[i]).eq(0.0))),
    )?;
    pb.minimize(0.5 * sum(0..t - 1, |i| u[i].sq()));
    Ok(pb)
}

/// CONTROLINVESTMENT: investment control, n = 2N variables, trapezoidal.
pub fn controlinvestment(n: usize) -> Result<Problem, BuildError> {
    let big_n = n / 2;
    let (h, gamma) = (1.0 / big_n as f64, 3.0);
    let mut pb = Problem::new();
    let x = pb.variable("x", big_n)?;
    let u = pb.variable("u", big_n)?;
    pb.set_initial(&x, &vec![1.0; big_n])?;
    pb.set_bounds(&u, 0.0, 1.0)?;
    pb.set_bounds(&[x[0]], 1.0, 1.0)?;
    let f = |k: usize| (u[k] - 1.0) * x[k];
    pb.minimize(0.5 * h * sum(0..big_n - 1, |k| f(k) + f(k + 1)));
    let rows = (0..big_n - 1)
        .map(|k| (x[k + 1] - x[k] - 0.5 * h * gamma * (u[k] * x[k] + u[k + 1] * x[k + 1])).eq(0.0));
    pb.subject_to_named("dynamics", Constraint::all(rows))?;
    Ok(pb)
}

/// ELEC (COPS 3.0 §2): `np` electrons on the unit sphere of least potential energy.
pub fn elec(np: usize) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let s = |i: usize| i as f64 / np as f64;
    let v = vars(&mut pb, 3 * np, |k| {
        let (c, i) = ((k - 1) / np, (k - 1) % np + 1);
        let (theta, phi) = (2.0 * PI * s(i), PI * s(i));
        [
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ][c]
    })?;
    let p = |c: usize, i: usize| v[c * np + i];
    let mut f = Expr::zero();
    for i in 0..np {
        for j in i + 1..np {
            f += 1.0
                / ((p(0, j) - p(0, i)).sq() + (p(1, j) - p(1, i)).sq() + (p(2, j) - p(2, i)).sq())
                    .sqrt();
        }
    }
    pb.minimize(f);
    let rows = (0..np).map(|k| (p(0, k).sq() + p(1, k).sq() + p(2, k).sq()).eq(1.0));
    pb.subject_to_named("sphere", Constraint::all(rows))?;
    Ok(pb)
}

/// TORSION (COPS 3.0 §11): elastic-plastic torsion on an `nx × nx` grid, (nx+2)² variables.
pub fn torsion(nx: usize) -> Result<Problem, BuildError> {
    let (c, h) = (5.0, 1.0 / (nx as f64 + 1.0));
    let area = 0.5 * h * h;
    let g = nx + 2;
    let dist =
        |i: usize, j: usize| ((i.min(nx + 1 - i) as f64) * h).min((j.min(nx + 1 - j) as f64) * h);
    let mut pb = Problem::new();
    let v = pb.variable("v", g * g)?;
    let at = |i: usize, j: usize| v[i * g + j];
    for i in 0..g {
        for j in 0..g {
            pb.set_bounds(&[at(i, j)], -dist(i, j), dist(i, j))?;
        }
    }
    pb.set_initial(
        &v,
        &(0..g * g).map(|k| dist(k / g, k % g)).collect::<Vec<_>>(),
    )?;
    let (mut lin, mut quad) = (Expr::zero(), Expr::zero());
    for i in 0..=nx {
        for j in 0..=nx {
            lin += at(i + 1, j) + at(i, j) + at(i, j + 1);
            quad += ((at(i + 1, j) - at(i, j)) / h).sq() + ((at(i, j + 1) - at(i, j)) / h).sq();
        }
    }
    for i in 1..=nx + 1 {
        for j in 1..=nx + 1 {
            lin += at(i, j) + at(i - 1, j) + at(i, j - 1);
            quad += ((at(i, j) - at(i - 1, j)) / h).sq() + ((at(i, j) - at(i, j - 1)) / h).sq();
        }
    }
    pb.minimize(area * (quad / 2.0 - c * lin / 3.0));
    Ok(pb)
}

/// CHAIN (COPS 3.0 §1): hanging chain of length 4 between heights 1 and 3, `nh`
/// trapezoidal intervals, n = 4(nh + 1).
pub fn chain(nh: usize) -> Result<Problem, BuildError> {
    let (len, a, b, tmin) = (4.0, 1.0, 3.0, 0.25);
    let h = 1.0 / nh as f64;
    let mut pb = Problem::new();
    let s = |k: usize| k as f64 / nh as f64;
    let u0 = |k: usize| 4.0 * (b - a) * (s(k) - tmin);
    let x10 = |k: usize| 4.0 * (b - a) * s(k) * (0.5 * s(k) - tmin) + a;
    let u = pb.variable("u", nh + 1)?;
    let x1 = pb.variable("x1", nh + 1)?;
    let x2 = pb.variable("x2", nh + 1)?;
    let x3 = pb.variable("x3", nh + 1)?;
    pb.set_initial(&u, &(1..=nh + 1).map(u0).collect::<Vec<_>>())?;
    pb.set_initial(&x1, &(1..=nh + 1).map(x10).collect::<Vec<_>>())?;
    pb.set_initial(
        &x2,
        &(1..=nh + 1).map(|k| x10(k) * u0(k)).collect::<Vec<_>>(),
    )?;
    pb.set_initial(&x3, &(1..=nh + 1).map(u0).collect::<Vec<_>>())?;
    pb.minimize(x2[nh]);
    let ds = |j: usize| (1.0 + u[j].sq()).sqrt();
    let rows = (0..nh).map(|j| (x1[j + 1] - x1[j] - 0.5 * h * (u[j] + u[j + 1])).eq(0.0));
    pb.subject_to_named("x1_dynamics", Constraint::all(rows))?;
    pb.set_bounds(&[x1[0]], a, a)?;
    pb.set_bounds(&[x1[nh]], b, b)?;
    pb.set_bounds(&[x2[0], x3[0]], 0.0, 0.0)?;
    pb.set_bounds(&[x3[nh]], len, len)?;
    let rows = (0..nh)
        .map(|j| (x2[j + 1] - x2[j] - 0.5 * h * (x1[j] * ds(j) + x1[j + 1] * ds(j + 1))).eq(0.0));
    pb.subject_to_named("x2_dynamics", Constraint::all(rows))?;
    let rows = (0..nh).map(|j| (x3[j + 1] - x3[j] - 0.5 * h * (ds(j) + ds(j + 1))).eq(0.0));
    pb.subject_to_named("x3_dynamics", Constraint::all(rows))?;
    Ok(pb)
}

/// CAMSHAPE (COPS 3.0 §5): cam of maximal area, `n` radii, as a minimisation.
pub fn camshape(n: usize) -> Result<Problem, BuildError> {
    let (r_min, r_max, r_v, alpha) = (1.0, 2.0, 1.0, 1.5);
    let theta = 2.0 * PI / (5.0 * (n + 1) as f64);
    let mut pb = Problem::new();
    let v = vars(&mut pb, n, |_| (r_min + r_max) / 2.0)?;
    let x = |i: usize| v[i - 1];
    pb.set_bounds(&v, r_min, r_max)?;
    pb.minimize(-r_v * PI / n as f64 * sum(1..n + 1, x));
    let at = alpha * theta;
    pb.subject_to_named("end", bounded(-at, r_max - x(n), at))?;
    pb.subject_to_named("start", bounded(-at, x(1) - r_min, at))?;
    pb.subject_to_named(
        "smooth",
        Constraint::all((1..n).map(|i| bounded(-at, x(i + 1) - x(i), at))),
    )?;
    let ct = theta.cos();
    pb.subject_to_named(
        "convex_1",
        (-r_min * r_min - r_min * x(1) + 2.0 * r_min * x(1) * ct).le(0.0),
    )?;
    pb.subject_to_named(
        "convex_2",
        (-r_min * x(1) - x(1) * x(2) + 2.0 * r_min * x(2) * ct).le(0.0),
    )?;
    pb.subject_to_named(
        "convex_n",
        (-x(n - 1) * x(n) - x(n) * r_max + 2.0 * x(n - 1) * r_max * ct).le(0.0),
    )?;
    pb.subject_to_named(
        "convex_end",
        (-2.0 * r_max * x(n) + 2.0 * x(n).sq() * ct).le(0.0),
    )?;
    let rows = (2..n)
        .map(|i| (-x(i - 1) * x(i) - x(i) * x(i + 1) + 2.0 * x(i - 1) * x(i + 1) * ct).le(0.0));
    pb.subject_to_named("convex", Constraint::all(rows))?;
    Ok(pb)
}

/// LINCON: linear constraints, quartic objective, 15 variables.
pub fn lincon(_: usize) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let v = vars(&mut pb, 15, |_| 0.0)?;
    let x = |i: usize| v[i - 1];
    pb.minimize(sum(1..16, |i| i as f64 + x(i).powi(4)));
    pb.subject_to((15.0 * x(15)).eq(22.0))?;
    pb.subject_to((x(10) + 2.0 * x(11) + 3.0 * x(12)).ge(1.0))?;
    pb.subject_to((x(13) - x(14)).le(16.0))?;
    pb.subject_to((-2.0 * x(7)).eq(-1.0))?;
    pb.subject_to((4.0 * x(6)).eq(1.0))?;
    pb.subject_to((x(1) + 2.0 * x(2)).ge(-5.0))?;
    pb.subject_to((3.0 * x(1) + 4.0 * x(2)).ge(-6.0))?;
    for (j, k) in [(3, 9.0), (4, 12.0), (5, 15.0)] {
        pb.subject_to((k * x(j)).le([1.0, 2.0, 3.0][j - 3]))?;
    }
    pb.subject_to(bounded(-11.0, 5.0 * x(8) + 6.0 * x(9), 9.0))?;
    Ok(pb)
}

fn allinit_objective(x: &dyn Fn(usize) -> Expr) -> Expr {
    x(3) - 1.0
        + x(1).sq()
        + x(2).sq()
        + (x(3) + x(4)).sq()
        + x(3).sin().sq()
        + x(1).sq() * x(2).sq()
        + x(4)
        - 3.0
        + x(3).sin().sq()
        + (x(4) - 1.0).sq()
        + x(2).sq().sq()
        + (x(3).sq() + (x(4) + x(1)).sq()).sq()
        + (x(1) - 4.0 + x(4).sin().sq() + x(2).sq() * x(3).sq()).sq()
        + x(4).sin().powi(4)
}

fn allinit_base(circle: bool) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let v = vars(&mut pb, 4, |_| 0.0)?;
    let x = |i: usize| v[i - 1];
    pb.minimize(allinit_objective(&x));
    pb.set_bounds(&[x(4)], 2.0, 2.0)?;
    pb.set_bounds(&[x(2)], 1.0, f64::INFINITY)?;
    pb.set_bounds(&[x(3)], -1e10, 1.0)?;
    if circle {
        pb.subject_to_named("circle", (x(1).sq() + x(2).sq() - 1.0).le(0.0))?;
    }
    Ok(pb)
}

/// ALLINIT: bounds and a fixed variable.
pub fn allinit(_: usize) -> Result<Problem, BuildError> {
    allinit_base(false)
}

/// ALLINITC: ALLINIT with a nonlinear inequality.
pub fn allinitc(_: usize) -> Result<Problem, BuildError> {
    allinit_base(true)
}

/// ZANGWIL3: a linear system as a feasibility problem (constant objective).
pub fn zangwil3(_: usize) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let v = vars(&mut pb, 3, |i| [100.0, -1.0, 2.5][i - 1])?;
    pb.minimize(Expr::zero());
    pb.subject_to((v[0] - v[1] + v[2]).eq(0.0))?;
    pb.subject_to((-v[0] + v[1] + v[2]).eq(0.0))?;
    pb.subject_to((v[0] + v[1] - v[2]).eq(0.0))?;
    Ok(pb)
}
