//! [`Compiled`]: a problem differentiated and compiled once; the numeric NLP solvers consume.
use crate::error::SolveError;
use crate::numeric::{AffineCone, NumericNlp};
use crate::parameter::{ParameterIndex, ParameterKey};
use crate::problem::{row_name, Block, BuildError, ProblemParts};
use std::sync::Arc;
use symx::{Evaluator, Expr, Function, Matrix, Sparsity};

/// A compiled problem: evaluators for f, ∇f, g, the sparse Jacobian of g and the sparse
/// lower-triangular Lagrangian Hessian, with fixed sparsity and their own work space.
///
/// It holds no symbolic expressions, so it is `Send` and can be solved on another thread.
/// Parameter values can change between solves ([`Compiled::set_value`]) without
/// recompiling. A clone shares the compiled evaluators (behind `Arc`) and owns its
/// bounds, initial point, parameter values and work space: clones solve independently,
/// e.g. one per thread, without compiling again.
#[derive(Clone)]
pub struct Compiled {
    n: usize,
    m: usize,
    x_l: Vec<f64>,
    x_u: Vec<f64>,
    g_l: Vec<f64>,
    g_u: Vec<f64>,
    x0: Vec<f64>,
    /// Parameter values; NaN for an entry never set (the setters accept finite values
    /// only), which [`NumericNlp::check_ready`] reports before a solve.
    params: Vec<f64>,
    parameter_index: ParameterIndex,
    /// f and g in one tape, ∇f and J in one tape: a pair shares its common subexpressions
    /// (the dynamics of an OCP's constraints are also in its objective's quadrature), and
    /// the solvers need both values of a pair at almost every point. One value alone is
    /// evaluated with its pair, the other written to a spare vector.
    f_g_fn: Arc<Function>,
    grad_jac_fn: Arc<Function>,
    hess_fn: Arc<Function>,
    /// Where a single value's evaluation writes the other value of its pair.
    spare: Spare,
    jac_sparsity: Sparsity,
    hess_sparsity: Sparsity,
    work: Vec<f64>,
    variable_names: Vec<String>,
    variable_blocks: Vec<Block>,
    constraint_blocks: Vec<Block>,
    /// Affine second-order cones, with evaluators of their stacked entries `[t; v]` and
    /// of the entries' Jacobian (`None` without affine cones).
    affine_cones: Vec<AffineCone>,
    cone_fns: Option<Arc<ConeEvaluators>>,
}

/// Options of [`Problem::compile_with`](crate::Problem::compile_with).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CompileOptions {
    /// How the compiled functions evaluate: the tape (default) or native code compiled by
    /// Cranelift ([`Evaluator::Jit`], bit-identical values, so identical iterates).
    ///
    /// The tape is the default because one solve does not repay the JIT's compile time:
    /// measured on the quadrotor (N = 320) and Van der Pol multiple-shooting examples
    /// (`tests/jit.rs`, `ocp_examples_solve_identically`), the JIT takes 0.26–0.44× the
    /// tape's solve time with call nodes and Van der Pol inlined (compile: 6–180 solves),
    /// but 0.94–1.24× on the inlined quadrotor, whose huge straight-line Hessian the tape's
    /// fused steps run as fast. Choose the JIT when the same compiled problem is solved
    /// many times: MPC loops, parameter sweeps, warm re-solves.
    pub evaluator: Evaluator,
}

/// Vectors for the value of a pair nobody asked for (see `Compiled::f_g_fn`).
#[derive(Clone)]
struct Spare {
    g: Vec<f64>,
    grad: Vec<f64>,
    jac: Vec<f64>,
}

/// Evaluators of the affine cones' stacked entries `[t; v]` and of their Jacobian.
struct ConeEvaluators {
    entries: Function,
    jacobian: Function,
    jacobian_sparsity: Sparsity,
}

