//! Building matrices from matrices: [`Matrix::kron`], [`Matrix::reshape`],
//! [`Matrix::repmat`], [`Matrix::diagcat`]. They move expressions only; no node is created
//! except the zeros of `diagcat`, which are the shared constant 0.
use crate::error::SymxError;
use crate::matrix::Matrix;

impl Matrix {
    /// The Kronecker product `self ⊗ other`: block `(i, j)` is `self[i,j] · other`.
    pub fn kron(&self, other: &Matrix) -> Matrix {
        let (ra, ca) = self.shape();
        let (rb, cb) = other.shape();
        Matrix::from_fn(ra * rb, ca * cb, |i, j| {
            self[(i / rb, j / cb)] * other[(i % rb, j % cb)]
        })
    }

    /// The same entries in column-major order as a `rows × cols` matrix (CasADi's and
    /// MATLAB's `reshape`); `Err` if the number of entries differs.
    pub fn reshape(&self, rows: usize, cols: usize) -> Result<Matrix, SymxError> {
        if rows * cols != self.len() {
            return Err(SymxError::Dimension {
                op: "reshape",
                left: self.shape(),
                right: (rows, cols),
            });
        }
        Matrix::from_column_major(rows, cols, self.to_vec())
    }

    /// `rows × cols` copies of `self` tiled as blocks.
    pub fn repmat(&self, rows: usize, cols: usize) -> Matrix {
        let (r, c) = self.shape();
        Matrix::from_fn(r * rows, c * cols, |i, j| self[(i % r, j % c)])
    }

    /// The block-diagonal matrix of `parts` (zeros elsewhere).
    pub fn diagcat(parts: &[&Matrix]) -> Matrix {
        let rows: usize = parts.iter().map(|m| m.nrows()).sum();
        let cols: usize = parts.iter().map(|m| m.ncols()).sum();
        let mut out = Matrix::zeros(rows, cols);
        let (mut r0, mut c0) = (0, 0);
        for m in parts {
            for j in 0..m.ncols() {
                for i in 0..m.nrows() {
                    out[(r0 + i, c0 + j)] = m[(i, j)];
                }
            }
            r0 += m.nrows();
            c0 += m.ncols();
        }
        out
    }
}
