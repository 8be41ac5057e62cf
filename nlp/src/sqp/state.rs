//! The state of one SQP solve ([`SqpState`]) — problem shape, geometry, the iterate, the
//! Hessian's convexification, the QP, the penalty and the counters — with its set-up and
//! the steps of an iteration that are not the QP (`subproblem.rs`), the line search
//! (`line_search.rs`) or accepting and rejecting its step (`accept.rs`): the stop tests
//! and the convexified Hessian.

#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use super::active_set::{penalty_for, MAX_PENALTY_INCREASES};
pub(super) use super::convexify::Curvature;
use super::convexify::{active_sets_into, Convexify};
use super::geometry::Geometry;
use super::iterate::{Iterate, Mult};
use super::options::{HessianApproximation, SqpOptions};
use super::qp::{Qp, QpStructure};
use super::shape::Shape;
use super::stop::{StepError, Stop};
use super::workspace::{Kept, StepBuffers, Structure, Workspace};
use crate::callback::Observer;
use crate::frontend::scaled::{refill, NormScratch, ScaledNlp};
use crate::frontend::user_solution::{user_solution_into, ConeDuals};
use crate::frontend::validate::Validated;
use crate::frontend::{KktResiduals, Termination};
use crate::ipm::reduced::same_pattern;
use crate::kkt::Kkt;
use crate::numeric::NumericNlp;
use crate::scaling::gradient_scale;
use crate::solution::{BackendColumns, IterationRecord, Solution, Stats, Status};

/// Work counters for `Stats`.
#[derive(Default)]
pub(super) struct Work {
    pub n_qp: usize,
    pub qp_iterations: u64,
    pub qp_seconds: f64,
    pub factor_seconds: f64,
    pub n_fact: usize,
    pub n_polished: usize,
    /// QPs solved by the active-set method (the others by clarabel).
    pub n_active_set: usize,
    /// QPs the active-set method handed to clarabel, by reason: the shape, a singular
    /// or non-convex equality QP, a cycle, the iteration limit, multipliers above every
    /// allowed ρ (printed at `print_level` ≥ 3).
    pub active_set_failures: [usize; 5],
}

/// Everything one SQP solve carries from iteration to iteration.
pub(super) struct SqpState<'a> {
    pub o: &'a SqpOptions,
    pub sc: ScaledNlp<'a>,
    /// The user's bounds and starting point.
    pub user: Validated,
    pub shape: Shape,
    pub geo: Geometry,
    pub it: Iterate,
    pub curv: Curvature,
    /// KKT matrix for the convexity test and polishing (`None` with BFGS).
    pub kkt: Option<Kkt>,
    pub qp: Qp,
    /// The QP of the other kind (with the augmented term when `qp` has none, and the
    /// reverse), when there is one: kept for the next solve.
    pub spare_qp: Option<Qp>,
    /// The structure the kept parts of the workspace were built for (handed back to it).
    pub kept_structure: Option<Structure>,
    /// ℓ1 penalty ρ.
    pub rho: f64,
    /// The vectors of the steps: merit weights, the working set of the last QP the
    /// active-set method solved (its warm start), QP results and trial points.
    pub steps: StepBuffers,
    /// What the solver keeps between solves (the buffers not in use during the solve).
    kept: Box<Kept>,
    pub work: Work,
    pub stats: Stats,
    /// The row of the iteration log being filled.
    pub record: IterationRecord,
    /// Consecutive rejected steps.
    pub ls_failures: usize,
}

/// Scaled g and the cone entries (when there are cones) at x, counted as one evaluation.
pub(super) fn eval_g(sc: &mut ScaledNlp<'_>, x: &[f64], g: &mut [f64], cone: &mut [f64]) {
    sc.g(x, g);
    if !cone.is_empty() {
        sc.cone_entries(x, cone);
    }
}

/// Scaled Jacobian and the cone Jacobian (when there are cones) at x.
pub(super) fn eval_jac(sc: &mut ScaledNlp<'_>, x: &[f64], jv: &mut [f64], cv: &mut [f64]) {
    sc.jac(x, jv);
    if !cv.is_empty() {
        sc.cone_jac(x, cv);
    }
}

