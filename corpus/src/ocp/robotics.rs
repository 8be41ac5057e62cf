//! Classic robotics optimal-control problems: cart-pole swing-up (trapezoidal and RK4
//! multiple shooting), planar quadrotor point to point around an obstacle (RK4 multiple
//! shooting), two-link arm in minimum time (trapezoidal).
use super::{fix, node, shooting, trapezoid};
use nlp::{BuildError, Problem, Relation};
use std::f64::consts::PI;
use symx::Expr;

/// Kelly (2017) §6: cart 1 kg, pole 0.3 kg, 0.5 m, swing up in T = 2 s to cart position
/// d = 1 m, |cart position| ≤ 2 m, |force| ≤ 20 N.
const CP: (f64, f64, f64, f64, f64, f64, f64, f64) = (1.0, 0.3, 0.5, 9.81, 2.0, 1.0, 2.0, 20.0);

/// Cart-pole dynamics of Kelly (2017), Appendix E (eqs. E.1–E.2); states (q1, q2, q̇1, q̇2).
fn cartpole_rhs(x: &[Expr], u: Expr) -> Vec<Expr> {
    let (m1, m2, l, g, ..) = CP;
    let (s, c) = (x[1].sin(), x[1].cos());
    let den = m1 + m2 * (1.0 - c.sq());
    let a1 = (l * m2 * s * x[3].sq() + u + m2 * g * c * s) / den;
    let a2 = -(l * m2 * c * s * x[3].sq() + u * c + (m1 + m2) * g * s) / (l * den);
    vec![x[2], x[3], a1, a2]
}

/// Cart-pole variables (one vector per state), bounds, boundary conditions and Kelly's
/// initial guess (positions interpolated linearly, velocities and force zero).
fn cartpole_states(pb: &mut Problem, n: usize) -> Result<[symx::Matrix; 4], BuildError> {
    let (.., d, dmax, _) = CP;
    let q1 = pb.variable("q1", n + 1)?;
    let q2 = pb.variable("q2", n + 1)?;
    let dq1 = pb.variable("dq1", n + 1)?;
    let dq2 = pb.variable("dq2", n + 1)?;
    pb.set_bounds(&q1, -dmax, dmax)?;
    let s = |k: usize| k as f64 / n as f64;
    pb.set_initial(&q1, &(0..=n).map(|k| d * s(k)).collect::<Vec<_>>())?;
    pb.set_initial(&q2, &(0..=n).map(|k| PI * s(k)).collect::<Vec<_>>())?;
    fix(pb, &[q1[0], q2[0], dq1[0], dq2[0]], &[0.0; 4])?;
    fix(pb, &[q1[n], q2[n], dq1[n], dq2[n]], &[d, PI, 0.0, 0.0])?;
    Ok([q1, q2, dq1, dq2])
}

/// Cart-pole swing-up, min `∫u²`, trapezoidal rule (force at the nodes). n = 5(n + 1).
pub fn cartpole_trap(n: usize) -> Result<Problem, BuildError> {
    let (.., t, _, _, umax) = CP;
    let mut pb = Problem::new();
    let [q1, q2, dq1, dq2] = cartpole_states(&mut pb, n)?;
    let u = pb.variable("u", n + 1)?;
    pb.set_bounds(&u, -umax, umax)?;
    let h = t / n as f64;
    let states: [&[Expr]; 4] = [&q1, &q2, &dq1, &dq2];
    let mut cost = Expr::zero();
    for k in 0..n {
        let (a, b) = (node(&states, k), node(&states, k + 1));
        let (fa, fb) = (cartpole_rhs(&a, u[k]), cartpole_rhs(&b, u[k + 1]));
        trapezoid(&mut pb, "dynamics", [&a, &b], [&fa, &fb], Expr::constant(h))?;
        cost += 0.5 * h * (u[k].sq() + u[k + 1].sq());
    }
    pb.minimize(cost);
    Ok(pb)
}

/// Cart-pole swing-up, min `∫u²`, RK4 multiple shooting with a piecewise-constant force.
/// n = 5n + 4.
pub fn cartpole_rk4(n: usize) -> Result<Problem, BuildError> {
    let (.., t, _, _, umax) = CP;
    let mut pb = Problem::new();
    let [q1, q2, dq1, dq2] = cartpole_states(&mut pb, n)?;
    let u = pb.variable("u", n)?;
    pb.set_bounds(&u, -umax, umax)?;
    let h = t / n as f64;
    let states: [&[Expr]; 4] = [&q1, &q2, &dq1, &dq2];
    let mut cost = Expr::zero();
    for k in 0..n {
        let uk = u[k];
        let f = move |x: &[Expr]| cartpole_rhs(x, uk);
        let (a, b) = (node(&states, k), node(&states, k + 1));
        shooting(&mut pb, "dynamics", &f, [&a, &b], Expr::constant(h))?;
        cost += h * uk.sq();
    }
    pb.minimize(cost);
    Ok(pb)
}

