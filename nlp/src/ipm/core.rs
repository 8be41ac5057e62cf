//! The primal-dual interior-point iteration (Wächter & Biegler 2006) on a problem in the
//! form seen through [`IpmProblem`]: inequality rows get slacks s (g(x) − s = 0,
//! g_l ≤ s ≤ g_u) and the primal vector is w = [x; s].

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use std::time::Instant;

use crate::callback::Observer;
use crate::frontend::{KktResiduals, Termination};
use crate::ipm::barrier::{loqo_mu, monotone_next, mu_floor, probing_mu, tau};
use crate::ipm::error::{At, CoreError};
use crate::ipm::filter::Filter;
use crate::ipm::reduced::IpmProblem;
use crate::ipm::restoration;
use crate::kkt::Kkt;
use crate::options::{IpmOptions, MuOracle, MuStrategy};
use crate::solution::{IterationRecord, Stats, Status};

/// State shared by the outer loop and nested restoration loops.
pub(crate) struct Shared<'c> {
    pub stats: Stats,
    pub start: Instant,
    pub iter: usize,
    /// The user's iteration callback, called by `record`.
    pub observer: Option<Observer<'c>>,
}

/// How to start the iteration.
pub(crate) enum Start {
    /// Push x0 into the bounds, least-squares y, bound multipliers = bound_mult_init_val.
    Cold,
    /// Warm start: x0 from the problem, given y and z (length n); warm-start pushes.
    Warm {
        y: Vec<f64>,
        zl: Vec<f64>,
        zu: Vec<f64>,
    },
    /// Exact full iterate (restoration): w = [x; s], y, z for all of w.
    Exact {
        w: Vec<f64>,
        y: Vec<f64>,
        zl: Vec<f64>,
        zu: Vec<f64>,
    },
}

/// Parameters of one run of the core.
pub(crate) struct Setup {
    pub mu_init: f64,
    pub bound_relax_factor: f64,
    pub in_resto: bool,
    pub obj_scale: f64,
    pub g_scale: Vec<f64>,
    pub mu_strategy: MuStrategy,
}

/// Result of a run.
pub(crate) struct Outcome {
    pub status: Status,
    pub w: Vec<f64>,
    pub y: Vec<f64>,
    pub zl: Vec<f64>,
    pub zu: Vec<f64>,
    pub message: String,
    /// For restoration: the inner problem converged (optimal) rather than being stopped
    /// by the acceptance hook.
    pub resto_converged: bool,
}

/// How the step of an accepted trial point was made (the log's character after
/// alpha_pr: lower case for the plain step, upper case for a second-order correction).
#[derive(Clone, Copy, Debug, PartialEq)]
enum StepKind {
    /// f-type: the switching and Armijo conditions hold; the filter is not augmented.
    FType { soc: bool },
    /// h-type: the filter was augmented.
    HType { soc: bool },
}

impl StepKind {
    fn new(ftype: bool, soc: bool) -> StepKind {
        if ftype {
            StepKind::FType { soc }
        } else {
            StepKind::HType { soc }
        }
    }

    fn log_char(self) -> char {
        match self {
            StepKind::FType { soc: false } => 'f',
            StepKind::HType { soc: false } => 'h',
            StepKind::FType { soc: true } => 'F',
            StepKind::HType { soc: true } => 'H',
        }
    }
}

/// The outcome of [`Core::line_search`]; `trials` counts the trial step sizes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum LineSearch {
    /// A trial point was accepted (and is now the iterate).
    Accepted {
        alpha_pr: f64,
        alpha_du: f64,
        kind: StepKind,
        trials: usize,
    },
    /// Every step size down to α_min was rejected; `alpha_pr` is the last one tried.
    Failed { alpha_pr: f64, trials: usize },
}

pub(crate) struct Core<'p> {
    pub nlp: &'p mut dyn IpmProblem,
    pub opts: IpmOptions,
    pub n: usize,
    pub m: usize,
    pub ni: usize,
    pub nw: usize,
    /// row → slack index (usize::MAX for equality rows).
    pub slack_of_row: Vec<usize>,
    /// slack index → row.
    pub row_of_slack: Vec<usize>,
    /// Right-hand side of equality rows.
    pub g_eq: Vec<f64>,
    pub wl: Vec<f64>,
    pub wu: Vec<f64>,
    pub has_l: Vec<bool>,
    pub has_u: Vec<bool>,
    // iterate
    pub w: Vec<f64>,
    pub y: Vec<f64>,
    pub zl: Vec<f64>,
    pub zu: Vec<f64>,
    pub f: f64,
    pub grad: Vec<f64>,
    pub g: Vec<f64>,
    pub c: Vec<f64>,
    pub jac: Vec<f64>,
    hess: Vec<f64>,
    // trial
    w_t: Vec<f64>,
    y_t: Vec<f64>,
    f_t: f64,
    grad_t: Vec<f64>,
    g_t: Vec<f64>,
    c_t: Vec<f64>,
    jac_t: Vec<f64>,
    hess_t: Vec<f64>,
    // direction
    dw: Vec<f64>,
    dy: Vec<f64>,
    dzl: Vec<f64>,
    dzu: Vec<f64>,
    dw_s: Vec<f64>,
    dy_s: Vec<f64>,
    dzl_s: Vec<f64>,
    dzu_s: Vec<f64>,
    c_soc: Vec<f64>,
    // linear algebra
    pub kkt: Kkt,
    kdx: Vec<f64>,
    kdc: Vec<f64>,
    rhs: Vec<f64>,
    rhs_s: Vec<f64>,
    rhs_copy: Vec<f64>,
    ds: Vec<f64>,
    /// The static regularisations in the last factorised matrix, with the sign that
    /// removes them in iterative refinement (set by `factor_kkt`).
    shift: Vec<f64>,
    /// Static regularisation of each equality row (see `update_eq_reg`).
    eq_reg: Vec<f64>,
    /// The regularisation of the current factorisation (see `step_eq_reg`).
    eq_reg_step: Vec<f64>,
    /// Position of the diagonal entry of each Hessian column (usize::MAX: none).
    hess_diag: Vec<usize>,
    hzero: Vec<f64>,
    work_nw: Vec<f64>,
    // algorithm state
    pub mu: f64,
    tau: f64,
    pub filter: Filter,
    theta_min: f64,
    theta_max: f64,
    delta_w: f64,
    delta_w_last: f64,
    delta_c: f64,
    jac_degenerate: bool,
    singular_iters: usize,
    perturbed_iters: usize,
    free_mode: bool,
    kkt_refs: Vec<f64>,
    tiny_count: usize,
    /// The convergence test's state (acceptable streak, previous objective).
    termination: Termination,
    setup_in_resto: bool,
    obj_scale: f64,
    g_scale: Vec<f64>,
    mu_strategy: MuStrategy,
    resto_calls: usize,
    /// The outer iteration's failed line search (alpha_pr, ls) that starts a restoration
    /// phase; shown in the restoration's first log row as IPOPT does ("12r … 4.8e-7R 22").
    pub resto_start: Option<(f64, usize)>,
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, &b| a.max(b.abs()))
}

fn one_norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x.abs()).sum()
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn first_non_finite(v: &[f64]) -> Option<usize> {
    v.iter().position(|x| !x.is_finite())
}

/// φ_μ(w) = f − μ Σ ln(slack) + κ_d μ Σ slack (one-sided bounds only).
#[allow(clippy::too_many_arguments)]
pub(crate) fn barrier_value(
    w: &[f64],
    f: f64,
    mu: f64,
    kappa_d: f64,
    wl: &[f64],
    wu: &[f64],
    has_l: &[bool],
    has_u: &[bool],
) -> f64 {
    let kd = kappa_d * mu;
    let mut phi = f;
    for j in 0..w.len() {
        if has_l[j] {
            let s = w[j] - wl[j];
            phi -= mu * s.ln();
            if !has_u[j] {
                phi += kd * s;
            }
        }
        if has_u[j] {
            let s = wu[j] - w[j];
            phi -= mu * s.ln();
            if !has_l[j] {
                phi += kd * s;
            }
        }
    }
    phi
}

