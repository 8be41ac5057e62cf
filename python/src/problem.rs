//! `Problem`: the Opti-like builder (nlp::Problem), its solves, and pickling by replay.
//!
//! Every builder call is recorded as a [`Step`]; pickling prints the steps' expressions
//! with symx's printer and unpickling replays them, parsing the text back against the
//! rebuilt problem's symbols (names are unique within a problem), so a problem crosses
//! processes as its formulation, not as a graph of thread-bound handles.
use std::ops::ControlFlow;

use nlp::{Compiled, NumericNlp, Solver, SolverOptions};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};
use serde::{Deserialize, Serialize};
use symx::{Evaluator, Expr};

use crate::error::{build_err, option_err, solve_err};
use crate::expr::{operand, symbols, PyConstraint, PyExpr};
use crate::function::numbers;
use crate::same_thread::SameThread;
use crate::solution::{iteration_dict, PySolution};

/// One recorded builder call; `E` is an expression (`Expr` live, `String` pickled).
#[derive(Clone, Serialize, Deserialize)]
enum Step<E> {
    Variable {
        name: String,
        rows: usize,
        cols: usize,
    },
    Parameter {
        name: String,
        n: usize,
    },
    Minimize {
        f: E,
    },
    Constraint {
        name: Option<String>,
        rows: Vec<(E, Option<f64>, Option<f64>)>,
    },
    Initial {
        targets: Vec<E>,
        values: Vec<f64>,
    },
    Value {
        targets: Vec<E>,
        values: Vec<f64>,
    },
    Cone {
        name: String,
        v: Vec<E>,
        t: E,
    },
    Complementarity {
        name: String,
        a: E,
        b: E,
    },
    DetectSimpleBounds {
        on: bool,
    },
}

impl<E> Step<E> {
    /// The same step with every expression mapped by `f`.
    fn map<F, R>(&self, mut f: impl FnMut(&E) -> Result<F, R>) -> Result<Step<F>, R> {
        let mut many = |v: &Vec<E>| v.iter().map(&mut f).collect::<Result<Vec<F>, R>>();
        Ok(match self {
            Step::Variable { name, rows, cols } => Step::Variable {
                name: name.clone(),
                rows: *rows,
                cols: *cols,
            },
            Step::Parameter { name, n } => Step::Parameter {
                name: name.clone(),
                n: *n,
            },
            Step::Minimize { f: e } => Step::Minimize { f: f(e)? },
            Step::Constraint { name, rows } => Step::Constraint {
                name: name.clone(),
                rows: rows
                    .iter()
                    .map(|(e, l, u)| Ok((f(e)?, *l, *u)))
                    .collect::<Result<_, R>>()?,
            },
            Step::Initial { targets, values } => Step::Initial {
                targets: many(targets)?,
                values: values.clone(),
            },
            Step::Value { targets, values } => Step::Value {
                targets: many(targets)?,
                values: values.clone(),
            },
            Step::Cone { name, v, t } => Step::Cone {
                name: name.clone(),
                v: many(v)?,
                t: f(t)?,
            },
            Step::Complementarity { name, a, b } => Step::Complementarity {
                name: name.clone(),
                a: f(a)?,
                b: f(b)?,
            },
            Step::DetectSimpleBounds { on } => Step::DetectSimpleBounds { on: *on },
        })
    }
}

/// A row bound as stored: `None` for ±∞ (no bound); NaN is kept, so that the builder
/// rejects it naming the constraint (it used to become "no bound", silently).
fn row_bound(v: f64) -> Option<f64> {
    (!v.is_infinite()).then_some(v)
}

