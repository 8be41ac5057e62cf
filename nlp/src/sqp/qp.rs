//! The SQP subproblem, an elastic (ℓ1-penalised) QP solved by clarabel:
//!
//! ```text
//! min_{d, e}  ½ dᵀ B d + ∇fᵀ d + ρ·Σ e
//! s.t.  g_i + J_i d − e⁺_i + e⁻_i = g_l,i          (equality rows, ZeroCone)
//!       g_i + J_i d − e_k ≤ g_u,i,  g_i + J_i d + e_k ≥ g_l,i   (inequality sides, Nonneg)
//!       x_l ≤ x + d ≤ x_u                          (bounds; fixed variables: ZeroCone)
//!       e ≥ 0
//!       ‖v + J_v d‖ ≤ t + J_t d + e_c              (affine cones, SecondOrderCone)
//! ```
//!
//! This is Fletcher's Sℓ1QP subproblem: always feasible (the elastic variables e absorb
//! whatever the linearisation cannot satisfy), bounded when B is positive definite, and
//! its optimal value is the model of the ℓ1 merit function, so `pred = m(0) − m(d) ≥ 0`.
//! When the linearised constraints are consistent and ρ exceeds the multipliers, e = 0
//! and d is the ordinary SQP step.
//!
//! The pattern of P (upper triangle of B) and A is built once; every iteration only
//! writes new values through precomputed positions and calls clarabel's `update_*`
//! (presolve off, zero dropping off, so the symbolic factorisation is kept).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, SolverError, SolverStatus, SupportedConeT,
};
use faer::sparse::SymbolicSparseColMat;

/// What a QP row stands for (to read multipliers back and to fill `b`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum RowKind {
    /// Equality row i of g.
    EqG(usize),
    /// Upper side of inequality row i of g.
    UpperG(usize),
    /// Lower side of inequality row i of g.
    LowerG(usize),
    /// Fixed variable j.
    Fixed(usize),
    /// Upper bound of variable j.
    UpperX(usize),
    /// Lower bound of variable j.
    LowerX(usize),
    /// Non-negativity of elastic variable k.
    Elastic,
    /// Entry `k` (into the stacked cone vector [t; v] of every cone) of an SOC block.
    Cone(usize),
}

/// Where a value of A comes from.
#[derive(Debug, Clone, Copy)]
enum Src {
    /// Jacobian storage position, times a sign.
    Jac(usize, f64),
    /// Cone Jacobian storage position, times a sign.
    ConeJac(usize, f64),
    /// A constant.
    Const(f64),
}

/// Why a QP could not be set up (a QP that was set up but not solved reports its
/// status in [`QpResult::status`] instead).
#[derive(Debug, thiserror::Error)]
pub(crate) enum QpError {
    /// clarabel rejected the QP data or settings.
    #[error("{0}")]
    Setup(#[from] SolverError),
}

/// Numeric data of one QP (scaled problem).
pub(crate) struct QpData<'a> {
    pub x: &'a [f64],
    pub x_l: &'a [f64],
    pub x_u: &'a [f64],
    pub g: &'a [f64],
    pub g_l: &'a [f64],
    pub g_u: &'a [f64],
    pub grad: &'a [f64],
    pub jac: &'a [f64],
    /// Stacked cone entries [t; v] of every cone at x.
    pub cone: &'a [f64],
    pub cone_jac: &'a [f64],
    /// Lower-triangular Hessian values (pattern given at construction).
    pub hess: &'a [f64],
    /// Diagonal shift δ added to B.
    pub shift: f64,
    /// Extra diagonal weight per variable (active bounds: ρ_a), added to B.
    pub bound_weight: &'a [f64],
    /// Augmented-Lagrangian weight per row of g (ρ_a on active rows, 0 elsewhere): the
    /// QP objective gets ½·w_i·(J_i d)² through the auxiliary variables `w = J d`.
    pub row_weight: &'a [f64],
    /// Optional dense B (damped BFGS), column-major n×n; replaces `hess`/`shift`.
    pub dense_b: Option<&'a [f64]>,
    /// ℓ1 penalty ρ.
    pub rho: f64,
}

