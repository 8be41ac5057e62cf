//! Sequential quadratic programming: a line-search Sℓ1QP method whose QP subproblems are
//! solved by clarabel.
//!
//! Each iteration at x_k (with multipliers λ_k):
//! 1. **Hessian.** B = ∇²L(x_k, λ_k) + δI + ρ_a·(J_AᵀJ_A + I_b) over the strongly active
//!    rows and bounds A (`active_sets`): δ is chosen for positive definiteness on the
//!    null space of the active constraints and ρ_a as small as makes B itself positive
//!    definite (inertia tests with a faer LDLᵀ, `Convexify`): clarabel needs a convex
//!    QP. Alternatively damped BFGS ([`HessianApproximation`]).
//! 2. **QP** (`qp`): the elastic subproblem min ½dᵀBd + ∇fᵀd + ρΣe over the linearised
//!    constraints relaxed by elastic variables e ≥ 0, the bounds, and affine second-order
//!    cones. It is always feasible. When e ≠ 0 (linearisation inconsistent, "elastic
//!    mode"), ρ grows by `penalty_increase` and the QP is solved again, up to
//!    `penalty_max`; past that the step minimises the linearised ℓ1 infeasibility.
//!    Without elastic variables or cones in use, clarabel's solution is then *polished*
//!    (`polish`, option `qp_polish`): the equality QP on its active set, solved exactly
//!    with the faer LDLᵀ, replaces it when that is a KKT point of the QP.
//! 3. **Line search** on the merit φ(x) = f(x) + Σ w_i·viol_i(x) (individual weights
//!    w_i ∈ [|λ_i|, ρ], Powell 1978; w_i = ρ is the classical ℓ1 merit) with Armijo's test
//!    φ(x + αd) ≤ φ(x) − η·α·pred, where pred = m(0) − m(d) ≥ 0 is the decrease of the
//!    QP model of φ. If the full step is rejected, one second-order correction (the QP
//!    again with constraint constants g(x+d) − J d) is tried before backtracking.
//! 4. **Multipliers** are the QP's: λ_{k+1}, z_{k+1}.
//!
//! Termination uses the IPM's scaled KKT error with the same options and meanings
//! (tol 1e-8, s_max, dual_inf_tol, constr_viol_tol, compl_inf_tol, acceptable_*), on
//! the problem scaled by the same gradient-based factors.
//!
//! In the iteration table, `lg(mu)` is log10 of the augmented weight ρ_a ("-" when 0),
//! `lg(rg)` is the Hessian shift δ,
//! the 'r' mark after the iteration number flags elastic mode, and the step character
//! is 'S' for an accepted second-order correction, 'f' otherwise.

#![allow(clippy::needless_range_loop)]

pub mod options;
mod polish;
pub(crate) mod qp;

use std::ops::ControlFlow;
use std::time::Instant;

use faer::sparse::SymbolicSparseColMat;

use crate::callback::{IterationCallback, IterationView, Observer};
use crate::error::SolveError;
use crate::frontend::validate::validate;
use crate::frontend::{KktResiduals, Solver, Termination};
use crate::kkt::Kkt;
use crate::numeric::{AffineCone, NumericNlp};
use crate::scaling::gradient_scale;
use crate::solution::{IterationRecord, Solution, Stats, Status};

pub use options::{HessianApproximation, SqpOptions};
use qp::{Qp, QpData, QpResult};

/// The SQP solver: `Sqp::new(opts).solve(&mut nlp)`, the same call shape as
/// [`Ipm`](crate::Ipm).
#[derive(Debug, Clone, Default)]
pub struct Sqp {
    /// Options.
    pub options: SqpOptions,
}

/// Evaluation counters.
#[derive(Default, Clone)]
struct Counters {
    f: usize,
    grad_f: usize,
    g: usize,
    jac_g: usize,
    hess_l: usize,
    seconds: f64,
}

/// The user's problem with scaling, counters and timing.
struct Scaled<'a> {
    nlp: &'a mut dyn NumericNlp,
    obj_scale: f64,
    g_scale: Vec<f64>,
    counters: Counters,
}

impl Scaled<'_> {
    fn f(&mut self, x: &[f64]) -> f64 {
        let t = Instant::now();
        let v = self.nlp.eval_f(x) * self.obj_scale;
        self.counters.f += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
        v
    }
    fn grad(&mut self, x: &[f64], out: &mut [f64]) {
        let t = Instant::now();
        self.nlp.eval_grad_f(x, out);
        out.iter_mut().for_each(|v| *v *= self.obj_scale);
        self.counters.grad_f += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
    }
    fn g(&mut self, x: &[f64], out: &mut [f64], cone: &mut [f64]) {
        let t = Instant::now();
        self.nlp.eval_g(x, out);
        for (v, s) in out.iter_mut().zip(&self.g_scale) {
            *v *= s;
        }
        if !cone.is_empty() {
            self.nlp.eval_cone_entries(x, cone);
        }
        self.counters.g += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
    }
    fn jac(&mut self, x: &[f64], out: &mut [f64], cone_jac: &mut [f64]) {
        let t = Instant::now();
        self.nlp.eval_jac_g(x, out);
        let p = self.nlp.jac_g_sparsity();
        let rows = p.row_idx();
        for (v, &r) in out.iter_mut().zip(rows) {
            *v *= self.g_scale[r];
        }
        if !cone_jac.is_empty() {
            self.nlp.eval_cone_jac(x, cone_jac);
        }
        self.counters.jac_g += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
    }
    /// Hessian of the scaled Lagrangian f̃ + λ̃ᵀg̃.
    fn hess(&mut self, x: &[f64], lambda: &[f64], out: &mut [f64]) {
        let t = Instant::now();
        let l: Vec<f64> = lambda
            .iter()
            .zip(&self.g_scale)
            .map(|(l, s)| l * s)
            .collect();
        self.nlp.eval_hess_l(x, self.obj_scale, &l, out);
        self.counters.hess_l += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
    }
}

impl Solver for Sqp {
    fn name(&self) -> &'static str {
        "sqp"
    }

    fn solve_dyn(
        &self,
        nlp: &mut dyn NumericNlp,
        warm: Option<&Solution>,
        callback: Option<&mut IterationCallback<'_>>,
    ) -> Result<Solution, SolveError> {
        self.run(nlp, warm, callback)
    }
}

/// Violation of `lo ≤ v ≤ hi`.
fn viol(v: f64, lo: f64, hi: f64) -> f64 {
    (lo - v).max(v - hi).max(0.0)
}