/// An optimisation problem built symbolically (CasADi's `Opti`): variables, parameters,
/// objective, constraints, cones and complementarity; solved by `solve`.
///
/// The problem is compiled (gradient, sparse Jacobian and Hessian) at the first solve
/// and the compiled form is reused while only initial values and parameter values change
/// (`set_initial`, `set_value`); any structural call recompiles at the next solve.
/// A problem belongs to the thread that built it (its expressions live in that thread's
/// graph); using it from another thread raises `BuildError`. Pickle it to use it
/// elsewhere: an unpickled problem is rebuilt in the first thread that uses it.
#[pyclass(name = "Problem", module = "symnlp")]
pub struct PyProblem {
    /// The thread whose graph holds `pb`'s expressions.
    owner: std::thread::ThreadId,
    /// An unpickled problem's `to_json` text, replayed by the first thread that uses it.
    pending: Option<String>,
    pb: nlp::Problem,
    steps: Vec<Step<Expr>>,
    compiled: Option<Compiled>,
    /// How `compiled` evaluates (`compile(evaluator=...)`; kept across recompilations,
    /// not pickled).
    evaluator: Evaluator,
    sensitivity: Option<nlp::ParametricSensitivity>,
}

// SAFETY: the thread-bound fields (expressions indexing the owner's graph) are only read
// or written after `bind` checked that the calling thread is `owner` (or rebuilt them in
// the calling thread). Other threads can only move or drop a problem, and dropping touches
// no graph: `Expr` is an index, and no type of nlp or symx held here implements `Drop`
// with graph access.
unsafe impl Send for PyProblem {}
// SAFETY: as above; the methods taking `&self` (`__repr__`, `bounded`) read no expression.
unsafe impl Sync for PyProblem {}

impl PyProblem {
    /// Makes the problem usable on this thread: replays a pending (unpickled) problem
    /// here, or checks that this thread built it.
    fn bind(&mut self) -> PyResult<()> {
        if let Some(text) = self.pending.take() {
            *self = PyProblem::replay(&text)?;
            return Ok(());
        }
        if self.owner != std::thread::current().id() {
            return Err(crate::error::BuildError::new_err(
                "this Problem was built on another thread and its expressions live there; \
                 pickle it (or use to_json/from_json) to use it on this thread",
            ));
        }
        Ok(())
    }

    /// A problem rebuilt from `to_json`'s text in this thread's graph.
    fn replay(text: &str) -> PyResult<PyProblem> {
        let steps: Vec<Step<String>> = serde_json::from_str(text).map_err(build_err)?;
        let mut p = PyProblem::new();
        for s in steps {
            let symbols: Vec<Expr> =
                p.pb.variables()
                    .iter()
                    .chain(p.pb.parameters())
                    .copied()
                    .collect();
            let live = s.map(|t| symx::parse(t, &symbols).map_err(build_err))?;
            p.apply(live)?;
        }
        Ok(p)
    }

    fn structural(&mut self, step: Step<Expr>) {
        self.steps.push(step);
        self.compiled = None;
        self.sensitivity = None;
    }

    fn apply(&mut self, step: Step<Expr>) -> PyResult<()> {
        match &step {
            Step::Variable { name, rows, cols } => {
                self.pb
                    .variable_matrix(name, *rows, *cols)
                    .map_err(build_err)?;
            }
            Step::Parameter { name, n } => {
                self.pb.parameter(name, *n).map_err(build_err)?;
            }
            Step::Minimize { f } => self.pb.minimize(*f),
            Step::Constraint { name, rows } => {
                // Runs of rows with the same bounds as one part each (a vector relation
                // is one run): one allocation per run, not per row.
                let runs = rows.chunk_by(|a, b| (a.1, a.2) == (b.1, b.2));
                let c = nlp::Constraint::all(runs.map(|run| {
                    let (l, u) = (run[0].1, run[0].2);
                    let entries: Vec<Expr> = run.iter().map(|r| r.0).collect();
                    nlp::bounded(
                        l.unwrap_or(f64::NEG_INFINITY),
                        symx::Matrix::from_vec(entries),
                        u.unwrap_or(f64::INFINITY),
                    )
                }));
                match name {
                    Some(n) => self.pb.subject_to_named(n, c),
                    None => self.pb.subject_to(c),
                }
                .map_err(build_err)?;
            }
            Step::Initial { targets, values } => {
                self.pb.set_initial(targets, values).map_err(build_err)?;
                if let Some(c) = &mut self.compiled {
                    let idx = self.pb.variable_indices(targets).map_err(build_err)?;
                    let mut x0 = vec![0.0; c.n()];
                    c.initial_point(&mut x0);
                    for (i, v) in idx.into_iter().zip(values) {
                        x0[i] = *v;
                    }
                    c.set_initial_point(&x0).map_err(build_err)?;
                }
                self.steps.push(step);
                return Ok(());
            }
            Step::Value { targets, values } => {
                self.pb
                    .set_value(targets.as_slice(), values)
                    .map_err(build_err)?;
                if let Some(c) = &mut self.compiled {
                    c.set_value(targets.as_slice(), values).map_err(build_err)?;
                }
                self.steps.push(step);
                return Ok(());
            }
            Step::Cone { name, v, t } => {
                self.pb.subject_to_cone(name, v, *t).map_err(build_err)?;
            }
            Step::Complementarity { name, a, b } => {
                self.pb.complementarity(name, *a, *b).map_err(build_err)?;
            }
            Step::DetectSimpleBounds { on } => self.pb.set_detect_simple_bounds(*on),
        }
        self.structural(step);
        Ok(())
    }

