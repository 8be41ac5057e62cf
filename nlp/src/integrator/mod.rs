//! Adaptive integration of `ẋ = f(x, p)`: plant simulation, and an integrator as a symx
//! call node for multiple shooting (CasADi's `integrator`).
//!
//! The method is Dormand–Prince 5(4) (explicit, adaptive, FSAL; Hairer, Nørsett & Wanner,
//! *Solving ODEs I*, §II.5) with the usual mixed error norm
//! `‖e / (atol + rtol·max(|x|, |x_new|))‖_rms ≤ 1`. It suits non-stiff systems; a stiff
//! one makes it take very many steps (bounded by [`IntegratorOptions::max_steps`]).
//!
//! **Sensitivities.** Derivatives of `x(T)` with respect to `(x₀, p)` come from the
//! variational equations `Ṡ = f_x S + f_p` integrated together with `x` by the *same*
//! steps: the error control looks at the `x` components only, so the step sequence is the
//! one of the plain simulation and the sensitivities are the exact derivatives of the
//! numerical map `(x₀, p) ↦ x_N` (internal numerical differentiation, Bock 1981), which is
//! what an optimizer needs for its Newton steps to be consistent. Second derivatives repeat
//! the construction once more. Adjoint (reverse) products `Jᵀȳ` are formed from the
//! forward sensitivities (cheap for the small state and control dimensions of shooting),
//! not by a backward adjoint integration.
//!
//! [`Integrator::to_function`] wraps all this as an external [`Function`] `F(x0, p) → xf`
//! whose Jacobian and Hessian work through symx's derivative builders, so it can be
//! called in a [`crate::Problem`]'s expressions.
use std::sync::Arc;
use symx::{Expr, Function, Matrix, SymxError};
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
    /// Building the symbolic sensitivity equations failed.
    #[error(transparent)]
    Symbolic(#[from] SymxError),
}

/// Tolerances and limits of [`Integrator`] (CasADi/CVODES names and meanings).
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
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        IntegratorOptions {
            rtol: 1e-8,
            atol: 1e-10,
            max_steps: 100_000,
            initial_step: None,
        }
    }
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
}

/// An adaptive Dormand–Prince 5(4) integrator of `ẋ = f(x, p)` over `[t0, tf]`.
///
/// ```
/// use nlp::integrator::{Integrator, IntegratorOptions};
/// use symx::{Function, Matrix};
/// // ẋ = −k·x
/// let x = Matrix::sym_vec("x", 1);
/// let k = Matrix::sym_vec("k", 1);
/// let ode = Function::new(&[&x, &k], &[&[-k[0] * x[0]]]).unwrap();
/// let int = Integrator::new(&ode, 0.0, 2.0, IntegratorOptions::default()).unwrap();
/// let (xf, _) = int.simulate(&[1.0], &[0.5]).unwrap();
/// assert!((xf[0] - (-1.0f64).exp()).abs() < 1e-8);
/// ```
#[derive(Clone, Debug)]
pub struct Integrator {
    /// Level 0: `(x, p) → ẋ`; level k + 1: the variational equations of level k.
    levels: Vec<Level>,
    nx: usize,
    np: usize,
    t0: f64,
    tf: f64,
    options: IntegratorOptions,
}

/// One right-hand side of the hierarchy: state `z` (the first `nx` entries are `x`).
#[derive(Clone, Debug)]
struct Level {
    rhs: Function,
    nz: usize,
}

