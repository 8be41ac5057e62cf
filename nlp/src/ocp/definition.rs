//! The continuous-time problem: [`Ocp`] (states, controls, parameters, costs,
//! constraints, bounds, guesses), its [`Dynamics`] and its [`Horizon`].
use super::error::OcpError;
use super::grid::ControlInterpolation;
use super::trajectory::Trajectory;
use crate::constraint::Constraint;
use crate::problem::BuildError;
use symx::{Expr, Matrix};

/// A function of `(x, u, p)` returning a vector (the dynamics, path constraints).
type StageVector = Box<dyn Fn(&Matrix, &Matrix, &Matrix) -> Matrix>;
/// A function of `(x, u, p)` returning a scalar (the Lagrange integrand).
type StageScalar = Box<dyn Fn(&Matrix, &Matrix, &Matrix) -> Expr>;
/// A path constraint `c(x, u, p)` in relation form.
type PathFn = Box<dyn Fn(&Matrix, &Matrix, &Matrix) -> Constraint>;
/// A boundary constraint `c(x(0), x(T), p, T)` in relation form.
type BoundaryFn = Box<dyn Fn(&Matrix, &Matrix, &Matrix, Expr) -> Constraint>;
/// The Mayer term `φ(x(T), p, T)`.
type TerminalFn = Box<dyn Fn(&Matrix, &Matrix, Expr) -> Expr>;
/// A guess as a function of time `t` and of the horizon's guess `T` (so that guesses in
/// normalised time follow a later `set_horizon`).
type GuessFn = Box<dyn Fn(f64, f64) -> Vec<f64>>;

/// The dynamics `ẋ = f(x, u, p)`, given once: a closure of expressions (inlined where it
/// is evaluated) or a compiled function (called where it is evaluated).
pub struct Dynamics {
    f: DynamicsKind,
}

enum DynamicsKind {
    Closure(StageVector),
    Function(Box<symx::Function>),
}

impl Dynamics {
    /// Dynamics from a closure of expressions: `f(x, u, p)` with `x`, `u`, `p` column
    /// vectors of the sizes the [`Ocp`] declares, returning `ẋ` (as many entries as `x`).
    pub fn new(f: impl Fn(&Matrix, &Matrix, &Matrix) -> Matrix + 'static) -> Self {
        Dynamics {
            f: DynamicsKind::Closure(Box::new(f)),
        }
    }

    /// Dynamics from a compiled function with three inputs `(x, u, p)` and one output `ẋ`
    /// as long as `x`; [`Dynamics::eval`] calls it ([`symx::Function::apply`]) instead of
    /// inlining its expressions. The input sizes are checked against the [`Ocp`] when it
    /// is set ([`Ocp::set_dynamics_function`]) and when evaluated.
    pub fn from_function(f: symx::Function) -> Result<Self, OcpError> {
        let n_in = f.input_sizes().len();
        let n_out = f.output_sizes().len();
        if n_in != 3 || n_out != 1 {
            return Err(OcpError::Invalid {
                what: format!("dynamics function '{}'", f.name()),
                why: format!("needs inputs (x, u, p) and one output ẋ, has {n_in} inputs and {n_out} outputs"),
            });
        }
        if f.output_sizes()[0] != f.input_sizes()[0] {
            return Err(OcpError::Size {
                what: format!(
                    "output ẋ of dynamics function '{}' (as long as x)",
                    f.name()
                ),
                expected: f.input_sizes()[0],
                got: f.output_sizes()[0],
            });
        }
        Ok(Dynamics {
            f: DynamicsKind::Function(Box::new(f)),
        })
    }

    /// The compiled function, if the dynamics was given as one.
    pub fn function(&self) -> Option<&symx::Function> {
        match &self.f {
            DynamicsKind::Function(f) => Some(f.as_ref()),
            DynamicsKind::Closure(_) => None,
        }
    }

