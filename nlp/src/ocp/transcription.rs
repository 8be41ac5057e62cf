//! Transcription of an [`Ocp`] into a [`Problem`]: direct multiple shooting, direct
//! collocation, trapezoidal or Hermite–Simpson collocation on a uniform or user-given
//! [`Grid`] of `N` intervals, with controls piecewise constant or linear between nodes.
use super::phase::{Phase, StagedRows};
use super::{
    ButcherTableau, Collocation, CollocationPoints, ControlInterpolation, Grid, Horizon, Ocp,
    OcpError, Trajectory,
};
use crate::compiled::{CompileOptions, Compiled};
use crate::constraint::{Constraint, Relation};
use crate::problem::Problem;
use crate::solution::Solution;
use symx::{Expr, Matrix};

/// How the dynamics become constraints.
#[derive(Clone, Debug, PartialEq)]
pub enum Method {
    /// Direct multiple shooting: the state at every grid point is a variable and one
    /// explicit Runge–Kutta integration of `steps` steps over each interval must end at the
    /// next grid state (Bock & Plitt 1984). The Lagrange cost is integrated with the same
    /// steps as a quadrature state.
    MultipleShooting {
        /// The Runge–Kutta method.
        tableau: ButcherTableau,
        /// Steps per interval (M ≥ 1).
        steps: usize,
        /// Compile one interval's integration (all `steps` steps and the cost quadrature)
        /// once as a function of `(x, u, p, h)` and call it at every interval (one call node
        /// each) instead of writing its expressions N times. Same problem, same iterates
        /// (to rounding); a far smaller graph and tape for large N.
        step_calls: bool,
    },
    /// Direct collocation: the state is a polynomial on each interval, its values at the
    /// collocation points are variables (named `Xc`), and the dynamics hold at those
    /// points; the Lagrange cost uses the collocation quadrature.
    Collocation(Collocation),
    /// Trapezoidal collocation (Betts 2010, §4.5; COPS 3.0's Goddard rocket): on interval
    /// `k`, `x_{k+1} = x_k + h_k/2 (f(x_k, u) + f(x_{k+1}, u))`; the Lagrange cost by the
    /// trapezoidal rule. Second order; no variables beyond `X` and `U`.
    Trapezoidal,
    /// Hermite–Simpson collocation (Betts 2010, §4.5; Kelly 2017, SIAM Rev. 59): the state
    /// is a Hermite cubic on each interval, its midpoint
    /// `x_m = (x_k + x_{k+1})/2 + h_k/8 (f_k − f_{k+1})`, and Simpson's rule
    /// `x_{k+1} = x_k + h_k/6 (f_k + 4 f_m + f_{k+1})` with `f_m = f(x_m, u_m)`; the Lagrange
    /// cost by Simpson's rule. Fourth order in the state. The midpoint control `u_m` is the
    /// interval's control, or the mean of the node controls when they are linear.
    HermiteSimpson {
        /// Separated form: the midpoint states are variables (`Xm`, `nx × N`, with the state
        /// bounds) tied to the cubic by the constraint group `midpoint`; sparser and larger.
        /// Compressed form (`false`): `x_m` is an expression of `X`, fewer variables.
        separated: bool,
    },
}

impl Method {
    /// Multiple shooting with `steps` steps of `tableau` per interval.
    pub fn multiple_shooting(tableau: ButcherTableau, steps: usize) -> Method {
        Method::MultipleShooting {
            tableau,
            steps,
            step_calls: false,
        }
    }

    /// Multiple shooting whose interval integration is compiled once as a function of
    /// `(x, u, p, h)` and called once per interval (see
    /// [`Method::MultipleShooting::step_calls`]).
    pub fn multiple_shooting_with_calls(tableau: ButcherTableau, steps: usize) -> Method {
        Method::MultipleShooting {
            tableau,
            steps,
            step_calls: true,
        }
    }

    /// Direct collocation with `degree` points of the given family.
    pub fn collocation(points: CollocationPoints, degree: usize) -> Result<Method, OcpError> {
        Ok(Method::Collocation(Collocation::new(points, degree)?))
    }

    /// Trapezoidal collocation ([`Method::Trapezoidal`]).
    pub fn trapezoidal() -> Method {
        Method::Trapezoidal
    }

    /// Hermite–Simpson collocation, compressed ([`Method::HermiteSimpson`]).
    pub fn hermite_simpson() -> Method {
        Method::HermiteSimpson { separated: false }
    }

    /// Hermite–Simpson collocation, separated: midpoint states as variables
    /// ([`Method::HermiteSimpson`]).
    pub fn hermite_simpson_separated() -> Method {
        Method::HermiteSimpson { separated: true }
    }
}