/// Result of a QP solve.
#[derive(Debug, Clone)]
pub(crate) struct QpResult {
    /// Primal step d (length n).
    pub d: Vec<f64>,
    /// Elastic variables.
    pub e: Vec<f64>,
    /// Constraint multipliers λ in IPOPT's convention (length m).
    pub lambda: Vec<f64>,
    /// Lower / upper bound multipliers (length n).
    pub z_l: Vec<f64>,
    pub z_u: Vec<f64>,
    /// Duals of the cone rows (stacked like the cone entries).
    pub z_cone: Vec<f64>,
    /// ρ_a·J_i d per row (the augmented term's share of the row multiplier; zero without it).
    pub z_w: Vec<f64>,
    pub status: SolverStatus,
    pub iterations: u32,
}

impl QpResult {
    /// A result with empty vectors (to be written into, e.g. by the active-set method).
    pub fn empty() -> QpResult {
        QpResult {
            d: Vec::new(),
            e: Vec::new(),
            lambda: Vec::new(),
            z_l: Vec::new(),
            z_u: Vec::new(),
            z_cone: Vec::new(),
            z_w: Vec::new(),
            status: SolverStatus::Unsolved,
            iterations: 0,
        }
    }
}

/// The QP of one problem structure, with its clarabel solver (set up on the first solve).
pub(crate) struct Qp {
    n: usize,
    m: usize,
    n_e: usize,
    rows: Vec<RowKind>,
    /// Elastic column (absolute, ≥ n) per row that has one (equality rows have two).
    cones: Vec<SupportedConeT<f64>>,
    p_colptr: Vec<usize>,
    p_rowval: Vec<usize>,
    p_vals: Vec<f64>,
    /// P position of each Hessian storage entry.
    h_pos: Vec<usize>,
    /// P position of each diagonal entry of the d block.
    diag_pos: Vec<usize>,
    /// P position of the dense upper triangle (BFGS), column-major (i ≤ j).
    dense: bool,
    a_colptr: Vec<usize>,
    a_rowval: Vec<usize>,
    a_vals: Vec<f64>,
    a_src: Vec<Src>,
    b: Vec<f64>,
    q: Vec<f64>,
    tol: f64,
    max_iter: u32,
    solver: Option<DefaultSolver<f64>>,
    /// Cone blocks: (row offset in the stacked cone vector, dimension).
    cone_blocks: Vec<(usize, usize)>,
    /// Whether P holds the augmented term ρ_a·J_AᵀJ_A.
    aug: bool,
    /// Whether the values of the last `load` have not reached clarabel yet (the QP was
    /// solved by the active-set method): the next clarabel solve updates them all.
    stale: bool,
    /// Jacobian entries (column, storage position) of each row of g.
    jrows: Vec<Vec<(usize, usize)>>,
    /// Products of the augmented term: (row, position of J_ia, of J_ib, P position).
    jtj: Vec<(usize, usize, usize, usize)>,
    /// Jacobian values and row weights of the last `fill` (to recover λ from the QP).
    jac_copy: Vec<f64>,
    weight_copy: Vec<f64>,
}

/// Builds CSC from (row, col, payload) triplets (no duplicates); returns colptr, rowval
/// and the payloads in CSC order.
fn to_csc<T: Copy>(
    ncols: usize,
    mut t: Vec<(usize, usize, T)>,
) -> (Vec<usize>, Vec<usize>, Vec<T>) {
    t.sort_by_key(|&(r, c, _)| (c, r));
    let mut colptr = vec![0usize; ncols + 1];
    for &(_, c, _) in &t {
        colptr[c + 1] += 1;
    }
    for c in 0..ncols {
        colptr[c + 1] += colptr[c];
    }
    let rowval = t.iter().map(|&(r, _, _)| r).collect();
    let payload = t.iter().map(|&(_, _, p)| p).collect();
    (colptr, rowval, payload)
}

/// The fixed structure of the QP's constraints: which sides are finite, which variables
/// are fixed, the patterns of J and of the cone Jacobian.
#[derive(Clone, Copy)]
pub(crate) struct QpStructure<'a> {
    pub jac: &'a SymbolicSparseColMat<usize>,
    pub x_l: &'a [f64],
    pub x_u: &'a [f64],
    pub g_l: &'a [f64],
    pub g_u: &'a [f64],
    /// (offset, dimension) of each cone in the stacked cone vector.
    pub cone_blocks: &'a [(usize, usize)],
    /// Pattern of the cone Jacobian (rows = stacked cone entries).
    pub cone_jac: Option<&'a SymbolicSparseColMat<usize>>,
    /// Rows of g replaced by a cone.
    pub skip_rows: &'a [bool],
}

