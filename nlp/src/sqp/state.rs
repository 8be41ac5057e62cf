//! The state of one SQP solve ([`SqpState`]) — problem shape, geometry, the iterate, the
//! Hessian's convexification, the QP, the penalty and the counters — with its set-up and
//! the steps of an iteration that are not the QP (`subproblem.rs`), the line search
//! (`line_search.rs`) or accepting and rejecting its step (`accept.rs`): the stop tests
//! and the convexified Hessian.

#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use super::convexify::{active_sets, Convexify};
use super::geometry::Geometry;
use super::iterate::{Iterate, Mult};
use super::options::{HessianApproximation, SqpOptions};
use super::polish::WorkingSet;
use super::qp::{Qp, QpStructure};
use super::shape::Shape;
use super::stop::{StepError, Stop};
use super::workspace::{Structure, Workspace};
use crate::callback::Observer;
use crate::frontend::scaled::ScaledNlp;
use crate::frontend::user_solution::{user_solution, ConeDuals, UserPoint};
use crate::frontend::validate::Validated;
use crate::frontend::{KktResiduals, Termination};
use crate::kkt::Kkt;
use crate::numeric::NumericNlp;
use crate::scaling::gradient_scale;
use crate::solution::{BackendColumns, IterationRecord, Solution, Stats, Status};

