//! A derivative checker for [`NumericNlp`] implementations, after IPOPT's
//! `derivative_test` option (`first-order`, `second-order`).
//!
//! At a point x (default: the problem's initial point) it compares
//! - **first order**: the gradient ∇f and every entry of the constraint Jacobian, with
//!   central differences of f and g: column j is `(g(x + hⱼeⱼ) − g(x − hⱼeⱼ)) / 2hⱼ`;
//! - **second order**: the lower triangle of the Lagrangian Hessian
//!   `σ∇²f + Σ λᵢ∇²gᵢ`, with central differences of the *analytic* gradient of the
//!   Lagrangian `σ∇f + Jᵀλ` (as IPOPT does: first-order derivatives are assumed right, so
//!   check them first).
//!
//! The step is `hⱼ = perturbation · max(1, |xⱼ|)` and an entry is wrong when
//! `|analytic − fd| / max(1, |fd|) > tol` (IPOPT's `derivative_test_tol` has the same
//! default, 1e-4). Entries outside the declared sparsity pattern count as analytic zeros, so
//! a pattern that misses a nonzero is reported too. For each wrong Hessian entry the checker
//! also says which part is wrong: the objective, or which constraint (it compares
//! `∇²f` and each `∇²gᵢ` whose Jacobian row holds both variables, one at a time).
//!
//! Cost: 2n evaluations of f and g, and with the second order 2n of ∇f and the Jacobian,
//! so it is meant for small and medium problems, like IPOPT's.
use crate::NumericNlp;
use faer::sparse::SymbolicSparseColMat;
use std::fmt;

/// Settings of [`check_derivatives`].
#[derive(Clone, Debug, PartialEq)]
pub struct DerivativeCheckOptions {
    /// Relative finite-difference step (IPOPT: `derivative_test_perturbation`). Default
    /// 1e-6, about the cube root of machine epsilon, the best step for central differences.
    pub perturbation: f64,
    /// Relative error above which an entry is reported (IPOPT: `derivative_test_tol`).
    /// Default 1e-4.
    pub tol: f64,
    /// Also check the Lagrangian Hessian. Default true.
    pub second_order: bool,
    /// Where to check; `None` (default): the problem's initial point.
    pub point: Option<Vec<f64>>,
    /// Objective factor σ of the checked Hessian. Default 1.
    pub obj_factor: f64,
    /// Multipliers λ of the checked Hessian; `None` (default): all 1.
    pub lambda: Option<Vec<f64>>,
    /// How many of the worst entries of each order to report. Default 10.
    pub max_reports: usize,
}

impl Default for DerivativeCheckOptions {
    fn default() -> Self {
        DerivativeCheckOptions {
            perturbation: 1e-6,
            tol: 1e-4,
            second_order: true,
            point: None,
            obj_factor: 1.0,
            lambda: None,
            max_reports: 10,
        }
    }
}

/// Which derivative an entry belongs to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Derivative {
    /// `∂f/∂x_col`.
    Gradient,
    /// `∂g_row/∂x_col`.
    Jacobian,
    /// `∂²L/∂x_row∂x_col` (row ≥ col).
    Hessian,
}

/// One entry whose analytic value disagrees with its finite difference.
#[derive(Clone, Debug, PartialEq)]
pub struct Mismatch {
    /// Gradient, Jacobian or Hessian.
    pub derivative: Derivative,
    /// Constraint index (Jacobian), first variable index (Hessian), 0 for the gradient.
    pub row: usize,
    /// Variable index.
    pub col: usize,
    /// Name of the row: the constraint (Jacobian), the variable (Hessian), `f` (gradient).
    pub row_name: String,
    /// Name of the variable of the column.
    pub col_name: String,
    /// The value of the callback (0 outside the declared pattern).
    pub analytic: f64,
    /// The finite-difference estimate.
    pub finite_difference: f64,
    /// `|analytic − fd| / max(1, |fd|)`.
    pub error: f64,
    /// Whether the entry is in the declared sparsity pattern.
    pub in_pattern: bool,
    /// For a Hessian entry: the parts found wrong on their own (`objective`, constraint
    /// names); empty if none could be singled out.
    pub culprits: Vec<String>,
}

