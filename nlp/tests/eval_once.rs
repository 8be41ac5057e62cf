//! Each of f, g, ∇f and J is evaluated at most once per point (issue 19 item 2): the end
//! of a solve reuses the values the iterations computed at the final point instead of
//! evaluating again, and the IPM's start shares its g. Checked on the cart-pole MPC of the
//! test kit (a cold solve and warm re-solves, both back ends) through a wrapper that
//! records every evaluation: the solution's reported values equal a fresh evaluation at
//! its point bit for bit, the statistics count exactly the evaluations made, and no value
//! is evaluated again at the point it was last evaluated at with nothing evaluated
//! elsewhere in between (what the solvers' cache guarantees). Both with f and g (∇f and
//! J) evaluated in pairs, as a compiled problem does, and each apart: the same solves bit
//! for bit.

use faer::sparse::SymbolicSparseColMat;
use nlp::{Compiled, Ipm, NumericNlp, Solution, Solver, Sqp};
use testkit::cart_pole_mpc;

/// Which value an evaluation computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Value {
    F,
    G,
    Grad,
    Jac,
}

/// A compiled problem that records every evaluation of f, g, ∇f and J with its point;
/// `together`: it evaluates f and g (∇f and J) together, as [`Compiled`] does, else apart.
struct Recorded {
    inner: Compiled,
    log: Vec<(Value, Vec<u64>)>,
    together: bool,
}

impl Recorded {
    fn record(&mut self, v: Value, x: &[f64]) {
        self.log.push((v, x.iter().map(|a| a.to_bits()).collect()));
    }

    fn count(&self, v: Value) -> usize {
        self.log.iter().filter(|(w, _)| *w == v).count()
    }

    /// Evaluations of a value again at the point of the previous evaluation, the value
    /// already evaluated there since the point was last changed: what a cache of the last
    /// point would have answered.
    fn repeats(&self) -> Vec<(usize, Value)> {
        let mut out = Vec::new();
        let mut seen: Vec<Value> = Vec::new();
        for (k, (v, x)) in self.log.iter().enumerate() {
            if k > 0 && self.log[k - 1].1 == *x {
                if seen.contains(v) {
                    out.push((k, *v));
                }
            } else {
                seen.clear();
            }
            seen.push(*v);
        }
        out
    }
}

impl NumericNlp for Recorded {
    fn n(&self) -> usize {
        self.inner.n()
    }
    fn m(&self) -> usize {
        self.inner.m()
    }
    fn bounds(&self, x_l: &mut [f64], x_u: &mut [f64], g_l: &mut [f64], g_u: &mut [f64]) {
        self.inner.bounds(x_l, x_u, g_l, g_u)
    }
    fn initial_point(&self, x: &mut [f64]) {
        self.inner.initial_point(x)
    }
    fn jac_g_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        self.inner.jac_g_sparsity()
    }
    fn hess_l_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        self.inner.hess_l_sparsity()
    }
    fn eval_f(&mut self, x: &[f64]) -> f64 {
        self.record(Value::F, x);
        self.inner.eval_f(x)
    }
    fn eval_grad_f(&mut self, x: &[f64], grad: &mut [f64]) {
        self.record(Value::Grad, x);
        self.inner.eval_grad_f(x, grad)
    }
    fn eval_g(&mut self, x: &[f64], g: &mut [f64]) {
        self.record(Value::G, x);
        self.inner.eval_g(x, g)
    }
    fn eval_jac_g(&mut self, x: &[f64], values: &mut [f64]) {
        self.record(Value::Jac, x);
        self.inner.eval_jac_g(x, values)
    }
    fn evaluates_together(&self) -> bool {
        self.together
    }
    fn eval_f_g(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        self.record(Value::F, x);
        self.record(Value::G, x);
        self.inner.eval_f_g(x, g)
    }
    fn eval_grad_f_jac_g(&mut self, x: &[f64], grad: &mut [f64], jac: &mut [f64]) {
        self.record(Value::Grad, x);
        self.record(Value::Jac, x);
        self.inner.eval_grad_f_jac_g(x, grad, jac)
    }
    fn eval_hess_l(&mut self, x: &[f64], obj_factor: f64, lambda: &[f64], values: &mut [f64]) {
        self.inner.eval_hess_l(x, obj_factor, lambda, values)
    }
    fn parameter_values(&self) -> &[f64] {
        self.inner.parameter_values()
    }
}

