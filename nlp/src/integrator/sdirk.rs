//! SDIRK4: the implicit adaptive stepper for stiff systems.
//!
//! Hairer & Wanner's L-stable, stiffly accurate singly diagonally implicit Runge–Kutta
//! method of order 4 with an embedded order-3 solution (*Solving ODEs II*, §IV.6, Table
//! 6.5, γ = 1/4). Each stage `Zᵢ = zₙ + hΣⱼ<ᵢ aᵢⱼKⱼ + hγf(Zᵢ)` is solved by a simplified
//! Newton iteration with the matrix `I − hγ J`, `J` the exact Jacobian `f_x` at the step's
//! start or, while Newton's iteration converges fast, at an earlier step's, with its LU
//! kept too when the step size allows (RADAU5's rule, [`Sdirk::reuse_size`]); the error
//! estimate is filtered through the same LU (as in RADAU5) so that stiff components do
//! not force tiny steps. All buffers, LU factors included, are kept between integrations
//! ([`SdirkBuffers`]).
//!
//! **Sensitivities** (levels above 0, see [`super::level`]): once the states' stage `Xᵢ`
//! has converged, the sensitivities' stage is the *exact* solution of the linear stage
//! equation `(I − hγ f_x(Xᵢ)) Sᵢ = Sₙ + hΣⱼ<ᵢ aᵢⱼ Ṡⱼ + hγ f_θ(Xᵢ)`, i.e. the derivative of
//! the step map with the stage equations solved exactly, at the converged stage. The
//! steps are chosen by the states alone, so they are the same steps, bit for bit, as
//! those of the plain simulation.
use super::level::Level;
use super::lu::DenseLu;
use super::options::{IntegratorError, IntegratorOptions, IntegratorStats};
use super::stepper::{error_norm, next_step_size, Stepper};
use faer::MatMut;

pub(super) const GAMMA: f64 = 0.25;
/// Stage coefficients `aᵢⱼ` (lower triangle; the diagonal is `GAMMA`).
pub(super) const A: [[f64; 4]; 5] = [
    [0.0; 4],
    [0.5, 0.0, 0.0, 0.0],
    [17.0 / 50.0, -1.0 / 25.0, 0.0, 0.0],
    [371.0 / 1360.0, -137.0 / 2720.0, 15.0 / 544.0, 0.0],
    [25.0 / 24.0, -49.0 / 48.0, 125.0 / 16.0, -85.0 / 12.0],
];
/// Weights of the solution minus those of the embedded order-3 one (the solution is the
/// last stage: `b` is the last row of `A` with `GAMMA`).
const E: [f64; 5] = [
    25.0 / 24.0 - 59.0 / 48.0,
    -49.0 / 48.0 + 17.0 / 96.0,
    125.0 / 16.0 - 225.0 / 32.0,
    0.0,
    0.25,
];
/// Newton iterations per stage before the step is retried with half the step size.
const MAX_NEWTON: usize = 7;
/// Newton tolerance, in the weighted RMS norm of the error control (1 = the tolerance).
const NEWTON_TOL: f64 = 0.01;

/// The stepping state of one SDIRK4 integration of `levels.last()`.
pub(super) struct Sdirk<'a> {
    levels: &'a [Level],
    p: &'a [f64],
    nx: usize,
    /// Entries under error control: the states, and the sensitivities if controlled.
    controlled: usize,
    options: IntegratorOptions,
    stats: IntegratorStats,
    h: f64,
    buf: SdirkBuffers,
    /// Whether `buf.jac0` may serve at the current point: evaluated there, or kept from
    /// an earlier point by the reuse rule.
    jac_valid: bool,
    /// Whether `buf.jac0` was evaluated at the current point.
    jac_current: bool,
    /// The step size of the factors in `buf.newton` (0 when they are not valid).
    lu_h: f64,
    /// The largest contraction rate of Newton's iteration in the current step attempt.
    theta: f64,
    /// Whether the last attempt failed in Newton's iteration.
    newton_failed: bool,
    /// Where accepted steps are recorded for an adjoint pass (`h`, the stage points), if
    /// anywhere, and the stage points of the current attempt.
    tape: Option<&'a mut Vec<f64>>,
}

