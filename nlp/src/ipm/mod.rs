//! Interior-point method: IPOPT's primal-dual barrier algorithm with a filter line search
//! (Wächter & Biegler, Math. Prog. 106:25–57, 2006).
//!
//! Layout: `reduced` (fixed variables and unbounded rows removed, on the front end's
//! scaled problem `frontend/scaled.rs`),
//! `core` (iteration, KKT step with inertia correction, line search with second-order
//! corrections), `filter`, `mu_update` (μ and τ), `restoration` (ℓ1 restoration
//! phase solved by the same core), `workspace` (what an `Ipm` keeps between solves).

#![allow(clippy::needless_range_loop)]

pub(crate) mod barrier;
mod core;
mod error;
pub(crate) mod filter;
pub(crate) mod mu_update;
pub(crate) mod quality;
pub(crate) mod reduced;
mod restoration;
mod termination;
mod workspace;

use std::time::Instant;

use crate::callback::{IterationCallback, Observer};
use crate::error::SolveError;
use crate::frontend::scaled::refill;
use crate::frontend::solver::{impl_solver_options, solver_entry_points};
use crate::frontend::user_solution::{conclude, user_solution_into};
use crate::frontend::validate::{validate_into, Validated};
use crate::frontend::Solver;
use crate::numeric::NumericNlp;
use crate::options::{IpmOptions, ScalingMethod};
use crate::scaling::{gradient_scale, gradient_scale_up};
use crate::solution::{Solution, Stats, Status};

use self::core::{Buffers, Core, Iterate, Outcome, Setup, Shared, Start};
use self::reduced::Reduced;
use self::workspace::{SolveBuffers, Structure, Workspace};

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
    /// [`Ipm::solve_warm`] with the result written into `out` (for example the previous
    /// step's solution in an MPC loop), reusing its vectors. A re-solve of a problem with
    /// the same structure as this solver's previous solve (same patterns, fixed
    /// variables and unbounded rows, exact Hessian, no callback, `print_level` < 5)
    /// allocates nothing; the iterates are those of a fresh solver's `solve_warm`.
    /// On error `out` is left unspecified.
    /// ```
    /// use nlp::{Ipm, Problem};
    ///
    /// let mut pb = Problem::new();
    /// let x = pb.variable("x", 2).unwrap();
    /// let p = pb.parameter("p", 1).unwrap();
    /// pb.set_value(&p, &[0.0]).unwrap();
    /// pb.minimize((x[0] - p[0]).sq() + (x[1] - 2.0).sq());
    /// let mut nlp = pb.compile().unwrap();
    /// let ipm = Ipm::default();
    /// let mut sol = ipm.solve(&mut nlp).unwrap();
    /// let mut next = sol.clone();
    /// for step in 0..3 {
    ///     nlp.set_value("p", &[step as f64]).unwrap();
    ///     ipm.solve_warm_into(&mut nlp, &sol, &mut next).unwrap();
    ///     assert!(next.status.is_success());
    ///     assert!((next.x[0] - step as f64).abs() < 1e-6);
    ///     std::mem::swap(&mut sol, &mut next);
    /// }
    /// ```
    pub fn solve_warm_into(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
        out: &mut Solution,
    ) -> Result<(), SolveError> {
        self.run_into(nlp, Some(previous), None, out)
    }

    fn run_into(
        &self,
        nlp: &mut dyn NumericNlp,
        warm: Option<&Solution>,
        callback: Option<&mut IterationCallback<'_>>,
        sol: &mut Solution,
    ) -> Result<(), SolveError> {
        let start_time = Instant::now();
        self.options.validate()?;
        let mut buffers = self.workspace.take();
        let res = self.run_in(&mut buffers, nlp, warm, callback, sol, start_time);
        self.workspace.keep(buffers);
        res
    }

    /// The solve in `b`'s vectors: validation, the reduced problem and its scaling, the
    /// iterations, and the user's solution written into `sol`.
    fn run_in(
        &self,
        b: &mut SolveBuffers,
        nlp: &mut dyn NumericNlp,
        warm: Option<&Solution>,
        callback: Option<&mut IterationCallback<'_>>,
        sol: &mut Solution,
        start_time: Instant,
    ) -> Result<(), SolveError> {
        let opts = &self.options;
        validate_into(nlp, warm, &mut b.validated)?;
        let v = &b.validated;
        let observer = callback.map(|cb| {
            let clamp = opts
                .honor_original_bounds
                .then_some((&v.x_l[..], &v.x_u[..]));
            Observer::new(cb, v.x_l.len(), v.g_l.len(), clamp)
        });
        let mut red = Reduced::new(nlp, v, std::mem::take(&mut b.reduced));
        let mut records = std::mem::take(&mut sol.stats.records);
        records.clear();
        let mut shared = Shared {
            stats: Stats {
                records,
                ..Stats::default()
            },
            start: start_time,
            iter: 0,
            observer,
        };
        scale_at_start(&mut red, opts);
        let ended = iterate(opts, &mut red, warm, &mut shared, &mut b.core, &mut b.warm);
        let (out, final_point) = match &ended {
            Ended::AtStart(out) => (out, None),
            Ended::Iterated(out) => (out, b.core.as_ref().map(|(_, c)| c.iterate())),
        };
        write_point(&red, v, final_point, opts.honor_original_bounds, sol);
        sol.status = out.status;
        sol.message.clear();
        sol.message.push_str(&out.message);
        user_solution_into(&mut red.sc, v, sol, None, &mut b.last);
        if red.free().is_empty() && sol.constr_viol > opts.constr_viol_tol {
            sol.status = Status::InfeasibleProblemDetected;
        }
        shared.stats.iterations = shared.iter;
        conclude(sol, shared.stats, &red.sc, start_time, opts.print_level);
        b.reduced = red.into_parts();
        Ok(())
    }
}

