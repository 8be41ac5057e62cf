//! `Ocp`: the continuous-time optimal control builder (nlp::ocp::Ocp) with the model given
//! as Python callables that build expressions.
//!
//! The builder records its calls as [`Step`]s and writes an `nlp::ocp::Ocp` from them when
//! it transcribes (each setter also writes one, so a mistake is reported by the call that
//! made it, with nlp's message). The callables are called by the Rust transcription
//! wherever it evaluates them (once per stage, as the Rust closures would be); an
//! exception they raise is kept and re-raised, chained, by `transcribe`. An `Ocp` pickles
//! as its calls (the callables by Python's pickle: module-level functions, or lambdas
//! under cloudpickle, which Dask and Ray use).
use std::cell::RefCell;
use std::rc::Rc;

use nlp::ocp::{ControlInterpolation, Grid, Horizon, Ocp, Trajectory};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};
use pyo3::BoundObject;
use symx::{Expr, Matrix};

use crate::error::{build_err, BuildError};
use crate::expr::{operand, PyConstraint, PyExpr};
use crate::function::{numbers, PyFunction};
use crate::method::{PyButcherTableau, PyGrid, PyMethod};
use crate::mpc::PySimulator;
use crate::trajectory::PyTrajectory;
use crate::transcription::PyTranscription;

/// The first exception raised by a model callable during one build or transcription.
#[derive(Clone, Default)]
pub struct ErrorSlot(Rc<RefCell<Option<PyErr>>>);

impl ErrorSlot {
    /// Keeps `e` (if it is the first) as a `BuildError` naming `what`, chained to `e`.
    fn keep(&self, py: Python<'_>, what: &str, e: PyErr) {
        let mut slot = self.0.borrow_mut();
        if slot.is_none() {
            let err = BuildError::new_err(format!("Ocp {what}: {e}"));
            err.set_cause(py, Some(e));
            *slot = Some(err);
        }
    }

    /// The kept exception, if any.
    pub fn take(&self) -> Option<PyErr> {
        self.0.borrow_mut().take()
    }
}

/// One recorded builder call.
enum Step {
    Parameter(String, Vec<f64>),
    Dynamics(Py<PyAny>),
    DynamicsFunction(Py<PyFunction>),
    Horizon(Horizon),
    Interpolation(ControlInterpolation),
    StageCost(Py<PyAny>),
    TerminalCost(Py<PyAny>),
    Path(String, Py<PyAny>),
    Boundary(String, Py<PyAny>),
    StateBounds(Vec<f64>, Vec<f64>),
    ControlBounds(Vec<f64>, Vec<f64>),
    InitialState(Vec<f64>),
    InitialStateParameter(String, Vec<f64>),
    FinalState(Vec<f64>),
    StateGuess(Py<PyAny>),
    ControlGuess(Py<PyAny>),
    StateGuessLinear(Vec<f64>, Vec<f64>),
    GuessFrom(Box<Trajectory>),
}

/// `±∞` for missing bounds, as Python's `None` in the recorded call.
fn optional(v: &[f64]) -> Vec<Option<f64>> {
    v.iter().map(|&x| x.is_finite().then_some(x)).collect()
}

