//! [`Matrix`]: dense matrices and column vectors of expressions.
//!
//! Storage is dense and column-major; structural zeros are the constant `0`, which
//! differentiation and sparsity detection recognise, so sparse structure survives into
//! derivatives. A `Matrix` dereferences to the slice of its entries (column-major), so
//! it can be passed wherever `&[Expr]` is expected.
use crate::error::SymxError;
use crate::expr::Expr;
use crate::sparsity::Sparsity;
use std::fmt;
use std::ops::{Add, Deref, DerefMut, Index, IndexMut, Mul, Neg, Range, Sub};

/// A dense matrix of expressions (a column vector when it has one column).
#[derive(Clone)]
pub struct Matrix {
    rows: usize,
    cols: usize,
    data: Vec<Expr>,
}

impl Matrix {
    /// A matrix of new symbols named `name[i,j]` (or `name[i]` for a column vector).
    pub fn sym(name: &str, rows: usize, cols: usize) -> Matrix {
        Matrix::from_fn(rows, cols, |i, j| {
            if cols == 1 {
                Expr::sym(&format!("{name}[{i}]"))
            } else {
                Expr::sym(&format!("{name}[{i},{j}]"))
            }
        })
    }

    /// A column vector of `n` new symbols named `name[i]`.
    pub fn sym_vec(name: &str, n: usize) -> Matrix {
        Matrix::sym(name, n, 1)
    }

    /// A matrix whose entry `(i, j)` is `f(i, j)`.
    pub fn from_fn(rows: usize, cols: usize, mut f: impl FnMut(usize, usize) -> Expr) -> Matrix {
        let mut data = Vec::with_capacity(rows * cols);
        for j in 0..cols {
            for i in 0..rows {
                data.push(f(i, j));
            }
        }
        Matrix { rows, cols, data }
    }

    /// A column vector.
    pub fn from_vec(entries: Vec<Expr>) -> Matrix {
        Matrix {
            rows: entries.len(),
            cols: 1,
            data: entries,
        }
    }

    /// A matrix from column-major entries; `Err` if the count is not `rows·cols`.
    pub fn from_column_major(
        rows: usize,
        cols: usize,
        data: Vec<Expr>,
    ) -> Result<Matrix, SymxError> {
        if data.len() != rows * cols {
            return Err(SymxError::Dimension {
                op: "from_column_major",
                left: (rows, cols),
                right: (data.len(), 1),
            });
        }
        Ok(Matrix { rows, cols, data })
    }

    /// A matrix of constants from row-major rows of numbers; `Err` on ragged rows.
    pub fn from_rows_f64(rows: &[&[f64]]) -> Result<Matrix, SymxError> {
        let cols = rows.first().map_or(0, |r| r.len());
        if let Some(bad) = rows.iter().find(|r| r.len() != cols) {
            return Err(SymxError::Dimension {
                op: "from_rows_f64",
                left: (1, cols),
                right: (1, bad.len()),
            });
        }
        Ok(Matrix::from_fn(rows.len(), cols, |i, j| rows[i][j].into()))
    }

    /// A column vector of constants.
    pub fn from_f64(values: &[f64]) -> Matrix {
        Matrix::from_vec(values.iter().map(|&v| v.into()).collect())
    }

    /// The `rows × cols` zero matrix.
    pub fn zeros(rows: usize, cols: usize) -> Matrix {
        Matrix::from_fn(rows, cols, |_, _| Expr::zero())
    }

    /// The `n × n` identity.
    pub fn eye(n: usize) -> Matrix {
        Matrix::from_fn(n, n, |i, j| if i == j { Expr::one() } else { Expr::zero() })
    }

    /// Number of rows.
    pub fn nrows(&self) -> usize {
        self.rows
    }

    /// Number of columns.
    pub fn ncols(&self) -> usize {
        self.cols
    }

    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// The entries in column-major order.
    pub fn entries(&self) -> &[Expr] {
        &self.data
    }

    /// Entry `(i, j)`; `None` out of range.
    pub fn get(&self, i: usize, j: usize) -> Option<Expr> {
        (i < self.rows && j < self.cols).then(|| self.data[i + j * self.rows])
    }

    /// The sub-matrix of the given row and column ranges; `Err` out of range.
    pub fn slice(&self, rows: Range<usize>, cols: Range<usize>) -> Result<Matrix, SymxError> {
        if rows.end > self.rows
            || cols.end > self.cols
            || rows.start > rows.end
            || cols.start > cols.end
        {
            return Err(SymxError::Dimension {
                op: "slice",
                left: self.shape(),
                right: (rows.end, cols.end),
            });
        }
        Ok(Matrix::from_fn(rows.len(), cols.len(), |i, j| {
            self.data[rows.start + i + (cols.start + j) * self.rows]
        }))
    }

