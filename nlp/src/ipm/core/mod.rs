//! The primal-dual interior-point iteration (Wächter & Biegler 2006) on a problem in the
//! form seen through [`IpmProblem`]: inequality rows get slacks s (g(x) − s = 0,
//! g_l ≤ s ≤ g_u) and the primal vector is w = [x; s].

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use std::time::Instant;

use crate::callback::Observer;
use crate::frontend::scaled::Scaling;
use crate::frontend::KktResiduals;
use crate::ipm::error::CoreError;
use crate::ipm::filter::{Acceptance, Filter};
use crate::ipm::mu_update::MuUpdate;
use crate::ipm::reduced::IpmProblem;
use crate::ipm::restoration::handoff::{refusal, Ended, Entry, Next};
use crate::ipm::termination::StopTest;
use crate::options::{IpmOptions, MuStrategy};
use crate::solution::{BackendColumns, IterationRecord, Stats, Status};

mod buffers;
mod direction;
mod evaluation;
mod factorization;
mod init;
mod iterate;
mod kkt_work;
mod layout;
mod line_search;
mod measures;
mod mu_oracles;
mod newton_step;
mod perturbation;
mod soft_resto;
mod step_kind;
mod vectors;

pub(crate) use buffers::Buffers;
use direction::Direction;
pub(crate) use iterate::Iterate;
use iterate::Trial;
use kkt_work::KktWork;
pub(crate) use layout::Layout;
use perturbation::Perturbation;
use step_kind::LineSearch;
use vectors::{inf_norm, one_norm};

/// State shared by the outer loop and nested restoration loops.
pub(crate) struct Shared<'c> {
    pub stats: Stats,
    pub start: Instant,
    pub iter: usize,
    /// The user's iteration callback, called by `record`.
    pub observer: Option<Observer<'c>>,
}

/// A restoration phase run from a core's state: it ends with what the core does next.
/// [`Core::run`] takes it as an argument (`ipm::restoration::restore`) because the
/// restoration phase drives a core itself: the core knows only the hand-over types.
pub(crate) type Restorer = fn(Entry<'_>, &mut Shared) -> Ended;

/// What one iteration of [`Core::run`] leads to.
enum Iteration {
    /// A step was taken: go on with the next iteration.
    Continue,
    /// The solve ended.
    Finished(Outcome),
    /// No step was taken, for reason `why`: a restoration phase starts (the filter
    /// already holds the current point if `filter_augmented`).
    Restore {
        why: &'static str,
        filter_augmented: bool,
    },
}

/// How to start the iteration.
#[derive(Clone, Copy)]
pub(crate) enum Start<'a> {
    /// Push x0 into the bounds, least-squares y, bound multipliers = bound_mult_init_val.
    Cold,
    /// Warm start: x0 from the problem, given y and z (length n); warm-start pushes.
    Warm {
        y: &'a [f64],
        zl: &'a [f64],
        zu: &'a [f64],
    },
    /// Exact full iterate (restoration): w = [x; s], y, z for all of w.
    Exact {
        w: &'a [f64],
        y: &'a [f64],
        zl: &'a [f64],
        zu: &'a [f64],
    },
}

/// Parameters of one run of the core.
pub(crate) struct Setup<'s> {
    pub mu_init: f64,
    pub bound_relax_factor: f64,
    pub in_resto: bool,
    /// The scaling of the problem's rows (for the user's units in the log and the
    /// termination tests).
    pub scaling: &'s Scaling,
    pub mu_strategy: MuStrategy,
    /// The failed outer line search (α_pr, trial count) a restoration run shows in its
    /// first log row; `None` outside restoration.
    pub failed_search: Option<(f64, usize)>,
}

/// How a run ended; its final point is the core's iterate ([`Core::iterate`], or
/// [`Buffers::iterate`] once the core is taken apart).
pub(crate) struct Outcome {
    pub status: Status,
    pub message: String,
    /// For restoration: the inner problem converged (optimal) rather than being stopped
    /// by the acceptance hook.
    pub resto_converged: bool,
}

/// Counters of the main loop.
#[derive(Default)]
struct Counters {
    /// Tiny steps in a row.
    tiny_count: usize,
    /// Restoration phases entered.
    resto_calls: usize,
    /// Accepted steps in a row with α_pr < `tiny_alpha`.
    tiny_alpha_run: usize,
    /// Refactorisations with lowered static regularisation after a failed refinement
    /// (see `Core::solve_with_higher_quality`).
    quality_retries: usize,
}

