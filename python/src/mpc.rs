//! `Mpc` (nlp::mpc::Mpc, the closed-loop driver) and `Simulator` (a nominal plant).
use nlp::mpc::{ClosedLoop, Mpc, StepReport};
use nlp::ocp::{OcpError, Simulator};
use nlp::{Ipm, Solver, SqpOptions};
use numpy::IntoPyArray;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::error::{build_err, solve_err};
use crate::function::numbers;
use crate::problem::{evaluator_named, make_solver, sqp_options, symbol_names};
use crate::same_thread::SameThread;
use crate::solution::PySolution;
use crate::transcription::PyTranscription;

/// A plant model: `steps` Runge–Kutta steps on an `Ocp`'s dynamics over `dt`, compiled
/// once (made by `Ocp.simulator`). Thread-independent.
#[pyclass(name = "Simulator", module = "symnlp")]
pub struct PySimulator {
    sim: Simulator,
    nu: usize,
}

impl PySimulator {
    pub fn new(sim: Simulator, nu: usize) -> Self {
        PySimulator { sim, nu }
    }
}

#[pymethods]
impl PySimulator {
    /// `x(t + dt)` from `x(t)` under the constant control `u`.
    fn step(
        &mut self,
        py: Python<'_>,
        x: &Bound<'_, PyAny>,
        u: &Bound<'_, PyAny>,
        dt: f64,
    ) -> PyResult<Py<PyAny>> {
        let (x, u) = (numbers(x)?, numbers(u)?);
        let u = if self.nu == 0 { Vec::new() } else { u };
        let next = self.sim.step(&x, &u, dt).map_err(build_err)?;
        Ok(next.into_pyarray(py).into_any().unbind())
    }

    /// Sets all parameter entries (stacked in declaration order, as the OCP's `p`).
    fn set_parameters(&mut self, p: &Bound<'_, PyAny>) -> PyResult<()> {
        self.sim.set_parameters(&numbers(p)?).map_err(build_err)
    }
}

/// A receding-horizon controller (nlp's `Mpc`, docs/mpc.md) for a `Transcription` whose
/// initial state is a parameter (`Ocp.set_initial_state_parameter`) and whose horizon is
/// fixed: each `step(x)` sets the measured state, shifts the previous solution one stage
/// and re-solves warm from it; `control` is the plan's first control. Solves release the
/// GIL.
#[pyclass(name = "Mpc", module = "symnlp")]
pub struct PyMpc {
    mpc: Mpc,
    names: Vec<String>,
}

fn report_dict<'py>(py: Python<'py>, r: &StepReport) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("status", r.status.to_string())?;
    d.set_item("success", r.succeeded())?;
    d.set_item("residual", r.residual)?;
    d.set_item("iterations", r.iterations)?;
    d.set_item("seconds", r.seconds)?;
    d.set_item("solve_seconds", r.solve_seconds)?;
    d.set_item("feedback_seconds", r.feedback_seconds)?;
    d.set_item("objective", r.objective)?;
    d.set_item("warm", r.warm)?;
    Ok(d)
}

fn rows(py: Python<'_>, rows: &[Vec<f64>]) -> PyResult<Py<PyAny>> {
    let ncols = rows.first().map_or(0, Vec::len);
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    let a = numpy::PyArrayMethods::reshape(&flat.into_pyarray(py), [rows.len(), ncols])?;
    Ok(a.into_any().unbind())
}

fn closed_loop_dict<'py>(py: Python<'py>, run: &ClosedLoop) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("states", rows(py, &run.states)?)?;
    d.set_item("controls", rows(py, &run.controls)?)?;
    let steps = run
        .steps
        .iter()
        .map(|r| report_dict(py, r))
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("steps", PyList::new(py, steps)?)?;
    d.set_item("all_succeeded", run.all_succeeded())?;
    d.set_item("latency", run.latency())?;
    d.set_item("iterations", run.iterations())?;
    Ok(d)
}

/// What a new controller solves each step with.
enum Engine {
    /// A solver, warm from the shifted plan.
    Solver(Box<dyn Solver>),
    /// Real-time iterations with these SQP options.
    Rti(Box<SqpOptions>),
}

#[pymethods]
impl PyMpc {
    /// A controller for `transcription`: `solver` `"ipm"` (the default) or `"sqp"` solves
    /// each step warm from the shifted plan; `"rti"` takes one real-time iteration per
    /// step (the SQP's `options`; the first step, and the first after `reset`, converged
    /// by the interior point). `options` by IPOPT's names; `evaluator` `"tape"` (the
    /// default) or `"jit"` (machine code compiled now, bit-identical iterates, repaid after
    /// some hundred steps: docs/mpc.md). Compiles without the GIL.
    #[new]
    #[pyo3(signature = (transcription, solver = "ipm", options = None, evaluator = "tape"))]
    fn new(
        py: Python<'_>,
        transcription: &mut PyTranscription,
        solver: &str,
        options: Option<&Bound<'_, PyDict>>,
        evaluator: &str,
    ) -> PyResult<PyMpc> {
        let evaluator = evaluator_named(evaluator)?;
        let engine = match solver {
            "rti" => Engine::Rti(Box::new(sqp_options(options)?)),
            "ipm" | "ipopt" | "sqp" => Engine::Solver(make_solver(solver, options)?),
            other => {
                return Err(crate::error::OptionError::new_err(format!(
                    "unknown solver '{other}': expected 'ipm', 'sqp' or 'rti'"
                )))
            }
        };
        let live = transcription.live(py)?;
        let names = symbol_names(live.tr.problem());
        let tr = SameThread(&live.tr);
        let mpc = py.allow_threads(move || {
            let tr = tr;
            let mpc = match engine {
                Engine::Rti(o) => Mpc::with_rti(tr.0, *o, Box::new(Ipm::default()))?,
                Engine::Solver(backend) => Mpc::new(tr.0, backend)?,
            };
            mpc.with_evaluator(evaluator)
        });
        Ok(PyMpc {
            mpc: mpc.map_err(build_err)?,
            names,
        })
    }

