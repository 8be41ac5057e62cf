//! Interior-point method: IPOPT's primal-dual barrier algorithm with a filter line search
//! (Wächter & Biegler, Math. Prog. 106:25–57, 2006).
//!
//! Layout: `reduced` (fixed variables and unbounded rows removed, on the front end's
//! scaled problem `frontend/scaled.rs`),
//! `core` (iteration, KKT step with inertia correction, line search with second-order
//! corrections), `filter`, `barrier` (μ updates), `restoration` (ℓ1 restoration
//! phase solved by the same core).

#![allow(clippy::needless_range_loop)]

pub(crate) mod barrier;
mod core;
mod error;
pub(crate) mod filter;
pub(crate) mod quality;
pub(crate) mod reduced;
mod restoration;

use std::ops::ControlFlow;
use std::time::Instant;

use crate::callback::{IterationCallback, IterationView, Observer};
use crate::error::SolveError;
use crate::frontend::user_solution::{user_solution, UserPoint};
use crate::frontend::validate::{validate, Validated};
use crate::frontend::Solver;
use crate::numeric::NumericNlp;
use crate::options::{IpmOptions, ScalingMethod};
use crate::scaling::{gradient_scale, gradient_scale_up};
use crate::solution::{Solution, Stats, Status};

use self::core::{Core, Setup, Shared, Start};
use self::reduced::Reduced;

/// The interior-point solver.
#[derive(Debug, Clone, Default)]
pub struct Ipm {
    /// Options (IPOPT names and defaults).
    pub options: IpmOptions,
}

impl Ipm {
    /// A solver with the given options.
    pub fn new(options: IpmOptions) -> Self {
        Ipm { options }
    }

    /// Solves from the problem's initial point.
    pub fn solve(&self, nlp: &mut dyn NumericNlp) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, None, None)
    }

    /// [`Ipm::solve`] with a per-iteration callback (IPOPT's `intermediate_callback`):
    /// `callback` sees every iteration, restoration iterations and iteration 0 included,
    /// once per row of `Solution::stats.records`, before the convergence test; returning
    /// [`ControlFlow::Break`] ends the solve with [`Status::UserRequestedStop`] at that
    /// point. See [`crate::callback`].
    pub fn solve_with_callback(
        &self,
        nlp: &mut dyn NumericNlp,
        mut callback: impl FnMut(&IterationView<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, None, Some(&mut callback))
    }

    /// [`Ipm::solve_warm`] with a per-iteration callback (see [`Ipm::solve_with_callback`]).
    pub fn solve_warm_with_callback(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
        mut callback: impl FnMut(&IterationView<'_>) -> ControlFlow<()>,
    ) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, Some(previous), Some(&mut callback))
    }

    /// Warm start from a previous solution (IPOPT's `warm_start_init_point = yes`): x, λ,
    /// z_L, z_U are reused, pushed into the interior with the `warm_start_*` options, and
    /// μ starts at `warm_start_mu_init`.
    pub fn solve_warm(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
    ) -> Result<Solution, SolveError> {
        self.solve_dyn(nlp, Some(previous), None)
    }

    fn run(
        &self,
        nlp: &mut dyn NumericNlp,
        warm: Option<&Solution>,
        callback: Option<&mut IterationCallback<'_>>,
    ) -> Result<Solution, SolveError> {
        let start_time = Instant::now();
        let opts = &self.options;
        opts.validate()?;
        let v = validate(nlp, warm)?;
        let observer = callback.map(|cb| {
            let clamp = opts
                .honor_original_bounds
                .then_some((&v.x_l[..], &v.x_u[..]));
            Observer::new(cb, v.x_l.len(), v.g_l.len(), clamp)
        });
        let mut red = Reduced::new(nlp, &v.x_l, &v.x_u, &v.g_l, &v.g_u, &v.x0);
        let mut shared = Shared {
            stats: Stats::default(),
            start: start_time,
            iter: 0,
            observer,
        };
        let n = red.free.len();
        let m = red.rows.len();
        let n_eq = red.g_l.iter().zip(&red.g_u).filter(|(l, u)| l == u).count();
        scale_at_start(&mut red, opts);
        let (status, w, y, zl, zu, message) = if n == 0 {
            // Everything fixed: nothing to optimise; feasibility is checked below.
            (
                Status::SolveSucceeded,
                vec![],
                vec![0.0; m],
                vec![],
                vec![],
                String::from("all variables are fixed"),
            )
        } else if n_eq > n {
            (
                Status::NotEnoughDegreesOfFreedom,
                red.x0.clone(),
                vec![0.0; m],
                vec![0.0; n],
                vec![0.0; n],
                format!("{n_eq} equality constraints but only {n} free variables"),
            )
        } else {
            let start = match warm {
                None => Start::Cold,
                Some(prev) => Start::Warm {
                    y: red
                        .rows
                        .iter()
                        .map(|&i| red.sc.scaling.lambda_from_user(i, prev.lambda[i]))
                        .collect(),
                    zl: red
                        .free
                        .iter()
                        .map(|&j| red.sc.scaling.z_from_user(prev.z_l[j]))
                        .collect(),
                    zu: red
                        .free
                        .iter()
                        .map(|&j| red.sc.scaling.z_from_user(prev.z_u[j]))
                        .collect(),
                },
            };
            let setup = Setup {
                mu_init: if warm.is_some() {
                    opts.warm_start_mu_init
                } else {
                    opts.mu_init
                },
                bound_relax_factor: opts.bound_relax_factor,
                in_resto: false,
                scaling: red.scaling(),
                mu_strategy: opts.effective_mu_strategy(),
            };
            match Core::new(&mut red, opts, &setup) {
                Err(e) => (
                    Status::InternalError,
                    red.x0.clone(),
                    vec![0.0; m],
                    vec![0.0; n],
                    vec![0.0; n],
                    e.to_string(),
                ),
                Ok(mut core) => {
                    let out = core.run(&mut shared, start);
                    (
                        out.status,
                        out.w[..n].to_vec(),
                        out.y,
                        out.zl[..n].to_vec(),
                        out.zu[..n].to_vec(),
                        out.message,
                    )
                }
            }
        };
        let mut w = w;
        if opts.honor_original_bounds {
            for (k, &j) in red.free.iter().enumerate() {
                if k < w.len() {
                    w[k] = w[k].clamp(v.x_l[j], v.x_u[j]);
                }
            }
        }
        let mut sol = finish(&mut red, &v, status, &w, &y, &zl, &zu, message);
        if n == 0 && sol.constr_viol > opts.constr_viol_tol {
            sol.status = Status::InfeasibleProblemDetected;
        }
        let mut stats = shared.stats;
        stats.iterations = shared.iter;
        red.sc.write_stats(&mut stats);
        stats.total_seconds = start_time.elapsed().as_secs_f64();
        stats.other_seconds =
            (stats.total_seconds - stats.eval_seconds - stats.factor_seconds).max(0.0);
        sol.stats = stats;
        if opts.print_level >= 3 {
            print!("{}", crate::log::format_summary(&sol));
            if !sol.message.is_empty() {
                println!("{}", sol.message);
            }
        }
        Ok(sol)
    }
}

