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

/// The error norm of the step-size control: the largest weighted RMS norm over the blocks
/// of `block` consecutive entries among the first `len` (`len` a multiple of `block`: the
/// states, then each sensitivity column when they are under error control), `scaled(i)`
/// being entry `i`'s error divided by its weight. With one block this is the usual
/// weighted RMS norm.
pub(super) fn error_norm(len: usize, block: usize, mut scaled: impl FnMut(usize) -> f64) -> f64 {
    let mut worst = 0.0f64;
    for start in (0..len.max(1)).step_by(block.max(1)) {
        let mut sum = 0.0;
        for i in start..(start + block).min(len) {
            let r = scaled(i);
            sum += r * r;
        }
        let norm = (sum / block.max(1) as f64).sqrt();
        // A NaN norm wins and stays (the step is then rejected as non-finite).
        if norm.is_nan() || norm > worst {
            worst = norm;
        }
    }
    worst
}