impl<'p> Core<'p> {
    pub fn new(
        nlp: &'p mut dyn IpmProblem,
        opts: &IpmOptions,
        setup: &Setup,
    ) -> Result<Self, CoreError> {
        let n = nlp.n();
        let m = nlp.m();
        let mut x_l = vec![0.0; n];
        let mut x_u = vec![0.0; n];
        let mut g_l = vec![0.0; m];
        let mut g_u = vec![0.0; m];
        nlp.bounds(&mut x_l, &mut x_u, &mut g_l, &mut g_u);
        let mut slack_of_row = vec![usize::MAX; m];
        let mut row_of_slack = Vec::new();
        let mut g_eq = vec![0.0; m];
        for i in 0..m {
            if g_l[i] == g_u[i] {
                g_eq[i] = g_l[i];
            } else {
                slack_of_row[i] = row_of_slack.len();
                row_of_slack.push(i);
            }
        }
        let ni = row_of_slack.len();
        let nw = n + ni;
        let mut wl = vec![f64::NEG_INFINITY; nw];
        let mut wu = vec![f64::INFINITY; nw];
        wl[..n].copy_from_slice(&x_l);
        wu[..n].copy_from_slice(&x_u);
        for (k, &i) in row_of_slack.iter().enumerate() {
            wl[n + k] = g_l[i];
            wu[n + k] = g_u[i];
        }
        let rf = setup.bound_relax_factor;
        for j in 0..nw {
            if wl[j].is_finite() {
                wl[j] -= rf * wl[j].abs().max(1.0);
            }
            if wu[j].is_finite() {
                wu[j] += rf * wu[j].abs().max(1.0);
            }
        }
        let has_l: Vec<bool> = wl.iter().map(|v| v.is_finite()).collect();
        let has_u: Vec<bool> = wu.iter().map(|v| v.is_finite()).collect();
        let kkt = Kkt::new(n, m, nlp.hess_l_sparsity(), nlp.jac_g_sparsity())?;
        let nnz_j = nlp.jac_g_sparsity().row_idx().len();
        let nnz_h = nlp.hess_l_sparsity().row_idx().len();
        let mut kkt = kkt;
        kkt.min_refinement_steps = opts.min_refinement_steps;
        kkt.max_refinement_steps = opts.max_refinement_steps;
        kkt.residual_ratio_max = opts.residual_ratio_max;
        // Refinement target: K without the static regularisation of equality rows.
        let shift = vec![0.0; n + m];
        let mut hess_diag = vec![usize::MAX; n];
        {
            let hp = nlp.hess_l_sparsity();
            for (j, d) in hess_diag.iter_mut().enumerate() {
                for p in hp.col_range(j) {
                    if hp.row_idx()[p] == j {
                        *d = p;
                    }
                }
            }
        }
        Ok(Core {
            nlp,
            opts: opts.clone(),
            n,
            m,
            ni,
            nw,
            slack_of_row,
            row_of_slack,
            g_eq,
            wl,
            wu,
            has_l,
            has_u,
            w: vec![0.0; nw],
            y: vec![0.0; m],
            zl: vec![0.0; nw],
            zu: vec![0.0; nw],
            f: 0.0,
            grad: vec![0.0; n],
            g: vec![0.0; m],
            c: vec![0.0; m],
            jac: vec![0.0; nnz_j],
            hess: vec![0.0; nnz_h],
            w_t: vec![0.0; nw],
            y_t: vec![0.0; m],
            f_t: 0.0,
            grad_t: vec![0.0; n],
            g_t: vec![0.0; m],
            c_t: vec![0.0; m],
            jac_t: vec![0.0; nnz_j],
            hess_t: vec![0.0; nnz_h],
            dw: vec![0.0; nw],
            dy: vec![0.0; m],
            dzl: vec![0.0; nw],
            dzu: vec![0.0; nw],
            dw_s: vec![0.0; nw],
            dy_s: vec![0.0; m],
            dzl_s: vec![0.0; nw],
            dzu_s: vec![0.0; nw],
            c_soc: vec![0.0; m],
            kkt,
            kdx: vec![0.0; n],
            kdc: vec![0.0; m],
            rhs: vec![0.0; n + m],
            rhs_s: vec![0.0; ni],
            rhs_copy: vec![0.0; n + m],
            ds: vec![0.0; ni],
            shift,
            eq_reg: vec![0.0; m],
            eq_reg_step: vec![0.0; m],
            hess_diag,
            hzero: vec![0.0; nnz_h],
            work_nw: vec![0.0; nw],
            mu: setup.mu_init,
            tau: tau(setup.mu_init, opts),
            filter: Filter::new(),
            theta_min: 0.0,
            theta_max: 0.0,
            delta_w: 0.0,
            delta_w_last: 0.0,
            delta_c: 0.0,
            jac_degenerate: false,
            singular_iters: 0,
            perturbed_iters: 0,
            free_mode: setup.mu_strategy == MuStrategy::Adaptive,
            kkt_refs: Vec::new(),
            tiny_count: 0,
            termination: Termination::default(),
            setup_in_resto: setup.in_resto,
            obj_scale: setup.obj_scale,
            g_scale: setup.g_scale.clone(),
            mu_strategy: setup.mu_strategy,
            resto_calls: 0,
            resto_start: None,
        })
    }

    // ------------------------------------------------------------------ evaluation

    /// c = g − s (inequality rows) or g − g_eq (equality rows).
    fn constraint_residual(&self, w: &[f64], g: &[f64], c: &mut [f64]) {
        for i in 0..self.m {
            let k = self.slack_of_row[i];
            c[i] = if k == usize::MAX {
                g[i] - self.g_eq[i]
            } else {
                g[i] - w[self.n + k]
            };
        }
    }

    /// out = Aᵀ y with A = [J, −E].
    fn at_times(&self, jac: &[f64], y: &[f64], out: &mut [f64]) {
        let pat = self.nlp.jac_g_sparsity();
        for j in 0..self.n {
            let mut s = 0.0;
            for p in pat.col_range(j) {
                s += jac[p] * y[pat.row_idx()[p]];
            }
            out[j] = s;
        }
        for k in 0..self.ni {
            out[self.n + k] = -y[self.row_of_slack[k]];
        }
    }

    /// Evaluates f and g at `w_t` into the trial buffers; false if non-finite.
    fn eval_trial_fc(&mut self) -> bool {
        let x = &self.w_t[..self.n];
        self.f_t = self.nlp.eval_f(x);
        if !self.f_t.is_finite() {
            return false;
        }
        self.nlp.eval_g(x, &mut self.g_t);
        if !all_finite(&self.g_t) {
            return false;
        }
        let (w_t, g_t) = (&self.w_t, &self.g_t);
        let mut c_t = std::mem::take(&mut self.c_t);
        self.constraint_residual(w_t, g_t, &mut c_t);
        self.c_t = c_t;
        true
    }

    /// Evaluates ∇f, J and the Hessian at the trial point with multipliers `y_t`.
    fn eval_trial_derivs(&mut self) -> bool {
        let x = &self.w_t[..self.n];
        self.nlp.eval_grad_f(x, &mut self.grad_t);
        if !all_finite(&self.grad_t) {
            return false;
        }
        self.nlp.eval_jac_g(x, &mut self.jac_t);
        if !all_finite(&self.jac_t) {
            return false;
        }
        self.nlp.eval_hess_l(x, 1.0, &self.y_t, &mut self.hess_t);
        all_finite(&self.hess_t)
    }

    /// Makes the trial point current (swapping buffers).
    fn accept_trial(&mut self) {
        std::mem::swap(&mut self.w, &mut self.w_t);
        std::mem::swap(&mut self.y, &mut self.y_t);
        std::mem::swap(&mut self.grad, &mut self.grad_t);
        std::mem::swap(&mut self.g, &mut self.g_t);
        std::mem::swap(&mut self.c, &mut self.c_t);
        std::mem::swap(&mut self.jac, &mut self.jac_t);
        std::mem::swap(&mut self.hess, &mut self.hess_t);
        self.f = self.f_t;
    }

    /// Evaluates everything at the current w, y. Err names the callback on NaN/Inf.
    fn eval_current(&mut self) -> Result<(), CoreError> {
        self.eval_all(At::Start)
    }

    /// f, ∇f, g, J and ∇²L at the current w, y, and the residual c; Err names the first
    /// non-finite value.
    fn eval_all(&mut self, at: At) -> Result<(), CoreError> {
        self.eval_first_order(at)?;
        self.eval_hessian(at)?;
        let mut c = std::mem::take(&mut self.c);
        self.constraint_residual(&self.w, &self.g, &mut c);
        self.c = c;
        Ok(())
    }

    /// f, ∇f, g and J at the current w; Err names the first non-finite value.
    fn eval_first_order(&mut self, at: At) -> Result<(), CoreError> {
        let n = self.n;
        let x = &self.w[..n];
        self.f = self.nlp.eval_f(x);
        if !self.f.is_finite() {
            return Err(CoreError::Objective { value: self.f, at });
        }
        self.nlp.eval_grad_f(x, &mut self.grad);
        if let Some(i) = first_non_finite(&self.grad) {
            return Err(CoreError::Gradient {
                value: self.grad[i],
                index: i,
                name: self.nlp.variable_name(i),
                at,
            });
        }
        self.nlp.eval_g(x, &mut self.g);
        self.check_g(at)?;
        self.nlp.eval_jac_g(x, &mut self.jac);
        if let Some(p) = first_non_finite(&self.jac) {
            let pat = self.nlp.jac_g_sparsity();
            let col = (0..n).find(|&j| pat.col_range(j).contains(&p)).unwrap_or(0);
            let row = pat.row_idx()[p];
            return Err(CoreError::Jacobian {
                value: self.jac[p],
                row,
                row_name: self.nlp.constraint_name(row),
                col,
                col_name: self.nlp.variable_name(col),
                at,
            });
        }
        Ok(())
    }