/// The interior-point iteration: its named parts and the barrier and filter state.
pub(crate) struct Core<'p> {
    nlp: &'p mut dyn IpmProblem,
    opts: IpmOptions,
    lay: Layout,
    /// The current iterate.
    it: Iterate,
    /// The line search's trial point.
    trial: Trial,
    /// The Newton direction.
    dir: Direction,
    /// The second-order correction's direction.
    dir_soc: Direction,
    /// The second-order correction's constraint residual.
    c_soc: Vec<f64>,
    kw: KktWork,
    pert: Perturbation,
    /// In IPOPT's soft restoration phase: the number of its iterations so far (read and
    /// written in `soft_resto.rs` only).
    soft_resto: Option<usize>,
    count: Counters,
    /// The barrier parameter μ, τ and the adaptive rule's state.
    mu_update: MuUpdate,
    filter: Filter,
    /// The line search's acceptance rules (θ_min, θ_max set by `initialize`).
    accept: Acceptance,
    /// Scratch: the problem's starting point (see `Core::initialize`).
    x_start: Vec<f64>,
    /// Scratch: the multipliers before a least-squares re-estimate (`recalc_y`).
    y_saved: Vec<f64>,
    /// Scratch of `Layout::fill`, returned with the buffers.
    bounds: [Vec<f64>; 4],
    /// The termination test (acceptable streak, previous objective, limits).
    termination: StopTest,
    setup_in_resto: bool,
    /// IPOPT's `recalc_y` in effect (see `Core::recalc_multipliers`).
    recalc_y: bool,
    scaling: Scaling,
    /// The outer iteration's failed line search (alpha_pr, ls) that starts a restoration
    /// phase; shown in the restoration's first log row as IPOPT does ("12r … 4.8e-7R 22").
    resto_start: Option<(f64, usize)>,
    /// The error measures (`Core::errors` with μ = 0, no damping) of the current
    /// iterate, computed for its log row and taken by the next stop test, which needs
    /// the same numbers (one evaluation of them instead of two per iteration). Set only
    /// where the stop test follows the log row with the iterate unchanged; cleared
    /// when a restoration phase starts.
    errors_here: Option<([f64; 3], [f64; 3])>,
}

impl<'p> Core<'p> {
    /// The iteration on `nlp` in `buffers` (from [`Core::into_buffers`] of a run on a
    /// problem with the same Hessian and Jacobian patterns, or the default).
    pub(crate) fn new(
        nlp: &'p mut dyn IpmProblem,
        opts: &IpmOptions,
        setup: &Setup<'_>,
        mut buffers: Buffers,
    ) -> Result<Self, CoreError> {
        buffers.prepare(&*nlp, opts, setup.bound_relax_factor, setup.scaling)?;
        let Buffers {
            lay,
            it,
            trial,
            dir,
            dir_soc,
            c_soc,
            kw,
            filter,
            kkt_refs,
            quality_pairs,
            scaling,
            x_start,
            y_saved,
            bounds,
        } = buffers;
        let m = lay.m;
        Ok(Core {
            nlp,
            opts: opts.clone(),
            lay,
            it,
            trial,
            dir,
            dir_soc,
            c_soc,
            kw: kw.expect("Buffers::prepare builds the KKT work"),
            pert: Perturbation::default(),
            soft_resto: None,
            count: Counters::default(),
            mu_update: MuUpdate::new(
                setup.mu_init,
                setup.mu_strategy,
                opts,
                scaling.obj,
                kkt_refs,
                quality_pairs,
            ),
            filter,
            accept: Acceptance::default(),
            x_start,
            y_saved,
            bounds,
            termination: StopTest::new(opts, setup.in_resto),
            setup_in_resto: setup.in_resto,
            recalc_y: !setup.in_resto
                && m > 0
                && opts
                    .recalc_y
                    .unwrap_or(opts.hessian_approximation == crate::IpmHessian::LimitedMemory),
            scaling,
            resto_start: setup.failed_search,
            errors_here: None,
        })
    }

