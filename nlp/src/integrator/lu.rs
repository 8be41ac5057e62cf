//! A dense LU factorisation whose memory is kept from one factorisation to the next
//! (faer's partial-pivoting LU, in place), so that the implicit method's repeated
//! factorisations and solves allocate nothing once the sizes are reached.
use faer::dyn_stack::{MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Mat, MatMut, Par};
use std::mem::MaybeUninit;

/// `A = PᵀLU` of a square matrix, with its buffers.
#[derive(Debug)]
pub(super) struct DenseLu {
    /// The matrix to factor, then its factors (`L` strictly below the diagonal, unit
    /// diagonal implied; `U` on and above).
    pub(super) matrix: Mat<f64>,
    forward: Vec<usize>,
    inverse: Vec<usize>,
    scratch: Vec<MaybeUninit<u8>>,
}

impl Default for DenseLu {
    fn default() -> Self {
        DenseLu {
            matrix: Mat::zeros(0, 0),
            forward: Vec::new(),
            inverse: Vec::new(),
            scratch: Vec::new(),
        }
    }
}

impl DenseLu {
    /// Sizes the buffers for `n × n` matrices and right-hand sides of up to `columns`
    /// columns (no allocation when they already fit).
    pub(super) fn reserve(&mut self, n: usize, columns: usize) {
        if self.matrix.nrows() != n {
            self.matrix = Mat::zeros(n, n);
        }
        self.forward.resize(n, 0);
        self.inverse.resize(n, 0);
        let params = Default::default();
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, params),
            solve::solve_in_place_scratch::<usize, f64>(n, columns, Par::Seq),
            solve::solve_transpose_in_place_scratch::<usize, f64>(n, columns, Par::Seq),
        ]);
        let bytes = req.unaligned_bytes_required();
        if self.scratch.len() < bytes {
            self.scratch.resize(bytes, MaybeUninit::uninit());
        }
    }

    /// Factors `self.matrix` in place (sized by [`DenseLu::reserve`]).
    pub(super) fn factor(&mut self) {
        let stack = MemStack::new(&mut self.scratch);
        factor::lu_in_place(
            self.matrix.as_mut(),
            &mut self.forward,
            &mut self.inverse,
            Par::Seq,
            stack,
            Default::default(),
        );
    }

    /// Solves `A X = B` (or `Aᵀ X = B` if `transpose`) in place, `B` the column-major
    /// `rhs` of `rhs.len() / n` columns (at most the reserved number).
    pub(super) fn solve(&mut self, rhs: &mut [f64], transpose: bool) {
        let n = self.matrix.nrows();
        let columns = rhs.len() / n.max(1);
        let rhs = MatMut::from_column_major_slice_mut(rhs, n, columns);
        let perm = PermRef::new_checked(&self.forward, &self.inverse, n);
        let lu = self.matrix.as_ref();
        let stack = MemStack::new(&mut self.scratch);
        if transpose {
            solve::solve_transpose_in_place(lu, lu, perm, rhs, Par::Seq, stack);
        } else {
            solve::solve_in_place(lu, lu, perm, rhs, Par::Seq, stack);
        }
    }
}
