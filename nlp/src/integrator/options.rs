//! The integrator's options, statistics and errors.
use symx::SymxError;
use thiserror::Error;

/// Why an integration failed or could not be set up.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum IntegratorError {
    /// The right-hand side function does not have the form `f(x) → ẋ` or `f(x, p) → ẋ`.
    #[error("ODE right-hand side: {why}")]
    BadOde {
        /// What is wrong.
        why: String,
    },
    /// An option out of range.
    #[error("integrator option {name} = {value}: {why}")]
    BadOption {
        /// The option.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The valid range.
        why: &'static str,
    },
    /// An argument of the wrong length.
    #[error("{what} has length {got}, expected {expected}")]
    Length {
        /// Which argument.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// Output times not increasing or outside `[t0, tf]`.
    #[error("output times must be non-decreasing within [{t0}, {tf}]")]
    BadTimes {
        /// Start of the interval.
        t0: f64,
        /// End of the interval.
        tf: f64,
    },
    /// `max_steps` steps were taken before the end (a stiff system, or tolerances too tight).
    #[error(
        "integration stopped at t = {t} after {steps} steps (max_steps): the system may be stiff"
    )]
    MaxSteps {
        /// Time reached.
        t: f64,
        /// Steps taken.
        steps: usize,
    },
    /// The step size fell below the resolution of `t` (a singularity, a blow-up).
    #[error("step size {h:e} too small at t = {t}")]
    StepTooSmall {
        /// Time reached.
        t: f64,
        /// The step size.
        h: f64,
    },
    /// The right-hand side returned a NaN or infinity that step rejection could not avoid.
    #[error("non-finite state or derivative at t = {t}")]
    NonFinite {
        /// Time reached.
        t: f64,
    },
    /// The implicit method's Newton iteration kept failing until the step size fell below
    /// the resolution of `t` (a singular or badly scaled Jacobian, a blow-up).
    #[error("Newton iteration of the implicit method failed with step size {h:e} at t = {t}")]
    NewtonFailure {
        /// Time reached.
        t: f64,
        /// The last step size tried.
        h: f64,
    },
    /// Building the symbolic sensitivity equations failed.
    #[error(transparent)]
    Symbolic(#[from] SymxError),
}

/// Tolerances and limits of [`Integrator`](super::Integrator) (CasADi/CVODES names and meanings).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratorOptions {
    /// Relative tolerance (default 1e-8).
    pub rtol: f64,
    /// Absolute tolerance (default 1e-10).
    pub atol: f64,
    /// Maximum number of steps, accepted and rejected, per integration (default 100 000).
    pub max_steps: usize,
    /// First step size; `None` picks one from the derivatives at `t0` (Hairer's rule).
    pub initial_step: Option<f64>,
    /// The integration method (default [`Method::Dopri5`]).
    pub method: Method,
    /// Whether the forward sensitivities take part in the step-size control (CVODES'
    /// `fsens_err_con`; default `false`). When `true`, an integration that computes
    /// sensitivities ([`Integrator::simulate_with_jacobian`](super::Integrator::simulate_with_jacobian),
    /// [`Integrator::to_function`](super::Integrator::to_function)) accepts a step only if
    /// the error of every column of `∂x/∂(x₀, p)` is within the tolerances too (the largest
    /// weighted RMS norm over `x` and the columns, weights `atol + rtol·|·|`): accurate
    /// sensitivities where the variational equations have a fast transient that `x` alone
    /// does not (a relaxation jump), at the price of more, smaller steps. Off by default
    /// because the states then choose the steps alone: the sensitivities are the exact
    /// derivatives of the very map [`Integrator::simulate`](super::Integrator::simulate)
    /// computes, and an integration with sensitivities costs no extra steps.
    pub sensitivity_error_control: bool,
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        IntegratorOptions {
            rtol: 1e-8,
            atol: 1e-10,
            max_steps: 100_000,
            initial_step: None,
            method: Method::Dopri5,
            sensitivity_error_control: false,
        }
    }
}

/// The integration method of an [`Integrator`](super::Integrator).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Method {
    /// Dormand–Prince 5(4): explicit, for non-stiff systems (CasADi's `rk`-like adaptive
    /// explicit method).
    #[default]
    Dopri5,
    /// A singly diagonally implicit Runge–Kutta method of order 4 with an embedded order 3
    /// (Hairer & Wanner's SDIRK4, L-stable, stiffly accurate): for stiff systems (where
    /// CasADi users take CVODES' BDF). Each step solves its 5 stages by Newton's method with
    /// the exact Jacobian of `f` (symx AD, compiled once).
    Sdirk4,
}

/// Statistics of one integration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IntegratorStats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// Right-hand side evaluations.
    pub rhs_evaluations: usize,
    /// LU factorizations of the Newton matrix `I − hγ f_x` (implicit method; 0 for
    /// DOPRI5). Kept across steps while Newton's iteration converges fast (RADAU5's rule).
    pub factorizations: usize,
    /// Evaluations of the Jacobian `f_x` for the Newton matrix (implicit method; 0 for
    /// DOPRI5).
    pub jacobians: usize,
    /// Steps rejected because Newton's iteration did not converge (implicit method;
    /// included in `rejected`).
    pub newton_failures: usize,
}