/// The constraint rows of the QP (A, b's meaning, clarabel's cones) for a problem with
/// the given Jacobian pattern, bounds and cones.
struct ConstraintLayout {
    rows: Vec<RowKind>,
    /// Number of elastic variables.
    n_e: usize,
    cones: Vec<SupportedConeT<f64>>,
    a_colptr: Vec<usize>,
    a_rowval: Vec<usize>,
    a_src: Vec<Src>,
    /// Jacobian entries (column, storage position) of each row of g.
    jrows: Vec<Vec<(usize, usize)>>,
}

/// The rows of A as they are laid out: their meanings, A's entries as triplets, the next
/// free elastic column, and the Jacobian's entries by row.
struct RowsBuilder {
    rows: Vec<RowKind>,
    a_trip: Vec<(usize, usize, Src)>,
    next_e: usize,
    jrows: Vec<Vec<(usize, usize)>>,
}

impl RowsBuilder {
    /// A new row of meaning `kind`; returns its index.
    fn row(&mut self, kind: RowKind) -> usize {
        self.rows.push(kind);
        self.rows.len() - 1
    }

    /// A new row of meaning `kind` with row i of J times `sign`.
    fn g_row(&mut self, kind: RowKind, i: usize, sign: f64) -> usize {
        let r = self.row(kind);
        for &(c, p) in &self.jrows[i] {
            self.a_trip.push((r, c, Src::Jac(p, sign)));
        }
        r
    }

    /// A new elastic variable in row r with coefficient `sign`.
    fn elastic(&mut self, r: usize, sign: f64) {
        self.a_trip.push((r, self.next_e, Src::Const(sign)));
        self.next_e += 1;
    }

    /// A row of variable j's bound: ±d_j.
    fn bound_row(&mut self, kind: RowKind, j: usize, sign: f64) {
        let r = self.row(kind);
        self.a_trip.push((r, j, Src::Const(sign)));
    }

    /// The zero cone: equality rows (two elastic variables each), fixed variables.
    fn zero_cone(&mut self, st: &QpStructure) {
        for i in 0..st.g_l.len() {
            if !st.skip_rows[i] && st.g_l[i] == st.g_u[i] {
                let r = self.g_row(RowKind::EqG(i), i, 1.0);
                self.elastic(r, -1.0);
                self.elastic(r, 1.0);
            }
        }
        for j in 0..st.x_l.len() {
            if st.x_l[j] == st.x_u[j] {
                self.bound_row(RowKind::Fixed(j), j, 1.0);
            }
        }
    }

    /// The inequality sides (one elastic variable each) and bounds of the nonnegative
    /// cone.
    fn inequalities(&mut self, st: &QpStructure) {
        let (g_l, g_u, x_l, x_u) = (st.g_l, st.g_u, st.x_l, st.x_u);
        for i in 0..g_l.len() {
            if st.skip_rows[i] || g_l[i] == g_u[i] {
                continue;
            }
            if g_u[i].is_finite() {
                let r = self.g_row(RowKind::UpperG(i), i, 1.0);
                self.elastic(r, -1.0);
            }
            if g_l[i].is_finite() {
                let r = self.g_row(RowKind::LowerG(i), i, -1.0);
                self.elastic(r, -1.0);
            }
        }
        for j in 0..x_l.len() {
            if x_l[j] == x_u[j] {
                continue;
            }
            if x_u[j].is_finite() {
                self.bound_row(RowKind::UpperX(j), j, 1.0);
            }
            if x_l[j].is_finite() {
                self.bound_row(RowKind::LowerX(j), j, -1.0);
            }
        }
    }

