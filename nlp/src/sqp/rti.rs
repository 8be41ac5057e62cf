//! Real-time iterations (Diehl, Bock & Schlöder 2005; acados' `rti_phase`): one SQP
//! iteration per sampling instant, split so that the latency between a measurement and
//! the control it produces is that of a QP back-substitution, not of a solve.
//!
//! * [`Rti::prepare`] (before the measurement, at the shifted plan x̄): evaluates f, ∇f, g,
//!   J and ∇²L at x̄, convexifies the Hessian as the SQP does (`Convexify`: B = ∇²L + δI +
//!   ρ_a·(J_AᵀJ_A + I_b) positive definite, certified by inertia), picks the working set
//!   of the last QP (or one guessed from the multipliers) and factorises the KKT matrix of
//!   its equality QP. None of this depends on the initial state: the parameter x0 enters
//!   only the constant term of the rows `X₀ − x0 = 0`.
//! * [`Rti::feedback`] (with the measured state): sets the parameter, updates the
//!   constants of the rows x0 enters (found once at construction: rows affine in x0 with
//!   coefficients independent of x, as the OCP's `X₀ − x0 = 0`; all of g is re-evaluated
//!   instead when x0 enters g otherwise), solves the QP with the active-set method from the
//!   prepared factorisation (usually one back-substitution, more when the working set
//!   changes), and takes the full step x̄ + d with the QP's multipliers. No line search,
//!   no elastic mode: RTI relies on the previous plan being close (the contraction of
//!   Newton-type iterations on a slowly moving problem). When the active-set method gives
//!   up, clarabel solves the elastic QP with the penalty `penalty_max` instead.
//!
//! The problem is not scaled (acados does not scale either): a QP's solution does not
//! depend on the objective's or the rows' scale, only the convexification's shift does.
//! Cones and the damped BFGS Hessian are not supported ([`RtiError::Unsupported`]).

#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use thiserror::Error;

use super::active_set;
use super::convexify::{active_sets_into, Convexify, ConvexifyScratch};
use super::geometry::Geometry;
use super::iterate::{Errors, Iterate, Mult};
use super::options::{HessianApproximation, SqpOptions};
use super::polish::{factor_working_set_in, EqScratch, WorkingSet};
use super::qp::{Qp, QpResult};
use super::rti_predictor::Predictor;
use super::shape::Shape;
use super::state::{new_qp, Curvature};
use super::subproblem::qp_data;
use crate::compiled::Compiled;
use crate::error::SolveError;
use crate::frontend::validate::validate;
use crate::kkt::{Kkt, KktError};
use crate::numeric::NumericNlp;
use crate::ocp::{OcpError, Shift, Transcription};
use crate::problem::BuildError;
use crate::solution::{Solution, Stats, Status};
use symx::Evaluator;

