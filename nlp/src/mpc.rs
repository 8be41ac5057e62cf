//! Model-predictive control: a closed-loop driver over any [`Solver`].
//!
//! An [`Mpc`] holds a compiled [`Transcription`] whose initial state is a parameter
//! ([`Ocp::set_initial_state_parameter`](crate::ocp::Ocp::set_initial_state_parameter)),
//! a solver and the previous solution. Each [`Mpc::step`] sets the measured state, moves
//! the previous solution one stage forward ([`Shift`]), re-solves warm from it
//! ([`Solver::solve_warm`]) and reports the latency and the status; [`Mpc::control`] is
//! the first control of the new plan. [`Mpc::run`] closes the loop with a plant (for
//! instance a [`Simulator`](crate::ocp::Simulator)). See `docs/mpc.md`.
//!
//! [`Mpc::with_rti`] runs real-time iterations instead ([`Rti`]): the first step (and the
//! first after [`Mpc::reset`]) is solved to convergence by a solver, every later one is
//! one SQP iteration split into a preparation (shift, linearise, factorise; also
//! callable ahead with [`Mpc::prepare`]) and a feedback with the measured state.
//!
//! The time budget of a step is the solver's: its options' `max_iter` and
//! `max_wall_time` (a step that hits them reports `MaximumIterationsExceeded` /
//! `MaximumWallTimeExceeded` and its iterate is still applied and used as the next warm
//! start).
use std::time::Instant;

/// The guide `docs/mpc.md`, compiled and run as doc tests so that its examples stay true.
#[cfg(doctest)]
#[doc = include_str!("../../docs/mpc.md")]
pub struct MpcGuide;

use symx::Evaluator;
use thiserror::Error;

use crate::compiled::Compiled;
use crate::error::SolveError;
use crate::frontend::Solver;
use crate::ocp::{OcpError, Shift, Transcription};
use crate::problem::BuildError;
use crate::solution::{Solution, Status};
use crate::sqp::{Rti, RtiError, SqpOptions};

/// Why an MPC set-up or step failed.
#[derive(Debug, Error)]
pub enum MpcError {
    /// The transcription has no initial-state parameter.
    #[error("the OCP's initial state is not a parameter: call Ocp::set_initial_state_parameter")]
    NoInitialStateParameter,
    /// The horizon is free: a receding horizon needs a fixed sampling period `T/N`.
    #[error("the OCP's final time is free: MPC needs a fixed horizon (Horizon::Fixed)")]
    FreeHorizon,
    /// A transcription or shift error.
    #[error(transparent)]
    Ocp(#[from] OcpError),
    /// A problem error (e.g. a measured state of the wrong length or not finite).
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The solver refused the problem.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The real-time iteration refused the problem or a step.
    #[error(transparent)]
    Rti(#[from] RtiError),
}

/// What one MPC step did.
#[derive(Clone, Debug, PartialEq)]
pub struct StepReport {
    /// The solver's status; for a real-time iteration
    /// [`Status::RealTimeIterationTaken`] (its QP solved, its step taken) or
    /// `ErrorInStepComputation` (no QP method solved its QP).
    pub status: Status,
    /// Solver iterations.
    pub iterations: usize,
    /// Wall seconds of the whole step: parameter update, shift and solve; with real-time
    /// iterations the preparation and the feedback (wherever the preparation ran: in the
    /// step, or ahead of it through [`Mpc::prepare`]).
    pub seconds: f64,
    /// Wall seconds inside the solver (its `stats.total_seconds`; with real-time
    /// iterations the preparation and the feedback).
    pub solve_seconds: f64,
    /// Wall seconds of the real-time iteration's feedback phase, the latency from the
    /// measured state to the control when the preparation runs ahead; equal to
    /// `solve_seconds` for a solver (all of its work follows the measurement).
    pub feedback_seconds: f64,
    /// Objective of the new plan.
    pub objective: f64,
    /// Whether the solve was warm-started (every step but the first one and the first
    /// one after [`Mpc::reset`]).
    pub warm: bool,
    /// With real-time iterations, the KKT residual (the largest of
    /// [`RtiResidual`](crate::sqp::RtiResidual)'s three) of the plan this step linearised
    /// at, measured by its preparation: how far from converged the iteration is. `None`
    /// for a solver's step (its status tells).
    pub residual: Option<f64>,
}

impl StepReport {
    /// Whether the step did what it is for: a solver's converged
    /// ([`Status::is_success`]), a real-time iteration's step was taken
    /// ([`Status::RealTimeIterationTaken`]).
    pub fn succeeded(&self) -> bool {
        self.status.is_success() || self.status == Status::RealTimeIterationTaken
    }
}

/// A closed loop run by [`Mpc::run`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ClosedLoop {
    /// Plant states `x₀ … x_S` (S + 1 entries).
    pub states: Vec<Vec<f64>>,
    /// Applied controls `u₀ … u_{S−1}`.
    pub controls: Vec<Vec<f64>>,
    /// One report per step.
    pub steps: Vec<StepReport>,
}

impl ClosedLoop {
    /// Whether every step succeeded ([`StepReport::succeeded`]: a solver's step converged,
    /// a real-time iteration's step was taken).
    pub fn all_succeeded(&self) -> bool {
        self.steps.iter().all(StepReport::succeeded)
    }