/// Gradient-based scaling at the starting point x (IPOPT's rule, option
/// `gradient_scaling`; rows replaced by cones stay unscaled), and the row bounds of `geo`
/// scaled with it.
fn scale(
    sc: &mut ScaledNlp<'_>,
    geo: &mut Geometry,
    x: &[f64],
    o: &SqpOptions,
    norms: &mut NormScratch,
) {
    let (max_gradient, min_value) = (o.nlp_scaling_max_gradient, o.nlp_scaling_min_value);
    if o.gradient_scaling {
        let gmax = sc.unscaled_gradient_norms_into(x, None, norms);
        sc.scaling.obj = gradient_scale(gmax, max_gradient, min_value);
        for (i, &r) in norms.rmax.iter().enumerate() {
            if !geo.cone_row[i] {
                sc.scaling.rows[i] = gradient_scale(r, max_gradient, min_value);
            }
        }
    }
    for (i, s) in sc.scaling.rows.iter().enumerate() {
        geo.g_l[i] *= s;
        geo.g_u[i] *= s;
    }
}

/// A new QP laid out for `shape` and `geo` (`aug`: with the augmented term).
pub(super) fn new_qp(shape: &Shape, geo: &Geometry, o: &SqpOptions, aug: bool) -> Qp {
    let st = QpStructure {
        jac: &shape.jp,
        x_l: &geo.x_l,
        x_u: &geo.x_u,
        g_l: &geo.g_l,
        g_u: &geo.g_u,
        cone_blocks: &shape.block,
        cone_jac: shape.cp.as_ref(),
        skip_rows: &geo.cone_row,
    };
    Qp::new(&shape.hp, &st, aug, shape.dense, o.qp_tol, o.qp_max_iter)
}

/// The shape and the geometry (unscaled bounds, cones) of `nlp` with the validated
/// bounds `v`: in `kept`'s vectors when it has the same sizes and patterns (and neither
/// has cones), new ones otherwise.
fn layout(
    nlp: &dyn NumericNlp,
    v: &Validated,
    o: &SqpOptions,
    kept: Option<(Shape, Geometry)>,
) -> (Shape, Geometry) {
    let (n, m) = (nlp.n(), nlp.m());
    let dense = o.hessian_approximation == HessianApproximation::DampedBfgs;
    let same = |s: &Shape| {
        s.n == n
            && s.m == m
            && s.dense == dense
            && s.n_cone == 0
            && nlp.affine_cones().is_empty()
            && nlp.cone_jac_sparsity().is_none()
            && same_pattern(&s.jp, nlp.jac_g_sparsity())
            && same_pattern(&s.hp, nlp.hess_l_sparsity())
    };
    if let Some((shape, mut geo)) = kept.filter(|(s, _)| same(s)) {
        for (to, from) in [
            (&mut geo.x_l, &v.x_l),
            (&mut geo.x_u, &v.x_u),
            (&mut geo.g_l, &v.g_l),
            (&mut geo.g_u, &v.g_u),
        ] {
            to.clone_from(from);
        }
        refill(&mut geo.cone_row, m, false);
        return (shape, geo);
    }
    let cones = nlp.affine_cones().to_vec();
    let n_cone = cones.iter().map(|c| c.offset + c.dim).max().unwrap_or(0);
    let mut cone_row = vec![false; m];
    for c in &cones {
        cone_row[c.row] = true;
    }
    let shape = Shape {
        n,
        m,
        n_cone,
        jp: nlp.jac_g_sparsity().clone(),
        hp: nlp.hess_l_sparsity().clone(),
        cp: nlp.cone_jac_sparsity().cloned(),
        block: cones.iter().map(|c| (c.offset, c.dim)).collect(),
        dense,
    };
    let geo = Geometry {
        x_l: v.x_l.clone(),
        x_u: v.x_u.clone(),
        g_l: v.g_l.clone(),
        g_u: v.g_u.clone(),
        cone_row,
        cones,
    };
    (shape, geo)
}