impl Integrator {
    /// An integrator of `ode` over `[t0, tf]`: `ode` has inputs `(x)` or `(x, p)` and one
    /// output `ẋ` of `x`'s length (a compiled expression; external functions have no
    /// symbolic Jacobian for the sensitivity equations). `tf > t0`.
    pub fn new(
        ode: &Function,
        t0: f64,
        tf: f64,
        options: IntegratorOptions,
    ) -> Result<Integrator, IntegratorError> {
        let bad = |why: String| Err(IntegratorError::BadOde { why });
        if !(1..=2).contains(&ode.n_inputs()) || ode.n_outputs() != 1 {
            return bad(format!(
                "expected inputs (x) or (x, p) and one output ẋ, got {} inputs and {} outputs",
                ode.n_inputs(),
                ode.n_outputs()
            ));
        }
        let nx = ode.input_sizes()[0];
        let np = ode.input_sizes().get(1).copied().unwrap_or(0);
        if ode.output_sizes()[0] != nx {
            return bad(format!(
                "ẋ has length {}, x has length {nx}",
                ode.output_sizes()[0]
            ));
        }
        if ode.is_external() {
            return bad(
                "an external function has no symbolic Jacobian for the sensitivity equations"
                    .into(),
            );
        }
        let check = |name, value: f64, ok: bool, why| {
            if ok {
                Ok(())
            } else {
                Err(IntegratorError::BadOption { name, value, why })
            }
        };
        check(
            "tf - t0",
            tf - t0,
            tf > t0 && (tf - t0).is_finite(),
            "must be finite and > 0",
        )?;
        check(
            "rtol",
            options.rtol,
            options.rtol > 0.0 && options.rtol < 1.0,
            "must be in (0, 1)",
        )?;
        check(
            "atol",
            options.atol,
            options.atol > 0.0 && options.atol.is_finite(),
            "must be finite and > 0",
        )?;
        check(
            "max_steps",
            options.max_steps as f64,
            options.max_steps > 0,
            "must be ≥ 1",
        )?;
        if let Some(h) = options.initial_step {
            check(
                "initial_step",
                h,
                h > 0.0 && h.is_finite(),
                "must be finite and > 0",
            )?;
        }
        // Level 0 in the normal form (z, p) → ż.
        let z = Matrix::sym_vec("z", nx);
        let p = Matrix::sym_vec("p", np);
        let args: Vec<&[Expr]> = if ode.n_inputs() == 2 {
            vec![&z, &p]
        } else {
            vec![&z]
        };
        let zdot = ode.apply(&args)?.remove(0);
        let rhs = Function::named("ode", &[("z", &z), ("p", &p)], &[("zdot", &zdot)])?;
        Ok(Integrator {
            levels: vec![Level { rhs, nz: nx }],
            nx,
            np,
            t0,
            tf,
            options,
        })
    }

    /// Number of states.
    pub fn nx(&self) -> usize {
        self.nx
    }

    /// Number of parameters (controls held constant over the interval, model parameters).
    pub fn np(&self) -> usize {
        self.np
    }

    /// `x(tf)` from `x(t0) = x0`, and the step statistics.
    pub fn simulate(
        &self,
        x0: &[f64],
        p: &[f64],
    ) -> Result<(Vec<f64>, IntegratorStats), IntegratorError> {
        self.check_args(x0, p)?;
        let mut out = vec![0.0; self.nx];
        let stats = self.run(0, x0, p, &[self.tf], &mut out)?;
        Ok((out, stats))
    }

    /// The states at `times` (non-decreasing, within `[t0, tf]`; steps end exactly on
    /// them), one vector per time: a plant simulation sampled on a grid.
    pub fn simulate_at(
        &self,
        x0: &[f64],
        p: &[f64],
        times: &[f64],
    ) -> Result<Vec<Vec<f64>>, IntegratorError> {
        self.check_args(x0, p)?;
        if times.windows(2).any(|w| w[0] > w[1] || w[0].is_nan())
            || times.iter().any(|&t| !(t >= self.t0 && t <= self.tf))
        {
            return Err(IntegratorError::BadTimes {
                t0: self.t0,
                tf: self.tf,
            });
        }
        let mut out = vec![0.0; self.nx * times.len()];
        self.run(0, x0, p, times, &mut out)?;
        Ok(out
            .chunks(self.nx.max(1))
            .take(times.len())
            .map(|c| c.to_vec())
            .collect())
    }

    /// `x(tf)` and its Jacobian `∂x(tf)/∂(x0, p)` (`nx × (nx + np)`, column-major), the
    /// exact derivative of the numerical solution (see the module notes).
    pub fn simulate_with_jacobian(
        &self,
        x0: &[f64],
        p: &[f64],
    ) -> Result<(Vec<f64>, Vec<f64>), IntegratorError> {
        self.check_args(x0, p)?;
        let int = self.with_levels(2)?;
        let m = self.nx + self.np;
        let mut z = vec![0.0; int.levels[1].nz];
        int.run(1, x0, p, &[self.tf], &mut z)?;
        let xf = z[..self.nx].to_vec();
        Ok((xf, z[self.nx..self.nx + self.nx * m].to_vec()))
    }

