//! The interior-point method's solution as the start of a cold SQP solve (option
//! [`SqpOptions::cold_start_ipm`]).
//!
//! From a cold start the SQP's QPs change their working sets by hundreds of constraints,
//! and its ℓ1 merit and elastic mode can stall far from a solution (the cold corpus in
//! benches/reference/results/performance-notebook.md, "Cold SQP corpus"); from the IPM's
//! solution the same problems converge in 0–2 SQP iterations. This is the usual split of
//! work in control loops: the interior point for the first solve, the SQP (or RTI) for
//! the warm ones.

use crate::error::SolveError;
use crate::frontend::Solver;
use crate::numeric::NumericNlp;
use crate::options::IpmOptions;
use crate::solution::Solution;
use crate::Ipm;

use super::SqpOptions;

/// The IPM's solution of `nlp` under the SQP's common options (termination, scaling
/// bounds, output), or `None` when the IPM does not succeed (the SQP then starts cold).
pub(super) fn ipm_start(
    o: &SqpOptions,
    nlp: &mut dyn NumericNlp,
) -> Result<Option<Solution>, SolveError> {
    let ipm = Ipm::new(IpmOptions {
        common: o.common.clone(),
        ..IpmOptions::default()
    });
    let sol = ipm.solve_dyn(nlp, None, None)?;
    Ok(sol.status.is_success().then_some(sol))
}
