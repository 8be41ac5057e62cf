//! One check of the problem handed to either back end, before any evaluation: the
//! stricter of the rules the two back ends used to apply separately.

use crate::error::SolveError;
use crate::numeric::NumericNlp;
use crate::solution::Solution;

/// Bounds and starting point of a problem that passed [`validate`].
#[derive(Default)]
pub(crate) struct Validated {
    pub x_l: Vec<f64>,
    pub x_u: Vec<f64>,
    pub g_l: Vec<f64>,
    pub g_u: Vec<f64>,
    /// The starting point: `warm.x` if given, else the problem's initial point.
    pub x0: Vec<f64>,
}

/// Checks, in this order: the problem is ready ([`NumericNlp::check_ready`], e.g. every
/// parameter has a value), the Jacobian pattern is m×n, the Hessian pattern n×n with
/// entries in the lower triangle only, every cone row is a row of g, no bound is NaN,
/// +∞ below or −∞ above, every lower bound is at most its upper bound, the warm start
/// (if any) has the problem's sizes, and the starting point is finite. The error names
/// the first violation.
pub(crate) fn validate(
    nlp: &dyn NumericNlp,
    warm: Option<&Solution>,
) -> Result<Validated, SolveError> {
    let mut v = Validated::default();
    validate_into(nlp, warm, &mut v)?;
    Ok(v)
}

/// [`validate`] into the vectors of `v` (resized; no allocation once they have grown to
/// the problem's sizes). On error `v` holds no meaningful values.
pub(crate) fn validate_into(
    nlp: &dyn NumericNlp,
    warm: Option<&Solution>,
    v: &mut Validated,
) -> Result<(), SolveError> {
    nlp.check_ready()?;
    let n = nlp.n();
    let m = nlp.m();
    let jac = nlp.jac_g_sparsity();
    if jac.nrows() != m || jac.ncols() != n {
        return Err(SolveError::WrongSize(format!(
            "Jacobian pattern is {}x{}, expected {m}x{n}",
            jac.nrows(),
            jac.ncols()
        )));
    }
    let hess = nlp.hess_l_sparsity();
    if hess.nrows() != n || hess.ncols() != n {
        return Err(SolveError::WrongSize(format!(
            "Hessian pattern is {}x{}, expected {n}x{n}",
            hess.nrows(),
            hess.ncols()
        )));
    }
    for c in 0..n {
        if let Some(&r) = hess.row_idx_of_col_raw(c).iter().find(|&&r| r < c) {
            return Err(SolveError::WrongSize(format!(
                "Hessian pattern entry ({r}, {c}) is above the diagonal; give the lower triangle"
            )));
        }
    }
    if let Some(c) = nlp.affine_cones().iter().find(|c| c.row >= m) {
        return Err(SolveError::WrongSize(format!(
            "cone row {} out of range (m = {m})",
            c.row
        )));
    }
    for (vec, len) in [
        (&mut v.x_l, n),
        (&mut v.x_u, n),
        (&mut v.g_l, m),
        (&mut v.g_u, m),
        (&mut v.x0, n),
    ] {
        vec.clear();
        vec.resize(len, 0.0);
    }
    nlp.bounds(&mut v.x_l, &mut v.x_u, &mut v.g_l, &mut v.g_u);
    check_bounds("variable", &v.x_l, &v.x_u, &|i| nlp.variable_name(i))?;
    check_bounds("constraint", &v.g_l, &v.g_u, &|i| nlp.constraint_name(i))?;
    match warm {
        Some(prev) => {
            prev.check_warm_start(n, m)?;
            v.x0.copy_from_slice(&prev.x);
        }
        None => nlp.initial_point(&mut v.x0),
    }
    if let Some((i, &x)) = v.x0.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(SolveError::InvalidInitialPoint {
            index: i,
            name: nlp.variable_name(i),
            value: x,
        });
    }
    Ok(())
}

fn check_bounds(
    what: &'static str,
    l: &[f64],
    u: &[f64],
    name: &dyn Fn(usize) -> String,
) -> Result<(), SolveError> {
    for i in 0..l.len() {
        for (value, bad) in [
            (l[i], l[i].is_nan() || l[i] == f64::INFINITY),
            (u[i], u[i].is_nan() || u[i] == f64::NEG_INFINITY),
        ] {
            if bad {
                return Err(SolveError::InvalidBound {
                    what,
                    index: i,
                    name: name(i),
                    value,
                });
            }
        }
        if l[i] > u[i] {
            let (index, name, lower, upper) = (i, name(i), l[i], u[i]);
            return Err(if what == "variable" {
                SolveError::InconsistentVariableBounds {
                    index,
                    name,
                    lower,
                    upper,
                }
            } else {
                SolveError::InconsistentConstraintBounds {
                    index,
                    name,
                    lower,
                    upper,
                }
            });
        }
    }
    Ok(())
}
