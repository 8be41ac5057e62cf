//! [`Table`]: a piecewise polynomial on a rectilinear grid of any dimension, cubic (or
//! lower) in each coordinate, the numeric data behind lookup nodes.
//!
//! On each cell `(j₀, j₁, …)` of the grid the table is
//! `Σ c[a₀ + 4a₁ + 16a₂ + …] · t₀^a₀ · t₁^a₁ ⋯` with `t_k = x_k − grid_k[j_k]` and every
//! power `a_k ≤ 3`. The partial derivative along an axis is again such a table, so a lookup
//! node differentiates into a lookup node, to any order. A tensor-product interpolant is
//! built by fitting 1-D piecewise cubics along one axis after the other
//! ([`Table::tensor`]): the 1-D fits are linear in the data, so this is the tensor-product
//! interpolant of the 1-D method.

/// Coefficients of `c₀ + c₁t + c₂t² + c₃t³` on each interval of a 1-D grid.
pub(crate) type Fit1 = fn(&[f64], &[f64]) -> Vec<[f64; 4]>;

/// A piecewise polynomial on the cells of a rectilinear grid.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct Table {
    /// The grid points of each axis (strictly increasing, at least 2).
    grids: Vec<Vec<f64>>,
    /// `4^d` coefficients per cell; cells ordered with axis 0 fastest.
    coeffs: Vec<f64>,
    /// Whether the end cells extend beyond the grid (else the table is 0 there).
    extrapolate: bool,
}

/// `Σ c[a] t^a` by Horner's rule, in any dimension: the last axis is the outermost sum.
#[inline]
fn horner(c: &[f64], t: &[f64]) -> f64 {
    match t {
        [t0] => c[0] + t0 * (c[1] + t0 * (c[2] + t0 * c[3])),
        [rest @ .., last] => {
            let s = c.len() / 4;
            let v = |a: usize| horner(&c[a * s..(a + 1) * s], rest);
            v(0) + last * (v(1) + last * (v(2) + last * v(3)))
        }
        [] => c[0],
    }
}

impl Table {
    /// The tensor-product interpolant of `values` (axis 0 fastest, as CasADi orders them)
    /// on `grids`, fitting each axis with `fit`. The sizes must have been checked.
    pub fn tensor(grids: &[&[f64]], values: &[f64], fit: Fit1, extrapolate: bool) -> Table {
        let d = grids.len();
        // Fit axis after axis; along an axis already fitted the index is `cell·4 + power`.
        let mut shape: Vec<usize> = grids.iter().map(|g| g.len()).collect();
        let mut data = values.to_vec();
        let mut line = Vec::new();
        for k in 0..d {
            let n = shape[k];
            let inner: usize = shape[..k].iter().product();
            let outer: usize = shape[k + 1..].iter().product();
            let m = (n - 1) * 4;
            let mut out = vec![0.0; inner * m * outer];
            for o in 0..outer {
                for i in 0..inner {
                    line.clear();
                    line.extend((0..n).map(|p| data[i + inner * (p + n * o)]));
                    for (cell, c) in fit(grids[k], &line).iter().enumerate() {
                        for (a, &v) in c.iter().enumerate() {
                            out[i + inner * (cell * 4 + a + m * o)] = v;
                        }
                    }
                }
            }
            data = out;
            shape[k] = m;
        }
        // Regroup into one block of 4^d coefficients per cell.
        let block = 4usize.pow(d as u32);
        let mut coeffs = vec![0.0; data.len()];
        for (index, &v) in data.iter().enumerate() {
            let (mut rest, mut cell, mut cell_stride, mut power, mut power_stride) =
                (index, 0, 1, 0, 1);
            for &m in &shape {
                let q = rest % m;
                rest /= m;
                cell += q / 4 * cell_stride;
                cell_stride *= m / 4;
                power += q % 4 * power_stride;
                power_stride *= 4;
            }
            coeffs[cell * block + power] = v;
        }
        Table {
            grids: grids.iter().map(|g| g.to_vec()).collect(),
            coeffs,
            extrapolate,
        }
    }

