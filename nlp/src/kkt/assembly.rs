//! Operations on the assembled K of a [`Kkt`]: scattering the Hessian's and the
//! Jacobian's values and the diagonals into it, and products with K.

#![allow(clippy::needless_range_loop)]

use super::error::KktError;
use super::system::Kkt;

impl Kkt {
    /// Checks the lengths and scatters the values into K (in `pattern`'s space):
    /// `h_vals`/`j_vals` in the storage order of the patterns given to [`Kkt::new`],
    /// `dx` (length n) added to the first diagonal, `dc` (length m) subtracted from the
    /// second.
    pub(super) fn assemble(
        &mut self,
        h_vals: &[f64],
        dx: &[f64],
        j_vals: &[f64],
        dc: &[f64],
    ) -> Result<(), KktError> {
        let check = |what, expected: usize, got: usize| {
            if expected != got {
                Err(KktError::Length {
                    what,
                    expected,
                    got,
                })
            } else {
                Ok(())
            }
        };
        check("h_vals", self.h_map.len(), h_vals.len())?;
        check("j_vals", self.j_map.len(), j_vals.len())?;
        check("dx", self.n, dx.len())?;
        check("dc", self.m, dc.len())?;
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for (&p, &v) in self.h_map.iter().zip(h_vals) {
            self.values[p] += v;
        }
        for (&p, &v) in self.j_map.iter().zip(j_vals) {
            self.values[p] += v;
        }
        for (i, &d) in dx.iter().enumerate() {
            self.values[self.diag_pos[i]] += d;
        }
        for (i, &d) in dc.iter().enumerate() {
            self.values[self.diag_pos[self.n + i]] -= d;
        }
        if self.values.iter().any(|v| !v.is_finite()) {
            return Err(KktError::NonFinite);
        }
        Ok(())
    }

    /// y = (K + diag(shift)) x using the assembled upper triangle, in `pattern`'s space
    /// (permuted when simplicial).
    pub(super) fn matvec(&self, x: &[f64], shift: Option<&[f64]>, y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        let cp = self.pattern.col_ptr();
        let ri = self.pattern.row_idx();
        for j in 0..self.dim() {
            let xj = x[j];
            let mut acc = 0.0;
            for p in cp[j]..cp[j + 1] {
                let i = ri[p];
                let v = self.values[p];
                acc += v * x[i];
                if i != j {
                    y[i] += v * xj;
                }
            }
            y[j] += acc;
        }
        if let Some(s) = shift {
            for ((yi, si), xi) in y.iter_mut().zip(s).zip(x) {
                *yi += si * xi;
            }
        }
    }

    /// y = (K + diag(shift)) x in the original (unpermuted) ordering, K the matrix of the
    /// last [`Kkt::factorize`].
    pub fn multiply(
        &self,
        x: &[f64],
        shift: Option<&[f64]>,
        y: &mut [f64],
    ) -> Result<(), KktError> {
        let dim = self.dim();
        for (what, len) in [("x", x.len()), ("y", y.len())] {
            if len != dim {
                return Err(KktError::Length {
                    what,
                    expected: dim,
                    got: len,
                });
            }
        }
        match &self.simplicial {
            Some(simp) => {
                let px: Vec<f64> = simp.fwd.iter().map(|&o| x[o]).collect();
                let mut py = vec![0.0; dim];
                self.matvec(&px, None, &mut py);
                for (&v, &o) in py.iter().zip(&simp.fwd) {
                    y[o] = v;
                }
            }
            None => self.matvec(x, None, y),
        }
        if let Some(s) = shift {
            for ((yi, si), xi) in y.iter_mut().zip(s).zip(x) {
                *yi += si * xi;
            }
        }
        Ok(())
    }
}