    /// Second-order cones: s = [t; v] + J_c d + [e_c; 0] ∈ SOC, i.e. A = −J_c,
    /// b = [t; v]; `cone_e`: the elastic column of each cone (on its t entry).
    fn second_order_cones(&mut self, st: &QpStructure, cone_e: &[usize]) {
        let Some(cj) = st.cone_jac else {
            return;
        };
        let mut crows: Vec<Vec<(usize, usize)>> = vec![Vec::new(); cj.nrows()];
        for c in 0..st.x_l.len() {
            for p in cj.col_range(c) {
                crows[cj.row_idx()[p]].push((c, p));
            }
        }
        for (k, &(off, dim)) in st.cone_blocks.iter().enumerate() {
            for q in 0..dim {
                let r = self.row(RowKind::Cone(off + q));
                for &(c, p) in &crows[off + q] {
                    self.a_trip.push((r, c, Src::ConeJac(p, -1.0)));
                }
                if q == 0 {
                    self.a_trip.push((r, cone_e[k], Src::Const(-1.0)));
                }
            }
        }
    }
}

/// Lays out A: equality rows (two elastic variables each) and fixed variables in the zero
/// cone; inequality sides (one elastic variable each), bounds and elastic
/// non-negativity in the nonnegative cone; then one second-order cone per affine cone
/// (with one elastic variable on its t entry). Rows in `skip_rows` (replaced by cones)
/// are left out.
fn constraint_layout(st: &QpStructure) -> ConstraintLayout {
    let (n, m, jac) = (st.x_l.len(), st.g_l.len(), st.jac);
    // Rows of g by column: collect J entries per row once.
    let mut jrows: Vec<Vec<(usize, usize)>> = vec![Vec::new(); m];
    for c in 0..n {
        for p in jac.col_range(c) {
            jrows[jac.row_idx()[p]].push((c, p));
        }
    }
    let mut b = RowsBuilder {
        rows: Vec::new(),
        a_trip: Vec::new(),
        next_e: n,
        jrows,
    };
    b.zero_cone(st);
    let n_zero = b.rows.len();
    b.inequalities(st);
    // Cone elastic variables (one per cone, on its t entry) are allocated now so that
    // their non-negativity rows sit in the nonnegative block.
    let cone_e: Vec<usize> = (0..st.cone_blocks.len()).map(|k| b.next_e + k).collect();
    b.next_e += st.cone_blocks.len();
    for col in n..b.next_e {
        b.bound_row(RowKind::Elastic, col, -1.0);
    }
    let n_nonneg = b.rows.len() - n_zero;
    b.second_order_cones(st, &cone_e);
    let n_e = b.next_e - n;
    let mut cones = Vec::new();
    if n_zero > 0 {
        cones.push(SupportedConeT::ZeroConeT(n_zero));
    }
    if n_nonneg > 0 {
        cones.push(SupportedConeT::NonnegativeConeT(n_nonneg));
    }
    for &(_, dim) in st.cone_blocks {
        cones.push(SupportedConeT::SecondOrderConeT(dim));
    }
    let (a_colptr, a_rowval, a_src) = to_csc(n + n_e, b.a_trip);
    ConstraintLayout {
        rows: b.rows,
        n_e,
        cones,
        a_colptr,
        a_rowval,
        a_src,
        jrows: b.jrows,
    }
}

/// The fixed pattern of P and where the values of H, the diagonal and the augmented term
/// go.
struct PLayout {
    p_colptr: Vec<usize>,
    p_rowval: Vec<usize>,
    h_pos: Vec<usize>,
    diag_pos: Vec<usize>,
    jtj: Vec<(usize, usize, usize, usize)>,
}

/// The entries (column, row), row ≤ column, of P's upper triangle, sorted: B's
/// (transpose of the lower Hessian pattern, or a full triangle for BFGS) with the
/// diagonal, plus (augmented-Lagrangian convexification) the pattern of JᵀJ, so that
/// P = H + δI + ρ_a·(J_AᵀJ_A + I_b) is exactly the matrix `Convexify` certified positive
/// definite. The pattern of JᵀJ over all rows contains that of any active subset, so it
/// is fixed.
fn p_pattern(
    hess: &SymbolicSparseColMat<usize>,
    jrows: &[Vec<(usize, usize)>],
    n: usize,
    aug: bool,
    dense: bool,
) -> Vec<(usize, usize)> {
    let mut pat: Vec<(usize, usize)> = Vec::new();
    if dense {
        for j in 0..n {
            for i in 0..=j {
                pat.push((j, i));
            }
        }
    } else {
        for c in 0..n {
            for p in hess.col_range(c) {
                let r = hess.row_idx()[p];
                pat.push((r.max(c), r.min(c)));
            }
            pat.push((c, c));
        }
    }
    if aug {
        for row in jrows {
            for (a, &(ca, _)) in row.iter().enumerate() {
                for &(cb, _) in &row[a..] {
                    pat.push((ca.max(cb), ca.min(cb)));
                }
            }
        }
    }
    pat.sort_unstable();
    pat.dedup();
    pat
}