/// What [`check_derivatives`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct DerivativeReport {
    /// Wrong gradient and Jacobian entries, worst first (at most `max_reports`).
    pub first_order: Vec<Mismatch>,
    /// Wrong Hessian entries, worst first (at most `max_reports`).
    pub second_order: Vec<Mismatch>,
    /// Number of wrong first-order entries (all of them, not only those reported).
    pub n_first_order_wrong: usize,
    /// Number of wrong Hessian entries.
    pub n_second_order_wrong: usize,
    /// Largest first-order relative error.
    pub max_first_order_error: f64,
    /// Largest second-order relative error (0 when not checked).
    pub max_second_order_error: f64,
}

impl DerivativeReport {
    /// True when no entry exceeds the tolerance.
    pub fn passed(&self) -> bool {
        self.n_first_order_wrong == 0 && self.n_second_order_wrong == 0
    }
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = match self.derivative {
            Derivative::Gradient => format!("grad_f[{}]", self.col_name),
            Derivative::Jacobian => format!("jac_g[{}, {}]", self.row_name, self.col_name),
            Derivative::Hessian => format!("hess_L[{}, {}]", self.row_name, self.col_name),
        };
        write!(
            f,
            "{what}: analytic {:.8e}, finite difference {:.8e}, rel. error {:.2e}{}",
            self.analytic,
            self.finite_difference,
            self.error,
            if self.in_pattern {
                ""
            } else {
                " (not in the sparsity pattern)"
            }
        )?;
        if !self.culprits.is_empty() {
            write!(f, "; wrong in: {}", self.culprits.join(", "))?;
        }
        Ok(())
    }
}

impl fmt::Display for DerivativeReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "derivative check: {} wrong first-order entries (max rel. error {:.2e}), {} wrong Hessian entries (max rel. error {:.2e})",
            self.n_first_order_wrong, self.max_first_order_error, self.n_second_order_wrong, self.max_second_order_error
        )?;
        for m in self.first_order.iter().chain(&self.second_order) {
            writeln!(f, "  {m}")?;
        }
        Ok(())
    }
}

/// A bad argument of [`check_derivatives`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DerivativeCheckError {
    /// A vector has the wrong length.
    #[error("derivative check: {what} has length {got}, expected {expected}")]
    WrongSize {
        /// Which vector.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The expected length.
        expected: usize,
    },
    /// A setting is not a positive finite number.
    #[error("derivative check: {what} must be positive and finite, got {value}")]
    BadSetting {
        /// Which setting.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A callback returned NaN or Inf.
    #[error("derivative check: {what} is not finite at the check point (entry {index})")]
    NotFinite {
        /// Which callback.
        what: &'static str,
        /// The first non-finite entry.
        index: usize,
    },
}

/// Column `c` of a sparse matrix given by its pattern and values, dense (duplicates summed).
fn column(pattern: &SymbolicSparseColMat<usize>, values: &[f64], c: usize) -> Vec<f64> {
    let mut d = vec![0.0; pattern.nrows()];
    for p in pattern.col_range(c) {
        d[pattern.row_idx()[p]] += values[p];
    }
    d
}

/// Which rows of column `c` are in the pattern.
fn column_mask(pattern: &SymbolicSparseColMat<usize>, c: usize) -> Vec<bool> {
    let mut mask = vec![false; pattern.nrows()];
    for p in pattern.col_range(c) {
        mask[pattern.row_idx()[p]] = true;
    }
    mask
}

fn finite(what: &'static str, v: &[f64]) -> Result<(), DerivativeCheckError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(DerivativeCheckError::NotFinite { what, index }),
        None => Ok(()),
    }
}

fn relative_error(analytic: f64, fd: f64) -> f64 {
    (analytic - fd).abs() / fd.abs().max(1.0)
}

/// Keeps the `max` worst of `all`, worst first.
fn worst(mut all: Vec<Mismatch>, max: usize) -> Vec<Mismatch> {
    all.sort_by(|a, b| {
        b.error
            .total_cmp(&a.error)
            .then(a.row.cmp(&b.row))
            .then(a.col.cmp(&b.col))
    });
    all.truncate(max);
    all
}