/// An [`Ocp`] written as a [`Problem`], with what is needed to read solutions back.
///
/// The problem's variables are `X` (`nx × (N+1)`, the grid states), `U` (`nu × N`, or
/// `nu × (N+1)` for controls at the nodes), `T` for a free final time, `Xc` (`nx × N·d`)
/// for direct collocation and `Xm` (`nx × N`) for separated Hermite–Simpson; its
/// parameters are the OCP's. [`Transcription::problem_mut`] allows adding anything else before compiling.
pub struct Transcription {
    problem: Problem,
    phase: Phase,
}

/// Counts the raw rows added to the problem and records the per-stage groups.
struct RowLog<'a> {
    count: usize,
    staged: Vec<StagedRows>,
    /// Prefix of the group names (the phase's, empty for one phase).
    prefix: &'a str,
}

impl<'a> RowLog<'a> {
    /// A log of a problem that already has `count` raw rows, naming groups with `prefix`.
    fn starting_at(count: usize, prefix: &'a str) -> Self {
        RowLog {
            count,
            staged: Vec::new(),
            prefix,
        }
    }

    /// Adds `c` as the group `name` (after the prefix); `stages`: the number of stages it
    /// repeats over.
    fn add(
        &mut self,
        pb: &mut Problem,
        name: &str,
        c: Constraint,
        stages: Option<usize>,
    ) -> Result<(), OcpError> {
        let len = c.len();
        let name = &format!("{}{name}", self.prefix);
        pb.subject_to_named(name, c)?;
        if let (Some(stages), true) = (stages, len > 0) {
            if len % stages != 0 {
                return Err(OcpError::Invalid {
                    what: format!("constraint '{name}'"),
                    why: format!("{len} rows do not split into {stages} equal stages"),
                });
            }
            self.staged.push(StagedRows {
                name: name.to_string(),
                start: self.count,
                stages,
                per_stage: len / stages,
            });
        }
        self.count += len;
        Ok(())
    }
}

const RESERVED: [&str; 5] = ["X", "U", "T", "Xc", "Xm"];

/// The parameters of a problem being written. The phases of a
/// [`MultiPhaseOcp`](super::MultiPhaseOcp) share a parameter by name: a name declared
/// again must come with the same values.
#[derive(Default)]
pub(crate) struct ParameterTable {
    /// Name, symbols, values and the phase that declared it first.
    entries: Vec<(String, Matrix, Vec<f64>, String)>,
}

impl ParameterTable {
    /// The OCP's parameters stacked as `p` (declared in `pb` unless an earlier phase did)
    /// and the parameter that `x(0)` equals, if any.
    fn declare(
        &mut self,
        pb: &mut Problem,
        ocp: &Ocp,
        phase: &str,
    ) -> Result<(Matrix, Option<Matrix>), OcpError> {
        let (mut p_all, mut x0) = (Vec::new(), None);
        for (name, values) in &ocp.parameters {
            if RESERVED.contains(&name.as_str()) {
                return Err(OcpError::Invalid {
                    what: format!("parameter '{name}'"),
                    why: format!("the names {RESERVED:?} are used by the transcription"),
                });
            }
            let p = match self.entries.iter().find(|e| &e.0 == name) {
                Some((_, p, old, _)) if old == values => p.clone(),
                Some((_, _, old, first)) => {
                    return Err(OcpError::Invalid {
                        what: format!("parameter '{name}' of phase '{phase}'"),
                        why: format!("phase '{first}' declared it with the values {old:?}, this phase with {values:?}"),
                    })
                }
                None => {
                    let p = pb.parameter(name, values.len())?;
                    pb.set_value(&p, values)?;
                    let entry = (name.clone(), p.clone(), values.clone(), phase.to_string());
                    self.entries.push(entry);
                    p
                }
            };
            if ocp.initial_state_parameter.as_deref() == Some(name.as_str()) {
                x0 = Some(p.clone());
            }
            p_all.extend_from_slice(&p);
        }
        Ok((Matrix::from_vec(p_all), x0))
    }

    /// Every parameter, stacked in the order of first declaration.
    pub(crate) fn stacked(&self) -> Matrix {
        Matrix::from_vec(self.entries.iter().flat_map(|e| e.1.to_vec()).collect())
    }
}

