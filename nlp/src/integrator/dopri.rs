//! Dormand–Prince 5(4): the explicit adaptive stepper (Hairer, Nørsett & Wanner, *Solving
//! ODEs I*, §II.5), first same as last.
use super::options::{IntegratorError, IntegratorOptions, IntegratorStats};
use super::stepper::{error_norm, next_step_size, Stepper};
use symx::Function;

/// Dormand–Prince 5(4) coefficients (Dormand & Prince 1980; Hairer–Nørsett–Wanner Table 5.2).
/// The system is autonomous, so the nodes `c` are not needed.
pub(super) const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// Error weights: 5th-order weights minus the embedded 4th-order ones.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// The stepping state of one integration.
pub(super) struct Dopri<'a> {
    rhs: &'a Function,
    p: &'a [f64],
    /// The number of original states (the first block under error control).
    nx: usize,
    /// Entries under error control: the states, and the sensitivities if controlled.
    controlled: usize,
    buf: DopriBuffers,
    h: f64,
    /// Whether `k[0]` holds `f(z)` at the current point (first same as last).
    fresh: bool,
    options: IntegratorOptions,
    stats: IntegratorStats,
    /// Where accepted steps are recorded for an adjoint pass (`h`, `zₙ`), if anywhere.
    tape: Option<&'a mut Vec<f64>>,
}

/// The buffers of a DOPRI5 integration, kept between integrations of the same system so
/// that a repeated integration allocates nothing.
#[derive(Debug, Default)]
pub(super) struct DopriBuffers {
    k: [Vec<f64>; 7],
    stage: Vec<f64>,
    work: Vec<f64>,
}

impl<'a> Dopri<'a> {
    /// A stepper for `rhs` (state length `nz`, the first `controlled` entries under error
    /// control, in blocks of `nx`) using `buf`, resized as needed (no allocation when it
    /// already fits).
    pub(super) fn new(
        rhs: &'a Function,
        nz: usize,
        nx: usize,
        controlled: usize,
        p: &'a [f64],
        options: IntegratorOptions,
        mut buf: DopriBuffers,
    ) -> Dopri<'a> {
        buf.k.iter_mut().for_each(|k| k.resize(nz, 0.0));
        buf.stage.resize(nz, 0.0);
        buf.work.resize(rhs.work_size(), 0.0);
        Dopri {
            rhs,
            p,
            nx,
            controlled,
            buf,
            h: options.initial_step.unwrap_or(0.0),
            fresh: false,
            options,
            stats: IntegratorStats::default(),
            tape: None,
        }
    }

    /// Records every accepted step in `tape` (see [`super::adjoint`]).
    pub(super) fn with_tape(mut self, tape: Option<&'a mut Vec<f64>>) -> Dopri<'a> {
        self.tape = tape;
        self
    }

    /// The buffers, for the next integration.
    pub(super) fn into_buffers(self) -> DopriBuffers {
        self.buf
    }

    fn eval(&mut self, z_is_stage: bool, z: &[f64], into: usize) {
        let input = if z_is_stage { &self.buf.stage[..] } else { z };
        let mut out = std::mem::take(&mut self.buf.k[into]);
        self.rhs
            .eval(&[input, self.p], &mut [&mut out], &mut self.buf.work)
            .expect("sizes fixed at construction");
        self.buf.k[into] = out;
        self.stats.rhs_evaluations += 1;
    }

    fn weight(&self, a: f64, b: f64) -> f64 {
        self.options.atol + self.options.rtol * a.abs().max(b.abs())
    }

    /// Hairer's starting step (Solving ODEs I, §II.4): from ‖z‖, ‖f(z)‖ and one Euler step.
    fn initial_step(&mut self, z: &[f64], span: f64) -> f64 {
        let n = self.nx;
        let (atol, rtol) = (self.options.atol, self.options.rtol);
        // Weighted by atol + rtol·|z| (`weight(z, z)`), without a buffer.
        let rms = |v: &mut dyn Iterator<Item = f64>| {
            let sum = v
                .zip(&z[..n])
                .map(|(a, &zi)| (a / (atol + rtol * zi.abs())).powi(2))
                .sum::<f64>();
            (sum / n.max(1) as f64).sqrt()
        };
        let d0 = rms(&mut z.iter().copied());
        let d1 = rms(&mut self.buf.k[0].iter().copied());
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        let h0 = h0.min(span);
        for ((s, &zi), &ki) in self.buf.stage.iter_mut().zip(z).zip(&self.buf.k[0]) {
            *s = zi + h0 * ki;
        }
        self.eval(true, z, 1);
        let d2 = rms(&mut self.buf.k[1].iter().zip(&self.buf.k[0]).map(|(a, b)| a - b)) / h0;
        let h1 = if d1.max(d2) <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / 5.0)
        };
        (100.0 * h0).min(h1).min(span)
    }
}

impl Stepper for Dopri<'_> {
    fn stats(&self) -> IntegratorStats {
        self.stats
    }

    fn advance(&mut self, t: &mut f64, z: &mut [f64], target: f64) -> Result<(), IntegratorError> {
        if !self.fresh {
            self.eval(false, z, 0);
            self.fresh = true;
        }
        if self.h <= 0.0 && target > *t {
            self.h = self.initial_step(z, target - *t);
        }
        while *t < target {
            if self.stats.accepted + self.stats.rejected >= self.options.max_steps {
                return Err(IntegratorError::MaxSteps {
                    t: *t,
                    steps: self.stats.accepted + self.stats.rejected,
                });
            }
            let last = *t + self.h >= target;
            let h = if last { target - *t } else { self.h };
            if h <= 16.0 * f64::EPSILON * t.abs().max(1.0) && !last {
                return Err(IntegratorError::StepTooSmall { t: *t, h });
            }
            for s in 1..7 {
                for (i, (stage, &zi)) in self.buf.stage.iter_mut().zip(z.iter()).enumerate() {
                    let mut acc = 0.0;
                    for (j, &a) in A[s][..s].iter().enumerate() {
                        acc += a * self.buf.k[j][i];
                    }
                    *stage = zi + h * acc;
                }
                self.eval(true, z, s);
            }
            // The 5th-order solution is the last stage's point (FSAL).
            let znew = &self.buf.stage;
            let err = error_norm(self.controlled, self.nx, |i| {
                let mut e = 0.0;
                for (s, &w) in E.iter().enumerate() {
                    e += w * self.buf.k[s][i];
                }
                h * e / self.weight(z[i], znew[i])
            });
            let finite = err.is_finite() && znew.iter().all(|v| v.is_finite());
            if finite && err <= 1.0 {
                if let Some(tape) = self.tape.as_mut() {
                    tape.push(h);
                    tape.extend_from_slice(&z[..self.nx]);
                }
                *t = if last { target } else { *t + h };
                z.copy_from_slice(&self.buf.stage);
                self.buf.k.swap(0, 6);
                self.stats.accepted += 1;
            } else {
                self.stats.rejected += 1;
                if !finite && h <= 1e-14 * t.abs().max(1.0) {
                    return Err(IntegratorError::NonFinite { t: *t });
                }
            }
            self.h = next_step_size(self.h, h, err, finite, last, 0.2);
        }
        Ok(())
    }
}
