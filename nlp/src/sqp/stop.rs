//! Why an SQP solve stops: the status and message it ends with, and the typed failures of
//! its steps.

use clarabel::solver::SolverStatus;
use thiserror::Error;

use super::qp::QpError;
use crate::kkt::KktError;
use crate::solution::Status;

/// A step of the SQP iteration that could not be carried out.
#[derive(Debug, Error)]
pub(super) enum StepError {
    /// The KKT matrix used to certify B's convexity (and to polish) could not be set up.
    #[error("the KKT matrix of the convexification could not be set up: {0}")]
    KktSetup(#[from] KktError),
    /// ∇²L has a NaN or infinite entry.
    #[error("the Lagrangian Hessian has a non-finite value")]
    NonFiniteHessian,
    /// No shift up to `max_hessian_shift` made B positive definite.
    #[error("no Hessian shift up to max_hessian_shift made B positive definite")]
    NoConvexification,
    /// clarabel rejected the QP.
    #[error("QP setup failed: {0}")]
    QpSetup(#[from] QpError),
    /// clarabel did not solve the QP, after the retries.
    #[error("QP solver (clarabel) returned {0:?}")]
    QpStatus(SolverStatus),
    /// ∇f or the Jacobian is not finite at the accepted point.
    #[error("non-finite gradient or Jacobian at the accepted point")]
    NonFiniteDerivatives,
}

impl StepError {
    /// The solve's status when this error ends it.
    pub fn status(&self) -> Status {
        match self {
            StepError::KktSetup(_) => Status::InternalError,
            StepError::NonFiniteHessian | StepError::NonFiniteDerivatives => {
                Status::InvalidNumberDetected
            }
            StepError::NoConvexification | StepError::QpSetup(_) | StepError::QpStatus(_) => {
                Status::ErrorInStepComputation
            }
        }
    }
}

/// How a solve ends: its status and a message for `Solution::message`.
pub(super) struct Stop {
    pub status: Status,
    pub message: String,
}

impl Stop {
    /// A stop with an empty message.
    pub fn new(status: Status) -> Stop {
        Stop {
            status,
            message: String::new(),
        }
    }
}

impl From<StepError> for Stop {
    fn from(e: StepError) -> Stop {
        Stop {
            status: e.status(),
            message: e.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{StepError, Stop};
    use crate::kkt::KktError;
    use crate::solution::Status;
    use clarabel::solver::SolverStatus;

    #[test]
    fn a_kkt_setup_failure_names_its_cause() {
        let stop = Stop::from(StepError::from(KktError::Symbolic("out of memory".into())));
        assert_eq!(stop.status, Status::InternalError);
        assert!(stop.message.contains("KKT matrix"), "{}", stop.message);
        assert!(stop.message.contains("out of memory"), "{}", stop.message);
        let stop = Stop::from(StepError::QpStatus(SolverStatus::InsufficientProgress));
        assert_eq!(stop.status, Status::ErrorInStepComputation);
        assert!(
            stop.message.contains("InsufficientProgress"),
            "{}",
            stop.message
        );
    }
}
