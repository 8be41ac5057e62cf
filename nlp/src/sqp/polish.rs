//! Active-set polishing of a QP step (as OSQP's `polish`): clarabel's interior-point
//! solution identifies the QP's active set W; the equality-constrained QP on W
//!
//! ```text
//! [ B   J_Wᵀ ] [d]   [ −∇f ]
//! [ J_W  0   ] [λ] = [ r_W ]      (bounds in W fixed: d_j = bound_j − x_j)
//! ```
//!
//! is then solved directly with the faer LDLᵀ ([`Kkt`]), and the result replaces
//! clarabel's if it is a KKT point of the inequality QP: the inertia says B is positive
//! definite on the null space of J_W, the rows and bounds outside W hold, and the
//! multipliers of W have the active side's sign.
//!
//! Why: clarabel stops at a relative accuracy of its (equilibrated) problem. When the
//! reduced Hessian has curvatures many orders of magnitude apart — the gap-crossing
//! planner on flat ground: CoM weight 1000 against force weight 0.001, and the tangential
//! forces determined only by the latter — the step's error in the flat directions
//! (QP stationarity residual 1e-5–1e-3) is larger than the step itself near the
//! solution, and the SQP crept for its 3000 iterations at ‖d‖ ≈ 1e-3 with a dual
//! infeasibility stuck at 1e-6. The polished step is the exact Newton step of the active
//! set, so the local convergence is the SQP's (superlinear) again.

use faer::sparse::SymbolicSparseColMat;

use super::qp::{QpData, QpResult};
use crate::frontend::scaled::refill;
use crate::kkt::Kkt;

/// Side of a row or bound in the working set.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub(super) enum Side {
    Free,
    Lower,
    Upper,
    Both,
}

/// Clarabel's active set W: the side of each row and bound, active when its multiplier
/// exceeds its slack (the larger of the complementary pair).
#[derive(Clone, PartialEq, Eq, Hash, Debug)]
pub(super) struct WorkingSet {
    pub rows: Vec<Side>,
    pub vars: Vec<Side>,
}

impl WorkingSet {
    /// W from clarabel's solution `res`; `None` when a row or bound of the augmented term
    /// left W (the polished step, without the term, would solve another QP).
    fn from_qp(p: &QpData, jp: &SymbolicSparseColMat<usize>, res: &QpResult) -> Option<Self> {
        let (n, m) = (p.x.len(), p.g.len());
        let jd = jac_times(p, jp, &res.d);
        let mut rows = vec![Side::Free; m];
        for i in 0..m {
            let lin = p.g[i] + jd[i];
            rows[i] = if p.g_l[i] == p.g_u[i] {
                Side::Both
            } else if p.g_u[i].is_finite() && res.lambda[i] > 0.0 && res.lambda[i] > p.g_u[i] - lin
            {
                Side::Upper
            } else if p.g_l[i].is_finite() && res.lambda[i] < 0.0 && -res.lambda[i] > lin - p.g_l[i]
            {
                Side::Lower
            } else {
                Side::Free
            };
            if p.row_weight[i] > 0.0 && rows[i] == Side::Free {
                return None;
            }
        }
        let mut vars = vec![Side::Free; n];
        for j in 0..n {
            let xn = p.x[j] + res.d[j];
            vars[j] = if p.x_l[j] == p.x_u[j] {
                Side::Both
            } else if p.x_u[j].is_finite() && res.z_u[j] > 0.0 && res.z_u[j] > p.x_u[j] - xn {
                Side::Upper
            } else if p.x_l[j].is_finite() && res.z_l[j] > 0.0 && res.z_l[j] > xn - p.x_l[j] {
                Side::Lower
            } else {
                Side::Free
            };
            if p.bound_weight[j] > 0.0 && vars[j] == Side::Free {
                return None;
            }
        }
        Some(WorkingSet { rows, vars })
    }

    /// The step of a bound in W: to that bound.
    fn target(&self, p: &QpData, j: usize) -> f64 {
        match self.vars[j] {
            Side::Lower => p.x_l[j] - p.x[j],
            Side::Upper | Side::Both => p.x_u[j] - p.x[j],
            Side::Free => 0.0,
        }
    }
}

