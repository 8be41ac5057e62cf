//! A warm-started primal-dual active-set method for the SQP's QP subproblem (without
//! elastic variables, cones or a dense BFGS matrix):
//!
//! ```text
//! min ½ dᵀ B d + ∇fᵀ d   s.t.  g_l ≤ g + J d ≤ g_u,   x_l ≤ x + d ≤ x_u
//! ```
//!
//! with B = H + δI + ρ_a·(J_AᵀJ_A + I_b) as `Convexify` built it. Each iteration solves
//! the equality QP of a working set W exactly with the faer LDLᵀ of the KKT matrix
//! (`polish::equality_qp_step`, whose inertia test also certifies that B is positive
//! definite on the null space of W) and then moves every row and bound whose sign test
//! fails (Hintermüller, Ito & Kunisch 2002, the primal-dual active-set strategy as a
//! semismooth Newton method): a row or bound outside W that the step violates enters W
//! on the violated side; a row or bound of W whose multiplier has the wrong sign leaves.
//! When nothing moves, the step and its multipliers are a KKT point of the QP, checked
//! with the same tolerances as polishing. Started from the previous QP's working set
//! (qpOASES' hot start), a QP of an SQP near convergence, or of a warm-started MPC step,
//! usually needs one or two factorisations where clarabel's interior point needs 10–20.
//!
//! When the total violation of the proposed changes stops falling, the method applies
//! only the largest half of them, and so on down to one (`ChangeBudget`); when a working
//! set repeats, one entry per iteration (the largest violation) from then on. It gives
//! up (`Err`, and the caller solves the QP with clarabel) when a working set repeats
//! again, after `max_iter` iterations, and when the equality QP of a working set is
//! singular or has the wrong inertia (dependent active rows, or B not convex on W's null
//! space). A solution whose multipliers exceed the ℓ1 penalty ρ is the elastic QP's only
//! for a larger ρ ([`penalty_for`]).

use std::hash::{DefaultHasher, Hash, Hasher};

use faer::sparse::SymbolicSparseColMat;

use super::iterate::Mult;
use super::polish::{
    correct_working_set_step_in, equality_qp_step_into, jac_times_into, solve_working_set_into,
    stationarity_into, EqScratch, Side, WorkingSet,
};
use super::qp::{QpData, QpResult};
use crate::frontend::scaled::refill;
use crate::kkt::Kkt;

/// Why the active-set method gave up on a QP (the caller falls back to clarabel); as
/// `usize`, the index into `Work::active_set_failures`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Failure {
    /// The KKT matrix or the problem sizes do not fit.
    Shape,
    /// The equality QP of a working set was singular, had the wrong inertia or was
    /// solved inaccurately.
    EqualityQp,
    /// A working set came back (cycling).
    Cycle,
    /// `max_iter` iterations without a KKT point.
    IterationLimit,
}

/// How often one QP step may raise the ℓ1 penalty ρ (elastic mode, [`penalty_for`]).
pub(super) const MAX_PENALTY_INCREASES: usize = 11;

/// The ℓ1 penalty for which a QP solution with multipliers up to `max_multiplier` is
/// also the elastic QP's: `rho` itself when it suffices, otherwise the first of
/// ρ·f, ρ·f², … (`f` = `increase`, at most `max_increases` times, at most `rho_max`) that
/// does: the ρ that clarabel's elastic mode reaches by the same increases, each of which
/// lowers its Σe while the linearisation is consistent. `None` when no allowed ρ does.
pub(super) fn penalty_for(
    max_multiplier: f64,
    rho: f64,
    (increase, max_increases, rho_max): (f64, usize, f64),
) -> Option<f64> {
    let mut r = rho;
    for _ in 0..max_increases {
        if max_multiplier <= r {
            return Some(r);
        }
        r = (r * increase).min(rho_max);
    }
    (max_multiplier <= r).then_some(r)
}

/// The working set guessed from multipliers at the point of `p` (a warm start without a
/// previous QP): equality rows and fixed variables always; an inequality side or a
/// bound when its multiplier has the side's sign and exceeds its slack.
/// Written into `w` (resized; no allocation once its vectors have grown to the sizes).
pub(super) fn guess_into(p: &QpData, mult: &Mult, w: &mut WorkingSet) {
    let (n, m) = (p.x.len(), p.g.len());
    w.rows.clear();
    w.rows.extend((0..m).map(|i| {
        let l = mult.lambda[i];
        if p.g_l[i] == p.g_u[i] {
            Side::Both
        } else if p.g_u[i].is_finite() && l > 0.0 && l > p.g_u[i] - p.g[i] {
            Side::Upper
        } else if p.g_l[i].is_finite() && l < 0.0 && -l > p.g[i] - p.g_l[i] {
            Side::Lower
        } else {
            Side::Free
        }
    }));
    w.vars.clear();
    w.vars.extend((0..n).map(|j| {
        let (zl, zu) = (mult.z_l[j], mult.z_u[j]);
        if p.x_l[j] == p.x_u[j] {
            Side::Both
        } else if p.x_u[j].is_finite() && zu > 0.0 && zu > p.x_u[j] - p.x[j] {
            Side::Upper
        } else if p.x_l[j].is_finite() && zl > 0.0 && zl > p.x[j] - p.x_l[j] {
            Side::Lower
        } else {
            Side::Free
        }
    }));
}

