//! Errors for invalid solver input.

use thiserror::Error;

/// Invalid input to a solver. A run that fails numerically is *not* an error: it returns a
/// [`Solution`](crate::Solution) with a failing [`Status`](crate::Status).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolveError {
    /// A variable's lower bound exceeds its upper bound.
    #[error("variable {index} ('{name}'): lower bound {lower} > upper bound {upper}")]
    InconsistentVariableBounds {
        /// Variable index.
        index: usize,
        /// Variable name.
        name: String,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// A constraint's lower bound exceeds its upper bound.
    #[error("constraint {index} ('{name}'): lower bound {lower} > upper bound {upper}")]
    InconsistentConstraintBounds {
        /// Constraint index.
        index: usize,
        /// Constraint name.
        name: String,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// A bound is NaN, or a lower bound is +∞ / an upper bound is −∞.
    #[error("invalid bound for {what} {index} ('{name}'): {value}")]
    InvalidBound {
        /// "variable" or "constraint".
        what: &'static str,
        /// Index.
        index: usize,
        /// Name.
        name: String,
        /// The offending value.
        value: f64,
    },
    /// The starting point has a non-finite entry.
    #[error("initial point: non-finite value {value} for variable {index} ('{name}')")]
    InvalidInitialPoint {
        /// Variable index.
        index: usize,
        /// Variable name.
        name: String,
        /// The offending value.
        value: f64,
    },
    /// A sparsity pattern or vector has the wrong dimensions or shape.
    #[error("wrong size: {0}")]
    WrongSize(String),
    /// A parameter of the problem was never given a value (see
    /// [`Compiled::set_value`](crate::Compiled::set_value)).
    #[error("parameter '{name}' has no value (call set_value before solving)")]
    MissingParameterValue {
        /// The parameter entry.
        name: String,
    },
    /// An option value is invalid.
    #[error("invalid option '{field}': {reason}")]
    InvalidOption {
        /// Option name.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
}
