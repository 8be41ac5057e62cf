//! [`Interpolant`], [`Interpolant2`] and [`InterpolantN`]: differentiable lookup tables on
//! 1-D, 2-D and n-D rectilinear grids (CasADi's `interpolant`).
//!
//! A table is stored as a piecewise polynomial ([`crate::table`]: one polynomial per grid
//! cell, cubic at most in each coordinate), so that its partial derivatives are again
//! such tables: a lookup node differentiates into lookup nodes of the derivative tables,
//! to any order, and the compiled tape evaluates each lookup with a binary search per
//! axis and Horner steps.
//!
//! * `linear`: the piecewise-linear interpolant (bilinear on 2-D cells); outside the grid
//!   it extends the end cells' polynomials (as CasADi's `'linear'`).
//! * `bspline`: the cubic spline through the data with not-a-knot end conditions, which is
//!   what CasADi's `'bspline'` computes (checked in `symx/tests/ops.rs`); on a 2-D grid
//!   the tensor product of it (checked in `symx/tests/interpolant2.rs`); as in CasADi it is
//!   zero outside the grid.
//!
//! 1-D and 2-D lookups are graph nodes of their own (`Interpolant`, `Interpolant2`). A
//! node holds at most three operand slots, so an n-D lookup is instead a call (see
//! `call.rs`) of a small compiled function whose tape is one [`crate::Op::InterpolantN`]
//! instruction; its Jacobian function calls the lookup functions of the partial-derivative
//! tables, so it differentiates to any order like any call.
use crate::error::SymxError;
use crate::expr::Expr;
use crate::function::{next_uid, Function, Instr};
use crate::graph;
use crate::interpret::Tape;
use crate::op::Op;
use crate::table::{linear_fit, not_a_knot_fit, Fit1, Table};
use std::sync::{Arc, OnceLock};

/// A differentiable 1-D lookup table; apply it to an expression with [`Interpolant::eval`].
///
/// The table is plain data (`Send + Sync`): build it once and use it in any thread's graph.
/// ```
/// use symx::{gradient, Expr, Function, Interpolant};
/// let table = Interpolant::linear(&[0.0, 1.0, 2.0], &[0.0, 2.0, 3.0]).unwrap();
/// let x = Expr::sym("x");
/// let y = table.eval(x);
/// let dy = gradient(y, &[x]).unwrap();
/// let f = Function::new(&[&[x]], &[&[y], &dy]).unwrap();
/// assert_eq!(f.call(&[&[1.5]]).unwrap(), vec![vec![2.5], vec![1.0]]);
/// assert_eq!(table.value(0.5), 1.0);
/// ```
#[derive(Clone, Debug)]
pub struct Interpolant {
    table: Arc<Table>,
}

impl Interpolant {
    /// Piecewise-linear interpolation of `values` at the strictly increasing `grid` (at least
    /// two points); linear extrapolation outside the grid.
    pub fn linear(grid: &[f64], values: &[f64]) -> Result<Interpolant, SymxError> {
        Interpolant::fit(grid, values, 2, linear_fit, true)
    }

    /// The cubic spline through `values` at the strictly increasing `grid` (at least four
    /// points) with not-a-knot end conditions (CasADi's `'bspline'`); zero outside the grid.
    pub fn bspline(grid: &[f64], values: &[f64]) -> Result<Interpolant, SymxError> {
        Interpolant::fit(grid, values, 4, not_a_knot_fit, false)
    }

    fn fit(
        grid: &[f64],
        values: &[f64],
        min_points: usize,
        fit: Fit1,
        extrapolate: bool,
    ) -> Result<Interpolant, SymxError> {
        check_grid("grid", grid, min_points)?;
        check_values(values, grid.len())?;
        Ok(Interpolant {
            table: Arc::new(Table::tensor(&[grid], values, fit, extrapolate)),
        })
    }