/// Whether `w` fits the problem of `p` (sizes, and fixed entries where `p` has them).
pub(super) fn fits(w: &WorkingSet, p: &QpData) -> bool {
    w.rows.len() == p.g.len()
        && w.vars.len() == p.x.len()
        && (0..p.g.len()).all(|i| (w.rows[i] == Side::Both) == (p.g_l[i] == p.g_u[i]))
        && (0..p.x.len()).all(|j| (w.vars[j] == Side::Both) == (p.x_l[j] == p.x_u[j]))
}

/// A hash of `w` (the same in every run).
fn hash_of(w: &WorkingSet) -> u64 {
    let mut h = DefaultHasher::new();
    w.hash(&mut h);
    h.finish()
}

/// The work vectors of [`solve_in`], kept between QPs (no allocation once they have
/// grown to the sizes and the most iterations seen).
#[derive(Default)]
pub(super) struct Scratch {
    /// Hashes of the working sets met.
    seen: Vec<u64>,
    changes: Vec<Change>,
    eq: EqScratch,
    d: Vec<f64>,
    lambda: Vec<f64>,
    s: Vec<f64>,
    jd: Vec<f64>,
}

/// What [`solve_in`] reports besides the result: the active-set iterations (=
/// factorisations) and the largest |λ_i| of the rows: the solution is the elastic QP's
/// (zero elastic variables) only for ρ ≥ this (see [`penalty_for`]).
pub(super) struct Found {
    pub iterations: usize,
    pub max_multiplier: f64,
}

/// Solves the QP of `p` from the working set `w` (see the module documentation) in
/// place: `w` ends as the solution's (on failure: the last one tried), the result is
/// written into `res` (its vectors reused), the work vectors are `scratch`'s. `jp`, `hp`:
/// the patterns of `p.jac` and `p.hess`; `n_elastic`: the length of the (zero) elastic
/// part of the result; every factorisation is counted in `n_fact`. `factored`: `kkt`
/// already holds the factorisation of `w`'s equality QP for this B, J and weights
/// (`polish::factor_working_set_in`, the real-time iteration's preparation), so the
/// first iteration only solves with it.
pub(super) fn solve_in(
    kkt: &mut Kkt,
    p: &QpData,
    (jp, hp): (&SymbolicSparseColMat<usize>, &SymbolicSparseColMat<usize>),
    (w, res): (&mut WorkingSet, &mut QpResult),
    (max_iter, n_elastic): (usize, usize),
    (n_fact, factored): (&mut usize, bool),
    scratch: &mut Scratch,
) -> Result<Found, Failure> {
    let (n, m) = (p.x.len(), p.g.len());
    if kkt.n() != n || kkt.m() != m || !fits(w, p) {
        return Err(Failure::Shape);
    }
    let Scratch {
        seen,
        changes,
        eq,
        d,
        lambda,
        s,
        jd,
    } = scratch;
    // Hashes of the working sets met (a deterministic SipHash; two different sets with
    // the same hash would only end the method early, never change its result).
    seen.clear();
    changes.clear();
    let mut budget = ChangeBudget::new();
    for iteration in 1..=max_iter {
        let solved = if factored && iteration == 1 {
            solve_working_set_into(kkt, p, w, eq, (d, lambda))
        } else {
            equality_qp_step_into(kkt, p, w, n_fact, eq, (d, lambda))
        };
        if !solved {
            return Err(Failure::EqualityQp);
        }
        let pats = (jp, hp);
        test_step(
            kkt,
            p,
            pats,
            w,
            eq,
            (&mut *d, &mut *lambda, &mut *s, &mut *jd),
            changes,
        );
        let step = Step { d, lambda, s, jd };
        if changes.is_empty() {
            let max_multiplier = kkt_point(p, w, step, n_elastic, res)?;
            res.iterations = iteration as u32;
            return Ok(Found {
                iterations: iteration,
                max_multiplier,
            });
        }
        if iteration > FULL_STEPS {
            budget.observe(changes);
        }
        keep_largest(changes, budget.limit);
        seen.push(hash_of(w));
        for &(k, side, _) in changes.iter() {
            if k < m {
                w.rows[k] = side;
            } else {
                w.vars[k - m] = side;
            }
        }
        if seen.contains(&hash_of(w)) {
            if budget.limit == 1 {
                return Err(Failure::Cycle);
            }
            budget.limit = 1;
            seen.clear();
        }
    }
    Err(Failure::IterationLimit)
}

