//! What the integration driver needs of a stepping method.
use super::options::{IntegratorError, IntegratorStats};

/// A one-step method integrating a fixed system from its current point.
pub(super) trait Stepper {
    /// Steps from `t` to exactly `target`, updating `t` and the state `z`.
    fn advance(&mut self, t: &mut f64, z: &mut [f64], target: f64) -> Result<(), IntegratorError>;

    /// The statistics so far.
    fn stats(&self) -> IntegratorStats;
}

/// The step-size controller shared by the methods: the size after a step of size `h` with
/// weighted error `err` (1 = the tolerance) for an error estimate of order q, with
/// `exponent` = 1/(q + 1). `current` is the controller's size before the step and `last`
/// whether the step was cut to end on an output time (its size is then kept). An accepted
/// step grows the size by at most 5; a rejected one shrinks it by 0.9·err^(−exponent),
/// at least 5 times when the step produced non-finite values (`finite` false).
pub(super) fn next_step_size(
    current: f64,
    h: f64,
    err: f64,
    finite: bool,
    last: bool,
    exponent: f64,
) -> f64 {
    let accepted = finite && err <= 1.0;
    if accepted {
        let factor = if err == 0.0 {
            5.0
        } else {
            (0.9 * err.powf(-exponent)).clamp(0.2, 5.0)
        };
        if last {
            current.max(h)
        } else {
            h * factor
        }
    } else if finite {
        h * (0.9 * err.powf(-exponent)).clamp(0.2, 1.0)
    } else {
        h * 0.2
    }
}