/// J·v for the Jacobian values of `p`.
pub(super) fn jac_times(p: &QpData, jp: &SymbolicSparseColMat<usize>, v: &[f64]) -> Vec<f64> {
    let mut jd = Vec::new();
    jac_times_into(p, jp, v, &mut jd);
    jd
}

/// [`jac_times`] into `jd` (resized; no allocation once it has grown to m).
pub(super) fn jac_times_into(
    p: &QpData,
    jp: &SymbolicSparseColMat<usize>,
    v: &[f64],
    jd: &mut Vec<f64>,
) {
    refill(jd, p.g.len(), 0.0);
    for c in 0..p.x.len() {
        for q in jp.col_range(c) {
            jd[jp.row_idx()[q]] += p.jac[q] * v[c];
        }
    }
}

/// The work vectors of [`equality_qp_step`] (kept between QPs: no allocation once they
/// have grown to the sizes): the KKT diagonals, the right-hand side and the shift.
#[derive(Default)]
pub(super) struct EqScratch {
    dx: Vec<f64>,
    dc: Vec<f64>,
    rhs: Vec<f64>,
    shift: Vec<f64>,
}

/// The equality QP on W: `[B, J_Wᵀ; J_W, 0]·(d, λ) = (−∇f, r_W)`, the bounds of W fixed by
/// a large diagonal and the zero block recovered from a 1e-10 regularisation by
/// iterative refinement. The augmented term of rows and bounds outside W enters exactly:
/// a row i with weight w_i > 0 gets the diagonal −1/w_i (its multiplier is then
/// w_i·J_i d, the term's gradient), a bound weight is added to the diagonal of B (rows
/// and bounds of W need neither: the term is constant on W). `None` unless the inertia is
/// (n, m) and the solve accurate. The two halves, [`factor_working_set_in`] and
/// [`solve_working_set_into`], may run apart (the real-time iteration factorises before the
/// new initial state is known).
pub(super) fn equality_qp_step(
    kkt: &mut Kkt,
    p: &QpData,
    w: &WorkingSet,
    n_fact: &mut usize,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let (mut scratch, mut d, mut lambda) = (EqScratch::default(), Vec::new(), Vec::new());
    equality_qp_step_into(kkt, p, w, n_fact, &mut scratch, (&mut d, &mut lambda))
        .then_some((d, lambda))
}

/// [`equality_qp_step`] in `scratch`'s vectors, the step and multipliers written into
/// `d` and `lambda` (resized); `false` where it gives `None`.
pub(super) fn equality_qp_step_into(
    kkt: &mut Kkt,
    p: &QpData,
    w: &WorkingSet,
    n_fact: &mut usize,
    scratch: &mut EqScratch,
    out: (&mut Vec<f64>, &mut Vec<f64>),
) -> bool {
    factor_working_set_in(kkt, p, w, n_fact, scratch)
        && solve_working_set_into(kkt, p, w, scratch, out)
}

/// Regularisation of the zero block of W's rows, removed again by iterative refinement.
pub(super) const ZERO_BLOCK_REG: f64 = 1e-10;

/// The diagonal weight that fixes a bound of W (far above the Hessian's entries).
fn fixing_weight(p: &QpData) -> f64 {
    1e14 * p.hess.iter().fold(1.0f64, |a, v| a.max(v.abs()))
}

/// Factorises the KKT matrix of W's equality QP (see [`equality_qp_step`]): it depends on
/// B, J, the weights and W, not on the constraint values or the point. `false` unless the
/// inertia is (n, m).
/// The diagonals are in `scratch`'s vectors.
pub(super) fn factor_working_set_in(
    kkt: &mut Kkt,
    p: &QpData,
    w: &WorkingSet,
    n_fact: &mut usize,
    scratch: &mut EqScratch,
) -> bool {
    let (n, m) = (p.x.len(), p.g.len());
    let big = fixing_weight(p);
    let EqScratch { dx, dc, .. } = scratch;
    dx.clear();
    dx.extend((0..n).map(|j| {
        p.shift
            + if w.vars[j] == Side::Free {
                p.bound_weight[j]
            } else {
                big
            }
    }));
    dc.clear();
    dc.extend((0..m).map(|i| match (w.rows[i], p.row_weight[i]) {
        (Side::Free, r) if r > 0.0 => 1.0 / r,
        (Side::Free, _) => 1e20,
        _ => ZERO_BLOCK_REG,
    }));
    *n_fact += 1;
    matches!(kkt.factorize(p.hess, dx, p.jac, dc),
        Ok(inertia) if inertia.positive == n && inertia.negative == m)
}

