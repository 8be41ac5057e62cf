//! COPS 3.0's control problems in COPS's own transcriptions (constants, bounds and initial
//! guesses as in the COPS statements; see the sources in [`super::FAMILIES`]).
//! Maximisations are written as minimisations of the negated objective.
use super::{fix, node, trapezoid};
use nlp::{BuildError, Constraint, Problem, Relation};
use symx::Expr;

/// Goddard rocket: maximise the final altitude, `nh` trapezoidal intervals, free final
/// time (`step` = tf/nh is a variable). n = 4(nh+1)+1.
pub fn rocket(nh: usize) -> Result<Problem, BuildError> {
    rocket_with(nh, false)
}

/// The Goddard rocket exactly as COPS writes it: the boundary values h(0), v(0), m(0) and
/// m(T) as equality rows `x − value = 0` with those entries' simple bounds dropped. Same
/// optimum as [`rocket`]; with simple bound detection on (the default) the rows become
/// the bounds [`rocket`] sets.
pub fn rocket_rows(nh: usize) -> Result<Problem, BuildError> {
    rocket_with(nh, true)
}

fn rocket_with(nh: usize, boundary_rows: bool) -> Result<Problem, BuildError> {
    let (h0, v0, m0, g0): (f64, f64, f64, f64) = (1.0, 0.0, 1.0, 1.0);
    let (tc, hc, vc, mc) = (3.5, 500.0, 620.0, 0.6);
    let c = 0.5 * (g0 * h0).sqrt();
    let mf = mc * m0;
    let dc = 0.5 * vc * m0 / g0;
    let tmax = tc * g0 * m0;
    let mut pb = Problem::new();
    let h = pb.variable("h", nh + 1)?;
    let v = pb.variable("v", nh + 1)?;
    let m = pb.variable("m", nh + 1)?;
    let t = pb.variable("T", nh + 1)?;
    let step = pb.scalar_variable("step")?;
    pb.set_bounds(&h, 1.0, f64::INFINITY)?;
    pb.set_bounds(&v, 0.0, f64::INFINITY)?;
    pb.set_bounds(&m, mf, m0)?;
    pb.set_bounds(&t, 0.0, tmax)?;
    pb.set_bounds(&[step], 0.0, f64::INFINITY)?;
    let s = |i: usize| i as f64 / nh as f64;
    pb.set_initial(&h, &vec![1.0; nh + 1])?;
    pb.set_initial(
        &v,
        &(0..=nh).map(|i| s(i) * (1.0 - s(i))).collect::<Vec<_>>(),
    )?;
    pb.set_initial(
        &m,
        &(0..=nh).map(|i| (mf - m0) * s(i) + m0).collect::<Vec<_>>(),
    )?;
    pb.set_initial(&t, &vec![tmax / 2.0; nh + 1])?;
    pb.set_initial(&[step], &[1.0 / nh as f64])?;
    let rhs = |i: usize| -> Vec<Expr> {
        let drag = dc * v[i].sq() * (-hc * (h[i] - h0) / h0).exp();
        let grav = g0 * (h0 / h[i]).sq();
        vec![v[i], (t[i] - drag - m[i] * grav) / m[i], -t[i] / c]
    };
    for i in 1..=nh {
        let (x0, x1) = (node(&[&h, &v, &m], i - 1), node(&[&h, &v, &m], i));
        trapezoid(
            &mut pb,
            "dynamics",
            [&x0, &x1],
            [&rhs(i - 1), &rhs(i)],
            step,
        )?;
    }
    let ends = [h[0], v[0], m[0], m[nh]];
    let values = [h0, v0, m0, mf];
    if boundary_rows {
        for x in ends {
            pb.set_bounds(&[x], f64::NEG_INFINITY, f64::INFINITY)?;
        }
        let rows = ends
            .iter()
            .zip(values)
            .map(|(&x, value)| (x - value).eq(0.0));
        pb.subject_to_named("boundary", Constraint::all(rows))?;
    } else {
        fix(&mut pb, &ends, &values)?;
    }
    pb.minimize(-h[nh]);
    Ok(pb)
}

