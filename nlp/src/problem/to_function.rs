//! A solver as a function: [`Problem::to_function`] (CasADi's `Opti.to_function`) maps
//! parameter values and initial guesses to any expressions of the solution, and gives their
//! Jacobian with respect to the parameters from the parametric sensitivities
//! ([`crate::ParametricSensitivity`]), not from finite differences.
use super::{BuildError, Problem};
use crate::compiled::Compiled;
use crate::frontend::Solver;
use crate::sensitivity::{ParametricSensitivity, SensitivityError};
use crate::solution::{Solution, Status};
use crate::{Ipm, SolveError};
use symx::{Expr, Function, Matrix};
use thiserror::Error;

/// Why a [`SolverFunction`] could not be built or evaluated.
#[derive(Debug, Error)]
pub enum ToFunctionError {
    /// A mistake in the problem, the inputs or the outputs.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The solver refused the problem.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The solver ran but did not meet its tolerances: no value is returned.
    #[error("the solve did not succeed ({status}): {message}")]
    NotSolved {
        /// The solver's status.
        status: Status,
        /// The solver's message.
        message: String,
    },
    /// The sensitivities could not be computed at the solution.
    #[error(transparent)]
    Sensitivity(#[from] SensitivityError),
    /// An error from symx (compiling the outputs or their derivatives).
    #[error(transparent)]
    Symx(#[from] symx::SymxError),
}

/// One input of a [`SolverFunction`].
#[derive(Clone, Debug, PartialEq)]
enum Input {
    /// Values of these parameter entries (indices in `Problem::parameters`).
    Parameter(Vec<usize>),
    /// Initial guesses of these variables (indices in `Problem::variables`).
    Guess(Vec<usize>),
}

/// A problem's solver as a function of its parameters and initial guesses, returning
/// expressions of the solution: built by [`Problem::to_function`]. Each call solves the
/// problem from its initial point (a cold start: the same inputs give bit-identical
/// outputs), and fails unless the solver succeeds.
pub struct SolverFunction {
    compiled: Compiled,
    solver: Box<dyn Solver>,
    sensitivity: Option<ParametricSensitivity>,
    inputs: Vec<Input>,
    input_sizes: Vec<usize>,
    output_sizes: Vec<usize>,
    /// `(x, p) ↦ outputs stacked`.
    outputs: Function,
    /// `(x, p) ↦ (∂outputs/∂x, ∂outputs/∂p)`, dense, column-major.
    derivatives: Function,
    x0: Vec<f64>,
    p0: Vec<f64>,
    /// The last successful solve: the stacked inputs, the solution and the parameter
    /// vector (a call and a Jacobian at the same inputs solve once).
    last: Option<(Vec<f64>, Solution, Vec<f64>)>,
}

impl Problem {
    /// This problem's solution as a function (CasADi's `opti.to_function`): `inputs` are
    /// vectors of parameters (their values) or of variables (their initial guesses), each
    /// entirely one or the other; `outputs` are any expressions of the variables and
    /// parameters, evaluated at the solution with the parameter values of the call.
    /// Parameters and guesses not listed keep the values set on this problem. The solver
    /// is [`Ipm`] with default options until [`SolverFunction::with_solver`].
    ///
    /// [`SolverFunction::jacobian`] differentiates the outputs with respect to the
    /// parameter inputs by the parametric sensitivities (sIPOPT's system, strict
    /// complementarity assumed); with respect to a guess input the derivative is 0 (the
    /// solution does not move with the starting point while the solve lands on the same
    /// optimum).
    ///
    /// ```
    /// use nlp::{Problem, Relation};
    /// // min (x − a)² s.t. x ≤ b: x* = min(a, b).
    /// let mut pb = Problem::new();
    /// let x = pb.scalar_variable("x")?;
    /// let (a, b) = (pb.scalar_parameter("a")?, pb.scalar_parameter("b")?);
    /// pb.set_value(a, &[0.0])?;
    /// pb.set_value(b, &[1.0])?;
    /// pb.minimize((x - a).sq());
    /// pb.subject_to(x.le(b))?;
    /// let mut f = pb.to_function(&[&[a], &[b]], &[&[x, x * x]])?;
    /// let y = f.call(&[&[3.0], &[2.0]])?; // the bound is active: x* = b = 2
    /// assert!((y[0] - 2.0).abs() < 1e-8 && (y[1] - 4.0).abs() < 1e-7);
    /// // d(x*, x*²)/d(a, b) = [[0, 1], [0, 2b]], rows = outputs, columns = inputs
    /// let (_, jac) = f.jacobian(&[&[3.0], &[2.0]])?;
    /// assert!(jac[0][0].abs() < 1e-8 && (jac[0][1] - 1.0).abs() < 1e-8);
    /// assert!((jac[1][1] - 4.0).abs() < 1e-7);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn to_function(
        &self,
        inputs: &[&[Expr]],
        outputs: &[&[Expr]],
    ) -> Result<SolverFunction, ToFunctionError> {
        let mut classified = Vec::with_capacity(inputs.len());
        for (k, input) in inputs.iter().enumerate() {
            let params: Option<Vec<usize>> = input
                .iter()
                .map(|&e| self.parameter_index.index_of(e))
                .collect();
            let vars: Option<Vec<usize>> = input
                .iter()
                .map(|e| self.variable_index.get(&e.id()).copied())
                .collect();
            classified.push(match (params, vars) {
                (Some(p), _) if !input.is_empty() => Input::Parameter(p),
                (_, Some(v)) => Input::Guess(v),
                _ => {
                    return Err(BuildError::NotDeclared {
                        what: format!(
                        "to_function input {k} (all parameters or all variables of this problem)"
                    ),
                        index: k,
                        kind: "parameter or variable",
                    }
                    .into())
                }
            });
        }
        let stacked: Vec<Expr> = outputs.iter().flat_map(|o| o.iter().copied()).collect();
        let outputs_fn = self.function(&stacked, "to_function output")?;
        let (x, p) = (
            Matrix::from_vec(self.variables.clone()),
            Matrix::from_vec(self.parameters.clone()),
        );
        let dx = symx::jacobian(&stacked, &x)?.to_dense();
        let dp = symx::jacobian(&stacked, &p)?.to_dense();
        let derivatives = Function::new(&[&x, &p], &[&dx, &dp])?;
        let has_parameter_input = classified.iter().any(|i| matches!(i, Input::Parameter(_)));
        let sensitivity = if has_parameter_input {
            Some(ParametricSensitivity::new(self)?)
        } else {
            None
        };
        Ok(SolverFunction {
            compiled: self.compile()?,
            solver: Box::new(Ipm::default()),
            sensitivity,
            inputs: classified,
            input_sizes: inputs.iter().map(|i| i.len()).collect(),
            output_sizes: outputs.iter().map(|o| o.len()).collect(),
            outputs: outputs_fn,
            derivatives,
            x0: self.initial.clone(),
            p0: self.parameter_vector_or_unset(),
            last: None,
        })
    }
}

impl SolverFunction {
    /// Solves with `solver` instead of the default [`Ipm`] (e.g. an `Sqp`, or an `Ipm` with
    /// options).
    pub fn with_solver(mut self, solver: Box<dyn Solver>) -> SolverFunction {
        self.solver = solver;
        self.last = None;
        self
    }