    /// ∇²L at the current w, y; Err names the first non-finite entry.
    fn eval_hessian(&mut self, at: At) -> Result<(), CoreError> {
        let n = self.n;
        let x = &self.w[..n];
        self.nlp.eval_hess_l(x, 1.0, &self.y, &mut self.hess);
        if let Some(p) = first_non_finite(&self.hess) {
            let pat = self.nlp.hess_l_sparsity();
            let col = (0..n).find(|&j| pat.col_range(j).contains(&p)).unwrap_or(0);
            let row = pat.row_idx()[p];
            return Err(CoreError::Hessian {
                value: self.hess[p],
                row,
                row_name: self.nlp.variable_name(row),
                col,
                col_name: self.nlp.variable_name(col),
                at,
            });
        }
        Ok(())
    }

    // ------------------------------------------------------------------ initialisation

    fn push_into_bounds(&self, j: usize, v: f64, push: f64, frac: f64) -> f64 {
        let (l, u) = (self.wl[j], self.wu[j]);
        let mut v = v;
        if self.has_l[j] && self.has_u[j] {
            let pl = (push * l.abs().max(1.0)).min(frac * (u - l));
            let pu = (push * u.abs().max(1.0)).min(frac * (u - l));
            if l + pl > u - pu {
                v = 0.5 * (l + u);
            } else {
                v = v.clamp(l + pl, u - pu);
            }
        } else if self.has_l[j] {
            v = v.max(l + push * l.abs().max(1.0));
        } else if self.has_u[j] {
            v = v.min(u - push * u.abs().max(1.0));
        }
        v
    }

    /// Err names the first non-finite entry of g.
    fn check_g(&self, at: At) -> Result<(), CoreError> {
        match first_non_finite(&self.g) {
            Some(i) => Err(CoreError::Constraint {
                value: self.g[i],
                index: i,
                name: self.nlp.constraint_name(i),
                at,
            }),
            None => Ok(()),
        }
    }

    fn initialize(&mut self, start: Start) -> Result<(), CoreError> {
        let n = self.n;
        let mut x0 = vec![0.0; n];
        self.nlp.initial_point(&mut x0);
        match start {
            Start::Exact { w, y, zl, zu } => {
                self.w.copy_from_slice(&w);
                self.y.copy_from_slice(&y);
                self.zl.copy_from_slice(&zl);
                self.zu.copy_from_slice(&zu);
                self.eval_current()?;
            }
            Start::Cold | Start::Warm { .. } => {
                let warm = matches!(start, Start::Warm { .. });
                let (bp, bf, sp, sf) = if warm {
                    (
                        self.opts.warm_start_bound_push,
                        self.opts.warm_start_bound_frac,
                        self.opts.warm_start_slack_bound_push,
                        self.opts.warm_start_slack_bound_frac,
                    )
                } else {
                    (
                        self.opts.bound_push,
                        self.opts.bound_frac,
                        self.opts.slack_bound_push,
                        self.opts.slack_bound_frac,
                    )
                };
                for j in 0..n {
                    self.w[j] = self.push_into_bounds(j, x0[j], bp, bf);
                }
                // Slacks from g(x0).
                self.nlp.eval_g(&self.w[..n], &mut self.g);
                self.check_g(At::Start)?;
                for k in 0..self.ni {
                    let gi = self.g[self.row_of_slack[k]];
                    self.w[n + k] = self.push_into_bounds(n + k, gi, sp, sf);
                }
                match start {
                    Start::Warm { y, zl, zu } => {
                        let zmin = self.opts.warm_start_mult_bound_push;
                        self.y.copy_from_slice(&y);
                        for j in 0..self.nw {
                            let (a, b) = if j < n {
                                (zl[j], zu[j])
                            } else {
                                // slack multipliers from y: ∇_s L = −y − v_L + v_U = 0
                                let yi = y[self.row_of_slack[j - n]];
                                ((-yi).max(0.0), yi.max(0.0))
                            };
                            self.zl[j] = if self.has_l[j] { a.max(zmin) } else { 0.0 };
                            self.zu[j] = if self.has_u[j] { b.max(zmin) } else { 0.0 };
                        }
                        self.eval_current()?;
                    }
                    _ => {
                        let v = self.opts.bound_mult_init_val;
                        for j in 0..self.nw {
                            self.zl[j] = if self.has_l[j] { v } else { 0.0 };
                            self.zu[j] = if self.has_u[j] { v } else { 0.0 };
                        }
                        self.y.iter_mut().for_each(|v| *v = 0.0);
                        self.eval_current()?;
                        if self.m > 0 {
                            self.least_squares_multipliers(self.opts.constr_mult_init_max);
                            // Hessian at the new multipliers.
                            self.eval_hessian(At::Start)?;
                        }
                    }
                }
            }
        }
        let theta0 = one_norm(&self.c);
        self.theta_max = self.opts.theta_max_fact * theta0.max(1.0);
        self.theta_min = self.opts.theta_min_fact * theta0.max(1.0);
        Ok(())
    }

    /// y = argmin ‖∇f + Aᵀy − z_L + z_U‖₂ (IPOPT's least-squares estimate), set to 0 if
    /// larger than `max_norm` (max-norm) or not computable.
    pub fn least_squares_multipliers(&mut self, max_norm: f64) {
        let (n, m) = (self.n, self.m);
        if m == 0 {
            return;
        }
        let xreg = self.opts.kkt_static_hessian_regularization;
        self.kdx.iter_mut().for_each(|v| *v = 1.0 + xreg);
        self.update_eq_reg();
        // The static regularisation of the equality rows, 1e-2 × the step's: the
        // Schur complement here is J Jᵀ, whose smallest eigenvalue on a long chain is
        // far below its diagonal (≈ (π/N)² × it), so a regularisation relative to the
        // diagonal perturbs the smooth part of y and can trip the singularity test
        // below (y = 0). Measured: 1× fails the hanging chain with 50 000 links (rows
        // scaled up to gradient 0.8 by nlp_scaling_min_gradient; not solved in 40 s),
        // 1e-2× solves it in 8 iterations; 1e-6× (chosen before the row scaling, for the
        // unscaled 5000-link chain) changed hs027 from 54 to 77 iterations through
        // round-off alone (the path of hs027 is long and sensitive).
        let ls_reg = 1e-2;
        for i in 0..m {
            self.kdc[i] = if self.slack_of_row[i] == usize::MAX {
                ls_reg * self.eq_reg[i]
            } else {
                1.0
            };
        }
        // rhs: [−(∇f − z_L + z_U)_x ; −(rhs_s/1) contribution]; with W = I, Σ_s = 1.
        for j in 0..n {
            self.rhs[j] = -(self.grad[j] - self.zl[j] + self.zu[j]);
        }
        for i in 0..m {
            let k = self.slack_of_row[i];
            self.rhs[n + i] = if k == usize::MAX {
                0.0
            } else {
                // s-row: ds − y_i = r_s := z_L − z_U; row i: J dx − ds = 0
                // ⇒ J dx − y_i = r_s.
                self.zl[n + k] - self.zu[n + k]
            };
        }
        // IPOPT computes these multipliers with an unregularised factorisation and sets
        // them to zero when the linear solver reports the system singular (a
        // rank-deficient Jacobian of the equality rows). The static regularisation δ_s
        // hides that singularity from faer, so detect it from the determinant instead:
        // det K(δ) = det(−δI − J Jᵀ) on the equality rows, and multiplying δ by 10 multiplies
        // |det K| by about 10 per (numerically) zero singular value of J.
        let n_eq = self
            .slack_of_row
            .iter()
            .filter(|&&k| k == usize::MAX)
            .count();
        let mut singular = false;
        if n_eq > 0 && self.opts.kkt_static_regularization > 0.0 {
            for i in 0..m {
                if self.slack_of_row[i] == usize::MAX {
                    self.kdc[i] = 10.0 * ls_reg * self.eq_reg[i];
                }
            }
            if self
                .kkt
                .factorize(&self.hzero, &self.kdx, &self.jac, &self.kdc)
                .is_ok()
            {
                let ld10 = self.kkt.log_abs_det();
                for i in 0..m {
                    if self.slack_of_row[i] == usize::MAX {
                        self.kdc[i] = ls_reg * self.eq_reg[i];
                    }
                }
                if self
                    .kkt
                    .factorize(&self.hzero, &self.kdx, &self.jac, &self.kdc)
                    .is_ok()
                {
                    singular = (ld10 - self.kkt.log_abs_det()) / std::f64::consts::LN_10 > 0.5;
                }
            }
            for i in 0..m {
                if self.slack_of_row[i] == usize::MAX {
                    self.kdc[i] = ls_reg * self.eq_reg[i];
                }
            }
        }
        for j in 0..n {
            self.shift[j] = -xreg;
        }
        for i in 0..m {
            self.shift[n + i] = if self.slack_of_row[i] == usize::MAX {
                ls_reg * self.eq_reg[i]
            } else {
                0.0
            };
        }
        let ok = !singular
            && self
                .kkt
                .factorize(&self.hzero, &self.kdx, &self.jac, &self.kdc)
                .is_ok()
            && self
                .kkt
                .solve_shifted(&mut self.rhs, Some(&self.shift))
                .is_ok();
        if ok {
            let ymax = inf_norm(&self.rhs[n..]);
            if ymax <= max_norm && ymax.is_finite() {
                self.y.copy_from_slice(&self.rhs[n..]);
                return;
            }
        }
        self.y.iter_mut().for_each(|v| *v = 0.0);
    }