/// Hang glider: maximise the range `x(tf)` in a thermal, `nh` trapezoidal intervals, free
/// final time. n = 5(nh+1)+1.
pub fn glider(nh: usize) -> Result<Problem, BuildError> {
    let (x_0, y_0, y_f) = (0.0, 1000.0, 900.0);
    let (vx_0, vx_f, vy_0, vy_f) = (13.23, 13.23, -1.288, -1.288);
    let (u_c, r_0, mass, g) = (2.5, 100.0, 100.0, 9.81);
    let (c0, c1, area, rho) = (0.034, 0.069662, 14.0, 1.13);
    let (cl_min, cl_max) = (0.0, 1.4);
    let mut pb = Problem::new();
    let tf = pb.scalar_variable("t_f")?;
    let x = pb.variable("x", nh + 1)?;
    let y = pb.variable("y", nh + 1)?;
    let vx = pb.variable("vx", nh + 1)?;
    let vy = pb.variable("vy", nh + 1)?;
    let cl = pb.variable("cL", nh + 1)?;
    pb.set_bounds(&[tf], 0.0, f64::INFINITY)?;
    pb.set_bounds(&x, 0.0, f64::INFINITY)?;
    pb.set_bounds(&vx, 0.0, f64::INFINITY)?;
    pb.set_bounds(&cl, cl_min, cl_max)?;
    let s = |k: usize| k as f64 / nh as f64;
    pb.set_initial(&[tf], &[1.0])?;
    pb.set_initial(&x, &(0..=nh).map(|k| x_0 + vx_0 * s(k)).collect::<Vec<_>>())?;
    pb.set_initial(
        &y,
        &(0..=nh)
            .map(|k| y_0 + s(k) * (y_f - y_0))
            .collect::<Vec<_>>(),
    )?;
    pb.set_initial(&vx, &vec![vx_0; nh + 1])?;
    pb.set_initial(&vy, &vec![vy_0; nh + 1])?;
    pb.set_initial(&cl, &vec![cl_max / 2.0; nh + 1])?;
    let rhs = |i: usize| -> Vec<Expr> {
        let r = (x[i] / r_0 - 2.5).sq();
        let u = u_c * (1.0 - r) * (-r).exp();
        let w = vy[i] - u;
        let speed = (vx[i].sq() + w.sq()).sqrt();
        let drag = 0.5 * (c0 + c1 * cl[i].sq()) * rho * area * speed.sq();
        let lift = 0.5 * cl[i] * rho * area * speed.sq();
        let ax = (-lift * (w / speed) - drag * (vx[i] / speed)) / mass;
        let ay = (lift * (vx[i] / speed) - drag * (w / speed)) / mass - g;
        vec![vx[i], vy[i], ax, ay]
    };
    let step = tf / nh as f64;
    for j in 1..=nh {
        let states: [&[Expr]; 4] = [&x, &y, &vx, &vy];
        let (a, b) = (node(&states, j - 1), node(&states, j));
        trapezoid(&mut pb, "dynamics", [&a, &b], [&rhs(j - 1), &rhs(j)], step)?;
    }
    fix(
        &mut pb,
        &[x[0], y[0], y[nh], vx[0], vx[nh], vy[0], vy[nh]],
        &[x_0, y_0, y_f, vx_0, vx_f, vy_0, vy_f],
    )?;
    pb.minimize(-x[nh]);
    Ok(pb)
}