    /// `ẋ` at `(x, u, p)`; every transcription evaluates the dynamics through this call.
    /// A compiled function is called (one call node); an error names an input of the
    /// wrong length.
    pub fn eval(&self, x: &Matrix, u: &Matrix, p: &Matrix) -> Result<Matrix, OcpError> {
        match &self.f {
            DynamicsKind::Closure(f) => Ok(f(x, u, p)),
            DynamicsKind::Function(f) => {
                for ((name, arg), &n) in ["x", "u", "p"].iter().zip([x, u, p]).zip(f.input_sizes())
                {
                    if arg.len() != n {
                        return Err(OcpError::Size {
                            what: format!("input {name} of dynamics function '{}'", f.name()),
                            expected: n,
                            got: arg.len(),
                        });
                    }
                }
                let out = f.apply(&[x, u, p])?;
                Ok(Matrix::from_vec(out.into_iter().next().unwrap_or_default()))
            }
        }
    }
}

/// The final time.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Horizon {
    /// A given final time `T > 0`.
    Fixed(f64),
    /// A decision variable `T` with `lower ≤ T ≤ upper` and an initial guess.
    Free { lower: f64, upper: f64, guess: f64 },
}

impl Horizon {
    /// A free final time `lower ≤ T ≤ upper` with an initial guess, i.e.
    /// `Horizon::Free { lower, upper, guess }` (checked by [`Ocp::set_horizon`]).
    pub const fn free(lower: f64, upper: f64, guess: f64) -> Horizon {
        Horizon::Free {
            lower,
            upper,
            guess,
        }
    }

    /// The fixed value or the guess.
    pub fn guess(&self) -> f64 {
        match *self {
            Horizon::Fixed(t) => t,
            Horizon::Free { guess, .. } => guess,
        }
    }
}

/// A continuous-time optimal control problem
///
/// ```text
/// min  ∫₀ᵀ l(x, u, p) dt + φ(x(T), p, T)
/// s.t. ẋ = f(x, u, p),  c(x, u, p) within bounds on the grid,  b(x(0), x(T), p, T) within bounds,
///      x_l ≤ x ≤ x_u,  u_l ≤ u ≤ u_u,  T fixed or free
/// ```
///
/// with `p` parameters (values fixed in a solve, changeable afterwards, and the variables
/// of [`crate::sensitivity`]). Controls are piecewise constant on the transcription grid,
/// or piecewise linear with values at the nodes ([`Ocp::set_control_interpolation`]).
pub struct Ocp {
    pub(crate) states: Vec<String>,
    pub(crate) controls: Vec<String>,
    pub(crate) parameters: Vec<(String, Vec<f64>)>,
    pub(crate) dynamics: Option<Dynamics>,
    pub(crate) horizon: Option<Horizon>,
    pub(crate) control_interpolation: ControlInterpolation,
    pub(crate) stage_cost: Option<StageScalar>,
    pub(crate) terminal_cost: Option<TerminalFn>,
    pub(crate) path: Vec<(String, PathFn)>,
    pub(crate) boundary: Vec<(String, BoundaryFn)>,
    pub(crate) state_bounds: (Vec<f64>, Vec<f64>),
    pub(crate) control_bounds: (Vec<f64>, Vec<f64>),
    pub(crate) initial_state: Option<Vec<f64>>,
    /// The parameter that `x(0)` equals ([`Ocp::set_initial_state_parameter`]).
    pub(crate) initial_state_parameter: Option<String>,
    pub(crate) final_state: Option<Vec<f64>>,
    pub(crate) state_guess: Option<GuessFn>,
    pub(crate) control_guess: Option<GuessFn>,
}

