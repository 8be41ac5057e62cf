//! Our own simplicial LDLᵀ of the AMD-permuted K, used when faer's analysis picks the
//! simplicial factorisation.

#![allow(clippy::needless_range_loop)]

use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::SymbolicSparseColMat;

use super::error::KktError;
use super::inertia::Inertia;

/// Simplicial LDLᵀ of the AMD-permuted K (up-looking, Davis's LDL), on the pattern of L
/// from faer's symbolic analysis. The rows of L (for each k, the columns j < k with
/// L_kj ≠ 0 and the positions of those entries) are precomputed once, so a numeric
/// factorisation does the arithmetic only. Ascending column order is a topological order
/// of the elimination tree (parents have larger indices), as the algorithm needs.
pub(super) struct Simplicial {
    /// Permutation: permuted index k is original index `fwd[k]`.
    pub fwd: Vec<usize>,
    /// Column pointers and row indices of L (diagonal first in each column, rows
    /// ascending); the diagonal slot holds D.
    l_col_ptr: Vec<usize>,
    l_row_idx: Vec<usize>,
    /// Rows of L below the diagonal: for row k, `row_col[row_ptr[k]..row_ptr[k+1]]` are
    /// the columns j (ascending) and `row_pos[..]` the positions of L_kj in the values.
    row_ptr: Vec<usize>,
    row_col: Vec<usize>,
    row_pos: Vec<usize>,
    /// 1 / D.
    d_inv: Vec<f64>,
    /// Dense accumulator of the current row (all zero between rows).
    x: Vec<f64>,
    /// The permuted shift of `solve_shifted`.
    pub pshift: Vec<f64>,
}

/// The permuted upper triangle of `pattern` under the inverse permutation `inv`, and
/// the position in it of each entry of `pattern`. Original entry (r, c), r ≤ c, goes
/// to (min, max) of (inv[r], inv[c]).
fn permuted_upper(
    pattern: &SymbolicSparseColMat<usize>,
    inv: &[usize],
) -> (SymbolicSparseColMat<usize>, Vec<usize>) {
    let dim = pattern.ncols();
    let cp = pattern.col_ptr();
    let ri = pattern.row_idx();
    let nnz = ri.len();
    let mut count = vec![0usize; dim + 1];
    let mut target = Vec::with_capacity(nnz);
    for c in 0..dim {
        for &r in &ri[cp[c]..cp[c + 1]] {
            let (a, b) = (inv[r], inv[c]);
            let (row, col) = if a <= b { (a, b) } else { (b, a) };
            target.push((row, col));
            count[col + 1] += 1;
        }
    }
    for j in 0..dim {
        count[j + 1] += count[j];
    }
    let col_ptr = count.clone();
    let mut next = count;
    let mut row_idx = vec![0usize; nnz];
    let mut pos = vec![0usize; nnz];
    // Fill column by column; then sort each column's rows, carrying `pos` along.
    for (p, &(row, col)) in target.iter().enumerate() {
        let q = next[col];
        next[col] += 1;
        row_idx[q] = row;
        pos[p] = q;
    }
    let mut order: Vec<usize> = Vec::new();
    let mut where_new = vec![0usize; nnz];
    let mut sorted_rows = vec![0usize; nnz];
    for j in 0..dim {
        let (a, b) = (col_ptr[j], col_ptr[j + 1]);
        order.clear();
        order.extend(a..b);
        order.sort_unstable_by_key(|&q| row_idx[q]);
        for (t, &q) in order.iter().enumerate() {
            where_new[q] = a + t;
            sorted_rows[a + t] = row_idx[q];
        }
    }
    for p in pos.iter_mut() {
        *p = where_new[*p];
    }
    let ppat = SymbolicSparseColMat::new_checked(dim, dim, col_ptr, None, sorted_rows);
    (ppat, pos)
}

/// The rows of L (`row_ptr`, the column and the position in L of each entry below the
/// diagonal), from L's column pattern; `None` if a column does not start at its
/// diagonal or has an entry above it.
fn rows_of_l(
    l_col_ptr: &[usize],
    l_row_idx: &[usize],
) -> Option<(Vec<usize>, Vec<usize>, Vec<usize>)> {
    let dim = l_col_ptr.len() - 1;
    let mut row_ptr = vec![0usize; dim + 1];
    for j in 0..dim {
        if l_row_idx[l_col_ptr[j]] != j {
            return None;
        }
        for &r in &l_row_idx[l_col_ptr[j] + 1..l_col_ptr[j + 1]] {
            if r <= j {
                return None;
            }
            row_ptr[r + 1] += 1;
        }
    }
    for k in 0..dim {
        row_ptr[k + 1] += row_ptr[k];
    }
    let mut fill = row_ptr.clone();
    let mut row_col = vec![0usize; row_ptr[dim]];
    let mut row_pos = vec![0usize; row_ptr[dim]];
    for j in 0..dim {
        for p in l_col_ptr[j] + 1..l_col_ptr[j + 1] {
            let r = l_row_idx[p];
            row_col[fill[r]] = j;
            row_pos[fill[r]] = p;
            fill[r] += 1;
        }
    }
    Some((row_ptr, row_col, row_pos))
}

