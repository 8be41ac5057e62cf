//! The KKT system with a low-rank Hessian block: W = σI + V N⁻¹ Vᵀ (a limited-memory
//! quasi-Newton matrix in compact form, see `crate::lbfgs`).
//!
//! ```text
//! K = K₀ + [V; 0] N⁻¹ [V; 0]ᵀ,   K₀ = [ σI + diag(dx)   Jᵀ       ]
//!                                     [ J              −diag(dc) ]
//! ```
//!
//! K₀ keeps the sparse pattern of [`Kkt`] and is factorised by it; the low-rank term is
//! handled by the Sherman–Morrison–Woodbury formula with the small (k×k) capacitance
//! matrix T = N + Vᵀ K₀⁻¹ V:  K⁻¹ = K₀⁻¹ − K₀⁻¹V T⁻¹ VᵀK₀⁻¹ (IPOPT's
//! LowRankAugSystemSolver does the same with N = ±I). The inertia of K follows from
//! Sylvester's law applied to the bordered matrix [[K₀, V], [Vᵀ, −N]] eliminated in both
//! orders: inertia(K) = inertia(K₀) + inertia(−T) − inertia(−N).

#![allow(clippy::needless_range_loop)]

use faer::{Mat, Side};

use super::error::KktError;
use super::inertia::Inertia;
use super::refine::{refine, Refinable, RefineLimits};
use super::system::Kkt;

/// Eigenvalues below this × the largest magnitude in their matrix count as zero (the
/// small matrices are formed from sums of products of O(n) vectors, so their entries
/// carry relative round-off of a few ε·n; 1e-12 leaves room for n up to ~10⁴·ε⁻¹ scale
/// effects without calling a merely ill-conditioned matrix singular).
const ZERO_EIG_REL: f64 = 1e-12;

/// A small symmetric matrix with its eigendecomposition (for inverse and inertia).
#[derive(Debug, Clone)]
struct SmallSym {
    q: Mat<f64>,
    lambda: Vec<f64>,
}

impl SmallSym {
    /// Eigendecomposition of the symmetric `a`; `scale` is the magnitude against which
    /// an eigenvalue counts as zero (at least the largest eigenvalue's).
    fn new(a: &Mat<f64>, scale: f64) -> Option<(SmallSym, Inertia)> {
        let k = a.nrows();
        if k == 0 {
            return Some((
                SmallSym {
                    q: Mat::zeros(0, 0),
                    lambda: Vec::new(),
                },
                Inertia::default(),
            ));
        }
        if (0..k).any(|i| (0..k).any(|j| !a[(i, j)].is_finite())) {
            return None;
        }
        let eig = a.self_adjoint_eigen(Side::Lower).ok()?;
        let s = eig.S().column_vector();
        let lambda: Vec<f64> = (0..k).map(|i| s[i]).collect();
        let big = lambda.iter().fold(scale, |m, l| m.max(l.abs()));
        let mut inertia = Inertia::default();
        for &l in &lambda {
            if l.abs() <= ZERO_EIG_REL * big {
                inertia.zero += 1;
            } else if l > 0.0 {
                inertia.positive += 1;
            } else {
                inertia.negative += 1;
            }
        }
        Some((
            SmallSym {
                q: eig.U().to_owned(),
                lambda,
            },
            inertia,
        ))
    }

    /// out = A⁻¹ c (only called when A has no zero eigenvalue).
    fn solve(&self, c: &[f64], out: &mut [f64]) {
        let k = self.lambda.len();
        out.iter_mut().for_each(|v| *v = 0.0);
        for l in 0..k {
            let mut d = 0.0;
            for i in 0..k {
                d += self.q[(i, l)] * c[i];
            }
            d /= self.lambda[l];
            for i in 0..k {
                out[i] += self.q[(i, l)] * d;
            }
        }
    }
}

/// The Hessian approximation B = σI + V N⁻¹ Vᵀ on the n primal variables, with N a small
/// nonsingular symmetric matrix (k = number of columns of V).
#[derive(Debug, Clone)]
pub(crate) struct LowRankTerm {
    n: usize,
    sigma: f64,
    /// Columns of V (each of length n).
    cols: Vec<Vec<f64>>,
    /// N.
    middle_mat: Mat<f64>,
    /// N's eigendecomposition.
    middle: SmallSym,
    /// inertia(N).
    middle_inertia: Inertia,
}

