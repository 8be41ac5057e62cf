//! Results of a solve: status, primal/dual point, statistics and iteration records.

use serde::{Deserialize, Serialize};

/// Outcome of a solve (IPOPT's return-code vocabulary). `Display` prints IPOPT's name
/// of the code (`Solve_Succeeded`). New outcomes may be added: match with a wildcard.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Status {
    /// Converged to the requested tolerances.
    SolveSucceeded,
    /// Converged to the "acceptable" tolerances only.
    SolvedToAcceptableLevel,
    /// The iterates converged to a local minimiser of the infeasibility: the problem is
    /// (locally) infeasible.
    InfeasibleProblemDetected,
    /// The search direction became negligibly small before convergence.
    SearchDirectionBecomesTooSmall,
    /// The iterates grew beyond `diverging_iterates_tol` (problem possibly unbounded).
    DivergingIterates,
    /// The iteration callback (`solve_with_callback`, see [`crate::callback`]) returned
    /// `ControlFlow::Break`; the solution is the iterate it was shown.
    UserRequestedStop,
    /// A feasible point was found (feasibility-only problems).
    FeasiblePointFound,
    /// `max_iter` was reached.
    MaximumIterationsExceeded,
    /// The feasibility restoration phase failed.
    RestorationFailed,
    /// The linear system could not be solved (inertia correction failed).
    ErrorInStepComputation,
    /// `max_wall_time` was reached.
    MaximumWallTimeExceeded,
    /// A callback returned NaN/Inf at a point where the solver could not recover.
    InvalidNumberDetected,
    /// Fewer free variables than equality constraints.
    NotEnoughDegreesOfFreedom,
    /// An internal error.
    InternalError,
    /// One real-time iteration was taken ([`Rti::feedback`](crate::Rti::feedback)): its
    /// QP was solved and its full step applied. Convergence is not tested, by design: the
    /// KKT residual ([`Rti::residual`](crate::Rti::residual)) tells how far the plan is
    /// from a solution. Not [`Status::is_success`] (a converged solve).
    RealTimeIterationTaken,
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Status::SolveSucceeded => "Solve_Succeeded",
            Status::SolvedToAcceptableLevel => "Solved_To_Acceptable_Level",
            Status::InfeasibleProblemDetected => "Infeasible_Problem_Detected",
            Status::SearchDirectionBecomesTooSmall => "Search_Direction_Becomes_Too_Small",
            Status::DivergingIterates => "Diverging_Iterates",
            Status::UserRequestedStop => "User_Requested_Stop",
            Status::FeasiblePointFound => "Feasible_Point_Found",
            Status::MaximumIterationsExceeded => "Maximum_Iterations_Exceeded",
            Status::RestorationFailed => "Restoration_Failed",
            Status::ErrorInStepComputation => "Error_In_Step_Computation",
            Status::MaximumWallTimeExceeded => "Maximum_WallTime_Exceeded",
            Status::InvalidNumberDetected => "Invalid_Number_Detected",
            Status::NotEnoughDegreesOfFreedom => "Not_Enough_Degrees_Of_Freedom",
            Status::InternalError => "Internal_Error",
            Status::RealTimeIterationTaken => "Real_Time_Iteration_Taken",
        })
    }
}

impl Status {
    /// True for `SolveSucceeded`, `SolvedToAcceptableLevel` and `FeasiblePointFound`.
    pub fn is_success(self) -> bool {
        matches!(
            self,
            Status::SolveSucceeded | Status::SolvedToAcceptableLevel | Status::FeasiblePointFound
        )
    }
}