/// The first iterate in `it` (whose `x` holds the starting point; the other vectors are
/// resized): the scaled problem evaluated at x, with the multipliers of `warm`
/// (scaled) or zeros. ∇f and J at x come from the front end's cache when the gradient
/// scaling evaluated them there (the same numbers, not evaluated again).
fn first_iterate(sc: &mut ScaledNlp<'_>, shape: &Shape, it: &mut Iterate, warm: Option<&Solution>) {
    let (n, m) = (shape.n, shape.m);
    refill(&mut it.grad, n, 0.0);
    refill(&mut it.jv, shape.jp.row_idx().len(), 0.0);
    refill(
        &mut it.cv,
        shape.cp.as_ref().map_or(0, |p| p.row_idx().len()),
        0.0,
    );
    refill(&mut it.g, m, 0.0);
    refill(&mut it.cone, shape.n_cone, 0.0);
    it.f = sc.f(&it.x);
    eval_g(sc, &it.x, &mut it.g, &mut it.cone);
    sc.grad(&it.x, &mut it.grad);
    eval_jac(sc, &it.x, &mut it.jv, &mut it.cv);
    let mult = &mut it.mult;
    refill(&mut mult.lambda, m, 0.0);
    refill(&mut mult.z_l, n, 0.0);
    refill(&mut mult.z_u, n, 0.0);
    refill(&mut mult.z_cone, shape.n_cone, 0.0);
    if let Some(p) = warm {
        for i in 0..m {
            mult.lambda[i] = sc.scaling.lambda_from_user(i, p.lambda[i]);
        }
        for j in 0..n {
            mult.z_l[j] = sc.scaling.z_from_user(p.z_l[j]);
            mult.z_u[j] = sc.scaling.z_from_user(p.z_u[j]);
        }
    }
    it.have_mult = warm.is_some();
}

/// The first ℓ1 penalty ρ: `penalty_init`, raised (×`penalty_increase`, as the elastic
/// mode raises it, at most `penalty_max`) above the largest row multiplier of the start
/// (`lambda`, scaled; zero on a cold start). Exact-penalty theory needs ρ > ‖λ*‖∞: with a
/// smaller ρ the elastic QP at a KKT point prefers violating the constraints whose
/// multipliers exceed ρ to meeting them. From the IPM's optimum of hs116 (multipliers up
/// to 3.8e5 in the scaled problem) the first QP with ρ = 10 did so, Σe fell by less than
/// 10 % at ρ = 100, the elastic mode took that as an inconsistent linearisation, and the
/// step of length 74 left the optimum for good.
fn first_penalty(o: &SqpOptions, lambda: &[f64], cone_row: &[bool]) -> f64 {
    let max = lambda
        .iter()
        .zip(cone_row)
        .filter(|(_, &cone)| !cone)
        .fold(0.0f64, |a, (l, _)| a.max(l.abs()));
    let limits = (o.penalty_increase, MAX_PENALTY_INCREASES, o.penalty_max);
    penalty_for(max, o.penalty_init, limits).unwrap_or(o.penalty_max)
}

/// An iterate with empty vectors (to be filled by [`first_iterate`]).
fn empty_iterate() -> Iterate {
    Iterate {
        x: Vec::new(),
        f: 0.0,
        g: Vec::new(),
        cone: Vec::new(),
        grad: Vec::new(),
        jv: Vec::new(),
        cv: Vec::new(),
        mult: Mult::zeros(0, 0, 0),
        have_mult: false,
    }
}

impl<'a> SqpState<'a> {
    /// Lays out the solve of `nlp` with the validated bounds and starting point in
    /// `kept.bufs.validated` (with the KKT matrix, QPs and vectors `kept` has for this
    /// structure), scales the problem at the (clamped) starting point and evaluates it
    /// there; `warm` supplies the first multipliers, `records` the vector of the
    /// iteration log (cleared).
    pub fn new(
        o: &'a SqpOptions,
        nlp: &'a mut dyn NumericNlp,
        warm: Option<&Solution>,
        mut kept: Box<Kept>,
        mut records: Vec<IterationRecord>,
    ) -> Self {
        let b = &mut kept.bufs;
        let v = std::mem::take(&mut b.validated);
        let (shape, mut geo) = layout(nlp, &v, o, b.layout.take());
        let mut it = b.it.take().unwrap_or_else(empty_iterate);
        it.x.clear();
        it.x.extend((0..shape.n).map(|j| v.x0[j].clamp(geo.x_l[j], geo.x_u[j])));
        let mut sc = ScaledNlp::with_buffers(nlp, std::mem::take(&mut b.scaled));
        scale(&mut sc, &mut geo, &it.x, o, &mut b.norms);
        records.clear();
        let stats = Stats {
            obj_scaling: sc.scaling.obj,
            records,
            ..Stats::default()
        };
        first_iterate(&mut sc, &shape, &mut it, warm);
        let record = IterationRecord::starting_point(
            sc.scaling.objective_to_user(it.f),
            BackendColumns::Sqp {
                augmented_weight: 0.0,
            },
        );
        let mut curv = match b.curv.take() {
            Some(c) => c,
            None => Curvature::new(&shape),
        };
        curv.reset(&shape);
        let mut steps = std::mem::take(&mut b.steps);
        refill(&mut steps.merit_w, shape.m, 0.0);
        refill(&mut steps.lgrad, shape.n, 0.0);
        if let Some(w) = steps.working_set.take() {
            steps.spare_working_set = Some(w);
        }
        let reused = kept.reuse(&shape, &geo, (o.qp_tol, o.qp_max_iter));
        let qp = reused
            .plain
            .unwrap_or_else(|| new_qp(&shape, &geo, o, false));
        let rho = first_penalty(o, &it.mult.lambda, &geo.cone_row);
        SqpState {
            o,
            sc,
            user: v,
            it,
            curv,
            kkt: reused.kkt,
            qp,
            spare_qp: reused.aug,
            kept_structure: reused.structure,
            rho,
            steps,
            kept,
            work: Work::default(),
            stats,
            record,
            ls_failures: 0,
            shape,
            geo,
        }
    }