/// The residuals of W's step `(d, lambda)` (into `s` and `jd`) and its sign test (into
/// `changes`). A candidate solution (nothing to change) whose rows of W are off by more
/// than the feasibility tolerance gets one more refinement step
/// ([`correct_working_set_step_in`]) before it is judged, and the test is repeated on
/// the corrected step.
#[allow(clippy::type_complexity)]
fn test_step(
    kkt: &mut Kkt,
    p: &QpData,
    (jp, hp): (&SymbolicSparseColMat<usize>, &SymbolicSparseColMat<usize>),
    w: &WorkingSet,
    eq: &mut EqScratch,
    (d, lambda, s, jd): (&mut [f64], &mut [f64], &mut Vec<f64>, &mut Vec<f64>),
    changes: &mut Vec<Change>,
) {
    stationarity_into(p, (jp, hp), d, lambda, s);
    jac_times_into(p, jp, d, jd);
    sign_test(p, w, &Step { d, lambda, s, jd }, changes);
    if changes.is_empty()
        && !rows_met(p, w, jd)
        && correct_working_set_step_in(kkt, p, w, (s, jd), eq, (d, lambda))
    {
        stationarity_into(p, (jp, hp), d, lambda, s);
        jac_times_into(p, jp, d, jd);
        sign_test(p, w, &Step { d, lambda, s, jd }, changes);
    }
}

/// The first iteration of [`solve_in`] for a step of W's equality QP computed by the
/// caller (`d` and the rows' total multipliers `lambda`; the real-time iteration's
/// predictor-corrector): the sign test and, when it passes and the step is a KKT point
/// of the QP (as [`solve_in`] checks it), the result in `res` (one iteration). `None`
/// when W must change or the step is inaccurate: the caller then runs [`solve_in`].
pub(super) fn accept_step_in(
    p: &QpData,
    (jp, hp): (&SymbolicSparseColMat<usize>, &SymbolicSparseColMat<usize>),
    (w, res): (&WorkingSet, &mut QpResult),
    (d, lambda): (&[f64], &[f64]),
    n_elastic: usize,
    scratch: &mut Scratch,
) -> Option<Found> {
    let Scratch { changes, s, jd, .. } = scratch;
    stationarity_into(p, (jp, hp), d, lambda, s);
    jac_times_into(p, jp, d, jd);
    let step = Step { d, lambda, s, jd };
    sign_test(p, w, &step, changes);
    if !changes.is_empty() {
        return None;
    }
    let max_multiplier = kkt_point(p, w, step, n_elastic, res).ok()?;
    res.iterations = 1;
    Some(Found {
        iterations: 1,
        max_multiplier,
    })
}

/// A change of the working set: (index, rows then variables; the new side; the size of
/// the violation).
type Change = (usize, Side, f64);

/// The equality QP's solution for a working set: the step d, the rows' multipliers λ
/// (augmented term included), the stationarity residual s = B d + ∇f + Jᵀλ and J d.
struct Step<'s> {
    d: &'s [f64],
    lambda: &'s [f64],
    s: &'s [f64],
    jd: &'s [f64],
}

/// The feasibility tolerance of a constraint with bound `b`.
fn feas_tol(b: f64) -> f64 {
    1e-9 * (1.0 + b.abs())
}

/// Whether the step with J d = `jd` meets every row of W to its feasibility tolerance.
fn rows_met(p: &QpData, w: &WorkingSet, jd: &[f64]) -> bool {
    (0..p.g.len()).all(|i| {
        let lin = p.g[i] + jd[i];
        match w.rows[i] {
            Side::Free => true,
            Side::Lower => (lin - p.g_l[i]).abs() <= feas_tol(p.g_l[i]),
            Side::Upper | Side::Both => (lin - p.g_u[i]).abs() <= feas_tol(p.g_u[i]),
        }
    })
}