    /// Median and maximum of the steps' wall seconds ([`StepReport::seconds`]); `(0, 0)`
    /// for no step.
    pub fn latency(&self) -> (f64, f64) {
        median_and_max(self.steps.iter().map(|s| s.seconds))
    }

    /// Median and maximum of the warm-started steps' wall seconds: every step but the
    /// cold first one (and the first after [`Mpc::reset`]), which solves from the
    /// transcription's guess and is the loop's initialisation (acados and CasADi users
    /// solve it before the loop starts); `(0, 0)` for no warm step.
    pub fn warm_latency(&self) -> (f64, f64) {
        median_and_max(self.steps.iter().filter(|s| s.warm).map(|s| s.seconds))
    }

    /// Median and maximum of the steps' feedback seconds
    /// ([`StepReport::feedback_seconds`]); `(0, 0)` for no step.
    pub fn feedback_latency(&self) -> (f64, f64) {
        median_and_max(self.steps.iter().map(|s| s.feedback_seconds))
    }

    /// Mean and maximum of the iterations per step.
    pub fn iterations(&self) -> (f64, usize) {
        let total: usize = self.steps.iter().map(|s| s.iterations).sum();
        let max = self.steps.iter().map(|s| s.iterations).max().unwrap_or(0);
        (total as f64 / self.steps.len().max(1) as f64, max)
    }
}

fn median_and_max(t: impl Iterator<Item = f64>) -> (f64, f64) {
    let mut t: Vec<f64> = t.collect();
    t.sort_by(f64::total_cmp);
    match t.len() {
        0 => (0.0, 0.0),
        n => (median_of_sorted(&t), t[n - 1]),
    }
}

fn median_of_sorted(t: &[f64]) -> f64 {
    let n = t.len();
    if n % 2 == 1 {
        t[n / 2]
    } else {
        0.5 * (t[n / 2 - 1] + t[n / 2])
    }
}

/// A receding-horizon controller: see the [module documentation](self).
///
/// ```
/// use nlp::mpc::Mpc;
/// use nlp::ocp::{ButcherTableau, Horizon, Method, Ocp, Simulator};
/// use nlp::Ipm;
/// use symx::Matrix;
///
/// // Stabilise ẋ = x + u (unstable) at 0 with |u| ≤ 2.
/// let mut ocp = Ocp::new(&["x"], &["u"]);
/// ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![x[0] + u[0]]));
/// ocp.set_stage_cost(|x, u, _p| x[0].sq() + 0.1 * u[0].sq());
/// ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
/// ocp.set_control_bounds(&[-2.0], &[2.0]).unwrap();
/// ocp.set_initial_state_parameter("x0", &[1.0]).unwrap();
/// let tr = ocp.transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), 10).unwrap();
/// let mut mpc = Mpc::new(&tr, Box::new(Ipm::default())).unwrap();
/// let mut plant = Simulator::new(&ocp, ButcherTableau::rk4(), 1).unwrap();
/// let dt = mpc.sampling_period();
/// let run = mpc.run(&[1.0], 20, |x, u, next| plant.step_into(x, u, dt, next)).unwrap();
/// assert!(run.all_succeeded());
/// assert!(run.states[20][0].abs() < 1e-2); // regulated to 0
/// ```
pub struct Mpc {
    engine: Engine,
    shift: Shift,
    x0_parameter: String,
    /// The entries of the initial-state parameter in the parameter vector.
    x0_entries: std::ops::Range<usize>,
    /// Number of states.
    nx: usize,
    /// Positions of `U[:, 0]` in `x`.
    first_control: Vec<usize>,
    sampling_period: f64,
    previous: Option<Solution>,
    /// The solution a warm re-solve writes into (then swapped with `previous`): its
    /// vectors are reused, so that an IPM step allocates nothing in the steady state.
    next: Solution,
    control: Vec<f64>,
}

/// What solves a step.
enum Engine {
    /// A solver, re-solving warm.
    Solver {
        solver: Box<dyn Solver>,
        compiled: Box<Compiled>,
    },
    /// Real-time iterations after a first step solved by `first`.
    Rti {
        rti: Box<Rti>,
        first: Box<dyn Solver>,
        /// Whether the RTI plan is started (a first step was solved).
        started: bool,
        /// Whether the plan is shifted and prepared for the next feedback, and how long
        /// that took.
        prepared: Option<f64>,
    },
}

impl Mpc {
    /// A controller for `tr` (compiled here, its shift planned once) solved by `solver`.
    /// Errors: no initial-state parameter, a free horizon, or what compiling reports.
    pub fn new(tr: &Transcription, solver: Box<dyn Solver>) -> Result<Mpc, MpcError> {
        let compiled = Box::new(tr.compile()?);
        Mpc::with_engine(tr, Engine::Solver { solver, compiled })
    }