impl Ocp {
    /// Writes the problem on `intervals` (N ≥ 1) uniform intervals with `method`
    /// ([`Ocp::transcribe_on`] with [`Grid::uniform`]).
    pub fn transcribe(&self, method: &Method, intervals: usize) -> Result<Transcription, OcpError> {
        if intervals == 0 || self.nx() == 0 {
            return Err(OcpError::Invalid {
                what: "transcription".into(),
                why: format!(
                    "needs at least one interval and one state (N = {intervals}, nx = {})",
                    self.nx()
                ),
            });
        }
        self.transcribe_on(method, &Grid::uniform(intervals)?)
    }

    /// Writes the problem with `method` on `grid` (uniform or user-given, see [`Grid`]).
    /// Errors: no dynamics, no horizon ([`OcpError::NoHorizon`]), closures returning the
    /// wrong sizes, and what the [`Problem`] builder reports.
    pub fn transcribe_on(&self, method: &Method, grid: &Grid) -> Result<Transcription, OcpError> {
        let mut problem = Problem::new();
        let mut parameters = ParameterTable::default();
        let (phase, cost) = self.write_phase(&mut problem, "", method, grid, &mut parameters)?;
        problem.minimize(cost);
        Ok(Transcription { problem, phase })
    }

    /// Writes this OCP as one phase of `pb`: its variables and constraint groups named with
    /// `prefix` (`"{prefix}X"`, `"{prefix}continuity"`...), its parameters through
    /// `parameters`, its guess. Returns the phase's layout and its cost (Lagrange and Mayer
    /// terms), which the caller minimises (summed over the phases).
    pub(crate) fn write_phase(
        &self,
        pb: &mut Problem,
        prefix: &str,
        method: &Method,
        grid: &Grid,
        parameters: &mut ParameterTable,
    ) -> Result<(Phase, Expr), OcpError> {
        let horizon = self.check_transcribable(method)?;
        let n = grid.intervals();
        let (x, u, t_f) = self.declare_variables(pb, prefix, horizon, n)?;
        let (p, x0_parameter) = parameters.declare(pb, self, prefix.trim_end_matches('.'))?;
        self.check_dynamics_output(&x, &u, &p)?;
        let mut log = RowLog::starting_at(pb.n_raw_rows(), prefix);
        self.write_end_states(pb, &mut log, &x, x0_parameter.as_ref())?;
        // Interval lengths: T/N on a uniform grid (one expression), (s_{k+1} − s_k)·T otherwise.
        let s = grid.fractions();
        let h: Vec<Expr> = (0..n)
            .map(|k| match grid.is_uniform() {
                true => t_f / n as f64,
                false => t_f * (s[k + 1] - s[k]),
            })
            .collect();
        let linear = self.control_interpolation == ControlInterpolation::PiecewiseLinear;
        let stage = Stage {
            ocp: self,
            x: &x,
            u: &u,
            p: &p,
            h: &h,
            linear,
            prefix,
        };
        let (mut cost, xc, tau) = stage.write(pb, &mut log, method)?;
        if let Some(phi) = self.write_path_and_boundary(pb, &mut log, &stage, t_f)? {
            cost += phi;
        }
        let phase = Phase {
            intervals: n,
            grid: grid.clone(),
            control_interpolation: self.control_interpolation,
            states: x,
            controls: u,
            collocation_states: xc,
            final_time: t_f,
            tau,
            state_names: self.states.clone(),
            control_names: self.controls.clone(),
            initial_state_parameter: self.initial_state_parameter.clone(),
            staged_rows: log.staged,
        };
        self.apply_guess(pb, &phase, horizon.guess())?;
        Ok((phase, cost))
    }

    /// The horizon, after checking that the problem can be transcribed with `method`.
    fn check_transcribable(&self, method: &Method) -> Result<Horizon, OcpError> {
        self.dynamics.as_ref().ok_or(OcpError::NoDynamics)?;
        let horizon = self.horizon.ok_or(OcpError::NoHorizon)?;
        if self.nx() == 0 {
            return Err(OcpError::Invalid {
                what: "transcription".into(),
                why: "needs at least one state".into(),
            });
        }
        if let Method::MultipleShooting { steps: 0, .. } = method {
            return Err(OcpError::Invalid {
                what: "multiple shooting".into(),
                why: "steps per interval must be ≥ 1".into(),
            });
        }
        Ok(horizon)
    }