    /// This integrator as an external symx function `F(x0, p) → xf` (inputs named `x0`
    /// and `p`, output `xf`), with its Jacobian and Hessian (the sensitivity equations of
    /// first and second order, built here once); third derivatives are refused with
    /// [`SymxError::NoDerivative`]. A failed integration makes the outputs NaN (the
    /// solver calling it then rejects the point). Evaluation allocates its buffers per
    /// call.
    ///
    /// ```
    /// use nlp::integrator::{Integrator, IntegratorOptions};
    /// use symx::{gradient, Function, Matrix};
    /// let x = Matrix::sym_vec("x", 1);
    /// let k = Matrix::sym_vec("k", 1);
    /// let ode = Function::new(&[&x, &k], &[&[-k[0] * x[0]]]).unwrap();
    /// let f = Integrator::new(&ode, 0.0, 1.0, IntegratorOptions::default()).unwrap().to_function().unwrap();
    /// let w = Matrix::sym_vec("w", 2);
    /// let xf = f.apply(&[&w[..1], &w[1..]]).unwrap()[0][0];        // w0·exp(−w1)
    /// let g = Function::new(&[&w], &[&gradient(xf, &w).unwrap()]).unwrap();
    /// let d = g.call(&[&[2.0, 0.5]]).unwrap()[0].clone();
    /// // ∂/∂w0 = e^{−w1}, ∂/∂w1 = −w0·e^{−w1}, to the default rtol 1e-8 (global error ≲ 1e-7)
    /// assert!((d[0] - (-0.5f64).exp()).abs() < 1e-7 && (d[1] + 2.0 * (-0.5f64).exp()).abs() < 1e-7);
    /// ```
    pub fn to_function(&self) -> Result<Function, IntegratorError> {
        const ORDER: usize = 2;
        let int = Arc::new(self.with_levels(ORDER + 1)?);
        let (nx, np, m) = (self.nx, self.np, self.nx + self.np);
        // Level k outputs the entries `sel[k]` of z_k(tf): level 0 x(tf), level k + 1 the
        // Jacobian of level k's outputs, column-major (column j of ∂z_k/∂(x0, p) starts at
        // nz_k + j·nz_k in z_{k+1}).
        let mut sel: Vec<Vec<usize>> = vec![(0..nx).collect()];
        for k in 0..ORDER {
            let nz = int.levels[k].nz;
            let next = (0..m)
                .flat_map(|j| sel[k].iter().map(move |&i| nz + j * nz + i))
                .collect();
            sel.push(next);
        }
        let mut function: Option<Function> = None;
        for k in (0..=ORDER).rev() {
            let int = int.clone();
            let picked = sel[k].clone();
            let nz = int.levels[k].nz;
            let name = match k {
                0 => "integrator".to_string(),
                1 => "jac_integrator".to_string(),
                _ => format!("jac{k}_integrator"),
            };
            let eval = move |args: &[f64], out: &mut [f64]| {
                let mut z = vec![0.0; nz];
                match int.run(k, &args[..nx], &args[nx..], &[int.tf], &mut z) {
                    Ok(_) => out.iter_mut().zip(&picked).for_each(|(o, &i)| *o = z[i]),
                    Err(_) => out.fill(f64::NAN),
                }
            };
            let out_name = if k == 0 { "xf" } else { "jac" };
            let f = Function::external(
                &name,
                &[("x0", nx), ("p", np)],
                &[(out_name, sel[k].len())],
                eval,
            )?;
            function = Some(match function {
                None => f,
                Some(jac) => {
                    let dense = symx::sparsity::pattern_from_entries(
                        sel[k].len(),
                        m,
                        (0..m).flat_map(|j| (0..sel[k].len()).map(move |i| (i, j))),
                    );
                    f.with_jacobian(&dense, &jac)?
                }
            });
        }
        Ok(function.expect("ORDER + 1 levels built"))
    }

