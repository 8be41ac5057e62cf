//! `Transcription`: an `Ocp` written as an NLP (nlp::ocp::Transcription), compiled and
//! solved like a `Problem`, its solutions read back as `Trajectory`s.
//!
//! Like a `Problem`, a transcription's expressions live in the graph of the thread that
//! wrote it. It pickles as its `Ocp`, method, grid and the parameter values set since,
//! and an unpickled one is transcribed again by the first thread that uses it.
use nlp::ocp::{Grid, Transcription};
use nlp::Compiled;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use symx::Evaluator;

use crate::error::{build_err, BuildError};
use crate::expr::PyExpr;
use crate::function::numbers;
use crate::method::{MethodSpec, PyGrid, PyMethod};
use crate::ocp::{ErrorSlot, PyOcp};
use crate::problem::{
    compile_without_gil, evaluator_named, make_solver, sensitivity_dict, solve_compiled,
    symbol_names, with_evaluator_without_gil,
};
use crate::solution::PySolution;
use crate::trajectory::PyTrajectory;

/// The transcribed problem of this thread, its compiled form and caches.
pub struct Live {
    pub tr: Transcription,
    compiled: Option<Compiled>,
    sensitivity: Option<nlp::ParametricSensitivity>,
}

/// An `Ocp` written as an NLP by `Ocp.transcribe(method, N)`: solve it with `solve` (the
/// options of `Problem.solve`), read solutions with `trajectory(sol)` or `sol.value(expr)`
/// on `states` / `controls` / `final_time`, change parameters with `set_value` (no
/// rebuild), move a solution one stage forward with `shift` (MPC warm starts).
#[pyclass(name = "Transcription", module = "symnlp")]
pub struct PyTranscription {
    /// The thread whose graph holds `live`'s expressions.
    owner: std::thread::ThreadId,
    ocp: Py<PyOcp>,
    method: MethodSpec,
    grid: Grid,
    /// Parameter values set since transcription, in order (replayed after unpickling).
    values: Vec<(String, Vec<f64>)>,
    /// `None` for an unpickled transcription not yet used.
    live: Option<Live>,
}

// SAFETY: as for `PyProblem`: the thread-bound `live` (expressions indexing the owner's
// graph) is only touched after `live` checked the calling thread (or transcribed anew in
// it); other threads can only move or drop it, and dropping touches no graph.
unsafe impl Send for PyTranscription {}
// SAFETY: as above; `&self` methods read no expression.
unsafe impl Sync for PyTranscription {}

/// Writes `ocp` with `method` on `grid` in this thread's graph; an exception raised by a
/// model callable is re-raised first.
fn transcribe(
    py: Python<'_>,
    ocp: &PyOcp,
    method: &MethodSpec,
    grid: &Grid,
) -> PyResult<Transcription> {
    let slot = ErrorSlot::default();
    let o = ocp.build(py, &slot)?;
    let tr = o.transcribe_on(&method.method()?, grid);
    if let Some(e) = slot.take() {
        return Err(e);
    }
    tr.map_err(build_err)
}

impl PyTranscription {
    pub fn new(py: Python<'_>, ocp: PyOcp, method: MethodSpec, grid: Grid) -> PyResult<Self> {
        let tr = transcribe(py, &ocp, &method, &grid)?;
        Ok(PyTranscription {
            owner: std::thread::current().id(),
            ocp: Py::new(py, ocp)?,
            method,
            grid,
            values: Vec::new(),
            live: Some(Live {
                tr,
                compiled: None,
                sensitivity: None,
            }),
        })
    }

