//! [`Solver`]: what both back ends offer, so that drivers choose one at run time
//! (`&dyn Solver`) instead of matching on the back end; [`SolverOptions`]: the same for
//! their options (set by name, the common part, the solver they configure).

use std::ops::{ControlFlow, Deref, DerefMut};

use super::CommonOptions;
use crate::callback::{IterationCallback, IterationView};
use crate::error::SolveError;
use crate::numeric::NumericNlp;
use crate::option_names::OptionError;
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

    /// [`Solver::solve_warm`] with the result written into `out` (any solution, e.g. the
    /// last step's in an MPC loop), reusing its vectors: the IPM's re-solve of a problem
    /// with an unchanged structure then allocates nothing (see
    /// [`Ipm::solve_warm_into`](crate::Ipm::solve_warm_into)). This default solves and
    /// moves the result into `out`. On error `out` is left unspecified.
    fn solve_warm_into(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
        out: &mut Solution,
    ) -> Result<(), SolveError> {
        *out = self.solve_dyn(nlp, Some(previous), None)?;
        Ok(())
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

/// The [`Solver`] entry points as inherent methods of a back end, each one call of
/// [`Solver::solve_dyn`]: callers need no `use nlp::Solver` and pass callbacks by value.
/// `$warm` documents what the back end's `solve_warm` reuses.
macro_rules! solver_entry_points {
    ($solver:ident, $warm:literal) => {
        impl $solver {
            /// Solves from the problem's initial point.
            pub fn solve(
                &self,
                nlp: &mut dyn $crate::numeric::NumericNlp,
            ) -> Result<$crate::solution::Solution, $crate::error::SolveError> {
                $crate::frontend::Solver::solve_dyn(self, nlp, None, None)
            }

            #[doc = $warm]
            pub fn solve_warm(
                &self,
                nlp: &mut dyn $crate::numeric::NumericNlp,
                previous: &$crate::solution::Solution,
            ) -> Result<$crate::solution::Solution, $crate::error::SolveError> {
                $crate::frontend::Solver::solve_dyn(self, nlp, Some(previous), None)
            }

            /// `solve` with a per-iteration callback (IPOPT's `intermediate_callback`):
            /// `callback` sees every iteration, restoration iterations and iteration 0
            /// included, once per row of `Solution::stats.records`, before the
            /// convergence test; returning [`ControlFlow::Break`](std::ops::ControlFlow::Break)
            /// ends the solve with [`Status::UserRequestedStop`](crate::Status::UserRequestedStop)
            /// at that point. See [`crate::callback`].
            pub fn solve_with_callback(
                &self,
                nlp: &mut dyn $crate::numeric::NumericNlp,
                mut callback: impl FnMut(
                    &$crate::callback::IterationView<'_>,
                ) -> std::ops::ControlFlow<()>,
            ) -> Result<$crate::solution::Solution, $crate::error::SolveError> {
                $crate::frontend::Solver::solve_dyn(self, nlp, None, Some(&mut callback))
            }

            /// `solve_warm` with a per-iteration callback (see `solve_with_callback`).
            pub fn solve_warm_with_callback(
                &self,
                nlp: &mut dyn $crate::numeric::NumericNlp,
                previous: &$crate::solution::Solution,
                mut callback: impl FnMut(
                    &$crate::callback::IterationView<'_>,
                ) -> std::ops::ControlFlow<()>,
            ) -> Result<$crate::solution::Solution, $crate::error::SolveError> {
                $crate::frontend::Solver::solve_dyn(self, nlp, Some(previous), Some(&mut callback))
            }
        }
    };
}

pub(crate) use solver_entry_points;

/// The options of one back end ([`IpmOptions`](crate::IpmOptions) or
/// [`SqpOptions`](crate::SqpOptions)) behind a `&dyn`, so
/// that a driver holding either sets them by name, reads and writes their common part
/// (through `Deref`/`DerefMut` to [`CommonOptions`], the one way to it, as on the
/// concrete options) and builds their solver without matching on the back end.
/// ```
/// use nlp::{IpmOptions, SolverOptions, SqpOptions};
///
/// let mut ipm = IpmOptions::default();
/// let mut sqp = SqpOptions::default();
/// for o in [&mut ipm as &mut dyn SolverOptions, &mut sqp] {
///     o.set_options_by_name(&["tol=1e-10", "max_iter=50"]).unwrap();
///     // The common part through `Deref`, as on the concrete options (`ipm.tol`).
///     assert_eq!((o.tol, o.max_iter), (1e-10, 50));
///     // An option of the other back end only is refused, named.
///     let err = o.set_options_by_name(&["mu_init=1e-3", "penalty_init=5"]).unwrap_err();
///     assert!(err.to_string().contains("unknown option"), "{err}");
/// }
/// assert_eq!(ipm.solver().name(), "ipm");
/// assert_eq!(sqp.solver().name(), "sqp");
/// ```
pub trait SolverOptions:
    Deref<Target = CommonOptions> + DerefMut + Send + Sync + std::fmt::Debug
{
    /// Applies `KEY=VALUE` assignments in order (the names of
    /// [`NamedOptions`](crate::option_names::NamedOptions): the
    /// fields of the options struct); on any error nothing changes and the error names
    /// the option.
    fn set_options_by_name(&mut self, assignments: &[&str]) -> Result<(), OptionError>;

    /// The solver with a copy of these options.
    fn solver(&self) -> Box<dyn Solver>;
}

/// `SolverOptions` for an options struct (with the `Deref` to [`CommonOptions`] of
/// `strict_options_serde!`), whose solver is built by `$solver::new`; invoked by each
/// back end, so that the front end does not import them.
macro_rules! impl_solver_options {
    ($($options:ty => $solver:ident),*) => {$(
        impl $crate::frontend::SolverOptions for $options {
            fn set_options_by_name(
                &mut self,
                assignments: &[&str],
            ) -> Result<(), $crate::option_names::OptionError> {
                $crate::option_names::NamedOptions::set_by_name(self, assignments)
            }

            fn solver(&self) -> Box<dyn $crate::frontend::Solver> {
                Box::new($solver::new(self.clone()))
            }
        }
    )*};
}

pub(crate) use impl_solver_options;
