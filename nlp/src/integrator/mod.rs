//! Adaptive integration of `ẋ = f(x, p)`: plant simulation, and an integrator as a symx
//! call node for multiple shooting (CasADi's `integrator`).
//!
//! Two methods ([`Method`]), both adaptive with the usual mixed error norm
//! `‖e / (atol + rtol·max(|x|, |x_new|))‖_rms ≤ 1`:
//! * [`Method::Dopri5`] (default), Dormand–Prince 5(4) (explicit, FSAL; Hairer, Nørsett &
//!   Wanner, *Solving ODEs I*, §II.5) for non-stiff systems; a stiff one makes it take very
//!   many steps (bounded by [`IntegratorOptions::max_steps`]);
//! * [`Method::Sdirk4`], an L-stable implicit Runge–Kutta method of order 4 (Hairer &
//!   Wanner, *Solving ODEs II*, §IV.6) whose stages are solved by Newton's method with the
//!   exact Jacobian of `f` from symx AD: for stiff systems.
//!
//! **Sensitivities.** Derivatives of `x(T)` with respect to `(x₀, p)` come from the
//! variational equations `Ṡ = f_x S + f_p` integrated together with `x` by the *same*
//! steps. By default the error control looks at the `x` components only, so the step
//! sequence is the one of the plain simulation and the sensitivities are the exact
//! derivatives of the numerical map `(x₀, p) ↦ x_N` (internal numerical differentiation,
//! Bock 1981), which is what an optimizer needs for its Newton steps to be consistent.
//! [`IntegratorOptions::sensitivity_error_control`] puts the sensitivities under the
//! error control too (CVODES' `fsens_err_con`): accurate sensitivities where the
//! variational equations have a transient the states do not show. Second derivatives
//! repeat the construction once more. Adjoint (reverse) products `vᵀ∂x(T)/∂(x₀, p)`:
//! [`Integrator::simulate_with_adjoint`] runs a backward pass over the recorded steps
//! (the discrete adjoint, see `adjoint`), one pass per `v` whatever `nx + np`; the
//! reverse products of [`Integrator::to_function`]'s node still come from its forward
//! sensitivities (symx's external node takes a Jacobian, not a reverse product).
//!
//! [`Integrator::to_function`] wraps all this as an external [`Function`] `F(x0, p) → xf`
//! whose Jacobian and Hessian work through symx's derivative builders, so it can be
//! called in a [`crate::Problem`]'s expressions.
mod adjoint;
mod dopri;
mod level;
mod lu;
mod options;
mod sdirk;
mod stepper;

pub use options::{IntegratorError, IntegratorOptions, IntegratorStats, Method};

use adjoint::{dopri_record_len, sdirk_record_len, vjp_function, Backward};
use dopri::{Dopri, DopriBuffers};
use level::Level;
use sdirk::{Sdirk, SdirkBuffers};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};
use stepper::Stepper;
use symx::{Expr, Function, Matrix};

