//! Transcription of an [`Ocp`] into a [`Problem`]: direct multiple shooting or direct
//! collocation on a uniform grid of `N` intervals with piecewise-constant controls.
use super::{ButcherTableau, Collocation, CollocationPoints, Ocp, OcpError, Trajectory};
use crate::compiled::Compiled;
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
}

/// An [`Ocp`] written as a [`Problem`], with what is needed to read solutions back.
///
/// The problem's variables are `X` (`nx × (N+1)`, the grid states), `U` (`nu × N`), `T`
/// for a free final time and `Xc` (`nx × N·d`) for collocation; its parameters are the
/// OCP's. [`Transcription::problem_mut`] allows adding anything else before compiling.
pub struct Transcription {
    problem: Problem,
    intervals: usize,
    states: Matrix,
    controls: Matrix,
    collocation_states: Option<Matrix>,
    final_time: Expr,
    tau: Vec<f64>,
    state_names: Vec<String>,
    control_names: Vec<String>,
    initial_state_parameter: Option<String>,
    /// The constraint groups written once per stage, in raw rows (before simple-bound
    /// detection), for [`Transcription::shift_plan`].
    staged_rows: Vec<StagedRows>,
}

/// A constraint group written once per stage: `stages` consecutive runs of `per_stage`
/// raw rows (rows as added, before simple-bound detection) from `start`.
#[derive(Clone, Debug)]
pub(crate) struct StagedRows {
    pub(crate) name: String,
    pub(crate) start: usize,
    pub(crate) stages: usize,
    pub(crate) per_stage: usize,
}

/// Counts the raw rows added to the problem and records the per-stage groups.
#[derive(Default)]
struct RowLog {
    count: usize,
    staged: Vec<StagedRows>,
}