/// One row of the IPOPT-style iteration table. The columns both back ends fill mean the
/// same in both; [`IterationRecord::backend`] holds the columns of the back end that
/// wrote the row (μ for the interior point, ρ_a for the SQP).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(into = "RecordFields", from = "RecordFields")]
pub struct IterationRecord {
    /// Iteration number. The counter runs on through a restoration phase (IPOPT's
    /// convention): the outer iteration whose line search failed gives its number to the
    /// restoration's first row, each restoration step takes the next one.
    pub iter: usize,
    /// True during the feasibility restoration phase (printed as 'r' after the number).
    pub restoration: bool,
    /// Unscaled objective of the original problem, also during restoration (at the
    /// restoration iterate's x, as IPOPT prints it).
    pub objective: f64,
    /// Unscaled constraint violation of the original problem (max-norm), also during
    /// restoration.
    pub inf_pr: f64,
    /// Dual infeasibility (max-norm), unscaled: divided by the objective scale factor
    /// (IPOPT prints the scaled value; the two differ when the objective is scaled). In
    /// restoration: the restoration problem's, as in IPOPT.
    pub inf_du: f64,
    /// Max-norm of the primal step.
    pub d_norm: f64,
    /// Hessian regularisation used for the step (0: none; printed as lg(rg)): the
    /// interior point's δ_w, the SQP's Hessian shift.
    pub regularization: f64,
    /// The columns of the back end that wrote the row.
    pub backend: BackendColumns,
    /// Dual step size.
    pub alpha_du: f64,
    /// Primal step size.
    pub alpha_pr: f64,
    /// IPOPT's step-type character after alpha_pr: 'f' (f-type: switching and Armijo
    /// conditions hold, the filter is not augmented), 'h' (h-type), upper case with
    /// second-order correction, 'R' on a restoration phase's first row (alpha_pr and ls
    /// are then those of the failed line search), 't' tiny step, ' ' for the initial row.
    pub alpha_pr_char: char,
    /// Number of trial step sizes of the backtracking line search (second-order
    /// corrections are not counted, as in IPOPT).
    pub ls: usize,
}

/// The columns of an [`IterationRecord`] that only one back end has; the fifth column of
/// its table (lg(mu) or lg(ra)) is the first field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BackendColumns {
    /// The interior point's (`Ipm`).
    Ipm {
        /// Barrier parameter μ (printed as lg(mu)).
        mu: f64,
        /// Jacobian regularisation δ_c of the equality rows used for the step (0: none;
        /// not printed in the table, as in IPOPT).
        jacobian_regularization: f64,
    },
    /// The SQP's (`Sqp`).
    Sqp {
        /// Augmented weight ρ_a of its convexified Hessian (0: none; printed as lg(ra)).
        augmented_weight: f64,
    },
}

impl IterationRecord {
    /// The row of a starting point: objective `objective`, every measure and step 0, the
    /// back end's columns `backend`.
    pub(crate) fn starting_point(objective: f64, backend: BackendColumns) -> IterationRecord {
        IterationRecord {
            iter: 0,
            restoration: false,
            objective,
            inf_pr: 0.0,
            inf_du: 0.0,
            d_norm: 0.0,
            regularization: 0.0,
            backend,
            alpha_du: 0.0,
            alpha_pr: 0.0,
            alpha_pr_char: ' ',
            ls: 0,
        }
    }

    /// The interior point's barrier parameter μ; `None` in an SQP row.
    pub fn mu(&self) -> Option<f64> {
        match self.backend {
            BackendColumns::Ipm { mu, .. } => Some(mu),
            BackendColumns::Sqp { .. } => None,
        }
    }

    /// The interior point's Jacobian regularisation δ_c (0 in an SQP row, which has
    /// none).
    pub fn jacobian_regularization(&self) -> f64 {
        match self.backend {
            BackendColumns::Ipm {
                jacobian_regularization,
                ..
            } => jacobian_regularization,
            BackendColumns::Sqp { .. } => 0.0,
        }
    }

    /// The SQP's augmented weight ρ_a; `None` in an interior-point row.
    pub fn augmented_weight(&self) -> Option<f64> {
        match self.backend {
            BackendColumns::Sqp { augmented_weight } => Some(augmented_weight),
            BackendColumns::Ipm { .. } => None,
        }
    }
}

/// The back end named in a stored record.
#[derive(Clone, Copy, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
enum Backend {
    Ipm,
    Sqp,
}

