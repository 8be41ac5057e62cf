//! Helpers shared by the crate's unit tests (`kkt/tests.rs`, `lbfgs/tests.rs`).

use faer::sparse::SymbolicSparseColMat;

/// Tiny deterministic generator (xorshift) so the tests need no extra dependency.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    /// Uniform in [0, 1).
    pub(crate) fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [−1, 1).
    pub(crate) fn sym(&mut self) -> f64 {
        2.0 * self.next() - 1.0
    }

    /// `n` values uniform in [−1, 1).
    pub(crate) fn vec(&mut self, n: usize) -> Vec<f64> {
        (0..n).map(|_| self.sym()).collect()
    }
}

/// CSC pattern from (row, col) entries (duplicates merged).
pub(crate) fn pattern(
    nrows: usize,
    ncols: usize,
    entries: &[(usize, usize)],
) -> SymbolicSparseColMat<usize> {
    let mut cols: Vec<Vec<usize>> = vec![Vec::new(); ncols];
    for &(r, c) in entries {
        cols[c].push(r);
    }
    let mut cp = vec![0];
    let mut ri = Vec::new();
    for mut c in cols {
        c.sort_unstable();
        c.dedup();
        ri.extend(c);
        cp.push(ri.len());
    }
    SymbolicSparseColMat::new_checked(nrows, ncols, cp, None, ri)
}
