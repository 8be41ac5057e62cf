//! [`Interpolant`] and [`Interpolant2`]: differentiable lookup tables on 1-D and 2-D
//! rectilinear grids (CasADi's `interpolant`).
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
use crate::error::SymxError;
use crate::expr::Expr;
use crate::graph;
use crate::table::{linear_fit, not_a_knot_fit, Fit1, Table};
use std::sync::Arc;

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