/// Violation of an SOC: ‖v‖ − t (if positive).
fn cone_viol(c: &[f64]) -> f64 {
    let nv = c[1..].iter().map(|v| v * v).sum::<f64>().sqrt();
    (nv - c[0]).max(0.0)
}

/// Constraint and cone data fixed for one solve.
struct Geometry {
    x_l: Vec<f64>,
    x_u: Vec<f64>,
    g_l: Vec<f64>,
    g_u: Vec<f64>,
    cones: Vec<AffineCone>,
    /// Rows of g replaced by an exact cone.
    cone_row: Vec<bool>,
}

impl Geometry {
    /// Weighted ℓ1 penalty Σ w_i·viol_i(g) + ρ·Σ cone violations (the merit's
    /// infeasibility term; w = ρ everywhere is the classical ℓ1 penalty).
    fn penalty(&self, g: &[f64], cone: &[f64], w: &[f64], rho: f64) -> f64 {
        let mut s = 0.0;
        for i in 0..g.len() {
            if !self.cone_row[i] {
                s += w[i] * viol(g[i], self.g_l[i], self.g_u[i]);
            }
        }
        for c in &self.cones {
            s += rho * cone_viol(&cone[c.offset..c.offset + c.dim]);
        }
        s
    }
    /// Max-norm of the violation (g, cones, bounds).
    fn max(&self, x: &[f64], g: &[f64], cone: &[f64]) -> f64 {
        let mut s: f64 = 0.0;
        for i in 0..g.len() {
            if !self.cone_row[i] {
                s = s.max(viol(g[i], self.g_l[i], self.g_u[i]));
            }
        }
        for c in &self.cones {
            s = s.max(cone_viol(&cone[c.offset..c.offset + c.dim]));
        }
        for j in 0..x.len() {
            s = s.max(viol(x[j], self.x_l[j], self.x_u[j]));
        }
        s
    }
}

/// Multipliers of the current iterate.
#[derive(Clone)]
struct Mult {
    lambda: Vec<f64>,
    z_l: Vec<f64>,
    z_u: Vec<f64>,
    z_cone: Vec<f64>,
}

impl Mult {
    /// The QP's multipliers; with the augmented term ½ρ_a‖J_A d‖² the row multiplier is
    /// λ_i + ρ_a·J_i d (the dual of `J_i d − w_i = 0`), which tends to λ_i as d → 0.
    fn from_qp(r: &QpResult) -> Mult {
        let lambda = r.lambda.iter().zip(&r.z_w).map(|(l, w)| l + w).collect();
        Mult {
            lambda,
            z_l: r.z_l.clone(),
            z_u: r.z_u.clone(),
            z_cone: r.z_cone.clone(),
        }
    }
}

/// KKT errors of a (scaled) iterate.
struct Errors {
    /// Scaled overall error (IPOPT's E_0 with s_d, s_c).
    scaled: f64,
    inf_pr: f64,
    inf_du: f64,
    compl: f64,
}

/// Problem-independent scratch for the gradient of the Lagrangian.
#[allow(clippy::too_many_arguments)]
fn lagrangian_gradient(
    grad: &[f64],
    jp: &SymbolicSparseColMat<usize>,
    jv: &[f64],
    cp: Option<&SymbolicSparseColMat<usize>>,
    cv: &[f64],
    mult: &Mult,
    cone_row: &[bool],
    out: &mut [f64],
) {
    out.copy_from_slice(grad);
    for c in 0..grad.len() {
        for p in jp.col_range(c) {
            let r = jp.row_idx()[p];
            if !cone_row[r] {
                out[c] += jv[p] * mult.lambda[r];
            }
        }
        if let Some(cp) = cp {
            for p in cp.col_range(c) {
                out[c] -= cv[p] * mult.z_cone[cp.row_idx()[p]];
            }
        }
    }
}

impl Sqp {
    /// A solver with the given options.
    pub fn new(options: SqpOptions) -> Self {
        Sqp { options }
    }