impl Step {
    /// The Python call `(method name, arguments)` that records this step (pickling).
    fn call<'py>(&self, py: Python<'py>) -> PyResult<(&'static str, Bound<'py, PyTuple>)> {
        let f = |f: &Py<PyAny>| f.clone_ref(py);
        let (name, args): (&'static str, Vec<PyObject>) = match self {
            Step::Parameter(n, v) => ("add_parameter", vec![obj(py, n)?, obj(py, v)?]),
            Step::Dynamics(g) => ("set_dynamics", vec![f(g)]),
            Step::DynamicsFunction(g) => {
                ("set_dynamics_function", vec![g.clone_ref(py).into_any()])
            }
            Step::Horizon(Horizon::Fixed(t)) => ("set_horizon", vec![obj(py, t)?]),
            Step::Horizon(Horizon::Free {
                lower,
                upper,
                guess,
            }) => (
                "set_free_horizon",
                vec![obj(py, lower)?, obj(py, upper)?, obj(py, guess)?],
            ),
            Step::Interpolation(i) => (
                "set_control_interpolation",
                vec![obj(py, interpolation_name(*i))?],
            ),
            Step::StageCost(g) => ("set_stage_cost", vec![f(g)]),
            Step::TerminalCost(g) => ("set_terminal_cost", vec![f(g)]),
            Step::Path(n, g) => ("add_path_constraint", vec![obj(py, n)?, f(g)]),
            Step::Boundary(n, g) => ("add_boundary_constraint", vec![obj(py, n)?, f(g)]),
            Step::StateBounds(l, u) => (
                "set_state_bounds",
                vec![obj(py, optional(l))?, obj(py, optional(u))?],
            ),
            Step::ControlBounds(l, u) => (
                "set_control_bounds",
                vec![obj(py, optional(l))?, obj(py, optional(u))?],
            ),
            Step::InitialState(v) => ("set_initial_state", vec![obj(py, v)?]),
            Step::InitialStateParameter(n, v) => (
                "set_initial_state_parameter",
                vec![obj(py, n)?, obj(py, v)?],
            ),
            Step::FinalState(v) => ("set_final_state", vec![obj(py, v)?]),
            Step::StateGuess(g) => ("set_state_guess", vec![f(g)]),
            Step::ControlGuess(g) => ("set_control_guess", vec![f(g)]),
            Step::StateGuessLinear(a, b) => {
                ("set_state_guess_linear", vec![obj(py, a)?, obj(py, b)?])
            }
            Step::GuessFrom(t) => (
                "set_guess_from",
                vec![Py::new(
                    py,
                    PyTrajectory {
                        inner: (**t).clone(),
                    },
                )?
                .into_any()],
            ),
        };
        Ok((name, PyTuple::new(py, args)?))
    }

    fn clone_ref(&self, py: Python<'_>) -> Step {
        match self {
            Step::Parameter(n, v) => Step::Parameter(n.clone(), v.clone()),
            Step::Dynamics(f) => Step::Dynamics(f.clone_ref(py)),
            Step::DynamicsFunction(f) => Step::DynamicsFunction(f.clone_ref(py)),
            Step::Horizon(h) => Step::Horizon(*h),
            Step::Interpolation(i) => Step::Interpolation(*i),
            Step::StageCost(f) => Step::StageCost(f.clone_ref(py)),
            Step::TerminalCost(f) => Step::TerminalCost(f.clone_ref(py)),
            Step::Path(n, f) => Step::Path(n.clone(), f.clone_ref(py)),
            Step::Boundary(n, f) => Step::Boundary(n.clone(), f.clone_ref(py)),
            Step::StateBounds(l, u) => Step::StateBounds(l.clone(), u.clone()),
            Step::ControlBounds(l, u) => Step::ControlBounds(l.clone(), u.clone()),
            Step::InitialState(v) => Step::InitialState(v.clone()),
            Step::InitialStateParameter(n, v) => Step::InitialStateParameter(n.clone(), v.clone()),
            Step::FinalState(v) => Step::FinalState(v.clone()),
            Step::StateGuess(f) => Step::StateGuess(f.clone_ref(py)),
            Step::ControlGuess(f) => Step::ControlGuess(f.clone_ref(py)),
            Step::StateGuessLinear(a, b) => Step::StateGuessLinear(a.clone(), b.clone()),
            Step::GuessFrom(t) => Step::GuessFrom(t.clone()),
        }
    }
}

/// `v` as a Python object.
fn obj<'py>(py: Python<'py>, v: impl IntoPyObject<'py>) -> PyResult<PyObject> {
    Ok(v.into_pyobject(py).map_err(Into::into)?.into_any().unbind())
}

fn interpolation_name(i: ControlInterpolation) -> &'static str {
    match i {
        ControlInterpolation::PiecewiseConstant => "constant",
        ControlInterpolation::PiecewiseLinear => "linear",
    }
}

