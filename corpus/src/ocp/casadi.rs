//! CasADi's optimal-control examples: the race car (RK4 multiple shooting) and the Van der
//! Pol oscillator (RK4 multiple shooting and trapezoidal rule).
use super::{fix, node, shooting, trapezoid};
use nlp::{bounded, BuildError, Problem, Relation};
use std::f64::consts::PI;
use symx::Expr;

/// CasADi's race car (`docs/examples/python/race_car.py`; this repository's
/// `examples/src/race_car.rs`): minimum time over 1 m under a position-dependent speed limit,
/// RK4 multiple shooting on `n` intervals. Same formulation as the example, with one
/// variable vector per state (`pos`, `speed`). n = 3n + 3.
pub fn race_car(n: usize) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let pos = pb.variable("pos", n + 1)?;
    let speed = pb.variable("speed", n + 1)?;
    let u = pb.variable("U", n)?;
    let t = pb.scalar_variable("T")?;
    pb.minimize(t);
    let dt = t / n as f64;
    for k in 0..n {
        let uk = u[k];
        let f = move |x: &[Expr]| vec![x[1], uk - x[1]];
        let (a, b) = (node(&[&pos, &speed], k), node(&[&pos, &speed], k + 1));
        shooting(&mut pb, "dynamics", &f, [&a, &b], dt)?;
    }
    for k in 0..=n {
        pb.subject_to_named(
            "speed_limit",
            speed[k].le(1.0 - (2.0 * PI * pos[k]).sin() / 2.0),
        )?;
    }
    pb.subject_to(bounded(0.0, u.clone(), 1.0))?;
    fix(&mut pb, &[pos[0], speed[0], pos[n]], &[0.0, 0.0, 1.0])?;
    pb.subject_to(t.ge(0.0))?;
    pb.set_initial(&speed, &vec![1.0; n + 1])?;
    pb.set_initial(&[t], &[1.0])?;
    Ok(pb)
}

const VDP_T: f64 = 10.0;

fn vdp_rhs(x: &[Expr], u: Expr) -> Vec<Expr> {
    vec![(1.0 - x[1].sq()) * x[0] - x[1] + u, x[0]]
}

fn vdp_variables(
    pb: &mut Problem,
    n: usize,
    controls: usize,
) -> Result<[symx::Matrix; 3], BuildError> {
    let x1 = pb.variable("x1", n + 1)?;
    let x2 = pb.variable("x2", n + 1)?;
    let u = pb.variable("u", controls)?;
    pb.set_bounds(&u, -1.0, 1.0)?;
    pb.set_bounds(&x1, -0.25, f64::INFINITY)?;
    fix(pb, &[x1[0], x2[0]], &[0.0, 1.0])?;
    pb.set_initial(&[x2[0]], &[1.0])?;
    Ok([x1, x2, u])
}

/// Van der Pol oscillator of CasADi's `direct_multiple_shooting.py`: minimise
/// `∫₀¹⁰ x₁² + x₂² + u² dt`, `ẋ₁ = (1 − x₂²)x₁ − x₂ + u`, `ẋ₂ = x₁`, `|u| ≤ 1`,
/// `x₁ ≥ −0.25`, `x(0) = (0, 1)`; RK4 multiple shooting with one step per interval, the
/// cost integrated by the same RK4 step (as CasADi's example does). n = 3n + 2.
pub fn vdp_rk4(n: usize) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let [x1, x2, u] = vdp_variables(&mut pb, n, n)?;
    let h = Expr::constant(VDP_T / n as f64);
    let mut cost = Expr::zero();
    for k in 0..n {
        let uk = u[k];
        let f = move |x: &[Expr]| {
            let mut d = vdp_rhs(x, uk);
            d.push(x[0].sq() + x[1].sq() + uk.sq());
            d
        };
        let start = [x1[k], x2[k], Expr::zero()];
        let next = super::rk4(&f, &start, h);
        cost += next[2];
        let rows = [(x1[k + 1] - next[0]).eq(0.0), (x2[k + 1] - next[1]).eq(0.0)];
        pb.subject_to_named("dynamics", nlp::Constraint::all(rows))?;
    }
    pb.minimize(cost);
    Ok(pb)
}

/// The same Van der Pol problem with states and control at the nodes, trapezoidal rule
/// for the dynamics and the cost. n = 3(n + 1).
pub fn vdp_trap(n: usize) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let [x1, x2, u] = vdp_variables(&mut pb, n, n + 1)?;
    let h = VDP_T / n as f64;
    let lagrange = |k: usize| x1[k].sq() + x2[k].sq() + u[k].sq();
    let mut cost = Expr::zero();
    for k in 0..n {
        let (a, b) = (node(&[&x1, &x2], k), node(&[&x1, &x2], k + 1));
        let (fa, fb) = (vdp_rhs(&a, u[k]), vdp_rhs(&b, u[k + 1]));
        trapezoid(&mut pb, "dynamics", [&a, &b], [&fa, &fb], Expr::constant(h))?;
        cost += 0.5 * h * (lagrange(k) + lagrange(k + 1));
    }
    pb.minimize(cost);
    Ok(pb)
}