/// Solves W's equality QP with the factorisation [`factor_working_set_in`] left in `kkt`
/// for the same B, J, weights and W (the point and the constraint values may differ),
/// in `scratch`'s vectors; the step and multipliers are written into `d` and `lambda`
/// (resized). `false` when the solve is inaccurate.
pub(super) fn solve_working_set_into(
    kkt: &mut Kkt,
    p: &QpData,
    w: &WorkingSet,
    scratch: &mut EqScratch,
    (d, lambda): (&mut Vec<f64>, &mut Vec<f64>),
) -> bool {
    let (n, m) = (p.x.len(), p.g.len());
    let big = fixing_weight(p);
    let EqScratch { rhs, shift, .. } = scratch;
    refill(rhs, n + m, 0.0);
    for j in 0..n {
        rhs[j] = -p.grad[j]
            + if w.vars[j] == Side::Free {
                0.0
            } else {
                big * w.target(p, j)
            };
    }
    for i in 0..m {
        rhs[n + i] = match w.rows[i] {
            Side::Free => 0.0,
            Side::Lower => p.g_l[i] - p.g[i],
            Side::Upper | Side::Both => p.g_u[i] - p.g[i],
        };
    }
    if !solve_exact_zero_block(kkt, w, rhs, shift) {
        return false;
    }
    d.clear();
    d.extend_from_slice(&rhs[..n]);
    lambda.clear();
    lambda.extend_from_slice(&rhs[n..]);
    for j in 0..n {
        if w.vars[j] != Side::Free {
            d[j] = w.target(p, j);
        }
    }
    for i in 0..m {
        if w.rows[i] == Side::Free && p.row_weight[i] == 0.0 {
            lambda[i] = 0.0;
        }
    }
    true
}

/// Solves with the factorisation of W's equality QP in `kkt` in place of `rhs`, the
/// regularisation of W's rows removed by refinement (the exact zero block; `shift`: its
/// work vector). `false` when the solve is inaccurate.
fn solve_exact_zero_block(
    kkt: &mut Kkt,
    w: &WorkingSet,
    rhs: &mut [f64],
    shift: &mut Vec<f64>,
) -> bool {
    let n = kkt.n();
    shift.clear();
    shift.extend((0..rhs.len()).map(|k| {
        if k >= n && w.rows[k - n] != Side::Free {
            ZERO_BLOCK_REG
        } else {
            0.0
        }
    }));
    matches!(kkt.solve_shifted(rhs, Some(shift)), Ok(ratio) if ratio <= 1e-8)
}

/// One more step of iterative refinement of W's equality QP solution `(d, lambda)` (from
/// [`solve_working_set_into`] with the factorisation still in `kkt`), on its residual
/// computed in the QP's own terms: `s` the stationarity B d + ∇f + Jᵀλ, `jd` = J d. The
/// refinement inside the solve judges its residual relative to the whole right-hand side,
/// which the fixing weights of W's bounds dominate (≈ 1e14·|H|·|target|): it can stop
/// with W's rows still off by the zero block's regularisation ε·λ_i, which with large
/// multipliers exceeds the feasibility tolerance (rows of hs116 at the IPM's optimum:
/// λ ≈ 16, off by 1.6e-9). Here the right-hand side is that residual alone. `false` when
/// the correction's solve is inaccurate.
pub(super) fn correct_working_set_step_in(
    kkt: &mut Kkt,
    p: &QpData,
    w: &WorkingSet,
    (s, jd): (&[f64], &[f64]),
    scratch: &mut EqScratch,
    (d, lambda): (&mut [f64], &mut [f64]),
) -> bool {
    let (n, m) = (p.x.len(), p.g.len());
    let EqScratch { rhs, shift, .. } = scratch;
    refill(rhs, n + m, 0.0);
    for j in 0..n {
        // A bound of W is met exactly (d_j is its target); its equation holds with the
        // implicit bound multiplier.
        if w.vars[j] == Side::Free {
            rhs[j] = -s[j];
        }
    }
    for i in 0..m {
        rhs[n + i] = match (w.rows[i], p.row_weight[i]) {
            (Side::Free, r) if r > 0.0 => lambda[i] / r - jd[i],
            (Side::Free, _) => 0.0,
            (Side::Lower, _) => p.g_l[i] - p.g[i] - jd[i],
            (Side::Upper | Side::Both, _) => p.g_u[i] - p.g[i] - jd[i],
        };
    }
    if !solve_exact_zero_block(kkt, w, rhs, shift) {
        return false;
    }
    for j in 0..n {
        if w.vars[j] == Side::Free {
            d[j] += rhs[j];
        }
    }
    for i in 0..m {
        if w.rows[i] != Side::Free || p.row_weight[i] != 0.0 {
            lambda[i] += rhs[n + i];
        }
    }
    true
}