/// Particle steering: minimum time to reach a given height and velocity, thrust angle as
/// control, `nh` trapezoidal intervals. n = 5(nh+1)+1.
pub fn steering(nh: usize) -> Result<Problem, BuildError> {
    let a = 100.0;
    let mut pb = Problem::new();
    let u = pb.variable("u", nh + 1)?;
    let x1 = pb.variable("x1", nh + 1)?;
    let x2 = pb.variable("x2", nh + 1)?;
    let x3 = pb.variable("x3", nh + 1)?;
    let x4 = pb.variable("x4", nh + 1)?;
    let tf = pb.scalar_variable("tf")?;
    let half_pi = std::f64::consts::FRAC_PI_2;
    pb.set_bounds(&u, -half_pi, half_pi)?;
    pb.set_bounds(&[tf], 0.0, f64::INFINITY)?;
    let s = |k: usize| k as f64 / nh as f64;
    pb.set_initial(&x2, &(0..=nh).map(|k| 5.0 * s(k)).collect::<Vec<_>>())?;
    pb.set_initial(&x3, &(0..=nh).map(|k| 45.0 * s(k)).collect::<Vec<_>>())?;
    pb.set_initial(&[tf], &[1.0])?;
    let rhs = |i: usize| vec![x3[i], x4[i], a * u[i].cos(), a * u[i].sin()];
    let h = tf / nh as f64;
    for i in 1..=nh {
        let states: [&[Expr]; 4] = [&x1, &x2, &x3, &x4];
        let (p, q) = (node(&states, i - 1), node(&states, i));
        trapezoid(&mut pb, "dynamics", [&p, &q], [&rhs(i - 1), &rhs(i)], h)?;
    }
    fix(&mut pb, &[x1[0], x2[0], x3[0], x4[0]], &[0.0; 4])?;
    fix(&mut pb, &[x2[nh], x3[nh], x4[nh]], &[5.0, 45.0, 0.0])?;
    pb.minimize(tf);
    Ok(pb)
}

/// Robot arm: minimum time to rotate a telescopic arm, `nh` trapezoidal intervals.
/// n = 9(nh+1)+1.
pub fn robot(nh: usize) -> Result<Problem, BuildError> {
    use std::f64::consts::PI;
    let len = 5.0;
    let (rho0, phi0) = (4.5, PI / 4.0);
    let mut pb = Problem::new();
    let rho = pb.variable("rho", nh + 1)?;
    let the = pb.variable("the", nh + 1)?;
    let phi = pb.variable("phi", nh + 1)?;
    let rho_dot = pb.variable("rho_dot", nh + 1)?;
    let the_dot = pb.variable("the_dot", nh + 1)?;
    let phi_dot = pb.variable("phi_dot", nh + 1)?;
    let u_rho = pb.variable("u_rho", nh + 1)?;
    let u_the = pb.variable("u_the", nh + 1)?;
    let u_phi = pb.variable("u_phi", nh + 1)?;
    let tf = pb.scalar_variable("tf")?;
    pb.set_bounds(&rho, 0.0, len)?;
    pb.set_bounds(&the, -PI, PI)?;
    pb.set_bounds(&phi, 0.0, PI)?;
    for u in [&u_rho, &u_the, &u_phi] {
        pb.set_bounds(u, -1.0, 1.0)?;
    }
    pb.set_bounds(&[tf], 0.0, f64::INFINITY)?;
    let s = |k: usize| k as f64 / nh as f64;
    pb.set_initial(&rho, &vec![rho0; nh + 1])?;
    pb.set_initial(
        &the,
        &(0..=nh)
            .map(|k| 2.0 * PI / 3.0 * s(k).powi(2))
            .collect::<Vec<_>>(),
    )?;
    pb.set_initial(&phi, &vec![phi0; nh + 1])?;
    pb.set_initial(
        &the_dot,
        &(0..=nh).map(|k| 4.0 * PI / 3.0 * s(k)).collect::<Vec<_>>(),
    )?;
    pb.set_initial(&[tf], &[1.0])?;
    let rhs = |i: usize| -> Vec<Expr> {
        let inertia = ((len - rho[i]).powi(3) + rho[i].powi(3)) / 3.0;
        let i_the = inertia * phi[i].sin().sq();
        vec![
            rho_dot[i],
            the_dot[i],
            phi_dot[i],
            u_rho[i] / len,
            u_the[i] / i_the,
            u_phi[i] / inertia,
        ]
    };
    let step = tf / nh as f64;
    let states: [&[Expr]; 6] = [&rho, &the, &phi, &rho_dot, &the_dot, &phi_dot];
    for j in 1..=nh {
        let (a, b) = (node(&states, j - 1), node(&states, j));
        trapezoid(&mut pb, "dynamics", [&a, &b], [&rhs(j - 1), &rhs(j)], step)?;
    }
    fix(
        &mut pb,
        &node(&states, 0),
        &[rho0, 0.0, phi0, 0.0, 0.0, 0.0],
    )?;
    fix(
        &mut pb,
        &node(&states, nh),
        &[rho0, 2.0 * PI / 3.0, phi0, 0.0, 0.0, 0.0],
    )?;
    pb.minimize(tf);
    Ok(pb)
}

