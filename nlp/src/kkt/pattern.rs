//! The matrix K itself: its upper-triangular pattern built from the Hessian's lower
//! triangle and the Jacobian, the maps from their entries into it, assembly of the
//! values, and products with K.

#![allow(clippy::needless_range_loop)]

use faer::sparse::SymbolicSparseColMat;

use super::{Kkt, KktError};

/// The upper triangle of K (original ordering) and where each input entry lands in it.
pub(super) struct UpperPattern {
    /// Column pointers and rows of the upper triangle of K, rows ascending, every
    /// diagonal entry present.
    pub pattern: SymbolicSparseColMat<usize>,
    /// Position in `pattern` of each entry of the Hessian's pattern (storage order).
    pub h_map: Vec<usize>,
    /// Position in `pattern` of each entry of the Jacobian's pattern (storage order).
    pub j_map: Vec<usize>,
    /// Position of each diagonal entry K_ii.
    pub diag_pos: Vec<usize>,
}

impl UpperPattern {
    /// Checks the shapes (n×n lower-triangular Hessian, m×n Jacobian) and builds the
    /// pattern and the maps.
    pub fn new(
        n: usize,
        m: usize,
        hess_lower: &SymbolicSparseColMat<usize>,
        jac: &SymbolicSparseColMat<usize>,
    ) -> Result<UpperPattern, KktError> {
        if hess_lower.nrows() != n || hess_lower.ncols() != n {
            return Err(KktError::Pattern(format!(
                "Hessian pattern is {}x{}, expected {n}x{n}",
                hess_lower.nrows(),
                hess_lower.ncols()
            )));
        }
        if jac.nrows() != m || jac.ncols() != n {
            return Err(KktError::Pattern(format!(
                "Jacobian pattern is {}x{}, expected {m}x{n}",
                jac.nrows(),
                jac.ncols()
            )));
        }
        let dim = n + m;
        // Rows of each column of the upper triangle of K.
        let mut cols: Vec<Vec<usize>> = (0..dim).map(|j| vec![j]).collect();
        for c in 0..n {
            for &r in hess_lower.row_idx_of_col_raw(c) {
                if r < c {
                    return Err(KktError::Pattern(format!(
                        "Hessian pattern entry ({r}, {c}) is above the diagonal; give the lower triangle"
                    )));
                }
                cols[r].push(c);
            }
        }
        for c in 0..n {
            for &r in jac.row_idx_of_col_raw(c) {
                cols[n + r].push(c);
            }
        }
        let mut col_ptr = Vec::with_capacity(dim + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0usize);
        for col in cols.iter_mut() {
            col.sort_unstable();
            col.dedup();
            row_idx.extend_from_slice(col);
            col_ptr.push(row_idx.len());
        }
        let pattern = SymbolicSparseColMat::new_checked(dim, dim, col_ptr, None, row_idx);
        let find = |row: usize, col: usize| -> usize {
            let start = pattern.col_ptr()[col];
            let rows = &pattern.row_idx()[start..pattern.col_ptr()[col + 1]];
            // The entry exists by construction.
            start + rows.binary_search(&row).unwrap_or(0)
        };
        let mut h_map = vec![usize::MAX; hess_lower.row_idx().len()];
        for c in 0..n {
            for p in hess_lower.col_range(c) {
                let r = hess_lower.row_idx()[p];
                h_map[p] = find(c, r);
            }
        }
        let mut j_map = vec![usize::MAX; jac.row_idx().len()];
        for c in 0..n {
            for p in jac.col_range(c) {
                let r = jac.row_idx()[p];
                j_map[p] = find(c, n + r);
            }
        }
        let diag_pos: Vec<usize> = (0..dim).map(|j| find(j, j)).collect();
        Ok(UpperPattern {
            pattern,
            h_map,
            j_map,
            diag_pos,
        })
    }
}

impl Kkt {
    /// Checks the lengths and scatters the values into K (in `pattern`'s space):
    /// `h_vals`/`j_vals` in the storage order of the patterns given to [`Kkt::new`],
    /// `dx` (length n) added to the first diagonal, `dc` (length m) subtracted from the
    /// second.
    pub(super) fn assemble(
        &mut self,
        h_vals: &[f64],
        dx: &[f64],
        j_vals: &[f64],
        dc: &[f64],
    ) -> Result<(), KktError> {
        let check = |what, expected: usize, got: usize| {
            if expected != got {
                Err(KktError::Length {
                    what,
                    expected,
                    got,
                })
            } else {
                Ok(())
            }
        };
        check("h_vals", self.h_map.len(), h_vals.len())?;
        check("j_vals", self.j_map.len(), j_vals.len())?;
        check("dx", self.n, dx.len())?;
        check("dc", self.m, dc.len())?;
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for (&p, &v) in self.h_map.iter().zip(h_vals) {
            self.values[p] += v;
        }
        for (&p, &v) in self.j_map.iter().zip(j_vals) {
            self.values[p] += v;
        }
        for (i, &d) in dx.iter().enumerate() {
            self.values[self.diag_pos[i]] += d;
        }
        for (i, &d) in dc.iter().enumerate() {
            self.values[self.diag_pos[self.n + i]] -= d;
        }
        if self.values.iter().any(|v| !v.is_finite()) {
            return Err(KktError::NonFinite);
        }
        Ok(())
    }

    /// y = (K + diag(shift)) x using the assembled upper triangle, in `pattern`'s space
    /// (permuted when simplicial).
    pub(super) fn matvec(&self, x: &[f64], shift: Option<&[f64]>, y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        let cp = self.pattern.col_ptr();
        let ri = self.pattern.row_idx();
        for j in 0..self.dim() {
            let xj = x[j];
            let mut acc = 0.0;
            for p in cp[j]..cp[j + 1] {
                let i = ri[p];
                let v = self.values[p];
                acc += v * x[i];
                if i != j {
                    y[i] += v * xj;
                }
            }
            y[j] += acc;
        }
        if let Some(s) = shift {
            for ((yi, si), xi) in y.iter_mut().zip(s).zip(x) {
                *yi += si * xi;
            }
        }
    }

    /// y = (K + diag(shift)) x in the original (unpermuted) ordering, K the matrix of the
    /// last [`Kkt::factorize`].
    pub fn multiply(
        &self,
        x: &[f64],
        shift: Option<&[f64]>,
        y: &mut [f64],
    ) -> Result<(), KktError> {
        let dim = self.dim();
        for (what, len) in [("x", x.len()), ("y", y.len())] {
            if len != dim {
                return Err(KktError::Length {
                    what,
                    expected: dim,
                    got: len,
                });
            }
        }
        match &self.simplicial {
            Some(simp) => {
                let px: Vec<f64> = simp.fwd.iter().map(|&o| x[o]).collect();
                let mut py = vec![0.0; dim];
                self.matvec(&px, None, &mut py);
                for (&v, &o) in py.iter().zip(&simp.fwd) {
                    y[o] = v;
                }
            }
            None => self.matvec(x, None, y),
        }
        if let Some(s) = shift {
            for ((yi, si), xi) in y.iter_mut().zip(s).zip(x) {
                *yi += si * xi;
            }
        }
        Ok(())
    }
}
