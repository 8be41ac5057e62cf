//! `Solution`: a solve's result, readable without the problem that produced it (values of
//! expressions are found by symbol name), picklable.
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use symx::{Expr, Matrix};

use crate::error::build_err;
use crate::expr::operand;

/// The result of `Problem.solve`: status, primal point, multipliers, statistics and the
/// iteration log. `value(expr)` evaluates any expression of the problem's variables and
/// parameters at the solution; it finds symbols by name, so a solution computed in another
/// process (and pickled back) reads the expressions of an identically built problem.
#[pyclass(name = "Solution", module = "symnlp", frozen)]
#[derive(Clone, Serialize, Deserialize)]
pub struct PySolution {
    pub inner: nlp::Solution,
    /// Symbol names of `x`'s entries, then of the parameters' entries.
    pub names: Vec<String>,
    /// Parameter values at the solve, after `x` in `names`.
    pub parameters: Vec<f64>,
}

/// A 1×1 result as a float, a column as a 1-D array, a matrix as a 2-D array (from
/// column-major `v`).
pub fn to_python(py: Python<'_>, v: &[f64], shape: (usize, usize)) -> PyResult<Py<PyAny>> {
    let (r, c) = shape;
    if (r, c) == (1, 1) {
        return Ok(v[0].into_pyobject(py)?.into_any().unbind());
    }
    let a = v.to_vec().into_pyarray(py);
    if c == 1 {
        return Ok(a.into_any().unbind());
    }
    let m = a.reshape_with_order([r, c], numpy::npyffi::NPY_ORDER::NPY_FORTRANORDER)?;
    Ok(m.into_any().unbind())
}

fn array(py: Python<'_>, v: &[f64]) -> Py<PyAny> {
    v.to_vec().into_pyarray(py).into_any().unbind()
}

/// The symbols in `roots`' graphs, each once, in order of discovery.
pub fn free_symbols(roots: &[Expr]) -> Vec<Expr> {
    let mut seen = std::collections::HashSet::new();
    let mut stack: Vec<Expr> = roots.to_vec();
    let mut out = Vec::new();
    while let Some(e) = stack.pop() {
        if !seen.insert(e.id()) {
            continue;
        }
        if e.is_symbol() {
            out.push(e);
        } else {
            stack.extend(e.operands());
        }
    }
    out
}

impl PySolution {
    /// Evaluates `m` at the solution, resolving its symbols by name.
    pub fn evaluate(&self, m: &Matrix) -> PyResult<Vec<f64>> {
        let syms = free_symbols(m.entries());
        let values: HashMap<&str, f64> = self
            .names
            .iter()
            .map(String::as_str)
            .zip(self.inner.x.iter().chain(&self.parameters).copied())
            .collect();
        let mut at = Vec::with_capacity(syms.len());
        for s in &syms {
            let name = s.name().unwrap_or_default();
            match values.get(name.as_str()) {
                Some(&v) => at.push(v),
                None => {
                    return Err(pyo3::exceptions::PyValueError::new_err(format!(
                        "value: symbol '{name}' is neither a variable nor a parameter of the solved problem"
                    )))
                }
            }
        }
        let f = symx::Function::new(&[&syms], &[m.entries()]).map_err(build_err)?;
        Ok(f.call(&[&at]).map_err(build_err)?.remove(0))
    }
}

fn record_dict<'py>(py: Python<'py>, r: &nlp::IterationRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("iter", r.iter)?;
    d.set_item("restoration", r.restoration)?;
    d.set_item("objective", r.objective)?;
    d.set_item("inf_pr", r.inf_pr)?;
    d.set_item("inf_du", r.inf_du)?;
    // The keys of both back ends, the other back end's as 0 (as before the records said
    // which back end wrote them).
    let mu = r.mu().unwrap_or(0.0);
    d.set_item("lg_mu", mu.log10())?;
    d.set_item("mu", mu)?;
    d.set_item("augmented_weight", r.augmented_weight().unwrap_or(0.0))?;
    d.set_item("d_norm", r.d_norm)?;
    d.set_item("regularization", r.regularization)?;
    d.set_item("alpha_du", r.alpha_du)?;
    d.set_item("alpha_pr", r.alpha_pr)?;
    d.set_item("ls", r.ls)?;
    Ok(d)
}

/// An iteration record as a dict with IPOPT's column names.
pub fn iteration_dict<'py>(
    py: Python<'py>,
    r: &nlp::IterationRecord,
) -> PyResult<Bound<'py, PyDict>> {
    record_dict(py, r)
}

#[pymethods]
impl PySolution {
    /// The value of an expression (or a number/array) at the solution: a float for a
    /// scalar, a 1-D array for a column, a 2-D array for a matrix.
    fn value(&self, py: Python<'_>, expr: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        let m = operand(expr)?;
        let v = self.evaluate(&m)?;
        to_python(py, &v, m.shape())
    }