    /// The vectors of this run (its final iterate among them), for a later run on a
    /// problem with the same structure.
    pub(crate) fn into_buffers(self) -> Buffers {
        let (kkt_refs, quality_pairs) = self.mu_update.into_scratch();
        Buffers {
            lay: self.lay,
            it: self.it,
            trial: self.trial,
            dir: self.dir,
            dir_soc: self.dir_soc,
            c_soc: self.c_soc,
            kw: Some(self.kw),
            filter: self.filter,
            kkt_refs,
            quality_pairs,
            scaling: self.scaling,
            x_start: self.x_start,
            y_saved: self.y_saved,
            bounds: self.bounds,
        }
    }

    // ------------------------------------------------------------------ records

    fn record(
        &mut self,
        shared: &mut Shared,
        d_norm: f64,
        alpha_du: f64,
        alpha_pr: f64,
        ch: char,
        ls: usize,
        dual: f64,
    ) {
        // In restoration, the objective and inf_pr columns are the original problem's at
        // the current x and s (IPOPT's RestoIterationOutput); inf_du and lg(mu) are the
        // restoration problem's.
        let (objective, inf_pr) = match self.nlp.original_measures(&self.it.w) {
            Some(v) => v,
            None => (
                self.scaling.objective_to_user(self.it.f),
                self.scaling.max_row_to_user(&self.it.c),
            ),
        };
        shared.stats.records.push(IterationRecord {
            iter: shared.iter,
            restoration: self.setup_in_resto,
            objective,
            inf_pr,
            inf_du: dual,
            d_norm,
            regularization: self.pert.delta_w(),
            backend: BackendColumns::Ipm {
                mu: self.mu_update.mu(),
                jacobian_regularization: self.pert.delta_c(),
            },
            alpha_du,
            alpha_pr,
            alpha_pr_char: ch,
            ls,
        });
        if let (Some(obs), Some(rec)) = (shared.observer.as_mut(), shared.stats.records.last()) {
            let (x, lambda) = obs.buffers();
            self.nlp
                .user_point(&self.it.w[..self.lay.n], &self.it.y, x, lambda);
            obs.call(rec);
        }
        if self.setup_in_resto {
            shared.stats.restoration_iterations += 1;
        }
        if self.pert.delta_w() > shared.stats.max_regularization {
            shared.stats.max_regularization = self.pert.delta_w();
        }
        if let (true, Some(rec)) = (self.opts.print_level >= 5, shared.stats.records.last()) {
            if shared.stats.records.len() % 10 == 1 {
                crate::log::log_out!("{}", crate::log::header(&rec.backend));
            }
            crate::log::log_out!("{}", crate::log::format_record(rec));
        }
    }

    /// The unscaled error measures of the current iterate for its log row, kept for
    /// the next stop test (`errors_here`).
    fn errors_for_record(&mut self) -> [f64; 3] {
        let errors = self.errors(0.0, false);
        self.errors_here = Some(errors);
        errors.1
    }

    pub(crate) fn outcome(
        &self,
        status: Status,
        message: impl Into<String>,
        resto_converged: bool,
    ) -> Outcome {
        Outcome {
            status,
            message: message.into(),
            resto_converged,
        }
    }

    // ------------------------------------------------------------------ main loop

    /// The tests before each iteration: user stop, convergence (or, in restoration, the
    /// restoration problem's own convergence) and the limits. Ok carries the scaled
    /// optimality error E_0 for the adaptive μ update.
    #[allow(clippy::result_large_err)]
    fn stop_test(&mut self, shared: &Shared) -> Result<f64, Outcome> {
        // The iteration callback (called by `record`) asked to stop (IPOPT tests
        // this before convergence).
        if shared.observer.as_ref().is_some_and(|o| o.stopped()) {
            return Err(self.outcome(
                Status::UserRequestedStop,
                "stopped by the iteration callback",
                false,
            ));
        }
        let (e0, eu) = match self.errors_here.take() {
            Some((e, eu)) => (self.scaled_error(e), eu),
            None => self.nlp_error(0.0, false),
        };
        let e = KktResiduals {
            overall: e0,
            dual: eu[0],
            primal: eu[1],
            compl: eu[2],
        };
        let now = (
            shared.iter,
            shared.start.elapsed().as_secs_f64(),
            inf_norm(&self.it.w),
        );
        if let Some(stop) = self.termination.check(&e, self.it.f, &self.opts, now) {
            return Err(self.outcome(stop.status, stop.message, stop.resto_converged));
        }
        Ok(e0)
    }