    /// A controller for `tr` by real-time iterations ([`Rti`] with the SQP's `options`):
    /// the first step (and the first after [`Mpc::reset`]) is solved to convergence by
    /// `first`, each later one is one preparation ([`Rti::prepare`] at the shifted plan)
    /// and one feedback ([`Rti::feedback`] with the measured state). A step's status is
    /// the feedback's ([`Status::RealTimeIterationTaken`], or `ErrorInStepComputation`
    /// when its QP failed) and its report carries the KKT residual the preparation
    /// measured ([`StepReport::residual`]).
    pub fn with_rti(
        tr: &Transcription,
        options: SqpOptions,
        first: Box<dyn Solver>,
    ) -> Result<Mpc, MpcError> {
        let rti = Box::new(Rti::from_transcription(tr, options)?);
        let engine = Engine::Rti {
            rti,
            first,
            started: false,
            prepared: None,
        };
        Mpc::with_engine(tr, engine)
    }

    /// This controller with its problem's functions evaluated by `evaluator` (CasADi's
    /// `jit` option): [`Evaluator::Jit`] compiles them to machine code once here (see
    /// [`Compiled::with_evaluator`]); the values are the tape's bit for bit, so every
    /// step takes the same iterates, in less time. Errors: native code cannot be generated
    /// (e.g. built without the `jit` feature). See `docs/mpc.md` §4 for when it pays.
    ///
    /// ```
    /// # use nlp::mpc::Mpc;
    /// # use nlp::ocp::{ButcherTableau, Horizon, Method, Ocp};
    /// # use nlp::Ipm;
    /// # use symx::Matrix;
    /// use symx::Evaluator;
    /// # let mut ocp = Ocp::new(&["x"], &["u"]);
    /// # ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![x[0] + u[0]]));
    /// # ocp.set_stage_cost(|x, u, _p| x[0].sq() + 0.1 * u[0].sq());
    /// # ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
    /// # ocp.set_initial_state_parameter("x0", &[1.0]).unwrap();
    /// # let tr = ocp.transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), 10).unwrap();
    /// let mut mpc = Mpc::new(&tr, Box::new(Ipm::default()))
    ///     .unwrap()
    ///     .with_evaluator(Evaluator::Jit)
    ///     .unwrap();
    /// assert_eq!(mpc.compiled_mut().evaluator(), Evaluator::Jit);
    /// assert!(mpc.step(&[1.0]).unwrap().status.is_success());
    /// ```
    pub fn with_evaluator(self, evaluator: Evaluator) -> Result<Mpc, MpcError> {
        let engine = match self.engine {
            Engine::Solver { solver, compiled } => Engine::Solver {
                solver,
                compiled: Box::new(compiled.with_evaluator(evaluator)?),
            },
            Engine::Rti {
                rti,
                first,
                started,
                prepared,
            } => Engine::Rti {
                rti: Box::new(rti.with_evaluator(evaluator)?),
                first,
                started,
                prepared,
            },
        };
        Ok(Mpc { engine, ..self })
    }