/// Lays out P for n variables and `ncols` QP columns (`jrows`: the Jacobian's entries by
/// row, for the augmented term; `dense`: a full upper triangle for BFGS).
fn p_layout(
    hess: &SymbolicSparseColMat<usize>,
    jrows: &[Vec<(usize, usize)>],
    n: usize,
    ncols: usize,
    aug: bool,
    dense: bool,
) -> PLayout {
    let pat = p_pattern(hess, jrows, n, aug, dense);
    let mut p_colptr = vec![0usize; ncols + 1];
    for &(c, _) in &pat {
        p_colptr[c + 1] += 1;
    }
    for c in 0..ncols {
        p_colptr[c + 1] += p_colptr[c];
    }
    let p_rowval: Vec<usize> = pat.iter().map(|&(_, r)| r).collect();
    let pos = |r: usize, c: usize| -> usize {
        let (r, c) = (r.min(c), r.max(c));
        let lo = p_colptr[c];
        lo + p_rowval[lo..p_colptr[c + 1]]
            .binary_search(&r)
            .expect("entry in the pattern of P")
    };
    let mut h_pos = vec![0usize; hess.row_idx().len()];
    let mut diag_pos = vec![0usize; n];
    if !dense {
        for c in 0..n {
            for p in hess.col_range(c) {
                h_pos[p] = pos(hess.row_idx()[p], c);
            }
        }
    }
    for (j, dp) in diag_pos.iter_mut().enumerate() {
        *dp = pos(j, j);
    }
    let mut jtj = Vec::new();
    if aug {
        for (i, row) in jrows.iter().enumerate() {
            for (a, &(ca, pa)) in row.iter().enumerate() {
                for &(cb, pb) in &row[a..] {
                    jtj.push((i, pa, pb, pos(ca, cb)));
                }
            }
        }
    }
    PLayout {
        p_colptr,
        p_rowval,
        h_pos,
        diag_pos,
        jtj,
    }
}

impl Qp {
    /// Lays out the QP for a problem with the Hessian pattern `hess` and the constraint
    /// structure `st`; `aug`: with the augmented term's pattern JᵀJ in P; `dense`: a full
    /// P for BFGS.
    pub fn new(
        hess: &SymbolicSparseColMat<usize>,
        st: &QpStructure,
        aug: bool,
        dense: bool,
        tol: f64,
        max_iter: u32,
    ) -> Qp {
        let (n, m) = (st.x_l.len(), st.g_l.len());
        let a = constraint_layout(st);
        let ncols = n + a.n_e;
        let pl = p_layout(hess, &a.jrows, n, ncols, aug, dense);
        Qp {
            n,
            m,
            n_e: a.n_e,
            b: vec![0.0; a.rows.len()],
            rows: a.rows,
            cones: a.cones,
            p_vals: vec![0.0; pl.p_rowval.len()],
            p_colptr: pl.p_colptr,
            p_rowval: pl.p_rowval,
            h_pos: pl.h_pos,
            diag_pos: pl.diag_pos,
            dense,
            a_vals: vec![0.0; a.a_src.len()],
            a_colptr: a.a_colptr,
            a_rowval: a.a_rowval,
            a_src: a.a_src,
            q: vec![0.0; ncols],
            tol,
            max_iter,
            solver: None,
            cone_blocks: st.cone_blocks.to_vec(),
            aug,
            stale: false,
            jrows: a.jrows,
            jtj: pl.jtj,
            jac_copy: Vec::new(),
            weight_copy: vec![0.0; m],
        }
    }

