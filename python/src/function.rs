//! `Function`: a compiled, thread-independent evaluator callable on numpy arrays.
use numpy::PyArrayMethods;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use symx::Matrix;

use crate::error::build_err;
use crate::expr::{csc, operand, symbols, CscPattern};
use crate::same_thread::SameThread;
use crate::solution::to_python;

/// A compiled function of symbolic inputs (CasADi's `Function(name, [x, p], [f, g])`).
///
/// Calling it evaluates at numbers: one array per input (any shape with the input's
/// number of entries, read in column-major order); returns one value per output (a float
/// for 1×1, a 1-D array for a column, else a 2-D array), a tuple when there are several.
/// A Function does not depend on the graph it was built from: it can be used from any
/// thread and is evaluated without the GIL.
#[pyclass(name = "Function", module = "symnlp", frozen)]
pub struct PyFunction {
    f: symx::Function,
    out_shapes: Vec<(usize, usize)>,
}

impl PyFunction {
    /// The compiled symx function.
    pub fn function(&self) -> &symx::Function {
        &self.f
    }
}

#[pymethods]
impl PyFunction {
    /// Compiles `outputs` as functions of the symbols in `inputs` (each an `Expr` of
    /// symbols). `input_names`/`output_names` default to `i0, i1, …` / `o0, o1, …`.
    /// `evaluator`: `"tape"` (the default) or `"jit"` (machine code, CasADi's `jit`
    /// option: the same values bit for bit, faster per call).
    #[new]
    #[pyo3(signature = (name, inputs, outputs, input_names = None, output_names = None, evaluator = "tape"))]
    fn new(
        py: Python<'_>,
        name: &str,
        inputs: Vec<Bound<'_, PyAny>>,
        outputs: Vec<Bound<'_, PyAny>>,
        input_names: Option<Vec<String>>,
        output_names: Option<Vec<String>>,
        evaluator: &str,
    ) -> PyResult<PyFunction> {
        let evaluator = crate::problem::evaluator_named(evaluator)?;
        let ins: Vec<Vec<symx::Expr>> = inputs
            .iter()
            .enumerate()
            .map(|(k, x)| symbols(&operand(x)?, &format!("Function '{name}': input {k}")))
            .collect::<PyResult<_>>()?;
        let outs: Vec<Matrix> = outputs.iter().map(operand).collect::<PyResult<_>>()?;
        let in_names =
            input_names.unwrap_or_else(|| (0..ins.len()).map(|k| format!("i{k}")).collect());
        let out_names =
            output_names.unwrap_or_else(|| (0..outs.len()).map(|k| format!("o{k}")).collect());
        if in_names.len() != ins.len() || out_names.len() != outs.len() {
            return Err(PyValueError::new_err(format!(
                "Function '{name}': {} input names for {} inputs, {} output names for {} outputs",
                in_names.len(),
                ins.len(),
                out_names.len(),
                outs.len()
            )));
        }
        let out_shapes = outs.iter().map(|m| m.shape()).collect();
        let job = SameThread((name.to_string(), ins, outs, in_names, out_names));
        let f = py.allow_threads(move || {
            let job = job;
            let (name, ins, outs, in_names, out_names) = job.0;
            let i: Vec<(&str, &[symx::Expr])> = in_names
                .iter()
                .map(|s| s.as_str())
                .zip(ins.iter().map(|v| v.as_slice()))
                .collect();
            let o: Vec<(&str, &[symx::Expr])> = out_names
                .iter()
                .map(|s| s.as_str())
                .zip(outs.iter().map(|m| m.entries()))
                .collect();
            symx::Function::named(&name, &i, &o)?.with_evaluator(evaluator)
        });
        Ok(PyFunction {
            f: f.map_err(build_err)?,
            out_shapes,
        })
    }

    /// The function's name.
    #[getter]
    fn name(&self) -> String {
        self.f.name().to_string()
    }