    // ------------------------------------------------------------------ error measures

    /// (scaled dual infeasibility, primal infeasibility, complementarity at μ_t) with or
    /// without the κ_d damping term, max-norms. Also returns unscaled versions.
    fn errors(&mut self, mu_t: f64, damping: bool) -> ([f64; 3], [f64; 3]) {
        let n = self.n;
        let mut work = std::mem::take(&mut self.work_nw);
        self.at_times(&self.jac, &self.y, &mut work);
        let kd = if damping {
            self.opts.kappa_d * mu_t
        } else {
            0.0
        };
        let mut dual: f64 = 0.0;
        let mut dual_u: f64 = 0.0;
        let mut compl: f64 = 0.0;
        for j in 0..self.nw {
            let gj = if j < n { self.grad[j] } else { 0.0 };
            let mut r = gj + work[j] - self.zl[j] + self.zu[j];
            if self.has_l[j] && !self.has_u[j] {
                r += kd;
            } else if self.has_u[j] && !self.has_l[j] {
                r -= kd;
            }
            dual = dual.max(r.abs());
            let unscale = if j < n {
                1.0 / self.obj_scale
            } else {
                self.g_scale[self.row_of_slack[j - n]] / self.obj_scale
            };
            dual_u = dual_u.max(r.abs() * unscale);
            if self.has_l[j] {
                compl = compl.max(((self.w[j] - self.wl[j]) * self.zl[j] - mu_t).abs());
            }
            if self.has_u[j] {
                compl = compl.max(((self.wu[j] - self.w[j]) * self.zu[j] - mu_t).abs());
            }
        }
        self.work_nw = work;
        let primal = inf_norm(&self.c);
        let primal_u = self
            .c
            .iter()
            .zip(&self.g_scale)
            .fold(0.0f64, |a, (c, s)| a.max(c.abs() / s));
        (
            [dual, primal, compl],
            [dual_u, primal_u, compl / self.obj_scale],
        )
    }

    /// IPOPT's scaled optimality error E_μ.
    fn nlp_error(&mut self, mu_t: f64, damping: bool) -> (f64, [f64; 3]) {
        let (e, eu) = self.errors(mu_t, damping);
        let s_max = self.opts.s_max;
        let mut nz = 0usize;
        let mut zsum = 0.0;
        for j in 0..self.nw {
            if self.has_l[j] {
                nz += 1;
                zsum += self.zl[j].abs();
            }
            if self.has_u[j] {
                nz += 1;
                zsum += self.zu[j].abs();
            }
        }
        let ysum = one_norm(&self.y);
        let sd = if self.m + nz > 0 {
            (s_max.max((ysum + zsum) / (self.m + nz) as f64)) / s_max
        } else {
            1.0
        };
        let sc = if nz > 0 {
            (s_max.max(zsum / nz as f64)) / s_max
        } else {
            1.0
        };
        ((e[0] / sd).max(e[1]).max(e[2] / sc), eu)
    }

    fn avg_compl(&self, w: &[f64], zl: &[f64], zu: &[f64]) -> (f64, f64) {
        let mut sum = 0.0;
        let mut cnt = 0usize;
        let mut mn = f64::INFINITY;
        for j in 0..self.nw {
            if self.has_l[j] {
                let v = (w[j] - self.wl[j]) * zl[j];
                sum += v;
                cnt += 1;
                mn = mn.min(v);
            }
            if self.has_u[j] {
                let v = (self.wu[j] - w[j]) * zu[j];
                sum += v;
                cnt += 1;
                mn = mn.min(v);
            }
        }
        if cnt == 0 {
            (0.0, 0.0)
        } else {
            (sum / cnt as f64, mn)
        }
    }

    // ------------------------------------------------------------------ barrier function

    fn barrier(&self, w: &[f64], f: f64, mu: f64) -> f64 {
        barrier_value(
            w,
            f,
            mu,
            self.opts.kappa_d,
            &self.wl,
            &self.wu,
            &self.has_l,
            &self.has_u,
        )
    }

    fn barrier_dir_deriv(&self, dw: &[f64]) -> f64 {
        let mu = self.mu;
        let kd = self.opts.kappa_d * mu;
        let mut d = 0.0;
        for j in 0..self.nw {
            let mut gj = if j < self.n { self.grad[j] } else { 0.0 };
            if self.has_l[j] {
                gj -= mu / (self.w[j] - self.wl[j]);
                if !self.has_u[j] {
                    gj += kd;
                }
            }
            if self.has_u[j] {
                gj += mu / (self.wu[j] - self.w[j]);
                if !self.has_l[j] {
                    gj -= kd;
                }
            }
            d += gj * dw[j];
        }
        d
    }

    // ------------------------------------------------------------------ linear algebra

    /// Static regularisation of the equality rows, relative to each row's scale:
    /// kkt_static_regularization · clamp(max_j J_ij², 1e-3, 1). An absolute 1e-8 would swamp
    /// the Schur complement J H⁻¹ Jᵀ of a Jacobian with small entries (hanging chain
    /// with 500 links: entries 0.008, smallest σ(J)² ≈ 2.5e-9), refinement could not
    /// remove it, and the step would be regularised for nothing. The floor 1e-3 was
    /// chosen by measurement on the chain (50 … 5000 links: 7, 8, 19 iterations; with no
    /// floor the 5000-link chain fails, an absolute 1e-8 fails at 500 links).
    fn update_eq_reg(&mut self) {
        let reg = self.opts.kkt_static_regularization;
        let mut rmax = std::mem::take(&mut self.eq_reg);
        rmax.fill(0.0);
        let jp = self.nlp.jac_g_sparsity();
        let ri = jp.row_idx();
        for (p, &v) in self.jac.iter().enumerate() {
            let r = &mut rmax[ri[p]];
            *r = r.max(v.abs());
        }
        for r in rmax.iter_mut() {
            *r = if *r > 0.0 && r.is_finite() {
                reg * (*r * *r).clamp(1e-3, 1.0)
            } else {
                reg
            };
        }
        self.eq_reg = rmax;
    }

    /// The static regularisation of the equality rows for this factorisation. With
    /// δ_w = 0 it is `eq_reg` lowered, row by row, to kkt_static_regularization ×
    /// Σ_j J_ij² / |D_jj| where that is smaller (D the diagonal of W + Σ + the static
    /// Hessian regularisation, so the sum estimates the row's Schur complement
    /// J D⁻¹ Jᵀ), but not below 1e-3 × `eq_reg`. The hanging chain needs it: with 50 000
    /// links (rows scaled up to gradient 0.8) the Schur diagonal is ≈ 1e-4 against
    /// `eq_reg` = 6.4e-9, and its smooth modes are (π/N)² ≈ 4e-9 times smaller still,
    /// so refinement could not remove `eq_reg` and the solve did not converge (40 s);
    /// with the lowering it takes 8 iterations. The 1e-3 bound: without it (or with
    /// 1e-6) the Wächter–Biegler example of nlp/tests/ipm_mechanisms.rs ends its
    /// restoration at a point of local infeasibility (1e-4 … 1e-2 pass). With δ_w > 0
    /// (inertia correction) `eq_reg` is kept: lowering it there too took the 5000-link
    /// chain 14 iterations (IPOPT's count) instead of 11.
    fn step_eq_reg(&mut self, delta_w: f64) {
        let mut out = std::mem::take(&mut self.eq_reg_step);
        if delta_w == 0.0 {
            let reg = self.opts.kkt_static_regularization;
            out.fill(0.0);
            let jp = self.nlp.jac_g_sparsity();
            let ri = jp.row_idx();
            for j in 0..self.n {
                let hd = self.hess_diag[j];
                let h = if hd == usize::MAX { 0.0 } else { self.hess[hd] };
                let d = (h + self.kdx[j]).abs();
                if d > 0.0 {
                    for p in jp.col_range(j) {
                        out[ri[p]] += self.jac[p] * self.jac[p] / d;
                    }
                }
            }
            for (o, &e) in out.iter_mut().zip(&self.eq_reg) {
                let r = reg * *o;
                *o = if r > 0.0 && r.is_finite() {
                    r.min(e).max(1e-3 * e)
                } else {
                    e
                };
            }
        } else {
            out.copy_from_slice(&self.eq_reg);
        }
        self.eq_reg_step = out;
    }