    /// Declares `X`, `U` (with their bounds) and, for a free horizon, `T`, on `n` intervals.
    fn declare_variables(
        &self,
        pb: &mut Problem,
        prefix: &str,
        horizon: Horizon,
        n: usize,
    ) -> Result<(Matrix, Matrix, Expr), OcpError> {
        let (nx, nu) = (self.nx(), self.nu());
        let linear = self.control_interpolation == ControlInterpolation::PiecewiseLinear;
        let n_u = if linear { n + 1 } else { n };
        let x = pb.variable_matrix(&format!("{prefix}X"), nx, n + 1)?;
        let u = if nu > 0 {
            pb.variable_matrix(&format!("{prefix}U"), nu, n_u)?
        } else {
            Matrix::zeros(0, n_u)
        };
        let t_f = match horizon {
            Horizon::Fixed(t) => Expr::constant(t),
            Horizon::Free {
                lower,
                upper,
                guess,
            } => {
                let t = pb.scalar_variable(&format!("{prefix}T"))?;
                pb.set_bounds(&[t], lower, upper)?;
                pb.set_initial(&[t], &[guess])?;
                t
            }
        };
        for i in 0..nx {
            let (lo, hi) = (self.state_bounds.0[i], self.state_bounds.1[i]);
            pb.set_bounds(&x.row(i)?, lo, hi)?;
        }
        for j in 0..nu {
            let (lo, hi) = (self.control_bounds.0[j], self.control_bounds.1[j]);
            pb.set_bounds(&u.row(j)?, lo, hi)?;
        }
        Ok((x, u, t_f))
    }

    /// Checks the dynamics' output length once, on the first stage (shapes do not change).
    fn check_dynamics_output(&self, x: &Matrix, u: &Matrix, p: &Matrix) -> Result<(), OcpError> {
        let dynamics = self.dynamics.as_ref().ok_or(OcpError::NoDynamics)?;
        let f0 = dynamics.eval(&x.column(0)?, &u.column(0)?, p)?;
        if f0.len() != self.nx() {
            return Err(OcpError::Size {
                what: "dynamics output".into(),
                expected: self.nx(),
                got: f0.len(),
            });
        }
        Ok(())
    }

    /// The rows fixing `x(0)` (to constants or to a parameter) and `x(T)`.
    fn write_end_states(
        &self,
        pb: &mut Problem,
        log: &mut RowLog,
        x: &Matrix,
        x0_parameter: Option<&Matrix>,
    ) -> Result<(), OcpError> {
        if let Some(x0) = &self.initial_state {
            let c = x.column(0)?.eq(&Matrix::from_f64(x0));
            log.add(pb, "initial state", c, None)?;
        }
        if let Some(p0) = x0_parameter {
            log.add(pb, "initial state", x.column(0)?.eq(p0), None)?;
        }
        if let Some(xf) = &self.final_state {
            let c = x.column(x.ncols() - 1)?.eq(&Matrix::from_f64(xf));
            log.add(pb, "final state", c, None)?;
        }
        Ok(())
    }

    /// The path constraints at every node and the boundary constraints; returns the Mayer
    /// term, if any.
    fn write_path_and_boundary(
        &self,
        pb: &mut Problem,
        log: &mut RowLog,
        stage: &Stage,
        t_f: Expr,
    ) -> Result<Option<Expr>, OcpError> {
        let (x, p) = (stage.x, stage.p);
        let n = x.ncols() - 1;
        for (name, c) in &self.path {
            let rows = (0..=n)
                .map(|k| Ok(c(&x.column(k)?, &stage.node_control(k)?, p)))
                .collect::<Result<Vec<_>, OcpError>>()?;
            log.add(pb, name, Constraint::all(rows), Some(n + 1))?;
        }
        for (name, b) in &self.boundary {
            log.add(pb, name, b(&x.column(0)?, &x.column(n)?, p, t_f), None)?;
        }
        Ok(match &self.terminal_cost {
            Some(phi) => Some(phi(&x.column(n)?, p, t_f)),
            None => None,
        })
    }

    /// Sets the initial guess of the phase's states and controls from the guess closures,
    /// `t_f` the horizon's guess.
    fn apply_guess(&self, pb: &mut Problem, phase: &Phase, t_f: f64) -> Result<(), OcpError> {
        let n = phase.intervals;
        let grid = &phase.grid;
        if let Some(g) = &self.state_guess {
            let mut set = |m: &Matrix, col: usize, t: f64| -> Result<(), OcpError> {
                let v = g(t, t_f);
                pb.set_initial(&m.column(col)?, &v).map_err(|e| match e {
                    crate::BuildError::Size { expected, got, .. } => OcpError::Size {
                        what: format!("state guess at t = {t}"),
                        expected,
                        got,
                    },
                    e => e.into(),
                })
            };
            for k in 0..=n {
                set(&phase.states, k, grid.time(k, t_f))?;
            }
            if let Some(xc) = &phase.collocation_states {
                let d = phase.tau.len() - 1;
                for k in 0..n {
                    for j in 1..=d {
                        set(xc, k * d + j - 1, grid.time_in(k, phase.tau[j], t_f))?;
                    }
                }
            }
        }
        if let (Some(g), true) = (&self.control_guess, self.nu() > 0) {
            for k in 0..phase.controls.ncols() {
                let t = grid.time(k, t_f);
                let v = g(t, t_f);
                if v.len() != self.nu() {
                    return Err(OcpError::Size {
                        what: format!("control guess at t = {t}"),
                        expected: self.nu(),
                        got: v.len(),
                    });
                }
                pb.set_initial(&phase.controls.column(k)?, &v)?;
            }
        }
        Ok(())
    }
}