impl Ocp {
    /// A problem with the named states and controls (their number is the size of `x` and
    /// `u`), no costs and no bounds. The final time must be given with
    /// [`Ocp::set_horizon`] before transcribing ([`OcpError::NoHorizon`] otherwise).
    ///
    /// Closures given to an `Ocp` (dynamics, costs, constraints, guesses) are stored in it,
    /// so they must be `'static`: one that uses a local variable must own it — write
    /// `move |x, u, p| …` (without `move` the compiler reports E0373, "closure may outlive
    /// the current function"). Copy or clone what the closure needs before it:
    ///
    /// ```
    /// use nlp::ocp::Ocp;
    /// use symx::Matrix;
    /// let mass = 2.0; // a local captured by the closure: `move` copies it in
    /// let mut ocp = Ocp::new(&["x", "v"], &["f"]);
    /// ocp.set_dynamics(move |x, u, _p| Matrix::from_vec(vec![x[1], u[0] / mass]));
    /// ```
    pub fn new(states: &[&str], controls: &[&str]) -> Ocp {
        let (nx, nu) = (states.len(), controls.len());
        Ocp {
            states: states.iter().map(|s| s.to_string()).collect(),
            controls: controls.iter().map(|s| s.to_string()).collect(),
            parameters: Vec::new(),
            dynamics: None,
            horizon: None,
            control_interpolation: ControlInterpolation::PiecewiseConstant,
            stage_cost: None,
            terminal_cost: None,
            path: Vec::new(),
            boundary: Vec::new(),
            state_bounds: (vec![f64::NEG_INFINITY; nx], vec![f64::INFINITY; nx]),
            control_bounds: (vec![f64::NEG_INFINITY; nu], vec![f64::INFINITY; nu]),
            initial_state: None,
            initial_state_parameter: None,
            final_state: None,
            state_guess: None,
            control_guess: None,
        }
    }

    /// Number of states.
    pub fn nx(&self) -> usize {
        self.states.len()
    }

    /// Number of controls.
    pub fn nu(&self) -> usize {
        self.controls.len()
    }

    /// Number of parameter entries (all parameters stacked in declaration order).
    pub fn np(&self) -> usize {
        self.parameters.iter().map(|(_, v)| v.len()).sum()
    }

    /// Declares a parameter vector `name` with its values; the closures receive all
    /// parameters stacked in declaration order as `p`. In the transcription it is a
    /// [`Problem`](crate::Problem) parameter of the same name.
    pub fn add_parameter(&mut self, name: &str, values: &[f64]) -> Result<(), OcpError> {
        if self.parameters.iter().any(|(n, _)| n == name) {
            return Err(BuildError::DuplicateName { name: name.into() }.into());
        }
        if let Some(&v) = values.iter().find(|v| !v.is_finite()) {
            return Err(OcpError::Invalid {
                what: format!("value of parameter '{name}'"),
                why: format!("{v} is not finite"),
            });
        }
        self.parameters.push((name.to_string(), values.to_vec()));
        Ok(())
    }

    /// The dynamics compiled as a numeric function `(x, u, p) ↦ ẋ` (three inputs, one
    /// output), e.g. to simulate a solution's controls or to plot the vector field. For
    /// dynamics given as a function, that function (its sizes checked).
    pub fn dynamics_function(&self) -> Result<symx::Function, OcpError> {
        let dynamics = self.dynamics.as_ref().ok_or(OcpError::NoDynamics)?;
        let x = Matrix::sym_vec("x", self.nx());
        let u = Matrix::sym_vec("u", self.nu());
        let p = Matrix::sym_vec("p", self.np());
        let f = dynamics.eval(&x, &u, &p)?;
        if let Some(f) = dynamics.function() {
            return Ok(f.clone());
        }
        if f.len() != self.nx() {
            return Err(OcpError::Size {
                what: "dynamics output".into(),
                expected: self.nx(),
                got: f.len(),
            });
        }
        Ok(symx::Function::new(&[&x, &u, &p], &[&f])?)
    }

    /// Sets the dynamics `ẋ = f(x, u, p)` as a closure of expressions (inlined wherever the
    /// transcription evaluates it).
    pub fn set_dynamics(&mut self, f: impl Fn(&Matrix, &Matrix, &Matrix) -> Matrix + 'static) {
        self.dynamics = Some(Dynamics::new(f));
    }