    /// Solves from the problem's initial point.
    pub fn solve(&self, nlp: &mut dyn NumericNlp) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, None, None)
    }

    /// [`Sqp::solve`] with a per-iteration callback, as
    /// [`Ipm::solve_with_callback`](crate::Ipm::solve_with_callback): called once per row
    /// of `Solution::stats.records` (iteration 0 included) before the convergence test;
    /// [`ControlFlow::Break`] ends the solve with [`Status::UserRequestedStop`].
    pub fn solve_with_callback(
        &self,
        nlp: &mut dyn NumericNlp,
        mut callback: impl FnMut(&IterationView<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, None, Some(&mut callback))
    }

    /// [`Sqp::solve_warm`] with a per-iteration callback (see [`Sqp::solve_with_callback`]).
    pub fn solve_warm_with_callback(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
        mut callback: impl FnMut(&IterationView<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, Some(previous), Some(&mut callback))
    }

    /// Starts from a previous solution's x and multipliers (λ, z_L, z_U): with a good
    /// guess the first QPs already have the right active set.
    pub fn solve_warm(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
    ) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, Some(previous), None)
    }

    fn run(
        &self,
        nlp: &mut dyn NumericNlp,
        warm: Option<&Solution>,
        callback: Option<&mut IterationCallback<'_>>,
    ) -> Result<Solution, SolveError> {
        let start = Instant::now();
        let o = &self.options;
        o.validate()?;
        let v = validate(nlp, warm)?;
        let n = nlp.n();
        let m = nlp.m();
        let jp = nlp.jac_g_sparsity().clone();
        let hp = nlp.hess_l_sparsity().clone();
        let cones: Vec<AffineCone> = nlp.affine_cones().to_vec();
        let cp = nlp.cone_jac_sparsity().cloned();
        let n_cone = cones.iter().map(|c| c.offset + c.dim).max().unwrap_or(0);
        let mut cone_row = vec![false; m];
        for c in &cones {
            cone_row[c.row] = true;
        }
        let mut geo = Geometry {
            x_l: v.x_l,
            x_u: v.x_u,
            g_l: v.g_l,
            g_u: v.g_u,
            cone_row,
            cones: cones.clone(),
        };
        let mut x = v.x0;
        for j in 0..n {
            x[j] = x[j].clamp(geo.x_l[j], geo.x_u[j]);
        }
        let mut sc = Scaled {
            nlp,
            obj_scale: 1.0,
            g_scale: vec![1.0; m],
            counters: Counters::default(),
        };
        let mut grad = vec![0.0; n];
        let mut jv = vec![0.0; jp.row_idx().len()];
        let mut cv = vec![0.0; cp.as_ref().map_or(0, |p| p.row_idx().len())];
        // Gradient-based scaling at the starting point (IPOPT's rule).
        if o.gradient_scaling {
            sc.grad(&x, &mut grad);
            let gmax = grad.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            sc.obj_scale =
                gradient_scale(gmax, o.nlp_scaling_max_gradient, o.nlp_scaling_min_value);
            sc.jac(&x, &mut jv, &mut cv);
            let mut rmax = vec![0.0f64; m];
            for (p, &r) in jp.row_idx().iter().enumerate() {
                rmax[r] = rmax[r].max(jv[p].abs());
            }
            for i in 0..m {
                if !geo.cone_row[i] {
                    sc.g_scale[i] = gradient_scale(
                        rmax[i],
                        o.nlp_scaling_max_gradient,
                        o.nlp_scaling_min_value,
                    );
                }
            }
        }
        for i in 0..m {
            geo.g_l[i] *= sc.g_scale[i];
            geo.g_u[i] *= sc.g_scale[i];
        }
        let mut stats = Stats {
            obj_scaling: sc.obj_scale,
            ..Stats::default()
        };
        let mut g = vec![0.0; m];
        let mut cone = vec![0.0; n_cone];
        let mut f = sc.f(&x);
        sc.g(&x, &mut g, &mut cone);
        sc.grad(&x, &mut grad);
        sc.jac(&x, &mut jv, &mut cv);
        let mut mult = Mult {
            lambda: vec![0.0; m],
            z_l: vec![0.0; n],
            z_u: vec![0.0; n],
            z_cone: vec![0.0; n_cone],
        };
        let mut have_mult = false;
        if let Some(p) = warm {
            for i in 0..m {
                mult.lambda[i] = p.lambda[i] * sc.obj_scale / sc.g_scale[i];
            }
            for j in 0..n {
                mult.z_l[j] = p.z_l[j] * sc.obj_scale;
                mult.z_u[j] = p.z_u[j] * sc.obj_scale;
            }
            have_mult = true;
        }
        let dense = o.hessian_approximation == HessianApproximation::DampedBfgs;
        let block: Vec<(usize, usize)> = cones.iter().map(|c| (c.offset, c.dim)).collect();
        let make_qp = |aug: bool| {
            Qp::new(
                &hp,
                &jp,
                &geo.x_l,
                &geo.x_u,
                &geo.g_l,
                &geo.g_u,
                &block,
                cp.as_ref(),
                &geo.cone_row,
                aug,
                dense,
                o.qp_tol,
                o.qp_max_iter,
            )
        };
        let mut qp = make_qp(false);
        let mut kkt = if dense {
            None
        } else {
            Kkt::new(n, m, &hp, &jp).ok()
        };
        let mut row_weight = vec![0.0; m];
        let mut bound_weight = vec![0.0; n];
        let mut rho_a_last = 0.0f64;
        let mut hv = vec![0.0; hp.row_idx().len()];
        let mut bfgs: Vec<f64> = if dense {
            (0..n * n)
                .map(|k| if k % (n + 1) == 0 { 1.0 } else { 0.0 })
                .collect()
        } else {
            vec![]
        };
        let mut rho = o.penalty_init;
        let mut merit_w = vec![0.0f64; m];
        let mut delta_last = 0.0f64;
        let mut termination = Termination::default();
        let status;
        let mut message = String::new();
        let mut record = IterationRecord {
            iter: 0,
            restoration: false,
            objective: f / sc.obj_scale,
            inf_pr: 0.0,
            inf_du: 0.0,
            mu: 0.0,
            d_norm: 0.0,
            regularization: 0.0,
            jacobian_regularization: 0.0,
            alpha_du: 0.0,
            alpha_pr: 0.0,
            alpha_pr_char: ' ',
            ls: 0,
        };
        let mut observer = callback.map(|cb| Observer::new(cb, n, m, None));
        let mut lgrad = vec![0.0; n];
        let mut iter = 0usize;
        let mut qp_iterations = 0u64;
        let mut n_qp = 0usize;
        let mut qp_seconds = 0.0f64;
        let mut conv_seconds = 0.0f64;
        let mut factor_seconds = 0.0;
        let mut n_fact = 0usize;
        let mut ls_failures = 0usize;
        let mut extra_shift = 0.0f64;
        let mut n_polished = 0usize;
        loop {
            // ---- convergence test ----
            let err = kkt_errors(
                o,
                &geo,
                &x,
                &g,
                &cone,
                &grad,
                &jp,
                &jv,
                cp.as_ref(),
                &cv,
                &mult,
                &mut lgrad,
            );
            let unscaled_du = err.inf_du / sc.obj_scale;
            record.iter = iter;
            record.objective = f / sc.obj_scale;
            record.inf_pr = err.inf_pr;
            record.inf_du = err.inf_du;
            stats.records.push(record);
            if o.print_level >= 5 {
                if iter % 10 == 0 {
                    println!("{}", crate::log::header());
                }
                println!("{}", crate::log::format_record(&record));
            }
            if let Some(obs) = observer.as_mut() {
                let (l, sg, os) = (&mult.lambda, &sc.g_scale, sc.obj_scale);
                if obs.call_sqp(&record, &x, l, sg, os, &cones, &mult.z_cone) {
                    status = Status::UserRequestedStop;
                    message = "stopped by the iteration callback".into();
                    break;
                }
            }
            let unscaled_pr = unscaled_violation(&geo, &sc.g_scale, &x, &g, &cone);
            // Without multipliers (a cold start's iteration 0) the dual error is not
            // measured: no test, and the streak of acceptable iterates restarts.
            let residuals = KktResiduals {
                overall: err.scaled,
                dual: unscaled_du,
                primal: unscaled_pr,
                compl: err.compl / sc.obj_scale,
            };
            if !have_mult {
                termination = Termination::default();
                termination.set_last_objective(f);
            } else if let Some(s) = termination.check(&residuals, f, &o.common) {
                status = s;
                break;
            }
            if iter >= o.max_iter {
                status = Status::MaximumIterationsExceeded;
                break;
            }
            if start.elapsed().as_secs_f64() > o.max_wall_time {
                status = Status::MaximumWallTimeExceeded;
                break;
            }
            if x.iter().any(|v| v.abs() > o.diverging_iterates_tol) {
                status = Status::DivergingIterates;
                break;
            }
            iter += 1;
            // ---- Hessian ----
            let t_fact = Instant::now();
            let mut delta = 0.0;
            if !dense {
                let lam: Vec<f64> = (0..m)
                    .map(|i| if geo.cone_row[i] { 0.0 } else { mult.lambda[i] })
                    .collect();
                sc.hess(&x, &lam, &mut hv);
                if hv.iter().any(|v| !v.is_finite()) {
                    status = Status::InvalidNumberDetected;
                    message = "the Lagrangian Hessian has a non-finite value".into();
                    break;
                }
                let (active_r, active_b) = active_sets(&geo, &x, &g, &mult);
                let conv = Convexify {
                    kkt: kkt.as_mut(),
                    hv: &hv,
                    jv: &jv,
                    active_r: &active_r,
                    active_b: &active_b,
                };
                let t_conv = Instant::now();
                let conv_res = conv.run(o, delta_last, rho_a_last, extra_shift, &mut n_fact);
                conv_seconds += t_conv.elapsed().as_secs_f64();
                match conv_res {
                    Some((d, rho_a)) => {
                        delta = d;
                        rho_a_last = rho_a;
                        for i in 0..m {
                            row_weight[i] = if active_r[i] { rho_a } else { 0.0 };
                        }
                        for j in 0..n {
                            bound_weight[j] = if active_b[j] { rho_a } else { 0.0 };
                        }
                        if rho_a > 0.0 && !qp.has_aug() {
                            qp = make_qp(true);
                        }
                    }
                    None => {
                        status = Status::ErrorInStepComputation;
                        message =
                            "no Hessian shift up to max_hessian_shift made B positive definite"
                                .into();
                        break;
                    }
                }
                delta_last = delta;
            }
            // ---- QP (elastic loop) ----
            let mut qp_shift = delta;
            let mut tries = 0;
            let mut elastic_prev: Option<(QpResult, f64, f64)> = None;
            // The accepted QP's result and the data it was solved with (for polishing).
            let res: Option<(QpResult, QpData)> = loop {
                let data = QpData {
                    x: &x,
                    x_l: &geo.x_l,
                    x_u: &geo.x_u,
                    g: &g,
                    g_l: &geo.g_l,
                    g_u: &geo.g_u,
                    grad: &grad,
                    jac: &jv,
                    cone: &cone,
                    cone_jac: &cv,
                    hess: &hv,
                    shift: qp_shift,
                    bound_weight: &bound_weight,
                    row_weight: &row_weight,
                    dense_b: if dense { Some(&bfgs) } else { None },
                    rho,
                };
                let t_qp = Instant::now();
                let res = qp.solve(&data);
                qp_seconds += t_qp.elapsed().as_secs_f64();
                n_qp += 1;
                let res = match res {
                    Ok(r) => r,
                    Err(e) => {
                        message = format!("QP setup failed: {e}");
                        break None;
                    }
                };
                qp_iterations += res.iterations as u64;
                tries += 1;
                use clarabel::solver::SolverStatus as S;
                match res.status {
                    S::Solved | S::AlmostSolved => {}
                    S::DualInfeasible | S::AlmostDualInfeasible if tries < 8 => {
                        // Unbounded QP: B too flat along a feasible direction (δ·I and
                        // ρ_a·J_AᵀJ_A certified by `Convexify` are positive definite,
                        // but a near-singular B may still read as unbounded to
                        // clarabel): fall back to a pure shift.
                        row_weight.iter_mut().for_each(|v| *v = 0.0);
                        bound_weight.iter_mut().for_each(|v| *v = 0.0);
                        qp_shift = (qp_shift * 100.0).max(o.first_hessian_shift);
                        continue;
                    }
                    _ if tries < 4 => {
                        qp_shift = (qp_shift * 10.0).max(o.first_hessian_shift);
                        continue;
                    }
                    st => {
                        message = format!("QP solver (clarabel) returned {st:?}");
                        break None;
                    }
                }
                let e_max = res.e.iter().fold(0.0f64, |a, v| a.max(*v));
                let e_sum: f64 = res.e.iter().map(|v| v.max(0.0)).sum();
                if e_max > o.elastic_tol {
                    // Elastic mode. A larger ρ helps only while it lowers the linearised
                    // infeasibility; when the linearisation is inconsistent (typical of
                    // complementarity products away from the solution) Σe stalls, and
                    // the step of the smaller ρ is kept (Fletcher & Leyffer 2004, §3).
                    if let Some((_, prev_sum, _)) = &elastic_prev {
                        if e_sum > 0.9 * prev_sum {
                            let (prev, _, prev_rho) = elastic_prev.take().expect("checked");
                            rho = prev_rho;
                            break Some((prev, data));
                        }
                    }
                    if rho < o.penalty_max && tries < 12 {
                        elastic_prev = Some((res, e_sum, rho));
                        rho = (rho * o.penalty_increase).min(o.penalty_max);
                        continue;
                    }
                }
                break Some((res, data));
            };
            factor_seconds += t_fact.elapsed().as_secs_f64();
            let Some((res, data)) = res else {
                status = Status::ErrorInStepComputation;
                break;
            };
            delta = qp_shift;
            // ---- polish: the exact solution of the equality QP on clarabel's active set
            // (see polish.rs; not with cones or elastic variables in use) ----
            let can_polish = o.qp_polish && !dense && n_cone == 0;
            let res = polished(
                kkt.as_mut().filter(|_| can_polish),
                o,
                (&data, &jp, &hp),
                res,
                &mut n_fact,
                &mut n_polished,
            );
            let elastic = res.e.iter().any(|v| *v > o.elastic_tol);
            // ---- merit weights ----
            // Powell (1978): w_i = max(|λ_i|, ½(w_i + |λ_i|)) with the QP's multipliers,
            // kept in [floor, ρ]. Any w with |λ_i| ≤ w_i ≤ ρ keeps pred ≥ 0 (the step is
            // a descent direction of the weighted merit), and rows with small
            // multipliers no longer pay ρ for second-order violations: with one ρ ≥
            // max|λ_i| (≈ 600 on the gap-crossing step-length rows), the bilinear moment
            // rows' O(‖d‖²) violation priced every long step out.
            if iter == 1 {
                // No multiplier history yet: start from the classical weights ρ.
                merit_w.iter_mut().for_each(|w| *w = rho);
            }
            for i in 0..m {
                merit_w[i] = if o.individual_penalties {
                    let l = res.lambda[i].abs();
                    l.max(0.5 * (merit_w[i] + l))
                        .max(o.penalty_weight_floor * rho)
                        .min(rho)
                } else {
                    rho
                };
            }
            // ---- merit and predicted reduction ----
            let d = res.d.clone();
            let phi0 = f + geo.penalty(&g, &cone, &merit_w, rho);
            let mut jd = vec![0.0; m];
            for c in 0..n {
                for p in jp.col_range(c) {
                    jd[jp.row_idx()[p]] += jv[p] * d[c];
                }
            }
            let mut cd = vec![0.0; n_cone];
            if let Some(cp) = cp.as_ref() {
                for c in 0..n {
                    for p in cp.col_range(c) {
                        cd[cp.row_idx()[p]] += cv[p] * d[c];
                    }
                }
            }
            let lin_g: Vec<f64> = (0..m).map(|i| g[i] + jd[i]).collect();
            let lin_c: Vec<f64> = (0..n_cone).map(|k| cone[k] + cd[k]).collect();
            let mut dbd = quad(&hp, &hv, delta, dense.then_some(&bfgs[..]), &d);
            if !dense {
                dbd += (0..m).map(|i| row_weight[i] * jd[i] * jd[i]).sum::<f64>();
                dbd += (0..n).map(|j| bound_weight[j] * d[j] * d[j]).sum::<f64>();
            }
            let gd: f64 = grad.iter().zip(&d).map(|(a, b)| a * b).sum();
            let pred = -(gd + 0.5 * dbd) + geo.penalty(&g, &cone, &merit_w, rho)
                - geo.penalty(&lin_g, &lin_c, &merit_w, rho);
            // ---- line search ----
            let d_norm = d.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let mut alpha = 1.0;
            let mut ls = 0usize;
            let mut xt = vec![0.0; n];
            let mut gt = vec![0.0; m];
            let mut ct = vec![0.0; n_cone];
            let mut ft;
            let mut accepted = false;
            let mut soc_used = false;
            let mut step_res = res.clone();
            // Rounding allowance of the merit: of f, and of every weighted row value (a row
            // at its bound shows violations at the rounding level of g_i, which the weights
            // up to ρ magnify; near a solution these decided the line search, see
            // docs/performance.md, "SQP on the flagship").
            let g_noise: f64 = (0..m)
                .filter(|&i| !geo.cone_row[i])
                .map(|i| merit_w[i] * g[i].abs().max(1.0))
                .sum();
            let slack = 10.0 * f64::EPSILON * (phi0.abs().max(1.0) + g_noise);
            let x_max = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            // A step at rounding level of x is taken without the merit test (IPOPT's 't').
            let tiny = d_norm <= 1e-9 * (1.0 + x_max);
            loop {
                ls += 1;
                for j in 0..n {
                    xt[j] = (x[j] + alpha * d[j]).clamp(geo.x_l[j], geo.x_u[j]);
                }
                ft = sc.f(&xt);
                sc.g(&xt, &mut gt, &mut ct);
                let finite = ft.is_finite()
                    && gt.iter().all(|v| v.is_finite())
                    && ct.iter().all(|v| v.is_finite());
                if finite {
                    let phi = ft + geo.penalty(&gt, &ct, &merit_w, rho);
                    if tiny || phi <= phi0 - o.armijo * alpha * pred.max(0.0) + slack {
                        accepted = true;
                        break;
                    }
                    if alpha == 1.0 && o.second_order_correction && pred > 0.0 {
                        // Second-order correction: constants g(x+d) − J d.
                        let gh: Vec<f64> = (0..m).map(|i| gt[i] - jd[i]).collect();
                        let chat: Vec<f64> = (0..n_cone).map(|k| ct[k] - cd[k]).collect();
                        let t_qp = Instant::now();
                        let r2 = qp
                            .resolve_with_g(&x, &geo.x_l, &geo.x_u, &gh, &geo.g_l, &geo.g_u, &chat);
                        qp_seconds += t_qp.elapsed().as_secs_f64();
                        n_qp += 1;
                        if let Ok(r2) = r2 {
                            qp_iterations += r2.iterations as u64;
                            if matches!(
                                r2.status,
                                clarabel::solver::SolverStatus::Solved
                                    | clarabel::solver::SolverStatus::AlmostSolved
                            ) {
                                let mut xs = vec![0.0; n];
                                for j in 0..n {
                                    xs[j] = (x[j] + r2.d[j]).clamp(geo.x_l[j], geo.x_u[j]);
                                }
                                let fs = sc.f(&xs);
                                let mut gs = vec![0.0; m];
                                let mut cs = vec![0.0; n_cone];
                                sc.g(&xs, &mut gs, &mut cs);
                                let phis = fs + geo.penalty(&gs, &cs, &merit_w, rho);
                                if phis.is_finite() && phis <= phi0 - o.armijo * pred + slack {
                                    xt = xs;
                                    ft = fs;
                                    gt = gs;
                                    ct = cs;
                                    step_res = r2;
                                    soc_used = true;
                                    accepted = true;
                                    break;
                                }
                            }
                        }
                    }
                }
                alpha *= o.backtrack;
                if alpha < o.min_step {
                    break;
                }
            }
            record = IterationRecord {
                iter,
                restoration: elastic,
                objective: 0.0,
                inf_pr: 0.0,
                inf_du: 0.0,
                mu: rho_a_last,
                d_norm,
                regularization: delta,
                jacobian_regularization: 0.0,
                alpha_du: alpha,
                alpha_pr: alpha,
                alpha_pr_char: if soc_used {
                    'S'
                } else if tiny {
                    't'
                } else {
                    'f'
                },
                ls,
            };
            stats.max_regularization = stats.max_regularization.max(delta);
            if !accepted {
                ls_failures += 1;
                if d_norm <= 1e-14 * (1.0 + x.iter().fold(0.0f64, |a, v| a.max(v.abs())))
                    || ls_failures > 8
                {
                    let pr = unscaled_violation(&geo, &sc.g_scale, &x, &g, &cone);
                    status = if pr > o.constr_viol_tol {
                        Status::InfeasibleProblemDetected
                    } else {
                        Status::SearchDirectionBecomesTooSmall
                    };
                    message = format!("line search failed (pred = {pred:.3e}, ‖d‖ = {d_norm:.3e})");
                    break;
                }
                // Shorter, more conservative steps next time (a trust-region-like reaction).
                extra_shift = (extra_shift * 10.0).max(1e-2 * (1.0 + delta));
                // Multipliers of the QP are still the best estimate.
                mult = Mult::from_qp(&res);
                have_mult = true;
                continue;
            }
            ls_failures = 0;
            // Levenberg–Marquardt-like safeguard: a heavily cut step means the model is
            // poor at this length, so the next step is shortened by a proximal shift;
            // full steps relax it again.
            if alpha < 0.1 && !soc_used {
                extra_shift = (extra_shift * 10.0).max(1e-1);
            } else if alpha == 1.0 {
                extra_shift = if extra_shift > 1e-6 {
                    extra_shift / 10.0
                } else {
                    0.0
                };
            }
            // ---- accept ----
            let x_old = std::mem::replace(&mut x, xt);
            f = ft;
            g = gt;
            cone = ct;
            mult = Mult::from_qp(&step_res);
            have_mult = true;
            let grad_old = grad.clone();
            let jv_old = jv.clone();
            let cv_old = cv.clone();
            sc.grad(&x, &mut grad);
            sc.jac(&x, &mut jv, &mut cv);
            if grad.iter().chain(&jv).any(|v| !v.is_finite()) {
                status = Status::InvalidNumberDetected;
                message = "non-finite gradient or Jacobian at the accepted point".into();
                break;
            }
            if dense {
                bfgs_update(
                    &mut bfgs,
                    n,
                    &x_old,
                    &x,
                    &grad_old,
                    &jv_old,
                    &cv_old,
                    &grad,
                    &jv,
                    &cv,
                    &jp,
                    cp.as_ref(),
                    &mult,
                    &geo.cone_row,
                );
            }
        }
        stats.iterations = iter;
        stats.n_factorizations = n_fact;
        stats.factor_seconds = factor_seconds;
        stats.n_qp_solves = n_qp;
        stats.qp_iterations = qp_iterations as usize;
        stats.qp_seconds = qp_seconds;
        let _ = conv_seconds;
        let sol = finish(
            &mut sc,
            &geo,
            &x,
            &mult,
            status,
            message,
            stats,
            start,
            cp.as_ref(),
            &cones,
        );
        if o.print_level >= 3 {
            print!("{}", crate::log::format_summary(&sol));
            println!("Polished QP solutions: {n_polished} of {n_qp}");
        }
        Ok(sol)
    }
}

