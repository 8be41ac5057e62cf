//! The planner's outcome as a type: what happened, why, and the exit code it maps to.
//!
//! [`PlanStatus`] is what `solve::plan` decides for a scenario; [`StatusKind`] is its
//! data-free tag, the word written to files (`solution.json`'s `solver.status`,
//! `sweep.csv`) and counted by `sweep`. Nothing in this crate compares status words as
//! text: they are parsed into [`StatusKind`] ([`StatusKind::from_word`]) and matched.
use crate::reach::{ForceThreshold, Uncrossable, Unreachable};
use serde::{Deserialize, Serialize};
use std::fmt;

/// What happened to one scenario, without the details. Serialised as the snake_case word
/// (`solved`, `gap_not_crossable`, ...).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StatusKind {
    /// Every equation holds (the independent checker agrees) and both CoMs end within
    /// `check::GOAL_TOL` (0.05 m) of their goals.
    Solved,
    /// A keep-out zone on the way is at least as wide as the step reach: no plan can
    /// reach the goal (a geometric certificate, [`Uncrossable`]).
    GapNotCrossable,
    /// Too few stances: n_step is below a lower bound on the stances any plan needs (a
    /// certificate, [`Unreachable`]).
    GoalNotReached,
    /// No plan satisfies the constraints: 4·F_thr is above what the weight allows (a
    /// certificate, [`ForceThreshold`]).
    Infeasible,
    /// No plan found: the planner's plan ends short of the goal though no certificate
    /// proves the goal unreachable.
    NoPlanFound,
    /// The NLP solver stopped without a solution (iteration limit, restoration failure, ...).
    SolverFailed,
    /// The solver reported success but the independent checker rejects the plan.
    CheckFailed,
    /// `sweep` only: the point's scenario is invalid.
    InvalidScenario,
    /// `sweep` only: planning stopped with an error (building or compiling the model).
    Error,
    /// `sweep` only: planning panicked (a bug).
    Panic,
}

impl StatusKind {
    /// Every kind, in the order `sweep` reports counts.
    pub const ALL: [StatusKind; 10] = [
        StatusKind::Solved,
        StatusKind::GapNotCrossable,
        StatusKind::GoalNotReached,
        StatusKind::Infeasible,
        StatusKind::NoPlanFound,
        StatusKind::SolverFailed,
        StatusKind::CheckFailed,
        StatusKind::InvalidScenario,
        StatusKind::Error,
        StatusKind::Panic,
    ];

    /// The word written to files.
    pub fn word(self) -> &'static str {
        match self {
            StatusKind::Solved => "solved",
            StatusKind::GapNotCrossable => "gap_not_crossable",
            StatusKind::GoalNotReached => "goal_not_reached",
            StatusKind::Infeasible => "infeasible",
            StatusKind::NoPlanFound => "no_plan_found",
            StatusKind::SolverFailed => "solver_failed",
            StatusKind::CheckFailed => "check_failed",
            StatusKind::InvalidScenario => "invalid_scenario",
            StatusKind::Error => "error",
            StatusKind::Panic => "panic",
        }
    }

    /// Parses a status word of a solution file; a word of the previous format (the
    /// solver's own status, e.g. `maximum_iterations_exceeded`) is a solver failure.
    pub fn from_word(word: &str) -> StatusKind {
        StatusKind::ALL
            .into_iter()
            .find(|k| k.word() == word)
            .unwrap_or(StatusKind::SolverFailed)
    }

    /// The exit code of `gap-crossing solve` for this outcome (docs/gap-crossing.md,
    /// "Exit codes"): 0 solved, 1 solver failure or checker rejection, 2 errors
    /// (invalid input), 3 gap not crossable, 4 goal not reached (too few stances),
    /// 5 infeasible (proved impossible: 3, 4, 5), 6 no plan found, 101 a panic.
    pub fn exit_code(self) -> u8 {
        match self {
            StatusKind::Solved => 0,
            StatusKind::SolverFailed | StatusKind::CheckFailed => 1,
            StatusKind::InvalidScenario | StatusKind::Error => 2,
            StatusKind::GapNotCrossable => 3,
            StatusKind::GoalNotReached => 4,
            StatusKind::Infeasible => 5,
            StatusKind::NoPlanFound => 6,
            StatusKind::Panic => 101,
        }
    }

    /// True for [`StatusKind::Solved`].
    pub fn is_solved(self) -> bool {
        self == StatusKind::Solved
    }

    /// True when a certificate proves that no plan exists (gap not crossable, goal not
    /// reached, infeasible), as opposed to a plan not found.
    pub fn is_proved_impossible(self) -> bool {
        matches!(
            self,
            StatusKind::GapNotCrossable | StatusKind::GoalNotReached | StatusKind::Infeasible
        )
    }
}