    /// Rows `range` of all columns (a segment of a vector).
    pub fn rows_range(&self, range: Range<usize>) -> Result<Matrix, SymxError> {
        self.slice(range, 0..self.cols)
    }

    /// Column `j`.
    pub fn column(&self, j: usize) -> Result<Matrix, SymxError> {
        self.slice(0..self.rows, j..j + 1)
    }

    /// Row `i`.
    pub fn row(&self, i: usize) -> Result<Matrix, SymxError> {
        self.slice(i..i + 1, 0..self.cols)
    }

    /// The transpose.
    pub fn t(&self) -> Matrix {
        Matrix::from_fn(self.cols, self.rows, |i, j| self.data[j + i * self.rows])
    }

    /// Stacks matrices vertically; `Err` if their column counts differ.
    pub fn vertcat(parts: &[&Matrix]) -> Result<Matrix, SymxError> {
        let cols = parts.first().map_or(1, |m| m.cols);
        let mut rows = 0;
        for m in parts {
            if m.cols != cols {
                return Err(SymxError::Dimension {
                    op: "vertcat",
                    left: (rows, cols),
                    right: m.shape(),
                });
            }
            rows += m.rows;
        }
        let mut data = Vec::with_capacity(rows * cols);
        for j in 0..cols {
            for m in parts {
                data.extend_from_slice(&m.data[j * m.rows..(j + 1) * m.rows]);
            }
        }
        Ok(Matrix { rows, cols, data })
    }

    /// Places matrices side by side; `Err` if their row counts differ.
    pub fn horzcat(parts: &[&Matrix]) -> Result<Matrix, SymxError> {
        let rows = parts.first().map_or(0, |m| m.rows);
        let mut data = Vec::new();
        let mut cols = 0;
        for m in parts {
            if m.rows != rows {
                return Err(SymxError::Dimension {
                    op: "horzcat",
                    left: (rows, cols),
                    right: m.shape(),
                });
            }
            data.extend_from_slice(&m.data);
            cols += m.cols;
        }
        Ok(Matrix { rows, cols, data })
    }

    /// Matrix product; `Err` if the inner dimensions differ.
    pub fn matmul(&self, other: &Matrix) -> Result<Matrix, SymxError> {
        if self.cols != other.rows {
            return Err(SymxError::Dimension {
                op: "matmul",
                left: self.shape(),
                right: other.shape(),
            });
        }
        Ok(Matrix::from_fn(self.rows, other.cols, |i, j| {
            (0..self.cols)
                .map(|k| self.data[i + k * self.rows] * other.data[k + j * other.rows])
                .sum()
        }))
    }

    fn same_shape(&self, other: &Matrix, op: &'static str) -> Result<(), SymxError> {
        if self.shape() == other.shape() {
            Ok(())
        } else {
            Err(SymxError::Dimension {
                op,
                left: self.shape(),
                right: other.shape(),
            })
        }
    }

    /// Inner product `Σ aᵢbᵢ` of two matrices of the same shape.
    pub fn dot(&self, other: &Matrix) -> Result<Expr, SymxError> {
        self.same_shape(other, "dot")?;
        Ok(self
            .data
            .iter()
            .zip(&other.data)
            .map(|(&a, &b)| a * b)
            .sum())
    }

    /// Cross product of two 3-vectors.
    pub fn cross(&self, other: &Matrix) -> Result<Matrix, SymxError> {
        if self.shape() != (3, 1) || other.shape() != (3, 1) {
            return Err(SymxError::Dimension {
                op: "cross",
                left: self.shape(),
                right: other.shape(),
            });
        }
        let (a, b) = (&self.data, &other.data);
        Ok(Matrix::from_vec(vec![
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]))
    }

    /// The skew-symmetric matrix `[v]×` of a 3-vector, with `[v]× w = v × w`.
    pub fn skew(&self) -> Result<Matrix, SymxError> {
        if self.shape() != (3, 1) {
            return Err(SymxError::Dimension {
                op: "skew",
                left: self.shape(),
                right: (3, 1),
            });
        }
        let v = &self.data;
        let z = Expr::zero();
        Matrix::from_column_major(3, 3, vec![z, v[2], -v[1], -v[2], z, v[0], v[1], -v[0], z])
    }

    /// Sum of all entries.
    pub fn sum(&self) -> Expr {
        self.data.iter().copied().sum()
    }

    /// Sum of squares of all entries (`‖·‖²` for vectors, squared Frobenius norm otherwise).
    pub fn sumsqr(&self) -> Expr {
        self.data.iter().map(|e| e.sq()).sum()
    }