    /// Values broadcast to `n` entries (a single number is repeated).
    fn values_for(n: usize, values: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
        let v = numbers(values)?;
        match v.len() {
            1 => Ok(vec![v[0]; n]),
            k if k == n => Ok(v),
            k => Err(PyValueError::new_err(format!(
                "{what}: {k} values for {n} entries"
            ))),
        }
    }

    fn ensure_compiled(&mut self, py: Python<'_>) -> PyResult<()> {
        if self.compiled.is_none() {
            self.compiled = Some(compile_without_gil(py, &self.pb, self.evaluator)?);
        }
        Ok(())
    }

    fn names(&self) -> Vec<String> {
        symbol_names(&self.pb)
    }

    fn run(
        &mut self,
        py: Python<'_>,
        solver: &str,
        options: Option<&Bound<'_, PyDict>>,
        callback: Option<Py<PyAny>>,
        warm: Option<&PySolution>,
    ) -> PyResult<PySolution> {
        self.bind()?;
        let backend = make_solver(solver, options)?;
        self.ensure_compiled(py)?;
        let names = self.names();
        let compiled = self.compiled.as_mut().expect("compiled above");
        solve_compiled(py, compiled, backend.as_ref(), callback, warm, names)
    }
}

/// `pb` compiled with the GIL released, its functions evaluated by `evaluator`.
pub fn compile_without_gil(
    py: Python<'_>,
    pb: &nlp::Problem,
    evaluator: Evaluator,
) -> PyResult<Compiled> {
    let pb = SameThread(pb);
    let c = py.allow_threads(move || {
        let pb = pb;
        pb.0.compile_with(nlp::CompileOptions { evaluator })
    });
    c.map_err(build_err)
}

/// The evaluator named `name`: `"tape"` (the interpreter, the default) or `"jit"`
/// (machine code by Cranelift, bit-identical values).
pub fn evaluator_named(name: &str) -> PyResult<Evaluator> {
    match name {
        "tape" => Ok(Evaluator::Tape),
        "jit" => Ok(Evaluator::Jit),
        other => Err(crate::error::OptionError::new_err(format!(
            "unknown evaluator '{other}': expected 'tape' or 'jit'"
        ))),
    }
}

/// `compiled` evaluated by `evaluator` (converted with the GIL released).
pub fn with_evaluator_without_gil(
    py: Python<'_>,
    compiled: Compiled,
    evaluator: Evaluator,
) -> PyResult<Compiled> {
    let c = SameThread(compiled);
    py.allow_threads(move || {
        let c = c;
        c.0.with_evaluator(evaluator)
    })
    .map_err(build_err)
}

/// The names of `pb`'s variables then parameters, entry by entry (what a [`PySolution`]
/// resolves symbols by).
pub fn symbol_names(pb: &nlp::Problem) -> Vec<String> {
    pb.variables()
        .iter()
        .chain(pb.parameters())
        .map(|e| e.name().unwrap_or_default())
        .collect()
}