/// The Hessian term B of the QP and how it was convexified.
pub(super) struct Curvature {
    /// Lower-triangular ∇²L values.
    pub hv: Vec<f64>,
    /// Dense B, column-major (BFGS only; empty otherwise).
    pub bfgs: Vec<f64>,
    /// ρ_a on the active rows, 0 elsewhere.
    pub row_weight: Vec<f64>,
    /// ρ_a on the active bounds, 0 elsewhere.
    pub bound_weight: Vec<f64>,
    pub rho_a_last: f64,
    pub delta_last: f64,
    /// Proximal shift added after rejected or heavily cut steps.
    pub extra_shift: f64,
}

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
    /// The working set of the last QP the active-set method solved (its warm start).
    pub working_set: Option<WorkingSet>,
    /// ℓ1 penalty ρ.
    pub rho: f64,
    /// Merit weights w_i.
    pub merit_w: Vec<f64>,
    pub work: Work,
    pub stats: Stats,
    /// The row of the iteration log being filled.
    pub record: IterationRecord,
    /// Consecutive rejected steps.
    pub ls_failures: usize,
    lgrad: Vec<f64>,
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
fn scale(sc: &mut ScaledNlp<'_>, geo: &mut Geometry, x: &[f64], o: &SqpOptions) {
    let (max_gradient, min_value) = (o.nlp_scaling_max_gradient, o.nlp_scaling_min_value);
    if o.gradient_scaling {
        let (gmax, rmax) = sc.unscaled_gradient_norms(x, None);
        sc.scaling.obj = gradient_scale(gmax, max_gradient, min_value);
        for (i, r) in rmax.into_iter().enumerate() {
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
/// bounds `v`.
fn layout(nlp: &dyn NumericNlp, v: &Validated, o: &SqpOptions) -> (Shape, Geometry) {
    let (n, m) = (nlp.n(), nlp.m());
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
        dense: o.hessian_approximation == HessianApproximation::DampedBfgs,
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

/// The first iterate: the scaled problem evaluated at `x`, with the multipliers of
/// `warm` (scaled) or zeros.
fn first_iterate(
    sc: &mut ScaledNlp<'_>,
    shape: &Shape,
    x: Vec<f64>,
    warm: Option<&Solution>,
) -> Iterate {
    let (n, m) = (shape.n, shape.m);
    let mut grad = vec![0.0; n];
    let mut jv = vec![0.0; shape.jp.row_idx().len()];
    let mut cv = vec![0.0; shape.cp.as_ref().map_or(0, |p| p.row_idx().len())];
    let mut g = vec![0.0; m];
    let mut cone = vec![0.0; shape.n_cone];
    let f = sc.f(&x);
    eval_g(sc, &x, &mut g, &mut cone);
    sc.grad(&x, &mut grad);
    eval_jac(sc, &x, &mut jv, &mut cv);
    let mut mult = Mult::zeros(n, m, shape.n_cone);
    if let Some(p) = warm {
        for i in 0..m {
            mult.lambda[i] = sc.scaling.lambda_from_user(i, p.lambda[i]);
        }
        for j in 0..n {
            mult.z_l[j] = sc.scaling.z_from_user(p.z_l[j]);
            mult.z_u[j] = sc.scaling.z_from_user(p.z_u[j]);
        }
    }
    Iterate {
        x,
        f,
        g,
        cone,
        grad,
        jv,
        cv,
        mult,
        have_mult: warm.is_some(),
    }
}

impl Curvature {
    /// No curvature yet: B = I for BFGS, no weights, no shifts.
    pub(super) fn new(shape: &Shape) -> Curvature {
        let n = shape.n;
        Curvature {
            hv: vec![0.0; shape.hp.row_idx().len()],
            bfgs: if shape.dense {
                (0..n * n)
                    .map(|k| if k % (n + 1) == 0 { 1.0 } else { 0.0 })
                    .collect()
            } else {
                vec![]
            },
            row_weight: vec![0.0; shape.m],
            bound_weight: vec![0.0; n],
            rho_a_last: 0.0,
            delta_last: 0.0,
            extra_shift: 0.0,
        }
    }
}

impl<'a> SqpState<'a> {
    /// Lays out the solve (with the KKT matrix and QPs the workspace `ws` kept for this
    /// structure), scales the problem at the (clamped) starting point and evaluates it
    /// there; `warm` supplies the first multipliers.
    pub fn new(
        o: &'a SqpOptions,
        nlp: &'a mut dyn NumericNlp,
        v: Validated,
        warm: Option<&Solution>,
        ws: &Workspace,
    ) -> Self {
        let (shape, mut geo) = layout(nlp, &v, o);
        let x: Vec<f64> = (0..shape.n)
            .map(|j| v.x0[j].clamp(geo.x_l[j], geo.x_u[j]))
            .collect();
        let mut sc = ScaledNlp::new(nlp);
        scale(&mut sc, &mut geo, &x, o);
        let stats = Stats {
            obj_scaling: sc.scaling.obj,
            ..Stats::default()
        };
        let it = first_iterate(&mut sc, &shape, x, warm);
        let record = IterationRecord::starting_point(
            sc.scaling.objective_to_user(it.f),
            BackendColumns::Sqp {
                augmented_weight: 0.0,
            },
        );
        let kept = ws.take(&shape, &geo, (o.qp_tol, o.qp_max_iter));
        let qp = kept.plain.unwrap_or_else(|| new_qp(&shape, &geo, o, false));
        SqpState {
            o,
            sc,
            user: v,
            it,
            curv: Curvature::new(&shape),
            kkt: kept.kkt,
            qp,
            spare_qp: kept.aug,
            kept_structure: kept.structure,
            working_set: None,
            rho: o.penalty_init,
            merit_w: vec![0.0; shape.m],
            work: Work::default(),
            stats,
            record,
            ls_failures: 0,
            lgrad: vec![0.0; shape.n],
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
            .kkt_errors(o.s_max, &self.geo, &self.shape, &mut self.lgrad);
        let (it, sc) = (&self.it, &self.sc);
        self.record.iter = iter;
        self.record.objective = sc.scaling.objective_to_user(it.f);
        self.record.inf_pr = err.inf_pr;
        self.record.inf_du = err.inf_du;
        self.stats.records.push(self.record);
        if o.print_level >= 5 {
            if iter % 10 == 0 {
                println!("{}", crate::log::header(&self.record.backend));
            }
            println!("{}", crate::log::format_record(&self.record));
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
        let lam: Vec<f64> = (0..self.shape.m)
            .map(|i| {
                if geo.cone_row[i] {
                    0.0
                } else {
                    it.mult.lambda[i]
                }
            })
            .collect();
        self.sc.hess(&it.x, 1.0, &lam, &mut curv.hv);
        if curv.hv.iter().any(|v| !v.is_finite()) {
            return Err(StepError::NonFiniteHessian);
        }
        let (active_r, active_b) = active_sets(geo, &it.x, &it.g, &it.mult);
        let conv = Convexify {
            kkt: self
                .kkt
                .as_mut()
                .expect("the KKT matrix is set up before iterating"),
            hv: &curv.hv,
            jv: &it.jv,
            active_r: &active_r,
            active_b: &active_b,
        };
        let (delta_inertia, rho_a) = conv
            .run(
                self.o,
                curv.delta_last,
                curv.rho_a_last,
                &mut self.work.n_fact,
            )
            .ok_or(StepError::NoConvexification)?;
        // The proximal shift of the step control on top of the inertia's (B stays
        // positive definite: adding δI to a positive definite B keeps it so). Only the
        // inertia's shift is remembered for the next search: when the applied shift was
        // remembered, one heavily cut step (shift 0.1) damped the following iterations
        // through the δ_last/3 start of the search (0.1, 0.033, 0.011, ...) long after the
        // step control had released it, and the cart-pole swing-up of issue 19 crawled
        // through 324 iterations instead of 60.
        curv.rho_a_last = rho_a;
        for (w, &a) in curv.row_weight.iter_mut().zip(&active_r) {
            *w = if a { rho_a } else { 0.0 };
        }
        for (w, &a) in curv.bound_weight.iter_mut().zip(&active_b) {
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

    /// Hands the KKT matrix and the QPs to the workspace for the next solve.
    pub fn keep_parts(self, ws: &Workspace) {
        let (shape, geo) = (&self.shape, &self.geo);
        ws.keep(
            (shape, geo),
            self.kept_structure,
            self.kkt,
            [Some(self.qp), self.spare_qp],
        );
    }

    /// The solution in the user's units at the iterate, ending with `stop`.
    pub fn user_solution(&mut self, stop: Stop) -> Solution {
        let (sc, it) = (&self.sc, &self.it);
        let mut lambda = vec![0.0; self.shape.m];
        sc.scaling.lambdas_to_user(&it.mult.lambda, &mut lambda);
        let point = UserPoint {
            x: it.x.clone(),
            lambda,
            z_l: it
                .mult
                .z_l
                .iter()
                .map(|&z| sc.scaling.z_to_user(z))
                .collect(),
            z_u: it
                .mult
                .z_u
                .iter()
                .map(|&z| sc.scaling.z_to_user(z))
                .collect(),
        };
        let z_cone: Vec<f64> = it
            .mult
            .z_cone
            .iter()
            .map(|&z| sc.scaling.z_to_user(z))
            .collect();
        let cones = ConeDuals {
            cones: &self.geo.cones,
            cone_row: &self.geo.cone_row,
            z_cone: &z_cone,
        };
        user_solution(
            &mut self.sc,
            &self.user,
            point,
            Some(cones),
            stop.status,
            stop.message,
        )
    }
}