    /// IPOPT's return status name, e.g. `"Solve_Succeeded"`.
    #[getter]
    fn status(&self) -> String {
        self.inner.status.to_string()
    }

    /// True when the solve met its goal (solved, solved to acceptable level, or a feasible
    /// point found for a feasibility problem).
    #[getter]
    fn success(&self) -> bool {
        self.inner.status.is_success()
    }

    /// Objective value at the solution.
    #[getter]
    fn objective(&self) -> f64 {
        self.inner.objective
    }

    /// Primal point, in declaration order of the variables.
    #[getter]
    fn x(&self, py: Python<'_>) -> Py<PyAny> {
        array(py, &self.inner.x)
    }

    /// Constraint multipliers (CasADi's `lam_g`), in the order of the constraint rows.
    #[getter]
    fn lam_g(&self, py: Python<'_>) -> Py<PyAny> {
        array(py, &self.inner.lambda)
    }

    /// Bound multipliers as one vector `z_u - z_l` (CasADi's `lam_x`).
    #[getter]
    fn lam_x(&self, py: Python<'_>) -> Py<PyAny> {
        let v: Vec<f64> = self
            .inner
            .z_u
            .iter()
            .zip(&self.inner.z_l)
            .map(|(u, l)| u - l)
            .collect();
        array(py, &v)
    }

    /// Lower-bound multipliers (IPOPT's `z_L`).
    #[getter]
    fn z_l(&self, py: Python<'_>) -> Py<PyAny> {
        array(py, &self.inner.z_l)
    }

    /// Upper-bound multipliers (IPOPT's `z_U`).
    #[getter]
    fn z_u(&self, py: Python<'_>) -> Py<PyAny> {
        array(py, &self.inner.z_u)
    }

    /// Constraint values at the solution.
    #[getter]
    fn g(&self, py: Python<'_>) -> Py<PyAny> {
        array(py, &self.inner.g)
    }

    /// Final constraint violation, dual infeasibility and complementarity.
    #[getter]
    fn constr_viol(&self) -> f64 {
        self.inner.constr_viol
    }

    /// The solver's final message.
    #[getter]
    fn message(&self) -> String {
        self.inner.message.clone()
    }

    /// Statistics as a dict: iteration and evaluation counts, timings (seconds).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.inner.stats;
        let d = PyDict::new(py);
        d.set_item("return_status", self.inner.status.to_string())?;
        d.set_item("success", self.inner.status.is_success())?;
        d.set_item("iter_count", s.iterations)?;
        d.set_item("restoration_iterations", s.restoration_iterations)?;
        d.set_item("n_eval_f", s.n_eval_f)?;
        d.set_item("n_eval_grad_f", s.n_eval_grad_f)?;
        d.set_item("n_eval_g", s.n_eval_g)?;
        d.set_item("n_eval_jac_g", s.n_eval_jac_g)?;
        d.set_item("n_eval_hess_l", s.n_eval_hess_l)?;
        d.set_item("n_factorizations", s.n_factorizations)?;
        d.set_item("t_wall_total", s.total_seconds)?;
        d.set_item("t_wall_eval", s.eval_seconds)?;
        d.set_item("t_wall_factor", s.factor_seconds)?;
        d.set_item("n_qp_solves", s.n_qp_solves)?;
        Ok(d)
    }

    /// The iteration log: one dict per iteration with IPOPT's columns (`iter`,
    /// `objective`, `inf_pr`, `inf_du`, `lg_mu`, `d_norm`, `alpha_du`, `alpha_pr`, `ls`).
    #[getter]
    fn iterations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let items: Vec<Bound<'py, PyDict>> = self
            .inner
            .stats
            .records
            .iter()
            .map(|r| record_dict(py, r))
            .collect::<PyResult<_>>()?;
        PyList::new(py, items)
    }

    /// The iteration log as IPOPT prints it.
    fn log_table(&self) -> String {
        nlp::format_table(&self.inner.stats.records)
    }

    /// The solution as JSON text (what pickling uses).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(self).map_err(build_err)
    }

    /// A solution from `to_json`'s text.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<PySolution> {
        serde_json::from_str(text).map_err(build_err)
    }

    fn __reduce__(slf: &Bound<'_, Self>) -> PyResult<(Py<PyAny>, (String,))> {
        let cls = slf.get_type().getattr("from_json")?;
        Ok((cls.unbind(), (slf.get().to_json()?,)))
    }

    fn __repr__(&self) -> String {
        format!(
            "Solution(status={}, objective={}, iterations={})",
            self.inner.status, self.inner.objective, self.inner.stats.iterations
        )
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySolution>()
}