/// How [`iterate`] ended: before iterating (the point is the start, with zero
/// multipliers) or after running the core (the point is the core's final iterate).
enum Ended {
    AtStart(Outcome),
    Iterated(Outcome),
}

/// The iterations on the reduced, scaled problem (none when every variable is fixed
/// or the equality rows outnumber the free variables), in the core's buffers `kept`
/// when they were built for this structure (new ones otherwise, kept for the next
/// solve); `warm_buf` holds the warm start's multipliers.
fn iterate(
    opts: &IpmOptions,
    red: &mut Reduced<'_>,
    warm: Option<&Solution>,
    shared: &mut Shared<'_>,
    kept: &mut Option<(Structure, Buffers)>,
    warm_buf: &mut [Vec<f64>; 3],
) -> Ended {
    let n = red.free().len();
    let m = red.rows().len();
    let n_eq = red
        .g_l()
        .iter()
        .zip(red.g_u())
        .filter(|(l, u)| l == u)
        .count();
    let at_start = |status, message: String| {
        Ended::AtStart(Outcome {
            status,
            message,
            resto_converged: false,
        })
    };
    if n == 0 {
        // Everything fixed: nothing to optimise; feasibility is checked by the caller.
        return at_start(Status::SolveSucceeded, "all variables are fixed".into());
    }
    if n_eq > n {
        return at_start(
            Status::NotEnoughDegreesOfFreedom,
            format!("{n_eq} equality constraints but only {n} free variables"),
        );
    }
    let start = match warm {
        None => Start::Cold,
        Some(prev) => warm_start(red, prev, warm_buf),
    };
    let scaling = red.take_scaling();
    let setup = Setup {
        mu_init: if warm.is_some() {
            opts.warm_start_mu_init
        } else {
            opts.mu_init
        },
        bound_relax_factor: opts.bound_relax_factor,
        in_resto: false,
        scaling: &scaling,
        mu_strategy: opts.effective_mu_strategy(),
        failed_search: None,
    };
    let (hess, jac) = (red.hess_l_sparsity(), red.jac_g_sparsity());
    let (structure, buffers) = match kept.take() {
        Some((s, b)) if s.is(n, m, hess, jac) => (s, b),
        _ => (Structure::new(n, m, hess, jac), Buffers::default()),
    };
    let ended = match Core::new(red, opts, &setup, buffers) {
        Err(e) => at_start(Status::InternalError, e.to_string()),
        Ok(mut core) => {
            let out = core.run(shared, start, restoration::restore);
            *kept = Some((structure, core.into_buffers()));
            Ended::Iterated(out)
        }
    };
    red.put_scaling(scaling);
    ended
}