impl LowRankTerm {
    /// B = σI.
    pub(crate) fn diagonal(n: usize, sigma: f64) -> LowRankTerm {
        LowRankTerm {
            n,
            sigma,
            cols: Vec::new(),
            middle_mat: Mat::zeros(0, 0),
            middle: SmallSym {
                q: Mat::zeros(0, 0),
                lambda: Vec::new(),
            },
            middle_inertia: Inertia::default(),
        }
    }

    /// B = σI + V N⁻¹ Vᵀ; `None` when N is singular (relative to its own scale) or not
    /// finite, or the shapes disagree.
    pub(crate) fn new(
        n: usize,
        sigma: f64,
        cols: Vec<Vec<f64>>,
        middle: &Mat<f64>,
    ) -> Option<LowRankTerm> {
        let k = cols.len();
        if middle.nrows() != k || middle.ncols() != k || cols.iter().any(|c| c.len() != n) {
            return None;
        }
        let (sym, inertia) = SmallSym::new(middle, 0.0)?;
        if inertia.zero > 0 {
            return None;
        }
        Some(LowRankTerm {
            n,
            sigma,
            cols,
            middle_mat: middle.to_owned(),
            middle: sym,
            middle_inertia: inertia,
        })
    }

    /// σ of B₀ = σI.
    #[cfg(test)]
    pub(crate) fn sigma(&self) -> f64 {
        self.sigma
    }

    /// Rank of the low-rank part (number of columns of V).
    pub(crate) fn rank(&self) -> usize {
        self.cols.len()
    }

    /// y += V N⁻¹ Vᵀ x (x, y of length ≥ n; only the first n entries are used).
    fn add_low_rank_product(&self, x: &[f64], y: &mut [f64]) {
        let k = self.rank();
        if k == 0 {
            return;
        }
        let c: Vec<f64> = self.cols.iter().map(|v| dot(v, &x[..self.n])).collect();
        let mut t = vec![0.0; k];
        self.middle.solve(&c, &mut t);
        for (v, &ti) in self.cols.iter().zip(&t) {
            for (yj, vj) in y[..self.n].iter_mut().zip(v) {
                *yj += ti * vj;
            }
        }
    }

