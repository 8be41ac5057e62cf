//! `Expr`: a matrix of symx expressions with Python operators, numpy interop and printing,
//! and the module-level math functions and derivatives.
use nlp::{Constraint, Relation};
use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::basic::CompareOp;
use pyo3::exceptions::{PyIndexError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PySlice, PyTuple};
use symx::{Expr, Matrix};

use crate::error::build_err;

/// A symbolic expression: a `rows × cols` matrix of scalar expressions (a scalar is 1×1,
/// a vector n×1), made by `sym`, by a problem's `variable`/`parameter`, or by arithmetic.
/// Operators act entry by entry (`*` too; `@` is the matrix product), with scalars
/// broadcast. Comparisons (`<=`, `>=`, `==`) make constraints for `Problem.subject_to`.
#[pyclass(name = "Expr", module = "symnlp", unsendable)]
#[derive(Clone)]
pub struct PyExpr {
    pub m: Matrix,
}

/// Constraint rows `lower ≤ expr ≤ upper`, made by comparisons or `Problem.bounded`.
#[pyclass(name = "Constraint", module = "symnlp", unsendable)]
#[derive(Clone)]
pub struct PyConstraint {
    pub c: Constraint,
}

#[pymethods]
impl PyConstraint {
    /// Number of rows.
    fn __len__(&self) -> usize {
        self.c.len()
    }

    fn __repr__(&self) -> String {
        let rows: Vec<String> = self
            .c
            .expressions()
            .iter()
            .zip(self.c.lower_bounds())
            .zip(self.c.upper_bounds())
            .map(|((e, l), u)| format!("{l} <= {e} <= {u}"))
            .collect();
        format!("Constraint([{}])", rows.join(", "))
    }

    /// Truth value of a constraint is ambiguous (it is not a comparison result).
    fn __bool__(&self) -> PyResult<bool> {
        Err(PyTypeError::new_err(
            "a Constraint has no truth value; pass it to Problem.subject_to (for a symbolic \
             comparison inside an expression use symnlp.le/ge/eq with if_else)",
        ))
    }
}

impl PyExpr {
    pub fn new(m: Matrix) -> PyExpr {
        PyExpr { m }
    }

    pub fn scalar(e: Expr) -> PyExpr {
        PyExpr {
            m: Matrix::from_vec(vec![e]),
        }
    }

    /// The single entry of a 1×1 expression.
    pub fn as_scalar(&self, what: &str) -> PyResult<Expr> {
        if self.m.shape() == (1, 1) {
            Ok(self.m[0])
        } else {
            Err(PyValueError::new_err(format!(
                "{what}: expected a scalar expression, got shape {:?}",
                self.m.shape()
            )))
        }
    }
}

/// Reads a Python value as a matrix of expressions: an `Expr`, a number, a (nested)
/// sequence of numbers or a numpy array (1-D: a column vector; 2-D: a matrix).
pub fn operand(obj: &Bound<'_, PyAny>) -> PyResult<Matrix> {
    if let Ok(e) = obj.downcast::<PyExpr>() {
        return Ok(e.borrow().m.clone());
    }
    if let Ok(v) = obj.extract::<f64>() {
        return Ok(Matrix::from_vec(vec![Expr::constant(v)]));
    }
    if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, f64>>() {
        let shape = a.shape().to_vec();
        let v = a.as_array();
        return match shape.len() {
            0 => Ok(Matrix::from_vec(vec![Expr::constant(v[[]])])),
            1 => Ok(Matrix::from_f64(&v.iter().copied().collect::<Vec<_>>())),
            2 => Ok(Matrix::from_fn(shape[0], shape[1], |i, j| {
                Expr::constant(v[[i, j]])
            })),
            d => Err(PyValueError::new_err(format!(
                "expected at most 2 dimensions, got a {d}-D array"
            ))),
        };
    }
    if let Ok(v) = obj.extract::<Vec<f64>>() {
        return Ok(Matrix::from_f64(&v));
    }
    if let Ok(rows) = obj.extract::<Vec<Vec<f64>>>() {
        let r: Vec<&[f64]> = rows.iter().map(|r| r.as_slice()).collect();
        return Matrix::from_rows_f64(&r).map_err(build_err);
    }
    if let Ok(items) = obj.extract::<Vec<Bound<'_, PyAny>>>() {
        // A list mixing expressions and numbers: a column of scalars.
        let mut entries = Vec::with_capacity(items.len());
        for (i, it) in items.iter().enumerate() {
            let m = operand(it)?;
            if m.shape() != (1, 1) {
                return Err(PyValueError::new_err(format!(
                    "list entry {i}: expected a scalar, got shape {:?} (use vertcat)",
                    m.shape()
                )));
            }
            entries.push(m[0]);
        }
        return Ok(Matrix::from_vec(entries));
    }
    Err(PyTypeError::new_err(format!(
        "expected an Expr, a number, a sequence of numbers or a numpy array, got {}",
        obj.get_type().name()?
    )))
}