/// The QP result `res` polished ([`polish::polish`]) when a KKT matrix is given and no
/// elastic variable is in use; `res` itself otherwise or when polishing is rejected.
fn polished(
    kkt: Option<&mut Kkt>,
    o: &SqpOptions,
    (data, jp, hp): (
        &QpData,
        &SymbolicSparseColMat<usize>,
        &SymbolicSparseColMat<usize>,
    ),
    res: QpResult,
    n_fact: &mut usize,
    n_polished: &mut usize,
) -> QpResult {
    match kkt {
        Some(kkt) if res.e.iter().all(|v| *v <= o.elastic_tol) => {
            match polish::polish(kkt, data, jp, hp, &res, n_fact) {
                Some(p) => {
                    *n_polished += 1;
                    p
                }
                None => res,
            }
        }
        _ => res,
    }
}

/// ½-less quadratic form dᵀBd for B = lower-triangular H + δI (or dense B).
fn quad(
    hp: &SymbolicSparseColMat<usize>,
    hv: &[f64],
    delta: f64,
    dense: Option<&[f64]>,
    d: &[f64],
) -> f64 {
    let n = d.len();
    if let Some(b) = dense {
        let mut s = 0.0;
        for j in 0..n {
            for i in 0..n {
                s += d[i] * b[i + j * n] * d[j];
            }
        }
        return s;
    }
    let mut s = delta * d.iter().map(|v| v * v).sum::<f64>();
    for c in 0..n {
        for p in hp.col_range(c) {
            let r = hp.row_idx()[p];
            let w = if r == c { 1.0 } else { 2.0 };
            s += w * hv[p] * d[r] * d[c];
        }
    }
    s
}