    /// The table applied to an expression: a lookup node of this thread's graph.
    pub fn eval(&self, x: impl Into<Expr>) -> Expr {
        let x = x.into().id;
        Expr::from_id(graph::with(|g| {
            let t = g.table_id(&self.table);
            g.interpolant(x, t)
        }))
    }

    /// The table's value at a number.
    pub fn value(&self, x: f64) -> f64 {
        self.table.eval(&[x])
    }

    /// The derivative table (again an `Interpolant`).
    pub fn derivative(&self) -> Interpolant {
        Interpolant {
            table: Arc::new(self.table.derivative(0)),
        }
    }
}

/// A differentiable lookup table on a 2-D rectilinear grid; apply it to two expressions
/// with [`Interpolant2::eval`].
///
/// The values are given with the first coordinate varying fastest (`values[i + nx·j]` at
/// `(x[i], y[j])`, CasADi's column-major order). Plain data (`Send + Sync`), like
/// [`Interpolant`].
/// ```
/// use symx::{gradient, Expr, Function, Interpolant2};
/// // f(x, y) = x + 10y on the grid {0, 1} × {0, 1, 2}: bilinear reproduces it.
/// let table = Interpolant2::linear(&[0.0, 1.0], &[0.0, 1.0, 2.0], &[0.0, 1.0, 10.0, 11.0, 20.0, 21.0]).unwrap();
/// let (x, y) = (Expr::sym("x"), Expr::sym("y"));
/// let f = table.eval(x, y);
/// let df = gradient(f, &[x, y]).unwrap();
/// let fun = Function::new(&[&[x, y]], &[&[f], &df]).unwrap();
/// assert_eq!(fun.call(&[&[0.5, 1.5]]).unwrap(), vec![vec![15.5], vec![1.0, 10.0]]);
/// assert_eq!(table.value(0.25, 2.0), 20.25);
/// ```
#[derive(Clone, Debug)]
pub struct Interpolant2 {
    table: Arc<Table>,
}

impl Interpolant2 {
    /// Bilinear interpolation of `values` on the grid `x × y` (each strictly increasing,
    /// at least two points); outside the grid the end cells' bilinear polynomials extend.
    pub fn linear(x: &[f64], y: &[f64], values: &[f64]) -> Result<Interpolant2, SymxError> {
        Interpolant2::fit(x, y, values, 2, linear_fit, true)
    }

    /// The tensor-product cubic spline with not-a-knot end conditions through `values` on
    /// the grid `x × y` (each strictly increasing, at least four points; CasADi's
    /// `'bspline'`); zero outside the grid.
    pub fn bspline(x: &[f64], y: &[f64], values: &[f64]) -> Result<Interpolant2, SymxError> {
        Interpolant2::fit(x, y, values, 4, not_a_knot_fit, false)
    }

    /// A piecewise bicubic (or lower) polynomial given cell by cell: on the cell
    /// `[x[i], x[i+1]] × [y[j], y[j+1]]` the table is `Σ_a Σ_b c[a + 4b] · s^a · t^b` with
    /// `s = x − x[i]`, `t = y − y[j]`, `a, b ≤ 3`, where `c` is the block of 16
    /// coefficients starting at `coeffs[16·(i + (nx − 1)·j)]`. Each grid strictly
    /// increasing, at least two points, every coefficient finite. With `extrapolate` the
    /// end cells' polynomials extend beyond the grid, else the table is zero there. For
    /// interpolation schemes the other constructors do not offer (e.g. Catmull-Rom).
    /// ```
    /// use symx::Interpolant2;
    /// // f(x, y) = x·y on one cell [1, 2] × [0, 1]: (1 + s)·t = t + s·t.
    /// let mut c = vec![0.0; 16];
    /// c[4] = 1.0; // t
    /// c[5] = 1.0; // s·t
    /// let table = Interpolant2::from_cells(&[1.0, 2.0], &[0.0, 1.0], &c, false).unwrap();
    /// assert_eq!(table.value(1.5, 0.5), 0.75);
    /// assert_eq!(table.value(3.0, 0.5), 0.0);
    /// ```
    pub fn from_cells(
        x: &[f64],
        y: &[f64],
        coeffs: &[f64],
        extrapolate: bool,
    ) -> Result<Interpolant2, SymxError> {
        check_grid("x grid", x, 2)?;
        check_grid("y grid", y, 2)?;
        let cells = (x.len() - 1) * (y.len() - 1);
        if coeffs.len() != 16 * cells {
            return Err(SymxError::Table {
                reason: format!(
                    "{cells} cells need {} coefficients, got {}",
                    16 * cells,
                    coeffs.len()
                ),
            });
        }
        if let Some(i) = coeffs.iter().position(|v| !v.is_finite()) {
            return Err(SymxError::Table {
                reason: format!("coefficient {i} is not finite"),
            });
        }
        Ok(Interpolant2 {
            table: Arc::new(Table::from_cells(&[x, y], coeffs.to_vec(), extrapolate)),
        })
    }