    /// The live transcription of this thread: transcribes an unpickled one here, or checks
    /// that this thread wrote it.
    pub fn live(&mut self, py: Python<'_>) -> PyResult<&mut Live> {
        if self.live.is_none() {
            let mut tr = transcribe(py, &self.ocp.borrow(py), &self.method, &self.grid)?;
            for (name, v) in &self.values {
                tr.problem_mut()
                    .set_value(name.as_str(), v)
                    .map_err(build_err)?;
            }
            self.owner = std::thread::current().id();
            self.live = Some(Live {
                tr,
                compiled: None,
                sensitivity: None,
            });
        } else if self.owner != std::thread::current().id() {
            return Err(BuildError::new_err(
                "this Transcription was written on another thread and its expressions live \
                 there; pickle it to use it on this thread",
            ));
        }
        Ok(self.live.as_mut().expect("set above"))
    }

    /// The compiled problem (compiled now, without the GIL, if not yet).
    fn compiled(&mut self, py: Python<'_>) -> PyResult<&mut Live> {
        let live = self.live(py)?;
        if live.compiled.is_none() {
            live.compiled = Some(compile_without_gil(py, live.tr.problem(), Evaluator::Tape)?);
        }
        Ok(live)
    }

    fn run(
        &mut self,
        py: Python<'_>,
        solver: &str,
        options: Option<&Bound<'_, PyDict>>,
        callback: Option<Py<PyAny>>,
        warm: Option<&PySolution>,
    ) -> PyResult<PySolution> {
        let backend = make_solver(solver, options)?;
        let live = self.compiled(py)?;
        let names = symbol_names(live.tr.problem());
        let compiled = live.compiled.as_mut().expect("compiled above");
        solve_compiled(py, compiled, backend.as_ref(), callback, warm, names)
    }

    /// The OCP this transcription was written from.
    pub fn ocp(&self) -> &Py<PyOcp> {
        &self.ocp
    }
}

#[pymethods]
impl PyTranscription {
    /// Compiles now (otherwise the first solve does), its functions evaluated by
    /// `evaluator` (`"tape"`, the default, or `"jit"`, as `Problem.compile`). Releases
    /// the GIL.
    #[pyo3(signature = (evaluator = "tape"))]
    fn compile(&mut self, py: Python<'_>, evaluator: &str) -> PyResult<()> {
        let evaluator = evaluator_named(evaluator)?;
        let live = self.live(py)?;
        let c = match live.compiled.take() {
            Some(c) => c,
            None => compile_without_gil(py, live.tr.problem(), evaluator)?,
        };
        live.compiled = Some(with_evaluator_without_gil(py, c, evaluator)?);
        Ok(())
    }

    /// Solves the NLP: as `Problem.solve` (`solver="ipm" | "sqp"`, `options` by IPOPT's
    /// names, `callback`). Returns a `Solution` whatever the status. Releases the GIL.
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

    /// Like `solve`, started from `previous` (e.g. `shift(previous)` in an MPC loop).
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

    /// Sets the parameter `name` (declared by `Ocp.add_parameter` or
    /// `set_initial_state_parameter`) without rebuilding.
    fn set_value(
        &mut self,
        py: Python<'_>,
        name: String,
        values: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let v = numbers(values)?;
        let live = self.live(py)?;
        live.tr
            .problem_mut()
            .set_value(name.as_str(), &v)
            .map_err(build_err)?;
        if let Some(c) = &mut live.compiled {
            c.set_value(name.as_str(), &v).map_err(build_err)?;
        }
        self.values.push((name, v));
        Ok(())
    }

    /// The solution `sol` of this transcription as a `Trajectory`.
    fn trajectory(&mut self, py: Python<'_>, sol: &PySolution) -> PyResult<PyTrajectory> {
        let live = self.live(py)?;
        let inner = live.tr.trajectory(&sol.inner).map_err(build_err)?;
        Ok(PyTrajectory { inner })
    }

    /// `sol` moved one stage forward (states, controls and their multipliers; the last
    /// stage duplicated): the warm start of the next MPC solve (docs/mpc.md §3). Needs a
    /// uniform grid.
    fn shift(&mut self, py: Python<'_>, sol: &PySolution) -> PyResult<PySolution> {
        let live = self.live(py)?;
        let inner = live.tr.shift(&sol.inner).map_err(build_err)?;
        Ok(PySolution {
            inner,
            names: sol.names.clone(),
            parameters: sol.parameters.clone(),
        })
    }

