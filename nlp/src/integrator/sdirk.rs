//! SDIRK4: the implicit adaptive stepper for stiff systems.
//!
//! Hairer & Wanner's L-stable, stiffly accurate singly diagonally implicit Runge–Kutta
//! method of order 4 with an embedded order-3 solution (*Solving ODEs II*, §IV.6, Table
//! 6.5, γ = 1/4). Each stage `Zᵢ = zₙ + hΣⱼ<ᵢ aᵢⱼKⱼ + hγf(Zᵢ)` is solved by a simplified
//! Newton iteration with the matrix `I − hγ f_x(xₙ)` (exact Jacobian, one LU per step
//! attempt); the error estimate is filtered through the same LU (as in RADAU5) so that
//! stiff components do not force tiny steps.
//!
//! **Sensitivities** (levels above 0, see [`super::level`]): once the states' stage `Xᵢ`
//! has converged, the sensitivities' stage is the *exact* solution of the linear stage
//! equation `(I − hγ f_x(Xᵢ)) Sᵢ = Sₙ + hΣⱼ<ᵢ aᵢⱼ Ṡⱼ + hγ f_θ(Xᵢ)`, i.e. the derivative of
//! the step map with the stage equations solved exactly, at the converged stage. The
//! steps are chosen by the states alone, so they are the same steps, bit for bit, as
//! those of the plain simulation.
use super::level::Level;
use super::options::{IntegratorError, IntegratorOptions, IntegratorStats};
use super::stepper::{next_step_size, Stepper};
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{Mat, MatMut};

const GAMMA: f64 = 0.25;
/// Stage coefficients `aᵢⱼ` (lower triangle; the diagonal is `GAMMA`).
const A: [[f64; 4]; 5] = [
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
    options: IntegratorOptions,
    stats: IntegratorStats,
    h: f64,
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
    /// `−f_x(xₙ)` (dense), valid while `jac_fresh`.
    jac0: Mat<f64>,
    jac_fresh: bool,
    /// The LU of `I − hγ f_x(xₙ)` of the current step attempt.
    newton: Option<PartialPivLu<f64>>,
    /// Whether the last attempt failed in Newton's iteration.
    newton_failed: bool,
}

impl<'a> Sdirk<'a> {
    /// A stepper for `levels.last()`; every level below it, and level 0, has its Jacobian.
    pub(super) fn new(
        levels: &'a [Level],
        nx: usize,
        p: &'a [f64],
        options: IntegratorOptions,
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
        Sdirk {
            levels,
            p,
            nx,
            options,
            stats: IntegratorStats::default(),
            h: options.initial_step.unwrap_or(0.0),
            k: std::array::from_fn(|_| vec![0.0; nz]),
            stage: vec![0.0; nz],
            base: vec![0.0; nz],
            fz: vec![0.0; nz],
            delta: vec![0.0; nz],
            padded: vec![0.0; nz],
            jac_values: vec![0.0; nnz],
            work: vec![0.0; work],
            jac0: Mat::zeros(nx, nx),
            jac_fresh: false,
            newton: None,
            newton_failed: false,
        }
    }

    fn weight(&self, a: f64, b: f64) -> f64 {
        self.options.atol + self.options.rtol * a.abs().max(b.abs())
    }

    /// `f` of level `level` at `input` into `self.fz`.
    fn eval_rhs(&mut self, level: usize, input: &[f64]) {
        let nz = self.levels[level].nz;
        self.levels[level]
            .rhs
            .eval(&[input, self.p], &mut [&mut self.fz[..nz]], &mut self.work)
            .expect("sizes fixed at construction");
        self.stats.rhs_evaluations += 1;
    }

    /// `I − c·∂ż/∂z` of level `level` at `z` (its first `nz` entries), dense.
    fn iteration_matrix(&mut self, level: usize, z: &[f64], c: f64, into: &mut Mat<f64>) {
        let jac = self.levels[level]
            .jacobian
            .as_ref()
            .expect("Jacobians built for the implicit method");
        let n = self.levels[level].nz;
        let nnz = jac.entries.len();
        jac.values
            .eval(
                &[&z[..n], self.p],
                &mut [&mut self.jac_values[..nnz]],
                &mut self.work,
            )
            .expect("sizes fixed at construction");
        into.fill(0.0);
        for (&v, &(r, col)) in self.jac_values.iter().zip(&jac.entries) {
            into[(r, col)] = -c * v;
        }
        for i in 0..n {
            into[(i, i)] += 1.0;
        }
    }

