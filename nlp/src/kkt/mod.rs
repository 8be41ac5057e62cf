//! Assembly, factorisation (LDLᵀ without pivoting: faer's supernodal one, or our own
//! simplicial one on faer's symbolic analysis), inertia and solution of the symmetric
//! quasi-definite KKT system
//!
//! ```text
//! K = [ W + diag(dx)   Jᵀ         ]
//!     [ J             −diag(dc)   ]
//! ```
//!
//! The pattern, the AMD ordering and the symbolic factorisation are computed once in
//! [`Kkt::new`]; every [`Kkt::factorize`] only scatters values through precomputed maps.
//! When faer's analysis picks the simplicial factorisation, K is stored already permuted
//! and factorised by `Simplicial` (up-looking LDLᵀ with the rows of L precomputed).
//! faer has no inertia API, so the inertia is counted from the signs of D (Sylvester's law
//! of inertia). Unpivoted LDLᵀ needs `dc > 0` on every row (see docs/dependencies.md).
//!
//! The parts:
//! - `pattern`: the upper triangle of K, the maps from the Hessian's and the Jacobian's
//!   entries into it, assembly of the values and products with K;
//! - `factor`: the numeric factorisation, the inertia and ln |det K|;
//! - `simplicial`: our own up-looking LDLᵀ of the permuted K;
//! - `refine`: solves with residual-checked iterative refinement (`solve_shifted`);
//! - `error`: [`KktError`];
//! - `low_rank`: K plus a low-rank term (Sherman–Morrison–Woodbury), for L-BFGS.

use faer::dyn_stack::{MemBuffer, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltParams;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::SymbolicSparseColMat;
use faer::{Par, Side, Spec};

mod error;
mod factor;
mod low_rank;
mod pattern;
mod refine;
mod simplicial;
#[cfg(test)]
mod tests;

pub use error::KktError;
pub(crate) use low_rank::{LowRankKkt, LowRankTerm};

use pattern::UpperPattern;
use simplicial::Simplicial;

/// Numbers of positive, negative and zero eigenvalues.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Inertia {
    /// Positive eigenvalues.
    pub positive: usize,
    /// Negative eigenvalues.
    pub negative: usize,
    /// Zero eigenvalues.
    pub zero: usize,
}

/// Which faer numeric factorisation the symbolic analysis selects (the solvers use
/// `Auto`; the forced kinds are compared in the unit tests).
#[cfg_attr(not(test), allow(dead_code))]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KktFactorization {
    /// Supernodal (dense blocks; fastest when the factor has large dense parts).
    Supernodal,
    /// Simplicial (column by column; our own up-looking LDLᵀ on faer's analysis).
    Simplicial,
    /// Let faer decide from the flop ratio (the default). Measured on the gap-crossing
    /// crawl gait (n + m = 2678, 33 k factor entries) it picks simplicial, 2.5× faster
    /// than forced supernodal; on a 35 000-row KKT it picks supernodal, 30× faster than
    /// forced simplicial.
    #[default]
    Auto,
}

/// Reusable KKT system: pattern, symbolic factorisation, numeric factor and work space.
pub struct Kkt {
    n: usize,
    m: usize,
    pattern: SymbolicSparseColMat<usize>,
    values: Vec<f64>,
    h_map: Vec<usize>,
    j_map: Vec<usize>,
    diag_pos: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    /// Our own simplicial LDLᵀ (used when faer's analysis picks simplicial); `None` for
    /// supernodal, which stays with faer.
    simplicial: Option<Simplicial>,
    mem: MemBuffer,
    factored: bool,
    wx: Vec<f64>,
    wr: Vec<f64>,
    wd: Vec<f64>,
    wb: Vec<f64>,
    /// Minimum number of iterative-refinement steps (default 1).
    pub min_refinement_steps: usize,
    /// Maximum number of iterative-refinement steps (default 10).
    pub max_refinement_steps: usize,
    /// Target relative residual (default 1e-12).
    pub residual_ratio_max: f64,
    last_residual_ratio: f64,
}

