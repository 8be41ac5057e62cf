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
//! The time budget of a step is the solver's: its options' `max_iter` and
//! `max_wall_time` (a step that hits them reports `MaximumIterationsExceeded` /
//! `MaximumWallTimeExceeded` and its iterate is still applied and used as the next warm
//! start).
use std::time::Instant;

/// The guide `docs/mpc.md`, compiled and run as doc tests so that its examples stay true.
#[cfg(doctest)]
#[doc = include_str!("../../docs/mpc.md")]
pub struct MpcGuide;

use thiserror::Error;

use crate::compiled::Compiled;
use crate::error::SolveError;
use crate::frontend::Solver;
use crate::ocp::{OcpError, Shift, Transcription};
use crate::problem::BuildError;
use crate::solution::{Solution, Status};

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
}

/// What one MPC step did.
#[derive(Clone, Debug, PartialEq)]
pub struct StepReport {
    /// The solver's status.
    pub status: Status,
    /// Solver iterations.
    pub iterations: usize,
    /// Wall seconds of the whole step: parameter update, shift and solve.
    pub seconds: f64,
    /// Wall seconds inside the solver (its `stats.total_seconds`).
    pub solve_seconds: f64,
    /// Objective of the new plan.
    pub objective: f64,
    /// Whether the solve was warm-started (every step but the first one and the first
    /// one after [`Mpc::reset`]).
    pub warm: bool,
}

/// A closed loop run by [`Mpc::run`].
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedLoop {
    /// Plant states `x₀ … x_S` (S + 1 entries).
    pub states: Vec<Vec<f64>>,
    /// Applied controls `u₀ … u_{S−1}`.
    pub controls: Vec<Vec<f64>>,
    /// One report per step.
    pub steps: Vec<StepReport>,
}

impl ClosedLoop {
    /// Whether every step's status is a success ([`Status::is_success`]).
    pub fn all_succeeded(&self) -> bool {
        self.steps.iter().all(|s| s.status.is_success())
    }

    /// Median and maximum of the steps' wall seconds ([`StepReport::seconds`]); `(0, 0)`
    /// for no step.
    pub fn latency(&self) -> (f64, f64) {
        let mut t: Vec<f64> = self.steps.iter().map(|s| s.seconds).collect();
        t.sort_by(f64::total_cmp);
        match t.len() {
            0 => (0.0, 0.0),
            n => (median_of_sorted(&t), t[n - 1]),
        }
    }

    /// Mean and maximum of the iterations per step.
    pub fn iterations(&self) -> (f64, usize) {
        let total: usize = self.steps.iter().map(|s| s.iterations).sum();
        let max = self.steps.iter().map(|s| s.iterations).max().unwrap_or(0);
        (total as f64 / self.steps.len().max(1) as f64, max)
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
    solver: Box<dyn Solver>,
    compiled: Compiled,
    shift: Shift,
    x0_parameter: String,
    /// Number of states.
    nx: usize,
    /// Positions of `U[:, 0]` in `x`.
    first_control: Vec<usize>,
    sampling_period: f64,
    previous: Option<Solution>,
    control: Vec<f64>,
}

impl Mpc {
    /// A controller for `tr` (compiled here, its shift planned once) solved by `solver`.
    /// Errors: no initial-state parameter, a free horizon, or what compiling reports.
    pub fn new(tr: &Transcription, solver: Box<dyn Solver>) -> Result<Mpc, MpcError> {
        let x0_parameter = tr
            .initial_state_parameter()
            .ok_or(MpcError::NoInitialStateParameter)?
            .to_string();
        let t_f = tr.final_time().value().ok_or(MpcError::FreeHorizon)?;
        let u = tr.controls();
        let first_control = if u.nrows() > 0 {
            tr.problem()
                .variable_indices(&u.column(0).map_err(OcpError::from)?)?
        } else {
            Vec::new()
        };
        Ok(Mpc {
            solver,
            compiled: tr.compile()?,
            shift: tr.shift_plan()?,
            x0_parameter,
            nx: tr.states().nrows(),
            control: vec![0.0; first_control.len()],
            first_control,
            sampling_period: t_f / tr.intervals() as f64,
            previous: None,
        })
    }

    /// One step from the measured state `x0`: sets the parameter, shifts the previous
    /// solution (if any) and re-solves warm from it, or solves from the problem's initial
    /// point on the first step. The solution becomes the next step's warm start whatever
    /// its status (the report tells the status).
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
        self.compiled.set_value(self.x0_parameter.as_str(), x0)?;
        let warm = self.previous.is_some();
        let sol = match self.previous.as_mut() {
            Some(prev) => {
                self.shift.apply(prev)?;
                self.solver.solve_warm(&mut self.compiled, prev)?
            }
            None => self.solver.solve(&mut self.compiled)?,
        };
        for (c, &j) in self.control.iter_mut().zip(&self.first_control) {
            *c = sol.x[j];
        }
        let report = StepReport {
            status: sol.status,
            iterations: sol.stats.iterations,
            seconds: 0.0,
            solve_seconds: sol.stats.total_seconds,
            objective: sol.objective,
            warm,
        };
        self.previous = Some(sol);
        Ok(StepReport {
            seconds: start.elapsed().as_secs_f64(),
            ..report
        })
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

    /// The latest solution (the plan over the horizon), if a step was taken.
    pub fn solution(&self) -> Option<&Solution> {
        self.previous.as_ref()
    }

    /// The sampling period `T / N` (one stage of the grid): the plant must advance by it
    /// between steps, which is what the shift assumes.
    pub fn sampling_period(&self) -> f64 {
        self.sampling_period
    }

    /// The compiled problem, e.g. to change other parameters (a reference) between steps.
    pub fn compiled_mut(&mut self) -> &mut Compiled {
        &mut self.compiled
    }

    /// Forgets the previous solution: the next step solves from the problem's initial
    /// point (e.g. after a large disturbance).
    pub fn reset(&mut self) {
        self.previous = None;
    }
}