    /// y = B x (length n).
    pub(crate) fn apply(&self, x: &[f64], y: &mut [f64]) {
        for (yj, xj) in y.iter_mut().zip(x) {
            *yj = self.sigma * xj;
        }
        self.add_low_rank_product(x, y);
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Factorisation and solution of K = K₀ + [V; 0] N⁻¹ [V; 0]ᵀ on top of a [`Kkt`] that
/// holds K₀.
#[derive(Debug, Default)]
pub(crate) struct LowRankKkt {
    /// The term of the current factorisation.
    term: Option<LowRankTerm>,
    /// Z = K₀⁻¹ [V; 0], one column per column of V.
    z: Vec<Vec<f64>>,
    /// T = N + Vᵀ K₀⁻¹ V.
    cap: Option<SmallSym>,
    dx: Vec<f64>,
    work_c: Vec<f64>,
    work_t: Vec<f64>,
    wb: Vec<f64>,
    wr: Vec<f64>,
    wd: Vec<f64>,
}

impl LowRankKkt {
    /// Factorises K with the Hessian block `hess` (values in the pattern of `kkt`; zero
    /// for a pure quasi-Newton Hessian) + diag(dx) + B, B given by `term`. Returns the
    /// inertia of K. A singular capacitance matrix is reported as zero eigenvalues of K
    /// (and the factorisation cannot be used for solves).
    pub(crate) fn factorize(
        &mut self,
        kkt: &mut Kkt,
        term: &LowRankTerm,
        hess: &[f64],
        dx: &[f64],
        jac: &[f64],
        dc: &[f64],
    ) -> Result<Inertia, KktError> {
        self.term = None;
        self.cap = None;
        let n = term.n;
        if dx.len() != n {
            return Err(KktError::Length {
                what: "dx",
                expected: n,
                got: dx.len(),
            });
        }
        self.dx.clear();
        self.dx.extend(dx.iter().map(|d| d + term.sigma));
        let base = kkt.factorize(hess, &self.dx, jac, dc)?;
        let k = term.rank();
        let dim = kkt.dim();
        self.z.resize_with(k, Vec::new);
        for (zi, v) in self.z.iter_mut().zip(&term.cols) {
            zi.clear();
            zi.extend_from_slice(v);
            zi.resize(dim, 0.0);
            kkt.solve_shifted(zi, None)?;
        }
        let mut t = Mat::<f64>::zeros(k, k);
        let mut scale: f64 = 0.0;
        for i in 0..k {
            for j in 0..=i {
                let vzj = dot(&term.cols[i], &self.z[j][..n]);
                let vzi = dot(&term.cols[j], &self.z[i][..n]);
                let nij = term.middle_mat[(i, j)];
                let s = nij + 0.5 * (vzj + vzi);
                scale = scale.max(nij.abs()).max(vzj.abs());
                t[(i, j)] = s;
                t[(j, i)] = s;
            }
        }
        let Some((cap, ti)) = SmallSym::new(&t, scale) else {
            return Err(KktError::NonFinite);
        };
        let ni = term.middle_inertia;
        // inertia(K) = inertia(K₀) + inertia(−T) − inertia(−N).
        let inertia = Inertia {
            positive: (base.positive + ti.negative).saturating_sub(ni.negative),
            negative: (base.negative + ti.positive).saturating_sub(ni.positive),
            zero: base.zero + ti.zero,
        };
        if ti.zero == 0 {
            self.cap = Some(cap);
            self.term = Some(term.clone());
        }
        Ok(inertia)
    }

    /// x ← K⁻¹ x by Sherman–Morrison–Woodbury (K₀ solves refined against K₀).
    fn smw_solve(&mut self, kkt: &mut Kkt, x: &mut [f64]) -> Result<(), KktError> {
        let (Some(term), Some(cap)) = (&self.term, &self.cap) else {
            return Err(KktError::NotFactorized);
        };
        kkt.solve_shifted(x, None)?;
        let k = term.rank();
        self.work_c.clear();
        self.work_c
            .extend(term.cols.iter().map(|v| dot(v, &x[..term.n])));
        self.work_t.resize(k, 0.0);
        cap.solve(&self.work_c, &mut self.work_t);
        for (zi, &ti) in self.z.iter().zip(&self.work_t) {
            for (xj, zj) in x.iter_mut().zip(zi) {
                *xj -= ti * zj;
            }
        }
        Ok(())
    }

    /// Solves (K + diag(shift)) x = rhs in place with the factorisation of K as the
    /// preconditioner of iterative refinement (as [`Kkt::solve_shifted`], whose
    /// refinement settings it uses). Returns the final relative residual.
    pub(crate) fn solve_shifted(
        &mut self,
        kkt: &mut Kkt,
        rhs: &mut [f64],
        shift: Option<&[f64]>,
    ) -> Result<f64, KktError> {
        let dim = kkt.dim();
        if rhs.len() != dim {
            return Err(KktError::Length {
                what: "rhs",
                expected: dim,
                got: rhs.len(),
            });
        }
        let mut wb = std::mem::take(&mut self.wb);
        let mut wr = std::mem::take(&mut self.wr);
        let mut wd = std::mem::take(&mut self.wd);
        wb.clear();
        wb.extend_from_slice(rhs);
        wr.resize(dim, 0.0);
        wd.resize(dim, 0.0);
        let out = self.refine(kkt, rhs, shift, &wb, &mut wr, &mut wd);
        self.wb = wb;
        self.wr = wr;
        self.wd = wd;
        let ratio = out?;
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(KktError::NonFinite);
        }
        Ok(ratio)
    }

    /// x (= rhs on entry) ← refined solution of (K + diag(shift)) x = b, K with the
    /// low-rank term (the shared [`refine`] loop, the SMW solve as its approximate solve).
    fn refine(
        &mut self,
        kkt: &mut Kkt,
        x: &mut [f64],
        shift: Option<&[f64]>,
        b: &[f64],
        r: &mut [f64],
        d: &mut [f64],
    ) -> Result<f64, KktError> {
        let limits = RefineLimits::of(kkt);
        let mut op = WithLowRank {
            solver: self,
            kkt,
            shift,
        };
        refine(&mut op, limits, b, x, r, d)
    }
}

/// K + diag(shift) + the low-rank term, with the SMW solve, as [`Refinable`].
struct WithLowRank<'a> {
    solver: &'a mut LowRankKkt,
    kkt: &'a mut Kkt,
    shift: Option<&'a [f64]>,
}

impl Refinable for WithLowRank<'_> {
    type Error = KktError;
    fn apply(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), KktError> {
        self.kkt.multiply(x, self.shift, r)?;
        if let Some(term) = &self.solver.term {
            term.add_low_rank_product(x, r);
        }
        Ok(())
    }
    fn approx_solve(&mut self, v: &mut [f64]) -> Result<(), KktError> {
        self.solver.smw_solve(self.kkt, v)
    }
}