/// The warm start's multipliers in the reduced problem's numbering and scaling, in `buf`.
fn warm_start<'b>(red: &Reduced<'_>, prev: &Solution, buf: &'b mut [Vec<f64>; 3]) -> Start<'b> {
    let scaling = &red.sc.scaling;
    let [y, zl, zu] = buf;
    y.clear();
    y.extend(
        red.rows()
            .iter()
            .map(|&i| scaling.lambda_from_user(i, prev.lambda[i])),
    );
    zl.clear();
    zl.extend(red.free().iter().map(|&j| scaling.z_from_user(prev.z_l[j])));
    zu.clear();
    zu.extend(red.free().iter().map(|&j| scaling.z_from_user(prev.z_u[j])));
    Start::Warm { y, zl, zu }
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
        let mut sol = Solution::empty();
        self.run_into(nlp, warm, callback, &mut sol)?;
        Ok(sol)
    }

    fn solve_warm_into(
        &self,
        nlp: &mut dyn NumericNlp,
        previous: &Solution,
        out: &mut Solution,
    ) -> Result<(), SolveError> {
        Ipm::solve_warm_into(self, nlp, previous, out)
    }
}

/// Writes the user-level point of the reduced, scaled `point` (w = [x; s], y, z_L, z_U;
/// `None`: the starting point with zero multipliers) into `sol`'s x, λ, z_L, z_U: fixed
/// variables at their values, free ones clamped to the original bounds with
/// `honor_bounds`, multipliers unscaled (rows without bounds: λ = 0).
fn write_point(
    red: &Reduced<'_>,
    v: &Validated,
    point: Option<&Iterate>,
    honor_bounds: bool,
    sol: &mut Solution,
) {
    let (n_user, m_user) = (v.x_l.len(), v.g_l.len());
    let (w, y, zl, zu): (&[f64], &[f64], &[f64], &[f64]) = match point {
        Some(it) => (&it.w, &it.y, &it.zl, &it.zu),
        None => (red.x0(), &[], &[], &[]),
    };
    sol.x.clear();
    sol.x.extend_from_slice(red.x_full());
    refill(&mut sol.lambda, m_user, 0.0);
    refill(&mut sol.z_l, n_user, 0.0);
    refill(&mut sol.z_u, n_user, 0.0);
    let scaling = &red.sc.scaling;
    for (k, &j) in red.free().iter().enumerate() {
        if k < w.len() {
            sol.x[j] = if honor_bounds {
                w[k].clamp(v.x_l[j], v.x_u[j])
            } else {
                w[k]
            };
        }
        sol.z_l[j] = scaling.z_to_user(zl.get(k).copied().unwrap_or(0.0));
        sol.z_u[j] = scaling.z_to_user(zu.get(k).copied().unwrap_or(0.0));
    }
    for (k, &i) in red.rows().iter().enumerate() {
        sol.lambda[i] = scaling.lambda_to_user(i, y.get(k).copied().unwrap_or(0.0));
    }
}

/// IPOPT's gradient-based scaling at the starting point (or the fixed objective factor):
/// sets the scaled problem's objective and row factors (rows of the reduced problem).
fn scale_at_start(red: &mut Reduced<'_>, opts: &IpmOptions) {
    let n = red.free().len();
    if opts.nlp_scaling_method == ScalingMethod::GradientBased && n > 0 {
        let gmax = red.unscaled_gradient_norms_at_start();
        red.sc.scaling.obj = opts.obj_scaling_factor
            * gradient_scale(
                gmax,
                opts.nlp_scaling_max_gradient,
                opts.nlp_scaling_min_value,
            );
        for k in 0..red.rows().len() {
            let (i, rmax) = (red.rows()[k], red.row_norm(k));
            let mut s = gradient_scale(
                rmax,
                opts.nlp_scaling_max_gradient,
                opts.nlp_scaling_min_value,
            );
            // Upward scaling: equality rows only (see nlp_scaling_min_gradient).
            if red.g_l()[k] == red.g_u()[k] {
                s *= gradient_scale_up(
                    rmax,
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
