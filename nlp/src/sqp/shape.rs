//! The sizes and sparsity patterns of the problem an SQP solve works on ([`Shape`]).

use faer::sparse::SymbolicSparseColMat;

/// Sizes and sparsity patterns of the problem, fixed for the solve.
pub(super) struct Shape {
    pub n: usize,
    pub m: usize,
    /// Length of the stacked cone vector.
    pub n_cone: usize,
    pub jp: SymbolicSparseColMat<usize>,
    pub hp: SymbolicSparseColMat<usize>,
    /// Pattern of the cone Jacobian (rows: stacked cone entries).
    pub cp: Option<SymbolicSparseColMat<usize>>,
    /// (offset, dimension) of each cone in the stacked cone vector.
    pub block: Vec<(usize, usize)>,
    /// Dense damped BFGS instead of the exact Hessian.
    pub dense: bool,
}