    fn with_engine(tr: &Transcription, engine: Engine) -> Result<Mpc, MpcError> {
        let x0_parameter = tr
            .initial_state_parameter()
            .ok_or(MpcError::NoInitialStateParameter)?
            .to_string();
        let x0_entries = engine_compiled(&engine)
            .parameter_blocks()
            .iter()
            .find(|b| b.name == x0_parameter)
            .ok_or(MpcError::NoInitialStateParameter)?
            .range();
        let t_f = tr.final_time().value().ok_or(MpcError::FreeHorizon)?;
        let u = tr.controls();
        let first_control = if u.nrows() > 0 {
            tr.problem()
                .variable_indices(&u.column(0).map_err(OcpError::from)?)?
        } else {
            Vec::new()
        };
        Ok(Mpc {
            engine,
            shift: tr.shift_plan()?,
            x0_parameter,
            x0_entries,
            nx: tr.states().nrows(),
            control: vec![0.0; first_control.len()],
            first_control,
            sampling_period: t_f / tr.intervals() as f64,
            previous: None,
            next: Solution::empty(),
        })
    }

    /// One step from the measured state `x0`: sets the parameter, shifts the previous
    /// solution (if any) and re-solves warm from it, or solves from the problem's initial
    /// point on the first step. The solution becomes the next step's warm start whatever
    /// its status (the report tells the status). With real-time iterations: prepares (if
    /// [`Mpc::prepare`] has not) and runs the feedback.
    ///
    /// A warm step re-solves with [`Solver::solve_warm_into`] into vectors kept from the
    /// step before and shifts in place: with the [`Ipm`](crate::Ipm), a step that takes no
    /// more iterations than an earlier one allocates nothing.
    pub fn step(&mut self, x0: &[f64]) -> Result<StepReport, MpcError> {
        let start = Instant::now();
        let nx = self.nx;
        if x0.len() != nx {
            return Err(OcpError::Size {
                what: format!("measured state (parameter '{}')", self.x0_parameter),
                expected: nx,
                got: x0.len(),
            }
            .into());
        }
        let mut report = match &mut self.engine {
            Engine::Solver { solver, compiled } => {
                compiled.set_parameter_range(self.x0_entries.clone(), x0)?;
                match self.previous.as_mut() {
                    Some(prev) => {
                        self.shift.apply(prev)?;
                        solver.solve_warm_into(&mut **compiled, prev, &mut self.next)?;
                        std::mem::swap(prev, &mut self.next);
                        solver_report(prev, true)
                    }
                    None => {
                        let sol = self.previous.insert(solver.solve(&mut **compiled)?);
                        solver_report(sol, false)
                    }
                }
            }
            Engine::Rti { .. } => self.rti_step(x0)?,
        };
        let plan = match &self.engine {
            Engine::Solver { .. } => self.previous.as_ref().expect("solved above"),
            Engine::Rti { rti, .. } => rti.plan(),
        };
        for (c, &j) in self.control.iter_mut().zip(&self.first_control) {
            *c = plan.x[j];
        }
        report.seconds += start.elapsed().as_secs_f64();
        Ok(report)
    }

    /// A real-time iteration step: the first solved to convergence, the others one
    /// feedback after a preparation. `seconds` holds the preparation if it ran ahead.
    fn rti_step(&mut self, x0: &[f64]) -> Result<StepReport, MpcError> {
        let Engine::Rti { started, .. } = &self.engine else {
            unreachable!("called for the RTI engine only")
        };
        if !*started {
            let Engine::Rti {
                rti,
                first,
                started,
                ..
            } = &mut self.engine
            else {
                unreachable!("checked above")
            };
            rti.compiled_mut()
                .set_parameter_range(self.x0_entries.clone(), x0)?;
            let sol = first.solve(rti.compiled_mut())?;
            rti.initialize(&sol)?;
            *started = true;
            return Ok(solver_report(&sol, false));
        }
        let ahead = match &self.engine {
            Engine::Rti {
                prepared: Some(t), ..
            } => *t,
            _ => 0.0,
        };
        let prepare_seconds = if ahead > 0.0 { 0.0 } else { self.prepare()? };
        let Engine::Rti { rti, prepared, .. } = &mut self.engine else {
            unreachable!("checked above")
        };
        let prepare_seconds = prepare_seconds + ahead;
        *prepared = None;
        let fb = rti.feedback(x0)?;
        Ok(StepReport {
            status: fb.status,
            iterations: 1,
            seconds: ahead,
            solve_seconds: prepare_seconds + fb.seconds,
            feedback_seconds: fb.seconds,
            objective: rti.plan().objective,
            warm: true,
            residual: Some(rti.residual().max()),
        })
    }