    /// Euclidean (Frobenius) norm.
    pub fn norm_2(&self) -> Expr {
        self.sumsqr().sqrt()
    }

    /// Applies `f` to every entry.
    pub fn map(&self, mut f: impl FnMut(Expr) -> Expr) -> Matrix {
        Matrix {
            rows: self.rows,
            cols: self.cols,
            data: self.data.iter().map(|&e| f(e)).collect(),
        }
    }

    /// Combines two matrices of the same shape entry by entry.
    pub fn zip_map(
        &self,
        other: &Matrix,
        mut f: impl FnMut(Expr, Expr) -> Expr,
    ) -> Result<Matrix, SymxError> {
        self.same_shape(other, "zip_map")?;
        Ok(Matrix {
            rows: self.rows,
            cols: self.cols,
            data: self
                .data
                .iter()
                .zip(&other.data)
                .map(|(&a, &b)| f(a, b))
                .collect(),
        })
    }
}

impl Deref for Matrix {
    type Target = [Expr];
    fn deref(&self) -> &[Expr] {
        &self.data
    }
}

impl DerefMut for Matrix {
    fn deref_mut(&mut self) -> &mut [Expr] {
        &mut self.data
    }
}

impl Index<(usize, usize)> for Matrix {
    type Output = Expr;
    fn index(&self, (i, j): (usize, usize)) -> &Expr {
        assert!(
            i < self.rows && j < self.cols,
            "index ({i},{j}) out of range for {}x{} matrix",
            self.rows,
            self.cols
        );
        &self.data[i + j * self.rows]
    }
}

impl IndexMut<(usize, usize)> for Matrix {
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut Expr {
        assert!(
            i < self.rows && j < self.cols,
            "index ({i},{j}) out of range for {}x{} matrix",
            self.rows,
            self.cols
        );
        &mut self.data[i + j * self.rows]
    }
}

/// Linear (column-major) indexing: `v[i]` is entry `i` of a vector.
impl Index<usize> for Matrix {
    type Output = Expr;
    fn index(&self, i: usize) -> &Expr {
        &self.data[i]
    }
}

impl IndexMut<usize> for Matrix {
    fn index_mut(&mut self, i: usize) -> &mut Expr {
        &mut self.data[i]
    }
}

/// Ranges of entries (column-major): `v[1..3]` is a slice of a vector's entries.
macro_rules! range_index {
    ($($range:ty),*) => {$(
        impl Index<$range> for Matrix {
            type Output = [Expr];
            fn index(&self, r: $range) -> &[Expr] {
                &self.data[r]
            }
        }
    )*};
}
range_index!(
    Range<usize>,
    std::ops::RangeFrom<usize>,
    std::ops::RangeTo<usize>,
    std::ops::RangeInclusive<usize>,
    std::ops::RangeFull
);

impl From<Vec<Expr>> for Matrix {
    fn from(v: Vec<Expr>) -> Matrix {
        Matrix::from_vec(v)
    }
}

impl From<Expr> for Matrix {
    fn from(e: Expr) -> Matrix {
        Matrix::from_vec(vec![e])
    }
}

impl FromIterator<Expr> for Matrix {
    fn from_iter<I: IntoIterator<Item = Expr>>(iter: I) -> Matrix {
        Matrix::from_vec(iter.into_iter().collect())
    }
}

/// Elementwise `+` and `−` panic on a shape mismatch, as nalgebra's operators do; use
/// [`Matrix::zip_map`] for a checked version.
macro_rules! elementwise {
    ($($trait:ident $method:ident;)*) => {$(
        impl $trait<&Matrix> for &Matrix {
            type Output = Matrix;
            fn $method(self, rhs: &Matrix) -> Matrix {
                match self.zip_map(rhs, |a, b| a.$method(b)) {
                    Ok(m) => m,
                    Err(e) => panic!("{e}"),
                }
            }
        }
        impl $trait<Matrix> for Matrix {
            type Output = Matrix;
            fn $method(self, rhs: Matrix) -> Matrix {
                (&self).$method(&rhs)
            }
        }
        impl $trait<&Matrix> for Matrix {
            type Output = Matrix;
            fn $method(self, rhs: &Matrix) -> Matrix {
                (&self).$method(rhs)
            }
        }
        impl $trait<Matrix> for &Matrix {
            type Output = Matrix;
            fn $method(self, rhs: Matrix) -> Matrix {
                self.$method(&rhs)
            }
        }
    )*};
}
elementwise! { Add add; Sub sub; }

/// Matrix product; panics on an inner-dimension mismatch ([`Matrix::matmul`] is checked).
impl Mul<&Matrix> for &Matrix {
    type Output = Matrix;
    fn mul(self, rhs: &Matrix) -> Matrix {
        match self.matmul(rhs) {
            Ok(m) => m,
            Err(e) => panic!("{e}"),
        }
    }
}

