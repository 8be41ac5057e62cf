//! Interior-point method: IPOPT's primal-dual barrier algorithm with a filter line search
//! (Wächter & Biegler, Math. Prog. 106:25–57, 2006).
//!
//! Layout: `reduced` (fixed variables and unbounded rows removed, on the front end's
//! scaled problem `frontend/scaled.rs`),
//! `core` (iteration, KKT step with inertia correction, line search with second-order
//! corrections), `filter`, `barrier` (μ updates), `restoration` (ℓ1 restoration
//! phase solved by the same core), `workspace` (what an `Ipm` keeps between solves).

#![allow(clippy::needless_range_loop)]

pub(crate) mod barrier;
mod core;
mod error;
pub(crate) mod filter;
pub(crate) mod quality;
pub(crate) mod reduced;
mod restoration;
mod workspace;

use std::time::Instant;

use crate::callback::{IterationCallback, Observer};
use crate::error::SolveError;
use crate::frontend::solver::{impl_solver_options, solver_entry_points};
use crate::frontend::user_solution::{conclude, user_solution, UserPoint};
use crate::frontend::validate::{validate, Validated};
use crate::frontend::Solver;
use crate::numeric::NumericNlp;
use crate::options::{IpmOptions, ScalingMethod};
use crate::scaling::{gradient_scale, gradient_scale_up};
use crate::solution::{Solution, Stats, Status};

use self::core::{Core, Outcome, Setup, Shared, Start};
use self::reduced::Reduced;
use self::workspace::Workspace;

/// The interior-point solver. It keeps the KKT system's symbolic analysis between
/// solves of problems with the same structure (see [`Ipm::solve_warm`]); a clone starts
/// without it.
#[derive(Debug, Clone, Default)]
pub struct Ipm {
    /// Options (IPOPT names and defaults).
    pub options: IpmOptions,
    workspace: Workspace,
}

impl Ipm {
    /// A solver with the given options.
    pub fn new(options: IpmOptions) -> Self {
        Ipm {
            options,
            workspace: Workspace::default(),
        }
    }
}

solver_entry_points!(
    Ipm,
    "Warm start from a previous solution (IPOPT's `warm_start_init_point = yes`): x, λ, \
     z_L, z_U are reused, pushed into the interior with the `warm_start_*` options, and \
     μ starts at `warm_start_mu_init`.\n\n\
     The KKT system's pattern, ordering and symbolic factorisation are kept from the \
     previous solve with this solver when the problem's structure (after removing fixed \
     variables) is the same, as in an MPC loop; the iterates are those of a fresh solver."
);

impl_solver_options!(IpmOptions => Ipm);

impl Ipm {
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
        scale_at_start(&mut red, opts);
        let mut out = self.iterate(&mut red, warm, &mut shared);
        if opts.honor_original_bounds {
            for (k, &j) in red.free.iter().enumerate() {
                if let Some(w) = out.w.get_mut(k) {
                    *w = w.clamp(v.x_l[j], v.x_u[j]);
                }
            }
        }
        let all_fixed = red.free.is_empty();
        let mut sol = finish(&mut red, &v, out);
        if all_fixed && sol.constr_viol > opts.constr_viol_tol {
            sol.status = Status::InfeasibleProblemDetected;
        }
        shared.stats.iterations = shared.iter;
        conclude(
            &mut sol,
            shared.stats,
            &red.sc,
            start_time,
            opts.print_level,
        );
        Ok(sol)
    }

    /// The iterations on the reduced, scaled problem (none when every variable is fixed
    /// or the equality rows outnumber the free variables), with the KKT system kept by
    /// the workspace when the structure is the one it was analysed for.
    fn iterate(
        &self,
        red: &mut Reduced<'_>,
        warm: Option<&Solution>,
        shared: &mut Shared<'_>,
    ) -> Outcome {
        let opts = &self.options;
        let n = red.free.len();
        let m = red.rows.len();
        let n_eq = red.g_l.iter().zip(&red.g_u).filter(|(l, u)| l == u).count();
        if n == 0 {
            // Everything fixed: nothing to optimise; feasibility is checked by the caller.
            return Outcome::at_start(Status::SolveSucceeded, vec![], m, "all variables are fixed");
        }
        if n_eq > n {
            return Outcome::at_start(
                Status::NotEnoughDegreesOfFreedom,
                red.x0.clone(),
                m,
                format!("{n_eq} equality constraints but only {n} free variables"),
            );
        }
        let start = match warm {
            None => Start::Cold,
            Some(prev) => warm_start(red, prev),
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
        let kept = (self.workspace).take(n, m, red.hess_l_sparsity(), red.jac_g_sparsity());
        match Core::new(red, opts, &setup, kept) {
            Err(e) => Outcome::at_start(Status::InternalError, red.x0.clone(), m, e.to_string()),
            Ok(mut core) => {
                let out = core.run(shared, start);
                let kkt = core.into_kkt();
                (self.workspace).keep(kkt, red.hess_l_sparsity(), red.jac_g_sparsity());
                out
            }
        }
    }
}

/// The warm start's multipliers in the reduced problem's numbering and scaling.
fn warm_start(red: &Reduced<'_>, prev: &Solution) -> Start {
    let scaling = &red.sc.scaling;
    Start::Warm {
        y: red
            .rows
            .iter()
            .map(|&i| scaling.lambda_from_user(i, prev.lambda[i]))
            .collect(),
        zl: red
            .free
            .iter()
            .map(|&j| scaling.z_from_user(prev.z_l[j]))
            .collect(),
        zu: red
            .free
            .iter()
            .map(|&j| scaling.z_from_user(prev.z_u[j]))
            .collect(),
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

/// Builds the user-level solution from the reduced, scaled iterate `out` (w = [x; s] or
/// shorter: only its first `free.len()` entries are read): fixed variables at their
/// values, multipliers unscaled (rows without bounds: λ = 0), then the front end's
/// [`user_solution`].
fn finish(red: &mut Reduced<'_>, v: &Validated, out: Outcome) -> Solution {
    let (n_user, m_user) = (v.x_l.len(), v.g_l.len());
    let Outcome {
        status,
        w,
        y,
        zl,
        zu,
        message,
        ..
    } = out;
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