/// An [`IterationRecord`] as a solution file (version 1) stores it: flat, with the
/// columns of both back ends (the other back end's as 0) and `backend` naming the one
/// that wrote it. Files written before `backend` existed have none: their SQP rows
/// carry μ = 0 and the interior point's μ > 0, which tells them apart.
#[derive(Serialize, Deserialize)]
struct RecordFields {
    iter: usize,
    restoration: bool,
    objective: f64,
    inf_pr: f64,
    inf_du: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    backend: Option<Backend>,
    mu: f64,
    d_norm: f64,
    regularization: f64,
    #[serde(default)]
    jacobian_regularization: f64,
    #[serde(default)]
    augmented_weight: f64,
    alpha_du: f64,
    alpha_pr: f64,
    alpha_pr_char: char,
    ls: usize,
}

impl From<IterationRecord> for RecordFields {
    fn from(r: IterationRecord) -> RecordFields {
        let (backend, mu, jacobian_regularization, augmented_weight) = match r.backend {
            BackendColumns::Ipm {
                mu,
                jacobian_regularization,
            } => (Backend::Ipm, mu, jacobian_regularization, 0.0),
            BackendColumns::Sqp { augmented_weight } => (Backend::Sqp, 0.0, 0.0, augmented_weight),
        };
        RecordFields {
            iter: r.iter,
            restoration: r.restoration,
            objective: r.objective,
            inf_pr: r.inf_pr,
            inf_du: r.inf_du,
            backend: Some(backend),
            mu,
            d_norm: r.d_norm,
            regularization: r.regularization,
            jacobian_regularization,
            augmented_weight,
            alpha_du: r.alpha_du,
            alpha_pr: r.alpha_pr,
            alpha_pr_char: r.alpha_pr_char,
            ls: r.ls,
        }
    }
}

impl From<RecordFields> for IterationRecord {
    fn from(f: RecordFields) -> IterationRecord {
        let backend = match f.backend {
            Some(b) => b,
            None if f.mu > 0.0 => Backend::Ipm,
            None => Backend::Sqp,
        };
        IterationRecord {
            iter: f.iter,
            restoration: f.restoration,
            objective: f.objective,
            inf_pr: f.inf_pr,
            inf_du: f.inf_du,
            d_norm: f.d_norm,
            regularization: f.regularization,
            backend: match backend {
                Backend::Ipm => BackendColumns::Ipm {
                    mu: f.mu,
                    jacobian_regularization: f.jacobian_regularization,
                },
                Backend::Sqp => BackendColumns::Sqp {
                    augmented_weight: f.augmented_weight,
                },
            },
            alpha_du: f.alpha_du,
            alpha_pr: f.alpha_pr,
            alpha_pr_char: f.alpha_pr_char,
            ls: f.ls,
        }
    }
}

/// Counters and timers of a solve (filled by the solvers; fields may be added).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Stats {
    /// Number of iterations (including restoration iterations).
    pub iterations: usize,
    /// Iterations spent in restoration.
    pub restoration_iterations: usize,
    /// One record per iteration (row 0 is the starting point).
    pub records: Vec<IterationRecord>,
    /// Objective evaluations.
    pub n_eval_f: usize,
    /// Objective-gradient evaluations.
    pub n_eval_grad_f: usize,
    /// Constraint evaluations.
    pub n_eval_g: usize,
    /// Jacobian evaluations.
    pub n_eval_jac_g: usize,
    /// Hessian evaluations.
    pub n_eval_hess_l: usize,
    /// Numeric KKT factorisations.
    pub n_factorizations: usize,
    /// Largest Hessian regularisation δ_w used (0: none).
    pub max_regularization: f64,
    /// Seconds in user callbacks.
    pub eval_seconds: f64,
    /// Seconds in KKT factorisations and solves.
    pub factor_seconds: f64,
    /// Total wall-clock seconds.
    pub total_seconds: f64,
    /// Seconds in everything else.
    pub other_seconds: f64,
    /// Objective scaling factor used.
    pub obj_scaling: f64,
    /// QP subproblems solved (SQP only; second-order corrections and elastic-mode
    /// re-solves included).
    #[serde(default)]
    pub n_qp_solves: usize,
    /// Interior-point iterations of the QP solver, summed (SQP only).
    #[serde(default)]
    pub qp_iterations: usize,
    /// Seconds in QP solves (SQP only).
    #[serde(default)]
    pub qp_seconds: f64,
    /// Iterations of the interior-point method that started a cold SQP solve
    /// ([`SqpOptions::cold_start_ipm`](crate::SqpOptions::cold_start_ipm)), included in
    /// `iterations` (as its evaluations, factorisations and seconds are in theirs); 0
    /// otherwise.
    #[serde(default)]
    pub start_iterations: usize,
}