    fn fit(
        x: &[f64],
        y: &[f64],
        values: &[f64],
        min_points: usize,
        fit: Fit1,
        extrapolate: bool,
    ) -> Result<Interpolant2, SymxError> {
        check_grid("x grid", x, min_points)?;
        check_grid("y grid", y, min_points)?;
        check_values(values, x.len() * y.len())?;
        Ok(Interpolant2 {
            table: Arc::new(Table::tensor(&[x, y], values, fit, extrapolate)),
        })
    }

    /// The table applied to two expressions: a lookup node of this thread's graph.
    pub fn eval(&self, x: impl Into<Expr>, y: impl Into<Expr>) -> Expr {
        let (x, y) = (x.into().id, y.into().id);
        Expr::from_id(graph::with(|g| {
            let t = g.table_id(&self.table);
            g.interpolant2(x, y, t)
        }))
    }

    /// The table's value at a point.
    pub fn value(&self, x: f64, y: f64) -> f64 {
        self.table.eval(&[x, y])
    }

    /// The partial derivative along `axis` (0: x, 1: y) applied to two expressions: the
    /// node that differentiating [`Interpolant2::eval`] gives, on the same derivative
    /// table of this thread's graph (built once per graph, unlike looking up
    /// [`Interpolant2::derivative`]); `Err` for another axis.
    /// ```
    /// use symx::{Expr, Function, Interpolant2};
    /// let table = Interpolant2::linear(&[0.0, 1.0], &[0.0, 1.0], &[0.0, 1.0, 10.0, 11.0]).unwrap();
    /// let (x, y) = (Expr::sym("x"), Expr::sym("y"));
    /// let dy = table.eval_partial(1, x, y).unwrap();
    /// let f = Function::new(&[&[x, y]], &[&[dy]]).unwrap();
    /// assert_eq!(f.call(&[&[0.5, 0.5]]).unwrap(), vec![vec![10.0]]);
    /// ```
    pub fn eval_partial(
        &self,
        axis: usize,
        x: impl Into<Expr>,
        y: impl Into<Expr>,
    ) -> Result<Expr, SymxError> {
        if axis > 1 {
            return Err(SymxError::Table {
                reason: format!("axis {axis} of a 2-D table"),
            });
        }
        let (x, y) = (x.into().id, y.into().id);
        Ok(Expr::from_id(graph::with(|g| {
            let t = g.table_id(&self.table);
            let d = g.derivative_table(t, axis);
            g.interpolant2(x, y, d)
        })))
    }

    /// The table of the partial derivative along `axis` (0: x, 1: y); `Err` for another axis.
    pub fn derivative(&self, axis: usize) -> Result<Interpolant2, SymxError> {
        if axis > 1 {
            return Err(SymxError::Table {
                reason: format!("axis {axis} of a 2-D table"),
            });
        }
        Ok(Interpolant2 {
            table: Arc::new(self.table.derivative(axis)),
        })
    }
}