    fn check_args(&self, x0: &[f64], p: &[f64]) -> Result<(), IntegratorError> {
        let len = |what, expected, got| {
            if expected == got {
                Ok(())
            } else {
                Err(IntegratorError::Length {
                    what,
                    expected,
                    got,
                })
            }
        };
        len("x0", self.nx, x0.len())?;
        len("p", self.np, p.len())
    }

    /// This integrator with `count` levels of sensitivity equations built.
    fn with_levels(&self, count: usize) -> Result<Integrator, IntegratorError> {
        let mut int = self.clone();
        let m = self.nx + self.np;
        while int.levels.len() < count {
            let prev = int.levels.last().expect("level 0");
            let nz = prev.nz;
            let z = Matrix::sym_vec("z", nz);
            let s = Matrix::sym_vec("s", nz * m);
            let p = Matrix::sym_vec("p", self.np);
            let zdot = prev.rhs.apply(&[&z, &p])?.remove(0);
            // Ṡ = f_z S + [0 f_p] column by column: ṡ_j = f_z s_j + ∂f/∂x0_j or ∂f/∂p_j.
            let mut out = zdot.clone();
            for j in 0..m {
                let sj = &s[j * nz..(j + 1) * nz];
                let mut tangent = symx::forward(&zdot, &z, sj)?;
                if j >= self.nx {
                    let mut seed = vec![Expr::zero(); self.np];
                    seed[j - self.nx] = Expr::one();
                    let dp = symx::forward(&zdot, &p, &seed)?;
                    tangent.iter_mut().zip(dp).for_each(|(t, d)| *t += d);
                }
                out.extend(tangent);
            }
            let state: Vec<Expr> = z.iter().chain(s.iter()).copied().collect();
            let rhs = Function::named(
                "variational",
                &[("z", &state), ("p", &p)],
                &[("zdot", &out)],
            )?;
            int.levels.push(Level {
                rhs,
                nz: nz * (1 + m),
            });
        }
        Ok(int)
    }

    /// The initial state of level `k`: `x0`, then `∂z_{k-1}(t0)/∂(x0, p)` (the identity on
    /// the `x` rows of the `x0` columns, zero elsewhere) and so on down the levels.
    fn initial_state(&self, k: usize, x0: &[f64], z: &mut [f64]) {
        z.fill(0.0);
        z[..self.nx].copy_from_slice(x0);
        for level in 1..=k {
            let nz = self.levels[level - 1].nz;
            for j in 0..self.nx {
                z[nz + j * nz + j] = 1.0;
            }
        }
    }

    /// Integrates level `k` from `t0`, writing `z(t)` for each of `times` into `out`
    /// (consecutive blocks of the level's state length, or of `x` only for `simulate_at`
    /// which passes `out` of `nx` per time).
    fn run(
        &self,
        k: usize,
        x0: &[f64],
        p: &[f64],
        times: &[f64],
        out: &mut [f64],
    ) -> Result<IntegratorStats, IntegratorError> {
        let level = &self.levels[k];
        let nz = level.nz;
        let block = out.len() / times.len().max(1);
        let mut z = vec![0.0; nz];
        self.initial_state(k, x0, &mut z);
        let mut dopri = Dopri::new(&level.rhs, nz, self.nx, p, self.options);
        let mut t = self.t0;
        for (i, &target) in times.iter().enumerate() {
            dopri.advance(&mut t, &mut z, target)?;
            out[i * block..(i + 1) * block].copy_from_slice(&z[..block]);
        }
        Ok(dopri.stats)
    }
}

/// Dormand–Prince 5(4) coefficients (Dormand & Prince 1980; Hairer–Nørsett–Wanner Table 5.2).
/// The system is autonomous, so the nodes `c` are not needed.
const A: [[f64; 6]; 7] = [
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
struct Dopri<'a> {
    rhs: &'a Function,
    p: &'a [f64],
    /// Entries under error control (the original states).
    controlled: usize,
    k: [Vec<f64>; 7],
    stage: Vec<f64>,
    work: Vec<f64>,
    h: f64,
    /// Whether `k[0]` holds `f(z)` at the current point (first same as last).
    fresh: bool,
    options: IntegratorOptions,
    stats: IntegratorStats,
}