impl fmt::Display for StatusKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.word())
    }
}

/// The planner's verdict on a scenario, with the reason when it is not solved.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanStatus {
    /// Every equation holds and the plan reaches the goal.
    Solved,
    /// No plan can reach the goal: the certificate.
    GapNotCrossable(Uncrossable),
    /// Too few stances for any plan to reach the goal.
    GoalNotReached(GoalShortfall),
    /// No plan satisfies the constraints: the certificate.
    Infeasible(ForceThreshold),
    /// The plan ends short of the goal, with no certificate that it must.
    NoPlanFound(GoalShortfall),
    /// The solver stopped without a solution.
    SolverFailed(nlp::Status),
    /// The solver succeeded but the checker found violations: their count and labels.
    CheckFailed {
        /// Number of violations.
        violations: usize,
        /// Their distinct equation labels.
        labels: Vec<String>,
    },
}

/// How far a plan is from its goal, and how many stances the goal needs.
#[derive(Clone, Debug, PartialEq)]
pub struct GoalShortfall {
    /// The scenario's n_step.
    pub n_step: usize,
    /// Largest distance of a final CoM from its goal (m).
    pub distance: f64,
    /// The lower bound on the stances any plan needs (a proof when above n_step).
    pub bound: Unreachable,
    /// Stances the planner's own guess (crawl landing rule with the crossing search)
    /// needs to reach the goal, when it does within its search limit.
    pub guess_needs: Option<usize>,
}

impl PlanStatus {
    /// The data-free tag.
    pub fn kind(&self) -> StatusKind {
        match self {
            PlanStatus::Solved => StatusKind::Solved,
            PlanStatus::GapNotCrossable(_) => StatusKind::GapNotCrossable,
            PlanStatus::GoalNotReached(_) => StatusKind::GoalNotReached,
            PlanStatus::Infeasible(_) => StatusKind::Infeasible,
            PlanStatus::NoPlanFound(_) => StatusKind::NoPlanFound,
            PlanStatus::SolverFailed(_) => StatusKind::SolverFailed,
            PlanStatus::CheckFailed { .. } => StatusKind::CheckFailed,
        }
    }

    /// True for [`PlanStatus::Solved`].
    pub fn is_solved(&self) -> bool {
        self.kind().is_solved()
    }
}

impl fmt::Display for PlanStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlanStatus::Solved => f.write_str("solved: every equation holds and the goal is reached"),
            PlanStatus::GapNotCrossable(c) => write!(f, "gap not crossable: {c}"),
            PlanStatus::GoalNotReached(g) => {
                write!(
                    f,
                    "goal not reached: n_step = {} is too few: {}",
                    g.n_step, g.bound
                )?;
                match g.guess_needs {
                    Some(n) => write!(f, "; the planner's guess reaches the goal with n_step = {n}"),
                    None => Ok(()),
                }
            }
            PlanStatus::Infeasible(c) => write!(f, "infeasible: {c}"),
            PlanStatus::NoPlanFound(g) => {
                write!(
                    f,
                    "no plan found: the plan ends {:.3} m from a goal (tolerance 0.05 m) with n_step = {}, though no certificate rules the goal out (the lower bound is {} stances)",
                    g.distance, g.n_step, g.bound.needed
                )?;
                match g.guess_needs {
                    Some(n) => write!(f, "; the planner's guess reaches the goal with n_step = {n}"),
                    None => Ok(()),
                }
            }
            PlanStatus::SolverFailed(s) => write!(f, "solver failed: {s:?}"),
            PlanStatus::CheckFailed { violations, labels } => write!(
                f,
                "check failed: the solver reports success but the checker finds {violations} violations ({})",
                labels.join(", ")
            ),
        }
    }
}