    /// Hairer's first guess from ‖x‖ and ‖f(x)‖ (the growth of the step controller does
    /// the rest).
    fn initial_step(&mut self, z: &[f64], span: f64) -> f64 {
        let n = self.nx;
        self.eval_rhs(0, &z[..n]);
        let (mut d0, mut d1) = (0.0, 0.0);
        for (&zi, &fi) in z[..n].iter().zip(&self.fz) {
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
    /// `self.stage`, given `self.base`); `false` if Newton's iteration failed.
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
        let mut matrix = Mat::zeros(n, n);
        let stage = std::mem::take(&mut self.stage);
        self.iteration_matrix(level - 1, &stage, h * GAMMA, &mut matrix);
        self.stage = stage;
        self.padded[..n].copy_from_slice(&self.stage[..n]);
        self.padded[n..nz].fill(0.0);
        let padded = std::mem::take(&mut self.padded);
        self.eval_rhs(level, &padded[..nz]);
        self.padded = padded;
        for e in n..nz {
            self.stage[e] = self.base[e] + h * GAMMA * self.fz[e];
        }
        let lu = matrix.partial_piv_lu();
        lu.solve_in_place(MatMut::from_column_major_slice_mut(
            &mut self.stage[n..nz],
            n,
            nz / n - 1,
        ));
        self.stage[n..nz].iter().all(|v| v.is_finite())
    }

    /// Simplified Newton for the states' stage `i` with the step's LU.
    fn newton_stage(&mut self, i: usize, h: f64) -> bool {
        let n = self.nx;
        for e in 0..n {
            let previous = if i > 0 { self.k[i - 1][e] } else { 0.0 };
            self.stage[e] = self.base[e] + h * GAMMA * previous;
        }
        let mut previous_norm = f64::INFINITY;
        for iteration in 0..MAX_NEWTON {
            let stage = std::mem::take(&mut self.stage);
            self.eval_rhs(0, &stage[..n]);
            self.stage = stage;
            for e in 0..n {
                self.delta[e] = self.base[e] + h * GAMMA * self.fz[e] - self.stage[e];
            }
            let lu = self.newton.as_ref().expect("factored before the stages");
            lu.solve_in_place(MatMut::from_column_major_slice_mut(
                &mut self.delta[..n],
                n,
                1,
            ));
            let mut sum = 0.0;
            for e in 0..n {
                self.stage[e] += self.delta[e];
                sum += (self.delta[e] / self.weight(self.stage[e], self.stage[e])).powi(2);
            }
            let norm = (sum / n.max(1) as f64).sqrt();
            if !norm.is_finite() {
                return false;
            }
            let rate = norm / previous_norm;
            if iteration > 0 && rate >= 0.9 {
                return false;
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
            for (e, (b, &ze)) in self.base.iter_mut().zip(z).enumerate() {
                let mut acc = 0.0;
                for (j, &a) in A[i][..i].iter().enumerate() {
                    acc += a * self.k[j][e];
                }
                *b = ze + h * acc;
            }
            if !self.solve_stage(top, i, h) {
                return false;
            }
            for e in 0..self.stage.len() {
                self.k[i][e] = (self.stage[e] - self.base[e]) / (h * GAMMA);
            }
        }
        true
    }

    /// The filtered error estimate of the step just computed (weighted RMS, 1 = tolerance).
    fn error(&mut self, z: &[f64], h: f64) -> f64 {
        let n = self.nx;
        for e in 0..n {
            let mut acc = 0.0;
            for (s, &w) in E.iter().enumerate() {
                acc += w * self.k[s][e];
            }
            self.delta[e] = h * acc;
        }
        let lu = self.newton.as_ref().expect("factored before the stages");
        lu.solve_in_place(MatMut::from_column_major_slice_mut(
            &mut self.delta[..n],
            n,
            1,
        ));
        let mut sum = 0.0;
        for ((&d, &a), &b) in self.delta[..n].iter().zip(z).zip(&self.stage) {
            sum += (d / self.weight(a, b)).powi(2);
        }
        (sum / n.max(1) as f64).sqrt()
    }

    /// Factors `I − hγ f_x(xₙ)` (the Jacobian evaluated once per accepted point).
    fn factor(&mut self, z: &[f64], h: f64) {
        if !self.jac_fresh {
            let mut jac = std::mem::replace(&mut self.jac0, Mat::zeros(0, 0));
            self.iteration_matrix(0, z, 1.0, &mut jac);
            // jac0 holds −f_x: (I − f_x) − I.
            for i in 0..self.nx {
                jac[(i, i)] -= 1.0;
            }
            self.jac0 = jac;
            self.jac_fresh = true;
        }
        let n = self.nx;
        let c = h * GAMMA;
        let matrix = Mat::from_fn(n, n, |r, col| {
            let id = if r == col { 1.0 } else { 0.0 };
            id + c * self.jac0[(r, col)]
        });
        self.newton = Some(matrix.partial_piv_lu());
        self.stats.factorizations += 1;
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
            let last = *t + self.h >= target;
            let h = if last { target - *t } else { self.h };
            let tiny = h <= 16.0 * f64::EPSILON * t.abs().max(1.0);
            if tiny && !last {
                return Err(if self.newton_failed {
                    IntegratorError::NewtonFailure { t: *t, h }
                } else {
                    IntegratorError::StepTooSmall { t: *t, h }
                });
            }
            self.factor(z, h);
            self.newton_failed = !self.stages(z, h);
            if self.newton_failed {
                self.stats.rejected += 1;
                self.stats.newton_failures += 1;
                if tiny {
                    return Err(IntegratorError::NewtonFailure { t: *t, h });
                }
                self.h = 0.5 * h;
                continue;
            }
            let err = self.error(z, h);
            let finite = err.is_finite() && self.stage.iter().all(|v| v.is_finite());
            if finite && err <= 1.0 {
                *t = if last { target } else { *t + h };
                z.copy_from_slice(&self.stage);
                self.jac_fresh = false;
                self.stats.accepted += 1;
            } else {
                self.stats.rejected += 1;
                if !finite && tiny {
                    return Err(IntegratorError::NonFinite { t: *t });
                }
            }
            self.h = next_step_size(self.h, h, err, finite, last, 0.25);
        }
        Ok(())
    }
}