    /// Sets up the KKT matrix of the convexity test (not with BFGS) unless the workspace
    /// kept one.
    pub fn setup_kkt(&mut self) -> Result<(), StepError> {
        let s = &self.shape;
        if !s.dense && self.kkt.is_none() {
            self.kkt = Some(Kkt::new(s.n, s.m, &s.hp, &s.jp)?);
        }
        Ok(())
    }

    /// Logs iteration `iter`, shows it to the callback and tests for convergence and the
    /// other stop criteria; `Some` ends the solve.
    pub fn check(
        &mut self,
        iter: usize,
        termination: &mut Termination,
        observer: Option<&mut Observer<'_>>,
        start: Instant,
    ) -> Option<Stop> {
        let o = self.o;
        let err = self
            .it
            .kkt_errors(o.s_max, &self.geo, &self.shape, &mut self.steps.lgrad);
        let (it, sc) = (&self.it, &self.sc);
        self.record.iter = iter;
        self.record.objective = sc.scaling.objective_to_user(it.f);
        self.record.inf_pr = err.inf_pr;
        self.record.inf_du = err.inf_du;
        self.stats.records.push(self.record);
        if o.print_level >= 5 {
            if iter % 10 == 0 {
                crate::log::log_out!("{}", crate::log::header(&self.record.backend));
            }
            crate::log::log_out!("{}", crate::log::format_record(&self.record));
        }
        if let Some(obs) = observer {
            let (l, cones) = (&it.mult.lambda, &self.geo.cones);
            if obs.call_scaled(&self.record, &it.x, sc, l, cones, &it.mult.z_cone) {
                return Some(Stop {
                    status: Status::UserRequestedStop,
                    message: "stopped by the iteration callback".into(),
                });
            }
        }
        let unscaled_pr = self.geo.unscaled_max(sc, &it.x, &it.g, &it.cone);
        // Without multipliers (a cold start's iteration 0) the dual error is not
        // measured: no test, and the streak of acceptable iterates restarts.
        let residuals = KktResiduals {
            overall: err.scaled,
            dual: sc.scaling.objective_to_user(err.inf_du),
            primal: unscaled_pr,
            compl: sc.scaling.objective_to_user(err.compl),
        };
        if !it.have_mult {
            *termination = Termination::default();
            termination.set_last_objective(it.f);
        } else if let Some(s) = termination.check(&residuals, it.f, &o.common) {
            return Some(Stop::new(s));
        }
        let status = if iter >= o.max_iter {
            Status::MaximumIterationsExceeded
        } else if start.elapsed().as_secs_f64() > o.max_wall_time {
            Status::MaximumWallTimeExceeded
        } else if it.x.iter().any(|v| v.abs() > o.diverging_iterates_tol) {
            Status::DivergingIterates
        } else {
            return None;
        };
        Some(Stop::new(status))
    }