/// Applies `f` entry by entry to two matrices of one shape, or broadcasts a 1×1 one.
pub fn broadcast(
    a: &Matrix,
    b: &Matrix,
    what: &str,
    f: impl Fn(Expr, Expr) -> Expr,
) -> PyResult<Matrix> {
    if a.shape() == b.shape() {
        return a.zip_map(b, f).map_err(build_err);
    }
    if b.shape() == (1, 1) {
        let s = b[0];
        return Ok(a.map(|x| f(x, s)));
    }
    if a.shape() == (1, 1) {
        let s = a[0];
        return Ok(b.map(|y| f(s, y)));
    }
    Err(PyValueError::new_err(format!(
        "{what}: shapes {:?} and {:?} do not match",
        a.shape(),
        b.shape()
    )))
}

fn binary(
    a: &Matrix,
    other: &Bound<'_, PyAny>,
    what: &str,
    reflected: bool,
    f: impl Fn(Expr, Expr) -> Expr,
) -> PyResult<PyExpr> {
    let b = operand(other)?;
    let m = if reflected {
        broadcast(&b, a, what, f)?
    } else {
        broadcast(a, &b, what, f)?
    };
    Ok(PyExpr::new(m))
}

/// One index along an axis of length `n`: an int (negative from the end) or a slice.
fn axis_index(obj: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<usize>> {
    if let Ok(s) = obj.downcast::<PySlice>() {
        let ind = s.indices(n as isize)?;
        let mut out = Vec::new();
        let mut i = ind.start;
        for _ in 0..ind.slicelength {
            out.push(i as usize);
            i += ind.step;
        }
        return Ok(out);
    }
    let i: isize = obj
        .extract()
        .map_err(|_| PyTypeError::new_err("indices must be integers or slices"))?;
    let j = if i < 0 { i + n as isize } else { i };
    if j < 0 || j >= n as isize {
        return Err(PyIndexError::new_err(format!(
            "index {i} out of range for length {n}"
        )));
    }
    Ok(vec![j as usize])
}

fn take(m: &Matrix, rows: &[usize], cols: &[usize]) -> Matrix {
    Matrix::from_fn(rows.len(), cols.len(), |i, j| m[(rows[i], cols[j])])
}

/// The symbols among the expression's entries, in order; an error names the first entry
/// that is not a symbol.
pub fn symbols(m: &Matrix, what: &str) -> PyResult<Vec<Expr>> {
    for (i, e) in m.iter().enumerate() {
        if !e.is_symbol() {
            return Err(PyValueError::new_err(format!(
                "{what}: entry {i} ({e}) is not a symbol"
            )));
        }
    }
    Ok(m.iter().copied().collect())
}

#[pymethods]
impl PyExpr {
    /// A constant expression from a number, a sequence or a numpy array.
    #[new]
    fn py_new(value: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        Ok(PyExpr::new(operand(value)?))
    }

    /// `(rows, cols)`.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        self.m.shape()
    }

    /// Number of entries.
    #[getter]
    fn numel(&self) -> usize {
        self.m.len()
    }

    /// Transpose.
    #[getter(T)]
    fn transpose(&self) -> PyExpr {
        PyExpr::new(self.m.t())
    }

    fn __len__(&self) -> usize {
        if self.m.ncols() == 1 {
            self.m.nrows()
        } else {
            self.m.len()
        }
    }

    fn __getitem__(&self, key: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        let (r, c) = self.m.shape();
        if let Ok(t) = key.downcast::<PyTuple>() {
            if t.len() != 2 {
                return Err(PyIndexError::new_err("expected one or two indices"));
            }
            let rows = axis_index(&t.get_item(0)?, r)?;
            let cols = axis_index(&t.get_item(1)?, c)?;
            return Ok(PyExpr::new(take(&self.m, &rows, &cols)));
        }
        if c == 1 {
            let rows = axis_index(key, r)?;
            return Ok(PyExpr::new(take(&self.m, &rows, &[0])));
        }
        if r == 1 {
            let cols = axis_index(key, c)?;
            return Ok(PyExpr::new(take(&self.m, &[0], &cols)));
        }
        // A matrix with one index: entries in column-major order, as CasADi does.
        let idx = axis_index(key, self.m.len())?;
        let entries = self.m.entries();
        Ok(PyExpr::new(Matrix::from_vec(
            idx.iter().map(|&k| entries[k]).collect(),
        )))
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyResult<Py<PyAny>> {
        let py = slf.py();
        let items: Vec<PyExpr> = slf.m.iter().map(|&e| PyExpr::scalar(e)).collect();
        let list = pyo3::types::PyList::new(py, items)?;
        Ok(list.call_method0("__iter__")?.unbind())
    }

    fn __add__(&self, o: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        binary(&self.m, o, "+", false, |a, b| a + b)
    }
    fn __radd__(&self, o: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        binary(&self.m, o, "+", true, |a, b| a + b)
    }
    fn __sub__(&self, o: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        binary(&self.m, o, "-", false, |a, b| a - b)
    }
    fn __rsub__(&self, o: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        binary(&self.m, o, "-", true, |a, b| a - b)
    }
    fn __mul__(&self, o: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        binary(&self.m, o, "*", false, |a, b| a * b)
    }
    fn __rmul__(&self, o: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        binary(&self.m, o, "*", true, |a, b| a * b)
    }
    fn __truediv__(&self, o: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        binary(&self.m, o, "/", false, |a, b| a / b)
    }
    fn __rtruediv__(&self, o: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        binary(&self.m, o, "/", true, |a, b| a / b)
    }
    fn __pow__(
        &self,
        o: &Bound<'_, PyAny>,
        _modulo: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyExpr> {
        binary(&self.m, o, "**", false, pow_entry)
    }
    fn __rpow__(
        &self,
        o: &Bound<'_, PyAny>,
        _modulo: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyExpr> {
        binary(&self.m, o, "**", true, pow_entry)
    }
    fn __matmul__(&self, o: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        let b = operand(o)?;
        Ok(PyExpr::new(self.m.matmul(&b).map_err(build_err)?))
    }
    fn __rmatmul__(&self, o: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
        let a = operand(o)?;
        Ok(PyExpr::new(a.matmul(&self.m).map_err(build_err)?))
    }
    fn __neg__(&self) -> PyExpr {
        PyExpr::new(-&self.m)
    }
    fn __pos__(&self) -> PyExpr {
        self.clone()
    }
    fn __abs__(&self) -> PyExpr {
        PyExpr::new(self.m.map(|e| e.abs()))
    }

    /// `<=`, `>=`, `==` (and `<`, `>`, taken as non-strict, as CasADi does) make a
    /// `Constraint`, entry by entry with scalars broadcast.
    fn __richcmp__(&self, other: &Bound<'_, PyAny>, op: CompareOp) -> PyResult<PyConstraint> {
        let b = operand(other)?;
        let c = relation(&self.m, &b, op)?;
        Ok(PyConstraint { c })
    }

    /// The number of a constant 1×1 expression.
    fn __float__(&self) -> PyResult<f64> {
        let e = self.as_scalar("float()")?;
        e.value()
            .ok_or_else(|| PyTypeError::new_err(format!("{e} is not a constant")))
    }

    fn __repr__(&self) -> String {
        self.__str__()
    }

    fn __str__(&self) -> String {
        if self.m.shape() == (1, 1) {
            self.m[0].to_string()
        } else {
            self.m.to_string()
        }
    }

    /// numpy defers to `Expr`'s reflected operators (`2.0 * x`, `A @ x`).
    #[classattr]
    fn __array_ufunc__() -> Option<()> {
        None
    }

    /// Whether every entry is a symbol.
    fn is_symbolic(&self) -> bool {
        self.m.iter().all(|e| e.is_symbol())
    }

    /// The name of a 1×1 symbol, else None.
    fn name(&self) -> Option<String> {
        if self.m.shape() == (1, 1) {
            self.m[0].name()
        } else {
            None
        }
    }

    /// The values of a constant expression as a numpy array (shape as `value` gives it).
    fn to_numpy<'py>(&self, py: Python<'py>) -> PyResult<Py<PyAny>> {
        let mut v = Vec::with_capacity(self.m.len());
        for e in self.m.entries() {
            v.push(
                e.value()
                    .ok_or_else(|| PyValueError::new_err(format!("entry {e} is not a constant")))?,
            );
        }
        crate::solution::to_python(py, &v, self.m.shape())
    }

    /// Sum of all entries.
    fn sum(&self) -> PyExpr {
        PyExpr::scalar(self.m.sum())
    }

    /// What pickling stores: the shape, each entry printed (column-major) and the names
    /// of the symbols (each a distinct name that parses back).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Py<PyAny>, PickledExpr)> {
        let me = slf.borrow();
        let symbols = crate::solution::free_symbols(me.m.entries());
        let mut names: Vec<String> = Vec::with_capacity(symbols.len());
        for s in &symbols {
            let name = s.name().unwrap_or_default();
            if names.contains(&name) {
                return Err(PyTypeError::new_err(format!(
                    "cannot pickle this Expr: two different symbols are named '{name}' \
                     (pickling finds symbols by name)"
                )));
            }
            if !parses_back(&name) {
                return Err(PyTypeError::new_err(format!(
                    "cannot pickle this Expr: the symbol name '{name}' does not parse back \
                     (use letters, digits, '_', '.', '^' and [indices])"
                )));
            }
            names.push(name);
        }
        let entries = me.m.iter().map(|e| e.to_string()).collect();
        let (r, c) = me.m.shape();
        let f = slf.get_type().getattr("_from_pickle")?;
        Ok((f.unbind(), (r, c, entries, names)))
    }

    /// What unpickling calls: the entries parsed against new symbols of the given names
    /// (in this thread's graph).
    #[staticmethod]
    fn _from_pickle(
        rows: usize,
        cols: usize,
        entries: Vec<String>,
        names: Vec<String>,
    ) -> PyResult<PyExpr> {
        let symbols: Vec<Expr> = names.iter().map(|n| Expr::sym(n)).collect();
        let es = entries
            .iter()
            .map(|t| symx::parse(t, &symbols).map_err(build_err))
            .collect::<PyResult<Vec<Expr>>>()?;
        Matrix::from_column_major(rows, cols, es)
            .map(PyExpr::new)
            .map_err(build_err)
    }

    /// Reshapes to `(rows, cols)` in column-major order (CasADi's `reshape`).
    fn reshape(&self, rows: usize, cols: usize) -> PyResult<PyExpr> {
        if rows * cols != self.m.len() {
            return Err(PyValueError::new_err(format!(
                "cannot reshape {:?} into ({rows}, {cols})",
                self.m.shape()
            )));
        }
        Matrix::from_column_major(rows, cols, self.m.entries().to_vec())
            .map(PyExpr::new)
            .map_err(build_err)
    }
}

/// An `Expr` as pickling stores it: rows, columns, printed entries, symbol names.
type PickledExpr = (usize, usize, Vec<String>, Vec<String>);

/// Whether symx's parser reads `name` back as this one symbol name (symx::parse's rule:
/// a letter or `_`, then letters, digits, `_`, `.`, `^` and bracketed indices).
fn parses_back(name: &str) -> bool {
    let b = name.as_bytes();
    if !matches!(b.first(), Some(c) if c.is_ascii_alphabetic() || *c == b'_')
        || matches!(name, "inf" | "NaN")
    {
        return false;
    }
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_alphanumeric() || matches!(b[i], b'_' | b'.' | b'^') {
            i += 1;
        } else if b[i] == b'[' {
            match b[i..].iter().position(|&c| c == b']') {
                Some(close) => i += close + 1,
                None => return false,
            }
        } else {
            return false;
        }
    }
    true
}

