//! What the two back ends ([`Ipm`](crate::Ipm), [`Sqp`](crate::Sqp)) share in front of
//! and behind their iterations:
//!
//! - [`common_options`]: [`CommonOptions`], the options with one meaning in both;
//! - `validate`: one check of the problem handed to a solver (sizes, the Hessian's
//!   lower triangle, cone rows, bounds, starting point);
//! - `scaled`: the user's problem scaled (`ScaledNlp`: s_f, s_g, evaluation counters
//!   and timing, multipliers to and from the user's units);
//! - `point_values`: f, g, ∇f and J at the last point evaluated, so that no value is
//!   evaluated twice at one point (the end of a solve reuses the final iterate's);
//! - `user_solution`: the returned `Solution` in the user's units with its KKT
//!   measures;
//! - `termination`: the KKT error of an iterate (`KktResiduals`) and one
//!   convergence test (`tol` and the `acceptable_*` options);
//! - [`solver`]: the [`Solver`] trait both implement, through which drivers
//!   ([`solve_mpcc`](crate::solve_mpcc), the planner) dispatch, and [`SolverOptions`],
//!   the same for their options (set by name, common part, solver).

pub mod common_options;
pub(crate) mod point_values;
pub(crate) mod scaled;
pub mod solver;
pub(crate) mod termination;
pub(crate) mod user_solution;
pub(crate) mod validate;

pub(crate) use common_options::strict_options_serde;
pub use common_options::CommonOptions;
pub use solver::{Solver, SolverOptions};
pub(crate) use termination::{KktResiduals, Termination};
