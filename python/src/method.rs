//! How an `Ocp` is transcribed: `Method` (multiple shooting, collocation, trapezoidal,
//! Hermite–Simpson), `ButcherTableau` and `Grid`, thin wrappers over `nlp::ocp`'s types.
use nlp::ocp::{ButcherTableau, Collocation, CollocationPoints, Grid, Method};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::build_err;

/// A transcription method as data (what pickling stores; `nlp::ocp::Method` is rebuilt
/// from it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum MethodSpec {
    MultipleShooting {
        tableau: ButcherTableau,
        steps: usize,
        calls: bool,
    },
    Collocation {
        points: CollocationPoints,
        degree: usize,
    },
    Trapezoidal,
    HermiteSimpson {
        separated: bool,
    },
}

impl MethodSpec {
    /// The `nlp` method.
    pub fn method(&self) -> PyResult<Method> {
        Ok(match self {
            MethodSpec::MultipleShooting {
                tableau,
                steps,
                calls: false,
            } => Method::multiple_shooting(tableau.clone(), *steps),
            MethodSpec::MultipleShooting {
                tableau,
                steps,
                calls: true,
            } => Method::multiple_shooting_with_calls(tableau.clone(), *steps),
            MethodSpec::Collocation { points, degree } => {
                Method::Collocation(Collocation::new(*points, *degree).map_err(build_err)?)
            }
            MethodSpec::Trapezoidal => Method::trapezoidal(),
            MethodSpec::HermiteSimpson { separated: false } => Method::hermite_simpson(),
            MethodSpec::HermiteSimpson { separated: true } => Method::hermite_simpson_separated(),
        })
    }
}

/// How the dynamics of an `Ocp` become constraints; made by the static methods
/// `multiple_shooting`, `collocation`, `trapezoidal` and `hermite_simpson`
/// (docs/ocp.md §3 describes each).
#[pyclass(name = "Method", module = "symnlp", frozen)]
#[derive(Clone)]
pub struct PyMethod {
    pub spec: MethodSpec,
}

#[pymethods]
impl PyMethod {
    /// Direct multiple shooting: `steps` steps of an explicit Runge–Kutta `tableau` (a
    /// name: `"rk4"`, `"rk2"`/`"midpoint"`, `"heun"`, `"euler"`, or a `ButcherTableau`)
    /// per interval. `calls=True` compiles one interval's integration once and calls it at
    /// every interval (same problem, a far smaller graph for large N).
    #[staticmethod]
    #[pyo3(signature = (tableau = None, steps = 1, calls = false))]
    fn multiple_shooting(
        tableau: Option<&Bound<'_, PyAny>>,
        steps: usize,
        calls: bool,
    ) -> PyResult<PyMethod> {
        let tableau = match tableau {
            None => ButcherTableau::rk4(),
            Some(t) => match t.downcast::<PyButcherTableau>() {
                Ok(t) => t.get().tableau.clone(),
                Err(_) => {
                    let name: String = t.extract().map_err(|_| {
                        PyValueError::new_err(
                            "multiple_shooting: tableau must be a name or a ButcherTableau",
                        )
                    })?;
                    ButcherTableau::by_name(&name).map_err(build_err)?
                }
            },
        };
        if steps == 0 {
            return Err(PyValueError::new_err(
                "multiple_shooting: steps per interval must be >= 1",
            ));
        }
        Ok(PyMethod {
            spec: MethodSpec::MultipleShooting {
                tableau,
                steps,
                calls,
            },
        })
    }

    /// Direct collocation at `points` (`"legendre"` or `"radau"`) of `degree` (1…60).
    #[staticmethod]
    #[pyo3(signature = (points = "legendre", degree = 3))]
    fn collocation(points: &str, degree: usize) -> PyResult<PyMethod> {
        let points = match points.to_ascii_lowercase().as_str() {
            "legendre" => CollocationPoints::Legendre,
            "radau" => CollocationPoints::Radau,
            other => {
                return Err(PyValueError::new_err(format!(
                    "collocation: unknown points '{other}': expected 'legendre' or 'radau'"
                )))
            }
        };
        Collocation::new(points, degree).map_err(build_err)?;
        Ok(PyMethod {
            spec: MethodSpec::Collocation { points, degree },
        })
    }

    /// Trapezoidal collocation (second order; no variables beyond the grid).
    #[staticmethod]
    fn trapezoidal() -> PyMethod {
        PyMethod {
            spec: MethodSpec::Trapezoidal,
        }
    }

    /// Hermite–Simpson collocation (fourth order); `separated=True` makes the midpoint
    /// states variables.
    #[staticmethod]
    #[pyo3(signature = (separated = false))]
    fn hermite_simpson(separated: bool) -> PyMethod {
        PyMethod {
            spec: MethodSpec::HermiteSimpson { separated },
        }
    }

    fn __repr__(&self) -> String {
        match &self.spec {
            MethodSpec::MultipleShooting {
                tableau,
                steps,
                calls,
            } => format!(
                "Method.multiple_shooting('{}', steps={steps}, calls={})",
                tableau.name(),
                if *calls { "True" } else { "False" }
            ),
            MethodSpec::Collocation { points, degree } => format!(
                "Method.collocation('{}', {degree})",
                format!("{points:?}").to_lowercase()
            ),
            MethodSpec::Trapezoidal => "Method.trapezoidal()".into(),
            MethodSpec::HermiteSimpson { separated } => format!(
                "Method.hermite_simpson(separated={})",
                if *separated { "True" } else { "False" }
            ),
        }
    }