fn pow_entry(a: Expr, b: Expr) -> Expr {
    match b.value() {
        Some(v) if v == v.trunc() && v.abs() <= i32::MAX as f64 => a.powi(v as i32),
        Some(v) => a.powf(v),
        None => a.pow(b),
    }
}

/// `a op b` as constraint rows (a 1×1 side is broadcast).
pub fn relation(a: &Matrix, b: &Matrix, op: CompareOp) -> PyResult<Constraint> {
    // Make the scalar side the right-hand side so the matrix relations broadcast it.
    let (l, r, op) = if a.shape() == (1, 1) && b.shape() != (1, 1) {
        let flipped = match op {
            CompareOp::Le | CompareOp::Lt => CompareOp::Ge,
            CompareOp::Ge | CompareOp::Gt => CompareOp::Le,
            o => o,
        };
        (b, a, flipped)
    } else {
        (a, b, op)
    };
    if r.shape() != (1, 1) && l.shape() != r.shape() {
        return Err(PyValueError::new_err(format!(
            "comparison: shapes {:?} and {:?} do not match",
            l.shape(),
            r.shape()
        )));
    }
    let c = match (op, r.shape() == (1, 1)) {
        (CompareOp::Le | CompareOp::Lt, true) => l.le(r[0]),
        (CompareOp::Ge | CompareOp::Gt, true) => l.ge(r[0]),
        (CompareOp::Eq, true) => l.eq(r[0]),
        (CompareOp::Le | CompareOp::Lt, false) => l.le(r),
        (CompareOp::Ge | CompareOp::Gt, false) => l.ge(r),
        (CompareOp::Eq, false) => l.eq(r),
        (CompareOp::Ne, _) => {
            return Err(PyTypeError::new_err(
                "'!=' is not a constraint; use symnlp.ne for a symbolic comparison",
            ))
        }
    };
    Ok(c)
}

