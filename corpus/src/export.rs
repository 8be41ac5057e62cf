//! An instance as plain text, for solving the identical formulation elsewhere.
//!
//! The dump is an [`nlp::ProblemDump`] (variables with names, bounds and initial
//! values; constraint rows with their expression printed by symx, bounds, names and value
//! at the initial point; the objective and its initial value), the schema the planner's
//! export writes too, so that `benches/reference/corpus_ipopt.py` rebuilds it in CasADi with the parser of
//! `benches/reference/gap_crossing_casadi.py`. Variable names must be `name` or
//! `name[i]` (what that parser reads); the corpus declares only scalar and vector
//! variables.
use crate::{CorpusError, Instance};
use nlp::{Compiled, Problem, ProblemDump};
use serde::{Deserialize, Serialize};

/// An instance as text: the problem ([`ProblemDump`], its fields at the top level of the
/// JSON object) and, when the dump was written with a solve, symnlp's result.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Dump {
    /// The problem as text.
    #[serde(flatten)]
    pub problem: ProblemDump,
    /// symnlp's result on this instance, when the dump was written with a solve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub symnlp: Option<crate::run::Outcome>,
}

/// Whether the CasADi-side parser reads `name`: `[A-Za-z_][A-Za-z0-9_]*` optionally followed
/// by one `[digits]`.
fn readable(name: &str) -> bool {
    let (stem, index) = match name.find('[') {
        Some(p) => (&name[..p], Some(&name[p..])),
        None => (name, None),
    };
    let stem_ok = stem
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && stem.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    let index_ok = index.is_none_or(|i| {
        i.len() > 2 && i.ends_with(']') && i[1..i.len() - 1].chars().all(|c| c.is_ascii_digit())
    });
    stem_ok && index_ok
}

/// Dumps a built and compiled instance; an error when a variable's name is not one the
/// reference parser reads.
pub fn dump(
    instance: &Instance,
    pb: &Problem,
    compiled: &mut Compiled,
) -> Result<Dump, CorpusError> {
    let description = format!("{} ({})", instance.name(), instance.family.source);
    let problem = ProblemDump::new(pb, compiled, description);
    if let Some(v) = problem.variables.iter().find(|v| !readable(&v.name)) {
        return Err(CorpusError::VariableName {
            instance: instance.name(),
            name: v.name.clone(),
        });
    }
    Ok(Dump {
        problem,
        symnlp: None,
    })
}

/// Parses every printed expression of `d` back with [`symx::parse`] and evaluates it at
/// the dumped initial point with symx alone ([`ProblemDump::verify`]): returns the largest
/// absolute difference to the dumped `f0`, `g0` (zero up to rounding when the text
/// describes the compiled problem).
pub fn verify(d: &Dump) -> Result<f64, CorpusError> {
    let v = d.problem.verify().map_err(|e| CorpusError::Parse {
        what: "dump".into(),
        message: e.to_string(),
    })?;
    Ok(v.objective_error.max(v.constraint_error))
}