    /// Assembles the KKT matrix for the current iterate with Hessian perturbation
    /// `delta_w` and Jacobian perturbation `self.delta_c` (the static regularisation
    /// `kkt_static_regularization` on equality rows when δ_c = 0) and factorises it.
    fn factor_kkt(
        &mut self,
        shared: &mut Shared,
        delta_w: f64,
    ) -> Result<crate::kkt::Inertia, crate::kkt::KktError> {
        let (n, m) = (self.n, self.m);
        // The static Hessian regularisation only keeps exact zero pivots away while
        // δ_w = 0; a real δ_w > 0 does that itself.
        let x_reg = if delta_w == 0.0 {
            self.opts.kkt_static_hessian_regularization
        } else {
            0.0
        };
        for j in 0..n {
            let mut sig = 0.0;
            if self.has_l[j] {
                sig += self.zl[j] / (self.w[j] - self.wl[j]);
            }
            if self.has_u[j] {
                sig += self.zu[j] / (self.wu[j] - self.w[j]);
            }
            self.kdx[j] = sig + delta_w + x_reg;
        }
        self.step_eq_reg(delta_w);
        self.shift[..n].fill(-x_reg);
        for i in 0..m {
            self.shift[n + i] = if self.slack_of_row[i] == usize::MAX && self.delta_c == 0.0 {
                self.eq_reg_step[i]
            } else {
                0.0
            };
        }
        for k in 0..self.ni {
            let j = n + k;
            let mut sig = 0.0;
            if self.has_l[j] {
                sig += self.zl[j] / (self.w[j] - self.wl[j]);
            }
            if self.has_u[j] {
                sig += self.zu[j] / (self.wu[j] - self.w[j]);
            }
            self.ds[k] = (sig + delta_w).max(1e-300);
        }
        for i in 0..m {
            let k = self.slack_of_row[i];
            // Equality rows carry δ_c, or the static regularisation that faer's
            // unpivoted LDLᵀ needs (removed again by iterative refinement); inequality
            // rows already carry 1/(Σ_s + δ_w) > 0 from the eliminated slack, plus δ_c.
            self.kdc[i] = if k == usize::MAX {
                if self.delta_c > 0.0 {
                    self.delta_c
                } else {
                    self.eq_reg_step[i]
                }
            } else {
                self.delta_c + 1.0 / self.ds[k]
            };
        }
        let t = Instant::now();
        let res = self
            .kkt
            .factorize(&self.hess, &self.kdx, &self.jac, &self.kdc);
        shared.stats.factor_seconds += t.elapsed().as_secs_f64();
        shared.stats.n_factorizations += 1;
        res
    }

    /// δ_c = jacobian_regularization_value · μ^jacobian_regularization_exponent.
    fn delta_cd(&self) -> f64 {
        self.opts.jacobian_regularization_value
            * self.mu.powf(self.opts.jacobian_regularization_exponent)
    }

    /// IPOPT's next trial δ_w: the first one is `first_hessian_perturbation`, or
    /// κ_w⁻·δ_w_last when an earlier iteration needed one; then ×κ_w⁺ (×κ̄_w⁺ while no
    /// earlier iteration needed one).
    fn next_delta_w(&self, delta_w: f64) -> f64 {
        let o = &self.opts;
        if delta_w == 0.0 {
            if self.delta_w_last == 0.0 {
                o.first_hessian_perturbation
            } else {
                o.min_hessian_perturbation
                    .max(o.perturb_dec_fact * self.delta_w_last)
            }
        } else if self.delta_w_last == 0.0 {
            delta_w * o.perturb_inc_fact_first
        } else {
            delta_w * o.perturb_inc_fact
        }
    }

    /// Factorises the KKT matrix with IPOPT's inertia correction. Returns false if δ_w
    /// exceeded its maximum.
    fn factorize_with_inertia_correction(&mut self, shared: &mut Shared) -> bool {
        let (n, m) = (self.n, self.m);
        self.update_eq_reg();
        let mut delta_w = 0.0;
        self.delta_c = if self.jac_degenerate && m > 0 {
            self.delta_cd()
        } else {
            0.0
        };
        let mut tried_delta_c = self.delta_c > 0.0;
        // After `perturbation_skip_zero_after` iterations in a row that needed δ_w > 0,
        // start from IPOPT's second trial κ_w⁻·δ_w_last and skip the δ_w = 0 trial
        // (saves one factorisation per iteration on nonconvex problems). δ_w then keeps
        // shrinking by κ_w⁻ per iteration while the inertia allows it.
        let skip = self.opts.perturbation_skip_zero_after;
        let skipped = skip > 0 && self.perturbed_iters >= skip && self.delta_w_last > 0.0;
        if skipped {
            delta_w = self.next_delta_w(0.0);
        }
        loop {
            let res = self.factor_kkt(shared, delta_w);
            let singular = match res {
                Ok(inertia) => {
                    if inertia.positive == n && inertia.negative == m && inertia.zero == 0 {
                        self.delta_w = delta_w;
                        if delta_w > 0.0 {
                            self.delta_w_last = delta_w;
                            self.perturbed_iters += 1;
                        } else {
                            self.perturbed_iters = 0;
                        }
                        return true;
                    }
                    inertia.zero > 0
                }
                Err(_) => true,
            };
            let o = &self.opts;
            if singular && !tried_delta_c && m > 0 {
                tried_delta_c = true;
                self.delta_c = self.delta_cd();
                if self.delta_c > 0.0 {
                    continue;
                }
            }
            delta_w = self.next_delta_w(delta_w);
            if delta_w > o.max_hessian_perturbation {
                self.delta_w = delta_w;
                return false;
            }
        }
    }

    /// Solves for the direction with complementarity target `mu_t`; `soc` replaces the
    /// primal residual c by the given vector. Writes into (dw, dy, dzl, dzu) or the SOC
    /// buffers.
    fn solve_direction(&mut self, shared: &mut Shared, mu_t: f64, soc: bool) -> bool {
        let (n, m) = (self.n, self.m);
        let mut work = std::mem::take(&mut self.work_nw);
        self.at_times(&self.jac, &self.y, &mut work);
        let kd = self.opts.kappa_d * mu_t;
        // rhs_w = −(∇f + Aᵀy) + μ/(w−wl) − μ/(wu−w) ∓ κ_d μ
        for j in 0..self.nw {
            let gj = if j < n { self.grad[j] } else { 0.0 };
            let mut r = -(gj + work[j]);
            if self.has_l[j] {
                r += mu_t / (self.w[j] - self.wl[j]);
                if !self.has_u[j] {
                    r -= kd;
                }
            }
            if self.has_u[j] {
                r -= mu_t / (self.wu[j] - self.w[j]);
                if !self.has_l[j] {
                    r += kd;
                }
            }
            if j < n {
                self.rhs[j] = r;
            } else {
                self.rhs_s[j - n] = r;
            }
        }
        self.work_nw = work;
        for i in 0..m {
            let ci = if soc { self.c_soc[i] } else { self.c[i] };
            let k = self.slack_of_row[i];
            self.rhs[n + i] = if k == usize::MAX {
                -ci
            } else {
                -ci + self.rhs_s[k] / self.ds[k]
            };
        }
        // Refine against the system without the static regularisation.
        let t = Instant::now();
        self.rhs_copy.copy_from_slice(&self.rhs);
        let mut res = self.kkt.solve_shifted(&mut self.rhs, Some(&self.shift));
        if self.delta_c == 0.0 && !matches!(res, Ok(r) if r <= self.opts.residual_ratio_max) {
            // The system without the static regularisation is (numerically) singular:
            // a rank-deficient Jacobian of the equality rows with inconsistent
            // linearised constraints. Take IPOPT's regularised step: refactorise with
            // δ_c = 1e-8·μ^¼ and solve that system. After three such iterations in a
            // row, δ_c is applied from the start (IPOPT's "Jacobian degenerate").
            shared.stats.factor_seconds += t.elapsed().as_secs_f64();
            self.singular_iters += 1;
            if self.singular_iters >= 3 {
                self.jac_degenerate = true;
            }
            self.delta_c = self.delta_cd();
            let dw = self.delta_w;
            let ok = matches!(self.factor_kkt(shared, dw),
                Ok(i) if i.positive == n && i.negative == m && i.zero == 0);
            if !ok {
                // Should not happen (δ_c does not change the inertia); fall back to
                // the statically regularised system as it is.
                self.delta_c = 0.0;
                if self.factor_kkt(shared, dw).is_err() {
                    return false;
                }
            }
            let t = Instant::now();
            self.rhs.copy_from_slice(&self.rhs_copy);
            res = self.kkt.solve_shifted(&mut self.rhs, Some(&self.shift));
            shared.stats.factor_seconds += t.elapsed().as_secs_f64();
            let mut dw = self.delta_w;
            while ok && !matches!(res, Ok(r) if r <= self.opts.residual_ratio_max) {
                // Still singular (singular reduced Hessian): IPOPT increases δ_w.
                dw = self.next_delta_w(dw);
                if dw > self.opts.max_hessian_perturbation {
                    return false;
                }
                match self.factor_kkt(shared, dw) {
                    Ok(i) if i.positive == n && i.negative == m && i.zero == 0 => {}
                    Ok(_) => continue,
                    Err(_) => continue,
                }
                self.delta_w = dw;
                self.delta_w_last = dw;
                let t = Instant::now();
                self.rhs.copy_from_slice(&self.rhs_copy);
                res = self.kkt.solve_shifted(&mut self.rhs, Some(&self.shift));
                shared.stats.factor_seconds += t.elapsed().as_secs_f64();
            }
        } else {
            shared.stats.factor_seconds += t.elapsed().as_secs_f64();
            if self.delta_c == 0.0 && !soc {
                self.singular_iters = 0;
            }
        }
        if res.is_err() {
            return false;
        }
        let (dw, dy, dzl, dzu) = if soc {
            (
                &mut self.dw_s,
                &mut self.dy_s,
                &mut self.dzl_s,
                &mut self.dzu_s,
            )
        } else {
            (&mut self.dw, &mut self.dy, &mut self.dzl, &mut self.dzu)
        };
        dw[..n].copy_from_slice(&self.rhs[..n]);
        dy.copy_from_slice(&self.rhs[n..]);
        for k in 0..self.ni {
            let i = self.row_of_slack[k];
            dw[n + k] = (self.rhs_s[k] + dy[i]) / self.ds[k];
        }
        for j in 0..self.nw {
            if self.has_l[j] {
                let s = self.w[j] - self.wl[j];
                dzl[j] = mu_t / s - self.zl[j] - self.zl[j] / s * dw[j];
            } else {
                dzl[j] = 0.0;
            }
            if self.has_u[j] {
                let s = self.wu[j] - self.w[j];
                dzu[j] = mu_t / s - self.zu[j] + self.zu[j] / s * dw[j];
            } else {
                dzu[j] = 0.0;
            }
        }
        all_finite(dw) && all_finite(dy)
    }