impl Compiled {
    pub(crate) fn new(
        parts: ProblemParts<'_>,
        f: Expr,
        params: Vec<f64>,
    ) -> Result<Compiled, BuildError> {
        let x = parts.variables;
        let p = parts.parameters;
        let g: &[Expr] = &parts.rows.iter().map(|r| r.expr).collect::<Vec<_>>();
        let grad = symx::gradient(f, x)?;
        let jac = symx::jacobian(g, x)?;
        let sigma = Expr::sym("obj_factor");
        let lambda = Matrix::sym_vec("lambda", g.len());
        let hess = symx::lagrangian_hessian(f, g, x, sigma, &lambda)?;
        let f_g_fn = Function::new(&[x, p], &[&[f], g])?;
        let grad_jac_fn = Function::new(&[x, p], &[&grad, jac.values()])?;
        let hess_fn = Function::new(&[x, p, &[sigma], &lambda], &[hess.values()])?;
        let mut affine_cones = Vec::new();
        let mut entries = Vec::new();
        for &(row, c) in parts.cones.iter().filter(|(_, c)| c.affine) {
            affine_cones.push(AffineCone {
                row,
                offset: entries.len(),
                dim: 1 + c.v.len(),
            });
            entries.push(c.t);
            entries.extend_from_slice(&c.v);
        }
        let cone_fns = if entries.is_empty() {
            None
        } else {
            let cj = symx::jacobian(&entries, x)?;
            Some(Arc::new(ConeEvaluators {
                entries: Function::new(&[x, p], &[&entries])?,
                jacobian: Function::new(&[x, p], &[cj.values()])?,
                jacobian_sparsity: cj.sparsity().clone(),
            }))
        };
        let work_size = [&f_g_fn, &grad_jac_fn, &hess_fn]
            .into_iter()
            .chain(cone_fns.iter().flat_map(|c| [&c.entries, &c.jacobian]))
            .map(|f| f.work_size())
            .max()
            .unwrap_or(0);
        Ok(Compiled {
            n: x.len(),
            m: g.len(),
            x_l: parts.lower,
            x_u: parts.upper,
            g_l: parts.rows.iter().map(|r| r.lower).collect(),
            g_u: parts.rows.iter().map(|r| r.upper).collect(),
            x0: parts.initial.to_vec(),
            params,
            parameter_index: parts.parameter_index.clone(),
            f_g_fn: Arc::new(f_g_fn),
            grad_jac_fn: Arc::new(grad_jac_fn),
            hess_fn: Arc::new(hess_fn),
            spare: Spare {
                g: vec![0.0; g.len()],
                grad: vec![0.0; x.len()],
                jac: vec![0.0; jac.values().len()],
            },
            jac_sparsity: jac.sparsity().clone(),
            hess_sparsity: hess.sparsity().clone(),
            work: vec![0.0; work_size],
            variable_names: x
                .iter()
                .enumerate()
                .map(|(i, e)| e.name().unwrap_or_else(|| format!("x[{i}]")))
                .collect(),
            variable_blocks: parts.variable_blocks.to_vec(),
            constraint_blocks: parts.constraint_blocks,
            affine_cones,
            cone_fns,
        })
    }

    /// This problem with every evaluator (f, ∇f, g, the Jacobian, the Hessian and the cone
    /// functions) evaluated by `evaluator`; the values are bit-identical, so any solver
    /// takes identical iterates; `self` unchanged when it already evaluates so. `Err` if
    /// native code cannot be generated (e.g. symx built without its `jit` feature).
    ///
    /// ```
    /// use nlp::{Ipm, Problem, Solver};
    /// use symx::Evaluator;
    /// let mut p = Problem::new();
    /// let x = p.variable("x", 2).unwrap();
    /// p.minimize((1.0 - x[0]).sq() + 100.0 * (x[1] - x[0].sq()).sq());
    /// let mut c = p.compile().unwrap().with_evaluator(Evaluator::Jit).unwrap();
    /// let sol = Ipm::default().solve(&mut c).unwrap();
    /// assert!((sol.x[0] - 1.0).abs() < 1e-6);
    /// ```
    pub fn with_evaluator(mut self, evaluator: Evaluator) -> Result<Compiled, BuildError> {
        if self.evaluator() == evaluator {
            return Ok(self);
        }
        let convert = |f: &Function| f.with_evaluator(evaluator).map(Arc::new);
        self.f_g_fn = convert(&self.f_g_fn)?;
        self.grad_jac_fn = convert(&self.grad_jac_fn)?;
        self.hess_fn = convert(&self.hess_fn)?;
        if let Some(c) = &self.cone_fns {
            self.cone_fns = Some(Arc::new(ConeEvaluators {
                entries: c.entries.with_evaluator(evaluator)?,
                jacobian: c.jacobian.with_evaluator(evaluator)?,
                jacobian_sparsity: c.jacobian_sparsity.clone(),
            }));
        }
        Ok(self)
    }

    /// How the evaluators evaluate (see [`Compiled::with_evaluator`]).
    pub fn evaluator(&self) -> Evaluator {
        self.hess_fn.evaluator()
    }

