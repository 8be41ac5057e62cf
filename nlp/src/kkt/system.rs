//! [`Kkt`]: the reusable KKT system (pattern, symbolic analysis, numeric factor and
//! work space) and how it is built; its operations are in `assembly`, `factor` and
//! `refine`.

use faer::dyn_stack::{MemBuffer, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltParams;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::SymbolicSparseColMat;
use faer::{Par, Side, Spec};

use super::error::KktError;
use super::pattern::UpperPattern;
use super::simplicial::Simplicial;

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
    pub(super) n: usize,
    pub(super) m: usize,
    pub(super) pattern: SymbolicSparseColMat<usize>,
    pub(super) values: Vec<f64>,
    pub(super) h_map: Vec<usize>,
    pub(super) j_map: Vec<usize>,
    pub(super) diag_pos: Vec<usize>,
    pub(super) symbolic: SymbolicCholesky<usize>,
    pub(super) l_values: Vec<f64>,
    /// Our own simplicial LDLᵀ (used when faer's analysis picks simplicial); `None` for
    /// supernodal, which stays with faer.
    pub(super) simplicial: Option<Simplicial>,
    pub(super) mem: MemBuffer,
    pub(super) factored: bool,
    pub(super) wx: Vec<f64>,
    pub(super) wr: Vec<f64>,
    pub(super) wd: Vec<f64>,
    pub(super) wb: Vec<f64>,
    /// Minimum number of iterative-refinement steps (default 1).
    pub min_refinement_steps: usize,
    /// Maximum number of iterative-refinement steps (default 10).
    pub max_refinement_steps: usize,
    /// Target relative residual (default 1e-12).
    pub residual_ratio_max: f64,
    /// Refinement goes on past `residual_ratio_max` while a step at least halves the
    /// ratio, until the ratio is at most this (default 1e-14, round-off; a value of at
    /// least `residual_ratio_max` stops at the target, as IPOPT does).
    pub residual_ratio_floor: f64,
    pub(super) last_residual_ratio: f64,
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
            residual_ratio_floor: super::refine::REFINEMENT_FLOOR,
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