    /// The length of each input.
    pub fn input_sizes(&self) -> &[usize] {
        &self.input_sizes
    }

    /// The length of each output.
    pub fn output_sizes(&self) -> &[usize] {
        &self.output_sizes
    }

    /// The stacked input entries that are parameter values (the columns of
    /// [`SolverFunction::jacobian`] that can be nonzero), in increasing order.
    pub fn parameter_columns(&self) -> Vec<usize> {
        let mut columns = Vec::new();
        let mut col = 0;
        for input in &self.inputs {
            match input {
                Input::Guess(v) => col += v.len(),
                Input::Parameter(idx) => {
                    columns.extend(col..col + idx.len());
                    col += idx.len();
                }
            }
        }
        columns
    }

    /// Solves with `inputs` and returns the outputs stacked (in order, each output's
    /// entries in column-major order). An error names an input of the wrong length, a
    /// failed solve ([`ToFunctionError::NotSolved`], with the status), or a non-finite value.
    pub fn call(&mut self, inputs: &[&[f64]]) -> Result<Vec<f64>, ToFunctionError> {
        let (sol, p) = self.solve(inputs)?;
        Ok(self.outputs.call(&[&sol.x, &p])?.swap_remove(0))
    }

    /// The outputs and their Jacobian with respect to the inputs: `jac[i][j]` is the
    /// derivative of stacked output entry `i` by stacked input entry `j`. Parameter columns
    /// come from the parametric sensitivities at the solution; guess columns are 0.
    pub fn jacobian(
        &mut self,
        inputs: &[&[f64]],
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ToFunctionError> {
        let (sol, p) = self.solve(inputs)?;
        let y = self.outputs.call(&[&sol.x, &p])?.swap_remove(0);
        let mut d = self.derivatives.call(&[&sol.x, &p])?.into_iter();
        let (dx, dp) = (d.next().unwrap_or_default(), d.next().unwrap_or_default());
        let (n_out, n) = (y.len(), sol.x.len());
        let n_in: usize = self.input_sizes.iter().sum();
        let mut jac = vec![vec![0.0; n_in]; n_out];
        let sens = match &mut self.sensitivity {
            Some(s) => Some(s.compute(&sol, &p)?),
            None => None,
        };
        let mut col = 0;
        for input in &self.inputs {
            match input {
                Input::Guess(v) => col += v.len(),
                Input::Parameter(idx) => {
                    let sens = sens.as_ref().expect("built when a parameter is an input");
                    for &j in idx {
                        let dx_dpj = &sens.dx_dp[j];
                        for (i, row) in jac.iter_mut().enumerate() {
                            // ∂y/∂x · dx*/dp_j + ∂y/∂p_j (dense, column-major).
                            let through_x: f64 =
                                (0..n).map(|k| dx[i + k * n_out] * dx_dpj[k]).sum();
                            row[col] = through_x + dp[i + j * n_out];
                        }
                        col += 1;
                    }
                }
            }
        }
        Ok((y, jac))
    }

    /// Sets the inputs and solves (or reuses the last solve when the inputs are the same
    /// bits: cold starts are deterministic); returns the solution and the parameter vector.
    fn solve(&mut self, inputs: &[&[f64]]) -> Result<(Solution, Vec<f64>), ToFunctionError> {
        let stacked: Vec<f64> = inputs.iter().flat_map(|v| v.iter().copied()).collect();
        if let Some((last, sol, p)) = &self.last {
            let same = |a: &[f64], b: &[f64]| {
                a.iter()
                    .map(|v| v.to_bits())
                    .eq(b.iter().map(|v| v.to_bits()))
            };
            let sizes_match = inputs
                .iter()
                .map(|v| v.len())
                .eq(self.input_sizes.iter().copied());
            if sizes_match && same(last, &stacked) {
                return Ok((sol.clone(), p.clone()));
            }
        }
        let (sol, p) = self.solve_from_start(inputs)?;
        self.last = Some((stacked, sol.clone(), p.clone()));
        Ok((sol, p))
    }

    /// Sets the inputs and solves from the initial point.
    fn solve_from_start(
        &mut self,
        inputs: &[&[f64]],
    ) -> Result<(Solution, Vec<f64>), ToFunctionError> {
        if inputs.len() != self.inputs.len() {
            return Err(BuildError::Size {
                what: "to_function: number of inputs".into(),
                expected: self.inputs.len(),
                got: inputs.len(),
            }
            .into());
        }
        let (mut x0, mut p) = (self.x0.clone(), self.p0.clone());
        for (k, (input, values)) in self.inputs.iter().zip(inputs).enumerate() {
            let (idx, target) = match input {
                Input::Parameter(idx) => (idx, &mut p),
                Input::Guess(idx) => (idx, &mut x0),
            };
            if values.len() != idx.len() {
                return Err(BuildError::Size {
                    what: format!("to_function: input {k}"),
                    expected: idx.len(),
                    got: values.len(),
                }
                .into());
            }
            if let Some(&v) = values.iter().find(|v| !v.is_finite()) {
                return Err(BuildError::NotFinite {
                    what: format!("to_function: input {k}"),
                    value: v,
                }
                .into());
            }
            for (&i, &v) in idx.iter().zip(values.iter()) {
                target[i] = v;
            }
        }
        self.compiled.set_parameter_vector(&p);
        self.compiled.set_initial_point(&x0)?;
        let sol = self.solver.solve(&mut self.compiled)?;
        if !sol.status.is_success() {
            return Err(ToFunctionError::NotSolved {
                status: sol.status,
                message: sol.message,
            });
        }
        Ok((sol, p))
    }
}
