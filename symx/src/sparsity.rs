//! Sparsity patterns: faer's compressed-sparse-column pattern is the one sparse type.
//!
//! Patterns of derivatives are found structurally, never by evaluating dense matrices:
//! * [`crate::jacobian`] and [`crate::hessian`] build one derivative expression per
//!   structural nonzero, so their pattern is exact (up to cancellations the local
//!   simplifier cannot see, which only make it larger, never smaller);
//! * [`crate::Function::dependency_sparsity`] propagates 64-column bit masks along a compiled
//!   tape: output `i` depends on input `j` if any path of non-constant operations joins them.
//!
//! Derivative evaluation costs in proportion to the nonzeros because each nonzero is its own
//! expression in one compiled tape, with the work they share computed once (hash-consing
//! makes common subexpressions a single node). This is the symbolic alternative to
//! colouring: no compression, no recovery step, exact values.
use faer::sparse::SymbolicSparseColMat;

/// A compressed-sparse-column pattern (faer's type; row indices sorted within columns).
pub type Sparsity = SymbolicSparseColMat<usize>;

/// A pattern from `(row, column)` entries in any order; duplicates are merged.
///
/// Panics if an entry lies outside `nrows × ncols` (a caller's broken invariant).
pub fn pattern_from_entries(
    nrows: usize,
    ncols: usize,
    entries: impl IntoIterator<Item = (usize, usize)>,
) -> Sparsity {
    let mut e: Vec<(usize, usize)> = entries.into_iter().map(|(i, j)| (j, i)).collect();
    e.sort_unstable();
    e.dedup();
    let mut col_ptr = vec![0usize; ncols + 1];
    let mut row_idx = Vec::with_capacity(e.len());
    for &(j, i) in &e {
        assert!(
            i < nrows && j < ncols,
            "entry ({i},{j}) outside {nrows}x{ncols}"
        );
        col_ptr[j + 1] += 1;
        row_idx.push(i);
    }
    for j in 0..ncols {
        col_ptr[j + 1] += col_ptr[j];
    }
    SymbolicSparseColMat::new_checked(nrows, ncols, col_ptr, None, row_idx)
}

/// The `(row, column)` entries of a pattern in storage (column-major) order.
pub fn entries(p: &Sparsity) -> Vec<(usize, usize)> {
    let mut out = Vec::with_capacity(p.compute_nnz());
    for j in 0..p.ncols() {
        for k in p.col_ptr()[j]..p.col_ptr()[j + 1] {
            out.push((p.row_idx()[k], j));
        }
    }
    out
}

/// Whether the pattern holds entry `(i, j)`.
pub fn contains(p: &Sparsity, i: usize, j: usize) -> bool {
    j < p.ncols()
        && p.row_idx()[p.col_ptr()[j]..p.col_ptr()[j + 1]]
            .binary_search(&i)
            .is_ok()
}

/// The entries of `p` with `row ≥ column`.
pub fn lower_triangle(p: &Sparsity) -> Sparsity {
    pattern_from_entries(
        p.nrows(),
        p.ncols(),
        entries(p).into_iter().filter(|&(i, j)| i >= j),
    )
}

/// The largest distance `|i − j|` of any entry (0 for diagonal or empty patterns).
pub fn bandwidth(p: &Sparsity) -> usize {
    entries(p)
        .into_iter()
        .map(|(i, j)| i.abs_diff(j))
        .max()
        .unwrap_or(0)
}
