//! The crawl-gait problem as plain text, for solving the identical formulation elsewhere.
//!
//! [`crawl_dump`] builds the scheduled (crawl) formulation of [`crate::model`] from the
//! crawl heuristic's guess, compiles it, and returns an [`NlpDump`]: every variable with
//! its symbol name, bounds and initial value, every constraint row with its expression
//! printed by symx (`Display`), bounds and name, and the objective. The expressions use
//! symx's printed form: fully parenthesised infix `+ - * /`, `(-x)` for negation, calls such
//! as `sq(x)`, `sqrt(x)`, `atan(x)`, `pow(a,b)`, symbols by name (`r_BR^3[0]`), and shared
//! subexpressions as bindings `@1=...; @2=...; result`. `benches/reference/gap_crossing_casadi.py`
//! reads this file into CasADi SX and solves it with IPOPT, so both solvers see the same
//! problem without a second, hand-written formulation that could drift.
//!
//! The text format and its check ([`nlp::ProblemDump::verify`]: every printed expression
//! parsed back with [`symx::parse`] evaluates, at the initial point, to what the compiled
//! problem computes) are `nlp::dump`'s; this module adds the scenario.
use crate::gait;
use crate::model::{self, Formulation, Model};
use crate::scenario::Scenario;
use crate::terrain;
use nlp::{Compiled, ProblemDump};
use serde::{Deserialize, Serialize};

/// The dumped crawl-gait problem: the scenario it was built from and the problem
/// ([`ProblemDump`], its fields at the top level of the JSON object).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NlpDump {
    /// The scenario the problem was built from.
    pub scenario: Scenario,
    /// The problem as text.
    #[serde(flatten)]
    pub problem: ProblemDump,
}

/// The crawl-gait model of `s` (crawl schedule, crawl guess, the scenario's terrain),
/// built and compiled.
pub fn crawl_model(s: &Scenario) -> Result<(Model, Compiled), crate::solve::PlanningError> {
    let guess = gait::crawl(s);
    let formulation = Formulation::Scheduled(gait::crawl_schedule(s.n_step));
    let model = model::build(s, &*terrain::of(s), &formulation, &guess)?;
    let compiled = model.problem.compile()?;
    Ok((model, compiled))
}

/// Dumps a built and compiled model (see the module documentation).
pub fn dump(s: &Scenario, model: &Model, compiled: &mut Compiled) -> NlpDump {
    let description = format!(
        "gap_crossing crawl formulation (scheduled feet, keep-out as bounds), n_step {}, gap depth {}",
        s.n_step, s.gap.depth
    );
    NlpDump {
        scenario: s.clone(),
        problem: ProblemDump::new(&model.problem, compiled, description),
    }
}

/// Builds, compiles and dumps the crawl-gait problem of `s`.
pub fn crawl_dump(s: &Scenario) -> Result<NlpDump, crate::solve::PlanningError> {
    let (model, mut compiled) = crawl_model(s)?;
    Ok(dump(s, &model, &mut compiled))
}