fn factorial(k: usize) -> f64 {
    (1..=k).map(|i| i as f64).product()
}

/// Catalyst mixing: the mixing policy maximising the yield of a two-reaction process, 3-point
/// Gauss collocation on `nh` intervals (COPS's monomial-basis form). n = 23·nh + 2.
pub fn catmix(nh: usize) -> Result<Problem, BuildError> {
    const NC: usize = 3;
    let rho: [f64; 3] = [0.11270166537926, 0.5, 0.88729833462074];
    let h = 1.0 / nh as f64;
    let mut pb = Problem::new();
    let u = pb.variable("u", nh * NC)?;
    let v = pb.variable("v", nh * 2)?;
    let w = pb.variable("w", nh * NC * 2)?;
    let pp = pb.variable("pp", nh * NC * 2)?;
    let dpp = pb.variable("Dpp", nh * NC * 2)?;
    let ppf = pb.variable("ppf", 2)?;
    pb.set_bounds(&u, 0.0, 1.0)?;
    // COPS starts v, pp and ppf at mod(s, 2): 1 for species 1, 0 for species 2.
    let start = |len: usize| {
        (0..len)
            .map(|k| if k % 2 == 0 { 1.0 } else { 0.0 })
            .collect::<Vec<_>>()
    };
    pb.set_initial(&v, &start(nh * 2))?;
    pb.set_initial(&pp, &start(nh * NC * 2))?;
    pb.set_initial(&ppf, &[1.0, 0.0])?;
    let (iv, iw) = (
        |i: usize, s: usize| 2 * i + s,
        |i: usize, j: usize, s: usize| 2 * (NC * i + j) + s,
    );
    let mut rows = Vec::new();
    for i in 0..nh {
        for k in 0..NC {
            for s in 0..2 {
                let mut pk = v[iv(i, s)];
                let mut dk = Expr::zero();
                for j in 0..NC {
                    pk += h * w[iw(i, j, s)] * (rho[k].powi(j as i32 + 1) / factorial(j + 1));
                    dk += w[iw(i, j, s)] * (rho[k].powi(j as i32) / factorial(j));
                }
                rows.push((pp[iw(i, k, s)] - pk).eq(0.0));
                rows.push((dpp[iw(i, k, s)] - dk).eq(0.0));
            }
        }
    }
    pb.subject_to_named("collocation", Constraint::all(rows))?;
    let end = |i: usize, s: usize| {
        let mut e = v[iv(i, s)];
        for j in 0..NC {
            e += h * w[iw(i, j, s)] / factorial(j + 1);
        }
        e
    };
    for s in 0..2 {
        pb.subject_to_named("final", (ppf[s] - end(nh - 1, s)).eq(0.0))?;
    }
    for i in 0..nh - 1 {
        for s in 0..2 {
            pb.subject_to_named("continuity", (end(i, s) - v[iv(i + 1, s)]).eq(0.0))?;
        }
    }
    for i in 0..nh {
        for j in 0..NC {
            let (p1, p2) = (pp[iw(i, j, 0)], pp[iw(i, j, 1)]);
            let uij = u[NC * i + j];
            pb.subject_to_named("de1", (dpp[iw(i, j, 0)] - uij * (10.0 * p2 - p1)).eq(0.0))?;
            let r2 = uij * (p1 - 10.0 * p2) - (1.0 - uij) * p2;
            pb.subject_to_named("de2", (dpp[iw(i, j, 1)] - r2).eq(0.0))?;
        }
    }
    fix(&mut pb, &[v[iv(0, 0)], v[iv(0, 1)]], &[1.0, 0.0])?;
    pb.minimize(-1.0 + ppf[0] + ppf[1]);
    Ok(pb)
}