/// Solves `compiled` with `backend` (warm from `warm` if given) without the GIL;
/// `callback(info)` is called with the GIL at each iteration (`False` stops the solve, an
/// exception stops it and propagates). `names`: the problem's [`symbol_names`].
pub fn solve_compiled(
    py: Python<'_>,
    compiled: &mut Compiled,
    backend: &dyn Solver,
    callback: Option<Py<PyAny>>,
    warm: Option<&PySolution>,
    names: Vec<String>,
) -> PyResult<PySolution> {
    let parameters = compiled.parameter_values().to_vec();
    let warm = warm.map(|w| &w.inner);
    let mut raised: Option<PyErr> = None;
    let result = py.allow_threads(|| match callback {
        None => backend.solve_dyn(compiled, warm, None),
        Some(cb) => {
            let mut call = |view: &nlp::IterationView<'_>| -> ControlFlow<()> {
                Python::with_gil(|py| {
                    let go = iteration_dict(py, view.record()).and_then(|d| {
                        d.set_item("x", numpy::IntoPyArray::into_pyarray(view.x().to_vec(), py))?;
                        cb.call1(py, (d,))
                    });
                    match go {
                        Ok(r) if r.bind(py).is(&PyBool::new(py, false).to_owned()) => {
                            ControlFlow::Break(())
                        }
                        Ok(_) => ControlFlow::Continue(()),
                        Err(e) => {
                            raised = Some(e);
                            ControlFlow::Break(())
                        }
                    }
                })
            };
            backend.solve_dyn(compiled, warm, Some(&mut call))
        }
    });
    if let Some(e) = raised {
        return Err(e);
    }
    Ok(PySolution {
        inner: result.map_err(solve_err)?,
        names,
        parameters,
    })
}

/// The back end named `solver` with `options` (IPOPT names) applied.
pub fn make_solver(solver: &str, options: Option<&Bound<'_, PyDict>>) -> PyResult<Box<dyn Solver>> {
    let mut opts: Box<dyn SolverOptions> = match solver {
        "ipm" | "ipopt" => Box::new(nlp::IpmOptions::default()),
        "sqp" => Box::new(nlp::SqpOptions::default()),
        other => {
            return Err(crate::error::OptionError::new_err(format!(
                "unknown solver '{other}': expected 'ipm' or 'sqp'"
            )))
        }
    };
    set_options(opts.as_mut(), options)?;
    Ok(opts.solver())
}

/// The SQP's options with `options` (IPOPT-style names) set.
pub fn sqp_options(options: Option<&Bound<'_, PyDict>>) -> PyResult<nlp::SqpOptions> {
    let mut opts = nlp::SqpOptions::default();
    set_options(&mut opts, options)?;
    Ok(opts)
}

/// Sets `options` (a dict of IPOPT-style names to values) on `opts`.
fn set_options(opts: &mut dyn SolverOptions, options: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
    let Some(d) = options else {
        return Ok(());
    };
    let mut assignments = Vec::with_capacity(d.len());
    for (k, v) in d.iter() {
        let key: String = k.extract()?;
        let value = if v.is_instance_of::<PyBool>() {
            if v.extract::<bool>()? {
                "true".to_string()
            } else {
                "false".to_string()
            }
        } else {
            v.str()?.to_string()
        };
        assignments.push(format!("{key}={value}"));
    }
    let refs: Vec<&str> = assignments.iter().map(String::as_str).collect();
    opts.set_options_by_name(&refs).map_err(option_err)
}

#[pymethods]
impl PyProblem {
    /// An empty problem.
    #[new]
    fn new() -> PyProblem {
        PyProblem {
            owner: std::thread::current().id(),
            pending: None,
            pb: nlp::Problem::new(),
            steps: Vec::new(),
            compiled: None,
            evaluator: Evaluator::Tape,
            sensitivity: None,
        }
    }

    /// Declares `rows × cols` variables named `name[i]` (unbounded, initial value 0).
    #[pyo3(signature = (name, rows = 1, cols = 1))]
    fn variable(&mut self, name: &str, rows: usize, cols: usize) -> PyResult<PyExpr> {
        self.bind()?;
        let m = self
            .pb
            .variable_matrix(name, rows, cols)
            .map_err(build_err)?;
        self.structural(Step::Variable {
            name: name.into(),
            rows,
            cols,
        });
        Ok(PyExpr::new(m))
    }

