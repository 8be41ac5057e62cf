//! What passes between the outer iteration and a restoration phase: when a phase may
//! start ([`refusal`]), the outer state it starts from ([`Entry`]), how it ended
//! ([`Ended`]) and what the outer iteration does next ([`Ended::next`]).

use crate::frontend::scaled::Scaling;
use crate::ipm::core::{Iterate, Layout};
use crate::ipm::filter::Filter;
use crate::ipm::reduced::IpmProblem;
use crate::options::IpmOptions;
use crate::solution::Status;

/// The outer iteration's state, lent to a restoration phase for its duration.
pub(crate) struct Entry<'a> {
    /// The problem being solved (the restoration problem evaluates through it).
    pub nlp: &'a mut dyn IpmProblem,
    pub lay: &'a Layout,
    /// The iterate whose step failed.
    pub it: &'a Iterate,
    /// The outer barrier parameter μ.
    pub mu: f64,
    pub opts: &'a IpmOptions,
    /// The outer filter, already augmented with the current point: the phase ends at
    /// a point acceptable to it.
    pub filter: &'a Filter,
    /// θ_max of the outer line search.
    pub theta_max: f64,
    /// The outer problem's scaling (the log shows the user's units).
    pub scaling: &'a Scaling,
    /// The failed line search (α_pr, trial count) the phase's first log row shows.
    pub failed_search: Option<(f64, usize)>,
}

/// How a restoration phase ended.
pub(crate) struct Ended {
    /// The inner iteration's status.
    pub status: Status,
    pub message: String,
    /// The restoration problem converged (a minimiser of the infeasibility) rather than
    /// being stopped at a point acceptable to the outer filter.
    pub converged: bool,
    /// The phase's final point in the outer variables w = [x; s], for the outer
    /// iteration to move to; `None` when it stays where it is.
    pub point: Option<Vec<f64>>,
}

/// What the outer iteration does after a restoration phase.
#[derive(Debug, PartialEq)]
pub(crate) enum Next {
    /// Go on from the restored point, with an emptied filter if `reset_filter`.
    Resume { reset_filter: bool },
    /// The solve ends with this status and message.
    Stop { status: Status, message: String },
}

/// Why no restoration phase can start, as the solve's final status and message, or
/// `None` when one can: not inside a restoration phase (it would restore itself), and
/// not without constraints (the iteration then ends solved to an acceptable level if
/// the last iterate was acceptable, else with a too small search direction).
pub(crate) fn refusal(
    in_resto: bool,
    m: usize,
    last_acceptable: bool,
    why: &str,
) -> Option<(Status, String)> {
    if in_resto {
        return Some((Status::RestorationFailed, format!("{why} in restoration")));
    }
    if m == 0 {
        let status = if last_acceptable {
            Status::SolvedToAcceptableLevel
        } else {
            Status::SearchDirectionBecomesTooSmall
        };
        return Some((status, format!("{why} for a problem without constraints")));
    }
    None
}

impl Ended {
    /// The outer iteration's next step, given the result of moving it to
    /// [`Ended::point`] (`moved`: `None` if there is no point, else `Ok` with the outer
    /// constraint violation there in the user's units or the evaluation's error).
    ///
    /// A phase that stopped at an acceptable point resumes the iteration; one that
    /// converged does too if that point is feasible (`constr_viol_tol`), with a reset
    /// filter, else the problem is locally infeasible. Limits and a user stop end the
    /// solve with their own status, anything else as a failed restoration.
    pub(crate) fn next(self, moved: Option<Result<f64, String>>, constr_viol_tol: f64) -> Next {
        let stop = |status, message| Next::Stop { status, message };
        let Some(moved) = moved else {
            return stop(Status::RestorationFailed, self.message);
        };
        match self.status {
            Status::SolveSucceeded => match moved {
                Err(e) => stop(Status::RestorationFailed, e),
                Ok(viol) if self.converged && viol > constr_viol_tol => stop(
                    Status::InfeasibleProblemDetected,
                    format!(
                        "restoration converged to a point of local infeasibility (constraint violation {viol:.3e})"
                    ),
                ),
                Ok(_) => Next::Resume {
                    reset_filter: self.converged,
                },
            },
            Status::MaximumIterationsExceeded
            | Status::MaximumWallTimeExceeded
            | Status::UserRequestedStop => stop(self.status, with_error(self.message, moved)),
            _ => stop(Status::RestorationFailed, with_error(self.message, moved)),
        }
    }
}