    /// Solves from `start`: each iteration updates the barrier, factorises, solves for
    /// the direction and takes a tiny or line-searched step; a failed step starts a
    /// restoration phase (`restore`).
    pub(crate) fn run(
        &mut self,
        shared: &mut Shared,
        start: Start<'_>,
        restore: Restorer,
    ) -> Outcome {
        if let Err(e) = self.initialize(start) {
            return self.outcome(Status::InvalidNumberDetected, e.to_string(), false);
        }
        let eu = self.errors_for_record();
        match self.resto_start.take() {
            Some((a_pr, ls)) => self.record(shared, 0.0, 0.0, a_pr, 'R', ls, eu[0]),
            None => self.record(shared, 0.0, 0.0, 0.0, ' ', 0, eu[0]),
        }
        let mut pending_resto = self.opts.start_with_resto && !self.setup_in_resto;
        self.termination.start(shared.iter);
        loop {
            let e0 = match self.stop_test(shared) {
                Ok(e0) => e0,
                Err(out) => return out,
            };
            // Why the restoration phase below starts (or, where it cannot, the solve ends).
            let (why, filter_augmented) = if std::mem::take(&mut pending_resto) {
                ("line search failed", false)
            } else {
                match self.iterate_once(shared, e0) {
                    Iteration::Continue => continue,
                    Iteration::Finished(out) => return out,
                    Iteration::Restore {
                        why,
                        filter_augmented,
                    } => (why, filter_augmented),
                }
            };
            if let Some(out) = self.restoration_phase(shared, why, filter_augmented, restore) {
                return out;
            }
        }
    }

    /// One iteration: barrier update, factorisation, direction, then a tiny step or a
    /// line search.
    fn iterate_once(&mut self, shared: &mut Shared, e0: f64) -> Iteration {
        if self.mu_update.strategy() == MuStrategy::Monotone {
            self.update_mu_monotone(self.count.tiny_count > 0);
        }
        let factor_ok = self.factorize_with_inertia_correction(shared);
        if factor_ok && self.mu_update.strategy() == MuStrategy::Adaptive {
            self.update_mu_adaptive(shared, e0);
        }
        if factor_ok && self.solve_direction(shared, self.mu_update.mu(), false) {
            shared.iter += 1;
            let d_norm = inf_norm(&self.dir.dw);
            if let Some(done) = self.try_tiny_step(shared, d_norm) {
                return done;
            }
            self.count.tiny_count = 0;
            return self.step_by_line_search(shared, d_norm);
        }
        if self.setup_in_resto {
            return Iteration::Finished(self.outcome(
                Status::ErrorInStepComputation,
                "inertia correction failed in restoration",
                false,
            ));
        }
        if !factor_ok && self.lay.m == 0 {
            return Iteration::Finished(self.outcome(
                Status::ErrorInStepComputation,
                "inertia correction failed",
                false,
            ));
        }
        Iteration::Restore {
            why: "line search failed",
            filter_augmented: false,
        }
    }

    /// Takes the full step when the direction is tiny relative to the iterate; `None`
    /// when it is not tiny (or the full step could not be taken).
    fn try_tiny_step(&mut self, shared: &mut Shared, d_norm: f64) -> Option<Iteration> {
        let rel = (0..self.lay.nw)
            .map(|j| self.dir.dw[j].abs() / (1.0 + self.it.w[j].abs()))
            .fold(0.0, f64::max);
        let tiny = rel < self.opts.tiny_step_tol
            && inf_norm(&self.dir.dy) < self.opts.tiny_step_y_tol * (1.0 + inf_norm(&self.it.y));
        if !(tiny && self.take_full_step()) {
            return None;
        }
        self.end_soft_resto();
        self.count.tiny_count += 1;
        let eu = self.errors_for_record();
        self.record(shared, d_norm, 1.0, 1.0, 't', 1, eu[0]);
        if self.count.tiny_count >= 2 && self.mu_update.at_floor() {
            return Some(Iteration::Finished(self.outcome(
                Status::SearchDirectionBecomesTooSmall,
                "",
                false,
            )));
        }
        Some(Iteration::Continue)
    }