    /// Sets parameter values (finite numbers), by handle or by name: the same call as
    /// [`Problem::set_value`](crate::Problem::set_value). Handles only work on the thread
    /// that built the problem ([`BuildError::ForeignThread`] elsewhere); names work on
    /// any thread. A later solve's [`Solution::parameters`](crate::Solution::parameters)
    /// records the values it used, and [`Problem::value`](crate::Problem::value) reads
    /// expressions with them.
    pub fn set_value<'a>(
        &mut self,
        p: impl Into<ParameterKey<'a>>,
        values: &[f64],
    ) -> Result<(), BuildError> {
        let idx = self.parameter_index.resolve(p.into(), values)?;
        for (i, &v) in idx.into_iter().zip(values) {
            self.params[i] = v;
        }
        Ok(())
    }

    /// Sets the parameter entries `range` (a block's, found once through
    /// [`Compiled::parameter_blocks`]) to `values` without allocating, as an MPC step sets
    /// the measured state. An error names a wrong length or the first non-finite entry.
    pub(crate) fn set_parameter_range(
        &mut self,
        range: std::ops::Range<usize>,
        values: &[f64],
    ) -> Result<(), BuildError> {
        if values.len() != range.len() {
            return Err(BuildError::Size {
                what: "set_value: values".into(),
                expected: range.len(),
                got: values.len(),
            });
        }
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(BuildError::NotFinite {
                what: format!(
                    "value of parameter '{}'",
                    self.parameter_index.name(range.start + k)
                ),
                value: values[k],
            });
        }
        self.params[range].copy_from_slice(values);
        Ok(())
    }

    /// Sets all parameter entries at once (`p` as long as [`Compiled::parameter_values`],
    /// finite or NaN for an entry left unset: checked by the caller).
    pub(crate) fn set_parameter_vector(&mut self, p: &[f64]) {
        self.params.copy_from_slice(p);
    }

    /// The values of all parameter entries, in declaration order; NaN for an entry not
    /// set yet (compiling does not require values, solving does).
    pub fn parameter_values(&self) -> &[f64] {
        &self.params
    }

    /// The first parameter entry without a value, by name (`None` when all are set).
    pub fn unset_parameter(&self) -> Option<&str> {
        let i = self.params.iter().position(|v| v.is_nan())?;
        Some(self.parameter_index.name(i))
    }

    /// Replaces the initial guess (one finite value per variable, in variable order): the
    /// way to cold-start the next solve from a new point on an already compiled problem
    /// (`solve` starts from this point; `solve_warm` from a previous solution instead).
    /// An error names a wrong length or the first non-finite entry's variable.
    ///
    /// ```
    /// use nlp::{Ipm, Problem};
    /// let mut pb = Problem::new();
    /// let x = pb.scalar_variable("x")?;
    /// pb.minimize((x.sq() - 1.0).sq()); // two minima, x = ±1
    /// let mut compiled = pb.compile()?;
    /// compiled.set_initial_point(&[-3.0])?; // start near the left one
    /// let sol = Ipm::default().solve(&mut compiled)?;
    /// assert!((sol.x[0] + 1.0).abs() < 1e-8);
    /// assert!(compiled.set_initial_point(&[f64::NAN]).is_err());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn set_initial_point(&mut self, x0: &[f64]) -> Result<(), BuildError> {
        if x0.len() != self.n {
            return Err(BuildError::Size {
                what: "initial point".into(),
                expected: self.n,
                got: x0.len(),
            });
        }
        if let Some(i) = x0.iter().position(|v| !v.is_finite()) {
            return Err(BuildError::NotFinite {
                what: format!("initial value of '{}'", self.variable_names[i]),
                value: x0[i],
            });
        }
        self.x0.copy_from_slice(x0);
        Ok(())
    }

    /// The variable blocks, in declaration order (to find a variable in a solution's `x`).
    pub fn variable_blocks(&self) -> &[Block] {
        &self.variable_blocks
    }

    /// The parameter blocks, in declaration order (where a parameter's entries sit in
    /// [`Compiled::parameter_values`]).
    pub fn parameter_blocks(&self) -> &[Block] {
        self.parameter_index.blocks()
    }

    /// The named constraint groups, in the order of `g`.
    pub fn constraint_blocks(&self) -> &[Block] {
        &self.constraint_blocks
    }

    /// The entries of the variable declared as `name` in a primal vector `x`.
    pub fn variable_values<'a>(&self, name: &str, x: &'a [f64]) -> Option<&'a [f64]> {
        let b = self.variable_blocks.iter().find(|b| b.name == name)?; // names are unique
        x.get(b.range())
    }

    fn eval(f: &Function, inputs: &[&[f64]], out: &mut [f64], work: &mut [f64]) {
        Compiled::eval_into(f, inputs, &mut [out], work);
    }

    fn eval_into(f: &Function, inputs: &[&[f64]], outputs: &mut [&mut [f64]], work: &mut [f64]) {
        // Sizes are fixed at compilation and the solver passes vectors of those sizes; a
        // mismatch is a broken invariant of the caller.
        if let Err(e) = f.eval(inputs, outputs, work) {
            panic!("compiled problem evaluated with wrong sizes: {e}");
        }
    }
}