    /// A table from given per-cell coefficients (`4^d` per cell, cells with axis 0
    /// fastest, as stored). The sizes must have been checked ([`Table::check`]).
    pub fn from_cells(grids: &[&[f64]], coeffs: Vec<f64>, extrapolate: bool) -> Table {
        Table {
            grids: grids.iter().map(|g| g.to_vec()).collect(),
            coeffs,
            extrapolate,
        }
    }

    /// Why this table (read from a file) cannot be evaluated, if it cannot: 1 to 8 axes of
    /// at least 2 finite, strictly increasing points, `4^d` coefficients per cell.
    pub fn check(&self) -> Result<(), String> {
        let d = self.dims();
        if !(1..=8).contains(&d) {
            return Err(format!("{d} axes (1 to 8 supported)"));
        }
        for (k, g) in self.grids.iter().enumerate() {
            let increasing = g.windows(2).all(|w| w[0] < w[1]);
            if g.len() < 2 || !increasing || g.iter().any(|v| !v.is_finite()) {
                return Err(format!(
                    "axis {k} is not 2 or more finite, increasing points"
                ));
            }
        }
        let cells: usize = self.grids.iter().map(|g| g.len() - 1).product();
        if self.coeffs.len() != cells << (2 * d) {
            return Err(format!(
                "{} coefficients for {cells} cells of {d} axes (expected {})",
                self.coeffs.len(),
                cells << (2 * d)
            ));
        }
        Ok(())
    }

    /// Number of coordinates.
    pub fn dims(&self) -> usize {
        self.grids.len()
    }

    /// The table's value at `x` (`dims()` coordinates).
    #[inline]
    pub fn eval(&self, x: &[f64]) -> f64 {
        if let ([g], [x0]) = (self.grids.as_slice(), x) {
            // 1-D, the common case, without the loop over axes.
            let n = g.len();
            if !self.extrapolate && (*x0 < g[0] || *x0 > g[n - 1]) {
                return 0.0;
            }
            let i = g[1..n - 1].partition_point(|&p| p <= *x0);
            return horner(&self.coeffs[4 * i..4 * i + 4], &[x0 - g[i]]);
        }
        const MAX: usize = 8;
        let mut t = [0.0; MAX];
        let (mut cell, mut stride) = (0, 1);
        for (k, (g, &xk)) in self.grids.iter().zip(x).enumerate() {
            let n = g.len();
            if !self.extrapolate && (xk < g[0] || xk > g[n - 1]) {
                return 0.0;
            }
            // Interval: the number of interior grid points at or below x (end cells extend).
            let i = g[1..n - 1].partition_point(|&p| p <= xk);
            t[k] = xk - g[i];
            cell += i * stride;
            stride *= n - 1;
        }
        let block = 1 << (2 * self.dims());
        horner(
            &self.coeffs[cell * block..(cell + 1) * block],
            &t[..self.dims()],
        )
    }

    /// The table of the partial derivative along `axis`.
    pub fn derivative(&self, axis: usize) -> Table {
        let s = 4usize.pow(axis as u32);
        let coeffs = self
            .coeffs
            .iter()
            .enumerate()
            .map(|(index, _)| {
                let a = index / s % 4;
                if a == 3 {
                    0.0
                } else {
                    (a + 1) as f64 * self.coeffs[index + s]
                }
            })
            .collect();
        Table {
            grids: self.grids.clone(),
            coeffs,
            extrapolate: self.extrapolate,
        }
    }
}

/// The piecewise-linear interpolant: value and slope on each interval.
pub(crate) fn linear_fit(x: &[f64], y: &[f64]) -> Vec<[f64; 4]> {
    (0..x.len() - 1)
        .map(|i| [y[i], (y[i + 1] - y[i]) / (x[i + 1] - x[i]), 0.0, 0.0])
        .collect()
}

/// The cubic spline through the points with not-a-knot end conditions (at least 4).
pub(crate) fn not_a_knot_fit(x: &[f64], y: &[f64]) -> Vec<[f64; 4]> {
    let s = not_a_knot_slopes(x, y);
    (0..x.len() - 1)
        .map(|i| {
            let h = x[i + 1] - x[i];
            let d = (y[i + 1] - y[i]) / h;
            let c2 = (3.0 * d - 2.0 * s[i] - s[i + 1]) / h;
            let c3 = (s[i] + s[i + 1] - 2.0 * d) / (h * h);
            [y[i], s[i], c2, c3]
        })
        .collect()
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