    /// Number of entries of each input.
    #[getter]
    fn input_sizes(&self) -> Vec<usize> {
        self.f.input_sizes().to_vec()
    }

    /// Shape of each output.
    #[getter]
    fn output_shapes(&self) -> Vec<(usize, usize)> {
        self.out_shapes.clone()
    }

    /// Input names.
    #[getter]
    fn input_names(&self) -> Vec<String> {
        self.f.input_names().to_vec()
    }

    /// Output names.
    #[getter]
    fn output_names(&self) -> Vec<String> {
        self.f.output_names().to_vec()
    }

    /// Structural dependency of output `o` on input `i` (which output entries can depend
    /// on which input entries) as a scipy.sparse-compatible CSC triple
    /// `(indptr, indices, shape)` with shape `(output size, input size)`.
    fn sparsity(&self, i: usize, o: usize) -> PyResult<CscPattern> {
        let p = self.f.dependency_sparsity(i, o).map_err(build_err)?;
        Ok(csc(&p))
    }

    #[pyo3(signature = (*args))]
    fn __call__(&self, py: Python<'_>, args: &Bound<'_, PyTuple>) -> PyResult<Py<PyAny>> {
        if args.len() != self.f.n_inputs() {
            return Err(PyValueError::new_err(format!(
                "Function '{}': expected {} inputs, got {}",
                self.f.name(),
                self.f.n_inputs(),
                args.len()
            )));
        }
        let mut vals: Vec<Vec<f64>> = Vec::with_capacity(args.len());
        for (k, a) in args.iter().enumerate() {
            let v = numbers(&a).map_err(|e| {
                PyValueError::new_err(format!("Function '{}': input {k}: {e}", self.f.name()))
            })?;
            vals.push(v);
        }
        let out = py.allow_threads(|| {
            let refs: Vec<&[f64]> = vals.iter().map(|v| v.as_slice()).collect();
            self.f.call(&refs)
        });
        let out = out.map_err(build_err)?;
        let items: Vec<Py<PyAny>> = out
            .iter()
            .zip(&self.out_shapes)
            .map(|(v, &s)| to_python(py, v, s))
            .collect::<PyResult<_>>()?;
        if items.len() == 1 {
            Ok(items.into_iter().next().expect("one output"))
        } else {
            Ok(PyTuple::new(py, items)?.into_any().unbind())
        }
    }

    /// A compiled function does not pickle (it holds no expressions to rebuild it from):
    /// the error says what to do instead.
    fn __reduce__(&self) -> PyResult<()> {
        Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "cannot pickle Function '{}': pickle the expressions it is built from (an Expr \
             or a Problem pickles) and build the Function again where it is used",
            self.f.name()
        )))
    }

    fn __repr__(&self) -> String {
        format!(
            "Function('{}', inputs {:?}, outputs {:?})",
            self.f.name(),
            self.f.input_names(),
            self.f.output_names()
        )
    }
}

/// The numbers of a float, a sequence or an array (any shape; column-major order, as
/// CasADi stores matrices).
pub fn numbers(obj: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if let Ok(v) = obj.extract::<f64>() {
        return Ok(vec![v]);
    }
    // Fast paths (no numpy call): a contiguous 1-D float64 array, a flat list or tuple.
    if let Ok(a) = obj.downcast::<numpy::PyArray1<f64>>() {
        if let Ok(r) = a.readonly().as_slice() {
            return Ok(r.to_vec());
        }
    }
    if obj.is_instance_of::<pyo3::types::PyList>() || obj.is_instance_of::<PyTuple>() {
        if let Ok(v) = obj.extract::<Vec<f64>>() {
            return Ok(v);
        }
    }
    let np = obj.py().import("numpy")?;
    let arr = np.call_method1("asarray", (obj, "float64"))?;
    let arr = arr.call_method1("ravel", ("F",))?;
    let a = arr.downcast::<numpy::PyArray1<f64>>()?;
    Ok(a.readonly().as_slice()?.to_vec())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyFunction>()
}