    /// Declares `n` parameters named `name[i]`; give them values with `set_value` before
    /// solving; changing them later does not rebuild the problem.
    #[pyo3(signature = (name, n = 1))]
    fn parameter(&mut self, name: &str, n: usize) -> PyResult<PyExpr> {
        self.bind()?;
        let m = self.pb.parameter(name, n).map_err(build_err)?;
        self.structural(Step::Parameter {
            name: name.into(),
            n,
        });
        Ok(PyExpr::new(m))
    }

    /// Sets the objective (a scalar expression) to minimise.
    fn minimize(&mut self, f: &Bound<'_, PyAny>) -> PyResult<()> {
        self.bind()?;
        let m = operand(f)?;
        let f = PyExpr::new(m).as_scalar("minimize")?;
        self.apply(Step::Minimize { f })
    }

    /// Adds constraints: a `Constraint` (from `<=`, `>=`, `==` or `bounded`) or a list
    /// of them; `name` labels the rows in logs and errors.
    #[pyo3(signature = (constraint, name = None))]
    fn subject_to(&mut self, constraint: &Bound<'_, PyAny>, name: Option<String>) -> PyResult<()> {
        self.bind()?;
        let parts: Vec<PyRef<'_, PyConstraint>> =
            match constraint.extract::<PyRef<'_, PyConstraint>>() {
                Ok(c) => vec![c],
                Err(_) => constraint.extract().map_err(|_| {
                    pyo3::exceptions::PyTypeError::new_err(
                        "subject_to: expected a Constraint (e.g. x >= 0) or a list of them",
                    )
                })?,
            };
        let mut rows = Vec::new();
        for p in &parts {
            let c = &p.c;
            // A shape mismatch is reported by nlp when the parts are added.
            if c.is_empty() {
                continue;
            }
            for ((e, l), u) in c
                .expressions()
                .into_iter()
                .zip(c.lower_bounds())
                .zip(c.upper_bounds())
            {
                rows.push((e, row_bound(l), row_bound(u)));
            }
        }
        self.apply(Step::Constraint { name, rows })
    }

    /// `lower <= expr <= upper` entry by entry (numbers; `None` for no bound).
    #[pyo3(signature = (lower, expr, upper))]
    fn bounded(
        &self,
        lower: Option<f64>,
        expr: &Bound<'_, PyAny>,
        upper: Option<f64>,
    ) -> PyResult<PyConstraint> {
        crate::expr::bounded(lower, expr, upper)
    }

    /// Second-order cone `‖v‖₂ ≤ t`.
    fn subject_to_cone(
        &mut self,
        name: &str,
        v: &Bound<'_, PyAny>,
        t: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        self.bind()?;
        let v = operand(v)?.entries().to_vec();
        let t = PyExpr::new(operand(t)?).as_scalar("subject_to_cone: t")?;
        self.apply(Step::Cone {
            name: name.into(),
            v,
            t,
        })
    }

    /// Complementarity `0 ≤ a ⟂ b ≥ 0` (scalars).
    fn complementarity(
        &mut self,
        name: &str,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        self.bind()?;
        let a = PyExpr::new(operand(a)?).as_scalar("complementarity: a")?;
        let b = PyExpr::new(operand(b)?).as_scalar("complementarity: b")?;
        self.apply(Step::Complementarity {
            name: name.into(),
            a,
            b,
        })
    }

    /// Initial values of variables (a number is repeated over the entries).
    fn set_initial(&mut self, x: &PyExpr, values: &Bound<'_, PyAny>) -> PyResult<()> {
        self.bind()?;
        let targets = symbols(&x.m, "set_initial")?;
        let values = Self::values_for(targets.len(), values, "set_initial")?;
        self.apply(Step::Initial { targets, values })
    }

    /// Values of parameters (a number is repeated over the entries). Does not rebuild.
    fn set_value(&mut self, p: &PyExpr, values: &Bound<'_, PyAny>) -> PyResult<()> {
        self.bind()?;
        let targets = symbols(&p.m, "set_value")?;
        let values = Self::values_for(targets.len(), values, "set_value")?;
        self.apply(Step::Value { targets, values })
    }

    /// Turns single-variable constraint rows into bounds at compile time (default on).
    fn set_detect_simple_bounds(&mut self, on: bool) -> PyResult<()> {
        self.bind()?;
        self.apply(Step::DetectSimpleBounds { on })
    }

    /// The variable or parameter declared as `name`, as a column of its entries (for a
    /// problem rebuilt from pickle or `from_json`, whose handles the caller does not hold).
    fn lookup(&mut self, name: &str) -> PyResult<PyExpr> {
        self.bind()?;
        let prefix = format!("{name}[");
        let found: Vec<Expr> = self
            .pb
            .variables()
            .iter()
            .chain(self.pb.parameters())
            .copied()
            .filter(|e| {
                e.name()
                    .is_some_and(|n| n == name || n.starts_with(&prefix))
            })
            .collect();
        if found.is_empty() {
            return Err(crate::error::BuildError::new_err(format!(
                "lookup: no variable or parameter named '{name}'"
            )));
        }
        Ok(PyExpr::new(symx::Matrix::from_vec(found)))
    }

    /// Number of variables (entries).
    #[getter]
    fn n_variables(&mut self) -> PyResult<usize> {
        self.bind()?;
        Ok(self.pb.n_variables())
    }

    /// Number of constraint rows.
    #[getter]
    fn n_constraints(&mut self) -> PyResult<usize> {
        self.bind()?;
        Ok(self.pb.n_constraints())
    }

    /// Compiles now (otherwise the first solve does), its functions evaluated by
    /// `evaluator`: `"tape"` (the default) or `"jit"` (machine code, CasADi's `jit`
    /// option: bit-identical values, so identical iterates, several times faster per
    /// evaluation at a compile time worth it when the problem is solved many times). The
    /// choice stays for later recompilations of this object. Releases the GIL.
    #[pyo3(signature = (evaluator = "tape"))]
    fn compile(&mut self, py: Python<'_>, evaluator: &str) -> PyResult<()> {
        self.bind()?;
        self.evaluator = evaluator_named(evaluator)?;
        if let Some(c) = self.compiled.take() {
            self.compiled = Some(with_evaluator_without_gil(py, c, self.evaluator)?);
        }
        self.ensure_compiled(py)
    }

    /// Solves with `solver` (`"ipm"`, the default, or `"sqp"`) and `options` by their
    /// IPOPT names (`{"tol": 1e-10, "max_iter": 500, "print_level": 0}`).
    /// `callback(info)` is called at each iteration with a dict of the log's columns and
    /// `x`; returning `False` stops the solve (status `User_Requested_Stop`), an exception
    /// stops it and propagates. Returns a `Solution` whatever the status (check
    /// `success`); raises `SolveError` when the solve cannot run. Releases the GIL.
    #[pyo3(signature = (solver = "ipm", options = None, callback = None))]
    fn solve(
        &mut self,
        py: Python<'_>,
        solver: &str,
        options: Option<&Bound<'_, PyDict>>,
        callback: Option<Py<PyAny>>,
    ) -> PyResult<PySolution> {
        self.run(py, solver, options, callback, None)
    }

    /// Like `solve`, started from `previous` (primal point and multipliers), e.g. after
    /// `set_value` on parameters in an MPC loop. IPM users typically also pass
    /// `{"warm_start_init_point": True}`-style options by their IPOPT names.
    #[pyo3(signature = (previous, solver = "ipm", options = None, callback = None))]
    fn solve_warm(
        &mut self,
        py: Python<'_>,
        previous: &PySolution,
        solver: &str,
        options: Option<&Bound<'_, PyDict>>,
        callback: Option<Py<PyAny>>,
    ) -> PyResult<PySolution> {
        self.run(py, solver, options, callback, Some(previous))
    }

    /// Parametric sensitivities of a converged `solution` of this problem at its current
    /// parameter values: a dict with `dx_dp` (array n × n_p, `[i, j] = ∂x*ᵢ/∂pⱼ`, parameters
    /// in declaration order), `dlam_g_dp` (m × n_p), `active_rows`, `active_bounds`,
    /// `weakly_active` (where the solution is not differentiable) and `residual`.
    /// The derivatives are compiled at the first call and reused. Releases the GIL.
    fn sensitivity<'py>(
        &mut self,
        py: Python<'py>,
        solution: &PySolution,
    ) -> PyResult<Bound<'py, PyDict>> {
        self.bind()?;
        self.ensure_compiled(py)?;
        let compiled = self.compiled.as_ref().expect("compiled above");
        sensitivity_dict(py, &self.pb, compiled, &mut self.sensitivity, solution)
    }

    /// The state pickle uses: the recorded builder calls with printed expressions.
    #[pyo3(name = "to_json")]
    fn json_state(&mut self) -> PyResult<String> {
        if let Some(text) = &self.pending {
            return Ok(text.clone());
        }
        self.bind()?;
        let steps: Vec<Step<String>> = self
            .steps
            .iter()
            .map(|s| s.map(|e| Ok::<_, PyErr>(e.to_string())))
            .collect::<PyResult<_>>()?;
        serde_json::to_string(&steps).map_err(build_err)
    }

    /// Rebuilds a problem from `to_json`'s text (in this thread's graph).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<PyProblem> {
        PyProblem::replay(text)
    }

    /// What unpickling calls: a problem rebuilt from `text` by the first thread using it.
    #[staticmethod]
    fn _from_pickle(text: String) -> PyProblem {
        let mut p = PyProblem::new();
        p.pending = Some(text);
        p
    }

    fn __reduce__(slf: &Bound<'_, Self>) -> PyResult<(Py<PyAny>, (String,))> {
        let f = slf.get_type().getattr("_from_pickle")?;
        Ok((f.unbind(), (slf.borrow_mut().json_state()?,)))
    }

    fn __repr__(&self) -> String {
        if self.pending.is_some() {
            return "Problem(unpickled, rebuilt at first use)".into();
        }
        // Lengths only: no expression is read, so any thread may ask.
        format!(
            "Problem({} variables, {} constraints)",
            self.pb.n_variables(),
            self.pb.n_constraints()
        )
    }
}

