//! Errors of assembling, factorising and solving the KKT system.

use thiserror::Error;

/// KKT errors. `ZeroPivot` and `NonFinite` mean "singular: increase the regularisation".
#[derive(Debug, Clone, PartialEq, Error)]
pub enum KktError {
    /// A pattern has the wrong shape or content.
    #[error("invalid KKT pattern: {0}")]
    Pattern(String),
    /// A value vector has the wrong length.
    #[error("wrong length of {what}: expected {expected}, got {got}")]
    Length {
        /// Which vector.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// faer's symbolic analysis failed.
    #[error("symbolic factorisation failed: {0}")]
    Symbolic(String),
    /// Exactly zero pivot.
    #[error("zero pivot at (permuted) index {0}")]
    ZeroPivot(usize),
    /// A non-finite value in the matrix or in D.
    #[error("non-finite value in the KKT matrix or its factor")]
    NonFinite,
    /// `solve` was called without a successful factorisation.
    #[error("no valid factorisation")]
    NotFactorized,
}
