//! A [`SolverFunction`] as a symx call node ([`SolverFunction::into_external`]): another
//! problem can call the solver inside its expressions (bilevel problems, an MPC embedded in
//! a design problem), with first derivatives from the parametric sensitivities and second
//! derivatives from central differences of those sensitivities.
use super::to_function::{SolverFunction, ToFunctionError};
use std::sync::{Arc, Mutex, PoisonError};
use symx::sparsity::pattern_from_entries;
use symx::Function;

/// Relative step of the central differences that give a [`SolverFunction`] node's second
/// derivatives: `h = SECOND_DERIVATIVE_STEP · (1 + |input|)`. Central differences of a
/// derivative known to about the solver's tolerance ε (1e-8) err by O(ε/h + h²):
/// 1e-4 balances both near 1e-4 relative at worst, and is exact for solution maps
/// that are affine in the parameters (inner QPs with a fixed active set).
pub const SECOND_DERIVATIVE_STEP: f64 = 1e-4;

/// The solver function shared by the closures of the three levels (value, Jacobian, second
/// derivatives); the lock serialises concurrent callers, as one solver owns one work space.
type Shared = Arc<Mutex<SolverFunction>>;

/// Splits stacked inputs into the per-input slices `sizes` describes.
fn split<'a>(stacked: &'a [f64], sizes: &[usize]) -> Vec<&'a [f64]> {
    let mut rest = stacked;
    sizes
        .iter()
        .map(|&n| {
            let (head, tail) = rest.split_at(n);
            rest = tail;
            head
        })
        .collect()
}

/// The Jacobian's nonzeros at `stacked` (entries `(i, j)` for every output `i` and every
/// parameter column `j`, column-major), or `None` if the solve or the sensitivity failed.
fn jacobian_nonzeros(
    f: &mut SolverFunction,
    stacked: &[f64],
    columns: &[usize],
) -> Option<Vec<f64>> {
    let sizes = f.input_sizes().to_vec();
    let (_, jac) = f.jacobian(&split(stacked, &sizes)).ok()?;
    Some(
        columns
            .iter()
            .flat_map(|&j| jac.iter().map(move |row| row[j]))
            .collect(),
    )
}

/// Central differences of the Jacobian's nonzeros in each parameter column: column-major
/// `(nonzero k, column j)`, or `None` if a solve failed.
fn second_derivatives(
    f: &mut SolverFunction,
    stacked: &[f64],
    columns: &[usize],
) -> Option<Vec<f64>> {
    let mut out = Vec::new();
    for &j in columns {
        let h = SECOND_DERIVATIVE_STEP * (1.0 + stacked[j].abs());
        let mut shifted = stacked.to_vec();
        shifted[j] = stacked[j] + h;
        let plus = jacobian_nonzeros(f, &shifted, columns)?;
        shifted[j] = stacked[j] - h;
        let minus = jacobian_nonzeros(f, &shifted, columns)?;
        out.extend(plus.iter().zip(&minus).map(|(a, b)| (a - b) / (2.0 * h)));
    }
    Some(out)
}

/// An external function of the stacked inputs that runs `body` on the shared solver
/// function and writes its result, or NaN everywhere if `body` fails.
fn level(
    name: &str,
    inputs: &[(String, usize)],
    output: (&str, usize),
    shared: &Shared,
    body: impl Fn(&mut SolverFunction, &[f64]) -> Option<Vec<f64>> + Send + Sync + 'static,
) -> Result<Function, ToFunctionError> {
    let shared = shared.clone();
    let named: Vec<(&str, usize)> = inputs.iter().map(|(n, s)| (n.as_str(), *s)).collect();
    let eval = move |args: &[f64], out: &mut [f64]| {
        let mut f = shared.lock().unwrap_or_else(PoisonError::into_inner);
        match body(&mut f, args) {
            Some(values) if values.len() == out.len() => out.copy_from_slice(&values),
            _ => out.fill(f64::NAN),
        }
    };
    Ok(Function::external(name, &named, &[output], eval)?)
}

