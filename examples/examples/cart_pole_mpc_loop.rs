//! A cart-pole MPC loop written as a CasADi user writes it with `Opti`: the horizon's
//! states and controls as variables, RK4 multiple shooting, the measured state a
//! parameter, 40 closed-loop steps each warm-started from the last solution. The symnlp
//! half of the third line-count pair of docs/casadi.md (issue 22 item 6); the CasADi half
//! is `python/examples/casadi/cartpole_mpc.py`. Both print the same angles and forces.
//! (`examples/mpc_cart_pole.rs` is the swing-up benchmark with the `Mpc` helper.)
//!
//! Run: `cargo run --release -p symnlp-examples --example cart_pole_mpc_loop`
use symnlp::nlp::ocp::ButcherTableau;
use symnlp::nlp::{bounded, Ipm, Problem, Relation};
use symnlp::symx::{Expr, Function, Matrix};

/// Model: cart position p, pole angle th (0 = up), their rates; force u on the cart.
fn f(x: &Matrix, u: Expr) -> Matrix {
    let (m, mp, l, g) = (1.0, 0.1, 0.5, 9.81);
    let (s, c, w) = (x[1].sin(), x[1].cos(), x[3]);
    let den = m + mp * s.sq();
    let a = (u + mp * s * (l * w.sq() - g * c)) / den;
    let alpha = (-u * c - mp * l * w.sq() * s * c + (m + mp) * g * s) / (l * den);
    Matrix::from_vec(vec![x[2], w, a, alpha])
}

fn rk4(x: &Matrix, u: Expr, dt: f64) -> Matrix {
    ButcherTableau::rk4().step(&|x| f(x, u), x, dt.into())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The MPC problem: horizon N, states X[k], controls U[k], measured state x0.
    let (n, dt) = (20, 0.05);
    let mut pb = Problem::new();
    let xs = (0..=n)
        .map(|k| pb.variable(&format!("X{k}"), 4))
        .collect::<Result<Vec<_>, _>>()?;
    let u = pb.variable("U", n)?;
    let x0 = pb.parameter("x0", 4)?;
    pb.set_value(&x0, &[0.0; 4])?; // compiling needs values (set each step below)
    pb.subject_to(xs[0].eq(&x0))?;
    let mut cost = Expr::zero();
    for k in 0..n {
        pb.subject_to(xs[k + 1].eq(&rk4(&xs[k], u[k], dt)))?;
        cost = cost + xs[k].sumsqr() + 0.01 * u[k].sq();
    }
    pb.minimize(cost + 10.0 * xs[n].sumsqr());
    pb.subject_to(bounded(-20.0, u.clone(), 20.0))?;
    let mut compiled = pb.compile()?;

    // Closed loop: measure, solve (warm), apply the first control to the "plant".
    let (xp, up) = (Matrix::sym_vec("x", 4), Expr::sym("u"));
    let plant = Function::new(&[&xp, &[up]], &[&rk4(&xp, up, dt)])?;
    let mut x = vec![0.0, 0.3, 0.0, 0.0]; // pole 0.3 rad from upright
    let mut log = Vec::new();
    for step in 0..40 {
        compiled.set_value(&x0, &x)?;
        let sol = Ipm::default().solve(&mut compiled)?;
        let u0 = pb.value(u[0], &sol)?;
        x = plant.call(&[&x, &[u0]])?.swap_remove(0);
        log.push((step, x[1], u0, sol.stats.iterations));
        compiled.set_initial_point(&sol.x)?;
    }
    for (step, th, u0, it) in log.iter().step_by(8) {
        println!("step {step:2}: angle {th:+.4} rad, force {u0:+.3} N, {it} iterations");
    }
    println!("final angle {:+.2e} rad", x[1]);
    Ok(())
}