    fn max_step_primal(&self, dw: &[f64], tau: f64) -> f64 {
        let mut a: f64 = 1.0;
        for j in 0..self.nw {
            if dw[j] < 0.0 && self.has_l[j] {
                a = a.min(tau * (self.w[j] - self.wl[j]) / -dw[j]);
            }
            if dw[j] > 0.0 && self.has_u[j] {
                a = a.min(tau * (self.wu[j] - self.w[j]) / dw[j]);
            }
        }
        a
    }

    fn max_step_dual(&self, dzl: &[f64], dzu: &[f64], tau: f64) -> f64 {
        let mut a: f64 = 1.0;
        for j in 0..self.nw {
            if self.has_l[j] && dzl[j] < 0.0 {
                a = a.min(tau * self.zl[j] / -dzl[j]);
            }
            if self.has_u[j] && dzu[j] < 0.0 {
                a = a.min(tau * self.zu[j] / -dzu[j]);
            }
        }
        a
    }

    // ------------------------------------------------------------------ barrier update

    fn update_mu_monotone(&mut self, force: bool) {
        let floor = mu_floor(&self.opts);
        let mut first = true;
        loop {
            if self.mu <= floor {
                return;
            }
            let (e_mu, _) = self.nlp_error(self.mu, true);
            if !(force && first) && e_mu > self.opts.barrier_tol_factor * self.mu {
                return;
            }
            first = false;
            self.mu = monotone_next(self.mu, &self.opts);
            self.tau = tau(self.mu, &self.opts);
            self.filter.reset();
            if !self.opts.mu_allow_fast_monotone_decrease {
                return;
            }
        }
    }

    /// Adaptive μ (called after the KKT matrix is factorised).
    fn update_mu_adaptive(&mut self, shared: &mut Shared, e0: f64) {
        let red = self.opts.adaptive_mu_kkterror_red_fact;
        if self.free_mode {
            let ok = self.kkt_refs.is_empty() || self.kkt_refs.iter().any(|&r| e0 <= red * r);
            if !ok {
                // Switch to the monotone (fixed) mode.
                self.free_mode = false;
                let (avg, _) = self.avg_compl(&self.w, &self.zl, &self.zu);
                self.mu = (self.opts.adaptive_mu_monotone_init_factor * avg)
                    .clamp(mu_floor(&self.opts), self.opts.mu_max);
                self.tau = tau(self.mu, &self.opts);
                self.filter.reset();
                return;
            }
            self.kkt_refs.push(e0);
            if self.kkt_refs.len() > self.opts.adaptive_mu_kkterror_red_iters {
                self.kkt_refs.remove(0);
            }
        } else {
            if !self.kkt_refs.is_empty() && self.kkt_refs.iter().all(|&r| e0 <= red * r) {
                self.free_mode = true;
                self.kkt_refs.clear();
                self.kkt_refs.push(e0);
            } else {
                self.update_mu_monotone(false);
                return;
            }
        }
        // Free mode: oracle.
        let (avg, mn) = self.avg_compl(&self.w, &self.zl, &self.zu);
        let mut mu = match self.opts.mu_oracle {
            MuOracle::Loqo => loqo_mu(avg, mn),
            MuOracle::Probing => {
                if self.solve_direction(shared, 0.0, false) {
                    let ap = self.max_step_primal(&self.dw, 1.0);
                    let ad = self.max_step_dual(&self.dzl, &self.dzu, 1.0);
                    let mut sum = 0.0;
                    let mut cnt = 0usize;
                    for j in 0..self.nw {
                        if self.has_l[j] {
                            sum += (self.w[j] + ap * self.dw[j] - self.wl[j])
                                * (self.zl[j] + ad * self.dzl[j]);
                            cnt += 1;
                        }
                        if self.has_u[j] {
                            sum += (self.wu[j] - self.w[j] - ap * self.dw[j])
                                * (self.zu[j] + ad * self.dzu[j]);
                            cnt += 1;
                        }
                    }
                    let aff = if cnt > 0 { sum / cnt as f64 } else { 0.0 };
                    probing_mu(avg, aff.max(0.0))
                } else {
                    loqo_mu(avg, mn)
                }
            }
        };
        mu = mu.clamp(self.opts.mu_min.max(self.opts.tol * 1e-2), self.opts.mu_max);
        if mu != self.mu {
            self.mu = mu;
            self.tau = tau(mu, &self.opts);
            self.filter.reset();
        }
    }

    // ------------------------------------------------------------------ line search

    /// IPOPT's acceptance test of a trial point (FilterLSAcceptor::CheckAcceptabilityOfTrialPoint):
    /// θ_t ≤ θ_max, then, when θ ≤ θ_min and the switching condition holds, Armijo on φ_μ,
    /// else sufficient reduction of θ or φ_μ against the current iterate; and the filter.
    /// `alpha` is the step size used in the switching and Armijo conditions (for a
    /// second-order correction, the step of the rejected trial point).
    fn is_acceptable(
        &self,
        alpha: f64,
        theta: f64,
        phi: f64,
        gpd: f64,
        theta_t: f64,
        phi_t: f64,
    ) -> bool {
        let o = &self.opts;
        if !(theta_t <= self.theta_max) || !phi_t.is_finite() {
            return false;
        }
        let tol = 10.0 * f64::EPSILON * phi.abs();
        let ok = if theta <= self.theta_min && self.switching(alpha, theta, gpd) {
            phi_t - phi - o.eta_phi * alpha * gpd <= tol
        } else {
            theta_t <= (1.0 - o.gamma_theta) * theta || phi_t - (phi - o.gamma_phi * theta) <= tol
        };
        ok && self.filter.acceptable(theta_t, phi_t)
    }

    /// The switching condition α (−∇φ_μᵀd)^s_φ > δ θ^s_θ (with ∇φ_μᵀd < 0).
    fn switching(&self, alpha: f64, theta: f64, gpd: f64) -> bool {
        let o = &self.opts;
        gpd < 0.0 && alpha * (-gpd).powf(o.s_phi) > o.delta * theta.powf(o.s_theta)
    }

    /// Classifies an accepted step as IPOPT does (FilterLSAcceptor::UpdateForNextIteration,
    /// Wächter & Biegler 2006, Algorithm A step A-8): an f-type step satisfies the switching
    /// condition and the Armijo condition, whether or not θ ≤ θ_min; any other step
    /// augments the filter with the current iterate. Returns true for an f-type step.
    fn update_filter_after_step(
        &mut self,
        alpha: f64,
        theta: f64,
        phi: f64,
        gpd: f64,
        phi_t: f64,
    ) -> bool {
        let o = &self.opts;
        let tol = 10.0 * f64::EPSILON * phi.abs();
        let ftype =
            self.switching(alpha, theta, gpd) && phi_t - phi - o.eta_phi * alpha * gpd <= tol;
        if !ftype {
            self.filter.add(
                (1.0 - self.opts.gamma_theta) * theta,
                phi - self.opts.gamma_phi * theta,
            );
        }
        ftype
    }