/// The sign test of the primal-dual active-set strategy: into `changes`, every row and
/// bound outside W the step violates (entering on the violated side) and every one in W
/// whose multiplier has the wrong sign (leaving).
fn sign_test(p: &QpData, w: &WorkingSet, st: &Step, changes: &mut Vec<Change>) {
    let (n, m) = (p.x.len(), p.g.len());
    let lam_max = st
        .lambda
        .iter()
        .chain(st.s)
        .fold(1.0f64, |a, v| a.max(v.abs()));
    let mult_tol = 1e-8 * lam_max;
    changes.clear();
    for i in 0..m {
        let lin = p.g[i] + st.jd[i];
        // The QP's own multiplier (the augmented term's share ρ_a·J_i d removed).
        let l_qp = st.lambda[i] - p.row_weight[i] * st.jd[i];
        let (l, u) = (p.g_l[i], p.g_u[i]);
        let change = match w.rows[i] {
            Side::Free if lin > u + feas_tol(u) => Some((Side::Upper, lin - u)),
            Side::Free if lin < l - feas_tol(l) => Some((Side::Lower, l - lin)),
            Side::Upper if l_qp < -mult_tol => Some((Side::Free, -l_qp)),
            Side::Lower if l_qp > mult_tol => Some((Side::Free, l_qp)),
            _ => None,
        };
        if let Some((side, v)) = change {
            changes.push((i, side, v));
        }
    }
    for j in 0..n {
        let xn = p.x[j] + st.d[j];
        let (l, u, s) = (p.x_l[j], p.x_u[j], st.s[j]);
        // s_j = z_l − z_u: a lower bound needs s_j ≥ 0, an upper one s_j ≤ 0.
        let change = match w.vars[j] {
            Side::Free if xn > u + feas_tol(u) => Some((Side::Upper, xn - u)),
            Side::Free if xn < l - feas_tol(l) => Some((Side::Lower, l - xn)),
            Side::Upper if s > mult_tol => Some((Side::Free, s)),
            Side::Lower if s < -mult_tol => Some((Side::Free, -s)),
            _ => None,
        };
        if let Some((side, v)) = change {
            changes.push((m + j, side, v));
        }
    }
}

/// How many changes of the sign test an iteration applies. The full primal-dual
/// active-set step (all of them) converges fast near the solution and on M-matrix-like
/// QPs, but on others it can wander without ever repeating a working set: on the cold
/// cart-pole swing-up of issue 19, 16 QPs changed 30–60 entries per iteration for 50
/// and for 200 iterations. So the total violation of the proposed changes is watched
/// after the first [`FULL_STEPS`] iterations: when it has not fallen below 0.9× its best
/// for [`STALL_ITERATIONS`] iterations, the number of changes applied is halved (the
/// largest violations kept), down to one; and a repeated working set sets it to one at
/// once.
struct ChangeBudget {
    /// Most changes applied per iteration.
    limit: usize,
    /// The smallest total violation seen since the last cut, and the iterations since.
    best: f64,
    stalled: usize,
}

/// Iterations without a 10 % fall of the total violation before the changes are halved.
const STALL_ITERATIONS: usize = 3;

/// Iterations that always apply every change (the budget watches the later ones): on the
/// unit tests' random QPs, watching from the first iteration cut the full steps of 3 QPs
/// the full method solves, which then cycled; from the sixth, none (and the cart-pole's
/// wandering QPs are still caught).
const FULL_STEPS: usize = 5;

impl ChangeBudget {
    fn new() -> ChangeBudget {
        ChangeBudget {
            limit: usize::MAX,
            best: f64::INFINITY,
            stalled: 0,
        }
    }

    /// Updates the limit with this iteration's proposed `changes`.
    fn observe(&mut self, changes: &[Change]) {
        let total: f64 = changes.iter().map(|c| c.2).sum();
        if total < 0.9 * self.best {
            self.best = total;
            self.stalled = 0;
            return;
        }
        self.stalled += 1;
        if self.stalled >= STALL_ITERATIONS {
            self.limit = (changes.len().min(self.limit) / 2).max(1);
            self.best = total;
            self.stalled = 0;
        }
    }
}

/// Keeps the `k` changes of the largest violations (ties to the smaller index:
/// deterministic; no allocation).
fn keep_largest(changes: &mut Vec<Change>, k: usize) {
    if changes.len() <= k {
        return;
    }
    changes.sort_unstable_by(|a, b| b.2.total_cmp(&a.2).then(a.0.cmp(&b.0)));
    changes.truncate(k);
}

