//! [`Interpolant`]: differentiable 1-D lookup tables (CasADi's `interpolant`).
//!
//! A table is stored as a piecewise polynomial (one cubic per grid interval, in powers of
//! `x − xᵢ`), so that its derivative is again a piecewise polynomial table: a lookup node
//! differentiates into a lookup node of the derivative table, to any order, and the
//! compiled tape evaluates each lookup with a binary search and a Horner step.
//!
//! * `linear`: the piecewise-linear interpolant; outside the grid it extends the end
//!   segments linearly (as CasADi's `'linear'`).
//! * `bspline`: the cubic spline through the data with not-a-knot end conditions, which is
//!   what CasADi's `'bspline'` computes (checked in `symx/tests/ops.rs`); as in CasADi it is
//!   zero outside the grid.
use crate::error::SymxError;
use crate::expr::Expr;
use crate::graph;
use std::sync::Arc;

/// A piecewise cubic on the intervals of `breaks`.
#[derive(Debug, PartialEq)]
pub(crate) struct Table {
    breaks: Vec<f64>,
    /// Coefficients of `c₀ + c₁t + c₂t² + c₃t³`, `t = x − breaks[i]`, per interval `i`.
    coeffs: Vec<[f64; 4]>,
    /// Whether the end intervals extend beyond the grid (else the table is 0 there).
    extrapolate: bool,
}

impl Table {
    /// The table's value at `x`.
    #[inline]
    pub fn eval(&self, x: f64) -> f64 {
        let b = &self.breaks;
        let n = b.len();
        if !self.extrapolate && (x < b[0] || x > b[n - 1]) {
            return 0.0;
        }
        // Interval: the number of interior breaks at or below x.
        let i = b[1..n - 1].partition_point(|&t| t <= x);
        let t = x - b[i];
        let c = &self.coeffs[i];
        c[0] + t * (c[1] + t * (c[2] + t * c[3]))
    }

    /// The table of the derivative.
    pub fn derivative(&self) -> Table {
        Table {
            breaks: self.breaks.clone(),
            coeffs: self
                .coeffs
                .iter()
                .map(|c| [c[1], 2.0 * c[2], 3.0 * c[3], 0.0])
                .collect(),
            extrapolate: self.extrapolate,
        }
    }
}

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

fn check_data(grid: &[f64], values: &[f64], min_points: usize) -> Result<(), SymxError> {
    let bad = |reason: String| Err(SymxError::Table { reason });
    if grid.len() != values.len() {
        return bad(format!(
            "{} grid points but {} values",
            grid.len(),
            values.len()
        ));
    }
    if grid.len() < min_points {
        return bad(format!(
            "{} grid points, at least {min_points} needed",
            grid.len()
        ));
    }
    if let Some(i) = grid.iter().chain(values).position(|v| !v.is_finite()) {
        let (what, k) = if i < grid.len() {
            ("grid point", i)
        } else {
            ("value", i - grid.len())
        };
        return bad(format!("{what} {k} is not finite"));
    }
    if let Some(i) = grid.windows(2).position(|w| w[1] <= w[0]) {
        return bad(format!("grid not strictly increasing at index {}", i + 1));
    }
    Ok(())
}

impl Interpolant {
    /// Piecewise-linear interpolation of `values` at the strictly increasing `grid` (at least
    /// two points); linear extrapolation outside the grid.
    pub fn linear(grid: &[f64], values: &[f64]) -> Result<Interpolant, SymxError> {
        check_data(grid, values, 2)?;
        let coeffs = (0..grid.len() - 1)
            .map(|i| {
                let slope = (values[i + 1] - values[i]) / (grid[i + 1] - grid[i]);
                [values[i], slope, 0.0, 0.0]
            })
            .collect();
        Ok(Interpolant::from_table(Table {
            breaks: grid.to_vec(),
            coeffs,
            extrapolate: true,
        }))
    }

    /// The cubic spline through `values` at the strictly increasing `grid` (at least four
    /// points) with not-a-knot end conditions (CasADi's `'bspline'`); zero outside the grid.
    pub fn bspline(grid: &[f64], values: &[f64]) -> Result<Interpolant, SymxError> {
        check_data(grid, values, 4)?;
        let s = not_a_knot_slopes(grid, values);
        let coeffs = (0..grid.len() - 1)
            .map(|i| {
                let h = grid[i + 1] - grid[i];
                let d = (values[i + 1] - values[i]) / h;
                let c2 = (3.0 * d - 2.0 * s[i] - s[i + 1]) / h;
                let c3 = (s[i] + s[i + 1] - 2.0 * d) / (h * h);
                [values[i], s[i], c2, c3]
            })
            .collect();
        Ok(Interpolant::from_table(Table {
            breaks: grid.to_vec(),
            coeffs,
            extrapolate: false,
        }))
    }

    fn from_table(table: Table) -> Interpolant {
        Interpolant {
            table: Arc::new(table),
        }
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
        self.table.eval(x)
    }

    /// The derivative table (again an `Interpolant`).
    pub fn derivative(&self) -> Interpolant {
        Interpolant::from_table(self.table.derivative())
    }
}

/// Slopes of the not-a-knot cubic spline at the grid points: a tridiagonal system (the
/// formulation of de Boor, *A Practical Guide to Splines*, ch. IV, also used by SciPy's
/// `CubicSpline`), solved by tridiagonal elimination without pivoting: the interior rows are
/// diagonally dominant and the first elimination step leaves the pivot `h₀ + h₁ > 0`.
fn not_a_knot_slopes(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    let d: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
    let (mut sub, mut diag, mut sup, mut rhs) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let w0 = x[2] - x[0];
    diag[0] = h[1];
    sup[0] = w0;
    rhs[0] = ((h[0] + 2.0 * w0) * h[1] * d[0] + h[0] * h[0] * d[1]) / w0;
    for i in 1..n - 1 {
        sub[i] = h[i];
        diag[i] = 2.0 * (h[i - 1] + h[i]);
        sup[i] = h[i - 1];
        rhs[i] = 3.0 * (h[i] * d[i - 1] + h[i - 1] * d[i]);
    }
    let wn = x[n - 1] - x[n - 3];
    sub[n - 1] = wn;
    diag[n - 1] = h[n - 3];
    rhs[n - 1] =
        (h[n - 2] * h[n - 2] * d[n - 3] + (2.0 * wn + h[n - 2]) * h[n - 3] * d[n - 2]) / wn;
    // Thomas algorithm.
    for i in 1..n {
        let m = sub[i] / diag[i - 1];
        diag[i] -= m * sup[i - 1];
        rhs[i] -= m * rhs[i - 1];
    }
    let mut s = vec![0.0; n];
    s[n - 1] = rhs[n - 1] / diag[n - 1];
    for i in (0..n - 1).rev() {
        s[i] = (rhs[i] - sup[i] * s[i + 1]) / diag[i];
    }
    s
}