/// Flow in a channel: the fourth-order boundary-value problem `u'''' = R(u'u'' − u u''')`,
/// R = 10, as a feasibility problem (constant objective 1), 4-point Gauss collocation on
/// `nh` intervals. n = 40·nh.
pub fn channel(nh: usize) -> Result<Problem, BuildError> {
    const NC: usize = 4;
    const ND: usize = 4;
    let reynolds = 10.0;
    let rho: [f64; 4] = [
        0.06943184420297,
        0.33000947820757,
        0.66999052179243,
        0.93056815579703,
    ];
    let h = 1.0 / nh as f64;
    let mut pb = Problem::new();
    let v = pb.variable("v", nh * ND)?;
    let w = pb.variable("w", nh * NC)?;
    let uc = pb.variable("uc", nh * NC * ND)?;
    let duc = pb.variable("Duc", nh * NC * ND)?;
    let (iv, iu) = (
        |i: usize, s: usize| ND * i + s,
        |i: usize, j: usize, s: usize| ND * (NC * i + j) + s,
    );
    let mut uc0 = vec![0.0; nh * NC * ND];
    for i in 0..nh {
        let t = i as f64 * h;
        let v0 = [
            t * t * (3.0 - 2.0 * t),
            6.0 * t * (1.0 - t),
            6.0 * (1.0 - 2.0 * t),
            -12.0,
        ];
        for j in 0..NC {
            for s in 0..ND {
                uc0[iu(i, j, s)] = v0[s];
            }
        }
    }
    pb.set_initial(&uc, &uc0)?;
    // Derivative s (0-based) of the local polynomial at offset τ = ρ·h (τ = h at the end).
    let deriv = |i: usize, s: usize, tau: f64, r: f64| {
        let mut e = Expr::zero();
        for k in s..ND {
            e += v[iv(i, k)] * (tau.powi((k - s) as i32) / factorial(k - s));
        }
        for k in 0..NC {
            let p = k + ND - s;
            e += h.powi((ND - s) as i32) * w[NC * i + k] * (r.powi(p as i32) / factorial(p));
        }
        e
    };
    let mut rows = Vec::new();
    for i in 0..nh {
        for j in 0..NC {
            for s in 0..ND {
                let mut e = v[iv(i, s)];
                for k in 0..NC {
                    e += h * w[NC * i + k] * (rho[j].powi(k as i32 + 1) / factorial(k + 1));
                }
                rows.push((uc[iu(i, j, s)] - e).eq(0.0));
                rows.push((duc[iu(i, j, s)] - deriv(i, s, rho[j] * h, rho[j])).eq(0.0));
            }
        }
    }
    pb.subject_to_named("collocation_model", Constraint::all(rows))?;
    fix(&mut pb, &[v[iv(0, 0)], v[iv(0, 1)]], &[0.0, 0.0])?;
    pb.subject_to_named("bc_3", (deriv(nh - 1, 0, h, 1.0) - 1.0).eq(0.0))?;
    pb.subject_to_named("bc_4", deriv(nh - 1, 1, h, 1.0).eq(0.0))?;
    for i in 0..nh - 1 {
        for s in 0..ND {
            pb.subject_to_named(
                "continuity",
                (deriv(i, s, h, 1.0) - v[iv(i + 1, s)]).eq(0.0),
            )?;
        }
    }
    for i in 0..nh {
        for j in 0..NC {
            let mut lhs = Expr::zero();
            for k in 0..NC {
                lhs += w[NC * i + k] * (rho[j].powi(k as i32) / factorial(k));
            }
            let d = |s: usize| duc[iu(i, j, s)];
            let rhs = reynolds * (d(1) * d(2) - d(0) * d(3));
            pb.subject_to_named("collocation", (lhs - rhs).eq(0.0))?;
        }
    }
    pb.minimize(Expr::constant(1.0));
    Ok(pb)
}

