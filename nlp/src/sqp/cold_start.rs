//! The interior-point method's solution as the start of a cold SQP solve (option
//! [`SqpOptions::cold_start_ipm`]).
//!
//! From a cold start the SQP's QPs change their working sets by hundreds of constraints,
//! and its ℓ1 merit and elastic mode can stall far from a solution (the cold corpus in
//! benches/reference/results/performance-notebook.md, "Cold SQP corpus"); from the IPM's
//! solution the same problems converge in 0–2 SQP iterations. This is the usual split of
//! work in control loops: the interior point for the first solve, the SQP (or RTI) for
//! the warm ones.

use std::ops::ControlFlow;

use crate::callback::{IterationCallback, IterationView};
use crate::error::SolveError;
use crate::frontend::Solver;
use crate::numeric::NumericNlp;
use crate::options::IpmOptions;
use crate::solution::{Solution, Stats, Status};
use crate::Ipm;

use super::SqpOptions;

/// What the interior-point start gave.
pub(super) enum IpmStart {
    /// A solution: the SQP starts from it.
    Solved(Solution),
    /// The IPM did not succeed (its solution, for its statistics): the SQP starts cold.
    Failed(Solution),
    /// The user's callback asked to stop during the IPM: the solve ends with it.
    Stopped(Solution),
}

/// The IPM's solve of `nlp` under the SQP's common options (termination, scaling bounds,
/// output), the user's callback seeing its iterations.
pub(super) fn ipm_start(
    o: &SqpOptions,
    nlp: &mut dyn NumericNlp,
    callback: Option<&mut IterationCallback<'_>>,
) -> Result<IpmStart, SolveError> {
    let ipm = Ipm::new(IpmOptions {
        common: o.common.clone(),
        ..IpmOptions::default()
    });
    let sol = ipm.solve_dyn(nlp, None, callback)?;
    Ok(match sol.status {
        Status::UserRequestedStop => IpmStart::Stopped(sol),
        s if s.is_success() => IpmStart::Solved(sol),
        _ => IpmStart::Failed(sol),
    })
}

/// The user's callback for the SQP's iterations after an IPM start of `offset`
/// iterations: numbered on from the IPM's, the SQP's row 0 left out (its start: the
/// IPM's solution, seen as the IPM's last row, or after a failed IPM the problem's guess,
/// seen as the IPM's row 0), as in the merged [`Stats::records`] of [`count_start_in`].
pub(super) fn continue_numbering<'a, 'c: 'a>(
    callback: &'a mut IterationCallback<'c>,
    offset: usize,
) -> impl FnMut(&IterationView<'_>) -> ControlFlow<()> + use<'a, 'c> {
    move |view| {
        if view.record.iter == 0 {
            return ControlFlow::Continue(());
        }
        let mut record = *view.record;
        record.iter += offset;
        callback(&IterationView {
            record: &record,
            ..*view
        })
    }
}

/// `sqp`'s statistics with the interior-point start's counted in: iterations,
/// evaluations, factorisations and seconds summed, the IPM's iteration records followed
/// by the SQP's (the SQP's row 0, its start again, left out: see [`continue_numbering`];
/// its numbers continue the IPM's), `start_iterations` the IPM's iterations.
pub(super) fn count_start_in(ipm: &Stats, sqp: &mut Stats) {
    let offset = ipm.iterations;
    let mut records = ipm.records.clone();
    records.extend(sqp.records.iter().skip(1).copied().map(|mut r| {
        r.iter += offset;
        r
    }));
    sqp.records = records;
    sqp.iterations += ipm.iterations;
    sqp.restoration_iterations += ipm.restoration_iterations;
    sqp.start_iterations = ipm.iterations;
    sqp.n_eval_f += ipm.n_eval_f;
    sqp.n_eval_grad_f += ipm.n_eval_grad_f;
    sqp.n_eval_g += ipm.n_eval_g;
    sqp.n_eval_jac_g += ipm.n_eval_jac_g;
    sqp.n_eval_hess_l += ipm.n_eval_hess_l;
    sqp.n_factorizations += ipm.n_factorizations;
    sqp.max_regularization = sqp.max_regularization.max(ipm.max_regularization);
    sqp.eval_seconds += ipm.eval_seconds;
    sqp.factor_seconds += ipm.factor_seconds;
    sqp.total_seconds += ipm.total_seconds;
    sqp.other_seconds += ipm.other_seconds;
}
