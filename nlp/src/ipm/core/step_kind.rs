//! How a step was taken: the kind of an accepted trial point and the outcome of a line
//! search.

/// How the step of an accepted trial point was made (the log's character after
/// alpha_pr: lower case for the plain step, upper case for a second-order correction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum StepKind {
    /// f-type: the switching and Armijo conditions hold; the filter is not augmented.
    FType { soc: bool },
    /// h-type: the filter was augmented.
    HType { soc: bool },
    /// A soft restoration step (IPOPT's 's'; 'S' when it is acceptable to the filter,
    /// which ends the soft restoration phase).
    Soft { original: bool },
}

impl StepKind {
    pub(super) fn new(ftype: bool, soc: bool) -> StepKind {
        if ftype {
            StepKind::FType { soc }
        } else {
            StepKind::HType { soc }
        }
    }

    pub(super) fn log_char(self) -> char {
        match self {
            StepKind::FType { soc: false } => 'f',
            StepKind::HType { soc: false } => 'h',
            StepKind::FType { soc: true } => 'F',
            StepKind::HType { soc: true } => 'H',
            StepKind::Soft { original: false } => 's',
            StepKind::Soft { original: true } => 'S',
        }
    }
}

/// The outcome of [`Core::line_search`]; `trials` counts the trial step sizes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum LineSearch {
    /// A trial point was accepted (and is now the iterate).
    Accepted {
        alpha_pr: f64,
        alpha_du: f64,
        kind: StepKind,
        trials: usize,
    },
    /// Every step size down to α_min was rejected; `alpha_pr` is the last one tried.
    Failed { alpha_pr: f64, trials: usize },
}

impl LineSearch {
    /// The filter already holds the current point (or the soft restoration phase's start
    /// point), so a restoration phase starting now does not add it again: true after a
    /// failed search (`Core::search_step` augments the filter before it reports one)
    /// and after a soft restoration step (taken only once the filter was augmented).
    pub(super) fn filter_augmented(&self) -> bool {
        match self {
            LineSearch::Failed { .. } => true,
            LineSearch::Accepted { kind, .. } => matches!(kind, StepKind::Soft { .. }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{LineSearch, StepKind};

    #[test]
    fn only_failed_searches_and_soft_steps_leave_the_point_in_the_filter() {
        let accepted = |kind| LineSearch::Accepted {
            alpha_pr: 1.0,
            alpha_du: 1.0,
            kind,
            trials: 1,
        };
        assert!(!accepted(StepKind::new(true, false)).filter_augmented());
        assert!(!accepted(StepKind::new(false, true)).filter_augmented());
        assert!(accepted(StepKind::Soft { original: false }).filter_augmented());
        assert!(accepted(StepKind::Soft { original: true }).filter_augmented());
        let failed = LineSearch::Failed {
            alpha_pr: 0.0,
            trials: 3,
        };
        assert!(failed.filter_augmented());
    }
}
