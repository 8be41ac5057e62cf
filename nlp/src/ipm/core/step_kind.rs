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