/// The QP's solution from the step of W that passed the sign test, written into `res`
/// (status `Solved`; its `iterations` are left to the caller), if the equality QP was
/// solved accurately (free variables stationary, the rows of W met): returns the largest
/// |λ_i| of the rows; `Err(EqualityQp)` otherwise. `n_elastic`: the length of the (zero)
/// elastic part.
fn kkt_point(
    p: &QpData,
    w: &WorkingSet,
    st: Step,
    n_elastic: usize,
    res: &mut QpResult,
) -> Result<f64, Failure> {
    let (n, m) = (p.x.len(), p.g.len());
    let grad_max = p.grad.iter().fold(1.0f64, |a, v| a.max(v.abs()));
    if (0..n).any(|j| w.vars[j] == Side::Free && st.s[j].abs() > 1e-8 * grad_max)
        || !rows_met(p, w, st.jd)
    {
        return Err(Failure::EqualityQp);
    }
    res.d.clear();
    res.d.extend_from_slice(st.d);
    refill(&mut res.e, n_elastic, 0.0);
    res.z_w.clear();
    res.z_w.extend((0..m).map(|i| p.row_weight[i] * st.jd[i]));
    res.lambda.clear();
    res.lambda
        .extend((0..m).map(|i| st.lambda[i] - p.row_weight[i] * st.jd[i]));
    let max_multiplier = res.lambda.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    refill(&mut res.z_l, n, 0.0);
    refill(&mut res.z_u, n, 0.0);
    for j in 0..n {
        if w.vars[j] != Side::Free {
            res.z_l[j] = st.s[j].max(0.0);
            res.z_u[j] = (-st.s[j]).max(0.0);
        }
    }
    res.z_cone.clear();
    res.status = clarabel::solver::SolverStatus::Solved;
    Ok(max_multiplier)
}

#[cfg(test)]
mod tests {
    //! The active-set method against clarabel (`Qp`, the SQP's elastic QP with a penalty
    //! far above the multipliers, so that its elastic variables are zero) on random
    //! strictly convex QPs with equality rows, two-sided and one-sided inequalities,
    //! bounds and fixed variables, feasible by construction; and on degenerate ones
    //! (duplicated rows, a bound duplicating a row), where the method may give up but
    //! must not return a wrong answer.
    use super::{
        guess_into, keep_largest, penalty_for, solve_in, ChangeBudget, Failure, Scratch,
        STALL_ITERATIONS,
    };

    /// A solved QP: its result and working set (the test's view of `solve_in`).
    struct Solved {
        res: QpResult,
        working_set: WorkingSet,
    }

    /// The working set guessed from `mult` (`guess_into` into a new one).
    fn guess(p: &QpData, mult: &Mult) -> WorkingSet {
        let mut w = WorkingSet {
            rows: Vec::new(),
            vars: Vec::new(),
        };
        guess_into(p, mult, &mut w);
        w
    }

    /// `solve_in` from `start` with new vectors.
    fn solve(
        kkt: &mut Kkt,
        p: &QpData,
        pats: (&SymbolicSparseColMat<usize>, &SymbolicSparseColMat<usize>),
        mut w: WorkingSet,
        limits: (usize, usize),
        n_fact: &mut usize,
        factored: bool,
    ) -> Result<Solved, Failure> {
        let mut res = QpResult::empty();
        let mut scratch = Scratch::default();
        let ws = (&mut w, &mut res);
        solve_in(kkt, p, pats, ws, limits, (n_fact, factored), &mut scratch)?;
        Ok(Solved {
            res,
            working_set: w,
        })
    }
    use crate::kkt::Kkt;
    use crate::sqp::iterate::Mult;
    use crate::sqp::polish::Side;
    use crate::sqp::polish::WorkingSet;
    use crate::sqp::qp::{Qp, QpData, QpResult, QpStructure};
    use crate::test_support::{pattern, Rng};
    use faer::sparse::SymbolicSparseColMat;

    struct Case {
        n: usize,
        m: usize,
        hp: SymbolicSparseColMat<usize>,
        jp: SymbolicSparseColMat<usize>,
        hess: Vec<f64>,
        jac: Vec<f64>,
        x: Vec<f64>,
        x_l: Vec<f64>,
        x_u: Vec<f64>,
        g: Vec<f64>,
        g_l: Vec<f64>,
        g_u: Vec<f64>,
        grad: Vec<f64>,
        zeros_n: Vec<f64>,
        zeros_m: Vec<f64>,
    }