/// Which rows of g and which variable bounds count as active for the
/// augmented-Lagrangian convexification: equality rows, and inequality rows and bounds
/// whose multiplier is nonzero with the sign of an active side (strongly active).
///
/// A row or bound merely at its bound, or with a multiplier of the wrong sign, is left
/// out: the term ½ρ_a(J_i d)² penalises leaving the constraint in both directions, so on
/// a constraint the step should leave it acts as a proximal term of weight ρ_a and the
/// iterates creep (the gap-crossing planner crawled at ‖d‖ ≈ 1e-4 for 3000 iterations
/// with complementarity error 5e3 when "at the bound" counted as active).
fn active_sets(geo: &Geometry, x: &[f64], g: &[f64], mult: &Mult) -> (Vec<bool>, Vec<bool>) {
    const TOL: f64 = 1e-6;
    // "Nearly at the bound": a multiplier left on a row the iterate has moved away from
    // (e.g. the share ρ_a·J_i d of the last step) must not keep the row active.
    let near = |a: f64, b: f64| (a - b).abs() <= 1e-3 * (1.0 + b.abs());
    let rows = (0..g.len())
        .map(|i| {
            !geo.cone_row[i]
                && (geo.g_l[i] == geo.g_u[i]
                    || (geo.g_u[i].is_finite() && mult.lambda[i] > TOL && near(g[i], geo.g_u[i]))
                    || (geo.g_l[i].is_finite() && mult.lambda[i] < -TOL && near(g[i], geo.g_l[i])))
        })
        .collect();
    let bounds = (0..x.len())
        .map(|j| {
            (geo.x_l[j].is_finite() && mult.z_l[j] > TOL && near(x[j], geo.x_l[j]))
                || (geo.x_u[j].is_finite() && mult.z_u[j] > TOL && near(x[j], geo.x_u[j]))
        })
        .collect();
    (rows, bounds)
}

