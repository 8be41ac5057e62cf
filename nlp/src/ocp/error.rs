//! [`OcpError`]: what is wrong with an optimal control problem or its transcription.
use crate::problem::BuildError;
use thiserror::Error;

/// A mistake in an optimal control problem or its transcription, naming the culprit.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum OcpError {
    /// A Butcher tableau that is not an explicit Runge–Kutta method.
    #[error("Butcher tableau '{name}': {why}")]
    Tableau { name: String, why: String },
    /// A collocation degree outside the supported range.
    #[error("collocation degree {0} is outside 1..=60")]
    Degree(usize),
    /// A numerical routine failed (e.g. the eigensolver of the collocation points).
    #[error("{0}")]
    Numerical(String),
    /// Two lengths that must agree.
    #[error("{what}: expected {expected} values, got {got}")]
    Size {
        what: String,
        expected: usize,
        got: usize,
    },
    /// An invalid setting.
    #[error("{what}: {why}")]
    Invalid { what: String, why: String },
    /// No dynamics was given.
    #[error("the problem has no dynamics: call Ocp::set_dynamics")]
    NoDynamics,
    /// No final time was given.
    #[error("the problem has no final time: call Ocp::set_horizon (Horizon::Fixed(T) or Horizon::Free {{ .. }})")]
    NoHorizon,
    /// An error of the underlying problem.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// An error from symx.
    #[error(transparent)]
    Symx(#[from] symx::SymxError),
}
