//! The iterate (w = [x; s], y, z_L, z_U with f, ∇f, g, c, J, ∇²L there) and the trial
//! iterate of the line search.

use crate::frontend::scaled::refill;

/// A primal-dual point with the problem's values there.
#[derive(Clone, Default)]
pub(crate) struct Iterate {
    /// w = [x; s].
    pub(crate) w: Vec<f64>,
    /// Constraint multipliers.
    pub(crate) y: Vec<f64>,
    /// Lower-bound multipliers of w.
    pub(crate) zl: Vec<f64>,
    /// Upper-bound multipliers of w.
    pub(crate) zu: Vec<f64>,
    pub(crate) f: f64,
    pub(crate) grad: Vec<f64>,
    pub(crate) g: Vec<f64>,
    /// c = g − s (inequality rows) or g − g_eq (equality rows).
    pub(crate) c: Vec<f64>,
    pub(crate) jac: Vec<f64>,
    pub(crate) hess: Vec<f64>,
}

/// The line search's trial point (bound multipliers are updated in place on acceptance).
#[derive(Default)]
pub(super) struct Trial {
    pub(super) w: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) f: f64,
    pub(super) grad: Vec<f64>,
    pub(super) g: Vec<f64>,
    pub(super) c: Vec<f64>,
    pub(super) jac: Vec<f64>,
    pub(super) hess: Vec<f64>,
}

impl Iterate {
    /// Sized for `n` variables, `m` rows, `nw` entries of w and the Jacobian's and
    /// Hessian's nonzeros, zeroed.
    pub(super) fn prepare(&mut self, n: usize, m: usize, nw: usize, nnz_j: usize, nnz_h: usize) {
        zero_all([
            (&mut self.w, nw),
            (&mut self.y, m),
            (&mut self.zl, nw),
            (&mut self.zu, nw),
            (&mut self.grad, n),
            (&mut self.g, m),
            (&mut self.c, m),
            (&mut self.jac, nnz_j),
            (&mut self.hess, nnz_h),
        ]);
        self.f = 0.0;
    }
}

impl Trial {
    /// As [`Iterate::prepare`].
    pub(super) fn prepare(&mut self, n: usize, m: usize, nw: usize, nnz_j: usize, nnz_h: usize) {
        zero_all([
            (&mut self.w, nw),
            (&mut self.y, m),
            (&mut self.grad, n),
            (&mut self.g, m),
            (&mut self.c, m),
            (&mut self.jac, nnz_j),
            (&mut self.hess, nnz_h),
        ]);
        self.f = 0.0;
    }
}

/// Each vector refilled with zeros to its length (keeping its capacity).
fn zero_all<const N: usize>(vectors: [(&mut Vec<f64>, usize); N]) {
    for (v, len) in vectors {
        refill(v, len, 0.0);
    }
}