/// What every interval's transcription needs.
struct Stage<'a> {
    ocp: &'a Ocp,
    x: &'a Matrix,
    u: &'a Matrix,
    p: &'a Matrix,
    /// Interval lengths `h_k`.
    h: &'a [Expr],
    /// Controls at the nodes, linear in between (else one per interval).
    linear: bool,
    /// Prefix of the variable names (the phase's, empty for one phase).
    prefix: &'a str,
}

/// `ẋ` and the Lagrange integrand at one point.
type PointValues = (Matrix, Option<Expr>);

impl Stage<'_> {
    fn dynamics(&self) -> &super::Dynamics {
        self.ocp.dynamics.as_ref().expect("checked by transcribe")
    }

    /// The rows of `method` tying the states to the dynamics; returns the Lagrange cost,
    /// the collocation or midpoint states and their fractions `τ` of an interval.
    fn write(
        &self,
        pb: &mut Problem,
        log: &mut RowLog,
        method: &Method,
    ) -> Result<(Expr, Option<Matrix>, Vec<f64>), OcpError> {
        Ok(match method {
            Method::MultipleShooting {
                tableau,
                steps,
                step_calls,
            } => (
                self.shooting(pb, log, tableau, *steps, *step_calls)?,
                None,
                vec![0.0],
            ),
            Method::Collocation(c) => {
                let (cost, xc) = self.collocation(pb, log, c)?;
                (cost, Some(xc), c.tau.clone())
            }
            Method::Trapezoidal => (self.trapezoidal(pb, log)?, None, vec![0.0]),
            Method::HermiteSimpson { separated } => {
                let (cost, xm) = self.hermite_simpson(pb, log, *separated)?;
                let tau = match xm {
                    Some(_) => vec![0.0, 0.5],
                    None => vec![0.0],
                };
                (cost, xm, tau)
            }
        })
    }

    /// The control at the fraction `tau ∈ [0, 1]` of interval `k`.
    fn control(&self, k: usize, tau: f64) -> Result<Matrix, OcpError> {
        if !self.linear || tau == 0.0 {
            return Ok(self.u.column(k)?);
        }
        if tau == 1.0 {
            return Ok(self.u.column(k + 1)?);
        }
        let (a, b) = (self.u.column(k)?, self.u.column(k + 1)?);
        Ok(Matrix::from_vec(
            a.iter()
                .zip(b.iter())
                .map(|(&a, &b)| (1.0 - tau) * a + tau * b)
                .collect(),
        ))
    }

    /// The control at node `k` (for piecewise-constant controls, the last interval's at `t_N`).
    fn node_control(&self, k: usize) -> Result<Matrix, OcpError> {
        let last = self.u.ncols() - 1;
        Ok(self.u.column(k.min(last))?)
    }

    /// `ẋ` and the Lagrange integrand at `(x, u)`.
    fn point(&self, x: &Matrix, u: &Matrix) -> Result<PointValues, OcpError> {
        let f = self.dynamics().eval(x, u, self.p)?;
        let l = self.ocp.stage_cost.as_ref().map(|l| l(x, u, self.p));
        Ok((f, l))
    }

    /// The values at both ends of every interval: with controls at the nodes each node is
    /// evaluated once and shared by its two intervals.
    fn interval_ends(&self) -> Result<Vec<(PointValues, PointValues)>, OcpError> {
        let n = self.h.len();
        if self.linear {
            let nodes = (0..=n)
                .map(|k| self.point(&self.x.column(k)?, &self.u.column(k)?))
                .collect::<Result<Vec<_>, OcpError>>()?;
            return Ok((0..n)
                .map(|k| (nodes[k].clone(), nodes[k + 1].clone()))
                .collect());
        }
        (0..n)
            .map(|k| {
                let uk = self.u.column(k)?;
                Ok((
                    self.point(&self.x.column(k)?, &uk)?,
                    self.point(&self.x.column(k + 1)?, &uk)?,
                ))
            })
            .collect()
    }

    /// Trapezoidal collocation: `x_{k+1} = x_k + h_k/2 (f_k + f_{k+1})` (group
    /// `continuity`), the cost by the trapezoidal rule.
    fn trapezoidal(&self, pb: &mut Problem, log: &mut RowLog) -> Result<Expr, OcpError> {
        let mut cost = Expr::zero();
        let mut defects = Vec::with_capacity(self.h.len());
        for (k, ((fa, la), (fb, lb))) in self.interval_ends()?.into_iter().enumerate() {
            let h = self.h[k];
            let (xa, xb) = (self.x.column(k)?, self.x.column(k + 1)?);
            let d: Vec<Expr> = (0..xa.len())
                .map(|i| xb[i] - xa[i] - 0.5 * h * (fa[i] + fb[i]))
                .collect();
            defects.push(Matrix::from_vec(d).eq(0.0));
            if let (Some(la), Some(lb)) = (la, lb) {
                cost += 0.5 * h * (la + lb);
            }
        }
        log.add(
            pb,
            "continuity",
            Constraint::all(defects),
            Some(self.h.len()),
        )?;
        Ok(cost)
    }

    /// Hermite–Simpson collocation: the Hermite cubic's midpoint
    /// `x_m = (x_k + x_{k+1})/2 + h_k/8 (f_k − f_{k+1})` and Simpson's rule
    /// `x_{k+1} = x_k + h_k/6 (f_k + 4 f_m + f_{k+1})` (group `continuity`); the cost by
    /// Simpson's rule. Separated: `x_m` is a variable (`Xm`, `nx × N`) tied to the cubic by
    /// the group `midpoint`; compressed: `x_m` is the expression. Returns the cost and `Xm`.
    fn hermite_simpson(
        &self,
        pb: &mut Problem,
        log: &mut RowLog,
        separated: bool,
    ) -> Result<(Expr, Option<Matrix>), OcpError> {
        let (nx, n) = (self.ocp.nx(), self.h.len());
        let xm_var = if separated {
            let xm = pb.variable_matrix(&format!("{}Xm", self.prefix), nx, n)?;
            for i in 0..nx {
                let (lo, hi) = (self.ocp.state_bounds.0[i], self.ocp.state_bounds.1[i]);
                pb.set_bounds(&xm.row(i)?, lo, hi)?;
            }
            Some(xm)
        } else {
            None
        };
        let mut cost = Expr::zero();
        let (mut midpoints, mut defects) = (Vec::new(), Vec::with_capacity(n));
        for (k, ((fa, la), (fb, lb))) in self.interval_ends()?.into_iter().enumerate() {
            let h = self.h[k];
            let (xa, xb) = (self.x.column(k)?, self.x.column(k + 1)?);
            let cubic: Vec<Expr> = (0..nx)
                .map(|i| 0.5 * (xa[i] + xb[i]) + h / 8.0 * (fa[i] - fb[i]))
                .collect();
            let xm = match &xm_var {
                Some(v) => {
                    let xm = v.column(k)?;
                    let gap: Vec<Expr> = (0..nx).map(|i| xm[i] - cubic[i]).collect();
                    midpoints.push(Matrix::from_vec(gap).eq(0.0));
                    xm
                }
                None => Matrix::from_vec(cubic),
            };
            let (fm, lm) = self.point(&xm, &self.control(k, 0.5)?)?;
            let d: Vec<Expr> = (0..nx)
                .map(|i| xb[i] - xa[i] - h / 6.0 * (fa[i] + 4.0 * fm[i] + fb[i]))
                .collect();
            defects.push(Matrix::from_vec(d).eq(0.0));
            if let (Some(la), Some(lm), Some(lb)) = (la, lm, lb) {
                cost += h / 6.0 * (la + 4.0 * lm + lb);
            }
        }
        if separated {
            log.add(pb, "midpoint", Constraint::all(midpoints), Some(n))?;
        }
        log.add(pb, "continuity", Constraint::all(defects), Some(n))?;
        Ok((cost, xm_var))
    }

    /// Continuity constraints of multiple shooting; returns the integrated Lagrange cost.
    fn shooting(
        &self,
        pb: &mut Problem,
        log: &mut RowLog,
        tableau: &ButcherTableau,
        steps: usize,
        step_calls: bool,
    ) -> Result<Expr, OcpError> {
        let n = self.h.len();
        let step = if step_calls {
            Some(self.step_function(tableau, steps)?)
        } else {
            None
        };
        let mut cost = Expr::zero();
        let mut gaps = Vec::with_capacity(n);
        for k in 0..n {
            let xk = self.x.column(k)?;
            // The interval's control: U_k, or (U_k, U_{k+1}) stacked for linear controls.
            let mut uk = self.u.column(k)?.to_vec();
            if self.linear {
                uk.extend(self.u.column(k + 1)?.iter());
            }
            let uk = Matrix::from_vec(uk);
            let (x_end, q) = match &step {
                Some(f) => {
                    let mut out = f.apply(&[&xk, &uk, self.p, &[self.h[k]]])?.into_iter();
                    let x_end = Matrix::from_vec(out.next().unwrap_or_default());
                    (x_end, out.next().map(|q| q[0]))
                }
                None => self.integrate(tableau, steps, &xk, &uk, self.p, self.h[k])?,
            };
            if let Some(q) = q {
                cost += q;
            }
            gaps.push(self.x.column(k + 1)?.eq(&x_end));
        }
        log.add(pb, "continuity", Constraint::all(gaps), Some(n))?;
        Ok(cost)
    }

    /// One interval's integration compiled as `F(x, u, p, h) = (x(h), q(h))`, `q` the
    /// Lagrange cost's quadrature state (only with a stage cost); for linear controls `u`
    /// stacks the controls at both ends.
    fn step_function(
        &self,
        tableau: &ButcherTableau,
        steps: usize,
    ) -> Result<symx::Function, OcpError> {
        let x = Matrix::sym_vec("x", self.ocp.nx());
        let nu = self.ocp.nu() * if self.linear { 2 } else { 1 };
        let u = Matrix::sym_vec("u", nu);
        let p = Matrix::sym_vec("p", self.ocp.np());
        let h = Expr::sym("h");
        let (x_end, q) = self.integrate(tableau, steps, &x, &u, &p, h)?;
        let q: Vec<Expr> = q.into_iter().collect();
        let mut outputs: Vec<(&str, &[Expr])> = vec![("xf", &x_end)];
        if !q.is_empty() {
            outputs.push(("qf", &q));
        }
        let inputs: [(&str, &[Expr]); 4] = [("x", &x), ("u", &u), ("p", &p), ("h", &[h])];
        let name = format!("{}_interval", tableau.name());
        Ok(symx::Function::named(&name, &inputs, &outputs)?)
    }

    /// `steps` steps of `tableau` over `h` from `x` with control `u`: the end state and,
    /// with a stage cost, its integral (a quadrature state started at 0). For linear
    /// controls `u` stacks the controls at both ends and a clock state `s` (`ṡ = 1/h`,
    /// integrated exactly by any Runge–Kutta method) interpolates between them.
    fn integrate(
        &self,
        tableau: &ButcherTableau,
        steps: usize,
        x: &Matrix,
        u: &Matrix,
        p: &Matrix,
        h: Expr,
    ) -> Result<(Matrix, Option<Expr>), OcpError> {
        let (nx, nu) = (self.ocp.nx(), self.ocp.nu());
        let cost = self.ocp.stage_cost.is_some();
        let clock = nx + usize::from(cost);
        // The tableau takes an infallible right-hand side: a failure is kept and returned.
        let failure = std::cell::RefCell::new(None);
        let rhs = |z: &Matrix| -> Matrix {
            let xs = Matrix::from_vec(z[..nx].to_vec());
            let us = match self.linear {
                false => u.clone(),
                true => Matrix::from_vec(
                    (0..nu)
                        .map(|j| u[j] + z[clock] * (u[nu + j] - u[j]))
                        .collect(),
                ),
            };
            let mut dz: Vec<Expr> = match self.dynamics().eval(&xs, &us, p) {
                Ok(f) => f.to_vec(),
                Err(e) => {
                    failure.borrow_mut().get_or_insert(e);
                    vec![Expr::zero(); nx]
                }
            };
            if let Some(l) = &self.ocp.stage_cost {
                dz.push(l(&xs, &us, p));
            }
            if self.linear {
                dz.push(Expr::constant(1.0) / h);
            }
            Matrix::from_vec(dz)
        };
        let mut z0: Vec<Expr> = x.to_vec();
        if cost {
            z0.push(Expr::zero());
        }
        if self.linear {
            z0.push(Expr::zero());
        }
        let z_end = tableau.integrate(&rhs, &Matrix::from_vec(z0), h, steps);
        if let Some(e) = failure.into_inner() {
            return Err(e);
        }
        let q = cost.then(|| z_end[nx]);
        Ok((Matrix::from_vec(z_end[..nx].to_vec()), q))
    }

    /// Collocation and continuity constraints; returns the Lagrange cost by quadrature
    /// and the collocation-state variables.
    fn collocation(
        &self,
        pb: &mut Problem,
        log: &mut RowLog,
        c: &Collocation,
    ) -> Result<(Expr, Matrix), OcpError> {
        let (nx, n, d) = (self.ocp.nx(), self.h.len(), c.degree());
        let xc = pb.variable_matrix(&format!("{}Xc", self.prefix), nx, n * d)?;
        for i in 0..nx {
            let (lo, hi) = (self.ocp.state_bounds.0[i], self.ocp.state_bounds.1[i]);
            pb.set_bounds(&xc.row(i)?, lo, hi)?;
        }
        let mut cost = Expr::zero();
        let (mut colloc, mut gaps) = (Vec::new(), Vec::new());
        for k in 0..n {
            let h = self.h[k];
            let xk = self.x.column(k)?;
            let pts: Vec<Matrix> = (0..d)
                .map(|j| xc.column(k * d + j))
                .collect::<Result<_, _>>()?;
            for j in 1..=d {
                // State derivative at τ_j from the polynomial through X_k and the Xc.
                let mut xp = c.c[0][j] * &xk;
                for r in 1..=d {
                    xp = xp + c.c[r][j] * &pts[r - 1];
                }
                let uj = self.control(k, c.tau[j])?;
                let fj = self.dynamics().eval(&pts[j - 1], &uj, self.p)?;
                colloc.push((&(h * &fj - xp)).eq(0.0));
                if let Some(l) = &self.ocp.stage_cost {
                    cost += c.b[j] * l(&pts[j - 1], &uj, self.p) * h;
                }
            }
            let mut x_end = c.d[0] * &xk;
            for r in 1..=d {
                x_end = x_end + c.d[r] * &pts[r - 1];
            }
            gaps.push(self.x.column(k + 1)?.eq(&x_end));
        }
        log.add(pb, "collocation", Constraint::all(colloc), Some(n))?;
        log.add(pb, "continuity", Constraint::all(gaps), Some(n))?;
        Ok((cost, xc))
    }
}

