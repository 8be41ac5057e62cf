//! Solving instances with symnlp's interior-point method and recording the outcome.
use crate::{CorpusError, Instance, Kind};
use nlp::{Ipm, IpmOptions};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// What one solve of one instance gave.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Outcome {
    /// Instance name (`family_size`).
    pub instance: String,
    /// Family name.
    pub family: String,
    /// Optimal control or CUTEst-style.
    pub kind: Kind,
    /// Transcription of the family.
    pub transcription: String,
    /// Size parameter.
    pub size: usize,
    /// Number of variables.
    pub n: usize,
    /// Number of constraint rows.
    pub m: usize,
    /// The solver's status (IPOPT's vocabulary).
    pub status: String,
    /// Whether the status is a success.
    pub success: bool,
    /// Iterations, restoration included.
    pub iterations: usize,
    /// Iterations in restoration.
    pub restoration_iterations: usize,
    /// Final objective.
    pub objective: f64,
    /// Final constraint violation (max-norm, unscaled).
    pub constr_viol: f64,
    /// Final dual infeasibility (max-norm, unscaled).
    pub dual_inf: f64,
    /// Seconds to build and compile the problem.
    pub compile_s: f64,
    /// Seconds in the solve (wall time; noisy on a shared machine).
    pub solve_s: f64,
    /// Published optimum of this instance, if any.
    pub reference: Option<f64>,
}

/// The solver settings of every corpus run: IPOPT's defaults (tol 1e-8, max_iter 3000,
/// exact Hessian) with a wall-time cap of `max_wall` seconds.
pub fn options(max_wall: f64) -> IpmOptions {
    IpmOptions {
        common: nlp::CommonOptions {
            max_wall_time: max_wall,
            ..nlp::CommonOptions::default()
        },
        ..IpmOptions::default()
    }
}

/// Builds, compiles and solves `instance` with `options`.
pub fn solve(instance: &Instance, options: &IpmOptions) -> Result<Outcome, CorpusError> {
    let t = Instant::now();
    let pb = instance.build()?;
    let mut compiled = pb.compile()?;
    let compile_s = t.elapsed().as_secs_f64();
    solve_compiled(instance, &mut compiled, compile_s, options)
}

/// Solves an already compiled instance.
pub fn solve_compiled(
    instance: &Instance,
    compiled: &mut nlp::Compiled,
    compile_s: f64,
    options: &IpmOptions,
) -> Result<Outcome, CorpusError> {
    use nlp::NumericNlp;
    let t = Instant::now();
    let sol = Ipm::new(options.clone()).solve(compiled)?;
    let solve_s = t.elapsed().as_secs_f64();
    Ok(Outcome {
        instance: instance.name(),
        family: instance.family.name.to_string(),
        kind: instance.family.kind,
        transcription: instance.family.transcription.to_string(),
        size: instance.size,
        n: compiled.n(),
        m: compiled.m(),
        status: format!("{:?}", sol.status),
        success: sol.status.is_success(),
        iterations: sol.stats.iterations,
        restoration_iterations: sol.stats.restoration_iterations,
        objective: sol.objective,
        constr_viol: sol.constr_viol,
        dual_inf: sol.dual_inf,
        compile_s,
        solve_s,
        reference: instance.reference().map(|r| r.value),
    })
}