/// Checks the derivatives of `nlp` (see the module documentation).
pub fn check_derivatives(
    nlp: &mut dyn NumericNlp,
    options: &DerivativeCheckOptions,
) -> Result<DerivativeReport, DerivativeCheckError> {
    let (n, m) = (nlp.n(), nlp.m());
    for (what, value) in [("perturbation", options.perturbation), ("tol", options.tol)] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(DerivativeCheckError::BadSetting { what, value });
        }
    }
    let x = match &options.point {
        Some(p) if p.len() != n => {
            return Err(DerivativeCheckError::WrongSize {
                what: "point",
                got: p.len(),
                expected: n,
            })
        }
        Some(p) => p.clone(),
        None => {
            let mut x0 = vec![0.0; n];
            nlp.initial_point(&mut x0);
            x0
        }
    };
    let lambda = options.lambda.clone().unwrap_or_else(|| vec![1.0; m]);
    if lambda.len() != m {
        return Err(DerivativeCheckError::WrongSize {
            what: "lambda",
            got: lambda.len(),
            expected: m,
        });
    }
    finite("point", &x)?;
    let first = first_order(nlp, &x, options)?;
    let (second, n2, max2) = if options.second_order {
        second_order(nlp, &x, &lambda, options)?
    } else {
        (Vec::new(), 0, 0.0)
    };
    let max1 = first.iter().map(|m| m.error).fold(0.0, f64::max);
    let n1 = first.iter().filter(|mm| mm.error > options.tol).count();
    let first = worst(
        first
            .into_iter()
            .filter(|mm| mm.error > options.tol)
            .collect(),
        options.max_reports,
    );
    Ok(DerivativeReport {
        first_order: first,
        second_order: second,
        n_first_order_wrong: n1,
        n_second_order_wrong: n2,
        max_first_order_error: max1,
        max_second_order_error: max2,
    })
}

/// Every gradient and Jacobian entry (structural or finite-difference nonzero) with its error.
fn first_order(
    nlp: &mut dyn NumericNlp,
    x: &[f64],
    options: &DerivativeCheckOptions,
) -> Result<Vec<Mismatch>, DerivativeCheckError> {
    let (n, m) = (nlp.n(), nlp.m());
    let mut grad = vec![0.0; n];
    nlp.eval_grad_f(x, &mut grad);
    finite("eval_grad_f", &grad)?;
    let pattern = nlp.jac_g_sparsity().clone();
    let mut values = vec![0.0; pattern.row_idx().len()];
    nlp.eval_jac_g(x, &mut values);
    finite("eval_jac_g", &values)?;
    let (mut xp, mut gp, mut gm) = (x.to_vec(), vec![0.0; m], vec![0.0; m]);
    let mut out = Vec::new();
    for j in 0..n {
        let h = options.perturbation * x[j].abs().max(1.0);
        xp[j] = x[j] + h;
        let fp = nlp.eval_f(&xp);
        nlp.eval_g(&xp, &mut gp);
        xp[j] = x[j] - h;
        let fm = nlp.eval_f(&xp);
        nlp.eval_g(&xp, &mut gm);
        xp[j] = x[j];
        let jac = column(&pattern, &values, j);
        let mask = column_mask(&pattern, j);
        let fd = (fp - fm) / (2.0 * h);
        out.push(Mismatch {
            derivative: Derivative::Gradient,
            row: 0,
            col: j,
            row_name: "f".into(),
            col_name: nlp.variable_name(j),
            analytic: grad[j],
            finite_difference: fd,
            error: relative_error(grad[j], fd),
            in_pattern: true,
            culprits: Vec::new(),
        });
        for i in 0..m {
            let fd = (gp[i] - gm[i]) / (2.0 * h);
            let structural = mask[i];
            if !structural && fd.abs() <= options.tol {
                continue;
            }
            out.push(Mismatch {
                derivative: Derivative::Jacobian,
                row: i,
                col: j,
                row_name: nlp.constraint_name(i),
                col_name: nlp.variable_name(j),
                analytic: jac[i],
                finite_difference: fd,
                error: relative_error(jac[i], fd),
                in_pattern: structural,
                culprits: Vec::new(),
            });
        }
    }
    Ok(out)
}

/// `σ∇f + Jᵀλ` at `x` from the analytic callbacks.
fn lagrangian_gradient(
    nlp: &mut dyn NumericNlp,
    x: &[f64],
    sigma: f64,
    lambda: &[f64],
) -> Vec<f64> {
    let n = nlp.n();
    let mut grad = vec![0.0; n];
    nlp.eval_grad_f(x, &mut grad);
    let pattern = nlp.jac_g_sparsity().clone();
    let mut values = vec![0.0; pattern.row_idx().len()];
    nlp.eval_jac_g(x, &mut values);
    for (c, gc) in grad.iter_mut().enumerate() {
        *gc *= sigma;
        for p in pattern.col_range(c) {
            *gc += lambda[pattern.row_idx()[p]] * values[p];
        }
    }
    grad
}

