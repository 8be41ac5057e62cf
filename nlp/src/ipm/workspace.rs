//! What an [`Ipm`](crate::Ipm) keeps between solves, as IPOPT's application object does:
//! the validated bounds, the reduced problem's patterns and vectors, and the core's
//! buffers with the KKT system (its pattern, AMD ordering and symbolic factorisation)
//! for the reduced structure they were built for. With them a warm re-solve of a problem
//! with the same structure allocates nothing (`tests/ipm_warm_alloc.rs`).
//!
//! The [`Solver`](crate::Solver) trait takes `&self` (drivers hold a `Box<dyn Solver>`
//! and may share it between threads), so the buffers sit behind a mutex: a solve takes
//! them and puts them back at the end. A solve that finds them taken (another thread is
//! solving with the same solver) starts from empty ones, and the core's buffers are used
//! only for the structure they were built for, so results never depend on what was
//! kept: every vector is refilled and the numeric state reset, and the iterates are
//! bit-identical to a fresh solver's.

use std::sync::Mutex;

use faer::sparse::SymbolicSparseColMat;

use crate::frontend::user_solution::FinalScratch;
use crate::frontend::validate::Validated;
use crate::ipm::core::Buffers;
use crate::ipm::reduced::{same_pattern, ReducedParts};

/// The structure a core's buffers were built for: the reduced problem's sizes and its
/// Hessian (lower triangle) and Jacobian patterns.
pub(crate) struct Structure {
    n: usize,
    m: usize,
    hess: SymbolicSparseColMat<usize>,
    jac: SymbolicSparseColMat<usize>,
}

impl Structure {
    /// The structure of these sizes and patterns (copied).
    pub(crate) fn new(
        n: usize,
        m: usize,
        hess: &SymbolicSparseColMat<usize>,
        jac: &SymbolicSparseColMat<usize>,
    ) -> Structure {
        Structure {
            n,
            m,
            hess: hess.clone(),
            jac: jac.clone(),
        }
    }

    /// True if the sizes and patterns are these.
    pub(crate) fn is(
        &self,
        n: usize,
        m: usize,
        hess: &SymbolicSparseColMat<usize>,
        jac: &SymbolicSparseColMat<usize>,
    ) -> bool {
        self.n == n && self.m == m && same_pattern(&self.hess, hess) && same_pattern(&self.jac, jac)
    }
}

/// Everything one solve works in (see the module doc).
#[derive(Default)]
pub(crate) struct SolveBuffers {
    pub(crate) validated: Validated,
    pub(crate) reduced: ReducedParts,
    /// The core's buffers and the structure they were built for.
    pub(crate) core: Option<(Structure, Buffers)>,
    /// The warm start's multipliers y, z_L, z_U in the reduced problem.
    pub(crate) warm: [Vec<f64>; 3],
    pub(crate) last: FinalScratch,
}

/// The kept buffers of one solver (empty when cloned).
#[derive(Default)]
pub(crate) struct Workspace(Mutex<Option<Box<SolveBuffers>>>);

impl Workspace {
    /// The kept buffers, taken out until [`Workspace::keep`] (empty ones if another
    /// solve has them, or on the first solve).
    pub(crate) fn take(&self) -> Box<SolveBuffers> {
        self.0
            .try_lock()
            .ok()
            .and_then(|mut g| g.take())
            .unwrap_or_default()
    }

    /// Keeps `buffers` for the next solve (a concurrent solve's are dropped).
    pub(crate) fn keep(&self, buffers: Box<SolveBuffers>) {
        if let Ok(mut guard) = self.0.try_lock() {
            *guard = Some(buffers);
        }
    }
}

impl Clone for Workspace {
    /// A clone starts with nothing kept.
    fn clone(&self) -> Self {
        Workspace::default()
    }
}

impl std::fmt::Debug for Workspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Workspace")
    }
}