/// A new symbol, or a `rows × cols` matrix of symbols named `name[i]` (CasADi's `SX.sym`).
#[pyfunction]
#[pyo3(signature = (name, rows = 1, cols = 1))]
fn sym(name: &str, rows: usize, cols: usize) -> PyExpr {
    if rows == 1 && cols == 1 {
        PyExpr::scalar(Expr::sym(name))
    } else if cols == 1 {
        PyExpr::new(Matrix::sym_vec(name, rows))
    } else {
        PyExpr::new(Matrix::sym(name, rows, cols))
    }
}

macro_rules! unary {
    ($($py:ident => $method:ident, $doc:literal;)*) => {$(
        #[doc = $doc]
        #[pyfunction]
        fn $py(x: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
            Ok(PyExpr::new(operand(x)?.map(|e| e.$method())))
        }
    )*};
}

unary! {
    sin => sin, "Sine, entry by entry.";
    cos => cos, "Cosine, entry by entry.";
    tan => tan, "Tangent, entry by entry.";
    asin => asin, "Arc sine, entry by entry.";
    acos => acos, "Arc cosine, entry by entry.";
    atan => atan, "Arc tangent, entry by entry.";
    sinh => sinh, "Hyperbolic sine, entry by entry.";
    cosh => cosh, "Hyperbolic cosine, entry by entry.";
    tanh => tanh, "Hyperbolic tangent, entry by entry.";
    asinh => asinh, "Inverse hyperbolic sine, entry by entry.";
    acosh => acosh, "Inverse hyperbolic cosine, entry by entry.";
    atanh => atanh, "Inverse hyperbolic tangent, entry by entry.";
    exp => exp, "Exponential, entry by entry.";
    log => ln, "Natural logarithm, entry by entry.";
    log1p => log1p, "log(1 + x), entry by entry.";
    expm1 => expm1, "exp(x) - 1, entry by entry.";
    sqrt => sqrt, "Square root, entry by entry.";
    sq => sq, "Square, entry by entry.";
    fabs => abs, "Absolute value, entry by entry.";
    sign => sign, "Sign (-1, 0, 1), entry by entry.";
    floor => floor, "Floor, entry by entry.";
    ceil => ceil, "Ceiling, entry by entry.";
    erf => erf, "Error function, entry by entry.";
}