    /// Sets the dynamics as a compiled function `f(x, u, p) -> ẋ` (three inputs of lengths
    /// `nx`, `nu`, `np`, one output of length `nx`), which the transcription calls without
    /// inlining: the transcribed problem holds the dynamics once, however many intervals.
    /// The lengths of `x` and `u` are checked here, that of `p` when transcribing (parameters
    /// may be added later).
    ///
    /// ```
    /// use nlp::ocp::{Method, Ocp};
    /// use symx::{Function, Matrix};
    /// // ẋ = −x + u, compiled once.
    /// let (x, u, p) = (Matrix::sym_vec("x", 1), Matrix::sym_vec("u", 1), Matrix::sym_vec("p", 0));
    /// let f = Function::named("f", &[("x", &x), ("u", &u), ("p", &p)], &[("xdot", &[u[0] - x[0]])]).unwrap();
    /// let mut ocp = Ocp::new(&["x"], &["u"]);
    /// ocp.set_dynamics_function(f).unwrap();
    /// ocp.set_stage_cost(|x, u, _| x[0].sq() + u[0].sq());
    /// ocp.set_initial_state(&[1.0]).unwrap();
    /// ocp.set_horizon(nlp::ocp::Horizon::Fixed(1.0)).unwrap();
    /// let tr = ocp.transcribe(&Method::collocation(nlp::ocp::CollocationPoints::Radau, 3).unwrap(), 50).unwrap();
    /// // 50 intervals × 3 collocation points = 150 calls of the one function f.
    /// assert!(tr.problem().constraint_expressions()[0].to_string().contains("f("));
    /// ```
    pub fn set_dynamics_function(&mut self, f: symx::Function) -> Result<(), OcpError> {
        let d = Dynamics::from_function(f)?;
        let f = d.function().expect("just built from a function");
        for (name, n, want) in [
            ("x", f.input_sizes()[0], self.nx()),
            ("u", f.input_sizes()[1], self.nu()),
        ] {
            if n != want {
                return Err(OcpError::Size {
                    what: format!("input {name} of dynamics function '{}'", f.name()),
                    expected: want,
                    got: n,
                });
            }
        }
        self.dynamics = Some(d);
        Ok(())
    }

    /// Sets the final time: fixed `T > 0`, or free with `0 ≤ lower ≤ guess ≤ upper` and a
    /// finite guess `> 0`.
    pub fn set_horizon(&mut self, horizon: Horizon) -> Result<(), OcpError> {
        let bad = |why: &str| {
            Err(OcpError::Invalid {
                what: "horizon".into(),
                why: why.into(),
            })
        };
        match horizon {
            Horizon::Fixed(t) if !(t.is_finite() && t > 0.0) => bad("T must be finite and > 0"),
            Horizon::Free {
                lower,
                upper,
                guess,
            } if !(lower >= 0.0
                && lower <= guess
                && guess <= upper
                && guess > 0.0
                && guess.is_finite()) =>
            {
                bad("need 0 ≤ lower ≤ guess ≤ upper and a finite guess > 0")
            }
            _ => {
                self.horizon = Some(horizon);
                Ok(())
            }
        }
    }

    /// Sets how the controls vary on the transcription grid: piecewise constant (the
    /// default, one value per interval) or piecewise linear (one value per node, `U` is
    /// `nu × (N+1)`). Every method supports both; with multiple shooting a linear control
    /// is integrated exactly as a function of time within each Runge–Kutta step.
    pub fn set_control_interpolation(&mut self, interpolation: ControlInterpolation) {
        self.control_interpolation = interpolation;
    }

    /// Sets the Lagrange integrand `l(x, u, p)` of the cost `∫₀ᵀ l dt`.
    pub fn set_stage_cost(&mut self, l: impl Fn(&Matrix, &Matrix, &Matrix) -> Expr + 'static) {
        self.stage_cost = Some(Box::new(l));
    }

    /// Sets the Mayer term `φ(x(T), p, T)` (e.g. `|_, _, t| t` for minimum time).
    pub fn set_terminal_cost(&mut self, phi: impl Fn(&Matrix, &Matrix, Expr) -> Expr + 'static) {
        self.terminal_cost = Some(Box::new(phi));
    }

    /// Adds a path constraint `c(x, u, p)` imposed at every grid point `t₀ … t_N` (at
    /// `t_N` with the last interval's control).
    pub fn add_path_constraint(
        &mut self,
        name: &str,
        c: impl Fn(&Matrix, &Matrix, &Matrix) -> Constraint + 'static,
    ) {
        self.path.push((name.to_string(), Box::new(c)));
    }