impl std::fmt::Debug for Compiled {
    /// Sizes, sparsity and names; not the evaluators' instruction lists.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names = |b: &[Block]| b.iter().map(|b| b.name.clone()).collect::<Vec<_>>();
        f.debug_struct("Compiled")
            .field("n", &self.n)
            .field("m", &self.m)
            .field("jacobian_nnz", &self.jac_sparsity.compute_nnz())
            .field("hessian_nnz", &self.hess_sparsity.compute_nnz())
            .field("variables", &names(&self.variable_blocks))
            .field("parameters", &names(self.parameter_index.blocks()))
            .field("parameter_values", &self.params)
            .field("constraints", &names(&self.constraint_blocks))
            .field("affine_cones", &self.affine_cones.len())
            .finish_non_exhaustive()
    }
}

impl NumericNlp for Compiled {
    fn n(&self) -> usize {
        self.n
    }
    fn parameter_values(&self) -> &[f64] {
        &self.params
    }
    fn check_ready(&self) -> Result<(), SolveError> {
        match self.unset_parameter() {
            Some(name) => Err(SolveError::MissingParameterValue {
                name: name.to_string(),
            }),
            None => Ok(()),
        }
    }
    fn m(&self) -> usize {
        self.m
    }
    fn bounds(&self, x_l: &mut [f64], x_u: &mut [f64], g_l: &mut [f64], g_u: &mut [f64]) {
        x_l.copy_from_slice(&self.x_l);
        x_u.copy_from_slice(&self.x_u);
        g_l.copy_from_slice(&self.g_l);
        g_u.copy_from_slice(&self.g_u);
    }
    fn initial_point(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.x0);
    }
    fn jac_g_sparsity(&self) -> &Sparsity {
        &self.jac_sparsity
    }
    fn hess_l_sparsity(&self) -> &Sparsity {
        &self.hess_sparsity
    }
    fn eval_f(&mut self, x: &[f64]) -> f64 {
        let mut g = std::mem::take(&mut self.spare.g);
        let f = self.eval_f_g(x, &mut g);
        self.spare.g = g;
        f
    }
    fn eval_grad_f(&mut self, x: &[f64], grad: &mut [f64]) {
        let mut jac = std::mem::take(&mut self.spare.jac);
        self.eval_grad_f_jac_g(x, grad, &mut jac);
        self.spare.jac = jac;
    }
    fn eval_g(&mut self, x: &[f64], g: &mut [f64]) {
        self.eval_f_g(x, g);
    }
    fn eval_jac_g(&mut self, x: &[f64], values: &mut [f64]) {
        let mut grad = std::mem::take(&mut self.spare.grad);
        self.eval_grad_f_jac_g(x, &mut grad, values);
        self.spare.grad = grad;
    }
    fn evaluates_together(&self) -> bool {
        true
    }
    fn eval_f_g(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        let mut f = [0.0];
        let outputs = &mut [&mut f[..], g];
        Compiled::eval_into(&self.f_g_fn, &[x, &self.params], outputs, &mut self.work);
        f[0]
    }
    fn eval_grad_f_jac_g(&mut self, x: &[f64], grad: &mut [f64], jac: &mut [f64]) {
        let outputs = &mut [grad, jac];
        Compiled::eval_into(
            &self.grad_jac_fn,
            &[x, &self.params],
            outputs,
            &mut self.work,
        );
    }
    fn eval_hess_l(&mut self, x: &[f64], obj_factor: f64, lambda: &[f64], values: &mut [f64]) {
        Compiled::eval(
            &self.hess_fn,
            &[x, &self.params, &[obj_factor], lambda],
            values,
            &mut self.work,
        );
    }
    fn variable_name(&self, i: usize) -> String {
        self.variable_names
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("x[{i}]"))
    }
    fn constraint_name(&self, i: usize) -> String {
        row_name(&self.constraint_blocks, i, "g")
    }
    fn affine_cones(&self) -> &[AffineCone] {
        &self.affine_cones
    }
    fn cone_jac_sparsity(&self) -> Option<&Sparsity> {
        self.cone_fns.as_ref().map(|c| &c.jacobian_sparsity)
    }
    fn eval_cone_entries(&mut self, x: &[f64], out: &mut [f64]) {
        if let Some(c) = &self.cone_fns {
            Compiled::eval(&c.entries, &[x, &self.params], out, &mut self.work);
        }
    }
    fn eval_cone_jac(&mut self, x: &[f64], values: &mut [f64]) {
        if let Some(c) = &self.cone_fns {
            Compiled::eval(&c.jacobian, &[x, &self.params], values, &mut self.work);
        }
    }
}