macro_rules! binary_fn {
    ($($py:ident => $f:expr, $doc:literal;)*) => {$(
        #[doc = $doc]
        #[pyfunction]
        fn $py(a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
            let (a, b) = (operand(a)?, operand(b)?);
            Ok(PyExpr::new(broadcast(&a, &b, stringify!($py), $f)?))
        }
    )*};
}

binary_fn! {
    atan2 => |y: Expr, x: Expr| y.atan2(x), "atan2(y, x), entry by entry.";
    fmin => |a: Expr, b: Expr| a.min(b), "Minimum, entry by entry.";
    fmax => |a: Expr, b: Expr| a.max(b), "Maximum, entry by entry.";
    hypot => |a: Expr, b: Expr| a.hypot(b), "sqrt(a² + b²), entry by entry.";
    fmod => |a: Expr, b: Expr| a.fmod(b), "Remainder of a / b, entry by entry.";
    power => pow_entry, "a ** b, entry by entry.";
    lt => |a: Expr, b: Expr| symx::lt(a, b), "1 where a < b, else 0 (for if_else).";
    le => |a: Expr, b: Expr| symx::le(a, b), "1 where a <= b, else 0 (for if_else).";
    gt => |a: Expr, b: Expr| symx::gt(a, b), "1 where a > b, else 0 (for if_else).";
    ge => |a: Expr, b: Expr| symx::ge(a, b), "1 where a >= b, else 0 (for if_else).";
    eq => |a: Expr, b: Expr| symx::eq(a, b), "1 where a == b, else 0 (for if_else).";
    ne => |a: Expr, b: Expr| symx::ne(a, b), "1 where a != b, else 0 (for if_else).";
    logic_and => |a: Expr, b: Expr| symx::and(a, b), "Logical and of two conditions.";
    logic_or => |a: Expr, b: Expr| symx::or(a, b), "Logical or of two conditions.";
}

