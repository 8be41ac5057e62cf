//! The pattern of K: its upper triangle built from the Hessian's lower triangle and the
//! Jacobian, and the maps from their entries into it.

#![allow(clippy::needless_range_loop)]

use faer::sparse::SymbolicSparseColMat;

use super::error::KktError;

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