    /// With `solver="rti"`: shifts the plan and runs the preparation phase now (e.g. while
    /// waiting for the next measurement), so that the next `step` runs only the feedback;
    /// returns its wall seconds (0 for the other solvers, before the first step, or when
    /// already prepared). Releases the GIL.
    fn prepare(&mut self, py: Python<'_>) -> PyResult<f64> {
        let mpc = &mut self.mpc;
        py.allow_threads(|| mpc.prepare()).map_err(solve_err)
    }

    /// One step from the measured state `x0`; returns a dict (`status`, `success`,
    /// `residual` (a real-time iteration's KKT residual, else `None`), `iterations`,
    /// `seconds`, `solve_seconds`, `feedback_seconds` (a real-time iteration's feedback
    /// phase, the latency from `x0` to the control when `prepare` ran ahead), `objective`,
    /// `warm`).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        x0: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let x0 = numbers(x0)?;
        let mpc = &mut self.mpc;
        let r = py.allow_threads(|| mpc.step(&x0)).map_err(solve_err)?;
        report_dict(py, &r)
    }

    /// Closes the loop for `steps` steps from `x_init`: `plant` is a `Simulator` (stepped
    /// by the sampling period) or a callable `plant(x, u) -> next x`. Returns a dict:
    /// `states` (array `(steps + 1, nx)`), `controls` (`(steps, nu)`), `steps` (one
    /// report per step), `all_succeeded`, `latency` (median, max seconds), `iterations`
    /// (mean, max).
    fn run<'py>(
        &mut self,
        py: Python<'py>,
        x_init: &Bound<'_, PyAny>,
        steps: usize,
        plant: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let x_init = numbers(x_init)?;
        let dt = self.mpc.sampling_period();
        let mut raised: Option<PyErr> = None;
        let run = if let Ok(sim) = plant.downcast::<PySimulator>() {
            let mut sim = sim.borrow_mut();
            let sim = &mut sim.sim;
            let mpc = &mut self.mpc;
            py.allow_threads(|| mpc.run(&x_init, steps, |x, u, next| sim.step_into(x, u, dt, next)))
        } else if plant.is_callable() {
            let f = plant.clone().unbind();
            let mpc = &mut self.mpc;
            let raised = &mut raised;
            py.allow_threads(|| {
                mpc.run(&x_init, steps, |x, u, next| {
                    Python::with_gil(|py| {
                        let r = f
                            .call1(py, (x.to_vec(), u.to_vec()))
                            .and_then(|r| numbers(r.bind(py)));
                        match r {
                            Ok(v) if v.len() == next.len() => {
                                next.copy_from_slice(&v);
                                Ok(())
                            }
                            Ok(v) => Err(OcpError::Size {
                                what: "plant callable result".into(),
                                expected: next.len(),
                                got: v.len(),
                            }),
                            Err(e) => {
                                let msg = e.to_string();
                                *raised = Some(e);
                                Err(OcpError::Numerical(format!("plant callable raised: {msg}")))
                            }
                        }
                    })
                })
            })
        } else {
            return Err(PyTypeError::new_err(
                "Mpc.run: plant must be a Simulator or a callable plant(x, u) -> next x",
            ));
        };
        if let Some(e) = raised {
            return Err(e);
        }
        closed_loop_dict(py, &run.map_err(solve_err)?)
    }

    /// The first control of the latest plan (empty before the first step).
    #[getter]
    fn control(&self, py: Python<'_>) -> Py<PyAny> {
        self.mpc
            .control()
            .to_vec()
            .into_pyarray(py)
            .into_any()
            .unbind()
    }

    /// The latest solution (the plan over the horizon), or `None` before the first step.
    #[getter]
    fn solution(&self) -> Option<PySolution> {
        self.mpc.solution().map(|s| PySolution {
            inner: s.clone(),
            names: self.names.clone(),
            parameters: s.parameters.clone(),
        })
    }

    /// The sampling period `T / N`.
    #[getter]
    fn sampling_period(&self) -> f64 {
        self.mpc.sampling_period()
    }

    /// Sets another parameter (a reference, a model constant) between steps.
    fn set_value(&mut self, name: &str, values: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = numbers(values)?;
        self.mpc
            .compiled_mut()
            .set_value(name, &v)
            .map_err(build_err)
    }

    /// Forgets the previous solution: the next step solves cold.
    fn reset(&mut self) {
        self.mpc.reset();
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySimulator>()?;
    m.add_class::<PyMpc>()
}