impl Solver for Ipm {
    fn name(&self) -> &'static str {
        "ipm"
    }

    fn solve_dyn(
        &self,
        nlp: &mut dyn NumericNlp,
        warm: Option<&Solution>,
        callback: Option<&mut IterationCallback<'_>>,
    ) -> Result<Solution, SolveError> {
        self.run(nlp, warm, callback)
    }
}

/// Builds the user-level solution from the reduced, scaled iterate: fixed variables at
/// their values, multipliers unscaled (rows without bounds: λ = 0), then the front end's
/// [`user_solution`].
#[allow(clippy::too_many_arguments)]
fn finish(
    red: &mut Reduced<'_>,
    v: &Validated,
    status: Status,
    w: &[f64],
    y: &[f64],
    zl: &[f64],
    zu: &[f64],
    message: String,
) -> Solution {
    let (n_user, m_user) = (v.x_l.len(), v.g_l.len());
    let mut point = UserPoint {
        x: red.x_full.clone(),
        lambda: vec![0.0; m_user],
        z_l: vec![0.0; n_user],
        z_u: vec![0.0; n_user],
    };
    for (k, &j) in red.free.iter().enumerate() {
        if k < w.len() {
            point.x[j] = w[k];
        }
        point.z_l[j] = red.sc.scaling.z_to_user(zl.get(k).copied().unwrap_or(0.0));
        point.z_u[j] = red.sc.scaling.z_to_user(zu.get(k).copied().unwrap_or(0.0));
    }
    for (k, &i) in red.rows.iter().enumerate() {
        point.lambda[i] = red
            .sc
            .scaling
            .lambda_to_user(i, y.get(k).copied().unwrap_or(0.0));
    }
    user_solution(&mut red.sc, v, point, None, status, message)
}

/// IPOPT's gradient-based scaling at the starting point (or the fixed objective factor):
/// sets the scaled problem's objective and row factors (rows of the reduced problem).
fn scale_at_start(red: &mut Reduced<'_>, opts: &IpmOptions) {
    let n = red.free.len();
    if opts.nlp_scaling_method == ScalingMethod::GradientBased && n > 0 {
        let x0 = red.x0.clone();
        let (gmax, rmax) = red.unscaled_gradient_norms(&x0);
        red.sc.scaling.obj = opts.obj_scaling_factor
            * gradient_scale(
                gmax,
                opts.nlp_scaling_max_gradient,
                opts.nlp_scaling_min_value,
            );
        for (k, &i) in red.rows.iter().enumerate() {
            let mut s = gradient_scale(
                rmax[k],
                opts.nlp_scaling_max_gradient,
                opts.nlp_scaling_min_value,
            );
            // Upward scaling: equality rows only (see nlp_scaling_min_gradient).
            if red.g_l[k] == red.g_u[k] {
                s *= gradient_scale_up(
                    rmax[k],
                    opts.nlp_scaling_min_gradient,
                    opts.nlp_scaling_max_value,
                );
            }
            red.sc.scaling.rows[i] = s;
        }
    } else {
        red.sc.scaling.obj = opts.obj_scaling_factor;
    }
}
