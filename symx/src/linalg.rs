//! Linear algebra on small dense symbolic matrices: [`Matrix::solve`], [`Matrix::inverse`],
//! [`Matrix::det`] and the entrywise norms.
//!
//! As CasADi's SX does, these build scalar expressions; nothing is decided by value at
//! run time (no pivoting), so one expression serves every evaluation point:
//! * `solve` uses forward or back substitution when the matrix is structurally triangular
//!   (all entries on one side of the diagonal are the constant 0), and otherwise a symbolic
//!   QR factorisation by modified Gram–Schmidt, `x = R⁻¹(Qᵀb)`. QR needs no pivoting: it
//!   is defined for every non-singular matrix. At a point where the matrix is singular the
//!   result is ∞ or NaN (a division by a zero diagonal entry of `R`).
//! * `inverse` is `solve(A, I)`.
//! * `det` is a cofactor expansion along the row or column with the most structural zeros
//!   (CasADi's choice): exact for any matrix, but its size grows like `n!` for dense
//!   matrices, so it is meant for `n ≲ 6` or sparse structure.
//!
//! The expression size of `solve` is `O(n³)` nodes (`O(n²)` per right-hand side after the
//! factorisation). For large systems, solve numerically instead.
use crate::error::SymxError;
use crate::expr::Expr;
use crate::matrix::Matrix;

fn square(m: &Matrix, op: &'static str) -> Result<usize, SymxError> {
    if m.nrows() == m.ncols() {
        Ok(m.nrows())
    } else {
        Err(SymxError::Dimension {
            op,
            left: m.shape(),
            right: (m.ncols(), m.nrows()),
        })
    }
}

fn is_zero(e: Expr) -> bool {
    e.is_constant_value(0.0)
}

/// Whether every entry strictly below (`lower == false`: above) the diagonal is the constant 0.
fn is_triangular(a: &Matrix, upper: bool) -> bool {
    let n = a.nrows();
    (0..n).all(|j| {
        (0..n)
            .filter(|&i| if upper { i > j } else { i < j })
            .all(|i| is_zero(a[(i, j)]))
    })
}

/// Solves `A x = b` for triangular `A` by substitution (back substitution if `upper`).
fn substitute(a: &Matrix, b: &Matrix, upper: bool) -> Matrix {
    let n = a.nrows();
    let mut x = b.clone();
    for c in 0..b.ncols() {
        let order: Vec<usize> = if upper {
            (0..n).rev().collect()
        } else {
            (0..n).collect()
        };
        for (pos, &i) in order.iter().enumerate() {
            let known: Expr = order[..pos].iter().map(|&j| a[(i, j)] * x[(j, c)]).sum();
            x[(i, c)] = (b[(i, c)] - known) / a[(i, i)];
        }
    }
    x
}

/// `A = QR` by modified Gram–Schmidt: `Q` (as columns) orthonormal, `R` upper triangular.
fn gram_schmidt(a: &Matrix) -> (Vec<Vec<Expr>>, Matrix) {
    let n = a.nrows();
    let mut q: Vec<Vec<Expr>> = Vec::with_capacity(n);
    let mut r = Matrix::zeros(n, n);
    for j in 0..n {
        let mut v: Vec<Expr> = (0..n).map(|i| a[(i, j)]).collect();
        for (i, qi) in q.iter().enumerate() {
            let rij: Expr = qi.iter().zip(&v).map(|(&x, &y)| x * y).sum();
            r[(i, j)] = rij;
            for (vk, &qk) in v.iter_mut().zip(qi) {
                *vk -= rij * qk;
            }
        }
        let rjj = v.iter().map(|e| e.sq()).sum::<Expr>().sqrt();
        r[(j, j)] = rjj;
        q.push(v.into_iter().map(|e| e / rjj).collect());
    }
    (q, r)
}

/// The minor of `a` without row `i` and column `j`.
fn minor(a: &Matrix, i: usize, j: usize) -> Matrix {
    let n = a.nrows();
    Matrix::from_fn(n - 1, n - 1, |r, c| {
        a[(r + usize::from(r >= i), c + usize::from(c >= j))]
    })
}