impl std::fmt::Debug for Kkt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Kkt")
            .field("n", &self.n)
            .field("m", &self.m)
            .field("nnz", &self.values.len())
            .field("len_l", &self.l_values.len())
            .finish()
    }
}

impl Kkt {
    /// Builds the KKT pattern from the lower-triangular Hessian pattern (n×n) and the
    /// Jacobian pattern (m×n) and performs the symbolic analysis (AMD ordering;
    /// simplicial or supernodal as faer's flop-ratio heuristic chooses, see
    /// [`KktFactorization::Auto`]).
    pub fn new(
        n: usize,
        m: usize,
        hess_lower: &SymbolicSparseColMat<usize>,
        jac: &SymbolicSparseColMat<usize>,
    ) -> Result<Kkt, KktError> {
        Self::with_factorization(n, m, hess_lower, jac, KktFactorization::Auto)
    }

    /// As [`Kkt::new`] with a chosen factorisation kind.
    pub fn with_factorization(
        n: usize,
        m: usize,
        hess_lower: &SymbolicSparseColMat<usize>,
        jac: &SymbolicSparseColMat<usize>,
        kind: KktFactorization,
    ) -> Result<Kkt, KktError> {
        let UpperPattern {
            pattern,
            h_map,
            j_map,
            diag_pos,
        } = UpperPattern::new(n, m, hess_lower, jac)?;
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: match kind {
                    KktFactorization::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
                    KktFactorization::Simplicial => SupernodalThreshold::FORCE_SIMPLICIAL,
                    KktFactorization::Auto => SupernodalThreshold::AUTO,
                },
                ..Default::default()
            },
        )
        .map_err(|e| KktError::Symbolic(format!("{e:?}")))?;
        let l_values = vec![0.0; symbolic.len_val()];
        // Simplicial: store K already permuted by the AMD ordering (upper triangle, as
        // the up-looking factorisation reads it) and factorise it ourselves with the row
        // patterns of L precomputed, so that no factorisation permutes K or walks the
        // elimination tree again (faer's `permute_self_adjoint_to_unsorted` and `ereach`
        // took 35 % of the factorisation time on the gap-crossing crawl gait).
        let (pattern, h_map, j_map, diag_pos, simplicial) =
            match Simplicial::new(&symbolic, &pattern) {
                Some((simp, ppat, pos)) => (
                    ppat,
                    h_map.iter().map(|&p| pos[p]).collect(),
                    j_map.iter().map(|&p| pos[p]).collect(),
                    diag_pos.iter().map(|&p| pos[p]).collect(),
                    Some(simp),
                ),
                None => (pattern, h_map, j_map, diag_pos, None),
            };
        let mem = MemBuffer::new(StackReq::any_of(&[
            symbolic.factorize_numeric_ldlt_scratch::<f64>(
                Par::Seq,
                Spec::<LdltParams, f64>::default(),
            ),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]));
        let nnz = pattern.row_idx().len();
        let dim = n + m;
        Ok(Kkt {
            n,
            m,
            pattern,
            values: vec![0.0; nnz],
            h_map,
            j_map,
            diag_pos,
            symbolic,
            l_values,
            simplicial,
            mem,
            factored: false,
            wx: vec![0.0; dim],
            wr: vec![0.0; dim],
            wd: vec![0.0; dim],
            wb: vec![0.0; dim],
            min_refinement_steps: 1,
            max_refinement_steps: 10,
            residual_ratio_max: 1e-12,
            last_residual_ratio: 0.0,
        })
    }

    /// Number of primal rows `n`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of constraint rows `m`.
    pub fn m(&self) -> usize {
        self.m
    }

    /// Dimension n + m.
    pub fn dim(&self) -> usize {
        self.n + self.m
    }

    /// Forgets the numeric factor (keeps the pattern, the symbolic analysis and the work
    /// space): the state of a new [`Kkt`], for reuse on a problem of the same structure.
    pub(crate) fn reset(&mut self) {
        self.factored = false;
        self.last_residual_ratio = 0.0;
    }

    /// True if faer chose the supernodal factorisation.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn is_supernodal(&self) -> bool {
        matches!(self.symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_))
    }
}