    fn alpha_min(&self, theta: f64, gpd: f64) -> f64 {
        let o = &self.opts;
        let a = if gpd < 0.0 {
            let mut a = o.gamma_theta.min(o.gamma_phi * theta / -gpd);
            if theta <= self.theta_min {
                a = a.min(o.delta * theta.powf(o.s_theta) / (-gpd).powf(o.s_phi));
            }
            a
        } else {
            o.gamma_theta
        };
        (o.alpha_min_frac * a).max(f64::EPSILON)
    }

    /// Backtracking filter line search with second-order corrections. On success the
    /// trial point is accepted.
    fn line_search(&mut self, shared: &mut Shared) -> LineSearch {
        let theta = one_norm(&self.c);
        let phi = self.barrier(&self.w, self.f, self.mu);
        let gpd = self.barrier_dir_deriv(&self.dw);
        let alpha_max = self.max_step_primal(&self.dw, self.tau);
        let alpha_min = self.alpha_min(theta, gpd);
        let mut alpha = alpha_max;
        let mut ls = 0usize;
        loop {
            // The first trial step is always tried, even below α_min (IPOPT).
            if ls > 0 && !(alpha > alpha_min) {
                return LineSearch::Failed {
                    alpha_pr: alpha,
                    trials: ls,
                };
            }
            ls += 1;
            for j in 0..self.nw {
                self.w_t[j] = self.w[j] + alpha * self.dw[j];
            }
            let finite = self.eval_trial_fc();
            if finite {
                let theta_t = one_norm(&self.c_t);
                let phi_t = self.barrier(&self.w_t, self.f_t, self.mu);
                if self.is_acceptable(alpha, theta, phi, gpd, theta_t, phi_t) {
                    for i in 0..self.m {
                        self.y_t[i] = self.y[i] + alpha * self.dy[i];
                    }
                    if self.eval_trial_derivs() {
                        let ftype = self.update_filter_after_step(alpha, theta, phi, gpd, phi_t);
                        let alpha_du = self.max_step_dual(&self.dzl, &self.dzu, self.tau);
                        self.take_dual_step(alpha_du, false);
                        self.accept_trial();
                        return LineSearch::Accepted {
                            alpha_pr: alpha,
                            alpha_du,
                            kind: StepKind::new(ftype, false),
                            trials: ls,
                        };
                    }
                } else if alpha == alpha_max
                    && theta_t >= theta
                    && self.opts.max_soc > 0
                    && self.m > 0
                {
                    // Second-order corrections (IPOPT's TrySecondOrderCorrection):
                    // c_soc ← α_soc·c_soc + c(trial), starting from c_soc = c and
                    // α_soc = α; another correction is tried while the last one
                    // reduced θ by κ_soc against the trial point before it. The
                    // acceptance tests use the original step size α.
                    self.c_soc.copy_from_slice(&self.c);
                    let mut a_soc = alpha;
                    let mut theta_trial = theta_t;
                    let mut theta_soc_old = 0.0;
                    for count in 0..self.opts.max_soc {
                        if count > 0 && !(theta_trial <= self.opts.kappa_soc * theta_soc_old) {
                            break;
                        }
                        theta_soc_old = theta_trial;
                        for i in 0..self.m {
                            self.c_soc[i] = a_soc * self.c_soc[i] + self.c_t[i];
                        }
                        if !self.solve_direction(shared, self.mu, true) {
                            break;
                        }
                        a_soc = self.max_step_primal(&self.dw_s, self.tau);
                        for j in 0..self.nw {
                            self.w_t[j] = self.w[j] + a_soc * self.dw_s[j];
                        }
                        if !self.eval_trial_fc() {
                            break;
                        }
                        let th = one_norm(&self.c_t);
                        let ph = self.barrier(&self.w_t, self.f_t, self.mu);
                        if self.is_acceptable(alpha, theta, phi, gpd, th, ph) {
                            for i in 0..self.m {
                                self.y_t[i] = self.y[i] + a_soc * self.dy_s[i];
                            }
                            if self.eval_trial_derivs() {
                                let ftype =
                                    self.update_filter_after_step(alpha, theta, phi, gpd, ph);
                                let alpha_du =
                                    self.max_step_dual(&self.dzl_s, &self.dzu_s, self.tau);
                                self.take_dual_step(alpha_du, true);
                                self.accept_trial();
                                return LineSearch::Accepted {
                                    alpha_pr: a_soc,
                                    alpha_du,
                                    kind: StepKind::new(ftype, true),
                                    trials: ls,
                                };
                            }
                            break;
                        }
                        theta_trial = th;
                    }
                }
            }
            alpha *= self.opts.alpha_red_factor;
        }
    }

    /// z ← z + α_du·dz with the κ_Σ safeguard at the trial point (w_t).
    fn take_dual_step(&mut self, alpha_du: f64, soc: bool) {
        let ks = self.opts.kappa_sigma;
        let mu = self.mu;
        for j in 0..self.nw {
            let (dl, du) = if soc {
                (self.dzl_s[j], self.dzu_s[j])
            } else {
                (self.dzl[j], self.dzu[j])
            };
            if self.has_l[j] {
                let s = self.w_t[j] - self.wl[j];
                let z = self.zl[j] + alpha_du * dl;
                self.zl[j] = z.min(ks * mu / s).max(mu / (ks * s));
            }
            if self.has_u[j] {
                let s = self.wu[j] - self.w_t[j];
                let z = self.zu[j] + alpha_du * du;
                self.zu[j] = z.min(ks * mu / s).max(mu / (ks * s));
            }
        }
    }

    /// Full step without line search (tiny steps).
    fn take_full_step(&mut self) -> bool {
        let alpha = self.max_step_primal(&self.dw, self.tau);
        for j in 0..self.nw {
            self.w_t[j] = self.w[j] + alpha * self.dw[j];
        }
        for i in 0..self.m {
            self.y_t[i] = self.y[i] + alpha * self.dy[i];
        }
        if !self.eval_trial_fc() || !self.eval_trial_derivs() {
            return false;
        }
        let alpha_du = self.max_step_dual(&self.dzl, &self.dzu, self.tau);
        self.take_dual_step(alpha_du, false);
        self.accept_trial();
        true
    }

    // ------------------------------------------------------------------ records

    fn record(
        &mut self,
        shared: &mut Shared,
        d_norm: f64,
        alpha_du: f64,
        alpha_pr: f64,
        ch: char,
        ls: usize,
        dual: f64,
    ) {
        // In restoration, the objective and inf_pr columns are the original problem's at
        // the current x and s (IPOPT's RestoIterationOutput); inf_du and lg(mu) are the
        // restoration problem's.
        let (objective, inf_pr) = match self.nlp.original_measures(&self.w) {
            Some(v) => v,
            None => (
                self.f / self.obj_scale,
                self.c
                    .iter()
                    .zip(&self.g_scale)
                    .fold(0.0f64, |a, (c, s)| a.max(c.abs() / s)),
            ),
        };
        shared.stats.records.push(IterationRecord {
            iter: shared.iter,
            restoration: self.setup_in_resto,
            objective,
            inf_pr,
            inf_du: dual,
            mu: self.mu,
            d_norm,
            regularization: self.delta_w,
            alpha_du,
            alpha_pr,
            alpha_pr_char: ch,
            ls,
        });
        if let (Some(obs), Some(rec)) = (shared.observer.as_mut(), shared.stats.records.last()) {
            let (x, lambda) = obs.buffers();
            self.nlp.user_point(&self.w[..self.n], &self.y, x, lambda);
            obs.call(rec);
        }
        if self.setup_in_resto {
            shared.stats.restoration_iterations += 1;
        }
        if self.delta_w > shared.stats.max_regularization {
            shared.stats.max_regularization = self.delta_w;
        }
        if self.opts.print_level >= 5 {
            if shared.stats.records.len() % 10 == 1 {
                println!("{}", crate::log::header());
            }
            println!(
                "{}",
                crate::log::format_record(shared.stats.records.last().unwrap_or(
                    &IterationRecord {
                        iter: 0,
                        restoration: false,
                        objective: 0.0,
                        inf_pr: 0.0,
                        inf_du: 0.0,
                        mu: 0.0,
                        d_norm: 0.0,
                        regularization: 0.0,
                        alpha_du: 0.0,
                        alpha_pr: 0.0,
                        alpha_pr_char: ' ',
                        ls: 0
                    }
                ))
            );
        }
    }

    fn outcome(
        &self,
        status: Status,
        message: impl Into<String>,
        resto_converged: bool,
    ) -> Outcome {
        Outcome {
            status,
            w: self.w.clone(),
            y: self.y.clone(),
            zl: self.zl.clone(),
            zu: self.zu.clone(),
            message: message.into(),
            resto_converged,
        }
    }

    // ------------------------------------------------------------------ main loop