    impl Case {
        fn data(&self) -> QpData<'_> {
            QpData {
                x: &self.x,
                x_l: &self.x_l,
                x_u: &self.x_u,
                g: &self.g,
                g_l: &self.g_l,
                g_u: &self.g_u,
                grad: &self.grad,
                jac: &self.jac,
                cone: &[],
                cone_jac: &[],
                hess: &self.hess,
                shift: 0.0,
                bound_weight: &self.zeros_n,
                row_weight: &self.zeros_m,
                dense_b: None,
                rho: 1e6,
            }
        }
    }

    /// A random QP: B = LLᵀ + 0.1 I stored as its dense lower triangle; J dense m×n (with
    /// `dup` rows copied from row 0); the bounds around a random feasible step d₀ so that
    /// some constraints are active at the solution and others not.
    fn random_case(rng: &mut Rng, n: usize, m: usize, dup: usize, bound_dup: bool) -> Case {
        let mut he = Vec::new();
        for c in 0..n {
            for r in c..n {
                he.push((r, c));
            }
        }
        let hp = pattern(n, n, &he);
        let l: Vec<f64> = rng.vec(n * n);
        let mut hess = vec![0.0; he.len()];
        for c in 0..n {
            for p in hp.col_range(c) {
                let r = hp.row_idx()[p];
                let v: f64 = (0..n).map(|k| l[r * n + k] * l[c * n + k]).sum();
                hess[p] = v + if r == c { 0.1 } else { 0.0 };
            }
        }
        let mut je = Vec::new();
        for r in 0..m {
            for c in 0..n {
                je.push((r, c));
            }
        }
        let jp = pattern(m, n, &je);
        let mut jd = vec![vec![0.0; n]; m];
        for r in 0..m {
            for c in 0..n {
                jd[r][c] = if r > 0 && r <= dup {
                    jd[0][c]
                } else {
                    rng.sym()
                };
            }
        }
        if bound_dup && m > 0 {
            // Row 0 is a multiple of variable 0 alone.
            for c in 1..n {
                jd[0][c] = 0.0;
            }
            jd[0][0] = 2.0;
        }
        let mut jac = vec![0.0; je.len()];
        for c in 0..n {
            for p in jp.col_range(c) {
                jac[p] = jd[jp.row_idx()[p]][c];
            }
        }
        let x = rng.vec(n);
        let d0 = rng.vec(n);
        let g = rng.vec(m);
        let grad: Vec<f64> = rng.vec(n).iter().map(|v| 5.0 * v).collect();
        let (mut g_l, mut g_u) = (vec![0.0; m], vec![0.0; m]);
        for i in 0..m {
            let lin: f64 = g[i] + (0..n).map(|c| jd[i][c] * d0[c]).sum::<f64>();
            let kind = if i > 0 && i <= dup {
                1
            } else {
                (rng.next() * 4.0) as usize
            };
            (g_l[i], g_u[i]) = match kind {
                0 => (lin, lin),
                1 => (lin - 0.1 * rng.next(), lin + 0.1 * rng.next()),
                2 => (f64::NEG_INFINITY, lin + 0.1 * rng.next()),
                _ => (lin - 0.1 * rng.next(), f64::INFINITY),
            };
        }
        if bound_dup && m > 0 {
            g_l[0] = f64::NEG_INFINITY;
            g_u[0] = g[0] + 2.0 * d0[0];
        }
        let (mut x_l, mut x_u) = (vec![0.0; n], vec![0.0; n]);
        for j in 0..n {
            let xn = x[j] + d0[j];
            (x_l[j], x_u[j]) = match (rng.next() * 5.0) as usize {
                0 => (f64::NEG_INFINITY, f64::INFINITY),
                1 if j > 0 => (x[j], x[j]),
                2 => (xn - 0.05 * rng.next(), f64::INFINITY),
                3 => (f64::NEG_INFINITY, xn + 0.05 * rng.next()),
                _ => (xn - 0.2 * rng.next(), xn + 0.2 * rng.next()),
            };
            if x_l[j] == x_u[j] {
                // A fixed variable: the step must be zero, and d₀ with it.
                continue;
            }
            x_l[j] = x_l[j].min(x[j]);
            x_u[j] = x_u[j].max(x[j]);
        }
        if bound_dup {
            x_l[0] = f64::NEG_INFINITY;
            x_u[0] = x[0] + d0[0];
        }
        // Fixed variables make d₀ infeasible; make the rows accept d₀ with d_j = 0 there.
        let mut d0f = d0.clone();
        for j in 0..n {
            if x_l[j] == x_u[j] {
                d0f[j] = 0.0;
            }
        }
        for i in 0..m {
            let lin: f64 = g[i] + (0..n).map(|c| jd[i][c] * d0f[c]).sum::<f64>();
            let sh = lin - (g[i] + (0..n).map(|c| jd[i][c] * d0[c]).sum::<f64>());
            g_l[i] += sh;
            g_u[i] += sh;
        }
        Case {
            n,
            m,
            hp,
            jp,
            hess,
            jac,
            x,
            x_l,
            x_u,
            g,
            g_l,
            g_u,
            grad,
            zeros_n: vec![0.0; n],
            zeros_m: vec![0.0; m],
        }
    }

    fn objective(c: &Case, d: &[f64]) -> f64 {
        let mut f: f64 = c.grad.iter().zip(d).map(|(a, b)| a * b).sum();
        for col in 0..c.n {
            for p in c.hp.col_range(col) {
                let r = c.hp.row_idx()[p];
                let v = c.hess[p] * d[r] * d[col];
                f += if r == col { 0.5 * v } else { v };
            }
        }
        f
    }

    fn clarabel(c: &Case) -> QpResult {
        let st = QpStructure {
            jac: &c.jp,
            x_l: &c.x_l,
            x_u: &c.x_u,
            g_l: &c.g_l,
            g_u: &c.g_u,
            cone_blocks: &[],
            cone_jac: None,
            skip_rows: &c.zeros_m.iter().map(|_| false).collect::<Vec<_>>(),
        };
        let mut qp = Qp::new(&c.hp, &st, false, false, 1e-10, 200);
        qp.solve(&c.data()).unwrap()
    }

    fn cold(c: &Case) -> WorkingSet {
        let mult = Mult::zeros(c.n, c.m, 0);
        guess(&c.data(), &mult)
    }

    /// Runs the active-set method (cold, then warm from its own working set) and compares
    /// with clarabel; returns whether it solved the QP.
    fn check(c: &Case, label: &str) -> bool {
        let reference = clarabel(c);
        assert!(
            matches!(reference.status, clarabel::solver::SolverStatus::Solved),
            "{label}: clarabel {:?}",
            reference.status
        );
        assert!(
            reference.e.iter().all(|v| v.abs() < 1e-7),
            "{label}: elastic"
        );
        let mut kkt = Kkt::new(c.n, c.m, &c.hp, &c.jp).unwrap();
        let mut n_fact = 0;
        let data = c.data();
        let s = match solve(
            &mut kkt,
            &data,
            (&c.jp, &c.hp),
            cold(c),
            (50, 0),
            &mut n_fact,
            false,
        ) {
            Ok(s) => s,
            Err(f) => {
                eprintln!("{label}: {f:?}");
                return false;
            }
        };
        // Tolerances: clarabel stops at gap/feasibility 1e-10 of its equilibrated
        // problem, the active-set step is exact to rounding; the objective is strictly
        // convex, so the minimisers agree to about sqrt of clarabel's gap.
        let (fa, fc) = (objective(c, &s.res.d), objective(c, &reference.d));
        assert!(
            (fa - fc).abs() <= 1e-7 * (1.0 + fc.abs()),
            "{label}: objective {fa} vs clarabel {fc}"
        );
        for j in 0..c.n {
            assert!(
                (s.res.d[j] - reference.d[j]).abs() <= 1e-5 * (1.0 + reference.d[j].abs()),
                "{label}: d[{j}] {} vs clarabel {}",
                s.res.d[j],
                reference.d[j]
            );
        }
        // Warm from its own working set: one factorisation, the same step.
        let before = n_fact;
        let warm = solve(
            &mut kkt,
            &data,
            (&c.jp, &c.hp),
            s.working_set.clone(),
            (50, 0),
            &mut n_fact,
            false,
        )
        .unwrap_or_else(|f| panic!("{label}: warm start failed: {f:?}"));
        assert_eq!(n_fact - before, 1, "{label}");
        assert_eq!(warm.res.d, s.res.d, "{label}");
        true
    }

    /// min ½‖d‖² + 1e4·d₀ + 2e4·d₁ s.t. d₀ + d₁ = 0 (row, g = 0), x₁ + d₁ ≥ x₁ + 5 (bound):
    /// by hand, d = (−5, 5), the row's multiplier λ = −(1e4 + d₀) = −9995 and the bound's
    /// z_l = d₁ + 2e4 + λ = 10010 > 0. The bound's fixing weight (1e14 × target 5) makes
    /// the solve's refinement stop with the row off by the zero block's 1e-10·|λ| ≈ 1e-6;
    /// the candidate must be refined once more and accepted, not handed back
    /// (`Failure::EqualityQp`, as before the correction). Tolerances: an exact solve of a
    /// 3×3 system to rounding, relative 1e-9.
    #[test]
    fn a_candidate_with_large_multipliers_is_refined_not_refused() {
        let hp = pattern(2, 2, &[(0, 0), (1, 1)]);
        let jp = pattern(1, 2, &[(0, 0), (0, 1)]);
        let c = Case {
            n: 2,
            m: 1,
            hp,
            jp,
            hess: vec![1.0, 1.0],
            jac: vec![1.0, 1.0],
            x: vec![0.0, 0.0],
            x_l: vec![f64::NEG_INFINITY, 5.0],
            x_u: vec![f64::INFINITY, f64::INFINITY],
            g: vec![0.0],
            g_l: vec![0.0],
            g_u: vec![0.0],
            grad: vec![1e4, 2e4],
            zeros_n: vec![0.0; 2],
            zeros_m: vec![0.0; 1],
        };
        let mut kkt = Kkt::new(c.n, c.m, &c.hp, &c.jp).unwrap();
        let mut n_fact = 0;
        let data = c.data();
        let pats = (&c.jp, &c.hp);
        let s = solve(&mut kkt, &data, pats, cold(&c), (50, 0), &mut n_fact, false)
            .unwrap_or_else(|f| panic!("refused: {f:?}"));
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + b.abs());
        assert!(
            close(s.res.d[0], -5.0) && close(s.res.d[1], 5.0),
            "d {:?}",
            s.res.d
        );
        assert!(close(s.res.lambda[0], -9995.0), "λ {:?}", s.res.lambda);
        assert!(close(s.res.z_l[1], 10010.0), "z_l {:?}", s.res.z_l);
        assert_eq!(s.working_set.vars[1], Side::Lower);
    }

    #[test]
    fn matches_clarabel_on_random_convex_qps() {
        let mut solved = 0u64;
        let total = 200u64;
        for seed in 0..total {
            let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ (seed + 1));
            let n = 2 + (rng.next() * 10.0) as usize;
            let m = (rng.next() * n as f64) as usize;
            let c = random_case(&mut rng, n, m, 0, false);
            solved += check(&c, &format!("seed {seed} (n {n}, m {m})")) as u64;
        }
        // Not a method that gives up: cold starts on non-degenerate QPs succeed.
        println!("random convex QPs solved by the active-set method: {solved} of {total}");
        assert!(solved >= total * 9 / 10, "solved {solved} of {total}");
    }

    #[test]
    fn degenerate_qps_are_solved_right_or_handed_back() {
        for seed in 0..100 {
            let mut rng = Rng(0x2545_f491_4f6c_dd1d ^ (seed + 1));
            let n = 3 + (rng.next() * 6.0) as usize;
            let m = 3 + (rng.next() * (n - 2) as f64) as usize;
            let c = random_case(&mut rng, n, m, 2, seed % 2 == 0);
            check(&c, &format!("degenerate seed {seed} (n {n}, m {m})"));
        }
    }

    #[test]
    fn stalled_violations_halve_the_changes_down_to_one() {
        let changes = |count: usize, each: f64| -> Vec<(usize, Side, f64)> {
            (0..count).map(|k| (k, Side::Upper, each)).collect()
        };
        let mut b = ChangeBudget::new();
        // Falling violations: every change stays allowed.
        for total in [100.0, 50.0, 20.0] {
            b.observe(&changes(40, total / 40.0));
            assert_eq!(b.limit, usize::MAX);
        }
        // 40 changes whose total stays at 20 (not below 0.9 × 20): halved after the
        // third such iteration, then again after three more, down to one.
        let mut limits = Vec::new();
        for _ in 0..(8 * STALL_ITERATIONS) {
            b.observe(&changes(40, 0.5));
            limits.push(b.limit);
        }
        assert_eq!(limits[STALL_ITERATIONS - 2], usize::MAX);
        assert_eq!(limits[STALL_ITERATIONS - 1], 20);
        assert_eq!(limits[2 * STALL_ITERATIONS - 1], 10);
        assert_eq!(*limits.last().unwrap(), 1);
    }

    #[test]
    fn the_largest_violations_are_kept_ties_to_the_smaller_index() {
        let mut c = vec![
            (4, Side::Lower, 1.0),
            (1, Side::Upper, 3.0),
            (7, Side::Free, 3.0),
            (2, Side::Upper, 0.5),
        ];
        keep_largest(&mut c, 2);
        assert_eq!(c, vec![(1, Side::Upper, 3.0), (7, Side::Free, 3.0)]);
        keep_largest(&mut c, 1);
        assert_eq!(c, vec![(1, Side::Upper, 3.0)]);
        let mut all = vec![(3, Side::Lower, 0.1), (0, Side::Upper, 2.0)];
        keep_largest(&mut all, 5);
        assert_eq!(all.len(), 2, "nothing dropped below the limit");
    }

    #[test]
    fn the_penalty_grows_as_the_elastic_mode_would() {
        let f = (10.0, 11, 1e8);
        assert_eq!(penalty_for(5.0, 10.0, f), Some(10.0));
        assert_eq!(penalty_for(10.0, 10.0, f), Some(10.0));
        assert_eq!(penalty_for(10.5, 10.0, f), Some(100.0));
        assert_eq!(penalty_for(2e4, 10.0, f), Some(1e5));
        assert_eq!(penalty_for(2e8, 10.0, f), None);
        assert_eq!(penalty_for(2e4, 10.0, (10.0, 2, 1e8)), None);
        assert_eq!(penalty_for(2e3, 10.0, (10.0, 2, 1e8)), None);
        assert_eq!(penalty_for(500.0, 10.0, (10.0, 2, 1e8)), Some(1000.0));
        assert_eq!(penalty_for(5e7, 1e7, (10.0, 11, 3e7)), None);
    }
}