/// Cofactor expansion along the line with the most structural zeros.
fn cofactor_det(a: &Matrix) -> Expr {
    let n = a.nrows();
    match n {
        0 => return Expr::one(),
        1 => return a[(0, 0)],
        2 => return a[(0, 0)] * a[(1, 1)] - a[(0, 1)] * a[(1, 0)],
        _ => {}
    }
    let zeros_in_row = |i: usize| (0..n).filter(|&j| is_zero(a[(i, j)])).count();
    let zeros_in_col = |j: usize| (0..n).filter(|&i| is_zero(a[(i, j)])).count();
    let (best_row, row_zeros) = (0..n)
        .map(|i| (i, zeros_in_row(i)))
        .max_by_key(|&(i, z)| (z, std::cmp::Reverse(i)))
        .unwrap_or((0, 0));
    let (best_col, col_zeros) = (0..n)
        .map(|j| (j, zeros_in_col(j)))
        .max_by_key(|&(j, z)| (z, std::cmp::Reverse(j)))
        .unwrap_or((0, 0));
    let terms = (0..n).filter_map(|k| {
        let (i, j) = if col_zeros > row_zeros {
            (k, best_col)
        } else {
            (best_row, k)
        };
        let e = a[(i, j)];
        if is_zero(e) {
            return None;
        }
        let t = e * cofactor_det(&minor(a, i, j));
        Some(if (i + j) % 2 == 0 { t } else { -t })
    });
    terms.sum()
}

impl Matrix {
    /// The solution `x` of `self · x = b` (`self` square, `b` with as many rows); see the
    /// module notes for the method (triangular substitution or symbolic QR) and its limits.
    ///
    /// ```
    /// use symx::{Function, Matrix};
    /// let a = Matrix::sym("A", 2, 2);
    /// let b = Matrix::sym_vec("b", 2);
    /// let x = a.solve(&b).unwrap();
    /// let f = Function::new(&[&a, &b], &[&x]).unwrap();
    /// let out = f.call(&[&[2.0, 1.0, 1.0, 3.0], &[3.0, 5.0]]).unwrap(); // A = [[2,1],[1,3]]
    /// assert!((out[0][0] - 0.8).abs() < 1e-14 && (out[0][1] - 1.4).abs() < 1e-14);
    /// ```
    pub fn solve(&self, b: &Matrix) -> Result<Matrix, SymxError> {
        let n = square(self, "solve")?;
        if b.nrows() != n {
            return Err(SymxError::Dimension {
                op: "solve",
                left: self.shape(),
                right: b.shape(),
            });
        }
        if is_triangular(self, true) {
            return Ok(substitute(self, b, true));
        }
        if is_triangular(self, false) {
            return Ok(substitute(self, b, false));
        }
        let (q, r) = gram_schmidt(self);
        let qtb = Matrix::from_fn(n, b.ncols(), |i, c| {
            q[i].iter().enumerate().map(|(k, &qk)| qk * b[(k, c)]).sum()
        });
        Ok(substitute(&r, &qtb, true))
    }

    /// The inverse `solve(self, I)`; `Err` if `self` is not square.
    pub fn inverse(&self) -> Result<Matrix, SymxError> {
        let n = square(self, "inverse")?;
        self.solve(&Matrix::eye(n))
    }

    /// The determinant by cofactor expansion (see the module notes); `Err` if not square.
    pub fn det(&self) -> Result<Expr, SymxError> {
        square(self, "det")?;
        Ok(cofactor_det(self))
    }

    /// Sum of the absolute values of all entries (CasADi's `norm_1`, entrywise also for
    /// matrices).
    pub fn norm_1(&self) -> Expr {
        self.iter().map(|e| e.abs()).sum()
    }

    /// Largest absolute value of all entries (CasADi's `norm_inf`, entrywise); 0 when empty.
    pub fn norm_inf(&self) -> Expr {
        self.iter().fold(Expr::zero(), |m, e| m.max(e.abs()))
    }

    /// Frobenius norm `√Σ aᵢⱼ²` (the same as [`Matrix::norm_2`]).
    pub fn norm_fro(&self) -> Expr {
        self.norm_2()
    }
}