/// An adaptive integrator of `ẋ = f(x, p)` over `[t0, tf]` (the method chosen by
/// [`IntegratorOptions::method`]).
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
    /// `(x, p, v) → (f_xᵀ v, f_pᵀ v)`, built by the first adjoint integration.
    vjp: OnceLock<Function>,
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
        let (nx, np) = check_ode(ode)?;
        check_options(t0, tf, &options)?;
        // Level 0 in the normal form (z, p) → ż.
        let z = Matrix::sym_vec("z", nx);
        let p = Matrix::sym_vec("p", np);
        let args: Vec<&[Expr]> = if ode.n_inputs() == 2 {
            vec![&z, &p]
        } else {
            vec![&z]
        };
        let zdot = ode.apply(&args)?.remove(0);
        let mut level = Level::new("ode", &z, &p, &zdot)?;
        if options.method == Method::Sdirk4 {
            level.add_jacobian(np)?;
        }
        Ok(Integrator {
            levels: vec![level],
            nx,
            np,
            t0,
            tf,
            options,
            vjp: OnceLock::new(),
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

    /// `x(tf)` and the row `vᵀ ∂x(tf)/∂(x0, p)` (length `nx + np`: the `x0` part, then the
    /// `p` part) by the adjoint method: one integration that records its steps, then one
    /// backward pass over them (see the module notes). The derivative is that of the very
    /// map [`Integrator::simulate`] computes (same steps, `x(tf)` bit-identical), equal to
    /// `vᵀ` times [`Integrator::simulate_with_jacobian`]'s Jacobian up to rounding when the
    /// sensitivities are not under error control; its cost does not grow with `nx + np`
    /// (one backward pass per `v` instead of `nx + np` sensitivity columns).
    ///
    /// ```
    /// use nlp::integrator::{Integrator, IntegratorOptions};
    /// use symx::{Function, Matrix};
    /// // ẋ = −k·x: x(1) = x0·e^{−k}, so ∂x(1)/∂(x0, k) = (e^{−k}, −x0·e^{−k}).
    /// let x = Matrix::sym_vec("x", 1);
    /// let k = Matrix::sym_vec("k", 1);
    /// let ode = Function::new(&[&x, &k], &[&[-k[0] * x[0]]]).unwrap();
    /// let int = Integrator::new(&ode, 0.0, 1.0, IntegratorOptions::default()).unwrap();
    /// let (xf, row) = int.simulate_with_adjoint(&[2.0], &[0.5], &[1.0]).unwrap();
    /// let e = (-0.5f64).exp();
    /// assert!((xf[0] - 2.0 * e).abs() < 1e-7);
    /// assert!((row[0] - e).abs() < 1e-7 && (row[1] + 2.0 * e).abs() < 1e-7);
    /// ```
    pub fn simulate_with_adjoint(
        &self,
        x0: &[f64],
        p: &[f64],
        v: &[f64],
    ) -> Result<(Vec<f64>, Vec<f64>), IntegratorError> {
        self.check_args(x0, p)?;
        if v.len() != self.nx {
            return Err(IntegratorError::Length {
                what: "v",
                expected: self.nx,
                got: v.len(),
            });
        }
        let vjp = self.vjp()?;
        let mut ws = Workspace {
            tape: Some(Vec::new()),
            ..Default::default()
        };
        let mut xf = vec![0.0; self.nx];
        self.run_in(0, x0, p, &[self.tf], &mut xf, &mut ws)?;
        let tape = ws.tape.take().expect("recorded");
        let mut lambda = v.to_vec();
        let mut pbar = vec![0.0; self.np];
        let mut backward = Backward::new(&self.levels[0], vjp, p, self.nx);
        match self.options.method {
            Method::Dopri5 => {
                for record in tape.rchunks(dopri_record_len(self.nx)) {
                    backward.dopri_step(record, &mut lambda, &mut pbar);
                }
            }
            Method::Sdirk4 => {
                for record in tape.rchunks(sdirk_record_len(self.nx)) {
                    backward.sdirk_step(record, &mut lambda, &mut pbar);
                }
            }
        }
        lambda.extend(pbar);
        Ok((xf, lambda))
    }

    /// The compiled vector-Jacobian product of the ODE, built on first use.
    fn vjp(&self) -> Result<&Function, IntegratorError> {
        if self.vjp.get().is_none() {
            let f = vjp_function(&self.levels[0], self.nx, self.np)?;
            // Another thread may have set it meanwhile: the same function.
            let _ = self.vjp.set(f);
        }
        Ok(self.vjp.get().expect("set above"))
    }

    /// This integrator as an external symx function `F(x0, p) → xf` (inputs named `x0`
    /// and `p`, output `xf`), with its Jacobian and Hessian (the sensitivity equations of
    /// first and second order, built here once); third derivatives are refused with
    /// [`symx::SymxError::NoDerivative`]. A failed integration makes the outputs NaN (the
    /// solver calling it then rejects the point). Evaluation allocates nothing once warm,
    /// with either method: each evaluator keeps a pool of buffers (stages, LU factors),
    /// one set per concurrent caller (results do not depend on which set is used). With
    /// [`IntegratorOptions::sensitivity_error_control`], `xf` is computed together with
    /// the first-order sensitivities, on the steps of its Jacobian.
    ///
    /// Reverse mode through the node — a gradient ([`symx::gradient`], the objective's
    /// gradient of a `Problem`), a vector–Jacobian product ([`symx::reverse`]) — calls
    /// its reverse hook ([`symx::Function::with_vjp`]):
    /// [`Integrator::simulate_with_adjoint`], one backward pass whatever `nx + np`, where
    /// the Jacobian integrates `nx + np` sensitivity columns. The Jacobian of the node's
    /// outputs (a shooting constraint's) and forward mode use the Jacobian. Under `sensitivity_error_control` the node has
    /// no hook (the adjoint would not take the steps `xf` is computed on). The adjoint
    /// evaluation allocates (its step record), unlike the node's other evaluators.
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
            // With the sensitivities under error control they choose the steps: `xf` is
            // then computed with them (level 1), on the steps of its Jacobian.
            let run = if k == 0 && self.options.sensitivity_error_control {
                1
            } else {
                k
            };
            let name = match k {
                0 => "integrator".to_string(),
                1 => "jac_integrator".to_string(),
                _ => format!("jac{k}_integrator"),
            };
            // Buffers kept between evaluations, one set per concurrent caller.
            let pool: Mutex<Vec<Workspace>> = Mutex::new(Vec::new());
            let eval = move |args: &[f64], out: &mut [f64]| {
                let take = || pool.lock().unwrap_or_else(PoisonError::into_inner).pop();
                let mut ws = take().unwrap_or_default();
                match int.run_in(run, &args[..nx], &args[nx..], &[int.tf], &mut [], &mut ws) {
                    Ok(_) => out
                        .iter_mut()
                        .zip(&picked)
                        .for_each(|(o, &i)| *o = ws.state[i]),
                    Err(_) => out.fill(f64::NAN),
                }
                pool.lock().unwrap_or_else(PoisonError::into_inner).push(ws);
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
        let function = function.expect("ORDER + 1 levels built");
        if self.options.sensitivity_error_control {
            // `xf` then rides on the sensitivities' steps, which the adjoint does not take.
            return Ok(function);
        }
        Ok(function.with_vjp(&Integrator::adjoint_function(int)?)?)
    }

    /// `(x0, p, v) → vᵀ ∂x(tf)/∂(x0, p)` by [`Integrator::simulate_with_adjoint`], as an
    /// external function: the reverse hook of [`Integrator::to_function`]'s node (NaN
    /// where the integration fails, as the node's other evaluators).
    fn adjoint_function(int: Arc<Integrator>) -> Result<Function, IntegratorError> {
        int.vjp()?; // built now, so that an error shows here
        let (nx, m) = (int.nx, int.nx + int.np);
        let eval = move |a: &[f64], out: &mut [f64]| match int.simulate_with_adjoint(
            &a[..nx],
            &a[nx..m],
            &a[m..],
        ) {
            Ok((_, row)) => out.copy_from_slice(&row),
            Err(_) => out.fill(f64::NAN),
        };
        Ok(Function::external(
            "adj_integrator",
            &[("x0", nx), ("p", m - nx), ("adj", nx)],
            &[("adj_in", m)],
            eval,
        )?)
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

    /// This integrator with `count` levels of sensitivity equations built (and, for the
    /// implicit method, the Jacobians of all but the top level).
    fn with_levels(&self, count: usize) -> Result<Integrator, IntegratorError> {
        let mut int = self.clone();
        while int.levels.len() < count {
            let prev = int.levels.last_mut().expect("level 0");
            if self.options.method == Method::Sdirk4 {
                prev.add_jacobian(self.np)?;
            }
            let next = prev.variational(self.nx, self.np)?;
            int.levels.push(next);
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
        self.run_in(k, x0, p, times, out, &mut Workspace::default())
    }

    /// [`Integrator::run`] with the buffers of `ws` (reused: an integration that fits in
    /// them allocates nothing, unless it records a tape). The final state is left in `ws.state`.
    fn run_in(
        &self,
        k: usize,
        x0: &[f64],
        p: &[f64],
        times: &[f64],
        out: &mut [f64],
        ws: &mut Workspace,
    ) -> Result<IntegratorStats, IntegratorError> {
        let nz = self.levels[k].nz;
        ws.state.resize(nz, 0.0);
        self.initial_state(k, x0, &mut ws.state);
        let controlled = self.controlled(k);
        match self.options.method {
            Method::Dopri5 => {
                let rhs = &self.levels[k].rhs;
                let buffers = std::mem::take(&mut ws.dopri);
                let mut dopri = Dopri::new(rhs, nz, self.nx, controlled, p, self.options, buffers)
                    .with_tape(ws.tape.as_mut());
                let result = self.drive(&mut dopri, &mut ws.state, times, out);
                ws.dopri = dopri.into_buffers();
                result
            }
            Method::Sdirk4 => {
                let levels = &self.levels[..=k];
                let buffers = std::mem::take(&mut ws.sdirk);
                let mut sdirk = Sdirk::new(levels, self.nx, controlled, p, self.options, buffers)
                    .with_tape(ws.tape.as_mut());
                let result = self.drive(&mut sdirk, &mut ws.state, times, out);
                ws.sdirk = sdirk.into_buffers();
                result
            }
        }
    }

    /// How many leading entries of level `k`'s state are under error control: the states,
    /// and with [`IntegratorOptions::sensitivity_error_control`] the first-order
    /// sensitivities too (all of level 1; of a higher level, its part that is level 1, so
    /// that every level ≥ 1 takes the same steps).
    fn controlled(&self, k: usize) -> usize {
        if self.options.sensitivity_error_control && k >= 1 {
            self.levels[1].nz
        } else {
            self.nx
        }
    }

    /// Steps `z` from `t0` through `times`, copying a block of `out` at each.
    fn drive(
        &self,
        stepper: &mut impl Stepper,
        z: &mut [f64],
        times: &[f64],
        out: &mut [f64],
    ) -> Result<IntegratorStats, IntegratorError> {
        let block = out.len() / times.len().max(1);
        let mut t = self.t0;
        for (i, &target) in times.iter().enumerate() {
            stepper.advance(&mut t, z, target)?;
            out[i * block..(i + 1) * block].copy_from_slice(&z[..block]);
        }
        Ok(stepper.stats())
    }
}

/// `(nx, np)` of an ODE right-hand side `f(x) → ẋ` or `f(x, p) → ẋ`, or why it is not one.
fn check_ode(ode: &Function) -> Result<(usize, usize), IntegratorError> {
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
            "an external function has no symbolic Jacobian for the sensitivity equations".into(),
        );
    }
    Ok((nx, np))
}

/// The interval and the options, checked.
fn check_options(t0: f64, tf: f64, options: &IntegratorOptions) -> Result<(), IntegratorError> {
    let check = |name, value: f64, ok: bool, why| {
        if ok {
            Ok(())
        } else {
            Err(IntegratorError::BadOption { name, value, why })
        }
    };
    let finite_positive = "must be finite and > 0";
    check(
        "tf - t0",
        tf - t0,
        tf > t0 && (tf - t0).is_finite(),
        finite_positive,
    )?;
    let rtol = options.rtol;
    check("rtol", rtol, rtol > 0.0 && rtol < 1.0, "must be in (0, 1)")?;
    let atol = options.atol;
    check(
        "atol",
        atol,
        atol > 0.0 && atol.is_finite(),
        finite_positive,
    )?;
    let max_steps = options.max_steps;
    check("max_steps", max_steps as f64, max_steps > 0, "must be ≥ 1")?;
    if let Some(h) = options.initial_step {
        check("initial_step", h, h > 0.0 && h.is_finite(), finite_positive)?;
    }
    Ok(())
}

/// The buffers of one integration: the state, the stepper's buffers and, for an adjoint
/// integration, the tape of its steps.
#[derive(Debug, Default)]
struct Workspace {
    state: Vec<f64>,
    dopri: DopriBuffers,
    sdirk: SdirkBuffers,
    tape: Option<Vec<f64>>,
}
