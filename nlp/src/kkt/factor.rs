//! The numeric factorisation of K (faer's supernodal LDLᵀ or our simplicial one), its
//! inertia from the signs of D, ln |det K|, and the plain solve with the factor.

#![allow(clippy::needless_range_loop)]

use faer::dyn_stack::MemStack;
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltParams, LdltRegularization};
use faer::sparse::linalg::cholesky::{LdltRef, SymbolicCholeskyRaw};
use faer::sparse::SparseColMatRef;
use faer::{Conj, MatMut, Par, Side, Spec};

use super::error::KktError;
use super::inertia::Inertia;
use super::system::Kkt;

impl Kkt {
    /// Assembles and factorises K; returns its inertia. `h_vals`/`j_vals` are in the
    /// storage order of the patterns given to [`Kkt::new`]; `dx` has length n, `dc` length m.
    pub fn factorize(
        &mut self,
        h_vals: &[f64],
        dx: &[f64],
        j_vals: &[f64],
        dc: &[f64],
    ) -> Result<Inertia, KktError> {
        self.factored = false;
        self.assemble(h_vals, dx, j_vals, dc)?;
        if let Some(simp) = self.simplicial.as_mut() {
            let inertia = simp.factorize(
                self.pattern.col_ptr(),
                self.pattern.row_idx(),
                &self.values,
                &mut self.l_values,
            )?;
            self.factored = true;
            return Ok(inertia);
        }
        let Kkt {
            pattern,
            values,
            symbolic,
            l_values,
            mem,
            ..
        } = self;
        let kmat = SparseColMatRef::new(pattern.as_ref(), values);
        let stack = MemStack::new(mem);
        let res = symbolic.factorize_numeric_ldlt(
            l_values,
            kmat,
            Side::Upper,
            LdltRegularization::default(),
            Par::Seq,
            stack,
            Spec::<LdltParams, f64>::default(),
        );
        match res {
            Ok(_) => {}
            Err(LdltError::ZeroPivot { index }) => return Err(KktError::ZeroPivot(index)),
        }
        let inertia = self.inertia_from_d()?;
        self.factored = true;
        Ok(inertia)
    }

    fn inertia_from_d(&self) -> Result<Inertia, KktError> {
        let mut inertia = Inertia::default();
        let mut count = |d: f64| -> Result<(), KktError> {
            if !d.is_finite() {
                return Err(KktError::NonFinite);
            }
            if d > 0.0 {
                inertia.positive += 1;
            } else if d < 0.0 {
                inertia.negative += 1;
            } else {
                inertia.zero += 1;
            }
            Ok(())
        };
        self.for_each_pivot(&mut count)?;
        Ok(inertia)
    }

    /// Calls `f` with every pivot D_jj of the current factor (in factor order).
    fn for_each_pivot<E>(&self, mut f: impl FnMut(f64) -> Result<(), E>) -> Result<(), E> {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let cp = s.col_ptr();
                for j in 0..s.nrows() {
                    f(self.l_values[cp[j]])?;
                }
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let begin = s.supernode_begin();
                let end = s.supernode_end();
                let cpv = s.col_ptr_for_val();
                for k in 0..s.n_supernodes() {
                    let ncols = end[k] - begin[k];
                    if ncols == 0 {
                        continue;
                    }
                    let nrows = (cpv[k + 1] - cpv[k]) / ncols;
                    for j in 0..ncols {
                        f(self.l_values[cpv[k] + j * nrows + j])?;
                    }
                }
            }
        }
        Ok(())
    }

    /// ln |det K| of the current factorisation (the sum of ln |D_ii|; computed on demand,
    /// NaN without a valid factorisation).
    pub fn log_abs_det(&self) -> f64 {
        if !self.factored {
            return f64::NAN;
        }
        let mut sum = 0.0;
        let _ = self.for_each_pivot(|d| -> Result<(), ()> {
            sum += d.abs().ln();
            Ok(())
        });
        sum
    }

    /// x ← K⁻¹ x from the factor, in the space of `pattern` (permuted when simplicial).
    pub(super) fn raw_solve(&mut self, x: &mut [f64]) {
        if let Some(simp) = &self.simplicial {
            simp.solve_in_place(&self.l_values, x);
            return;
        }
        let Kkt {
            symbolic,
            l_values,
            mem,
            ..
        } = self;
        let stack = MemStack::new(mem);
        let dim = x.len();
        let f = LdltRef::<usize, f64>::new(symbolic, l_values);
        f.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, dim, 1),
            Par::Seq,
            stack,
        );
    }
}