/// The QP's stationarity residual without bound multipliers, B d + ∇f + Jᵀλ (with the
/// bound weights of B; `lambda` the rows' total multipliers, augmented term included).
pub(super) fn stationarity(
    p: &QpData,
    pats: (&SymbolicSparseColMat<usize>, &SymbolicSparseColMat<usize>),
    d: &[f64],
    lambda: &[f64],
) -> Vec<f64> {
    let mut s = Vec::new();
    stationarity_into(p, pats, d, lambda, &mut s);
    s
}

/// [`stationarity`] into `s` (resized; no allocation once it has grown to n).
pub(super) fn stationarity_into(
    p: &QpData,
    (jp, hp): (&SymbolicSparseColMat<usize>, &SymbolicSparseColMat<usize>),
    d: &[f64],
    lambda: &[f64],
    s: &mut Vec<f64>,
) {
    let n = p.x.len();
    s.clear();
    s.extend_from_slice(p.grad);
    for c in 0..n {
        s[c] += (p.shift + p.bound_weight[c]) * d[c];
        for q in hp.col_range(c) {
            let r = hp.row_idx()[q];
            s[r] += p.hess[q] * d[c];
            if r != c {
                s[c] += p.hess[q] * d[r];
            }
        }
        for q in jp.col_range(c) {
            s[c] += p.jac[q] * lambda[jp.row_idx()[q]];
        }
    }
}

/// Bound multipliers from the QP's stationarity, z_l − z_u = B d + ∇f + Jᵀλ (with the
/// augmented weight ρ_a of an active bound in B: the QP's own bound multiplier, as
/// clarabel's), and the multiplier tolerance; `None` when a free variable is not
/// stationary or a bound multiplier of W has the wrong sign.
fn bound_multipliers(
    p: &QpData,
    (jp, hp): (&SymbolicSparseColMat<usize>, &SymbolicSparseColMat<usize>),
    w: &WorkingSet,
    d: &[f64],
    lambda: &[f64],
) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let n = p.x.len();
    let s = stationarity(p, (jp, hp), d, lambda);
    let mut z_l = vec![0.0; n];
    let mut z_u = vec![0.0; n];
    let lam_max = lambda.iter().chain(&s).fold(1.0f64, |a, v| a.max(v.abs()));
    let mult_tol = 1e-8 * lam_max;
    // Absolute accuracy of stationarity, on the scale of the objective's gradient (the
    // solve's residual ratio is relative to the solution, which near-dependent rows of
    // J_W make huge: then it passes while rows of W are not met).
    let grad_max = p.grad.iter().fold(1.0f64, |a, v| a.max(v.abs()));
    for j in 0..n {
        match w.vars[j] {
            // Stationarity holds for free variables by construction; a large residual
            // means the solve failed.
            Side::Free if s[j].abs() > 1e-8 * grad_max => return None,
            Side::Free => {}
            Side::Lower if s[j] < -mult_tol => return None,
            Side::Lower => z_l[j] = s[j].max(0.0),
            Side::Upper if s[j] > mult_tol => return None,
            Side::Upper => z_u[j] = (-s[j]).max(0.0),
            Side::Both => {
                z_l[j] = s[j].max(0.0);
                z_u[j] = (-s[j]).max(0.0);
            }
        }
    }
    Some((z_l, z_u, mult_tol))
}

