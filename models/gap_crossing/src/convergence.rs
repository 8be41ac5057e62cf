//! The convergence history of a planning run: at every iteration of every solver run
//! (the free gait makes up to three), the objective, the constraint violation and the
//! residual of equation (10) at the iterate. Recorded through the solvers' iteration
//! callback ([`ResidualProbe`] turns an iterate into the (10) residual), written as
//! `convergence.json` (schema in docs/gap-crossing.md) and drawn by
//! [`crate::render::convergence_svg`].

use crate::model::Model;
use crate::plan::STANCE_LEN;
use crate::scenario::Scenario;
use crate::solve::{complementarity_residual, Phase};
use nlp::BuildError;
use serde::{Deserialize, Serialize};

/// `version` of the files written now. Version 1 (read by [`Convergence::from_json`]) was
/// a bare array of `{iter, objective, inf_pr, compl}` with the barrier μ as `compl` and
/// no (10) residual.
pub const FORMAT_VERSION: u32 = 2;

/// The history of one planning run (the content of `convergence.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Convergence {
    /// [`FORMAT_VERSION`].
    pub version: u32,
    /// The solver runs, in order.
    pub phases: Vec<PhaseSpan>,
    /// Every iteration of every run, in order.
    pub iterations: Vec<Iteration>,
}

/// One solver run of the history.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PhaseSpan {
    /// What the run solved (e.g. "free gait: choose the steps, penalty 1e8").
    pub name: String,
    /// The solver's status (`nlp::Status` variant name).
    pub status: String,
    /// The foot schedule was fixed: feet that do not move share variables between
    /// stances, so (10) holds exactly — its residual is 0 — at every iterate of the run.
    pub scheduled: bool,
    /// Index in [`Convergence::iterations`] of the run's first entry.
    pub first: usize,
    /// Number of entries of the run: its iterations + 1 (iteration 0 is the starting
    /// point), plus one per restoration phase entered (the restoration's starting row).
    pub len: usize,
    /// The solver's iteration count for the run.
    pub iterations: usize,
}

/// One iteration (one row of the solver's log).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Iteration {
    /// Position in the whole history (the x axis of the plot).
    pub index: usize,
    /// Index of the run in [`Convergence::phases`].
    pub phase: usize,
    /// The solver's iteration number within the run.
    pub iter: usize,
    /// Interior-point restoration phase (SQP: elastic mode).
    pub restoration: bool,
    /// The solver's objective: cost (1), plus the complementarity penalty π·Σ s_i s_j in
    /// the run choosing the steps (in restoration, the restoration problem's objective).
    pub objective: f64,
    /// Constraint violation (max-norm, unscaled).
    pub inf_pr: f64,
    /// Residual of (10) at the iterate: the largest over transitions of
    /// `Σ_{i<j} ‖Δr_i‖²‖Δr_j‖²` (m⁴), as [`complementarity_residual`]; exactly 0 in
    /// scheduled runs. `None` when not recorded (version-1 files).
    pub residual_10: Option<f64>,
    /// Barrier parameter μ (0 for the SQP).
    pub mu: f64,
}

/// A version-1 row.
#[derive(Deserialize)]
struct V1 {
    iter: usize,
    objective: f64,
    inf_pr: f64,
    compl: f64,
}

impl Convergence {
    /// The history of a planning run's solver runs.
    pub fn from_phases(phases: &[Phase]) -> Convergence {
        let mut spans = Vec::with_capacity(phases.len());
        let mut iterations = Vec::new();
        for (p, phase) in phases.iter().enumerate() {
            spans.push(PhaseSpan {
                name: phase.name.clone(),
                status: format!("{:?}", phase.status),
                scheduled: phase.scheduled,
                first: iterations.len(),
                len: phase.records.len(),
                iterations: phase.iterations,
            });
            for (k, r) in phase.records.iter().enumerate() {
                iterations.push(Iteration {
                    index: iterations.len(),
                    phase: p,
                    iter: r.iter,
                    restoration: r.restoration,
                    objective: r.objective,
                    inf_pr: r.inf_pr,
                    residual_10: phase.residuals.get(k).copied(),
                    mu: r.mu().unwrap_or(0.0),
                });
            }
        }
        Convergence {
            version: FORMAT_VERSION,
            phases: spans,
            iterations,
        }
    }

    /// Reads `convergence.json`: the current format, or version 1 (one run named
    /// "solver runs", no (10) residual, its `compl` read as μ).
    pub fn from_json(text: &str) -> Result<Convergence, serde_json::Error> {
        if text.trim_start().starts_with('[') {
            let rows: Vec<V1> = serde_json::from_str(text)?;
            let iterations: Vec<Iteration> = rows
                .iter()
                .enumerate()
                .map(|(k, r)| Iteration {
                    index: k,
                    phase: 0,
                    iter: r.iter,
                    restoration: false,
                    objective: r.objective,
                    inf_pr: r.inf_pr,
                    residual_10: None,
                    mu: r.compl,
                })
                .collect();
            return Ok(Convergence {
                version: 1,
                phases: vec![PhaseSpan {
                    name: "solver runs".into(),
                    status: "unknown".into(),
                    scheduled: false,
                    first: 0,
                    len: iterations.len(),
                    iterations: iterations.len().saturating_sub(1),
                }],
                iterations,
            });
        }
        serde_json::from_str(text)
    }

    /// The entries of run `p`.
    pub fn phase_iterations(&self, p: usize) -> &[Iteration] {
        let s = &self.phases[p];
        &self.iterations[s.first..s.first + s.len]
    }
}

/// The (10) residual of solver iterates: the model's plan layout (30 numbers per stance)
/// compiled once, evaluated at each iterate without allocating, then
/// [`complementarity_residual`].
pub struct ResidualProbe<'s> {
    scenario: &'s Scenario,
    layout: symx::Function,
    flat: Vec<f64>,
    work: Vec<f64>,
}

impl<'s> ResidualProbe<'s> {
    /// For the variables of `model` (the layout does not involve parameters).
    pub fn new(scenario: &'s Scenario, model: &Model) -> Result<Self, BuildError> {
        let layout = symx::Function::new(&[model.problem.variables()], &[&model.layout])?;
        let work = vec![0.0; layout.work_size()];
        Ok(ResidualProbe {
            scenario,
            layout,
            flat: vec![0.0; scenario.n_step * STANCE_LEN],
            work,
        })
    }

    /// The (10) residual at the model's primal point `x`.
    pub fn at(&mut self, x: &[f64]) -> f64 {
        match self
            .layout
            .eval(&[x], &mut [&mut self.flat[..]], &mut self.work)
        {
            Ok(()) => complementarity_residual(self.scenario, &self.flat),
            Err(_) => f64::NAN,
        }
    }
}