/// The buffers of an SDIRK4 integration, kept between integrations of the same system so
/// that a repeated integration allocates nothing (see [`super::lu`]).
#[derive(Debug, Default)]
pub(super) struct SdirkBuffers {
    /// Stage derivatives `Kᵢ` of the whole state.
    k: [Vec<f64>; 5],
    /// The current stage point `Zᵢ`.
    stage: Vec<f64>,
    /// `zₙ + hΣⱼ<ᵢ aᵢⱼKⱼ`.
    base: Vec<f64>,
    /// Right-hand side values and Newton corrections.
    fz: Vec<f64>,
    delta: Vec<f64>,
    /// A state whose sensitivity part is zero (forcing terms of the linear stage equations).
    padded: Vec<f64>,
    jac_values: Vec<f64>,
    work: Vec<f64>,
    /// `−f_x(xₙ)` (dense, column-major).
    jac0: Vec<f64>,
    /// The LU of `I − hγ f_x(xₙ)` of the current step attempt.
    newton: DenseLu,
    /// For each level k below the top, the LU of `I − hγ ∂ż_k/∂z_k` at a converged stage.
    levels: Vec<DenseLu>,
    /// The stage points of the current attempt (recorded for an adjoint pass).
    points: Vec<f64>,
}

impl<'a> Sdirk<'a> {
    /// A stepper for `levels.last()`; every level below it, and level 0, has its Jacobian.
    /// The first `controlled` entries of the state, in blocks of `nx`, are under error
    /// control.
    pub(super) fn new(
        levels: &'a [Level],
        nx: usize,
        controlled: usize,
        p: &'a [f64],
        options: IntegratorOptions,
        mut buf: SdirkBuffers,
    ) -> Sdirk<'a> {
        let nz = levels.last().expect("level 0").nz;
        let work = levels
            .iter()
            .flat_map(|l| {
                let jac = l.jacobian.as_ref().map_or(0, |j| j.values.work_size());
                [l.rhs.work_size(), jac]
            })
            .max()
            .unwrap_or(0);
        let nnz = levels
            .iter()
            .filter_map(|l| l.jacobian.as_ref().map(|j| j.entries.len()))
            .max()
            .unwrap_or(0);
        for v in buf.k.iter_mut().chain([
            &mut buf.stage,
            &mut buf.base,
            &mut buf.fz,
            &mut buf.delta,
            &mut buf.padded,
        ]) {
            v.resize(nz, 0.0);
        }
        buf.jac_values.resize(nnz, 0.0);
        buf.work.resize(work, 0.0);
        buf.jac0.resize(nx * nx, 0.0);
        buf.newton.reserve(nx, controlled / nx.max(1));
        buf.levels.resize_with(levels.len() - 1, DenseLu::default);
        for (lu, pair) in buf.levels.iter_mut().zip(levels.windows(2)) {
            lu.reserve(pair[0].nz, pair[1].nz / pair[0].nz.max(1));
        }
        Sdirk {
            levels,
            p,
            nx,
            controlled,
            options,
            stats: IntegratorStats::default(),
            h: options.initial_step.unwrap_or(0.0),
            buf,
            jac_valid: false,
            jac_current: false,
            lu_h: 0.0,
            theta: 0.0,
            newton_failed: false,
            tape: None,
        }
    }

    /// The buffers, for the next integration.
    pub(super) fn into_buffers(self) -> SdirkBuffers {
        self.buf
    }

    /// Records every accepted step in `tape` (see [`super::adjoint`]).
    pub(super) fn with_tape(mut self, tape: Option<&'a mut Vec<f64>>) -> Sdirk<'a> {
        if tape.is_some() {
            self.buf.points.resize(5 * self.nx, 0.0);
        }
        self.tape = tape;
        self
    }

    fn weight(&self, a: f64, b: f64) -> f64 {
        self.options.atol + self.options.rtol * a.abs().max(b.abs())
    }

    /// `f` of level `level` at `input` into `self.buf.fz`.
    fn eval_rhs(&mut self, level: usize, input: &[f64]) {
        let nz = self.levels[level].nz;
        self.levels[level]
            .rhs
            .eval(
                &[input, self.p],
                &mut [&mut self.buf.fz[..nz]],
                &mut self.buf.work,
            )
            .expect("sizes fixed at construction");
        self.stats.rhs_evaluations += 1;
    }

    /// `I − c·∂ż/∂z` of level `level` at `z` (its first `nz` entries), dense.
    fn iteration_matrix(&mut self, level: usize, z: &[f64], c: f64, into: MatMut<'_, f64>) {
        self.levels[level].iteration_matrix(
            z,
            self.p,
            c,
            &mut self.buf.jac_values,
            &mut self.buf.work,
            into,
        );
    }

    /// Hairer's first guess from ‖x‖ and ‖f(x)‖ (the growth of the step controller does
    /// the rest).
    fn initial_step(&mut self, z: &[f64], span: f64) -> f64 {
        let n = self.nx;
        self.eval_rhs(0, &z[..n]);
        let (mut d0, mut d1) = (0.0, 0.0);
        for (&zi, &fi) in z[..n].iter().zip(&self.buf.fz) {
            let w = self.weight(zi, zi);
            d0 += (zi / w).powi(2);
            d1 += (fi / w).powi(2);
        }
        let h = if d0 < 1e-10 * n as f64 || d1 < 1e-10 * n as f64 {
            1e-6
        } else {
            0.01 * (d0 / d1).sqrt()
        };
        h.min(span)
    }

    /// Solves stage `i`'s equation for level `level` (the first `nz` entries of
    /// `self.buf.stage`, given `self.buf.base`); `false` if Newton's iteration failed.
    fn solve_stage(&mut self, level: usize, i: usize, h: f64) -> bool {
        if level == 0 {
            return self.newton_stage(i, h);
        }
        if !self.solve_stage(level - 1, i, h) {
            return false;
        }
        // Linear in the sensitivities S: (I − hγ J(X)) S = base_S + hγ f_θ(X).
        let n = self.levels[level - 1].nz;
        let nz = self.levels[level].nz;
        let mut lu = std::mem::take(&mut self.buf.levels[level - 1]);
        let stage = std::mem::take(&mut self.buf.stage);
        self.iteration_matrix(level - 1, &stage, h * GAMMA, lu.matrix.as_mut());
        self.buf.stage = stage;
        lu.factor();
        self.buf.padded[..n].copy_from_slice(&self.buf.stage[..n]);
        self.buf.padded[n..nz].fill(0.0);
        let padded = std::mem::take(&mut self.buf.padded);
        self.eval_rhs(level, &padded[..nz]);
        self.buf.padded = padded;
        for e in n..nz {
            self.buf.stage[e] = self.buf.base[e] + h * GAMMA * self.buf.fz[e];
        }
        lu.solve(&mut self.buf.stage[n..nz], false);
        self.buf.levels[level - 1] = lu;
        self.buf.stage[n..nz].iter().all(|v| v.is_finite())
    }

    /// Simplified Newton for the states' stage `i` with the step's LU.
    fn newton_stage(&mut self, i: usize, h: f64) -> bool {
        let n = self.nx;
        for e in 0..n {
            let previous = if i > 0 { self.buf.k[i - 1][e] } else { 0.0 };
            self.buf.stage[e] = self.buf.base[e] + h * GAMMA * previous;
        }
        let mut previous_norm = f64::INFINITY;
        for iteration in 0..MAX_NEWTON {
            let stage = std::mem::take(&mut self.buf.stage);
            self.eval_rhs(0, &stage[..n]);
            self.buf.stage = stage;
            for e in 0..n {
                self.buf.delta[e] =
                    self.buf.base[e] + h * GAMMA * self.buf.fz[e] - self.buf.stage[e];
            }
            self.buf.newton.solve(&mut self.buf.delta[..n], false);
            let mut sum = 0.0;
            for e in 0..n {
                self.buf.stage[e] += self.buf.delta[e];
                sum +=
                    (self.buf.delta[e] / self.weight(self.buf.stage[e], self.buf.stage[e])).powi(2);
            }
            let norm = (sum / n.max(1) as f64).sqrt();
            if !norm.is_finite() {
                return false;
            }
            let rate = norm / previous_norm;
            if iteration > 0 {
                self.theta = self.theta.max(rate);
                if rate >= 0.9 {
                    return false;
                }
            }
            let converged = if iteration == 0 {
                norm <= 1e-2 * NEWTON_TOL
            } else {
                rate / (1.0 - rate) * norm <= NEWTON_TOL
            };
            if converged || norm == 0.0 {
                return true;
            }
            previous_norm = norm;
        }
        false
    }

    /// All stages of a step of size `h` from `z`; `false` if Newton's iteration failed.
    fn stages(&mut self, z: &[f64], h: f64) -> bool {
        let top = self.levels.len() - 1;
        for i in 0..5 {
            for (e, (b, &ze)) in self.buf.base.iter_mut().zip(z).enumerate() {
                let mut acc = 0.0;
                for (j, &a) in A[i][..i].iter().enumerate() {
                    acc += a * self.buf.k[j][e];
                }
                *b = ze + h * acc;
            }
            if !self.solve_stage(top, i, h) {
                return false;
            }
            if self.tape.is_some() {
                let n = self.nx;
                self.buf.points[i * n..(i + 1) * n].copy_from_slice(&self.buf.stage[..n]);
            }
            for e in 0..self.buf.stage.len() {
                self.buf.k[i][e] = (self.buf.stage[e] - self.buf.base[e]) / (h * GAMMA);
            }
        }
        true
    }

    /// The filtered error estimate of the step just computed (weighted RMS, 1 = tolerance;
    /// the largest over the states and the controlled sensitivity columns, whose
    /// variational equations have the same stiff part `f_x`, hence the same filter).
    fn error(&mut self, z: &[f64], h: f64) -> f64 {
        let (n, len) = (self.nx, self.controlled);
        for e in 0..len {
            let mut acc = 0.0;
            for (s, &w) in E.iter().enumerate() {
                acc += w * self.buf.k[s][e];
            }
            self.buf.delta[e] = h * acc;
        }
        self.buf.newton.solve(&mut self.buf.delta[..len], false);
        error_norm(len, n, |e| {
            self.buf.delta[e] / self.weight(z[e], self.buf.stage[e])
        })
    }

    /// Makes `buf.newton` the LU of `I − hγ J` for the step of size `h` from `z`:
    /// evaluates `J = f_x(z)` unless a valid one is kept, and factors unless the factors
    /// already are for `h` with that `J` (see [`Sdirk::reuse_size`]).
    fn factor(&mut self, z: &[f64], h: f64) {
        let n = self.nx;
        if !self.jac_valid {
            let mut jac = std::mem::take(&mut self.buf.jac0);
            self.iteration_matrix(
                0,
                z,
                1.0,
                MatMut::from_column_major_slice_mut(&mut jac, n, n),
            );
            // jac0 holds −f_x: (I − f_x) − I.
            for i in 0..n {
                jac[i * n + i] -= 1.0;
            }
            self.buf.jac0 = jac;
            (self.jac_valid, self.jac_current, self.lu_h) = (true, true, 0.0);
            self.stats.jacobians += 1;
        }
        if self.lu_h == h {
            return;
        }
        let c = h * GAMMA;
        let (matrix, jac0) = (&mut self.buf.newton.matrix, &self.buf.jac0);
        for col in 0..n {
            for r in 0..n {
                let id = if r == col { 1.0 } else { 0.0 };
                matrix[(r, col)] = id + c * jac0[col * n + r];
            }
        }
        self.buf.newton.factor();
        self.lu_h = h;
        self.stats.factorizations += 1;
    }

    /// RADAU5's rule for reusing the Newton matrix (Hairer & Wanner, *Solving ODEs II*,
    /// §IV.8): after an accepted step whose Newton iteration contracted fast (rate ≤
    /// 0.001, or convergence at the first iteration) the Jacobian is kept for the next
    /// step; if the proposed size `h` is then within `[1, 1.2]` times that of the current
    /// factors, the step takes the factors' size and reuses the LU too. A rejected step or
    /// a Newton failure with a kept Jacobian re-evaluates it at the current point.
    fn reuse_size(&self, h: f64) -> f64 {
        let kept = self.jac_valid && !self.jac_current && self.lu_h > 0.0;
        if kept && (1.0..=1.2).contains(&(h / self.lu_h)) {
            self.lu_h
        } else {
            h
        }
    }
}

