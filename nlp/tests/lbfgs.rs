//! The limited-memory Hessian (`hessian_approximation = limited-memory`) on problems
//! without a Hessian callback, with restoration, and its options.

mod ipm_common;

use faer::sparse::SymbolicSparseColMat;
use ipm_common::{hs071, rosenbrock};
use nlp::{
    Ipm, IpmHessian, IpmOptions, LimitedMemoryUpdate, NamedOptions, NumericNlp, Solution, Status,
};

/// A problem whose Hessian is unavailable: empty pattern, and `eval_hess_l` panics.
struct NoHessian<P> {
    inner: P,
    empty: SymbolicSparseColMat<usize>,
}

impl<P: NumericNlp> NoHessian<P> {
    fn new(inner: P) -> Self {
        let n = inner.n();
        let empty = SymbolicSparseColMat::new_checked(n, n, vec![0; n + 1], None, Vec::new());
        NoHessian { inner, empty }
    }
}

impl<P: NumericNlp> NumericNlp for NoHessian<P> {
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
        &self.empty
    }
    fn eval_f(&mut self, x: &[f64]) -> f64 {
        self.inner.eval_f(x)
    }
    fn eval_grad_f(&mut self, x: &[f64], grad: &mut [f64]) {
        self.inner.eval_grad_f(x, grad)
    }
    fn eval_g(&mut self, x: &[f64], g: &mut [f64]) {
        self.inner.eval_g(x, g)
    }
    fn eval_jac_g(&mut self, x: &[f64], values: &mut [f64]) {
        self.inner.eval_jac_g(x, values)
    }
    fn eval_hess_l(&mut self, _: &[f64], _: f64, _: &[f64], _: &mut [f64]) {
        panic!("eval_hess_l must not be called with hessian_approximation = limited-memory");
    }
}

fn lm() -> IpmOptions {
    IpmOptions {
        hessian_approximation: IpmHessian::LimitedMemory,
        ..IpmOptions::default()
    }
}

/// hs071's optimum f* = 17.0140172891516 (Hock & Schittkowski 1981, problem 71). The
/// solver stops at a scaled KKT error ≤ 1e-8, and the bounds are relaxed by 1e-8
/// (≈ 1.4e-7 in f, see nlp/tests/ipm_basic.rs), so 1e-6 absolute.
fn assert_hs071(sol: &Solution) {
    assert_eq!(sol.status, Status::SolveSucceeded, "{}", sol.message);
    assert!(
        (sol.objective - 17.0140172891516).abs() < 1e-6,
        "{}",
        sol.objective
    );
    let xs = [1.0, 4.74299963, 3.82114998, 1.37940829];
    for (a, b) in sol.x.iter().zip(xs) {
        assert!((a - b).abs() < 1e-6, "{:?}", sol.x);
    }
    assert_eq!(sol.stats.n_eval_hess_l, 0);
}

#[test]
fn solves_a_problem_without_a_hessian_callback() {
    let mut p = NoHessian::new(hs071());
    let sol = Ipm::new(lm()).solve(&mut p).unwrap();
    assert_hs071(&sol);
    // IPOPT 3.14 limited-memory (CasADi 3.8.2, default options) takes 9 iterations on
    // the same formulation (benches/reference/results/hs_lbfgs_ipopt.jsonl, hs071).
    eprintln!("hs071 limited-memory: {} iterations", sol.stats.iterations);
    assert!(sol.stats.iterations <= 14, "{}", sol.stats.iterations);
}

#[test]
fn restoration_runs_without_a_hessian_callback() {
    // start_with_resto forces a restoration phase at the start; its inner iteration
    // uses its own limited-memory Hessian and must not ask the user for one either.
    let mut p = NoHessian::new(hs071());
    let opts = IpmOptions {
        start_with_resto: true,
        ..lm()
    };
    let sol = Ipm::new(opts).solve(&mut p).unwrap();
    assert_hs071(&sol);
    assert!(sol.stats.restoration_iterations > 0);
}

#[test]
fn unconstrained_rosenbrock_bfgs_and_sr1() {
    // Rosenbrock: minimum 0 at (1, 1) (Rosenbrock 1960); 1e-6 on x as in ipm_basic.rs.
    // IPOPT 3.14 limited-memory (CasADi 3.8.2, tol 1e-8, x0 = (−1.2, 1)) takes 47
    // iterations with BFGS and 50 with SR1; the bound is 1.5× that (the target).
    for (update, ipopt) in [
        (LimitedMemoryUpdate::Bfgs, 47),
        (LimitedMemoryUpdate::Sr1, 50),
    ] {
        let mut p = NoHessian::new(rosenbrock());
        let opts = IpmOptions {
            limited_memory_update_type: update,
            ..lm()
        };
        let sol = Ipm::new(opts).solve(&mut p).unwrap();
        assert_eq!(sol.status, Status::SolveSucceeded, "{update:?}");
        assert!(
            (sol.x[0] - 1.0).abs() < 1e-6 && (sol.x[1] - 1.0).abs() < 1e-6,
            "{update:?}: {:?}",
            sol.x
        );
        let it = sol.stats.iterations;
        eprintln!("rosenbrock {update:?}: {it} iterations (IPOPT {ipopt})");
        assert!(2 * it <= 3 * ipopt, "{update:?}: {it} iterations");
    }
}

#[test]
fn same_input_gives_bit_identical_results() {
    let a = Ipm::new(lm()).solve(&mut NoHessian::new(hs071())).unwrap();
    let b = Ipm::new(lm()).solve(&mut NoHessian::new(hs071())).unwrap();
    assert_eq!(a.stats.iterations, b.stats.iterations);
    for (x, y) in a.x.iter().zip(&b.x) {
        assert_eq!(x.to_bits(), y.to_bits());
    }
}

#[test]
fn options_by_name_and_their_validation() {
    let mut o = IpmOptions::default();
    o.set_by_name(&[
        "hessian_approximation=limited-memory",
        "limited_memory_max_history=3",
        "limited_memory_update_type=sr1",
        "limited_memory_initialization=scalar2",
        "limited_memory_init_val=2",
    ])
    .unwrap();
    assert_eq!(o.hessian_approximation, IpmHessian::LimitedMemory);
    assert_eq!(o.limited_memory_max_history, 3);
    assert_eq!(o.limited_memory_update_type, LimitedMemoryUpdate::Sr1);
    let err = o
        .set_by_name(&["limited_memory_init_val_min=1e9"])
        .unwrap_err();
    assert!(
        err.to_string().contains("limited_memory_init_val_min"),
        "{err}"
    );
    let err = o.set_by_name(&["limited_memory_init_val=0"]).unwrap_err();
    assert!(err.to_string().contains("limited_memory_init_val"), "{err}");
    let err = o.set_by_name(&["hessian_approximation=bfgs"]).unwrap_err();
    assert!(err.to_string().contains("hessian_approximation"), "{err}");
}