impl Simplicial {
    /// Builds the permuted upper pattern of K and the map from positions in `pattern`
    /// (the original upper triangle) to positions in the permuted one. `None` if faer's
    /// analysis is supernodal (or, defensively, if the permuted K does not fit L's
    /// pattern).
    pub(super) fn new(
        symbolic: &SymbolicCholesky<usize>,
        pattern: &SymbolicSparseColMat<usize>,
    ) -> Option<(Simplicial, SymbolicSparseColMat<usize>, Vec<usize>)> {
        let SymbolicCholeskyRaw::Simplicial(s) = symbolic.raw() else {
            return None;
        };
        let dim = pattern.ncols();
        let (fwd, inv): (Vec<usize>, Vec<usize>) = match symbolic.perm() {
            Some(p) => {
                let (f, i) = p.arrays();
                (f.to_vec(), i.to_vec())
            }
            None => ((0..dim).collect(), (0..dim).collect()),
        };
        let (ppat, pos) = permuted_upper(pattern, &inv);
        let l_col_ptr = s.col_ptr().to_vec();
        let l_row_idx = s.row_idx().to_vec();
        if l_col_ptr.len() != dim + 1
            || l_col_ptr[dim] != l_row_idx.len()
            || l_row_idx.iter().any(|&r| r >= dim)
        {
            return None;
        }
        let (row_ptr, row_col, row_pos) = rows_of_l(&l_col_ptr, &l_row_idx)?;
        let simp = Simplicial {
            fwd,
            l_col_ptr,
            l_row_idx,
            row_ptr,
            row_col,
            row_pos,
            d_inv: vec![0.0; dim],
            x: vec![0.0; dim],
            pshift: vec![0.0; dim],
        };
        if !simp.covers(&ppat) {
            return None;
        }
        Some((simp, ppat, pos))
    }

    /// Whether every off-diagonal entry (i, k), i < k, of the permuted K `ppat` is an
    /// entry L_ki of the factor.
    fn covers(&self, ppat: &SymbolicSparseColMat<usize>) -> bool {
        let dim = self.fwd.len();
        for k in 0..dim {
            let cols = &self.row_col[self.row_ptr[k]..self.row_ptr[k + 1]];
            for &i in ppat.row_idx_of_col_raw(k) {
                if i < k && cols.binary_search(&i).is_err() {
                    return false;
                }
            }
        }
        true
    }

    /// Numeric LDLᵀ of the permuted upper triangle (`col_ptr`, `row_idx`, `values`) into
    /// `l` (the L pattern's values, D on the diagonal slots). Returns the inertia;
    /// `ZeroPivot` (permuted index) on an exactly zero pivot, `NonFinite` on a
    /// non-finite one.
    pub(super) fn factorize(
        &mut self,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
        l: &mut [f64],
    ) -> Result<Inertia, KktError> {
        let dim = self.d_inv.len();
        let x = &mut self.x[..dim];
        let lcp = &self.l_col_ptr;
        let lri = &self.l_row_idx;
        let mut inertia = Inertia::default();
        for k in 0..dim {
            for p in col_ptr[k]..col_ptr[k + 1] {
                x[row_idx[p]] += values[p];
            }
            let mut d = x[k];
            x[k] = 0.0;
            let (a, b) = (self.row_ptr[k], self.row_ptr[k + 1]);
            for (&j, &pos) in self.row_col[a..b].iter().zip(&self.row_pos[a..b]) {
                let xj = x[j];
                x[j] = 0.0;
                let start = lcp[j] + 1;
                for (&i, &lij) in lri[start..pos].iter().zip(&l[start..pos]) {
                    // SAFETY: every row index of L is below `dim` = x.len() (checked
                    // in `Simplicial::new`, the only place L's pattern is set).
                    unsafe { *x.get_unchecked_mut(i) -= lij * xj };
                }
                let lkj = xj * self.d_inv[j];
                d -= lkj * xj;
                l[pos] = lkj;
            }
            if d == 0.0 || !d.is_finite() {
                // Leave the accumulator clean for the next factorisation.
                x.fill(0.0);
                return Err(if d == 0.0 {
                    KktError::ZeroPivot(k)
                } else {
                    KktError::NonFinite
                });
            }
            l[lcp[k]] = d;
            self.d_inv[k] = 1.0 / d;
            if d > 0.0 {
                inertia.positive += 1;
            } else {
                inertia.negative += 1;
            }
        }
        Ok(inertia)
    }

    /// x ← (L D Lᵀ)⁻¹ x in the permuted space.
    pub(super) fn solve_in_place(&self, l: &[f64], x: &mut [f64]) {
        let dim = self.d_inv.len();
        let x = &mut x[..dim];
        let lcp = &self.l_col_ptr;
        let lri = &self.l_row_idx;
        for j in 0..dim {
            let xj = x[j];
            if xj != 0.0 {
                let (a, b) = (lcp[j] + 1, lcp[j + 1]);
                for (&i, &lij) in lri[a..b].iter().zip(&l[a..b]) {
                    // SAFETY: every row index of L is below `dim` = x.len() (checked
                    // in `Simplicial::new`, the only place L's pattern is set).
                    unsafe { *x.get_unchecked_mut(i) -= lij * xj };
                }
            }
        }
        for (xj, dj) in x.iter_mut().zip(&self.d_inv) {
            *xj *= dj;
        }
        for j in (0..dim).rev() {
            let (a, b) = (lcp[j] + 1, lcp[j + 1]);
            let mut acc = x[j];
            for (&i, &lij) in lri[a..b].iter().zip(&l[a..b]) {
                // SAFETY: as above, i < dim = x.len().
                acc -= lij * unsafe { *x.get_unchecked(i) };
            }
            x[j] = acc;
        }
    }
}
