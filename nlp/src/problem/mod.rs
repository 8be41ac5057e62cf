//! [`Problem`]: an Opti-like builder of nonlinear programs over symx expressions.
//!
//! The builder's parts: [`bounds`] (per-entry bounds, simple bound detection),
//! [`cone`] (second-order cones), [`complementarity`], [`error`] ([`BuildError`]); parameters
//! are set through [`crate::parameter`].
mod block;
pub mod bounds;
mod builder;
pub mod complementarity;
pub mod cone;
mod cone_record;
pub mod error;
pub mod file;
pub mod guess;
mod parts;
mod per_entry;
pub mod solver_node;
pub mod to_function;

pub(crate) use block::row_name;
pub use block::Block;
pub use bounds::PerEntry;
pub use builder::{Problem, DETECT_SIMPLE_BOUNDS};
pub use complementarity::ComplementarityReport;
pub use cone::{Cone, CONE_SMOOTHING};
pub use error::BuildError;
pub use file::{ProblemFileError, PROBLEM_FILE_FORMAT, PROBLEM_FILE_VERSION};
pub use guess::linspace;
pub(crate) use parts::ProblemParts;
pub use solver_node::SECOND_DERIVATIVE_STEP;
pub use to_function::{SolverFunction, ToFunctionError};

/// The guide `docs/problem.md`, compiled and run as doc tests so that its examples stay
/// true.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/problem.md")]
pub struct ProblemGuide;