/// The checks of the module doc on one solve; the log is cleared for the next.
fn check(what: &str, nlp: &mut Recorded, sol: &Solution) {
    let st = &sol.stats;
    assert_eq!(
        (st.n_eval_f, st.n_eval_g, st.n_eval_grad_f, st.n_eval_jac_g),
        (
            nlp.count(Value::F),
            nlp.count(Value::G),
            nlp.count(Value::Grad),
            nlp.count(Value::Jac)
        ),
        "{what}: the statistics count the evaluations made"
    );
    assert_eq!(
        nlp.repeats(),
        vec![],
        "{what}: evaluated again at one point"
    );
    // The reported f and g are those of the final point, bit for bit.
    let c = &mut nlp.inner;
    assert_eq!(
        c.eval_f(&sol.x).to_bits(),
        sol.objective.to_bits(),
        "{what}: f"
    );
    let mut g = vec![0.0; c.m()];
    c.eval_g(&sol.x, &mut g);
    assert!(
        g.iter()
            .zip(&sol.g)
            .all(|(a, b)| a.to_bits() == b.to_bits()),
        "{what}: g"
    );
    nlp.log.clear();
}

/// A cold solve then three warm re-solves from the shifted plan, with x0 moved along the
/// closed loop's first states; the four solutions.
fn solve_loop(solver: &dyn Solver, together: bool) -> Vec<Solution> {
    let mut nlp = Recorded {
        inner: cart_pole_mpc::build().compiled,
        log: Vec::new(),
        together,
    };
    let name = format!("{} (together: {together})", solver.name());
    let mut sol = solver.solve(&mut nlp).expect("cold solve");
    assert!(sol.status.is_success(), "{name} cold: {}", sol.status);
    check(&format!("{name} cold"), &mut nlp, &sol);
    let mut sols = vec![sol.clone()];
    let mut x = [0.0; cart_pole_mpc::NX];
    for step in 1..4 {
        let u = sol.x[cart_pole_mpc::NX];
        x = cart_pole_mpc::plant(&x, u);
        nlp.inner.set_value("x0", &x).expect("x0");
        cart_pole_mpc::shift(&mut sol);
        let next = solver.solve_warm(&mut nlp, &sol).expect("warm solve");
        assert!(
            next.status.is_success(),
            "{name} step {step}: {}",
            next.status
        );
        check(&format!("{name} step {step}"), &mut nlp, &next);
        sols.push(next.clone());
        sol = next;
    }
    sols
}

/// Both ways of evaluating (pairs together, each value apart) give the same solves bit
/// for bit: the values are the same, only their evaluations are shared.
fn same_solves(solver: &dyn Solver) {
    let together = solve_loop(solver, true);
    let apart = solve_loop(solver, false);
    for (k, (a, b)) in together.iter().zip(&apart).enumerate() {
        assert_eq!(
            a.stats.iterations, b.stats.iterations,
            "solve {k}: iterations"
        );
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.x), bits(&b.x), "solve {k}: x");
        assert_eq!(bits(&a.lambda), bits(&b.lambda), "solve {k}: λ");
        // Together, f and g (∇f and J) are counted in pairs.
        let st = &a.stats;
        assert_eq!(st.n_eval_f, st.n_eval_g, "solve {k}: f and g together");
        assert_eq!(
            st.n_eval_grad_f, st.n_eval_jac_g,
            "solve {k}: ∇f and J together"
        );
    }
}

#[test]
fn the_ipm_evaluates_each_value_once_per_point() {
    same_solves(&Ipm::default());
}

#[test]
fn the_sqp_evaluates_each_value_once_per_point() {
    same_solves(&Sqp::default());
}