/// The parametric sensitivities of `solution` (a solution of `pb` compiled as `compiled`,
/// at its current parameter values) as the dict `Problem.sensitivity` documents; the
/// derivatives are compiled into `cache` at the first call. Releases the GIL.
pub fn sensitivity_dict<'py>(
    py: Python<'py>,
    pb: &nlp::Problem,
    compiled: &Compiled,
    cache: &mut Option<nlp::ParametricSensitivity>,
    solution: &PySolution,
) -> PyResult<Bound<'py, PyDict>> {
    let p = compiled.parameter_values().to_vec();
    if cache.is_none() {
        let pb = SameThread(pb);
        let ps = py.allow_threads(move || {
            let pb = pb;
            nlp::ParametricSensitivity::new(pb.0)
        });
        *cache = Some(ps.map_err(build_err)?);
    }
    let ps = cache.as_mut().expect("built above");
    let sol = &solution.inner;
    let s = py
        .allow_threads(|| ps.compute(sol, &p))
        .map_err(solve_err)?;
    let d = PyDict::new(py);
    d.set_item("dx_dp", columns(py, &s.dx_dp)?)?;
    d.set_item("dlam_g_dp", columns(py, &s.dlambda_dp)?)?;
    d.set_item("active_rows", s.active_rows.clone())?;
    d.set_item("active_bounds", s.active_bounds.clone())?;
    d.set_item("weakly_active", s.weakly_active.clone())?;
    d.set_item("residual", s.residual)?;
    Ok(d)
}

/// Columns `cols[j]` (each of one length) as a 2-D array with those columns.
fn columns(py: Python<'_>, cols: &[Vec<f64>]) -> PyResult<Py<PyAny>> {
    let rows = cols.first().map_or(0, Vec::len);
    let flat: Vec<f64> = cols.iter().flatten().copied().collect();
    let a = numpy::IntoPyArray::into_pyarray(flat, py);
    let m = numpy::PyArrayMethods::reshape_with_order(
        &a,
        [rows, cols.len()],
        numpy::npyffi::NPY_ORDER::NPY_FORTRANORDER,
    )?;
    Ok(m.into_any().unbind())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyProblem>()
}