    /// Adds a boundary constraint `b(x(0), x(T), p, T)`.
    pub fn add_boundary_constraint(
        &mut self,
        name: &str,
        b: impl Fn(&Matrix, &Matrix, &Matrix, Expr) -> Constraint + 'static,
    ) {
        self.boundary.push((name.to_string(), Box::new(b)));
    }

    /// Bounds of the states, imposed at every grid and collocation point (±∞ for none).
    pub fn set_state_bounds(&mut self, lower: &[f64], upper: &[f64]) -> Result<(), OcpError> {
        self.state_bounds = check_bounds("state bounds", self.nx(), lower, upper)?;
        Ok(())
    }

    /// Bounds of the controls (±∞ for none).
    pub fn set_control_bounds(&mut self, lower: &[f64], upper: &[f64]) -> Result<(), OcpError> {
        self.control_bounds = check_bounds("control bounds", self.nu(), lower, upper)?;
        Ok(())
    }

    /// Fixes `x(0)` to constant values. Exclusive with
    /// [`Ocp::set_initial_state_parameter`] (an error names the conflict).
    pub fn set_initial_state(&mut self, x0: &[f64]) -> Result<(), OcpError> {
        if let Some(name) = &self.initial_state_parameter {
            return Err(OcpError::Invalid {
                what: "initial state".into(),
                why: format!("already the parameter '{name}' (set_initial_state_parameter)"),
            });
        }
        self.initial_state = Some(check_values("initial state", self.nx(), x0)?);
        Ok(())
    }

    /// Makes the initial state a parameter: declares the parameter `name` (`nx` entries,
    /// value `x0`, see [`Ocp::add_parameter`]) and the constraint rows `x(0) = name`
    /// (group `initial state`, as many rows as states). Between solves the measured state
    /// is set with `compiled.set_value(name, x)` without recompiling — the form model
    /// predictive control needs ([`crate::mpc::Mpc`]). Exclusive with
    /// [`Ocp::set_initial_state`].
    ///
    /// ```
    /// use nlp::ocp::{ButcherTableau, Method, Ocp};
    /// use nlp::Ipm;
    /// use symx::Matrix;
    /// let mut ocp = Ocp::new(&["x"], &["u"]);
    /// ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![-x[0] + u[0]]));
    /// ocp.set_stage_cost(|x, u, _p| x[0].sq() + u[0].sq());
    /// ocp.set_initial_state_parameter("x0", &[1.0]).unwrap();
    /// ocp.set_horizon(nlp::ocp::Horizon::Fixed(1.0)).unwrap();
    /// let tr = ocp.transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), 10).unwrap();
    /// assert_eq!(tr.initial_state_parameter(), Some("x0"));
    /// let mut compiled = tr.compile().unwrap();
    /// compiled.set_value("x0", &[0.5]).unwrap(); // a new measurement, no recompilation
    /// let sol = Ipm::default().solve(&mut compiled).unwrap();
    /// assert!((tr.trajectory(&sol).unwrap().states[0][0] - 0.5).abs() < 1e-8);
    /// ```
    pub fn set_initial_state_parameter(&mut self, name: &str, x0: &[f64]) -> Result<(), OcpError> {
        if self.initial_state.is_some() {
            return Err(OcpError::Invalid {
                what: "initial state".into(),
                why: "already fixed by set_initial_state".into(),
            });
        }
        if let Some(old) = &self.initial_state_parameter {
            return Err(OcpError::Invalid {
                what: "initial state".into(),
                why: format!("already the parameter '{old}'"),
            });
        }
        let x0 = check_values("initial state parameter", self.nx(), x0)?;
        self.add_parameter(name, &x0)?;
        self.initial_state_parameter = Some(name.to_string());
        Ok(())
    }

    /// Fixes `x(T)`.
    pub fn set_final_state(&mut self, xf: &[f64]) -> Result<(), OcpError> {
        self.final_state = Some(check_values("final state", self.nx(), xf)?);
        Ok(())
    }