/// Finds B = H + δI + ρ_a·(J_Aᵀ J_A + I_bounds) positive definite, where A are the active
/// rows and bounds. By the Schur complement, B is positive definite iff
/// `[H + δI + ρ_a·I_b, J_Aᵀ; J_A, −I/ρ_a]` (inactive rows with a negligible −1e20 pivot)
/// has inertia (n, m, 0) — the test IPOPT applies to its KKT matrix, counted from a faer
/// LDLᵀ ([`Kkt`]). Order: (0, 0) unless the last iteration needed ρ_a > 0; (0, ρ₀) with
/// ρ₀ = max(1, ρ_last/10); then δ by IPOPT's sequence with the test at ρ_a =
/// `max_augmented_weight` (positive definite on the null space of the active
/// constraints, so the QP keeps the Newton step there: for d with J_A d = −c_A the
/// augmented term is constant); then the smallest ρ_a = ρ₀·10^k passing at that δ.
struct Convexify<'a> {
    kkt: Option<&'a mut Kkt>,
    hv: &'a [f64],
    jv: &'a [f64],
    active_r: &'a [bool],
    active_b: &'a [bool],
}

impl Convexify<'_> {
    fn run(
        self,
        o: &SqpOptions,
        delta_last: f64,
        rho_last: f64,
        extra: f64,
        n_fact: &mut usize,
    ) -> Option<(f64, f64)> {
        let Convexify {
            kkt,
            hv,
            jv,
            active_r,
            active_b,
        } = self;
        let kkt = kkt?;
        let (n, m) = (kkt.n(), kkt.m());
        let mut test = |delta: f64, rho: f64| -> bool {
            *n_fact += 1;
            let dx: Vec<f64> = (0..n)
                .map(|j| delta + if active_b[j] { rho } else { 0.0 })
                .collect();
            let dc: Vec<f64> = (0..m)
                .map(|i| {
                    if rho > 0.0 && active_r[i] {
                        1.0 / rho
                    } else {
                        1e20
                    }
                })
                .collect();
            matches!(kkt.factorize(hv, &dx, jv, &dc), Ok(i) if i.positive == n && i.negative == m)
        };
        let any_active = active_r.iter().chain(active_b).any(|&a| a);
        let rho_max = o.max_augmented_weight;
        // Smallest shift δ ≥ δ_min for which `ok(δ)` holds, IPOPT's sequence: δ_min (0
        // when allowed), then first_hessian_shift or δ_last/3, ×100 at first, ×8 after.
        let shift_search = |test: &mut dyn FnMut(f64) -> bool, allow_zero: bool| {
            if allow_zero && test(0.0) {
                return Some(0.0);
            }
            let mut delta = if delta_last == 0.0 {
                o.first_hessian_shift
            } else {
                (delta_last / 3.0).max(o.min_hessian_shift)
            };
            delta = delta.max(extra);
            let grow = if delta_last == 0.0 { 100.0 } else { 8.0 };
            while delta <= o.max_hessian_shift {
                if test(delta) {
                    return Some(delta);
                }
                delta *= grow;
            }
            None
        };
        if extra == 0.0 && rho_last == 0.0 && test(0.0, 0.0) {
            return Some((0.0, 0.0));
        }
        if !any_active {
            return shift_search(&mut |d| test(d, 0.0), extra == 0.0).map(|d| (d, 0.0));
        }
        // The cheapest guess first: the last iteration's weight (or a tenth of it).
        let rho0 = if rho_last > 0.0 {
            (rho_last / 10.0).max(1.0)
        } else {
            1.0
        };
        if extra == 0.0 && test(0.0, rho0) {
            return Some((0.0, rho0));
        }
        // δ for the reduced Hessian: the test in the limit ρ_a = rho_max is IPOPT's
        // inertia test of [H + δI, J_Aᵀ; J_A, −I/rho_max] (active bounds nearly fixed),
        // i.e. positive definiteness on the null space of the active constraints. A
        // shift of the full-space Hessian (ρ_a = 0) would also pay for curvature across
        // the constraints, which the augmented term supplies for free.
        let delta = shift_search(&mut |d| test(d, rho_max), extra == 0.0)?;
        // Then the smallest weight ρ_a (×10 from rho0) that makes B itself positive
        // definite; rho_max passed above.
        let mut rho = if delta == 0.0 { rho0 * 10.0 } else { rho0 };
        while rho < rho_max {
            if test(delta, rho) {
                return Some((delta, rho));
            }
            rho *= 10.0;
        }
        Some((delta, rho_max))
    }
}