/// `a` where `cond` is nonzero, else `b`, entry by entry (CasADi's `if_else`); 1×1
/// arguments are broadcast.
#[pyfunction]
fn if_else(
    cond: &Bound<'_, PyAny>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
) -> PyResult<PyExpr> {
    let (c, a, b) = (operand(cond)?, operand(a)?, operand(b)?);
    let shape = [c.shape(), a.shape(), b.shape()]
        .into_iter()
        .find(|&s| s != (1, 1))
        .unwrap_or((1, 1));
    let [c, a, b] = [c, a, b].map(|m| expand(m, shape));
    let (c, a, b) = (c?, a?, b?);
    Ok(PyExpr::new(Matrix::from_fn(shape.0, shape.1, |i, j| {
        symx::if_else(c[(i, j)], a[(i, j)], b[(i, j)])
    })))
}

/// `m` itself if it has `shape`, a 1×1 `m` repeated to `shape`, else an error.
fn expand(m: Matrix, shape: (usize, usize)) -> PyResult<Matrix> {
    if m.shape() == shape {
        Ok(m)
    } else if m.shape() == (1, 1) {
        Ok(Matrix::from_fn(shape.0, shape.1, |_, _| m[0]))
    } else {
        Err(PyValueError::new_err(format!(
            "if_else: shapes {:?} and {:?} do not match",
            m.shape(),
            shape
        )))
    }
}