/// A lookup table on an n-D rectilinear grid (n from 1 to 8); apply it to n expressions
/// with [`InterpolantN::eval`].
///
/// The values are ordered with the first coordinate fastest (`values[i₀ + n₀·(i₁ + n₁·i₂)]`
/// in 3-D, CasADi's column-major order). In the graph a lookup is a call of
/// [`InterpolantN::function`] (1-D and 2-D tables have cheaper nodes of their own:
/// [`Interpolant`], [`Interpolant2`]).
/// ```
/// use symx::{gradient, Expr, Function, InterpolantN};
/// // f = x + 10y + 100z on {0,1}³ (x fastest): trilinear reproduces it.
/// let values: Vec<f64> = (0..8).map(|k| ((k & 1) + 10 * (k >> 1 & 1) + 100 * (k >> 2)) as f64).collect();
/// let g = [0.0, 1.0];
/// let table = InterpolantN::linear(&[&g, &g, &g], &values).unwrap();
/// let v = [Expr::sym("x"), Expr::sym("y"), Expr::sym("z")];
/// let f = table.eval(&v).unwrap();
/// let df = gradient(f, &v).unwrap();
/// let fun = Function::new(&[&v], &[&[f], &df]).unwrap();
/// assert_eq!(fun.call(&[&[0.5, 0.25, 0.5]]).unwrap(), vec![vec![53.0], vec![1.0, 10.0, 100.0]]);
/// assert_eq!(table.value(&[1.0, 1.0, 0.0]).unwrap(), 11.0);
/// ```
#[derive(Clone, Debug)]
pub struct InterpolantN {
    table: Arc<Table>,
    function: Function,
}

/// Most coordinates of an [`InterpolantN`] (the evaluation keeps them on the stack).
const MAX_DIMS: usize = 8;

impl InterpolantN {
    /// Multilinear interpolation of `values` on the grid `grids[0] × grids[1] × …` (each
    /// strictly increasing, at least two points); outside the grid the end cells'
    /// polynomials extend.
    pub fn linear(grids: &[&[f64]], values: &[f64]) -> Result<InterpolantN, SymxError> {
        InterpolantN::fit(grids, values, 2, linear_fit, true)
    }

    /// The tensor-product cubic spline with not-a-knot end conditions (each axis at least
    /// four points; CasADi's `'bspline'`); zero outside the grid.
    pub fn bspline(grids: &[&[f64]], values: &[f64]) -> Result<InterpolantN, SymxError> {
        InterpolantN::fit(grids, values, 4, not_a_knot_fit, false)
    }

    fn fit(
        grids: &[&[f64]],
        values: &[f64],
        min_points: usize,
        fit: Fit1,
        extrapolate: bool,
    ) -> Result<InterpolantN, SymxError> {
        if grids.is_empty() || grids.len() > MAX_DIMS {
            return Err(SymxError::Table {
                reason: format!("{} grid axes, 1 to {MAX_DIMS} supported", grids.len()),
            });
        }
        for (k, grid) in grids.iter().enumerate() {
            check_grid(&format!("grid {k}"), grid, min_points)?;
        }
        check_values(values, grids.iter().map(|g| g.len()).product())?;
        let table = Arc::new(Table::tensor(grids, values, fit, extrapolate));
        Ok(InterpolantN {
            function: Function::lookup(table.clone()),
            table,
        })
    }

    /// Number of coordinates.
    pub fn dims(&self) -> usize {
        self.table.dims()
    }