impl Transcription {
    /// The transcribed problem.
    pub fn problem(&self) -> &Problem {
        &self.problem
    }

    /// The transcribed problem, to add costs, constraints or guesses before compiling.
    pub fn problem_mut(&mut self) -> &mut Problem {
        &mut self.problem
    }

    /// Compiles the problem (see [`Problem::compile`]).
    pub fn compile(&self) -> Result<Compiled, OcpError> {
        Ok(self.problem.compile()?)
    }

    /// Compiles the problem with `options` (see [`Problem::compile_with`]), e.g. with
    /// native evaluators (`Evaluator::Jit`, CasADi's `jit` option) for a problem solved
    /// many times, as in an MPC loop.
    pub fn compile_with(&self, options: CompileOptions) -> Result<Compiled, OcpError> {
        Ok(self.problem.compile_with(options)?)
    }

    /// Number of intervals N.
    pub fn intervals(&self) -> usize {
        self.phase.intervals
    }

    /// The grid states `X` (`nx × (N+1)`).
    pub fn states(&self) -> &Matrix {
        &self.phase.states
    }

    /// The controls `U` (`nu × N`; `nu × (N+1)` for piecewise-linear controls).
    pub fn controls(&self) -> &Matrix {
        &self.phase.controls
    }

    /// The time grid.
    pub fn grid(&self) -> &Grid {
        &self.phase.grid
    }

    /// How the controls vary between nodes.
    pub fn control_interpolation(&self) -> ControlInterpolation {
        self.phase.control_interpolation
    }

    /// The final time: the variable `T` or the fixed value as a constant.
    pub fn final_time(&self) -> Expr {
        self.phase.final_time
    }

    /// The name of the parameter that `x(0)` equals, if the OCP declared one
    /// ([`Ocp::set_initial_state_parameter`]).
    pub fn initial_state_parameter(&self) -> Option<&str> {
        self.phase.initial_state_parameter.as_deref()
    }

    /// The collocation states `Xc` (`nx × N·d`, stage `k`'s `d` columns from `k·d`), for
    /// direct collocation, or the midpoint states `Xm` (`nx × N`) for separated
    /// Hermite–Simpson.
    pub fn collocation_states(&self) -> Option<&Matrix> {
        self.phase.collocation_states.as_ref()
    }

    pub(crate) fn staged_rows(&self) -> &[StagedRows] {
        &self.phase.staged_rows
    }

    /// Reads a solution of the compiled problem as a trajectory.
    pub fn trajectory(&self, sol: &Solution) -> Result<Trajectory, OcpError> {
        self.phase.trajectory(&self.problem, sol, 0.0)
    }
}