/// `lower <= expr <= upper` entry by entry (numbers; `None` for no bound): a
/// `Constraint`, e.g. for `Problem.subject_to` or an `Ocp` path constraint.
#[pyfunction]
#[pyo3(signature = (lower, expr, upper))]
pub fn bounded(
    lower: Option<f64>,
    expr: &Bound<'_, PyAny>,
    upper: Option<f64>,
) -> PyResult<PyConstraint> {
    let m = operand(expr)?;
    let (l, u) = (
        lower.unwrap_or(f64::NEG_INFINITY),
        upper.unwrap_or(f64::INFINITY),
    );
    if l.is_nan() || u.is_nan() || l > u {
        return Err(crate::error::BuildError::new_err(format!(
            "bounded: bounds [{l}, {u}] are not an interval"
        )));
    }
    Ok(PyConstraint {
        c: nlp::bounded(l, m, u),
    })
}

/// Stacks expressions vertically.
#[pyfunction]
#[pyo3(signature = (*parts))]
fn vertcat(parts: Vec<Bound<'_, PyAny>>) -> PyResult<PyExpr> {
    let ms: Vec<Matrix> = parts.iter().map(operand).collect::<PyResult<_>>()?;
    let refs: Vec<&Matrix> = ms.iter().collect();
    Ok(PyExpr::new(Matrix::vertcat(&refs).map_err(build_err)?))
}

/// Stacks expressions horizontally.
#[pyfunction]
#[pyo3(signature = (*parts))]
fn horzcat(parts: Vec<Bound<'_, PyAny>>) -> PyResult<PyExpr> {
    let ms: Vec<Matrix> = parts.iter().map(operand).collect::<PyResult<_>>()?;
    let refs: Vec<&Matrix> = ms.iter().collect();
    Ok(PyExpr::new(Matrix::horzcat(&refs).map_err(build_err)?))
}

/// Inner product of two vectors of one shape.
#[pyfunction]
fn dot(a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
    let (a, b) = (operand(a)?, operand(b)?);
    Ok(PyExpr::scalar(a.dot(&b).map_err(build_err)?))
}

/// Sum of squares of the entries.
#[pyfunction]
fn sumsqr(a: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
    Ok(PyExpr::scalar(operand(a)?.sumsqr()))
}

/// Euclidean norm of the entries.
#[pyfunction]
fn norm_2(a: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
    Ok(PyExpr::scalar(operand(a)?.norm_2()))
}

/// Sum of the entries.
#[pyfunction]
fn sum1(a: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
    Ok(PyExpr::scalar(operand(a)?.sum()))
}

/// The dense Jacobian of `f` (entries as rows) with respect to the symbols `x`.
#[pyfunction]
fn jacobian(f: &Bound<'_, PyAny>, x: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
    let f = operand(f)?;
    let xs = symbols(&operand(x)?, "jacobian: x")?;
    let j = symx::jacobian(f.entries(), &xs).map_err(build_err)?;
    Ok(PyExpr::new(j.to_dense()))
}

/// The structural sparsity of `jacobian(f, x)` as a scipy.sparse-compatible CSC triple
/// `(indptr, indices, shape)`: `scipy.sparse.csc_matrix((data, indices, indptr), shape)`.
#[pyfunction]
fn jacobian_sparsity(f: &Bound<'_, PyAny>, x: &Bound<'_, PyAny>) -> PyResult<CscPattern> {
    let f = operand(f)?;
    let xs = symbols(&operand(x)?, "jacobian_sparsity: x")?;
    let j = symx::jacobian(f.entries(), &xs).map_err(build_err)?;
    Ok(csc(j.sparsity()))
}

/// A sparsity pattern as scipy's CSC arrays: `(indptr, indices, (rows, cols))`.
pub type CscPattern = (Vec<usize>, Vec<usize>, (usize, usize));

/// `p` as a [`CscPattern`].
pub fn csc(p: &symx::Sparsity) -> CscPattern {
    (
        p.col_ptr().to_vec(),
        p.row_idx().to_vec(),
        (p.nrows(), p.ncols()),
    )
}

