//! An instance as plain text, for solving the identical formulation elsewhere.
//!
//! The dump has the schema of `gap_crossing::export::NlpDump` (variables with names,
//! bounds and initial values; constraint rows with their expression printed by symx,
//! bounds, names and value at the initial point; the objective and its initial value), so
//! that `benches/reference/corpus_ipopt.py` rebuilds it in CasADi with the parser of
//! `benches/reference/gap_crossing_casadi.py`. Variable names must be `name` or
//! `name[i]` (what that parser reads); the corpus declares only scalar and vector
//! variables.
use crate::{CorpusError, Instance};
use nlp::{Compiled, NumericNlp, Problem};
use serde::{Deserialize, Serialize};
use symx::Expr;

/// One variable.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct VariableDump {
    /// The symbol's name as it appears in the expressions.
    pub name: String,
    /// Lower bound (`null`: −∞).
    pub lower: Option<f64>,
    /// Upper bound (`null`: +∞).
    pub upper: Option<f64>,
    /// Initial value.
    pub x0: f64,
}

/// One constraint row `lower ≤ expr ≤ upper`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ConstraintDump {
    /// The row's name.
    pub name: String,
    /// The row's expression in symx's printed form.
    pub expr: String,
    /// Lower bound (`null`: −∞).
    pub lower: Option<f64>,
    /// Upper bound (`null`: +∞).
    pub upper: Option<f64>,
    /// The row's value at the initial point (computed by the compiled problem).
    pub g0: f64,
}

/// The whole problem `min f(x)` s.t. `lower ≤ g(x) ≤ upper`, `x_l ≤ x ≤ x_u`, from `x0`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Dump {
    /// The instance's name and source.
    pub description: String,
    /// Number of variables.
    pub n: usize,
    /// Number of constraint rows.
    pub m: usize,
    /// Variables, in the order of `x`.
    pub variables: Vec<VariableDump>,
    /// Constraint rows, in the order of `g`.
    pub constraints: Vec<ConstraintDump>,
    /// The objective in symx's printed form.
    pub objective: String,
    /// The objective at the initial point (computed by the compiled problem).
    pub f0: f64,
    /// symnlp's result on this instance, when the dump was written with a solve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub symnlp: Option<crate::run::Outcome>,
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
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

/// Dumps a built and compiled instance.
pub fn dump(
    instance: &Instance,
    pb: &Problem,
    compiled: &mut Compiled,
) -> Result<Dump, CorpusError> {
    let (n, m) = (compiled.n(), compiled.m());
    let (mut xl, mut xu, mut gl, mut gu) = (vec![0.0; n], vec![0.0; n], vec![0.0; m], vec![0.0; m]);
    compiled.bounds(&mut xl, &mut xu, &mut gl, &mut gu);
    let mut x0 = vec![0.0; n];
    compiled.initial_point(&mut x0);
    let mut g0 = vec![0.0; m];
    compiled.eval_g(&x0, &mut g0);
    let f0 = compiled.eval_f(&x0);
    let mut variables = Vec::with_capacity(n);
    for (i, v) in pb.variables().iter().enumerate() {
        let name = v.name().unwrap_or_default();
        if !readable(&name) {
            return Err(CorpusError::VariableName {
                instance: instance.name(),
                name,
            });
        }
        variables.push(VariableDump {
            name,
            lower: finite(xl[i]),
            upper: finite(xu[i]),
            x0: x0[i],
        });
    }
    let constraints = pb
        .constraint_expressions()
        .iter()
        .enumerate()
        .map(|(i, e)| ConstraintDump {
            name: compiled.constraint_name(i),
            expr: e.to_string(),
            lower: finite(gl[i]),
            upper: finite(gu[i]),
            g0: g0[i],
        })
        .collect();
    Ok(Dump {
        description: format!("{} ({})", instance.name(), instance.family.source),
        n,
        m,
        variables,
        constraints,
        objective: pb.objective().to_string(),
        f0,
        symnlp: None,
    })
}

/// Parses every printed expression of `d` back with [`symx::parse`] against fresh symbols
/// of the dumped names and evaluates it at the dumped initial point with symx alone:
/// returns the largest absolute difference to the dumped `f0`, `g0` (zero up to rounding
/// when the text describes the compiled problem).
pub fn verify(d: &Dump) -> Result<f64, CorpusError> {
    let xs: Vec<Expr> = d.variables.iter().map(|v| Expr::sym(&v.name)).collect();
    let x0: Vec<f64> = d.variables.iter().map(|v| v.x0).collect();
    let parse = |what: &str, text: &str| {
        symx::parse(text, &xs).map_err(|e| CorpusError::Parse {
            what: what.to_string(),
            message: e.to_string(),
        })
    };
    let mut exprs = Vec::with_capacity(d.m + 1);
    exprs.push(parse("objective", &d.objective)?);
    for c in &d.constraints {
        exprs.push(parse(&c.name, &c.expr)?);
    }
    let parse_err = |e: symx::SymxError| CorpusError::Parse {
        what: "evaluation".into(),
        message: e.to_string(),
    };
    let f = symx::Function::new(&[&xs], &[&exprs]).map_err(parse_err)?;
    let values = f.call(&[&x0]).map_err(parse_err)?.swap_remove(0);
    let mut err = (values[0] - d.f0).abs();
    for (v, c) in values[1..].iter().zip(&d.constraints) {
        err = err.max((v - c.g0).abs());
    }
    Ok(err)
}