/// Result of a solve. Multipliers use IPOPT's sign convention:
/// ∇f(x) + ∇g(x)ᵀλ − z_L + z_U = 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Solution {
    /// Outcome.
    pub status: Status,
    /// Primal point (length n).
    pub x: Vec<f64>,
    /// Constraint multipliers (length m).
    pub lambda: Vec<f64>,
    /// Lower-bound multipliers (length n, ≥ 0).
    pub z_l: Vec<f64>,
    /// Upper-bound multipliers (length n, ≥ 0).
    pub z_u: Vec<f64>,
    /// Constraint values g(x) (length m).
    pub g: Vec<f64>,
    /// Objective f(x).
    pub objective: f64,
    /// Unscaled constraint violation (max-norm, bounds of g and x).
    pub constr_viol: f64,
    /// Unscaled dual infeasibility (max-norm).
    pub dual_inf: f64,
    /// Unscaled complementarity (max-norm).
    pub compl: f64,
    /// Human-readable detail about the outcome (e.g. which callback returned NaN).
    pub message: String,
    /// Statistics.
    pub stats: Stats,
    /// The parameter values the problem was solved with, in declaration order (empty for a
    /// problem without parameters, and in files written before this field existed).
    /// [`crate::Problem::value`] evaluates expressions with them.
    #[serde(default)]
    pub parameters: Vec<f64>,
}

impl Solution {
    /// A solution of no problem (every vector empty, status `InternalError`): the value
    /// a solver fills in place.
    pub(crate) fn empty() -> Solution {
        Solution {
            status: Status::InternalError,
            x: Vec::new(),
            lambda: Vec::new(),
            z_l: Vec::new(),
            z_u: Vec::new(),
            g: Vec::new(),
            objective: 0.0,
            constr_viol: 0.0,
            dual_inf: 0.0,
            compl: 0.0,
            message: String::new(),
            stats: Stats::default(),
            parameters: Vec::new(),
        }
    }

    /// Checks that this solution can warm-start a problem with `n` variables and `m`
    /// constraints (lengths of x, λ, z_L, z_U).
    pub fn check_warm_start(&self, n: usize, m: usize) -> Result<(), crate::SolveError> {
        for (what, len, expected) in [
            ("previous.x", self.x.len(), n),
            ("previous.lambda", self.lambda.len(), m),
            ("previous.z_l", self.z_l.len(), n),
            ("previous.z_u", self.z_u.len(), n),
        ] {
            if len != expected {
                return Err(crate::SolveError::WrongSize(format!(
                    "{what} has length {len}, expected {expected}"
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::Status;

    /// The names of IPOPT's `ApplicationReturnStatus` (IpReturnCodes_inc.h, IPOPT 3.14).
    #[test]
    fn status_displays_ipopt_names() {
        assert_eq!(Status::SolveSucceeded.to_string(), "Solve_Succeeded");
        assert_eq!(
            Status::MaximumWallTimeExceeded.to_string(),
            "Maximum_WallTime_Exceeded"
        );
        assert_eq!(
            Status::SearchDirectionBecomesTooSmall.to_string(),
            "Search_Direction_Becomes_Too_Small"
        );
    }
}
