//! Second-order cones `‖v‖ ≤ t` (see [`Problem::subject_to_cone`]).
pub use super::cone_record::{Cone, CONE_SMOOTHING};

use super::{BuildError, Problem};
use crate::constraint::Relation;
use symx::Expr;

impl Problem {
    /// Adds the second-order cone constraint `‖v‖ ≤ t` (Euclidean norm).
    ///
    /// It becomes one row of g, named `name`, in the smooth convex form
    ///
    /// `√(‖v‖² + ε²) − t ≤ ε`, with ε = [`CONE_SMOOTHING`] = 1e-8,
    ///
    /// which solvers without cones (the interior-point method) solve as an ordinary
    /// constraint. It implies t ≥ 0 and is an outer approximation of the cone: it contains
    /// the cone and its points satisfy `‖v‖ − t ≤ ε` (the gap `‖v‖ + ε − √(‖v‖² + ε²)` is
    /// in [0, ε), largest at ‖v‖ ≫ ε); unlike `‖v‖ − t ≤ 0` it is differentiable at v = 0.
    ///
    /// When v and t are affine in the variables (their Hessians with respect to the
    /// variables are structurally zero; parameters are allowed), the cone is also recorded
    /// as an [`AffineCone`](crate::AffineCone) of the compiled problem: the SQP back end
    /// then replaces the smooth row by the exact cone, handed to clarabel as a second-order
    /// cone on the (exact) linearisation `‖v + ∇v·d‖ ≤ t + ∇t·d`. Otherwise the SQP
    /// linearises the smooth row like any other.
    pub fn subject_to_cone(&mut self, name: &str, v: &[Expr], t: Expr) -> Result<(), BuildError> {
        if v.is_empty() {
            return Err(BuildError::Size {
                what: format!("cone '{name}': entries of v"),
                expected: 1,
                got: 0,
            });
        }
        let mut affine = true;
        for &e in v.iter().chain(std::iter::once(&t)) {
            if e.value().is_none() && symx::hessian(e, &self.variables)?.nnz() != 0 {
                affine = false;
                break;
            }
        }
        let eps = CONE_SMOOTHING;
        let mut sum = Expr::constant(eps * eps);
        for &e in v {
            sum += e.sq();
        }
        let start = self.rows.len();
        self.subject_to_named(name, (sum.sqrt() - t).le(eps))?;
        debug_assert_eq!(self.rows.len(), start + 1);
        self.cones.push(Cone {
            name: name.to_string(),
            row: start,
            t,
            v: v.to_vec(),
            affine,
        });
        Ok(())
    }

    /// The second-order cones in the order they were added.
    pub fn cones(&self) -> &[Cone] {
        &self.cones
    }

    /// Largest violation `max(0, ‖v‖ − t)` over the cones at `x` (0 without cones).
    pub fn cone_residual(&self, x: &[f64]) -> Result<f64, BuildError> {
        let mut r: f64 = 0.0;
        for c in &self.cones {
            let mut exprs = vec![c.t];
            exprs.extend_from_slice(&c.v);
            let val = self.evaluate(&exprs, x)?;
            let norm = val[1..].iter().map(|a| a * a).sum::<f64>().sqrt();
            r = r.max(norm - val[0]);
        }
        Ok(r)
    }
}