/// α-pinene isomerisation: estimate the 5 rate constants of a linear reaction network from 8
/// measurements of 5 species, 3-point Gauss collocation on `nh` intervals of [0, 36420].
/// n = 50·nh + 5.
pub fn pinene(nh: usize) -> Result<Problem, BuildError> {
    const NC: usize = 3;
    const NE: usize = 5;
    let rho: [f64; 3] = [0.11270166537926, 0.5, 0.88729833462074];
    let bc = [100.0, 0.0, 0.0, 0.0, 0.0];
    let tau = [
        1230.0, 3060.0, 4920.0, 7800.0, 10680.0, 15030.0, 22620.0, 36420.0,
    ];
    let z = [
        [88.35, 7.3, 2.3, 0.4, 1.75],
        [76.4, 15.6, 4.5, 0.7, 2.8],
        [65.1, 23.1, 5.3, 1.1, 5.8],
        [50.4, 32.9, 6.0, 1.5, 9.3],
        [37.5, 42.7, 6.0, 1.9, 12.0],
        [25.9, 49.1, 5.9, 2.2, 17.0],
        [14.0, 57.4, 5.1, 2.6, 21.0],
        [4.5, 63.1, 3.8, 2.9, 25.7],
    ];
    let h = tau[7] / nh as f64;
    // itau[j]: the (0-based) interval holding measurement j.
    let itau: Vec<usize> = tau
        .iter()
        .map(|&t| ((t / h).floor() as usize).min(nh - 1))
        .collect();
    // COPS's start: each interval takes the value of the next measurement (bc before the first).
    let v0 = |i: usize, s: usize| match itau.iter().position(|&k| i <= k) {
        Some(0) => bc[s],
        Some(j) => z[j][s],
        None => z[7][s],
    };
    let mut pb = Problem::new();
    let theta = pb.variable("theta", 5)?;
    pb.set_bounds(&theta, 0.0, f64::INFINITY)?;
    let v = pb.variable("v", nh * NE)?;
    let w = pb.variable("w", nh * NC * NE)?;
    let uc = pb.variable("uc", nh * NC * NE)?;
    let duc = pb.variable("Duc", nh * NC * NE)?;
    let (iv, iw) = (
        |i: usize, s: usize| NE * i + s,
        |i: usize, j: usize, s: usize| NE * (NC * i + j) + s,
    );
    pb.set_initial(
        &v,
        &(0..nh * NE).map(|k| v0(k / NE, k % NE)).collect::<Vec<_>>(),
    )?;
    pb.set_initial(
        &uc,
        &(0..nh * NC * NE)
            .map(|k| v0(k / (NC * NE), k % NE))
            .collect::<Vec<_>>(),
    )?;
    let mut f = Expr::zero();
    for (j, &t) in tau.iter().enumerate() {
        let i = itau[j];
        let dt = t - i as f64 * h;
        for s in 0..NE {
            let mut e = v[iv(i, s)] - z[j][s];
            for k in 0..NC {
                e += w[iw(i, k, s)]
                    * (dt.powi(k as i32 + 1) / (factorial(k + 1) * h.powi(k as i32)));
            }
            f += e.sq();
        }
    }
    pb.minimize(f);
    let mut rows = Vec::new();
    for i in 0..nh {
        for j in 0..NC {
            for s in 0..NE {
                let (mut u, mut du) = (v[iv(i, s)], Expr::zero());
                for k in 0..NC {
                    u += h * w[iw(i, k, s)] * (rho[j].powi(k as i32 + 1) / factorial(k + 1));
                    du += w[iw(i, k, s)] * (rho[j].powi(k as i32) / factorial(k));
                }
                rows.push((uc[iw(i, j, s)] - u).eq(0.0));
                rows.push((duc[iw(i, j, s)] - du).eq(0.0));
            }
        }
    }
    pb.subject_to_named("collocation", Constraint::all(rows))?;
    fix(
        &mut pb,
        &(0..NE).map(|s| v[iv(0, s)]).collect::<Vec<_>>(),
        &bc,
    )?;
    for i in 0..nh - 1 {
        for s in 0..NE {
            let mut e = v[iv(i, s)];
            for k in 0..NC {
                e += w[iw(i, k, s)] * h / factorial(k + 1);
            }
            pb.subject_to_named("continuity", (e - v[iv(i + 1, s)]).eq(0.0))?;
        }
    }
    let th = |k: usize| theta[k];
    for i in 0..nh {
        for j in 0..NC {
            let (u, du) = (|s: usize| uc[iw(i, j, s)], |s: usize| duc[iw(i, j, s)]);
            let rhs = [
                -(th(0) + th(1)) * u(0),
                th(0) * u(0),
                th(1) * u(0) - (th(2) + th(3)) * u(2) + th(4) * u(4),
                th(2) * u(2),
                th(3) * u(2) - th(4) * u(4),
            ];
            let rows = (0..NE).map(|s| (du(s) - rhs[s]).eq(0.0));
            pb.subject_to_named("ode", Constraint::all(rows))?;
        }
    }
    Ok(pb)
}