    /// The line search along the direction and its record.
    fn step_by_line_search(&mut self, shared: &mut Shared, d_norm: f64) -> Iteration {
        let search = self.search_step(shared);
        let filter_augmented = search.filter_augmented();
        match search {
            LineSearch::Accepted {
                alpha_pr,
                alpha_du,
                kind,
                trials,
            } => {
                let eu = self.errors_for_record();
                let ch = kind.log_char();
                self.record(shared, d_norm, alpha_du, alpha_pr, ch, trials, eu[0]);
                if self.setup_in_resto && self.nlp.restoration_accepts(&self.it.w) {
                    return Iteration::Finished(self.outcome(Status::SolveSucceeded, "", false));
                }
                if !self.tiny_alpha_stall(alpha_pr) {
                    return Iteration::Continue;
                }
                // Treated as a failed line search (the step is kept): the
                // restoration's first row shows α_pr 0, 'R', ls 0.
                self.resto_start = Some((0.0, 0));
                Iteration::Restore {
                    why: "tiny_alpha_max_iter steps in a row with alpha_pr < tiny_alpha",
                    filter_augmented,
                }
            }
            LineSearch::Failed { alpha_pr, trials } => {
                // The restoration phase's first row reports the failed line search
                // (IPOPT: "12r", alpha_pr 'R', and its ls count, one more than the
                // trial steps).
                shared.iter -= 1;
                self.resto_start = Some((alpha_pr, trials + 1));
                Iteration::Restore {
                    why: "line search failed",
                    filter_augmented,
                }
            }
        }
    }

    /// A restoration phase started because of `why` (the filter already holds the
    /// current point if `filter_augmented`); `None` when the solve continues from the
    /// restored point, else the final outcome (also when no restoration phase can run:
    /// inside one, or without constraints).
    fn restoration_phase(
        &mut self,
        shared: &mut Shared,
        why: &str,
        filter_augmented: bool,
        restore: Restorer,
    ) -> Option<Outcome> {
        // The restoration phase moves the iterate: the kept error measures are stale.
        self.errors_here = None;
        let last_acceptable = self.termination.last_was_acceptable();
        if let Some((status, message)) =
            refusal(self.setup_in_resto, self.lay.m, last_acceptable, why)
        {
            return Some(self.outcome(status, message, false));
        }
        self.count.resto_calls += 1;
        // The restoration phase's first row takes the next iteration number (IPOPT's
        // count: the iteration whose line search failed is that row).
        shared.iter += 1;
        // Augment the filter with the current iterate (Wächter & Biegler, Alg. A step A-9)
        // unless the soft restoration attempt did.
        if !filter_augmented {
            let theta = one_norm(&self.it.c);
            let phi = self.barrier(&self.it.w, self.it.f, self.mu_update.mu());
            self.accept.augment(&mut self.filter, theta, phi);
        }
        let entry = Entry {
            nlp: &mut *self.nlp,
            lay: &self.lay,
            it: &self.it,
            mu: self.mu_update.mu(),
            opts: &self.opts,
            filter: &self.filter,
            theta_max: self.accept.theta_max,
            scaling: &self.scaling,
            failed_search: self.resto_start.take(),
        };
        let mut ended = restore(entry, shared);
        let moved = ended.point.take().map(|w| {
            self.restart_from(&w)
                .map(|()| self.scaling.max_row_to_user(&self.it.c))
                .map_err(|e| e.to_string())
        });
        match ended.next(moved, self.opts.constr_viol_tol) {
            Next::Resume { reset_filter } => {
                if reset_filter {
                    self.filter.reset();
                }
                self.end_soft_resto();
                self.pert.forget_last_delta_w();
                self.count.tiny_count = 0;
                None
            }
            Next::Stop { status, message } => Some(self.outcome(status, message, false)),
        }
    }

    /// Counts accepted steps with α_pr < `tiny_alpha`; true when `tiny_alpha_max_iter`
    /// of them came in a row (the count restarts). A run of such steps makes no
    /// progress that a restoration phase would not make faster: catenary_999 took 1159
    /// steps with α_pr ≤ 1e-8 at μ = 0.1 (‖d‖ ≈ 9e4, every step f-type) before this rule.
    fn tiny_alpha_stall(&mut self, alpha_pr: f64) -> bool {
        let max = self.opts.tiny_alpha_max_iter;
        if max == 0 || alpha_pr >= self.opts.tiny_alpha {
            self.count.tiny_alpha_run = 0;
            return false;
        }
        self.count.tiny_alpha_run += 1;
        if self.count.tiny_alpha_run >= max {
            self.count.tiny_alpha_run = 0;
            return true;
        }
        false
    }

    // ------------------------------------------------------------------ results

    /// The current iterate (a run's final point once it ended).
    pub(crate) fn iterate(&self) -> &Iterate {
        &self.it
    }
}