/// Damped BFGS update (Powell) of the dense B with s = x⁺ − x, y = ∇L(x⁺) − ∇L(x) (both
/// with the new multipliers).
#[allow(clippy::too_many_arguments)]
fn bfgs_update(
    b: &mut [f64],
    n: usize,
    x0: &[f64],
    x1: &[f64],
    g0: &[f64],
    j0: &[f64],
    c0: &[f64],
    g1: &[f64],
    j1: &[f64],
    c1: &[f64],
    jp: &SymbolicSparseColMat<usize>,
    cp: Option<&SymbolicSparseColMat<usize>>,
    mult: &Mult,
    cone_row: &[bool],
) {
    let mut l0 = vec![0.0; n];
    let mut l1 = vec![0.0; n];
    lagrangian_gradient(g0, jp, j0, cp, c0, mult, cone_row, &mut l0);
    lagrangian_gradient(g1, jp, j1, cp, c1, mult, cone_row, &mut l1);
    let s: Vec<f64> = (0..n).map(|i| x1[i] - x0[i]).collect();
    let y: Vec<f64> = (0..n).map(|i| l1[i] - l0[i]).collect();
    let bs: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| b[i + j * n] * s[j]).sum())
        .collect();
    let sbs: f64 = s.iter().zip(&bs).map(|(a, c)| a * c).sum();
    if sbs <= 1e-20 {
        return;
    }
    let sy: f64 = s.iter().zip(&y).map(|(a, c)| a * c).sum();
    let theta = if sy >= 0.2 * sbs {
        1.0
    } else {
        0.8 * sbs / (sbs - sy)
    };
    let r: Vec<f64> = (0..n)
        .map(|i| theta * y[i] + (1.0 - theta) * bs[i])
        .collect();
    let sr: f64 = s.iter().zip(&r).map(|(a, c)| a * c).sum();
    if sr <= 1e-20 {
        return;
    }
    for j in 0..n {
        for i in 0..n {
            b[i + j * n] += -bs[i] * bs[j] / sbs + r[i] * r[j] / sr;
        }
    }
}

/// Max-norm violation in the user's (unscaled) units.
fn unscaled_violation(geo: &Geometry, g_scale: &[f64], x: &[f64], g: &[f64], cone: &[f64]) -> f64 {
    let mut s: f64 = 0.0;
    for i in 0..g.len() {
        if !geo.cone_row[i] {
            s = s.max(viol(g[i], geo.g_l[i], geo.g_u[i]) / g_scale[i]);
        }
    }
    for c in &geo.cones {
        s = s.max(cone_viol(&cone[c.offset..c.offset + c.dim]));
    }
    for j in 0..x.len() {
        s = s.max(viol(x[j], geo.x_l[j], geo.x_u[j]));
    }
    s
}