/// A column vector from what a model callable returned (an `Expr` of any shape, read in
/// column-major order, or a list of scalars and numbers).
fn column(obj: &Bound<'_, PyAny>) -> PyResult<Matrix> {
    Ok(Matrix::from_vec(operand(obj)?.entries().to_vec()))
}

/// A scalar expression from what a cost callable returned.
fn scalar(obj: &Bound<'_, PyAny>) -> PyResult<Expr> {
    PyExpr::new(operand(obj)?).as_scalar("cost callable result")
}

/// Constraint rows from what a constraint callable returned: a `Constraint` or a list.
fn constraint(obj: &Bound<'_, PyAny>) -> PyResult<nlp::Constraint> {
    if let Ok(c) = obj.downcast::<PyConstraint>() {
        return Ok(c.borrow().c.clone());
    }
    let parts: Vec<PyRef<'_, PyConstraint>> = obj.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "expected a Constraint (e.g. x[0] >= 0) or a list of them, got {}",
            obj.get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        ))
    })?;
    Ok(nlp::Constraint::all(parts.iter().map(|p| p.c.clone())))
}

/// The expressions handed to a callable.
fn expr(m: &Matrix) -> PyExpr {
    PyExpr::new(m.clone())
}

/// An argument handed to a model callable.
enum Arg<'a> {
    /// A column of expressions (`x`, `u`, `p`).
    Column(&'a Matrix),
    /// A scalar expression (`T`).
    Scalar(Expr),
    /// A number (the time of a guess).
    Number(f64),
}