impl SolverFunction {
    /// This solver function as an external [`symx::Function`] named `name`, a call node
    /// for other problems' expressions ([`Function::apply`]): inputs `in0, in1, …` and
    /// outputs `out0, out1, …` as given to [`Problem::to_function`](crate::Problem::to_function).
    ///
    /// Derivatives (with respect to the parameter inputs; guess inputs have none):
    /// * first: the parametric sensitivities at the solution ([`SolverFunction::jacobian`]);
    ///   a call and its Jacobian at the same inputs solve once;
    /// * second: central differences of the first, step [`SECOND_DERIVATIVE_STEP`], so an
    ///   outer solve with the exact Hessian costs two inner solves per parameter input entry
    ///   at each Hessian evaluation. They are approximate: prefer an outer quasi-Newton
    ///   solve (`IpmOptions::hessian_approximation = LimitedMemory`, which never evaluates
    ///   them) unless the solution map is affine (then they are exact up to rounding);
    /// * third: none (differentiating further is [`symx::SymxError::NoDerivative`]).
    ///
    /// A failed inner solve makes the node's outputs NaN (the outer solver treats the
    /// point as an evaluation error). The node is `Send + Sync` like every function;
    /// concurrent calls are serialised by a lock (one solver, one work space). Like other
    /// external functions it cannot be compiled to native code (`Function::jit`).
    ///
    /// ```
    /// use nlp::{Problem, Relation, Ipm, Solver};
    /// // Inner: y*(a) = argmin (y − a)² s.t. y ≥ 0, so y* = a for a > 0.
    /// let mut inner = Problem::new();
    /// let y = inner.scalar_variable("y")?;
    /// let a = inner.scalar_parameter("a")?;
    /// inner.set_value(a, &[1.0])?;
    /// inner.minimize((y - a).sq());
    /// inner.subject_to(y.ge(0.0))?;
    /// let node = inner.to_function(&[&[a]], &[&[y]])?.into_external("inner")?;
    /// // Outer: min_a (y*(a) − 2)² + a²/10 ⇒ a = 20/11 while a > 0.
    /// let mut outer = Problem::new();
    /// let a = outer.scalar_variable("a")?;
    /// outer.set_initial(&[a], &[1.0])?;
    /// let y_star = node.apply(&[&[a]])?[0][0];
    /// outer.minimize((y_star - 2.0).sq() + a.sq() / 10.0);
    /// let sol = Ipm::default().solve(&mut outer.compile()?)?;
    /// assert!((sol.x[0] - 20.0 / 11.0).abs() < 1e-6);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn into_external(self, name: &str) -> Result<Function, ToFunctionError> {
        let inputs: Vec<(String, usize)> = self
            .input_sizes()
            .iter()
            .enumerate()
            .map(|(k, &n)| (format!("in{k}"), n))
            .collect();
        let outputs: Vec<(String, usize)> = self
            .output_sizes()
            .iter()
            .enumerate()
            .map(|(k, &n)| (format!("out{k}"), n))
            .collect();
        let (n_in, n_out) = (
            self.input_sizes().iter().sum::<usize>(),
            self.output_sizes().iter().sum::<usize>(),
        );
        let columns = self.parameter_columns();
        let nnz = n_out * columns.len();
        let shared: Shared = Arc::new(Mutex::new(self));
        let cols = columns.clone();
        let hessian = level(
            &format!("jac_jac_{name}"),
            &inputs,
            ("hess", nnz * columns.len()),
            &shared,
            move |f, x| second_derivatives(f, x, &cols),
        )?;
        let cols = columns.clone();
        let jacobian = level(
            &format!("jac_{name}"),
            &inputs,
            ("jac", nnz),
            &shared,
            move |f, x| jacobian_nonzeros(f, x, &cols),
        )?;
        let jac_pattern = pattern_from_entries(
            nnz,
            n_in,
            columns.iter().flat_map(|&j| (0..nnz).map(move |k| (k, j))),
        );
        let jacobian = jacobian.with_jacobian(&jac_pattern, &hessian)?;
        let sizes: Vec<usize> = inputs.iter().map(|i| i.1).collect();
        let named_in: Vec<(&str, usize)> = inputs.iter().map(|(n, s)| (n.as_str(), *s)).collect();
        let named_out: Vec<(&str, usize)> = outputs.iter().map(|(n, s)| (n.as_str(), *s)).collect();
        let value = Function::external(name, &named_in, &named_out, move |x, out| {
            let mut f = shared.lock().unwrap_or_else(PoisonError::into_inner);
            match f.call(&split(x, &sizes)) {
                Ok(values) => out.copy_from_slice(&values),
                Err(_) => out.fill(f64::NAN),
            }
        })?;
        let pattern = pattern_from_entries(
            n_out,
            n_in,
            columns
                .iter()
                .flat_map(|&j| (0..n_out).map(move |i| (i, j))),
        );
        Ok(value.with_jacobian(&pattern, &jacobian)?)
    }
}