    /// Parametric sensitivities of a converged `solution` (the dict of
    /// `Problem.sensitivity`). Releases the GIL.
    fn sensitivity<'py>(
        &mut self,
        py: Python<'py>,
        solution: &PySolution,
    ) -> PyResult<Bound<'py, PyDict>> {
        let live = self.compiled(py)?;
        let compiled = live.compiled.as_ref().expect("compiled above");
        sensitivity_dict(
            py,
            live.tr.problem(),
            compiled,
            &mut live.sensitivity,
            solution,
        )
    }

    /// The grid states `X` (an `Expr` `nx × (N+1)`), e.g. for `sol.value(tr.states)`.
    #[getter]
    fn states(&mut self, py: Python<'_>) -> PyResult<PyExpr> {
        Ok(PyExpr::new(self.live(py)?.tr.states().clone()))
    }

    /// The controls `U` (`nu × N`, or `nu × (N+1)` for controls at the nodes).
    #[getter]
    fn controls(&mut self, py: Python<'_>) -> PyResult<PyExpr> {
        Ok(PyExpr::new(self.live(py)?.tr.controls().clone()))
    }

    /// The final time: the variable `T` or the fixed value.
    #[getter]
    fn final_time(&mut self, py: Python<'_>) -> PyResult<PyExpr> {
        Ok(PyExpr::scalar(self.live(py)?.tr.final_time()))
    }

    /// The collocation states `Xc` (direct collocation) or midpoints `Xm` (separated
    /// Hermite–Simpson), else `None`.
    #[getter]
    fn collocation_states(&mut self, py: Python<'_>) -> PyResult<Option<PyExpr>> {
        Ok(self
            .live(py)?
            .tr
            .collocation_states()
            .map(|m| PyExpr::new(m.clone())))
    }

    /// Number of intervals N.
    #[getter]
    fn intervals(&self) -> usize {
        self.grid.intervals()
    }

    /// The grid.
    #[getter]
    fn grid(&self) -> PyGrid {
        PyGrid {
            grid: self.grid.clone(),
        }
    }

    /// The method.
    #[getter]
    fn method(&self) -> PyMethod {
        PyMethod {
            spec: self.method.clone(),
        }
    }

    /// Number of NLP variables.
    #[getter]
    fn n_variables(&mut self, py: Python<'_>) -> PyResult<usize> {
        Ok(self.live(py)?.tr.problem().n_variables())
    }

    /// Number of NLP constraint rows.
    #[getter]
    fn n_constraints(&mut self, py: Python<'_>) -> PyResult<usize> {
        Ok(self.live(py)?.tr.problem().n_constraints())
    }

    /// What unpickling calls: transcribed again by the first thread that uses it.
    #[staticmethod]
    fn _rebuild(
        ocp: Py<PyOcp>,
        method: PyMethod,
        grid: PyGrid,
        values: Vec<(String, Vec<f64>)>,
    ) -> PyTranscription {
        PyTranscription {
            owner: std::thread::current().id(),
            ocp,
            method: method.spec,
            grid: grid.grid,
            values,
            live: None,
        }
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Py<PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let me = slf.borrow();
        let f = slf.get_type().getattr("_rebuild")?;
        let args = (
            me.ocp.clone_ref(py),
            PyMethod {
                spec: me.method.clone(),
            },
            PyGrid {
                grid: me.grid.clone(),
            },
            me.values.clone(),
        )
            .into_pyobject(py)?;
        Ok((f.unbind(), args))
    }

    fn __repr__(&self) -> String {
        format!(
            "Transcription({} intervals{})",
            self.grid.intervals(),
            if self.live.is_none() {
                ", unpickled, written at first use"
            } else {
                ""
            }
        )
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyTranscription>()
}