    pub fn run(&mut self, shared: &mut Shared, start: Start) -> Outcome {
        if let Err(e) = self.initialize(start) {
            return self.outcome(Status::InvalidNumberDetected, e.to_string(), false);
        }
        let (_, eu) = self.errors(0.0, false);
        match self.resto_start.take() {
            Some((a_pr, ls)) => self.record(shared, 0.0, 0.0, a_pr, 'R', ls, eu[0]),
            None => self.record(shared, 0.0, 0.0, 0.0, ' ', 0, eu[0]),
        }
        let mut pending_resto = self.opts.start_with_resto && !self.setup_in_resto;
        let max_resto_iter_end = shared.iter + self.opts.max_resto_iter;
        loop {
            // The iteration callback (called by `record`) asked to stop (IPOPT tests
            // this before convergence).
            if shared.observer.as_ref().is_some_and(|o| o.stopped()) {
                return self.outcome(
                    Status::UserRequestedStop,
                    "stopped by the iteration callback",
                    false,
                );
            }
            // ---------------- convergence
            let (e0, eu) = self.nlp_error(0.0, false);
            if !self.setup_in_resto {
                let e = KktResiduals {
                    overall: e0,
                    dual: eu[0],
                    primal: eu[1],
                    compl: eu[2],
                };
                if let Some(status) = self.termination.check(&e, self.f, &self.opts.common) {
                    return self.outcome(status, "", false);
                }
            } else if e0 <= self.opts.tol {
                return self.outcome(
                    Status::SolveSucceeded,
                    "restoration problem converged",
                    true,
                );
            } else {
                self.termination.set_last_objective(self.f);
            }
            if shared.iter >= self.opts.max_iter {
                return self.outcome(Status::MaximumIterationsExceeded, "", false);
            }
            if self.setup_in_resto && shared.iter >= max_resto_iter_end {
                return self.outcome(Status::MaximumIterationsExceeded, "max_resto_iter", false);
            }
            if shared.start.elapsed().as_secs_f64() > self.opts.max_wall_time {
                return self.outcome(Status::MaximumWallTimeExceeded, "", false);
            }
            if inf_norm(&self.w) > self.opts.diverging_iterates_tol {
                return self.outcome(Status::DivergingIterates, "", false);
            }

            if !pending_resto {
                // ---------------- barrier update (monotone) and factorisation
                if self.mu_strategy == MuStrategy::Monotone {
                    self.update_mu_monotone(self.tiny_count > 0);
                }
                let factor_ok = self.factorize_with_inertia_correction(shared);
                if factor_ok && self.mu_strategy == MuStrategy::Adaptive {
                    self.update_mu_adaptive(shared, e0);
                }
                let dir_ok = factor_ok && self.solve_direction(shared, self.mu, false);
                if dir_ok {
                    shared.iter += 1;
                    let d_norm = inf_norm(&self.dw);
                    // Tiny step test.
                    let rel = (0..self.nw)
                        .map(|j| self.dw[j].abs() / (1.0 + self.w[j].abs()))
                        .fold(0.0, f64::max);
                    let tiny = rel < self.opts.tiny_step_tol
                        && inf_norm(&self.dy)
                            < self.opts.tiny_step_y_tol * (1.0 + inf_norm(&self.y));
                    if tiny && self.take_full_step() {
                        self.tiny_count += 1;
                        let (_, eu) = self.errors(0.0, false);
                        self.record(shared, d_norm, 1.0, 1.0, 't', 1, eu[0]);
                        if self.tiny_count >= 2 && self.mu <= mu_floor(&self.opts) * (1.0 + 1e-12) {
                            return self.outcome(Status::SearchDirectionBecomesTooSmall, "", false);
                        }
                        continue;
                    }
                    self.tiny_count = 0;
                    match self.line_search(shared) {
                        LineSearch::Accepted {
                            alpha_pr,
                            alpha_du,
                            kind,
                            trials,
                        } => {
                            let (_, eu) = self.errors(0.0, false);
                            let ch = kind.log_char();
                            self.record(shared, d_norm, alpha_du, alpha_pr, ch, trials, eu[0]);
                            if self.setup_in_resto && self.nlp.restoration_accepts(&self.w) {
                                return self.outcome(Status::SolveSucceeded, "", false);
                            }
                            continue;
                        }
                        LineSearch::Failed { alpha_pr, trials } => {
                            // The restoration phase's first row reports the failed line
                            // search (IPOPT: "12r", alpha_pr 'R', and its ls count, one
                            // more than the trial steps).
                            shared.iter -= 1;
                            self.resto_start = Some((alpha_pr, trials + 1));
                        }
                    }
                } else if self.setup_in_resto {
                    return self.outcome(
                        Status::ErrorInStepComputation,
                        "inertia correction failed in restoration",
                        false,
                    );
                }
                if !dir_ok && !factor_ok && self.m == 0 {
                    return self.outcome(
                        Status::ErrorInStepComputation,
                        "inertia correction failed",
                        false,
                    );
                }
            }
            pending_resto = false;
            // ---------------- line search failed (or step failed): restoration
            if self.setup_in_resto {
                return self.outcome(
                    Status::RestorationFailed,
                    "line search failed in restoration",
                    false,
                );
            }
            if self.m == 0 {
                let status = if self.termination.last_was_acceptable() {
                    Status::SolvedToAcceptableLevel
                } else {
                    Status::SearchDirectionBecomesTooSmall
                };
                return self.outcome(
                    status,
                    "line search failed for a problem without constraints",
                    false,
                );
            }
            self.resto_calls += 1;
            // The restoration phase's first row takes the next iteration number (IPOPT's
            // count: the iteration whose line search failed is that row).
            shared.iter += 1;
            // Augment the filter with the current iterate (Wächter & Biegler, Alg. A step A-9).
            let theta = one_norm(&self.c);
            let phi = self.barrier(&self.w, self.f, self.mu);
            self.filter.add(
                (1.0 - self.opts.gamma_theta) * theta,
                phi - self.opts.gamma_phi * theta,
            );
            match restoration::restore(self, shared) {
                Ok(()) => {
                    self.delta_w_last = 0.0;
                    self.tiny_count = 0;
                    continue;
                }
                Err(out) => return out,
            }
        }
    }

    // ------------------------------------------------------------------ for restoration

    /// Replaces the iterate by a restoration result `w` and re-evaluates everything.
    ///
    /// Multipliers as IPOPT sets them after a successful restoration
    /// (`MinC_1NrmRestorationPhase`): the bound multipliers take one primal-dual Newton
    /// step for complementarity, the whole move of the restoration phase counting as the
    /// primal step (Δz = (μ − z·Δs)/s − z, cut by the fraction to the boundary), and are
    /// all reset to 1 if one exceeds `bound_mult_reset_threshold`; the constraint
    /// multipliers are the least-squares estimate if `constr_mult_reset_threshold` > 0 and
    /// it is no larger than that, else 0.
    pub fn restart_from(&mut self, w: &[f64]) -> Result<(), CoreError> {
        let (mu, nw) = (self.mu, self.nw);
        let mut dzl = vec![0.0; nw];
        let mut dzu = vec![0.0; nw];
        for j in 0..nw {
            if self.has_l[j] {
                let (s, s_new) = (self.w[j] - self.wl[j], w[j] - self.wl[j]);
                dzl[j] = (mu + self.zl[j] * (s - s_new)) / s - self.zl[j];
            }
            if self.has_u[j] {
                let (s, s_new) = (self.wu[j] - self.w[j], self.wu[j] - w[j]);
                dzu[j] = (mu + self.zu[j] * (s - s_new)) / s - self.zu[j];
            }
        }
        let alpha = self.max_step_dual(&dzl, &dzu, tau(mu, &self.opts));
        let mut z_max: f64 = 0.0;
        for j in 0..nw {
            self.zl[j] += alpha * dzl[j];
            self.zu[j] += alpha * dzu[j];
            z_max = z_max.max(self.zl[j]).max(self.zu[j]);
        }
        if z_max > self.opts.bound_mult_reset_threshold {
            for j in 0..nw {
                self.zl[j] = if self.has_l[j] { 1.0 } else { 0.0 };
                self.zu[j] = if self.has_u[j] { 1.0 } else { 0.0 };
            }
        }
        self.w.copy_from_slice(w);
        self.y.iter_mut().for_each(|v| *v = 0.0);
        self.eval_first_order(At::RestorationResult)?;
        let mut c = std::mem::take(&mut self.c);
        self.constraint_residual(&self.w, &self.g, &mut c);
        self.c = c;
        if self.opts.constr_mult_reset_threshold > 0.0 {
            self.least_squares_multipliers(self.opts.constr_mult_reset_threshold);
        }
        self.eval_hessian(At::RestorationResult)
    }

    /// Current Hessian regularisation and δ_w bookkeeping accessors.
    pub fn theta_max(&self) -> f64 {
        self.theta_max
    }

    /// Objective scale factor (for the unscaled objective).
    pub fn obj_scale(&self) -> f64 {
        self.obj_scale
    }

    /// Constraint scale factors (for unscaled violations).
    pub fn g_scale(&self) -> &[f64] {
        &self.g_scale
    }
}