impl Stepper for Sdirk<'_> {
    fn stats(&self) -> IntegratorStats {
        self.stats
    }

    fn advance(&mut self, t: &mut f64, z: &mut [f64], target: f64) -> Result<(), IntegratorError> {
        if self.h <= 0.0 && target > *t {
            self.h = self.initial_step(z, target - *t);
        }
        while *t < target {
            let steps = self.stats.accepted + self.stats.rejected;
            if steps >= self.options.max_steps {
                return Err(IntegratorError::MaxSteps { t: *t, steps });
            }
            let proposed = self.reuse_size(self.h);
            let last = *t + proposed >= target;
            let h = if last { target - *t } else { proposed };
            let tiny = h <= 16.0 * f64::EPSILON * t.abs().max(1.0);
            if tiny && !last {
                return Err(if self.newton_failed {
                    IntegratorError::NewtonFailure { t: *t, h }
                } else {
                    IntegratorError::StepTooSmall { t: *t, h }
                });
            }
            self.factor(z, h);
            self.theta = 0.0;
            self.newton_failed = !self.stages(z, h);
            if self.newton_failed {
                // A kept Jacobian is re-evaluated before the smaller step.
                self.jac_valid = self.jac_current;
                self.stats.rejected += 1;
                self.stats.newton_failures += 1;
                if tiny {
                    return Err(IntegratorError::NewtonFailure { t: *t, h });
                }
                self.h = 0.5 * h;
                continue;
            }
            let err = self.error(z, h);
            let finite = err.is_finite() && self.buf.stage.iter().all(|v| v.is_finite());
            if finite && err <= 1.0 {
                if let Some(tape) = self.tape.as_mut() {
                    tape.push(h);
                    tape.extend_from_slice(&self.buf.points);
                }
                *t = if last { target } else { *t + h };
                z.copy_from_slice(&self.buf.stage);
                (self.jac_valid, self.jac_current) = (self.theta <= 1e-3, false);
                self.stats.accepted += 1;
            } else {
                // As after a Newton failure: a kept Jacobian is re-evaluated.
                self.jac_valid = self.jac_current;
                self.stats.rejected += 1;
                if !finite && tiny {
                    return Err(IntegratorError::NonFinite { t: *t });
                }
            }
            self.h = next_step_size(proposed, h, err, finite, last, 0.25);
        }
        Ok(())
    }
}