/// `message` with the failure to move to the restoration's point appended.
fn with_error(message: String, moved: Result<f64, String>) -> String {
    match moved {
        Ok(_) => message,
        Err(e) if message.is_empty() => e,
        Err(e) => format!("{message}; {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::{refusal, Ended, Next};
    use crate::solution::Status;

    fn ended(status: Status, message: &str, converged: bool) -> Ended {
        Ended {
            status,
            message: message.into(),
            converged,
            point: Some(vec![0.0]),
        }
    }

    #[test]
    fn a_phase_stopped_at_an_acceptable_point_resumes_with_the_filter() {
        let next = ended(Status::SolveSucceeded, "", false).next(Some(Ok(1.0)), 1e-4);
        // Not converged: the point is acceptable to the filter, whatever its violation.
        assert_eq!(
            next,
            Next::Resume {
                reset_filter: false
            }
        );
    }

    #[test]
    fn a_converged_phase_resumes_at_a_feasible_point_and_stops_at_an_infeasible_one() {
        let feasible = ended(Status::SolveSucceeded, "", true).next(Some(Ok(1e-5)), 1e-4);
        assert_eq!(feasible, Next::Resume { reset_filter: true });
        let infeasible = ended(Status::SolveSucceeded, "", true).next(Some(Ok(2e-4)), 1e-4);
        let Next::Stop { status, message } = infeasible else {
            panic!("an infeasible minimiser of the violation must end the solve");
        };
        assert_eq!(status, Status::InfeasibleProblemDetected);
        assert!(message.contains("2.000e-4"), "{message}");
    }

    #[test]
    fn a_failed_move_or_inner_failure_is_a_failed_restoration() {
        let next = ended(Status::SolveSucceeded, "", false).next(Some(Err("NaN".into())), 1e-4);
        assert_eq!(
            next,
            Next::Stop {
                status: Status::RestorationFailed,
                message: "NaN".into()
            }
        );
        let no_point = Ended {
            point: None,
            ..ended(Status::InvalidNumberDetected, "f is NaN", false)
        };
        assert_eq!(
            no_point.next(None, 1e-4),
            Next::Stop {
                status: Status::RestorationFailed,
                message: "f is NaN".into()
            }
        );
        let other = ended(Status::ErrorInStepComputation, "inertia", false);
        assert_eq!(
            other.next(Some(Err("g is NaN".into())), 1e-4),
            Next::Stop {
                status: Status::RestorationFailed,
                message: "inertia; g is NaN".into()
            }
        );
    }

    #[test]
    fn limits_and_user_stops_keep_their_status() {
        for status in [
            Status::MaximumIterationsExceeded,
            Status::MaximumWallTimeExceeded,
            Status::UserRequestedStop,
        ] {
            let next = ended(status, "limit", false).next(Some(Ok(1.0)), 1e-4);
            assert_eq!(
                next,
                Next::Stop {
                    status,
                    message: "limit".into()
                }
            );
        }
    }

    #[test]
    fn no_phase_starts_inside_one_or_without_constraints() {
        assert_eq!(refusal(false, 3, false, "line search failed"), None);
        let (status, message) = refusal(true, 3, false, "line search failed").unwrap();
        assert_eq!(status, Status::RestorationFailed);
        assert_eq!(message, "line search failed in restoration");
        assert_eq!(
            refusal(false, 0, true, "x").map(|r| r.0),
            Some(Status::SolvedToAcceptableLevel)
        );
        assert_eq!(
            refusal(false, 0, false, "x").map(|r| r.0),
            Some(Status::SearchDirectionBecomesTooSmall)
        );
    }
}