/// Column `k` of the Hessian of `σf + λᵀg` by central differences of its analytic gradient.
fn fd_hessian_column(
    nlp: &mut dyn NumericNlp,
    x: &[f64],
    k: usize,
    sigma: f64,
    lambda: &[f64],
    rel: f64,
) -> Vec<f64> {
    let h = rel * x[k].abs().max(1.0);
    let mut xp = x.to_vec();
    xp[k] = x[k] + h;
    let plus = lagrangian_gradient(nlp, &xp, sigma, lambda);
    xp[k] = x[k] - h;
    let minus = lagrangian_gradient(nlp, &xp, sigma, lambda);
    plus.iter()
        .zip(&minus)
        .map(|(a, b)| (a - b) / (2.0 * h))
        .collect()
}

/// The analytic Hessian values of `σf + λᵀg` in the pattern's order.
fn analytic_hessian(nlp: &mut dyn NumericNlp, x: &[f64], sigma: f64, lambda: &[f64]) -> Vec<f64> {
    let mut values = vec![0.0; nlp.hess_l_sparsity().row_idx().len()];
    nlp.eval_hess_l(x, sigma, lambda, &mut values);
    values
}

type SecondOrder = (Vec<Mismatch>, usize, f64);

fn second_order(
    nlp: &mut dyn NumericNlp,
    x: &[f64],
    lambda: &[f64],
    options: &DerivativeCheckOptions,
) -> Result<SecondOrder, DerivativeCheckError> {
    let n = nlp.n();
    let sigma = options.obj_factor;
    let pattern = nlp.hess_l_sparsity().clone();
    let values = analytic_hessian(nlp, x, sigma, lambda);
    finite("eval_hess_l", &values)?;
    let mut wrong = Vec::new();
    let mut max_error: f64 = 0.0;
    for k in 0..n {
        let fd_column = fd_hessian_column(nlp, x, k, sigma, lambda, options.perturbation);
        let hess = column(&pattern, &values, k);
        let mask = column_mask(&pattern, k);
        for (j, &fd) in fd_column.iter().enumerate().skip(k) {
            let structural = mask[j];
            let error = relative_error(hess[j], fd);
            max_error = max_error.max(error);
            if error > options.tol {
                wrong.push(Mismatch {
                    derivative: Derivative::Hessian,
                    row: j,
                    col: k,
                    row_name: nlp.variable_name(j),
                    col_name: nlp.variable_name(k),
                    analytic: hess[j],
                    finite_difference: fd,
                    error,
                    in_pattern: structural,
                    culprits: Vec::new(),
                });
            }
        }
    }
    let count = wrong.len();
    let mut reported = worst(wrong, options.max_reports);
    for mm in &mut reported {
        mm.culprits = culprits(nlp, x, mm.row, mm.col, options);
    }
    Ok((reported, count, max_error))
}

/// The parts of the Lagrangian whose own Hessian entry (j, k) is wrong: the objective, and
/// each constraint whose Jacobian row holds both variables j and k.
fn culprits(
    nlp: &mut dyn NumericNlp,
    x: &[f64],
    j: usize,
    k: usize,
    options: &DerivativeCheckOptions,
) -> Vec<String> {
    let m = nlp.m();
    let jac = nlp.jac_g_sparsity().clone();
    let rows_of = |c: usize| -> Vec<usize> { jac.col_range(c).map(|p| jac.row_idx()[p]).collect() };
    let (rj, rk) = (rows_of(j), rows_of(k));
    let mut parts: Vec<(String, f64, Vec<f64>)> = vec![("objective".into(), 1.0, vec![0.0; m])];
    for i in rj.into_iter().filter(|i| rk.contains(i)) {
        let mut e = vec![0.0; m];
        e[i] = 1.0;
        parts.push((nlp.constraint_name(i), 0.0, e));
    }
    let mut out = Vec::new();
    for (name, sigma, lambda) in parts {
        let values = analytic_hessian(nlp, x, sigma, &lambda);
        let analytic = column(nlp.hess_l_sparsity(), &values, k)[j];
        let fd = fd_hessian_column(nlp, x, k, sigma, &lambda, options.perturbation)[j];
        if relative_error(analytic, fd) > options.tol {
            out.push(name);
        }
    }
    out
}