    /// The method as JSON text (what pickling uses).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.spec).map_err(build_err)
    }

    /// A method from `to_json`'s text.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<PyMethod> {
        Ok(PyMethod {
            spec: serde_json::from_str(text).map_err(build_err)?,
        })
    }

    fn __reduce__(slf: &Bound<'_, Self>) -> PyResult<(Py<PyAny>, (String,))> {
        let f = slf.get_type().getattr("from_json")?;
        Ok((f.unbind(), (slf.get().to_json()?,)))
    }
}

/// The coefficients `(A, b, c)` of an explicit Runge–Kutta method, for
/// `Method.multiple_shooting`: `A` strictly lower triangular, weights summing to 1.
#[pyclass(name = "ButcherTableau", module = "symnlp", frozen)]
#[derive(Clone)]
pub struct PyButcherTableau {
    pub tableau: ButcherTableau,
}

#[pymethods]
impl PyButcherTableau {
    /// A tableau from its coefficients (checked: explicit, finite, weights summing to 1).
    #[new]
    fn new(name: &str, a: Vec<Vec<f64>>, b: Vec<f64>, c: Vec<f64>) -> PyResult<Self> {
        Ok(PyButcherTableau {
            tableau: ButcherTableau::new(name, &a, &b, &c).map_err(build_err)?,
        })
    }

    /// A built-in tableau by name: `"rk4"`, `"rk2"`/`"midpoint"`, `"heun"`, `"euler"`.
    #[staticmethod]
    fn by_name(name: &str) -> PyResult<Self> {
        Ok(PyButcherTableau {
            tableau: ButcherTableau::by_name(name).map_err(build_err)?,
        })
    }

    /// The method's name.
    #[getter]
    fn name(&self) -> String {
        self.tableau.name().to_string()
    }

    /// The weights `b`.
    #[getter]
    fn weights(&self) -> Vec<f64> {
        self.tableau.weights().to_vec()
    }

    /// The nodes `c`.
    #[getter]
    fn nodes(&self) -> Vec<f64> {
        self.tableau.nodes().to_vec()
    }

    fn __repr__(&self) -> String {
        format!(
            "ButcherTableau('{}', {} stages)",
            self.tableau.name(),
            self.tableau.stages()
        )
    }

    /// The tableau as JSON text (what pickling uses).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.tableau).map_err(build_err)
    }

    /// A tableau from `to_json`'s text.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(PyButcherTableau {
            tableau: serde_json::from_str(text).map_err(build_err)?,
        })
    }

    fn __reduce__(slf: &Bound<'_, Self>) -> PyResult<(Py<PyAny>, (String,))> {
        let f = slf.get_type().getattr("from_json")?;
        Ok((f.unbind(), (slf.get().to_json()?,)))
    }
}

/// The nodes of a transcription as fractions of the final time: `Grid.uniform(n)` or a
/// user-given `Grid([0, …, 1])` (strictly increasing, from exactly 0 to exactly 1).
#[pyclass(name = "Grid", module = "symnlp", frozen)]
#[derive(Clone)]
pub struct PyGrid {
    pub grid: Grid,
}

#[pymethods]
impl PyGrid {
    /// A grid from the fractions `0 = s₀ < s₁ < … < s_N = 1` of `T`.
    #[new]
    fn new(fractions: Vec<f64>) -> PyResult<Self> {
        Ok(PyGrid {
            grid: Grid::new(&fractions).map_err(build_err)?,
        })
    }

    /// `n ≥ 1` intervals of length `T/n`.
    #[staticmethod]
    fn uniform(n: usize) -> PyResult<Self> {
        Ok(PyGrid {
            grid: Grid::uniform(n).map_err(build_err)?,
        })
    }

    /// The fractions `s_k`.
    #[getter]
    fn fractions(&self) -> Vec<f64> {
        self.grid.fractions().to_vec()
    }

    /// Number of intervals N.
    #[getter]
    fn intervals(&self) -> usize {
        self.grid.intervals()
    }

    /// Whether the intervals are equal.
    #[getter]
    fn is_uniform(&self) -> bool {
        self.grid.is_uniform()
    }

    fn __repr__(&self) -> String {
        format!(
            "Grid({} intervals{})",
            self.grid.intervals(),
            if self.grid.is_uniform() {
                ", uniform"
            } else {
                ""
            }
        )
    }

    /// The grid as JSON text (what pickling uses).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.grid).map_err(build_err)
    }

    /// A grid from `to_json`'s text.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        let g: Grid = serde_json::from_str(text).map_err(build_err)?;
        // Checked as the constructors check (the text may come from anywhere).
        let grid = match g.is_uniform() {
            true => Grid::uniform(g.intervals()),
            false => Grid::new(g.fractions()),
        };
        Ok(PyGrid {
            grid: grid.map_err(build_err)?,
        })
    }

    fn __reduce__(slf: &Bound<'_, Self>) -> PyResult<(Py<PyAny>, (String,))> {
        let f = slf.get_type().getattr("from_json")?;
        Ok((f.unbind(), (slf.get().to_json()?,)))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyMethod>()?;
    m.add_class::<PyButcherTableau>()?;
    m.add_class::<PyGrid>()
}