    /// With real-time iterations: shifts the plan and runs the preparation phase now
    /// (e.g. while waiting for the next measurement), so that the next [`Mpc::step`]
    /// only runs the feedback; returns its wall seconds. Does nothing (0) for a solver,
    /// before the first step, or when already prepared.
    pub fn prepare(&mut self) -> Result<f64, MpcError> {
        let Engine::Rti {
            rti,
            started: true,
            prepared,
            ..
        } = &mut self.engine
        else {
            return Ok(0.0);
        };
        if prepared.is_some() {
            return Ok(0.0);
        }
        let start = Instant::now();
        rti.shift(&self.shift)?;
        rti.prepare()?;
        // A measured 0 still marks the plan prepared.
        let t = start.elapsed().as_secs_f64().max(f64::MIN_POSITIVE);
        *prepared = Some(t);
        Ok(t)
    }

    /// Closes the loop for `steps` steps from `x_init`: each step solves from the
    /// current state, applies [`Mpc::control`] to `plant(x, u, next)` (which writes the
    /// state one sampling period later into `next`) and moves on.
    pub fn run(
        &mut self,
        x_init: &[f64],
        steps: usize,
        mut plant: impl FnMut(&[f64], &[f64], &mut [f64]) -> Result<(), OcpError>,
    ) -> Result<ClosedLoop, MpcError> {
        let mut out = ClosedLoop {
            states: vec![x_init.to_vec()],
            controls: Vec::with_capacity(steps),
            steps: Vec::with_capacity(steps),
        };
        for _ in 0..steps {
            let x = out.states.last().expect("starts with x_init").clone();
            out.steps.push(self.step(&x)?);
            let mut next = vec![0.0; x.len()];
            plant(&x, &self.control, &mut next)?;
            out.controls.push(self.control.clone());
            out.states.push(next);
        }
        Ok(out)
    }

    /// The first control of the latest plan (empty before the first step).
    pub fn control(&self) -> &[f64] {
        &self.control
    }

    /// The latest solution (the plan over the horizon), if a step was taken. With
    /// real-time iterations, [`Rti::plan`] (shifted once [`Mpc::prepare`] ran).
    pub fn solution(&self) -> Option<&Solution> {
        match &self.engine {
            Engine::Solver { .. } => self.previous.as_ref(),
            Engine::Rti {
                rti, started: true, ..
            } => Some(rti.plan()),
            Engine::Rti { .. } => None,
        }
    }

    /// The sampling period `T / N` (one stage of the grid): the plant must advance by it
    /// between steps, which is what the shift assumes.
    pub fn sampling_period(&self) -> f64 {
        self.sampling_period
    }

    /// The compiled problem, e.g. to change other parameters (a reference) between steps.
    pub fn compiled_mut(&mut self) -> &mut Compiled {
        match &mut self.engine {
            Engine::Solver { compiled, .. } => compiled,
            Engine::Rti { rti, .. } => rti.compiled_mut(),
        }
    }

    /// Forgets the previous solution: the next step solves from the problem's initial
    /// point (e.g. after a large disturbance).
    pub fn reset(&mut self) {
        self.previous = None;
        if let Engine::Rti {
            started, prepared, ..
        } = &mut self.engine
        {
            *started = false;
            *prepared = None;
        }
    }
}

/// The compiled problem an engine solves.
fn engine_compiled(engine: &Engine) -> &Compiled {
    match engine {
        Engine::Solver { compiled, .. } => compiled,
        Engine::Rti { rti, .. } => rti.compiled(),
    }
}

/// The report of a solver's step (its `seconds` filled by the caller).
fn solver_report(sol: &Solution, warm: bool) -> StepReport {
    StepReport {
        status: sol.status,
        iterations: sol.stats.iterations,
        seconds: 0.0,
        solve_seconds: sol.stats.total_seconds,
        feedback_seconds: sol.stats.total_seconds,
        objective: sol.objective,
        warm,
        residual: None,
    }
}