/// Why a real-time iteration could not be set up or carried out.
#[derive(Debug, Error)]
pub enum RtiError {
    /// The problem has no parameter of that name.
    #[error(
        "the problem has no parameter '{0}' (the initial state x0 of the real-time iteration)"
    )]
    UnknownParameter(String),
    /// A transcription without an initial-state parameter.
    #[error("the OCP's initial state is not a parameter: call Ocp::set_initial_state_parameter")]
    NoInitialStateParameter,
    /// A feature the real-time iteration does not handle.
    #[error("the real-time iteration does not support {0}")]
    Unsupported(&'static str),
    /// The measured state passed to `feedback` does not have the parameter's length.
    #[error("initial state (parameter '{parameter}'): expected {expected} values, got {got}")]
    InitialStateSize {
        /// The parameter's name.
        parameter: String,
        /// Its length.
        expected: usize,
        /// The length passed.
        got: usize,
    },
    /// `feedback` was called without a `prepare` since the last feedback or start.
    #[error(
        "feedback called before prepare: each feedback needs a preparation at the current plan"
    )]
    NotPrepared,
    /// The KKT matrix could not be set up.
    #[error("KKT matrix set-up failed: {0}")]
    Kkt(#[from] KktError),
    /// The problem or the options were rejected (bounds, sizes, option values).
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// A parameter value was rejected (wrong length, not finite).
    #[error(transparent)]
    Build(#[from] BuildError),
    /// A shift error (the plan does not have the transcription's sizes).
    #[error(transparent)]
    Ocp(#[from] OcpError),
    /// A function value or derivative at the plan is NaN or infinite.
    #[error("non-finite {0} at the plan being prepared")]
    NonFinite(&'static str),
}

/// The KKT residuals of the plan at its last preparation (unscaled max-norms, with the
/// initial-state parameter as it was then).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RtiResidual {
    /// Constraint violation (rows and bounds).
    pub primal: f64,
    /// Stationarity ‖∇f + Jᵀλ − z_L + z_U‖∞.
    pub dual: f64,
    /// Complementarity.
    pub complementarity: f64,
}

impl RtiResidual {
    /// The largest of the three.
    pub fn max(&self) -> f64 {
        self.primal.max(self.dual).max(self.complementarity)
    }
}

/// What one [`Rti::feedback`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Feedback {
    /// [`Status::RealTimeIterationTaken`] after a step (one iteration, convergence not
    /// tested: RTI by design; [`Rti::residual`] measures it), `ErrorInStepComputation`
    /// when no QP method solved the QP (the plan is then left as prepared).
    pub status: Status,
    /// Active-set iterations of the QP (0 when clarabel solved it).
    pub qp_iterations: usize,
    /// Factorisations in the feedback (0 when the prepared one sufficed).
    pub factorizations: usize,
    /// Whether clarabel solved the QP (the active-set method gave up).
    pub fallback: bool,
    /// Whether the step prepared for the plan's own initial state, corrected for the
    /// measured one by one back-substitution, was the QP's solution (the
    /// predictor-corrector of docs/mpc.md §5.1; no active-set iteration ran).
    pub corrected: bool,
    /// ‖d‖∞ of the step.
    pub step_norm: f64,
    /// Wall seconds of the feedback.
    pub seconds: f64,
}

/// A real-time iteration scheme on a compiled problem whose initial state is a
/// parameter: see the [module documentation](self) and `docs/mpc.md` §5.
///
/// ```
/// use nlp::ocp::{ButcherTableau, Horizon, Method, Ocp};
/// use nlp::{Ipm, Rti, Solver, SqpOptions};
/// use symx::Matrix;
///
/// let mut ocp = Ocp::new(&["x"], &["u"]);
/// ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![x[0] + u[0]]));
/// ocp.set_stage_cost(|x, u, _p| x[0].sq() + 0.1 * u[0].sq());
/// ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
/// ocp.set_control_bounds(&[-2.0], &[2.0]).unwrap();
/// ocp.set_initial_state_parameter("x0", &[1.0]).unwrap();
/// let tr = ocp.transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), 10).unwrap();
/// let mut rti = Rti::from_transcription(&tr, SqpOptions::default()).unwrap();
/// // Start from a converged plan for x0 = 1 and apply its first control (u₀ is x[11]).
/// let first = Ipm::default().solve(rti.compiled_mut()).unwrap();
/// rti.initialize(&first).unwrap();
/// let shift = tr.shift_plan().unwrap();
/// let mut x = vec![1.0];
/// x[0] += 0.1 * (x[0] + rti.plan().x[11]); // the plant (explicit Euler)
/// // Then one iteration per sampling instant.
/// for _ in 0..20 {
///     rti.shift(&shift).unwrap(); // the plan one stage forward
///     rti.prepare().unwrap(); // before the measurement
///     let fb = rti.feedback(&x).unwrap(); // after it: the new plan
///     assert_eq!(fb.status, nlp::Status::RealTimeIterationTaken);
///     x[0] += 0.1 * (x[0] + rti.plan().x[11]);
/// }
/// assert!(x[0].abs() < 0.05);
/// ```
pub struct Rti {
    compiled: Compiled,
    x0_parameter: String,
    /// The entries of the initial-state parameter in the parameter vector.
    x0_entries: std::ops::Range<usize>,
    /// How x0 enters g: `(row, entry of x0, coefficient)`, so that a feedback updates
    /// only those rows; `None` when x0 enters g otherwise (all of g is re-evaluated).
    x0_terms: Option<Vec<(usize, usize, f64)>>,
    options: SqpOptions,
    shape: Shape,
    geo: Geometry,
    /// The linearisation point of the last preparation.
    it: Iterate,
    curv: Curvature,
    kkt: Kkt,
    /// clarabel's elastic QP, laid out on the first fallback.
    qp: Option<Qp>,
    /// The working set prepared (and, after a feedback, the one of its QP), when
    /// `has_working_set`; otherwise the next preparation guesses one.
    working_set: WorkingSet,
    has_working_set: bool,
    /// Whether `kkt` holds the factorisation of `working_set`'s equality QP.
    factored: bool,
    /// The shift δ of the prepared B.
    delta: f64,
    prepared: bool,
    plan: Solution,
    residual: RtiResidual,
    lgrad: Vec<f64>,
    /// Scratch: J d, for the QP model's prediction.
    jd: Vec<f64>,
    work: Work,
}

/// The work vectors of the two phases, kept between steps: a steady-state preparation
/// and feedback allocate nothing (`nlp/tests/rti.rs`), except when clarabel's fallback
/// solves the QP.
struct Work {
    /// The convexification's strongly active rows and bounds.
    active: (Vec<bool>, Vec<bool>),
    convexify: ConvexifyScratch,
    /// The diagonals of the preparation's factorisation.
    eq: EqScratch,
    /// The active-set method's vectors.
    qp: active_set::Scratch,
    /// The step prepared for the plan's initial state and its correction.
    predictor: Predictor,
    /// The QP's result.
    res: QpResult,
    /// The QP's multipliers of the problem (`Mult::set_from_qp`).
    mult: Mult,
}

impl Work {
    /// Empty work vectors for n variables and m rows.
    fn new(n: usize, m: usize) -> Work {
        Work {
            active: (Vec::with_capacity(m), Vec::with_capacity(n)),
            convexify: ConvexifyScratch::default(),
            eq: EqScratch::default(),
            qp: active_set::Scratch::default(),
            predictor: Predictor::default(),
            res: QpResult::empty(),
            mult: Mult::zeros(n, m, 0),
        }
    }
}

/// How the feedback's QP was solved.
struct QpOutcome {
    /// Whether a result is in `Work::res`.
    solved: bool,
    /// Active-set iterations (0 when clarabel solved it).
    iterations: usize,
    /// Factorisations.
    factorizations: usize,
    /// Whether the prepared step's correction was the solution.
    corrected: bool,
    /// Whether clarabel solved it.
    fallback: bool,
}

impl QpOutcome {
    /// Solved by the active-set method in `iterations` (`corrected`: the prepared step's
    /// correction was the solution).
    fn by_active_set(iterations: usize, factorizations: usize, corrected: bool) -> QpOutcome {
        QpOutcome {
            solved: true,
            iterations,
            factorizations,
            corrected,
            fallback: false,
        }
    }
}

impl Rti {
    /// A real-time iteration on `compiled` whose initial state is the parameter
    /// `x0_parameter`, with the SQP's Hessian and QP options. The plan starts at the
    /// problem's initial point with zero multipliers ([`Rti::initialize`] replaces it).
    /// Errors: unknown parameter, cones, damped BFGS, invalid options or bounds.
    pub fn new(
        mut compiled: Compiled,
        x0_parameter: &str,
        options: SqpOptions,
    ) -> Result<Rti, RtiError> {
        options.validate()?;
        if options.hessian_approximation != HessianApproximation::Exact {
            return Err(RtiError::Unsupported("the damped BFGS Hessian"));
        }
        if !compiled.affine_cones().is_empty() {
            return Err(RtiError::Unsupported("second-order cones"));
        }
        let x0_entries = compiled
            .parameter_blocks()
            .iter()
            .find(|b| b.name == x0_parameter)
            .ok_or_else(|| RtiError::UnknownParameter(x0_parameter.to_string()))?
            .range();
        let v = validate(&compiled, None)?;
        let x0_terms = x0_terms(&mut compiled, &v.x0, x0_entries.clone());
        let (n, m) = (compiled.n(), compiled.m());
        let shape = Shape {
            n,
            m,
            n_cone: 0,
            jp: compiled.jac_g_sparsity().clone(),
            hp: compiled.hess_l_sparsity().clone(),
            cp: None,
            block: Vec::new(),
            dense: false,
        };
        let kkt = Kkt::new(n, m, &shape.hp, &shape.jp)?;
        let plan = start_plan(&compiled, v.x0.clone());
        let geo = Geometry {
            x_l: v.x_l,
            x_u: v.x_u,
            g_l: v.g_l,
            g_u: v.g_u,
            cones: Vec::new(),
            cone_row: vec![false; m],
        };
        let it = Iterate {
            x: vec![0.0; n],
            f: 0.0,
            g: vec![0.0; m],
            cone: Vec::new(),
            grad: vec![0.0; n],
            jv: vec![0.0; shape.jp.row_idx().len()],
            cv: Vec::new(),
            mult: Mult::zeros(n, m, 0),
            have_mult: true,
        };
        let curv = Curvature::new(&shape);
        Ok(Rti {
            compiled,
            x0_parameter: x0_parameter.to_string(),
            x0_entries,
            x0_terms,
            options,
            shape,
            geo,
            it,
            curv,
            kkt,
            qp: None,
            working_set: WorkingSet {
                rows: Vec::with_capacity(m),
                vars: Vec::with_capacity(n),
            },
            has_working_set: false,
            factored: false,
            delta: 0.0,
            prepared: false,
            plan,
            residual: RtiResidual::default(),
            lgrad: vec![0.0; n],
            jd: vec![0.0; m],
            work: Work::new(n, m),
        })
    }

    /// A real-time iteration on the compiled transcription `tr`, its initial-state
    /// parameter as x0 ([`Ocp::set_initial_state_parameter`](crate::ocp::Ocp::set_initial_state_parameter)).
    pub fn from_transcription(tr: &Transcription, options: SqpOptions) -> Result<Rti, RtiError> {
        let name = tr
            .initial_state_parameter()
            .ok_or(RtiError::NoInitialStateParameter)?
            .to_string();
        Rti::new(tr.compile()?, &name, options)
    }

    /// This real-time iteration with its problem's functions evaluated by `evaluator`
    /// ([`Compiled::with_evaluator`]: e.g. `Evaluator::Jit`, native code with the tape's
    /// values bit for bit, so the same iterates, faster). Errors: native code cannot be
    /// generated (e.g. built without the `jit` feature).
    pub fn with_evaluator(self, evaluator: Evaluator) -> Result<Rti, RtiError> {
        let compiled = self.compiled.with_evaluator(evaluator)?;
        Ok(Rti { compiled, ..self })
    }

    /// Starts from `guess` (x and the multipliers λ, z_L, z_U; e.g. a converged solve of
    /// the first sampling instant, as acados users initialise RTI): the next call is
    /// [`Rti::prepare`] (or [`Rti::shift`] first). An error names a wrong length.
    pub fn initialize(&mut self, guess: &Solution) -> Result<(), RtiError> {
        guess.check_warm_start(self.shape.n, self.shape.m)?;
        self.plan.x.copy_from_slice(&guess.x);
        self.plan.lambda.copy_from_slice(&guess.lambda);
        self.plan.z_l.copy_from_slice(&guess.z_l);
        self.plan.z_u.copy_from_slice(&guess.z_u);
        if guess.g.len() == self.shape.m {
            self.plan.g.copy_from_slice(&guess.g);
        }
        self.plan.objective = guess.objective;
        self.prepared = false;
        self.has_working_set = false;
        Ok(())
    }

    /// Moves the plan one stage forward ([`Shift::apply`]); a preparation done before is
    /// void (the next feedback needs a new one).
    pub fn shift(&mut self, shift: &Shift) -> Result<(), RtiError> {
        shift.apply(&mut self.plan)?;
        self.prepared = false;
        // The last QP's working set belongs to the unshifted plan: the preparation
        // guesses the shifted one from the shifted multipliers.
        self.has_working_set = false;
        Ok(())
    }

    /// The preparation phase at the current plan (see the [module documentation](self)):
    /// everything of the next QP that does not depend on the initial state, its KKT
    /// matrix factorised for the expected working set. Also measures the plan's KKT
    /// residual ([`Rti::residual`]) with the parameter values set now.
    pub fn prepare(&mut self) -> Result<(), RtiError> {
        self.load_plan();
        self.linearise()?;
        let err = self
            .it
            .kkt_errors(self.options.s_max, &self.geo, &self.shape, &mut self.lgrad);
        self.residual = residual(&err);
        self.delta = self.convexify()?;
        let data = qp_data(&self.it, &self.geo, &self.curv, false, self.delta, 0.0);
        let w = &mut self.working_set;
        if !(self.has_working_set && active_set::fits(w, &data)) {
            active_set::guess_into(&data, &self.it.mult, w);
        }
        self.has_working_set = true;
        let mut n_fact = 0;
        let eq = &mut self.work.eq;
        self.factored = factor_working_set_in(&mut self.kkt, &data, w, &mut n_fact, eq);
        self.predict();
        self.prepared = true;
        Ok(())
    }

    /// The QP step for the plan's own initial state with the prepared factorisation
    /// (`Predictor`), when x0 enters g through rows affine in it; the feedback then only
    /// corrects it for the measured state.
    fn predict(&mut self) {
        let pr = &mut self.work.predictor;
        pr.reset(&self.compiled.parameter_values()[self.x0_entries.clone()]);
        let Some(terms) = self.x0_terms.as_deref() else {
            return;
        };
        if !self.factored {
            return;
        }
        pr.move_to_plan(terms, &mut self.it.g, (&self.geo.g_l, &self.geo.g_u));
        let data = qp_data(&self.it, &self.geo, &self.curv, false, self.delta, 0.0);
        pr.solve(&mut self.kkt, &data, &self.working_set, &mut self.work.eq);
    }

    /// The feedback phase with the measured initial state `x0`: the QP of the prepared
    /// linearisation with x0 inserted, solved warm, and the full step; the plan
    /// ([`Rti::plan`]) is then the new one. Errors: no preparation since the last
    /// feedback, `x0` of the wrong length or not finite.
    pub fn feedback(&mut self, x0: &[f64]) -> Result<Feedback, RtiError> {
        let start = Instant::now();
        if !self.prepared {
            return Err(RtiError::NotPrepared);
        }
        if x0.len() != self.x0_entries.len() {
            return Err(RtiError::InitialStateSize {
                parameter: self.x0_parameter.clone(),
                expected: self.x0_entries.len(),
                got: x0.len(),
            });
        }
        self.insert_initial_state(x0)?;
        self.prepared = false;
        let qp = self.solve_qp(x0);
        let status = if qp.solved {
            self.take_step();
            Status::RealTimeIterationTaken
        } else {
            Status::ErrorInStepComputation
        };
        self.plan.status = status;
        self.plan.parameters.clear();
        self.plan
            .parameters
            .extend_from_slice(self.compiled.parameter_values());
        let step_norm = self
            .plan
            .x
            .iter()
            .zip(&self.it.x)
            .fold(0.0f64, |a, (p, x)| a.max((p - x).abs()));
        Ok(Feedback {
            status,
            qp_iterations: qp.iterations,
            factorizations: qp.factorizations,
            fallback: qp.fallback,
            corrected: qp.corrected,
            step_norm,
            seconds: start.elapsed().as_secs_f64(),
        })
    }

    /// The current plan: after a feedback, the new iterate x̄ + d with the QP's
    /// multipliers; its `g` is the linearised prediction g(x̄) + J d and its `objective`
    /// the QP model's prediction f(x̄) + ∇fᵀd + ½dᵀBd (no evaluation on the latency
    /// path); its `status` that of the last feedback.
    pub fn plan(&self) -> &Solution {
        &self.plan
    }

    /// The KKT residuals of the plan measured by the last [`Rti::prepare`].
    pub fn residual(&self) -> RtiResidual {
        self.residual
    }

    /// The compiled problem (e.g. to set other parameters, or to solve it to convergence
    /// for [`Rti::initialize`]).
    pub fn compiled_mut(&mut self) -> &mut Compiled {
        &mut self.compiled
    }

    /// The compiled problem.
    pub fn compiled(&self) -> &Compiled {
        &self.compiled
    }

    /// The name of the initial-state parameter.
    pub fn x0_parameter(&self) -> &str {
        &self.x0_parameter
    }

    /// Sets the parameter x0 and g at the prepared point for it: the rows x0 enters
    /// updated by their coefficients, or all of g re-evaluated (see `x0_terms`).
    fn insert_initial_state(&mut self, x0: &[f64]) -> Result<(), RtiError> {
        let start = self.x0_entries.start;
        if let Some(terms) = &self.x0_terms {
            // The values the prepared g corresponds to (the plan's initial state).
            let old = &self.work.predictor.x0_lin;
            if x0.iter().all(|v| v.is_finite()) {
                for &(row, k, c) in terms {
                    self.it.g[row] += c * (x0[k] - old[k]);
                }
            }
        }
        self.compiled
            .set_parameter_range(start..start + x0.len(), x0)?;
        if self.x0_terms.is_none() {
            self.compiled.eval_g(&self.it.x, &mut self.it.g);
            if self.it.g.iter().any(|v| !v.is_finite()) {
                return Err(RtiError::NonFinite("constraint value"));
            }
        }
        Ok(())
    }

    /// The plan as the linearisation point: x clamped into its bounds, the multipliers.
    fn load_plan(&mut self) {
        let (it, plan, geo) = (&mut self.it, &self.plan, &self.geo);
        for j in 0..self.shape.n {
            it.x[j] = plan.x[j].clamp(geo.x_l[j], geo.x_u[j]);
        }
        it.mult.lambda.copy_from_slice(&plan.lambda);
        it.mult.z_l.copy_from_slice(&plan.z_l);
        it.mult.z_u.copy_from_slice(&plan.z_u);
    }

    /// f, ∇f, g, J and ∇²L at the linearisation point.
    fn linearise(&mut self) -> Result<(), RtiError> {
        let (c, it) = (&mut self.compiled, &mut self.it);
        it.f = c.eval_f_g(&it.x, &mut it.g);
        c.eval_grad_f_jac_g(&it.x, &mut it.grad, &mut it.jv);
        c.eval_hess_l(&it.x, 1.0, &it.mult.lambda, &mut self.curv.hv);
        let finite = |v: &[f64]| v.iter().all(|a| a.is_finite());
        if !it.f.is_finite() || !finite(&it.grad) || !finite(&it.g) {
            return Err(RtiError::NonFinite("objective or constraint value"));
        }
        if !finite(&it.jv) || !finite(&self.curv.hv) {
            return Err(RtiError::NonFinite("derivative"));
        }
        Ok(())
    }

    /// B's convexification at the linearisation point (as the SQP's), returning δ.
    fn convexify(&mut self) -> Result<f64, RtiError> {
        let (it, curv, work) = (&self.it, &mut self.curv, &mut self.work);
        active_sets_into(&self.geo, &it.x, &it.g, &it.mult, &mut work.active);
        let (active_r, active_b) = &work.active;
        let conv = Convexify {
            kkt: &mut self.kkt,
            hv: &curv.hv,
            jv: &it.jv,
            active_r,
            active_b,
        };
        let mut n_fact = 0;
        let last = (curv.delta_last, curv.rho_a_last);
        let (delta, rho_a) = conv
            .run_in(&self.options, last, &mut n_fact, &mut work.convexify)
            .ok_or(RtiError::Unsupported(
                "a Hessian that no shift up to max_hessian_shift convexifies",
            ))?;
        curv.rho_a_last = rho_a;
        curv.delta_last = delta;
        for (w, &a) in curv.row_weight.iter_mut().zip(active_r) {
            *w = if a { rho_a } else { 0.0 };
        }
        for (w, &a) in curv.bound_weight.iter_mut().zip(active_b) {
            *w = if a { rho_a } else { 0.0 };
        }
        Ok(delta)
    }

    /// The QP at the prepared linearisation with the current g, its result into
    /// `work.res`: the active-set method from the prepared working set (and
    /// factorisation), else clarabel's elastic QP with ρ = `penalty_max` (which allocates).
    fn solve_qp(&mut self, x0: &[f64]) -> QpOutcome {
        let o = &self.options;
        let data = qp_data(
            &self.it,
            &self.geo,
            &self.curv,
            false,
            self.delta,
            o.penalty_max,
        );
        let mut n_fact = 0;
        if o.qp_active_set && self.has_working_set && self.factored {
            let terms = self.x0_terms.as_deref().unwrap_or_default();
            let w = &self.working_set;
            let pats = (&self.shape.jp, &self.shape.hp);
            let work = &mut self.work;
            let step = work.predictor.correct(&mut self.kkt, &data, w, terms, x0);
            let found = step.and_then(|step| {
                let out = (w, &mut work.res);
                active_set::accept_step_in(&data, pats, out, step, 0, &mut work.qp)
            });
            if let Some(found) = found {
                self.factored = false;
                return QpOutcome::by_active_set(found.iterations, 0, true);
            }
        }
        if o.qp_active_set {
            let w = &mut self.working_set;
            if !self.has_working_set {
                active_set::guess_into(&data, &self.it.mult, w);
            }
            let solved = active_set::solve_in(
                &mut self.kkt,
                &data,
                (&self.shape.jp, &self.shape.hp),
                (w, &mut self.work.res),
                (o.qp_active_set_max_iter as usize, 0),
                (&mut n_fact, self.factored),
                &mut self.work.qp,
            );
            self.factored = false;
            // On failure `w` is the last working set tried: the next preparation guesses.
            self.has_working_set = solved.is_ok();
            if let Ok(found) = solved {
                return QpOutcome::by_active_set(found.iterations, n_fact, false);
            }
        }
        let qp = self
            .qp
            .get_or_insert_with(|| new_qp(&self.shape, &self.geo, o, true));
        let res = qp.solve(&data).ok().filter(|r| {
            matches!(
                r.status,
                clarabel::solver::SolverStatus::Solved
                    | clarabel::solver::SolverStatus::AlmostSolved
            ) && r.e.iter().all(|e| *e <= o.elastic_tol)
        });
        let solved = res.is_some();
        if let Some(res) = res {
            self.work.res = res;
        }
        QpOutcome {
            solved,
            iterations: 0,
            factorizations: n_fact,
            fallback: true,
            corrected: false,
        }
    }

    /// The plan ← x̄ + d with the QP's multipliers (of `work.res`), its predicted g and
    /// objective.
    fn take_step(&mut self) {
        let (it, plan, shape) = (&self.it, &mut self.plan, &self.shape);
        let (res, mult) = (&self.work.res, &mut self.work.mult);
        for j in 0..shape.n {
            plan.x[j] = it.x[j] + res.d[j];
        }
        mult.set_from_qp(res);
        plan.lambda.copy_from_slice(&mult.lambda);
        // The augmented term ρ_a·d_j of an active bound is in the QP's bound multiplier
        // but not in the problem's Lagrangian (as ρ_a·J_i d of a row is in λ, which
        // `set_from_qp` removes): without it the multipliers of a long step (a jump of the
        // initial state) would be off by ρ_a·d_j. The SQP's steps shrink to 0, RTI's not.
        for j in 0..shape.n {
            let z = mult.z_l[j] - mult.z_u[j] - self.curv.bound_weight[j] * res.d[j];
            plan.z_l[j] = z.max(0.0);
            plan.z_u[j] = (-z).max(0.0);
        }
        plan.g.copy_from_slice(&it.g);
        for c in 0..shape.n {
            for p in shape.jp.col_range(c) {
                plan.g[shape.jp.row_idx()[p]] += it.jv[p] * res.d[c];
            }
        }
        let change = model_change(it, &self.curv, self.delta, shape, &res.d, &mut self.jd);
        plan.objective = it.f + change;
    }
}

/// ∇fᵀd + ½dᵀBd with B = H + δI + ρ_a·(J_AᵀJ_A + I_b); `jd` (m entries) is scratch.
fn model_change(
    it: &Iterate,
    curv: &Curvature,
    delta: f64,
    shape: &Shape,
    d: &[f64],
    jd: &mut [f64],
) -> f64 {
    let mut lin = 0.0;
    let mut quad = 0.0;
    for c in 0..shape.n {
        lin += it.grad[c] * d[c];
        quad += (delta + curv.bound_weight[c]) * d[c] * d[c];
        for p in shape.hp.col_range(c) {
            let r = shape.hp.row_idx()[p];
            let v = curv.hv[p] * d[r] * d[c];
            quad += if r == c { v } else { 2.0 * v };
        }
    }
    jd.iter_mut().for_each(|v| *v = 0.0);
    for c in 0..shape.n {
        for p in shape.jp.col_range(c) {
            jd[shape.jp.row_idx()[p]] += it.jv[p] * d[c];
        }
    }
    for (w, v) in curv.row_weight.iter().zip(jd.iter()) {
        quad += w * v * v;
    }
    lin + 0.5 * quad
}

/// The residuals of `err` (the RTI does not scale: its scaled errors are the user's).
fn residual(err: &Errors) -> RtiResidual {
    RtiResidual {
        primal: err.inf_pr,
        dual: err.inf_du,
        complementarity: err.compl,
    }
}

/// How the parameter entries `x0` enter g, probed at construction: for each entry k, g
/// at `x` (the initial point) and at `x + 1` with x0_k moved by ±1 and +2. The rows that
/// move are kept with their coefficient c (central difference) when g moves by c per
/// unit at both points and linearly (to 1e-12 relative): affine in x0 with a coefficient
/// independent of x, as the OCP's initial-state rows `X₀ − x0`. `None` otherwise, or when
/// an evaluation is not finite. The parameter is left as it was.
fn x0_terms(
    compiled: &mut Compiled,
    x: &[f64],
    entries: std::ops::Range<usize>,
) -> Option<Vec<(usize, usize, f64)>> {
    let m = compiled.m();
    let x_moved: Vec<f64> = x.iter().map(|v| v + 1.0).collect();
    let base: Vec<f64> = compiled.parameter_values()[entries.clone()].to_vec();
    let g_at = |c: &mut Compiled, point: &[f64], k: usize, dp: f64| -> Option<Vec<f64>> {
        let mut p = base.clone();
        p[k] += dp;
        c.set_parameter_range(entries.clone(), &p).ok()?;
        let mut g = vec![0.0; m];
        c.eval_g(point, &mut g);
        g.iter().all(|v| v.is_finite()).then_some(g)
    };
    let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-12 * scale.max(1.0);
    let mut terms = Vec::new();
    let mut affine = true;
    'entries: for k in 0..base.len() {
        let mut coefficients: Option<Vec<f64>> = None;
        for point in [x, &x_moved[..]] {
            let (Some(g0), Some(up), Some(down), Some(up2)) = (
                g_at(compiled, point, k, 0.0),
                g_at(compiled, point, k, 1.0),
                g_at(compiled, point, k, -1.0),
                g_at(compiled, point, k, 2.0),
            ) else {
                affine = false;
                break 'entries;
            };
            let c: Vec<f64> = (0..m).map(|i| 0.5 * (up[i] - down[i])).collect();
            for i in 0..m {
                let scale = g0[i].abs() + c[i].abs();
                let linear =
                    close(up[i] - g0[i], c[i], scale) && close(up2[i] - g0[i], 2.0 * c[i], scale);
                let same = coefficients
                    .as_ref()
                    .is_none_or(|c0| close(c0[i], c[i], scale));
                if !linear || !same {
                    affine = false;
                    break 'entries;
                }
            }
            coefficients = Some(c);
        }
        let c = coefficients.expect("two points probed");
        terms.extend((0..m).filter(|&i| c[i] != 0.0).map(|i| (i, k, c[i])));
    }
    compiled
        .set_parameter_range(entries, &base)
        .expect("the values read back");
    affine.then_some(terms)
}

/// The plan before any start: `x` with zero multipliers.
fn start_plan(compiled: &Compiled, x: Vec<f64>) -> Solution {
    let (n, m) = (compiled.n(), compiled.m());
    Solution {
        status: Status::MaximumIterationsExceeded,
        x,
        lambda: vec![0.0; m],
        z_l: vec![0.0; n],
        z_u: vec![0.0; n],
        g: vec![0.0; m],
        objective: f64::NAN,
        constr_viol: f64::NAN,
        dual_inf: f64::NAN,
        compl: f64::NAN,
        message: "real-time iteration plan".into(),
        stats: Stats::default(),
        parameters: compiled.parameter_values().to_vec(),
    }
}