/// The gradient of a scalar `f` with respect to the symbols `x`, as a column.
#[pyfunction]
fn gradient(f: &PyExpr, x: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
    let f = f.as_scalar("gradient: f")?;
    let xs = symbols(&operand(x)?, "gradient: x")?;
    Ok(PyExpr::new(Matrix::from_vec(
        symx::gradient(f, &xs).map_err(build_err)?,
    )))
}

/// The dense, symmetric Hessian of a scalar `f` with respect to the symbols `x`.
#[pyfunction]
fn hessian(f: &PyExpr, x: &Bound<'_, PyAny>) -> PyResult<PyExpr> {
    let f = f.as_scalar("hessian: f")?;
    let xs = symbols(&operand(x)?, "hessian: x")?;
    // symx returns the lower triangle (what solvers use); Python users expect the full
    // symmetric matrix, as CasADi's `hessian` gives.
    let h = symx::hessian(f, &xs).map_err(build_err)?;
    let mut full = Matrix::zeros(xs.len(), xs.len());
    for (i, j, e) in h.triplets() {
        full[(i, j)] = e;
        full[(j, i)] = e;
    }
    Ok(PyExpr::new(full))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyExpr>()?;
    m.add_class::<PyConstraint>()?;
    m.add_function(wrap_pyfunction!(sym, m)?)?;
    for f in [
        wrap_pyfunction!(sin, m)?,
        wrap_pyfunction!(cos, m)?,
        wrap_pyfunction!(tan, m)?,
        wrap_pyfunction!(asin, m)?,
        wrap_pyfunction!(acos, m)?,
        wrap_pyfunction!(atan, m)?,
        wrap_pyfunction!(sinh, m)?,
        wrap_pyfunction!(cosh, m)?,
        wrap_pyfunction!(tanh, m)?,
        wrap_pyfunction!(asinh, m)?,
        wrap_pyfunction!(acosh, m)?,
        wrap_pyfunction!(atanh, m)?,
        wrap_pyfunction!(exp, m)?,
        wrap_pyfunction!(log, m)?,
        wrap_pyfunction!(log1p, m)?,
        wrap_pyfunction!(expm1, m)?,
        wrap_pyfunction!(sqrt, m)?,
        wrap_pyfunction!(sq, m)?,
        wrap_pyfunction!(fabs, m)?,
        wrap_pyfunction!(sign, m)?,
        wrap_pyfunction!(floor, m)?,
        wrap_pyfunction!(ceil, m)?,
        wrap_pyfunction!(erf, m)?,
        wrap_pyfunction!(atan2, m)?,
        wrap_pyfunction!(fmin, m)?,
        wrap_pyfunction!(fmax, m)?,
        wrap_pyfunction!(hypot, m)?,
        wrap_pyfunction!(fmod, m)?,
        wrap_pyfunction!(power, m)?,
        wrap_pyfunction!(lt, m)?,
        wrap_pyfunction!(le, m)?,
        wrap_pyfunction!(gt, m)?,
        wrap_pyfunction!(ge, m)?,
        wrap_pyfunction!(eq, m)?,
        wrap_pyfunction!(ne, m)?,
        wrap_pyfunction!(logic_and, m)?,
        wrap_pyfunction!(logic_or, m)?,
        wrap_pyfunction!(if_else, m)?,
        wrap_pyfunction!(bounded, m)?,
        wrap_pyfunction!(vertcat, m)?,
        wrap_pyfunction!(horzcat, m)?,
        wrap_pyfunction!(dot, m)?,
        wrap_pyfunction!(sumsqr, m)?,
        wrap_pyfunction!(norm_2, m)?,
        wrap_pyfunction!(sum1, m)?,
        wrap_pyfunction!(jacobian, m)?,
        wrap_pyfunction!(jacobian_sparsity, m)?,
        wrap_pyfunction!(gradient, m)?,
        wrap_pyfunction!(hessian, m)?,
    ] {
        m.add_function(f)?;
    }
    Ok(())
}