/// Calls `f(args)` and converts the result with `convert`; on an exception keeps it in
/// `slot` (naming `what`) and returns `fallback`.
fn call_with<T>(
    f: &Py<PyAny>,
    slot: &ErrorSlot,
    what: &str,
    args: &[Arg<'_>],
    convert: impl FnOnce(&Bound<'_, PyAny>) -> PyResult<T>,
    fallback: impl FnOnce() -> T,
) -> T {
    Python::with_gil(|py| {
        let items = args
            .iter()
            .map(|a| match a {
                Arg::Column(m) => Ok(Py::new(py, expr(m))?.into_any()),
                Arg::Scalar(e) => Ok(Py::new(py, PyExpr::scalar(*e))?.into_any()),
                Arg::Number(v) => obj(py, *v),
            })
            .collect::<PyResult<Vec<PyObject>>>();
        let r = items
            .and_then(|items| PyTuple::new(py, items))
            .and_then(|a| f.bind(py).call1(a))
            .and_then(|r| convert(&r));
        r.unwrap_or_else(|e| {
            slot.keep(py, what, e);
            fallback()
        })
    })
}

/// Writes `step` into `o`, wrapping callables as closures that report into `slot`.
fn apply(o: &mut Ocp, step: &Step, py: Python<'_>, slot: &ErrorSlot) -> PyResult<()> {
    let nx = o.nx();
    match step {
        Step::Parameter(n, v) => o.add_parameter(n, v).map_err(build_err)?,
        Step::Dynamics(f) => {
            let (f, slot) = (f.clone_ref(py), slot.clone());
            o.set_dynamics(move |x, u, p| {
                let args = [Arg::Column(x), Arg::Column(u), Arg::Column(p)];
                call_with(&f, &slot, "dynamics", &args, column, || {
                    Matrix::zeros(nx, 1)
                })
            });
        }
        Step::DynamicsFunction(f) => o
            .set_dynamics_function(f.get().function().clone())
            .map_err(build_err)?,
        Step::Horizon(h) => o.set_horizon(*h).map_err(build_err)?,
        Step::Interpolation(i) => o.set_control_interpolation(*i),
        Step::StageCost(f) => {
            let (f, slot) = (f.clone_ref(py), slot.clone());
            o.set_stage_cost(move |x, u, p| {
                let args = [Arg::Column(x), Arg::Column(u), Arg::Column(p)];
                call_with(&f, &slot, "stage cost", &args, scalar, Expr::zero)
            });
        }
        Step::TerminalCost(f) => {
            let (f, slot) = (f.clone_ref(py), slot.clone());
            o.set_terminal_cost(move |xt, p, t| {
                let args = [Arg::Column(xt), Arg::Column(p), Arg::Scalar(t)];
                call_with(&f, &slot, "terminal cost", &args, scalar, Expr::zero)
            });
        }
        Step::Path(name, f) => {
            let (f, slot, what) = (
                f.clone_ref(py),
                slot.clone(),
                format!("path constraint '{name}'"),
            );
            o.add_path_constraint(name, move |x, u, p| {
                let args = [Arg::Column(x), Arg::Column(u), Arg::Column(p)];
                call_with(&f, &slot, &what, &args, constraint, empty)
            });
        }
        Step::Boundary(name, f) => {
            let (f, slot, what) = (
                f.clone_ref(py),
                slot.clone(),
                format!("boundary constraint '{name}'"),
            );
            o.add_boundary_constraint(name, move |x0, xt, p, t| {
                let args = [
                    Arg::Column(x0),
                    Arg::Column(xt),
                    Arg::Column(p),
                    Arg::Scalar(t),
                ];
                call_with(&f, &slot, &what, &args, constraint, empty)
            });
        }
        Step::StateBounds(l, u) => o.set_state_bounds(l, u).map_err(build_err)?,
        Step::ControlBounds(l, u) => o.set_control_bounds(l, u).map_err(build_err)?,
        Step::InitialState(v) => o.set_initial_state(v).map_err(build_err)?,
        Step::InitialStateParameter(n, v) => {
            o.set_initial_state_parameter(n, v).map_err(build_err)?
        }
        Step::FinalState(v) => o.set_final_state(v).map_err(build_err)?,
        Step::StateGuess(f) => {
            let (f, slot) = (f.clone_ref(py), slot.clone());
            o.set_state_guess(move |t| guess(&f, &slot, "state guess", t));
        }
        Step::ControlGuess(f) => {
            let (f, slot) = (f.clone_ref(py), slot.clone());
            o.set_control_guess(move |t| guess(&f, &slot, "control guess", t));
        }
        Step::StateGuessLinear(a, b) => o.set_state_guess_linear(a, b).map_err(build_err)?,
        Step::GuessFrom(t) => o.set_guess_from(t),
    }
    Ok(())
}

fn empty() -> nlp::Constraint {
    nlp::Constraint::all(std::iter::empty())
}

fn guess(f: &Py<PyAny>, slot: &ErrorSlot, what: &str, t: f64) -> Vec<f64> {
    call_with(f, slot, what, &[Arg::Number(t)], numbers, Vec::new)
}

/// Bounds from Python: a list of numbers or `None` (no bound), or `None` for none at all.
fn bounds(v: Option<Vec<Option<f64>>>, n: usize, infinity: f64) -> Vec<f64> {
    match v {
        None => vec![infinity; n],
        Some(v) => v.into_iter().map(|x| x.unwrap_or(infinity)).collect(),
    }
}

/// A continuous-time optimal control problem (nlp's `Ocp`, docs/ocp.md):
/// `min ∫₀ᵀ l(x, u, p) dt + φ(x(T), p, T)` subject to `ẋ = f(x, u, p)`, path and boundary
/// constraints, bounds, and a fixed or free final time.
///
/// The model is given as Python callables of expressions — `f(x, u, p)`, `l(x, u, p)`,
/// `φ(xT, p, T)`, `c(x, u, p)`, `b(x0, xT, p, T)` — where `x`, `u`, `p` arrive as column
/// `Expr`s (`x[0]`, `x[1]`…) and `T` as a scalar `Expr`. `transcribe(method, N)` writes the
/// problem as an NLP (a `Transcription`), calling them at every stage. Mistakes raise
/// `BuildError` from the call that made them, with nlp's message.
#[pyclass(name = "Ocp", module = "symnlp")]
pub struct PyOcp {
    states: Vec<String>,
    controls: Vec<String>,
    steps: Vec<Step>,
}

impl PyOcp {
    /// Writes the `nlp::ocp::Ocp` of the recorded calls (this thread's graph).
    pub fn build(&self, py: Python<'_>, slot: &ErrorSlot) -> PyResult<Ocp> {
        let s: Vec<&str> = self.states.iter().map(String::as_str).collect();
        let c: Vec<&str> = self.controls.iter().map(String::as_str).collect();
        let mut o = Ocp::new(&s, &c);
        for step in &self.steps {
            apply(&mut o, step, py, slot)?;
        }
        Ok(o)
    }

    /// A copy holding the same callables (a transcription keeps the Ocp it was made from).
    pub fn snapshot(&self, py: Python<'_>) -> PyOcp {
        PyOcp {
            states: self.states.clone(),
            controls: self.controls.clone(),
            steps: self.steps.iter().map(|s| s.clone_ref(py)).collect(),
        }
    }

    /// Records `step` if the problem with it still builds; else raises nlp's error.
    fn record(&mut self, py: Python<'_>, step: Step) -> PyResult<()> {
        self.steps.push(step);
        if let Err(e) = self.build(py, &ErrorSlot::default()) {
            self.steps.pop();
            return Err(e);
        }
        Ok(())
    }
}

#[pymethods]
impl PyOcp {
    /// A problem with the named states and controls (their numbers are the sizes of `x`
    /// and `u`), no costs, no bounds and no horizon yet.
    #[new]
    #[pyo3(signature = (states, controls = Vec::new()))]
    fn new(states: Vec<String>, controls: Vec<String>) -> PyOcp {
        PyOcp {
            states,
            controls,
            steps: Vec::new(),
        }
    }

    /// The state names.
    #[getter]
    fn states(&self) -> Vec<String> {
        self.states.clone()
    }

    /// The control names.
    #[getter]
    fn controls(&self) -> Vec<String> {
        self.controls.clone()
    }

    /// Declares a parameter vector `name` with its values; the callables receive all
    /// parameters stacked in declaration order as `p`. In the transcription it is a
    /// parameter of that name (`Transcription.set_value(name, values)`, no rebuild).
    fn add_parameter(
        &mut self,
        py: Python<'_>,
        name: String,
        values: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let v = numbers(values)?;
        self.record(py, Step::Parameter(name, v))
    }

    /// The dynamics `ẋ = f(x, u, p)`: a callable returning as many entries as states (an
    /// `Expr` column or a list such as `[x[1], u[0] - x[0]]`).
    fn set_dynamics(&mut self, py: Python<'_>, f: Py<PyAny>) -> PyResult<()> {
        self.record(py, Step::Dynamics(f))
    }

    /// The dynamics as a compiled `Function` of `(x, u, p)` returning `ẋ`, called (not
    /// inlined) wherever the transcription evaluates the dynamics.
    fn set_dynamics_function(&mut self, py: Python<'_>, f: Py<PyFunction>) -> PyResult<()> {
        self.record(py, Step::DynamicsFunction(f))
    }

    /// A fixed final time `T > 0`.
    fn set_horizon(&mut self, py: Python<'_>, t: f64) -> PyResult<()> {
        self.record(py, Step::Horizon(Horizon::Fixed(t)))
    }

    /// A free final time `lower ≤ T ≤ upper` (a decision variable) starting from `guess`.
    #[pyo3(signature = (lower = 0.0, upper = f64::INFINITY, guess = 1.0))]
    fn set_free_horizon(
        &mut self,
        py: Python<'_>,
        lower: f64,
        upper: f64,
        guess: f64,
    ) -> PyResult<()> {
        self.record(py, Step::Horizon(Horizon::free(lower, upper, guess)))
    }

    /// `"constant"` (the default: one control per interval) or `"linear"` (controls at
    /// the nodes, linear in between).
    fn set_control_interpolation(&mut self, py: Python<'_>, kind: &str) -> PyResult<()> {
        let i = match kind {
            "constant" => ControlInterpolation::PiecewiseConstant,
            "linear" => ControlInterpolation::PiecewiseLinear,
            other => {
                return Err(PyValueError::new_err(format!(
                    "set_control_interpolation: unknown kind '{other}': expected 'constant' or 'linear'"
                )))
            }
        };
        self.record(py, Step::Interpolation(i))
    }

    /// The Lagrange integrand `l(x, u, p)` (a scalar) of the cost `∫₀ᵀ l dt`.
    fn set_stage_cost(&mut self, py: Python<'_>, l: Py<PyAny>) -> PyResult<()> {
        self.record(py, Step::StageCost(l))
    }

    /// The Mayer term `φ(xT, p, T)` (a scalar); `lambda xT, p, T: T` is minimum time.
    fn set_terminal_cost(&mut self, py: Python<'_>, phi: Py<PyAny>) -> PyResult<()> {
        self.record(py, Step::TerminalCost(phi))
    }

    /// A path constraint `c(x, u, p)` (a `Constraint` or a list of them) imposed at every
    /// grid node `t₀ … t_N` (at `t_N` with the last interval's control).
    fn add_path_constraint(&mut self, py: Python<'_>, name: String, c: Py<PyAny>) -> PyResult<()> {
        self.record(py, Step::Path(name, c))
    }

    /// A boundary constraint `b(x0, xT, p, T)` (a `Constraint` or a list of them).
    fn add_boundary_constraint(
        &mut self,
        py: Python<'_>,
        name: String,
        b: Py<PyAny>,
    ) -> PyResult<()> {
        self.record(py, Step::Boundary(name, b))
    }

    /// Bounds of the states at every grid and collocation point; `None` (or a `None`
    /// entry) for no bound.
    #[pyo3(signature = (lower = None, upper = None))]
    fn set_state_bounds(
        &mut self,
        py: Python<'_>,
        lower: Option<Vec<Option<f64>>>,
        upper: Option<Vec<Option<f64>>>,
    ) -> PyResult<()> {
        let n = self.states.len();
        let (l, u) = (
            bounds(lower, n, f64::NEG_INFINITY),
            bounds(upper, n, f64::INFINITY),
        );
        self.record(py, Step::StateBounds(l, u))
    }

    /// Bounds of the controls; `None` (or a `None` entry) for no bound.
    #[pyo3(signature = (lower = None, upper = None))]
    fn set_control_bounds(
        &mut self,
        py: Python<'_>,
        lower: Option<Vec<Option<f64>>>,
        upper: Option<Vec<Option<f64>>>,
    ) -> PyResult<()> {
        let n = self.controls.len();
        let (l, u) = (
            bounds(lower, n, f64::NEG_INFINITY),
            bounds(upper, n, f64::INFINITY),
        );
        self.record(py, Step::ControlBounds(l, u))
    }

    /// Fixes `x(0)`.
    fn set_initial_state(&mut self, py: Python<'_>, x0: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = numbers(x0)?;
        self.record(py, Step::InitialState(v))
    }

    /// Makes `x(0)` equal to a parameter `name` (initial value `x0`) for MPC: the measured
    /// state is set between solves without rebuilding (`Transcription.set_value`, `Mpc`).
    fn set_initial_state_parameter(
        &mut self,
        py: Python<'_>,
        name: String,
        x0: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let v = numbers(x0)?;
        self.record(py, Step::InitialStateParameter(name, v))
    }

    /// Fixes `x(T)`.
    fn set_final_state(&mut self, py: Python<'_>, xf: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = numbers(xf)?;
        self.record(py, Step::FinalState(v))
    }

    /// Guesses the states with `g(t)` (nx numbers) at the absolute time `t ∈ [0, T]` (`T`
    /// the fixed horizon or the free horizon's guess).
    fn set_state_guess(&mut self, py: Python<'_>, g: Py<PyAny>) -> PyResult<()> {
        self.record(py, Step::StateGuess(g))
    }

    /// Guesses the controls with `g(t)` (nu numbers), as `set_state_guess`.
    fn set_control_guess(&mut self, py: Python<'_>, g: Py<PyAny>) -> PyResult<()> {
        self.record(py, Step::ControlGuess(g))
    }

    /// Guesses the states on the straight line from `start` (t = 0) to `end` (t = T).
    fn set_state_guess_linear(
        &mut self,
        py: Python<'_>,
        start: &Bound<'_, PyAny>,
        end: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let (a, b) = (numbers(start)?, numbers(end)?);
        self.record(py, Step::StateGuessLinear(a, b))
    }

    /// Guesses states and controls from a previous `Trajectory` (e.g. on a coarser grid),
    /// interpolated linearly in normalised time.
    fn set_guess_from(&mut self, py: Python<'_>, previous: &PyTrajectory) -> PyResult<()> {
        self.record(py, Step::GuessFrom(Box::new(previous.inner.clone())))
    }

    /// Writes the problem as an NLP with `method` (a `Method`) on `intervals`: a number N
    /// of uniform intervals or a `Grid`. Calls the model callables at every stage; an
    /// exception they raise is re-raised as `BuildError` chained to it.
    fn transcribe(
        &self,
        py: Python<'_>,
        method: &PyMethod,
        intervals: &Bound<'_, PyAny>,
    ) -> PyResult<PyTranscription> {
        let grid = match intervals.downcast::<PyGrid>() {
            Ok(g) => g.get().grid.clone(),
            Err(_) => {
                let n: usize = intervals.extract().map_err(|_| {
                    PyTypeError::new_err("transcribe: intervals must be a number N >= 1 or a Grid")
                })?;
                Grid::uniform(n).map_err(build_err)?
            }
        };
        PyTranscription::new(py, self.snapshot(py), method.spec.clone(), grid)
    }

    /// A nominal plant for closed loops: `steps` steps of the Runge–Kutta `tableau` (a
    /// name or a `ButcherTableau`) on the dynamics, compiled once.
    #[pyo3(signature = (tableau = None, steps = 1))]
    fn simulator(
        &self,
        py: Python<'_>,
        tableau: Option<&Bound<'_, PyAny>>,
        steps: usize,
    ) -> PyResult<PySimulator> {
        let tableau = match tableau {
            None => nlp::ocp::ButcherTableau::rk4(),
            Some(t) => match t.downcast::<PyButcherTableau>() {
                Ok(t) => t.get().tableau.clone(),
                Err(_) => {
                    nlp::ocp::ButcherTableau::by_name(&t.extract::<String>()?).map_err(build_err)?
                }
            },
        };
        let slot = ErrorSlot::default();
        let o = self.build(py, &slot)?;
        let sim = nlp::ocp::Simulator::new(&o, tableau, steps);
        if let Some(e) = slot.take() {
            return Err(e);
        }
        Ok(PySimulator::new(sim.map_err(build_err)?, o.nu()))
    }

    /// What unpickling calls: the recorded calls replayed on a new problem.
    #[staticmethod]
    fn _replay(
        py: Python<'_>,
        states: Vec<String>,
        controls: Vec<String>,
        calls: Vec<(String, Py<PyTuple>)>,
    ) -> PyResult<Py<PyOcp>> {
        let ocp = Bound::new(py, PyOcp::new(states, controls))?;
        for (name, args) in calls {
            ocp.call_method1(name.as_str(), args.bind(py))?;
        }
        Ok(ocp.unbind())
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Py<PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let me = slf.borrow();
        let calls = me
            .steps
            .iter()
            .map(|s| s.call(py))
            .collect::<PyResult<Vec<_>>>()?;
        let calls = PyList::new(py, calls)?;
        let f = slf.get_type().getattr("_replay")?;
        let args = (me.states.clone(), me.controls.clone(), calls).into_pyobject(py)?;
        Ok((f.unbind(), args))
    }

    fn __repr__(&self) -> String {
        format!(
            "Ocp(states={:?}, controls={:?}, {} calls)",
            self.states,
            self.controls,
            self.steps.len()
        )
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyOcp>()
}