    /// Forgets the clarabel solver (its equilibration is that of earlier values) and
    /// takes new limits: the state of a new QP of this layout, for another solve of a
    /// problem with the same structure (`workspace.rs`).
    pub fn reset(&mut self, tol: f64, max_iter: u32) {
        self.solver = None;
        self.stale = false;
        self.tol = tol;
        self.max_iter = max_iter;
    }

    /// Number of elastic variables.
    pub fn n_elastic(&self) -> usize {
        self.n_e
    }

    /// Writes the values of `data` without solving (the active-set method solved this
    /// QP): a later [`Qp::resolve_with_g`] then hands all of them to clarabel.
    pub fn load(&mut self, data: &QpData) {
        self.fill(data);
        self.stale = true;
    }

    /// Whether the QP has the auxiliary variables of the augmented-Lagrangian term.
    pub fn has_aug(&self) -> bool {
        self.aug
    }

    fn settings(&self) -> DefaultSettings<f64> {
        DefaultSettings {
            verbose: false,
            presolve_enable: false,
            input_sparse_dropzeros: false,
            max_threads: 1,
            max_iter: self.max_iter,
            tol_gap_abs: self.tol,
            tol_gap_rel: self.tol,
            tol_feas: self.tol,
            tol_ktratio: 1e-8,
            direct_solve_method: "qdldl".into(),
            ..DefaultSettings::default()
        }
    }

    /// Writes P, q, A, b from `data`.
    fn fill(&mut self, data: &QpData) {
        let n = self.n;
        // P
        self.p_vals.iter_mut().for_each(|v| *v = 0.0);
        if let (true, Some(bd)) = (self.dense, data.dense_b) {
            let mut k = 0;
            for j in 0..n {
                for i in 0..=j {
                    self.p_vals[k] = bd[i + j * n];
                    k += 1;
                }
            }
        } else {
            for (p, &h) in data.hess.iter().enumerate() {
                self.p_vals[self.h_pos[p]] += h;
            }
            for j in 0..n {
                self.p_vals[self.diag_pos[j]] += data.shift + data.bound_weight[j];
            }
            if self.aug {
                for &(i, pa, pb, pos) in &self.jtj {
                    let w = data.row_weight[i];
                    if w != 0.0 {
                        // Off-diagonal pairs appear once in the upper triangle; a pair
                        // (a, a) is the diagonal entry w·J_ia².
                        self.p_vals[pos] += w * data.jac[pa] * data.jac[pb];
                    }
                }
                self.jac_copy.clear();
                self.jac_copy.extend_from_slice(data.jac);
                self.weight_copy.copy_from_slice(data.row_weight);
            }
        }
        // q
        self.q[..n].copy_from_slice(data.grad);
        let n_e = self.n_e;
        self.q[n..n + n_e].iter_mut().for_each(|v| *v = data.rho);
        // A
        for (v, s) in self.a_vals.iter_mut().zip(&self.a_src) {
            *v = match *s {
                Src::Jac(p, sign) => sign * data.jac[p],
                Src::ConeJac(p, sign) => sign * data.cone_jac[p],
                Src::Const(c) => c,
            };
        }
        self.fill_b(
            data.x, data.x_l, data.x_u, data.g, data.g_l, data.g_u, data.cone,
        );
    }

    /// Writes b for constraint values `g` (possibly corrected, for a second-order
    /// correction) at x.
    #[allow(clippy::too_many_arguments)]
    fn fill_b(
        &mut self,
        x: &[f64],
        x_l: &[f64],
        x_u: &[f64],
        g: &[f64],
        g_l: &[f64],
        g_u: &[f64],
        cone: &[f64],
    ) {
        for (b, kind) in self.b.iter_mut().zip(&self.rows) {
            *b = match *kind {
                RowKind::EqG(i) => g_l[i] - g[i],
                RowKind::UpperG(i) => g_u[i] - g[i],
                RowKind::LowerG(i) => g[i] - g_l[i],
                RowKind::Fixed(j) | RowKind::UpperX(j) => x_u[j] - x[j],
                RowKind::LowerX(j) => x[j] - x_l[j],
                RowKind::Elastic => 0.0,
                RowKind::Cone(k) => cone[k],
            };
        }
    }