    /// The table applied to `dims()` expressions (a call of [`InterpolantN::function`],
    /// folded to a constant when all are constants); `Err` for another count.
    pub fn eval(&self, x: &[Expr]) -> Result<Expr, SymxError> {
        let values: Option<Vec<f64>> = x.iter().map(|e| e.value()).collect();
        if let (Some(v), true) = (values, x.len() == self.dims()) {
            return Ok(Expr::constant(self.table.eval(&v)));
        }
        Ok(self.function.apply(&[x])?[0][0])
    }

    /// The table's value at a point of `dims()` coordinates; `Err` for another count.
    pub fn value(&self, x: &[f64]) -> Result<f64, SymxError> {
        if x.len() != self.dims() {
            return Err(SymxError::Length {
                what: "interpolant point",
                index: 0,
                expected: self.dims(),
                got: x.len(),
            });
        }
        Ok(self.table.eval(x))
    }

    /// The table of the partial derivative along `axis`; `Err` if there is no such axis.
    pub fn derivative(&self, axis: usize) -> Result<InterpolantN, SymxError> {
        if axis >= self.dims() {
            return Err(SymxError::Table {
                reason: format!("axis {axis} of a {}-D table", self.dims()),
            });
        }
        let table = Arc::new(self.table.derivative(axis));
        Ok(InterpolantN {
            function: Function::lookup(table.clone()),
            table,
        })
    }

    /// The lookup as a compiled function: one input of `dims()` entries, one output.
    pub fn function(&self) -> &Function {
        &self.function
    }
}

impl Function {
    /// The function `x ↦ table(x)` (input `x` of `table.dims()` entries), whose tape is one
    /// [`Op::InterpolantN`] instruction: work vector `[x | y]`.
    pub(crate) fn lookup(table: Arc<Table>) -> Function {
        let n = table.dims();
        Function {
            name: format!("interpolant{n}d"),
            input_names: vec!["x".into()],
            output_names: vec!["y".into()],
            uid: next_uid(),
            input_sizes: vec![n],
            output_sizes: vec![1],
            input_offsets: vec![0],
            input_used: vec![true],
            output_offsets: vec![n],
            tape: Tape::new(
                vec![Instr {
                    op: Op::InterpolantN,
                    d: n as u32,
                    a: 0,
                    b: n as u32,
                    c: 0,
                }],
                &[],
                n + 1,
                std::iter::once(n..n + 1),
            ),
            template: vec![0.0],
            template_start: n,
            work_size: n + 1,
            tables: vec![table],
            calls: Vec::new(),
            call_scratch: n + 1,
            dependencies: OnceLock::new(),
            jacobians: Default::default(),
            native: None,
            external: None,
        }
    }

    /// The table of a lookup function ([`Function::lookup`]).
    pub(crate) fn lookup_table(&self) -> Option<&Arc<Table>> {
        match &self.tape[..] {
            [Instr {
                op: Op::InterpolantN,
                ..
            }] => self.tables.first(),
            _ => None,
        }
    }
}

/// Checks one axis: at least `min_points` finite, strictly increasing points.
fn check_grid(what: &str, grid: &[f64], min_points: usize) -> Result<(), SymxError> {
    let bad = |reason: String| Err(SymxError::Table { reason });
    if grid.len() < min_points {
        return bad(format!(
            "{what} has {} points, at least {min_points} needed",
            grid.len()
        ));
    }
    if let Some(i) = grid.iter().position(|v| !v.is_finite()) {
        return bad(format!("{what} point {i} is not finite"));
    }
    if let Some(i) = grid.windows(2).position(|w| w[1] <= w[0]) {
        return bad(format!("{what} not strictly increasing at index {}", i + 1));
    }
    Ok(())
}

/// Checks the values: `expected` of them (one per grid point), all finite.
fn check_values(values: &[f64], expected: usize) -> Result<(), SymxError> {
    let bad = |reason: String| Err(SymxError::Table { reason });
    if values.len() != expected {
        return bad(format!(
            "{expected} grid points but {} values",
            values.len()
        ));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return bad(format!("value {i} is not finite"));
    }
    Ok(())
}
