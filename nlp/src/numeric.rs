//! The numeric NLP interface solved by the interior-point method (IPOPT's TNLP shape).

use faer::sparse::SymbolicSparseColMat;

/// A nonlinear program given by numeric callbacks:
///
/// min f(x)  s.t.  g_l <= g(x) <= g_u,  x_l <= x <= x_u
///
/// (`±f64::INFINITY` = no bound; `g_l == g_u` = equality).
///
/// Sparse values are written in the storage order of the corresponding pattern: the value
/// of storage position `p` (an index into `pattern.row_idx()`) goes to `values[p]`.
/// A non-finite value from any callback signals an evaluation failure; the solver detects
/// NaN/Inf itself (it cuts the step in the line search, or reports
/// [`Status::InvalidNumberDetected`](crate::Status::InvalidNumberDetected) at the start).
pub trait NumericNlp {
    /// Number of variables `n`.
    fn n(&self) -> usize;
    /// Number of constraints `m`.
    fn m(&self) -> usize;
    /// Writes variable bounds (length `n`) and constraint bounds (length `m`).
    fn bounds(&self, x_l: &mut [f64], x_u: &mut [f64], g_l: &mut [f64], g_u: &mut [f64]);
    /// Writes the starting point (length `n`).
    fn initial_point(&self, x: &mut [f64]);
    /// CSC pattern of the m×n constraint Jacobian; `eval_jac_g` writes values in this CSC order.
    fn jac_g_sparsity(&self) -> &SymbolicSparseColMat<usize>;
    /// CSC pattern of the LOWER triangle of the n×n Lagrangian Hessian.
    fn hess_l_sparsity(&self) -> &SymbolicSparseColMat<usize>;
    /// Objective value f(x).
    fn eval_f(&mut self, x: &[f64]) -> f64;
    /// Objective gradient ∇f(x) (length `n`).
    fn eval_grad_f(&mut self, x: &[f64], grad: &mut [f64]);
    /// Constraint values g(x) (length `m`).
    fn eval_g(&mut self, x: &[f64], g: &mut [f64]);
    /// Jacobian values in `jac_g_sparsity` order.
    fn eval_jac_g(&mut self, x: &[f64], values: &mut [f64]);
    /// Values of `obj_factor·∇²f(x) + Σ λ_i ∇²g_i(x)`, lower triangle, in `hess_l_sparsity` order.
    fn eval_hess_l(&mut self, x: &[f64], obj_factor: f64, lambda: &[f64], values: &mut [f64]);
    /// Whether [`NumericNlp::eval_f_g`] and [`NumericNlp::eval_grad_f_jac_g`] cost less
    /// than their two evaluations apart (default: no). Solvers then ask for the two values
    /// of a pair together whenever they need one of them at a new point (they need both
    /// at almost every point); a [`Compiled`](crate::Compiled) problem says yes.
    fn evaluates_together(&self) -> bool {
        false
    }
    /// f(x), and g(x) into `g`, in one evaluation (default: [`NumericNlp::eval_f`] then
    /// [`NumericNlp::eval_g`]); the values must be those of the two apart.
    fn eval_f_g(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        let f = self.eval_f(x);
        self.eval_g(x, g);
        f
    }
    /// ∇f(x) into `grad` and the Jacobian's values into `jac`, in one evaluation (default:
    /// [`NumericNlp::eval_grad_f`] then [`NumericNlp::eval_jac_g`]); the values must be
    /// those of the two apart.
    fn eval_grad_f_jac_g(&mut self, x: &[f64], grad: &mut [f64], jac: &mut [f64]) {
        self.eval_grad_f(x, grad);
        self.eval_jac_g(x, jac);
    }
    /// Name of variable `i` for messages (default `x[i]`).
    fn variable_name(&self, i: usize) -> String {
        format!("x[{i}]")
    }
    /// Name of constraint `i` for messages (default `g[i]`).
    fn constraint_name(&self, i: usize) -> String {
        format!("g[{i}]")
    }
    /// Second-order cones with affine entries (default: none). Each also has a row of g
    /// (its smooth form), which a cone-aware solver replaces by the exact cone.
    fn affine_cones(&self) -> &[AffineCone] {
        &[]
    }
    /// CSC pattern of the Jacobian of the stacked cone entries (rows: every cone's
    /// `[t, v]`, in the order of [`NumericNlp::affine_cones`]; columns: the n variables).
    /// `None` when there are no affine cones.
    fn cone_jac_sparsity(&self) -> Option<&SymbolicSparseColMat<usize>> {
        None
    }
    /// Values of the stacked cone entries at x.
    fn eval_cone_entries(&mut self, _x: &[f64], _out: &mut [f64]) {}
    /// Values of the cone-entry Jacobian in `cone_jac_sparsity` order.
    fn eval_cone_jac(&mut self, _x: &[f64], _values: &mut [f64]) {}
    /// The parameter values the functions are evaluated with (default: none); solvers
    /// copy them into [`crate::Solution::parameters`].
    fn parameter_values(&self) -> &[f64] {
        &[]
    }
    /// Whether the problem can be evaluated (default: yes); checked before every solve.
    /// A [`Compiled`](crate::Compiled) fails here while a parameter has no value.
    fn check_ready(&self) -> Result<(), crate::SolveError> {
        Ok(())
    }
}

/// A second-order cone `‖v(x)‖ ≤ t(x)` whose entries are affine in x, exposed by
/// [`NumericNlp::affine_cones`] to solvers that treat cones natively (the SQP hands it to
/// clarabel as a second-order cone). Row `row` of g holds the cone's smooth form for
/// solvers that do not (see `Problem::subject_to_cone`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct AffineCone {
    /// The row of g holding the smooth form of this cone.
    pub row: usize,
    /// Offset of this cone's entries `[t, v₁, …]` in the stacked vector of cone entries.
    pub offset: usize,
    /// Dimension `1 + len(v)`.
    pub dim: usize,
}