    fn build(&mut self) -> Result<(), QpError> {
        let ncols = self.q.len();
        let p = CscMatrix::new(
            ncols,
            ncols,
            self.p_colptr.clone(),
            self.p_rowval.clone(),
            self.p_vals.clone(),
        );
        let a = CscMatrix::new(
            self.b.len(),
            ncols,
            self.a_colptr.clone(),
            self.a_rowval.clone(),
            self.a_vals.clone(),
        );
        let s = DefaultSolver::new(&p, &self.q, &a, &self.b, &self.cones, self.settings())?;
        self.solver = Some(s);
        Ok(())
    }

    /// Solves the QP for `data`: reuses the clarabel solver with new values when it
    /// exists, rebuilding it (fresh equilibration) if that fails to converge.
    pub fn solve(&mut self, data: &QpData) -> Result<QpResult, QpError> {
        self.fill(data);
        self.run(true)
    }

    /// Solves again with only the constraint constants changed (second-order
    /// correction: `g` holds the corrected values ĝ = g(x + d) − J d).
    #[allow(clippy::too_many_arguments)]
    pub fn resolve_with_g(
        &mut self,
        x: &[f64],
        x_l: &[f64],
        x_u: &[f64],
        g: &[f64],
        g_l: &[f64],
        g_u: &[f64],
        cone: &[f64],
    ) -> Result<QpResult, QpError> {
        self.fill_b(x, x_l, x_u, g, g_l, g_u, cone);
        self.run(false)
    }

    fn run(&mut self, all: bool) -> Result<QpResult, QpError> {
        let all = all || std::mem::take(&mut self.stale);
        let mut fresh = false;
        match self.solver.as_mut() {
            None => {
                self.build()?;
                fresh = true;
            }
            Some(s) => {
                let r = if all {
                    s.update_P(&self.p_vals)
                        .and_then(|_| s.update_q(&self.q))
                        .and_then(|_| s.update_A(&self.a_vals))
                        .and_then(|_| s.update_b(&self.b))
                } else {
                    s.update_b(&self.b)
                };
                if r.is_err() {
                    self.build()?;
                    fresh = true;
                }
            }
        }
        let mut s = self.solver.as_mut().expect("built above");
        s.solve();
        let ok = |st: SolverStatus| matches!(st, SolverStatus::Solved | SolverStatus::AlmostSolved);
        if !ok(s.solution.status) && !fresh {
            // Equilibration from an earlier QP may be poor for these values: start over.
            self.build()?;
            s = self.solver.as_mut().expect("built above");
            s.solve();
        }
        let sol = &s.solution;
        let n = self.n;
        let mut res = QpResult {
            d: sol.x[..n].to_vec(),
            e: sol.x[n..n + self.n_e].to_vec(),
            z_w: vec![0.0; self.m],
            lambda: vec![0.0; self.m],
            z_l: vec![0.0; n],
            z_u: vec![0.0; n],
            z_cone: vec![
                0.0;
                self.cone_blocks
                    .iter()
                    .map(|&(o, d)| o + d)
                    .max()
                    .unwrap_or(0)
            ],
            status: sol.status,
            iterations: sol.iterations,
        };
        for (r, kind) in self.rows.iter().enumerate() {
            let z = sol.z[r];
            match *kind {
                RowKind::EqG(i) | RowKind::UpperG(i) => res.lambda[i] += z,
                RowKind::LowerG(i) => res.lambda[i] -= z,
                RowKind::Fixed(j) => {
                    res.z_u[j] = z.max(0.0);
                    res.z_l[j] = (-z).max(0.0);
                }
                RowKind::UpperX(j) => res.z_u[j] = z,
                RowKind::LowerX(j) => res.z_l[j] = z,
                RowKind::Elastic => {}
                RowKind::Cone(k) => res.z_cone[k] = z,
            }
        }
        if self.aug {
            // Row multiplier of the augmented QP: the term ½ρ_a(J_i d)² adds ρ_a·J_i d to
            // the dual of row i (→ λ_i as d → 0).
            for (i, row) in self.jrows.iter().enumerate() {
                let w = self.weight_copy[i];
                if w != 0.0 {
                    let jd: f64 = row.iter().map(|&(c, p)| self.jac_copy[p] * res.d[c]).sum();
                    res.z_w[i] = w * jd;
                }
            }
        }
        Ok(res)
    }
}