impl RowLog {
    /// Adds `c` as the group `name`; `stages`: the number of stages it repeats over.
    fn add(
        &mut self,
        pb: &mut Problem,
        name: &str,
        c: Constraint,
        stages: Option<usize>,
    ) -> Result<(), OcpError> {
        let len = c.len();
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

const RESERVED: [&str; 4] = ["X", "U", "T", "Xc"];

impl Ocp {
    /// Writes the problem on `intervals` (N ≥ 1) uniform intervals with `method`.
    pub fn transcribe(&self, method: &Method, intervals: usize) -> Result<Transcription, OcpError> {
        let dynamics = self.dynamics.as_ref().ok_or(OcpError::NoDynamics)?;
        let (nx, nu, n) = (self.nx(), self.nu(), intervals);
        if n == 0 || nx == 0 {
            return Err(OcpError::Invalid {
                what: "transcription".into(),
                why: format!("needs at least one interval and one state (N = {n}, nx = {nx})"),
            });
        }
        if let Method::MultipleShooting { steps: 0, .. } = method {
            return Err(OcpError::Invalid {
                what: "multiple shooting".into(),
                why: "steps per interval must be ≥ 1".into(),
            });
        }
        let mut pb = Problem::new();
        let x = pb.variable_matrix("X", nx, n + 1)?;
        let u = if nu > 0 {
            pb.variable_matrix("U", nu, n)?
        } else {
            Matrix::zeros(0, n)
        };
        let t_f = match self.horizon {
            super::Horizon::Fixed(t) => Expr::constant(t),
            super::Horizon::Free {
                lower,
                upper,
                guess,
            } => {
                let t = pb.scalar_variable("T")?;
                pb.set_bounds(&[t], lower, upper)?;
                pb.set_initial(&[t], &[guess])?;
                t
            }
        };
        let mut p_all = Vec::new();
        let mut x0_parameter = None;
        for (name, values) in &self.parameters {
            if RESERVED.contains(&name.as_str()) {
                return Err(OcpError::Invalid {
                    what: format!("parameter '{name}'"),
                    why: format!("the names {RESERVED:?} are used by the transcription"),
                });
            }
            let p = pb.parameter(name, values.len())?;
            pb.set_value(&p, values)?;
            if self.initial_state_parameter.as_deref() == Some(name.as_str()) {
                x0_parameter = Some(p.clone());
            }
            p_all.extend_from_slice(&p);
        }
        let p = Matrix::from_vec(p_all);
        let col = |m: &Matrix, k: usize| m.column(k).map_err(OcpError::from);
        // The closures are checked once on the first stage (their shapes do not change).
        let f0 = dynamics.eval(&col(&x, 0)?, &col(&u, 0)?, &p)?;
        if f0.len() != nx {
            return Err(OcpError::Size {
                what: "dynamics output".into(),
                expected: nx,
                got: f0.len(),
            });
        }
        for i in 0..nx {
            let (lo, hi) = (self.state_bounds.0[i], self.state_bounds.1[i]);
            pb.set_bounds(&x.row(i)?, lo, hi)?;
        }
        for j in 0..nu {
            let (lo, hi) = (self.control_bounds.0[j], self.control_bounds.1[j]);
            pb.set_bounds(&u.row(j)?, lo, hi)?;
        }
        let mut log = RowLog::default();
        if let Some(x0) = &self.initial_state {
            let c = col(&x, 0)?.eq(&Matrix::from_f64(x0));
            log.add(&mut pb, "initial state", c, None)?;
        }
        if let Some(p0) = &x0_parameter {
            log.add(&mut pb, "initial state", col(&x, 0)?.eq(p0), None)?;
        }
        if let Some(xf) = &self.final_state {
            let c = col(&x, n)?.eq(&Matrix::from_f64(xf));
            log.add(&mut pb, "final state", c, None)?;
        }
        let h = t_f / n as f64;
        let stage = Stage {
            ocp: self,
            x: &x,
            u: &u,
            p: &p,
            h,
        };
        let (mut cost, xc, tau) = match method {
            Method::MultipleShooting {
                tableau,
                steps,
                step_calls,
            } => (
                stage.shooting(&mut pb, &mut log, tableau, *steps, *step_calls)?,
                None,
                vec![0.0],
            ),
            Method::Collocation(c) => {
                let (cost, xc) = stage.collocation(&mut pb, &mut log, c)?;
                (cost, Some(xc), c.tau.clone())
            }
        };
        for (name, c) in &self.path {
            let rows = (0..=n)
                .map(|k| Ok(c(&col(&x, k)?, &col(&u, k.min(n - 1))?, &p)))
                .collect::<Result<Vec<_>, OcpError>>()?;
            log.add(&mut pb, name, Constraint::all(rows), Some(n + 1))?;
        }
        for (name, b) in &self.boundary {
            log.add(&mut pb, name, b(&col(&x, 0)?, &col(&x, n)?, &p, t_f), None)?;
        }
        if let Some(phi) = &self.terminal_cost {
            cost += phi(&col(&x, n)?, &p, t_f);
        }
        pb.minimize(cost);
        let tr = Transcription {
            problem: pb,
            intervals: n,
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
        self.apply_guess(tr)
    }

    fn apply_guess(&self, mut tr: Transcription) -> Result<Transcription, OcpError> {
        let n = tr.intervals;
        let t_f = self.horizon.guess();
        let times = |k: usize, tau: f64| (k as f64 + tau) * t_f / n as f64;
        if let Some(g) = &self.state_guess {
            let mut set = |m: &Matrix, col: usize, t: f64| -> Result<(), OcpError> {
                let v = g(t, t_f);
                tr.problem
                    .set_initial(&m.column(col)?, &v)
                    .map_err(|e| match e {
                        crate::BuildError::Size { expected, got, .. } => OcpError::Size {
                            what: format!("state guess at t = {t}"),
                            expected,
                            got,
                        },
                        e => e.into(),
                    })
            };
            for k in 0..=n {
                set(&tr.states, k, times(k, 0.0))?;
            }
            if let Some(xc) = &tr.collocation_states {
                let d = tr.tau.len() - 1;
                for k in 0..n {
                    for j in 1..=d {
                        set(xc, k * d + j - 1, times(k, tr.tau[j]))?;
                    }
                }
            }
        }
        if let (Some(g), true) = (&self.control_guess, self.nu() > 0) {
            for k in 0..n {
                let t = times(k, 0.0);
                let v = g(t, t_f);
                if v.len() != self.nu() {
                    return Err(OcpError::Size {
                        what: format!("control guess at t = {t}"),
                        expected: self.nu(),
                        got: v.len(),
                    });
                }
                tr.problem.set_initial(&tr.controls.column(k)?, &v)?;
            }
        }
        Ok(tr)
    }
}

/// What every interval's transcription needs.
struct Stage<'a> {
    ocp: &'a Ocp,
    x: &'a Matrix,
    u: &'a Matrix,
    p: &'a Matrix,
    h: Expr,
}

impl Stage<'_> {
    fn dynamics(&self) -> &super::Dynamics {
        self.ocp.dynamics.as_ref().expect("checked by transcribe")
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
        let n = self.u.ncols();
        let step = if step_calls {
            Some(self.step_function(tableau, steps)?)
        } else {
            None
        };
        let mut cost = Expr::zero();
        let mut gaps = Vec::with_capacity(n);
        for k in 0..n {
            let (xk, uk) = (self.x.column(k)?, self.u.column(k)?);
            let (x_end, q) = match &step {
                Some(f) => {
                    let mut out = f.apply(&[&xk, &uk, self.p, &[self.h]])?.into_iter();
                    let x_end = Matrix::from_vec(out.next().unwrap_or_default());
                    (x_end, out.next().map(|q| q[0]))
                }
                None => self.integrate(tableau, steps, &xk, &uk, self.p, self.h)?,
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
    /// Lagrange cost's quadrature state (only with a stage cost).
    fn step_function(
        &self,
        tableau: &ButcherTableau,
        steps: usize,
    ) -> Result<symx::Function, OcpError> {
        let x = Matrix::sym_vec("x", self.ocp.nx());
        let u = Matrix::sym_vec("u", self.ocp.nu());
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
    /// with a stage cost, its integral (a quadrature state started at 0).
    fn integrate(
        &self,
        tableau: &ButcherTableau,
        steps: usize,
        x: &Matrix,
        u: &Matrix,
        p: &Matrix,
        h: Expr,
    ) -> Result<(Matrix, Option<Expr>), OcpError> {
        let nx = self.ocp.nx();
        // The tableau takes an infallible right-hand side: a failure is kept and returned.
        let failure = std::cell::RefCell::new(None);
        let rhs = |z: &Matrix| -> Matrix {
            let xs = Matrix::from_vec(z[..nx].to_vec());
            let mut dz: Vec<Expr> = match self.dynamics().eval(&xs, u, p) {
                Ok(f) => f.to_vec(),
                Err(e) => {
                    failure.borrow_mut().get_or_insert(e);
                    vec![Expr::zero(); nx]
                }
            };
            if let Some(l) = &self.ocp.stage_cost {
                dz.push(l(&xs, u, p));
            }
            Matrix::from_vec(dz)
        };
        let mut z0: Vec<Expr> = x.to_vec();
        if self.ocp.stage_cost.is_some() {
            z0.push(Expr::zero());
        }
        let z_end = tableau.integrate(&rhs, &Matrix::from_vec(z0), h, steps);
        if let Some(e) = failure.into_inner() {
            return Err(e);
        }
        let q = self.ocp.stage_cost.as_ref().map(|_| z_end[nx]);
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
        let (nx, n, d) = (self.ocp.nx(), self.u.ncols(), c.degree());
        let xc = pb.variable_matrix("Xc", nx, n * d)?;
        for i in 0..nx {
            let (lo, hi) = (self.ocp.state_bounds.0[i], self.ocp.state_bounds.1[i]);
            pb.set_bounds(&xc.row(i)?, lo, hi)?;
        }
        let mut cost = Expr::zero();
        let (mut colloc, mut gaps) = (Vec::new(), Vec::new());
        for k in 0..n {
            let uk = self.u.column(k)?;
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
                let fj = self.dynamics().eval(&pts[j - 1], &uk, self.p)?;
                colloc.push((&(self.h * &fj - xp)).eq(0.0));
                if let Some(l) = &self.ocp.stage_cost {
                    cost += c.b[j] * l(&pts[j - 1], &uk, self.p) * self.h;
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

    /// Number of intervals N.
    pub fn intervals(&self) -> usize {
        self.intervals
    }

    /// The grid states `X` (`nx × (N+1)`).
    pub fn states(&self) -> &Matrix {
        &self.states
    }

    /// The controls `U` (`nu × N`).
    pub fn controls(&self) -> &Matrix {
        &self.controls
    }

    /// The final time: the variable `T` or the fixed value as a constant.
    pub fn final_time(&self) -> Expr {
        self.final_time
    }

    /// The name of the parameter that `x(0)` equals, if the OCP declared one
    /// ([`Ocp::set_initial_state_parameter`]).
    pub fn initial_state_parameter(&self) -> Option<&str> {
        self.initial_state_parameter.as_deref()
    }

    /// The collocation states `Xc` (`nx × N·d`, stage `k`'s `d` columns from `k·d`), for
    /// collocation methods.
    pub fn collocation_states(&self) -> Option<&Matrix> {
        self.collocation_states.as_ref()
    }

    pub(crate) fn staged_rows(&self) -> &[StagedRows] {
        &self.staged_rows
    }

    /// Reads a solution of the compiled problem as a trajectory.
    pub fn trajectory(&self, sol: &Solution) -> Result<Trajectory, OcpError> {
        let n_var = self.problem.n_variables();
        if sol.x.len() != n_var {
            return Err(OcpError::Size {
                what: "solution x".into(),
                expected: n_var,
                got: sol.x.len(),
            });
        }
        let values = |m: &Matrix| -> Result<Vec<Vec<f64>>, OcpError> {
            let idx = self.problem.variable_indices(m)?;
            let rows = m.nrows();
            Ok((0..rows)
                .map(|i| (0..m.ncols()).map(|k| sol.x[idx[k * rows + i]]).collect())
                .collect())
        };
        let t_f = match self.final_time.value() {
            Some(t) => t,
            None => sol.x[self.problem.variable_indices(&[self.final_time])?[0]],
        };
        let n = self.intervals;
        let grid = |k: usize, tau: f64| (k as f64 + tau) * t_f / n as f64;
        let collocation = match &self.collocation_states {
            Some(xc) => {
                let d = self.tau.len() - 1;
                Some(super::CollocationStates {
                    time: (0..n * d)
                        .map(|i| grid(i / d, self.tau[i % d + 1]))
                        .collect(),
                    states: values(xc)?,
                })
            }
            None => None,
        };
        let controls = if self.controls.nrows() > 0 {
            values(&self.controls)?
        } else {
            Vec::new()
        };
        let mut time: Vec<f64> = (0..=n).map(|k| grid(k, 0.0)).collect();
        time[n] = t_f; // exactly T, not (N·T)/N
        Ok(Trajectory {
            time,
            state_names: self.state_names.clone(),
            states: values(&self.states)?,
            control_names: self.control_names.clone(),
            control_time: (0..n).map(|k| grid(k, 0.0)).collect(),
            controls,
            final_time: t_f,
            objective: sol.objective,
            status: sol.status,
            collocation,
        })
    }
}
