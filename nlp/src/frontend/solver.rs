//! [`Solver`]: what both back ends offer, so that drivers choose one at run time
//! (`&dyn Solver`) instead of matching on the back end.

use std::ops::ControlFlow;

use crate::callback::{IterationCallback, IterationView};
use crate::error::SolveError;
use crate::numeric::NumericNlp;
use crate::solution::Solution;

/// A solver of [`NumericNlp`]s: [`Ipm`](crate::Ipm) or [`Sqp`](crate::Sqp).
///
/// Implementors provide [`Solver::solve_dyn`]; the other methods are provided.
/// ```
/// use nlp::{Ipm, Problem, Solver, Sqp};
///
/// let mut pb = Problem::new();
/// let x = pb.variable("x", 2).unwrap();
/// pb.minimize((x[0] - 1.0).sq() + (x[1] - 2.0).sq());
/// let ipm = Ipm::default();
/// let sqp = Sqp::default();
/// for solver in [&ipm as &dyn Solver, &sqp] {
///     let sol = solver.solve(&mut pb.compile().unwrap()).unwrap();
///     assert!(sol.status.is_success(), "{}: {}", solver.name(), sol.status);
/// }
/// ```
pub trait Solver: Send + Sync {
    /// Short name for logs and files: `"ipm"` or `"sqp"`.
    fn name(&self) -> &'static str;

    /// The solve behind every entry point: from `warm` (a previous solution's x and
    /// multipliers, size-checked) or the problem's initial point, calling `callback`
    /// once per iteration.
    fn solve_dyn(
        &self,
        nlp: &mut dyn NumericNlp,
        warm: Option<&Solution>,
        callback: Option<&mut IterationCallback<'_>>,
    ) -> Result<Solution, SolveError>;

    /// Solves from the problem's initial point.
    fn solve(&self, nlp: &mut dyn NumericNlp) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, None, None)
    }

    /// Starts from a previous solution of a problem of the same size (see the back
    /// end's `solve_warm` for what is reused).
    fn solve_warm(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
    ) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, Some(previous), None)
    }

    /// [`Solver::solve`] with a per-iteration callback (see [`crate::callback`]):
    /// [`ControlFlow::Break`] ends the solve with
    /// [`Status::UserRequestedStop`](crate::Status::UserRequestedStop).
    fn solve_with_callback(
        &self,
        nlp: &mut dyn NumericNlp,
        callback: &mut dyn FnMut(&IterationView<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, None, Some(callback))
    }

    /// [`Solver::solve_warm`] with a per-iteration callback.
    fn solve_warm_with_callback(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
        callback: &mut dyn FnMut(&IterationView<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, Some(previous), Some(callback))
    }
}