/// The IPM's scaled KKT error on the scaled problem.
#[allow(clippy::too_many_arguments)]
fn kkt_errors(
    o: &SqpOptions,
    geo: &Geometry,
    x: &[f64],
    g: &[f64],
    cone: &[f64],
    grad: &[f64],
    jp: &SymbolicSparseColMat<usize>,
    jv: &[f64],
    cp: Option<&SymbolicSparseColMat<usize>>,
    cv: &[f64],
    mult: &Mult,
    lgrad: &mut [f64],
) -> Errors {
    let n = x.len();
    lagrangian_gradient(grad, jp, jv, cp, cv, mult, &geo.cone_row, lgrad);
    let mut inf_du: f64 = 0.0;
    for j in 0..n {
        inf_du = inf_du.max((lgrad[j] - mult.z_l[j] + mult.z_u[j]).abs());
    }
    let inf_pr = geo.max(x, g, cone);
    let mut compl: f64 = 0.0;
    let mut ysum = 0.0;
    let mut zsum = 0.0;
    let mut nz = 0usize;
    let mut ny = 0usize;
    for i in 0..g.len() {
        if geo.cone_row[i] {
            continue;
        }
        ny += 1;
        ysum += mult.lambda[i].abs();
        if geo.g_l[i] != geo.g_u[i] {
            if geo.g_l[i].is_finite() {
                compl = compl.max(((g[i] - geo.g_l[i]) * (-mult.lambda[i]).max(0.0)).abs());
            }
            if geo.g_u[i].is_finite() {
                compl = compl.max(((geo.g_u[i] - g[i]) * mult.lambda[i].max(0.0)).abs());
            }
        }
    }
    for j in 0..n {
        if geo.x_l[j] == geo.x_u[j] {
            continue;
        }
        if geo.x_l[j].is_finite() {
            nz += 1;
            zsum += mult.z_l[j].abs();
            compl = compl.max(((x[j] - geo.x_l[j]) * mult.z_l[j]).abs());
        }
        if geo.x_u[j].is_finite() {
            nz += 1;
            zsum += mult.z_u[j].abs();
            compl = compl.max(((geo.x_u[j] - x[j]) * mult.z_u[j]).abs());
        }
    }
    for c in &geo.cones {
        let r = c.offset..c.offset + c.dim;
        let sz: f64 = cone[r.clone()]
            .iter()
            .zip(&mult.z_cone[r.clone()])
            .map(|(a, b)| a * b)
            .sum();
        compl = compl.max(sz.abs());
        nz += 1;
        zsum += mult.z_cone[c.offset].abs();
    }
    let s_max = o.s_max;
    let s_d = if ny + nz == 0 {
        1.0
    } else {
        s_max.max((ysum + zsum) / (ny + nz) as f64) / s_max
    };
    let s_c = if nz == 0 {
        1.0
    } else {
        s_max.max(zsum / nz as f64) / s_max
    };
    Errors {
        scaled: (inf_du / s_d).max(inf_pr).max(compl / s_c),
        inf_pr,
        inf_du,
        compl,
    }
}

/// The user-level solution (unscaled) at x with the given multipliers.
#[allow(clippy::too_many_arguments)]
fn finish(
    sc: &mut Scaled<'_>,
    geo: &Geometry,
    x: &[f64],
    mult: &Mult,
    status: Status,
    message: String,
    mut stats: Stats,
    start: Instant,
    cp: Option<&SymbolicSparseColMat<usize>>,
    cones: &[AffineCone],
) -> Solution {
    let n = x.len();
    let m = geo.g_l.len();
    let os = sc.obj_scale;
    let t = Instant::now();
    let nlp = &mut *sc.nlp;
    let objective = nlp.eval_f(x);
    let mut grad = vec![0.0; n];
    nlp.eval_grad_f(x, &mut grad);
    let mut g = vec![0.0; m];
    nlp.eval_g(x, &mut g);
    let jp = nlp.jac_g_sparsity().clone();
    let mut jv = vec![0.0; jp.row_idx().len()];
    nlp.eval_jac_g(x, &mut jv);
    let n_cone = mult.z_cone.len();
    let mut cone = vec![0.0; n_cone];
    let mut cv = vec![0.0; cp.map_or(0, |p| p.row_idx().len())];
    if n_cone > 0 {
        nlp.eval_cone_entries(x, &mut cone);
        nlp.eval_cone_jac(x, &mut cv);
    }
    sc.counters.f += 1;
    sc.counters.grad_f += 1;
    sc.counters.g += 1;
    sc.counters.jac_g += 1;
    sc.counters.seconds += t.elapsed().as_secs_f64();
    let mut lambda: Vec<f64> = (0..m)
        .map(|i| mult.lambda[i] * sc.g_scale[i] / os)
        .collect();
    let z_l: Vec<f64> = mult.z_l.iter().map(|v| v / os).collect();
    let z_u: Vec<f64> = mult.z_u.iter().map(|v| v / os).collect();
    let z_cone: Vec<f64> = mult.z_cone.iter().map(|v| v / os).collect();
    let um = Mult {
        lambda: lambda.clone(),
        z_l: z_l.clone(),
        z_u: z_u.clone(),
        z_cone: z_cone.clone(),
    };
    let mut r = vec![0.0; n];
    lagrangian_gradient(&grad, &jp, &jv, cp, &cv, &um, &geo.cone_row, &mut r);
    let dual_inf = (0..n).fold(0.0f64, |a, j| a.max((r[j] - z_l[j] + z_u[j]).abs()));
    // The smooth row of a cone reports the cone's multiplier z_t.
    for c in cones {
        lambda[c.row] = z_cone[c.offset];
    }
    let mut constr_viol: f64 = 0.0;
    let mut compl: f64 = 0.0;
    for j in 0..n {
        constr_viol = constr_viol.max(viol(x[j], geo.x_l[j], geo.x_u[j]));
        if geo.x_l[j] != geo.x_u[j] {
            if geo.x_l[j].is_finite() {
                compl = compl.max(((x[j] - geo.x_l[j]) * z_l[j]).abs());
            }
            if geo.x_u[j].is_finite() {
                compl = compl.max(((geo.x_u[j] - x[j]) * z_u[j]).abs());
            }
        }
    }
    for i in 0..m {
        if geo.cone_row[i] {
            continue;
        }
        let (l, u) = (geo.g_l[i] / sc.g_scale[i], geo.g_u[i] / sc.g_scale[i]);
        constr_viol = constr_viol.max(viol(g[i], l, u));
        if l != u {
            if l.is_finite() {
                compl = compl.max(((g[i] - l) * (-lambda[i]).max(0.0)).abs());
            }
            if u.is_finite() {
                compl = compl.max(((u - g[i]) * lambda[i].max(0.0)).abs());
            }
        }
    }
    for c in cones {
        constr_viol = constr_viol.max(cone_viol(&cone[c.offset..c.offset + c.dim]));
    }
    stats.n_eval_f = sc.counters.f;
    stats.n_eval_grad_f = sc.counters.grad_f;
    stats.n_eval_g = sc.counters.g;
    stats.n_eval_jac_g = sc.counters.jac_g;
    stats.n_eval_hess_l = sc.counters.hess_l;
    stats.eval_seconds = sc.counters.seconds;
    stats.total_seconds = start.elapsed().as_secs_f64();
    stats.other_seconds =
        (stats.total_seconds - stats.eval_seconds - stats.factor_seconds).max(0.0);
    Solution {
        status,
        x: x.to_vec(),
        lambda,
        z_l,
        z_u,
        g,
        objective,
        constr_viol,
        dual_inf,
        compl,
        message,
        stats,
    }
}
