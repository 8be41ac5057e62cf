//! What an [`Ipm`](crate::Ipm) keeps between solves of problems with the same structure,
//! as IPOPT's application object does: the KKT system with its pattern, AMD ordering and
//! symbolic factorisation (`Kkt::new`, 13 % of a warm cart-pole MPC re-solve before it
//! was kept).
//!
//! The [`Solver`](crate::Solver) trait takes `&self` (drivers hold a `Box<dyn Solver>`
//! and may share it between threads), so the workspace sits behind a mutex keyed on the
//! structure: a solve takes it when the reduced problem's Hessian and Jacobian patterns
//! are those it was analysed for, and puts it back at the end. A solve that finds it
//! taken (another thread is solving with the same solver) or keyed on another structure
//! builds its own, so results never depend on what was kept: the numeric state is reset
//! and the iterates are bit-identical to a fresh solver's (`tests/ipm_warm_alloc.rs`).

use std::sync::Mutex;

use faer::sparse::SymbolicSparseColMat;

use crate::kkt::Kkt;

/// The structure a KKT system was analysed for: the reduced problem's sizes and its
/// Hessian (lower triangle) and Jacobian patterns.
struct Structure {
    n: usize,
    m: usize,
    hess: SymbolicSparseColMat<usize>,
    jac: SymbolicSparseColMat<usize>,
}

fn same_pattern(a: &SymbolicSparseColMat<usize>, b: &SymbolicSparseColMat<usize>) -> bool {
    a.nrows() == b.nrows()
        && a.ncols() == b.ncols()
        && (0..a.ncols()).all(|j| a.row_idx()[a.col_range(j)] == b.row_idx()[b.col_range(j)])
}

impl Structure {
    fn is(
        &self,
        n: usize,
        m: usize,
        hess: &SymbolicSparseColMat<usize>,
        jac: &SymbolicSparseColMat<usize>,
    ) -> bool {
        self.n == n && self.m == m && same_pattern(&self.hess, hess) && same_pattern(&self.jac, jac)
    }
}

struct Kept {
    structure: Structure,
    /// `None` while a solve has it.
    kkt: Option<Kkt>,
}

/// The kept workspace of one solver (empty when cloned).
#[derive(Default)]
pub(crate) struct Workspace(Mutex<Option<Kept>>);

impl Workspace {
    /// The kept KKT system if it was analysed for this structure (and no other solve has
    /// it), taken out until [`Workspace::keep`].
    pub(crate) fn take(
        &self,
        n: usize,
        m: usize,
        hess: &SymbolicSparseColMat<usize>,
        jac: &SymbolicSparseColMat<usize>,
    ) -> Option<Kkt> {
        let mut guard = self.0.try_lock().ok()?;
        let kept = guard.as_mut()?;
        if kept.structure.is(n, m, hess, jac) {
            kept.kkt.take()
        } else {
            None
        }
    }

    /// Keeps `kkt`, analysed for this structure, for the next solve (replacing what was
    /// kept for another structure; a concurrent solve's is dropped).
    pub(crate) fn keep(
        &self,
        kkt: Kkt,
        hess: &SymbolicSparseColMat<usize>,
        jac: &SymbolicSparseColMat<usize>,
    ) {
        let Ok(mut guard) = self.0.try_lock() else {
            return;
        };
        let (n, m) = (kkt.n(), kkt.m());
        match guard.as_mut() {
            Some(kept) if kept.structure.is(n, m, hess, jac) => kept.kkt = Some(kkt),
            _ => {
                *guard = Some(Kept {
                    structure: Structure {
                        n,
                        m,
                        hess: hess.clone(),
                        jac: jac.clone(),
                    },
                    kkt: Some(kkt),
                })
            }
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
