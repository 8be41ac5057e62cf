//! Why the interior-point core could not start or resume: a non-finite value from a
//! callback (ended as `InvalidNumberDetected` or `RestorationFailed`) or a KKT setup
//! failure (`InternalError`). The message of the solution is this error's text.

use thiserror::Error;

use crate::kkt::KktError;

/// Where an evaluation happened.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum At {
    /// The (pushed) starting point.
    Start,
    /// The point a restoration phase returned.
    RestorationResult,
}

impl std::fmt::Display for At {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            At::Start => "the starting point",
            At::RestorationResult => "the restoration result",
        })
    }
}

/// A failure of the core's setup or of an evaluation it cannot recover from.
#[derive(Debug, Clone, PartialEq, Error)]
pub(crate) enum CoreError {
    #[error("eval_f returned {value} at {at}")]
    Objective { value: f64, at: At },
    #[error("eval_grad_f returned {value} for variable {index} ('{name}') at {at}")]
    Gradient {
        value: f64,
        index: usize,
        name: String,
        at: At,
    },
    #[error("eval_g returned {value} for constraint {index} ('{name}') at {at}")]
    Constraint {
        value: f64,
        index: usize,
        name: String,
        at: At,
    },
    #[error("eval_jac_g returned {value} at row {row} ('{row_name}'), column {col} ('{col_name}') at {at}")]
    Jacobian {
        value: f64,
        row: usize,
        row_name: String,
        col: usize,
        col_name: String,
        at: At,
    },
    #[error(
        "eval_hess_l returned {value} at entry ({row}, {col}) ('{row_name}', '{col_name}') at {at}"
    )]
    Hessian {
        value: f64,
        row: usize,
        row_name: String,
        col: usize,
        col_name: String,
        at: At,
    },
    #[error("KKT setup: {0}")]
    Kkt(#[from] KktError),
}