impl Mul<Matrix> for Matrix {
    type Output = Matrix;
    fn mul(self, rhs: Matrix) -> Matrix {
        &self * &rhs
    }
}

impl<T: Into<Expr> + Copy> Mul<T> for &Matrix {
    type Output = Matrix;
    fn mul(self, s: T) -> Matrix {
        let s = s.into();
        self.map(|e| e * s)
    }
}

impl<T: Into<Expr> + Copy> Mul<T> for Matrix {
    type Output = Matrix;
    fn mul(self, s: T) -> Matrix {
        &self * s
    }
}

impl Mul<&Matrix> for Expr {
    type Output = Matrix;
    fn mul(self, m: &Matrix) -> Matrix {
        m.map(|e| self * e)
    }
}

impl Mul<&Matrix> for f64 {
    type Output = Matrix;
    fn mul(self, m: &Matrix) -> Matrix {
        m.map(|e| self * e)
    }
}

impl Mul<Matrix> for Expr {
    type Output = Matrix;
    fn mul(self, m: Matrix) -> Matrix {
        self * &m
    }
}

impl Mul<Matrix> for f64 {
    type Output = Matrix;
    fn mul(self, m: Matrix) -> Matrix {
        self * &m
    }
}

impl Neg for &Matrix {
    type Output = Matrix;
    fn neg(self) -> Matrix {
        self.map(|e| -e)
    }
}

impl Neg for Matrix {
    type Output = Matrix;
    fn neg(self) -> Matrix {
        -&self
    }
}

impl fmt::Display for Matrix {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("[")?;
        for i in 0..self.rows {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str("[")?;
            for j in 0..self.cols {
                if j > 0 {
                    f.write_str(", ")?;
                }
                write!(f, "{}", self.data[i + j * self.rows])?;
            }
            f.write_str("]")?;
        }
        f.write_str("]")
    }
}

impl fmt::Debug for Matrix {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Matrix{}x{}{}", self.rows, self.cols, self)
    }
}

/// A sparse matrix of expressions: a [`Sparsity`] pattern and one expression per stored entry,
/// in the pattern's column-major order. Returned by [`crate::jacobian`] and [`crate::hessian`].
#[derive(Clone)]
pub struct SparseMatrix {
    sparsity: Sparsity,
    values: Vec<Expr>,
}

impl SparseMatrix {
    /// Pairs a pattern with its entries; `Err` if the counts differ.
    pub fn new(sparsity: Sparsity, values: Vec<Expr>) -> Result<SparseMatrix, SymxError> {
        let nnz = sparsity.compute_nnz();
        if values.len() != nnz {
            return Err(SymxError::Length {
                what: "sparse matrix values",
                index: 0,
                expected: nnz,
                got: values.len(),
            });
        }
        Ok(SparseMatrix { sparsity, values })
    }

    /// The pattern.
    pub fn sparsity(&self) -> &Sparsity {
        &self.sparsity
    }

    /// The stored entries, column-major.
    pub fn values(&self) -> &[Expr] {
        &self.values
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.sparsity.nrows(), self.sparsity.ncols())
    }

    /// Entry `(i, j)` (the constant zero where nothing is stored).
    pub fn get(&self, i: usize, j: usize) -> Expr {
        if j >= self.sparsity.ncols() {
            return Expr::zero();
        }
        let range = self.sparsity.col_ptr()[j]..self.sparsity.col_ptr()[j + 1];
        match self.sparsity.row_idx()[range.clone()].binary_search(&i) {
            Ok(k) => self.values[range.start + k],
            Err(_) => Expr::zero(),
        }
    }

    /// The `(row, column, expression)` triplets in storage order.
    pub fn triplets(&self) -> Vec<(usize, usize, Expr)> {
        crate::sparsity::entries(&self.sparsity)
            .into_iter()
            .zip(&self.values)
            .map(|((i, j), &e)| (i, j, e))
            .collect()
    }

    /// The dense matrix with zeros filled in.
    pub fn to_dense(&self) -> Matrix {
        let (r, c) = self.shape();
        let mut m = Matrix::zeros(r, c);
        for (i, j, e) in self.triplets() {
            m[(i, j)] = e;
        }
        m
    }
}

impl fmt::Debug for SparseMatrix {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (r, c) = self.shape();
        write!(f, "SparseMatrix {r}x{c}, {} nonzeros: ", self.nnz())?;
        f.debug_list()
            .entries(
                self.triplets()
                    .iter()
                    .map(|(i, j, e)| format!("({i},{j}): {e}")),
            )
            .finish()
    }
}