    /// Evaluates ∇²L at the iterate and convexifies it ([`Convexify`]), setting the
    /// augmented weights; returns the shift δ (0 with BFGS, whose B is positive definite).
    pub fn convexify(&mut self) -> Result<f64, StepError> {
        if self.shape.dense {
            return Ok(0.0);
        }
        let (it, geo, curv) = (&self.it, &self.geo, &mut self.curv);
        let steps = &mut self.steps;
        let lam = &mut steps.hess_lambda;
        lam.clear();
        lam.extend((0..self.shape.m).map(|i| {
            if geo.cone_row[i] {
                0.0
            } else {
                it.mult.lambda[i]
            }
        }));
        self.sc.hess(&it.x, 1.0, lam, &mut curv.hv);
        if curv.hv.iter().any(|v| !v.is_finite()) {
            return Err(StepError::NonFiniteHessian);
        }
        active_sets_into(geo, &it.x, &it.g, &it.mult, &mut steps.active);
        let (active_r, active_b) = (&steps.active.0, &steps.active.1);
        let conv = Convexify {
            kkt: self
                .kkt
                .as_mut()
                .expect("the KKT matrix is set up before iterating"),
            hv: &curv.hv,
            jv: &it.jv,
            active_r,
            active_b,
        };
        let last = (curv.delta_last, curv.rho_a_last);
        let (delta_inertia, rho_a) = conv
            .run_in(self.o, last, &mut self.work.n_fact, &mut steps.convexify)
            .ok_or(StepError::NoConvexification)?;
        // The proximal shift of the step control on top of the inertia's (B stays
        // positive definite: adding δI to a positive definite B keeps it so). Only the
        // inertia's shift is remembered for the next search: when the applied shift was
        // remembered, one heavily cut step (shift 0.1) damped the following iterations
        // through the δ_last/3 start of the search (0.1, 0.033, 0.011, ...) long after the
        // step control had released it, and the cart-pole swing-up of issue 19 crawled
        // through 324 iterations instead of 60.
        curv.rho_a_last = rho_a;
        for (w, &a) in curv.row_weight.iter_mut().zip(active_r) {
            *w = if a { rho_a } else { 0.0 };
        }
        for (w, &a) in curv.bound_weight.iter_mut().zip(active_b) {
            *w = if a { rho_a } else { 0.0 };
        }
        if rho_a > 0.0 && !self.qp.has_aug() {
            // The spare QP is the augmented one when there is one (kept from an earlier
            // solve); the plain one becomes the spare.
            let aug = self
                .spare_qp
                .take()
                .unwrap_or_else(|| new_qp(&self.shape, geo, self.o, true));
            self.spare_qp = Some(std::mem::replace(&mut self.qp, aug));
        }
        curv.delta_last = delta_inertia;
        Ok(delta_inertia.max(curv.extra_shift))
    }

    /// Hands the KKT matrix, the QPs and the vectors to the workspace for the next solve.
    pub fn keep_parts(self, ws: &Workspace) {
        let SqpState {
            sc,
            user,
            shape,
            geo,
            it,
            curv,
            kkt,
            qp,
            spare_qp,
            kept_structure,
            steps,
            mut kept,
            ..
        } = self;
        kept.keep((&shape, &geo), kept_structure, kkt, [Some(qp), spare_qp]);
        let b = &mut kept.bufs;
        b.validated = user;
        b.scaled = sc.into_buffers();
        b.layout = Some((shape, geo));
        b.it = Some(it);
        b.curv = Some(curv);
        b.steps = steps;
        ws.put(kept);
    }

    /// The solution in the user's units at the iterate, ending with `stop`, written into
    /// `sol` (its vectors reused; the stats are left to the caller).
    pub fn write_solution(&mut self, stop: Stop, sol: &mut Solution) {
        let (sc, it) = (&self.sc, &self.it);
        sol.x.clone_from(&it.x);
        refill(&mut sol.lambda, self.shape.m, 0.0);
        sc.scaling.lambdas_to_user(&it.mult.lambda, &mut sol.lambda);
        sol.z_l.clear();
        sol.z_l
            .extend(it.mult.z_l.iter().map(|&z| sc.scaling.z_to_user(z)));
        sol.z_u.clear();
        sol.z_u
            .extend(it.mult.z_u.iter().map(|&z| sc.scaling.z_to_user(z)));
        let z_cone = &mut self.steps.z_cone_user;
        z_cone.clear();
        z_cone.extend(it.mult.z_cone.iter().map(|&z| sc.scaling.z_to_user(z)));
        let cones = ConeDuals {
            cones: &self.geo.cones,
            cone_row: &self.geo.cone_row,
            z_cone,
        };
        sol.status = stop.status;
        sol.message.clear();
        sol.message.push_str(&stop.message);
        let last = &mut self.kept.bufs.last;
        user_solution_into(&mut self.sc, &self.user, sol, Some(cones), last);
    }
}
