//! The primal-dual search direction (Δw, Δy, Δz_L, Δz_U).

/// A primal-dual direction.
#[derive(Default)]
pub(super) struct Direction {
    pub(super) dw: Vec<f64>,
    pub(super) dy: Vec<f64>,
    pub(super) dzl: Vec<f64>,
    pub(super) dzu: Vec<f64>,
}

impl Direction {
    /// Sized for `nw` primal and `m` dual entries, zeroed.
    pub(super) fn prepare(&mut self, nw: usize, m: usize) {
        for (v, len) in [
            (&mut self.dw, nw),
            (&mut self.dy, m),
            (&mut self.dzl, nw),
            (&mut self.dzu, nw),
        ] {
            crate::frontend::scaled::refill(v, len, 0.0);
        }
    }
}