    /// Guesses the states as a function of the absolute time `t ∈ [0, T]` (`T` the fixed
    /// final time or, for a free one, the horizon's `guess`; `t` is not normalised to
    /// `[0, 1]`); it must return `nx` finite values. It is called at every grid node (and
    /// collocation or midpoint state) when transcribing.
    ///
    /// ```
    /// use nlp::ocp::{Horizon, Method, Ocp};
    /// use symx::Matrix;
    /// let mut ocp = Ocp::new(&["x"], &[]);
    /// ocp.set_dynamics(|_x, _u, _p| Matrix::from_vec(vec![1.0.into()]));
    /// ocp.set_horizon(Horizon::Fixed(4.0)).unwrap();
    /// ocp.set_state_guess(|t| vec![t]); // t runs over 0 … 4
    /// let tr = ocp.transcribe(&Method::trapezoidal(), 2).unwrap();
    /// let x0 = tr.problem().initial_point();
    /// assert_eq!(&x0[..3], [0.0, 2.0, 4.0]);
    /// ```
    pub fn set_state_guess(&mut self, x: impl Fn(f64) -> Vec<f64> + 'static) {
        self.state_guess = Some(Box::new(move |t, _| x(t)));
    }

    /// Guesses the controls as a function of the absolute time `t` (as
    /// [`Ocp::set_state_guess`]; `nu` finite values), at the interval starts for
    /// piecewise-constant controls and at every node for piecewise-linear ones.
    pub fn set_control_guess(&mut self, u: impl Fn(f64) -> Vec<f64> + 'static) {
        self.control_guess = Some(Box::new(move |t, _| u(t)));
    }

    /// Guesses the states on the straight line from `start` (t = 0) to `end` (t = T).
    pub fn set_state_guess_linear(&mut self, start: &[f64], end: &[f64]) -> Result<(), OcpError> {
        let a = check_values("state guess start", self.nx(), start)?;
        let b = check_values("state guess end", self.nx(), end)?;
        self.state_guess = Some(Box::new(move |t, t_f| {
            let s = (t / t_f).clamp(0.0, 1.0);
            a.iter().zip(&b).map(|(a, b)| a + s * (b - a)).collect()
        }));
        Ok(())
    }

    /// Guesses the states and controls from a previous solution (e.g. on a coarser grid),
    /// interpolated linearly in normalised time `t / T`.
    pub fn set_guess_from(&mut self, previous: &Trajectory) {
        let (p1, p2) = (previous.clone(), previous.clone());
        self.state_guess = Some(Box::new(move |t, t_f| {
            p1.states_at(t / t_f * p1.final_time)
        }));
        self.control_guess = Some(Box::new(move |t, t_f| {
            p2.controls_at(t / t_f * p2.final_time)
        }));
    }
}

fn check_values(what: &str, n: usize, v: &[f64]) -> Result<Vec<f64>, OcpError> {
    if v.len() != n {
        return Err(OcpError::Size {
            what: what.into(),
            expected: n,
            got: v.len(),
        });
    }
    if let Some(i) = v.iter().position(|v| !v.is_finite()) {
        return Err(OcpError::Invalid {
            what: format!("{what}[{i}]"),
            why: format!("{} is not finite", v[i]),
        });
    }
    Ok(v.to_vec())
}

fn check_bounds(
    what: &str,
    n: usize,
    lower: &[f64],
    upper: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), OcpError> {
    for (side, v) in [("lower", lower), ("upper", upper)] {
        if v.len() != n {
            return Err(OcpError::Size {
                what: format!("{what} ({side})"),
                expected: n,
                got: v.len(),
            });
        }
    }
    for (i, (&l, &u)) in lower.iter().zip(upper).enumerate() {
        if l.is_nan() || u.is_nan() || l > u {
            return Err(OcpError::Invalid {
                what: format!("{what}[{i}]"),
                why: format!("[{l}, {u}] is not an interval"),
            });
        }
    }
    Ok((lower.to_vec(), upper.to_vec()))
}