impl<'a> Dopri<'a> {
    fn new(
        rhs: &'a Function,
        nz: usize,
        controlled: usize,
        p: &'a [f64],
        options: IntegratorOptions,
    ) -> Dopri<'a> {
        Dopri {
            rhs,
            p,
            controlled,
            k: std::array::from_fn(|_| vec![0.0; nz]),
            stage: vec![0.0; nz],
            work: vec![0.0; rhs.work_size()],
            h: options.initial_step.unwrap_or(0.0),
            fresh: false,
            options,
            stats: IntegratorStats::default(),
        }
    }

    fn eval(&mut self, z_is_stage: bool, z: &[f64], into: usize) {
        let input = if z_is_stage { &self.stage[..] } else { z };
        let mut out = std::mem::take(&mut self.k[into]);
        self.rhs
            .eval(&[input, self.p], &mut [&mut out], &mut self.work)
            .expect("sizes fixed at construction");
        self.k[into] = out;
        self.stats.rhs_evaluations += 1;
    }

    fn weight(&self, a: f64, b: f64) -> f64 {
        self.options.atol + self.options.rtol * a.abs().max(b.abs())
    }

    /// Hairer's starting step (Solving ODEs I, §II.4): from ‖z‖, ‖f(z)‖ and one Euler step.
    fn initial_step(&mut self, z: &[f64], span: f64) -> f64 {
        let n = self.controlled;
        let w: Vec<f64> = z[..n].iter().map(|&v| self.weight(v, v)).collect();
        let rms = |v: &mut dyn Iterator<Item = f64>| {
            (v.zip(&w).map(|(a, b)| (a / b).powi(2)).sum::<f64>() / n.max(1) as f64).sqrt()
        };
        let d0 = rms(&mut z.iter().copied());
        let d1 = rms(&mut self.k[0].iter().copied());
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        let h0 = h0.min(span);
        for ((s, &zi), &ki) in self.stage.iter_mut().zip(z).zip(&self.k[0]) {
            *s = zi + h0 * ki;
        }
        self.eval(true, z, 1);
        let d2 = rms(&mut self.k[1].iter().zip(&self.k[0]).map(|(a, b)| a - b)) / h0;
        let h1 = if d1.max(d2) <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / 5.0)
        };
        (100.0 * h0).min(h1).min(span)
    }

    /// Steps from `t` to exactly `target`.
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
                for (i, (stage, &zi)) in self.stage.iter_mut().zip(z.iter()).enumerate() {
                    let mut acc = 0.0;
                    for (j, &a) in A[s][..s].iter().enumerate() {
                        acc += a * self.k[j][i];
                    }
                    *stage = zi + h * acc;
                }
                self.eval(true, z, s);
            }
            // The 5th-order solution is the last stage's point (FSAL).
            let znew = &self.stage;
            let mut sum = 0.0;
            let mut finite = true;
            for i in 0..self.controlled {
                let mut e = 0.0;
                for (s, &w) in E.iter().enumerate() {
                    e += w * self.k[s][i];
                }
                let r = h * e / self.weight(z[i], znew[i]);
                finite &= r.is_finite();
                sum += r * r;
            }
            let err = (sum / self.controlled.max(1) as f64).sqrt();
            let finite = finite && znew.iter().all(|v| v.is_finite());
            if finite && err <= 1.0 {
                *t = if last { target } else { *t + h };
                z.copy_from_slice(&self.stage);
                self.k.swap(0, 6);
                self.stats.accepted += 1;
                let factor = if err == 0.0 {
                    5.0
                } else {
                    (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
                };
                // After a step shortened to hit the target, keep the unshortened size.
                self.h = if last { self.h.max(h) } else { h * factor };
            } else {
                self.stats.rejected += 1;
                let factor = if finite {
                    (0.9 * err.powf(-0.2)).clamp(0.2, 1.0)
                } else {
                    0.2
                };
                if !finite && h <= 1e-14 * t.abs().max(1.0) {
                    return Err(IntegratorError::NonFinite { t: *t });
                }
                self.h = h * factor;
            }
        }
        Ok(())
    }
}
