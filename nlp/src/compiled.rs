//! [`Compiled`]: a problem differentiated and compiled once; the numeric NLP solvers consume.
use crate::numeric::{AffineCone, NumericNlp};
use crate::problem::{row_name, Block, BuildError, Problem};
use symx::{Expr, Function, Matrix, Sparsity};

/// A compiled problem: evaluators for f, ∇f, g, the sparse Jacobian of g and the sparse
/// lower-triangular Lagrangian Hessian, with fixed sparsity and their own work space.
///
/// It holds no symbolic expressions, so it is `Send` and can be solved on another thread.
/// Parameter values can change between solves ([`Compiled::set_parameter`]) without
/// recompiling.
pub struct Compiled {
    n: usize,
    m: usize,
    x_l: Vec<f64>,
    x_u: Vec<f64>,
    g_l: Vec<f64>,
    g_u: Vec<f64>,
    x0: Vec<f64>,
    params: Vec<f64>,
    f_fn: Function,
    grad_fn: Function,
    g_fn: Function,
    jac_fn: Function,
    hess_fn: Function,
    jac_sparsity: Sparsity,
    hess_sparsity: Sparsity,
    work: Vec<f64>,
    variable_names: Vec<String>,
    variable_blocks: Vec<Block>,
    parameter_blocks: Vec<Block>,
    constraint_blocks: Vec<Block>,
    /// Affine second-order cones, with evaluators of their stacked entries `[t; v]` and
    /// of the entries' Jacobian (`None` without affine cones).
    affine_cones: Vec<AffineCone>,
    cone_fns: Option<(Function, Function, Sparsity)>,
}

impl Compiled {
    pub(crate) fn new(
        problem: &Problem,
        f: Expr,
        g: &[Expr],
        params: Vec<f64>,
    ) -> Result<Compiled, BuildError> {
        let parts = problem.parts();
        let x = parts.variables;
        let p = parts.parameters;
        let grad = symx::gradient(f, x)?;
        let jac = symx::jacobian(g, x)?;
        let sigma = Expr::sym("obj_factor");
        let lambda = Matrix::sym_vec("lambda", g.len());
        let hess = symx::lagrangian_hessian(f, g, x, sigma, &lambda)?;
        let f_fn = Function::new(&[x, p], &[&[f]])?;
        let grad_fn = Function::new(&[x, p], &[&grad])?;
        let g_fn = Function::new(&[x, p], &[g])?;
        let jac_fn = Function::new(&[x, p], &[jac.values()])?;
        let hess_fn = Function::new(&[x, p, &[sigma], &lambda], &[hess.values()])?;
        let mut affine_cones = Vec::new();
        let mut entries = Vec::new();
        for c in parts.cones.iter().filter(|c| c.affine) {
            affine_cones.push(AffineCone {
                row: c.row,
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
            Some((
                Function::new(&[x, p], &[&entries])?,
                Function::new(&[x, p], &[cj.values()])?,
                cj.sparsity().clone(),
            ))
        };
        let work_size = [&f_fn, &grad_fn, &g_fn, &jac_fn, &hess_fn]
            .into_iter()
            .chain(cone_fns.iter().flat_map(|(a, b, _)| [a, b]))
            .map(|f| f.work_size())
            .max()
            .unwrap_or(0);
        Ok(Compiled {
            n: x.len(),
            m: g.len(),
            x_l: parts.lower.to_vec(),
            x_u: parts.upper.to_vec(),
            g_l: parts.rows.iter().map(|r| r.lower).collect(),
            g_u: parts.rows.iter().map(|r| r.upper).collect(),
            x0: parts.initial.to_vec(),
            params,
            f_fn,
            grad_fn,
            g_fn,
            jac_fn,
            hess_fn,
            jac_sparsity: jac.sparsity().clone(),
            hess_sparsity: hess.sparsity().clone(),
            work: vec![0.0; work_size],
            variable_names: x
                .iter()
                .enumerate()
                .map(|(i, e)| e.name().unwrap_or_else(|| format!("x[{i}]")))
                .collect(),
            variable_blocks: parts.variable_blocks.to_vec(),
            parameter_blocks: parts.parameter_blocks.to_vec(),
            constraint_blocks: parts.constraint_blocks.to_vec(),
            affine_cones,
            cone_fns,
        })
    }

    /// Sets the values of the parameter declared as `name` (finite numbers, one per entry).
    pub fn set_parameter(&mut self, name: &str, values: &[f64]) -> Result<(), BuildError> {
        let block = self
            .parameter_blocks
            .iter()
            .find(|b| b.name == name)
            .ok_or_else(|| BuildError::NotDeclared {
                what: format!("set_parameter('{name}')"),
                index: 0,
                kind: "parameter",
            })?;
        if values.len() != block.len {
            return Err(BuildError::Size {
                what: format!("parameter '{name}'"),
                expected: block.len,
                got: values.len(),
            });
        }
        if let Some(&v) = values.iter().find(|v| !v.is_finite()) {
            return Err(BuildError::NotFinite {
                what: format!("value of parameter '{name}'"),
                value: v,
            });
        }
        self.params[block.range()].copy_from_slice(values);
        Ok(())
    }

    /// Replaces the initial guess (e.g. for a new solve after changing parameters).
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

    /// The named constraint groups, in the order of `g`.
    pub fn constraint_blocks(&self) -> &[Block] {
        &self.constraint_blocks
    }

    /// The entries of the variable declared as `name` in a primal vector `x`.
    pub fn variable_values<'a>(&self, name: &str, x: &'a [f64]) -> Option<&'a [f64]> {
        let b = self.variable_blocks.iter().find(|b| b.name == name)?;
        x.get(b.range())
    }

    fn eval(f: &Function, inputs: &[&[f64]], out: &mut [f64], work: &mut [f64]) {
        // Sizes are fixed at compilation and the solver passes vectors of those sizes; a
        // mismatch is a broken invariant of the caller.
        if let Err(e) = f.eval(inputs, &mut [out], work) {
            panic!("compiled problem evaluated with wrong sizes: {e}");
        }
    }
}

impl NumericNlp for Compiled {
    fn n(&self) -> usize {
        self.n
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
        let mut out = [0.0];
        Compiled::eval(&self.f_fn, &[x, &self.params], &mut out, &mut self.work);
        out[0]
    }
    fn eval_grad_f(&mut self, x: &[f64], grad: &mut [f64]) {
        Compiled::eval(&self.grad_fn, &[x, &self.params], grad, &mut self.work);
    }
    fn eval_g(&mut self, x: &[f64], g: &mut [f64]) {
        Compiled::eval(&self.g_fn, &[x, &self.params], g, &mut self.work);
    }
    fn eval_jac_g(&mut self, x: &[f64], values: &mut [f64]) {
        Compiled::eval(&self.jac_fn, &[x, &self.params], values, &mut self.work);
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
        self.cone_fns.as_ref().map(|(_, _, s)| s)
    }
    fn eval_cone_entries(&mut self, x: &[f64], out: &mut [f64]) {
        if let Some((f, _, _)) = &self.cone_fns {
            Compiled::eval(f, &[x, &self.params], out, &mut self.work);
        }
    }
    fn eval_cone_jac(&mut self, x: &[f64], values: &mut [f64]) {
        if let Some((_, f, _)) = &self.cone_fns {
            Compiled::eval(f, &[x, &self.params], values, &mut self.work);
        }
    }
}
