//! `Trajectory`: a solved OCP as numpy time series (nlp::ocp::Trajectory), picklable.
use nlp::ocp::{ControlInterpolation, Trajectory};
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::exceptions::PyKeyError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::build_err;

/// A solution of a `Transcription` as time series: `time` (the grid nodes `t₀ = 0 … t_N
/// = T`), `states` (array `nx × (N+1)`), `control_time` and `controls` (array
/// `nu × N`, or `nu × (N+1)` for controls at the nodes), names, final time, objective
/// and status; for direct collocation and separated Hermite–Simpson also the states at
/// the collocation points or midpoints. Read one series with `state(name)` /
/// `control(name)`; plot with matplotlib as docs/python.md shows.
#[pyclass(name = "Trajectory", module = "symnlp", frozen)]
#[derive(Clone)]
pub struct PyTrajectory {
    pub inner: Trajectory,
}

/// Rows `rows[i]` (each of one length) as a 2-D array.
fn matrix(py: Python<'_>, rows: &[Vec<f64>], ncols: usize) -> PyResult<Py<PyAny>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    let a = flat.into_pyarray(py).reshape([rows.len(), ncols])?;
    Ok(a.into_any().unbind())
}

fn array(py: Python<'_>, v: &[f64]) -> Py<PyAny> {
    v.to_vec().into_pyarray(py).into_any().unbind()
}

#[pymethods]
impl PyTrajectory {
    /// The grid nodes `t_k` (N + 1 values, the last exactly `T`).
    #[getter]
    fn time(&self, py: Python<'_>) -> Py<PyAny> {
        array(py, &self.inner.time)
    }

    /// The states on the grid: array `(nx, N + 1)`, row `i` is state `i`.
    #[getter]
    fn states(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        matrix(py, &self.inner.states, self.inner.time.len())
    }

    /// The controls: array `(nu, len(control_time))`.
    #[getter]
    fn controls(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        matrix(py, &self.inner.controls, self.inner.control_time.len())
    }

    /// Times of the controls: interval starts (piecewise constant) or every node (linear).
    #[getter]
    fn control_time(&self, py: Python<'_>) -> Py<PyAny> {
        array(py, &self.inner.control_time)
    }

    /// `"constant"` or `"linear"`: how the controls vary between `control_time`s.
    #[getter]
    fn control_interpolation(&self) -> &'static str {
        match self.inner.control_interpolation {
            ControlInterpolation::PiecewiseConstant => "constant",
            ControlInterpolation::PiecewiseLinear => "linear",
        }
    }

    /// State names, in the order of `states`' rows.
    #[getter]
    fn state_names(&self) -> Vec<String> {
        self.inner.state_names.clone()
    }

    /// Control names, in the order of `controls`' rows.
    #[getter]
    fn control_names(&self) -> Vec<String> {
        self.inner.control_names.clone()
    }

    /// The final time `T`.
    #[getter]
    fn final_time(&self) -> f64 {
        self.inner.final_time
    }

    /// The optimal objective.
    #[getter]
    fn objective(&self) -> f64 {
        self.inner.objective
    }

    /// The solver's status (IPOPT's name).
    #[getter]
    fn status(&self) -> String {
        self.inner.status.to_string()
    }

    /// Whether the solve met its goal.
    #[getter]
    fn success(&self) -> bool {
        self.inner.status.is_success()
    }

    /// Times of the collocation points (or midpoints), or `None`.
    #[getter]
    fn collocation_time(&self, py: Python<'_>) -> Option<Py<PyAny>> {
        self.inner.collocation.as_ref().map(|c| array(py, &c.time))
    }

    /// States at the collocation points (array `(nx, len(collocation_time))`), or `None`.
    #[getter]
    fn collocation_states(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        match &self.inner.collocation {
            Some(c) => Ok(Some(matrix(py, &c.states, c.time.len())?)),
            None => Ok(None),
        }
    }

    /// The series of the state `name` on the grid.
    fn state(&self, py: Python<'_>, name: &str) -> PyResult<Py<PyAny>> {
        self.inner
            .state(name)
            .map(|v| array(py, v))
            .ok_or_else(|| PyKeyError::new_err(format!("no state named '{name}'")))
    }

    /// The series of the control `name` at `control_time`.
    fn control(&self, py: Python<'_>, name: &str) -> PyResult<Py<PyAny>> {
        self.inner
            .control(name)
            .map(|v| array(py, v))
            .ok_or_else(|| PyKeyError::new_err(format!("no control named '{name}'")))
    }

    /// The states at time `t`, interpolated linearly between nodes.
    fn states_at(&self, py: Python<'_>, t: f64) -> Py<PyAny> {
        array(py, &self.inner.states_at(t))
    }

    /// The controls at time `t` (held or interpolated as `control_interpolation` says).
    fn controls_at(&self, py: Python<'_>, t: f64) -> Py<PyAny> {
        array(py, &self.inner.controls_at(t))
    }

    /// The trajectory as CSV text (a header `t,<states>,<controls>`).
    fn to_csv(&self) -> String {
        self.inner.to_csv()
    }

    /// The trajectory as a dict of lists (JSON-ready; the Rust `Trajectory`'s fields).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let json = py.import("json")?;
        let d = json.call_method1("loads", (self.to_json()?,))?;
        Ok(d.downcast_into::<PyDict>()?)
    }

    /// The trajectory as JSON text (what pickling uses; nlp's file format).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.inner).map_err(build_err)
    }

    /// A trajectory from `to_json`'s text (or a file written by the Rust side).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<PyTrajectory> {
        Ok(PyTrajectory {
            inner: serde_json::from_str(text).map_err(build_err)?,
        })
    }

    fn __reduce__(slf: &Bound<'_, Self>) -> PyResult<(Py<PyAny>, (String,))> {
        let f = slf.get_type().getattr("from_json")?;
        Ok((f.unbind(), (slf.get().to_json()?,)))
    }

    fn __repr__(&self) -> String {
        format!(
            "Trajectory({} nodes, T = {}, objective = {}, status = {})",
            self.inner.time.len(),
            self.inner.final_time,
            self.inner.objective,
            self.inner.status
        )
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyTrajectory>()
}