/// Planar quadrotor (Tedrake, Underactuated Robotics, ch. 3): mass 1 kg, arm 0.25 m,
/// inertia 0.0125 kg·m² (this corpus's choice), thrusts 0 ≤ u ≤ 2mg. From rest at (0, 0)
/// to rest at (4, 2) in 4 s around the disc of radius 0.5 at (2, 1.1), min `∫u₁² + u₂²`;
/// RK4 multiple shooting, piecewise-constant thrusts; initial guess: the straight line
/// (through the obstacle) at hover thrust. n = 8n + 6.
pub fn quadrotor_rk4(n: usize) -> Result<Problem, BuildError> {
    let (mass, arm, inertia, g, t) = (1.0, 0.25, 0.0125, 9.81, 4.0);
    let (goal, centre, radius) = ([4.0, 2.0], [2.0, 1.1], 0.5);
    let mut pb = Problem::new();
    let names = ["px", "py", "theta", "vx", "vy", "omega"];
    let states = names
        .iter()
        .map(|s| pb.variable(s, n + 1))
        .collect::<Result<Vec<symx::Matrix>, _>>()?;
    let u1 = pb.variable("u1", n)?;
    let u2 = pb.variable("u2", n)?;
    pb.set_bounds(&u1, 0.0, 2.0 * mass * g)?;
    pb.set_bounds(&u2, 0.0, 2.0 * mass * g)?;
    pb.set_initial(&u1, &vec![mass * g / 2.0; n])?;
    pb.set_initial(&u2, &vec![mass * g / 2.0; n])?;
    for (axis, &end) in goal.iter().enumerate() {
        let line: Vec<f64> = (0..=n).map(|k| end * k as f64 / n as f64).collect();
        pb.set_initial(&states[axis], &line)?;
    }
    let refs: Vec<&[Expr]> = states.iter().map(|s| &s[..]).collect();
    let h = Expr::constant(t / n as f64);
    let mut cost = Expr::zero();
    for k in 0..n {
        let (a, b) = (u1[k], u2[k]);
        let f = move |x: &[Expr]| {
            let thrust = a + b;
            vec![
                x[3],
                x[4],
                x[5],
                -thrust * x[2].sin() / mass,
                thrust * x[2].cos() / mass - g,
                arm * (a - b) / inertia,
            ]
        };
        let (xa, xb) = (node(&refs, k), node(&refs, k + 1));
        shooting(&mut pb, "dynamics", &f, [&xa, &xb], h)?;
        cost += (t / n as f64) * (a.sq() + b.sq());
        if k > 0 {
            let d2 = (xa[0] - centre[0]).sq() + (xa[1] - centre[1]).sq();
            pb.subject_to_named("obstacle", d2.ge(radius * radius))?;
        }
    }
    fix(&mut pb, &node(&refs, 0), &[0.0; 6])?;
    fix(
        &mut pb,
        &node(&refs, n),
        &[goal[0], goal[1], 0.0, 0.0, 0.0, 0.0],
    )?;
    pb.minimize(cost);
    Ok(pb)
}

/// Two-link planar arm in a horizontal plane, point masses 1 kg at the ends of links of
/// 1 m, `M(q)q̈ + c(q, q̇) = τ`, |τᵢ| ≤ 1 N·m; from rest at q = (0, 0) to rest at
/// q = (π/2, π/2) in minimum time; trapezoidal rule with torques at the nodes; initial
/// guess: tf = 3 s, joint angles interpolated linearly. n = 6(n + 1) + 1.
pub fn arm2_trap(n: usize) -> Result<Problem, BuildError> {
    let (m1, m2, l1, l2) = (1.0, 1.0, 1.0, 1.0);
    let goal = [PI / 2.0, PI / 2.0];
    let mut pb = Problem::new();
    let names = ["q1", "q2", "dq1", "dq2"];
    let states = names
        .iter()
        .map(|s| pb.variable(s, n + 1))
        .collect::<Result<Vec<symx::Matrix>, _>>()?;
    let tau1 = pb.variable("tau1", n + 1)?;
    let tau2 = pb.variable("tau2", n + 1)?;
    let tf = pb.scalar_variable("tf")?;
    pb.set_bounds(&tau1, -1.0, 1.0)?;
    pb.set_bounds(&tau2, -1.0, 1.0)?;
    pb.set_bounds(&[tf], 0.0, f64::INFINITY)?;
    pb.set_initial(&[tf], &[3.0])?;
    for (axis, &end) in goal.iter().enumerate() {
        let line: Vec<f64> = (0..=n).map(|k| end * k as f64 / n as f64).collect();
        pb.set_initial(&states[axis], &line)?;
    }
    let refs: Vec<&[Expr]> = states.iter().map(|s| &s[..]).collect();
    let rhs = |k: usize| -> Vec<Expr> {
        let (q2, dq1, dq2) = (refs[1][k], refs[2][k], refs[3][k]);
        let (c, s) = (q2.cos(), q2.sin());
        let m11 = (m1 + m2) * l1 * l1 + m2 * l2 * l2 + 2.0 * m2 * l1 * l2 * c;
        let m12 = m2 * l2 * l2 + m2 * l1 * l2 * c;
        let m22 = m2 * l2 * l2;
        let hh = m2 * l1 * l2 * s;
        let r1 = tau1[k] + hh * (2.0 * dq1 * dq2 + dq2.sq());
        let r2 = tau2[k] - hh * dq1.sq();
        let det = m11 * m22 - m12.sq();
        vec![
            dq1,
            dq2,
            (m22 * r1 - m12 * r2) / det,
            (m11 * r2 - m12 * r1) / det,
        ]
    };
    let h = tf / n as f64;
    for k in 0..n {
        let (a, b) = (node(&refs, k), node(&refs, k + 1));
        trapezoid(&mut pb, "dynamics", [&a, &b], [&rhs(k), &rhs(k + 1)], h)?;
    }
    fix(&mut pb, &node(&refs, 0), &[0.0; 4])?;
    fix(&mut pb, &node(&refs, n), &[goal[0], goal[1], 0.0, 0.0])?;
    pb.minimize(tf);
    Ok(pb)
}