/// Whether the rows and bounds outside W hold at `x + d`, W's rows are met and their QP
/// multipliers (λ_i − ρ_a·J_i d, with `jd` = J d) have the active side's sign.
fn consistent(
    p: &QpData,
    w: &WorkingSet,
    d: &[f64],
    lambda: &[f64],
    jd: &[f64],
    mult_tol: f64,
) -> bool {
    let tol = |b: f64| 1e-9 * (1.0 + b.abs());
    let rows_ok = (0..p.g.len()).all(|i| {
        let lin = p.g[i] + jd[i];
        let l_qp = lambda[i] - p.row_weight[i] * jd[i];
        match w.rows[i] {
            Side::Free => lin <= p.g_u[i] + tol(p.g_u[i]) && lin >= p.g_l[i] - tol(p.g_l[i]),
            Side::Upper => l_qp >= -mult_tol && (lin - p.g_u[i]).abs() <= tol(p.g_u[i]),
            Side::Lower => l_qp <= mult_tol && (lin - p.g_l[i]).abs() <= tol(p.g_l[i]),
            Side::Both => (lin - p.g_u[i]).abs() <= tol(p.g_u[i]),
        }
    });
    rows_ok
        && (0..p.x.len()).all(|j| {
            let xn = p.x[j] + d[j];
            w.vars[j] != Side::Free
                || (xn <= p.x_u[j] + tol(p.x_u[j]) && xn >= p.x_l[j] - tol(p.x_l[j]))
        })
}

/// The polished QP result, or `None` when clarabel's active set does not give a KKT point
/// of the QP (then clarabel's solution stands). `jp`, `hp` are the patterns of
/// `p.jac` and `p.hess`. Counts one factorisation in `n_fact`.
pub(crate) fn polish(
    kkt: &mut Kkt,
    p: &QpData,
    jp: &SymbolicSparseColMat<usize>,
    hp: &SymbolicSparseColMat<usize>,
    res: &QpResult,
    n_fact: &mut usize,
) -> Option<QpResult> {
    let m = p.g.len();
    if kkt.n() != p.x.len() || kkt.m() != m {
        return None;
    }
    let w = WorkingSet::from_qp(p, jp, res)?;
    let (d, lambda) = equality_qp_step(kkt, p, &w, n_fact)?;
    let (z_l, z_u, mult_tol) = bound_multipliers(p, (jp, hp), &w, &d, &lambda)?;
    let jd = jac_times(p, jp, &d);
    if !consistent(p, &w, &d, &lambda, &jd, mult_tol) {
        return None;
    }
    // A refinement, not another solution: the multipliers must agree with clarabel's.
    // They do not when the rows and bounds of W are (nearly) linearly dependent (the
    // multipliers are not unique; hs013's cusp: clarabel 1e6, the equality QP 1e2), and
    // there the exact active-set step of a degenerate QP only made the SQP cycle.
    let lam_cl = |i: usize| res.lambda[i] + res.z_w[i];
    let lam_scale = (0..m).fold(1.0f64, |a, i| a.max(lam_cl(i).abs()));
    let lam_diff = (0..m).fold(0.0f64, |a, i| a.max((lambda[i] - lam_cl(i)).abs()));
    if lam_diff > 0.1 * lam_scale {
        return None;
    }
    // The result in the QP's convention: with the augmented term ½ρ_a(J_i d)² the QP's
    // own multiplier is λ_i − ρ_a·J_i d (the share ρ_a·J_i d is `z_w`).
    let z_w: Vec<f64> = (0..m).map(|i| p.row_weight[i] * jd[i]).collect();
    let lambda_qp: Vec<f64> = (0..m).map(|i| lambda[i] - z_w[i]).collect();
    Some(QpResult {
        d,
        e: vec![0.0; res.e.len()],
        lambda: lambda_qp,
        z_l,
        z_u,
        z_cone: res.z_cone.clone(),
        z_w,
        status: res.status,
        iterations: res.iterations,
    })
}
