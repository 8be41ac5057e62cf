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
//! [`verify`] parses every printed expression back with [`symx::parse`] and checks that it
//! evaluates, at the initial point, to what the compiled problem computes.
use crate::gait;
use crate::model::{self, Formulation, Model};
use crate::scenario::Scenario;
use crate::terrain;
use nlp::{Compiled, NumericNlp};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use symx::Expr;

/// One variable of the dumped problem.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct VariableDump {
    /// The symbol's name, as it appears in the expressions (e.g. `r_BR^3[0]`).
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
    /// The row's name (equation and stance, e.g. `(11) leg BR, stance 3`).
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

/// The whole problem: `min f(x)` s.t. `lower ≤ g(x) ≤ upper`, `x_l ≤ x ≤ x_u`, from `x0`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NlpDump {
    /// What was dumped (formulation and scenario summary).
    pub description: String,
    /// The scenario the problem was built from.
    pub scenario: Scenario,
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
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
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
    let (n, m) = (compiled.n(), compiled.m());
    let (mut xl, mut xu, mut gl, mut gu) = (vec![0.0; n], vec![0.0; n], vec![0.0; m], vec![0.0; m]);
    compiled.bounds(&mut xl, &mut xu, &mut gl, &mut gu);
    let mut x0 = vec![0.0; n];
    compiled.initial_point(&mut x0);
    let mut g0 = vec![0.0; m];
    compiled.eval_g(&x0, &mut g0);
    let f0 = compiled.eval_f(&x0);
    let symbols = model.problem.variables();
    let variables = (0..n)
        .map(|i| VariableDump {
            name: symbols[i]
                .name()
                .unwrap_or_else(|| compiled.variable_name(i)),
            lower: finite(xl[i]),
            upper: finite(xu[i]),
            x0: x0[i],
        })
        .collect();
    let constraints = model
        .problem
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
    NlpDump {
        description: format!(
            "gap_crossing crawl formulation (scheduled feet, keep-out as bounds), n_step {}, gap depth {}",
            s.n_step, s.gap.depth
        ),
        scenario: s.clone(),
        n,
        m,
        variables,
        constraints,
        objective: model.problem.objective().to_string(),
        f0,
    }
}

/// Builds, compiles and dumps the crawl-gait problem of `s`.
pub fn crawl_dump(s: &Scenario) -> Result<NlpDump, crate::solve::PlanningError> {
    let (model, mut compiled) = crawl_model(s)?;
    Ok(dump(s, &model, &mut compiled))
}

/// What [`verify`] found: the largest differences between the printed-and-parsed
/// expressions and the compiled problem at the initial point.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Verification {
    /// `|f_parsed(x0) − f0|`.
    pub objective_error: f64,
    /// `max_i |g_parsed,i(x0) − g0_i|`.
    pub constraint_error: f64,
}

/// Replaces every symbol name of `names` in the printed expression `text` by `x[i]`, its
/// position in `x` (exact tokens: a name is `[A-Za-z_][A-Za-z0-9_^]*` optionally followed
/// by one `[digits]`; function names such as `sq` are left alone). symx's parser does not
/// accept `^` in a name, and the CasADi side indexes one vector `x` the same way.
pub fn indexed(text: &str, names: &HashMap<&str, usize>) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let mut copied = 0;
    while i < b.len() {
        let c = b[i];
        let starts = (c.is_ascii_alphabetic() || c == b'_')
            && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || matches!(b[i - 1], b'_' | b'.')));
        if !starts {
            i += 1;
            continue;
        }
        let start = i;
        while i < b.len() && (b[i].is_ascii_alphanumeric() || matches!(b[i], b'_' | b'^')) {
            i += 1;
        }
        if i < b.len() && b[i] == b'[' {
            if let Some(close) = b[i..].iter().position(|&c| c == b']') {
                if b[i + 1..i + close].iter().all(u8::is_ascii_digit) {
                    i += close + 1;
                }
            }
        }
        if let Some(k) = names.get(&text[start..i]) {
            out.push_str(&text[copied..start]);
            out.push_str(&format!("x[{k}]"));
            copied = i;
        }
    }
    out.push_str(&text[copied..]);
    out
}

/// Parses every printed expression of `d` back with [`symx::parse`] (after [`indexed`],
/// against fresh symbols `x[i]`) and evaluates it at the dumped initial point, with symx
/// alone (no nlp code): the text the CasADi side reads describes the compiled problem.
pub fn verify(d: &NlpDump) -> Result<Verification, String> {
    let names: HashMap<&str, usize> = d
        .variables
        .iter()
        .enumerate()
        .map(|(i, v)| (v.name.as_str(), i))
        .collect();
    if names.len() != d.n {
        return Err("variable names are not distinct".into());
    }
    let xs: Vec<Expr> = (0..d.n).map(|i| Expr::sym(&format!("x[{i}]"))).collect();
    let x0: Vec<f64> = d.variables.iter().map(|v| v.x0).collect();
    let parse = |what: &str, text: &str| {
        symx::parse(&indexed(text, &names), &xs).map_err(|e| format!("{what}: {e}"))
    };
    let mut exprs = Vec::with_capacity(d.m + 1);
    exprs.push(parse("objective", &d.objective)?);
    for c in &d.constraints {
        exprs.push(parse(&c.name, &c.expr)?);
    }
    let f = symx::Function::new(&[&xs], &[&exprs]).map_err(|e| e.to_string())?;
    let values = f.call(&[&x0]).map_err(|e| e.to_string())?.swap_remove(0);
    let objective_error = (values[0] - d.f0).abs();
    let constraint_error = values[1..]
        .iter()
        .zip(&d.constraints)
        .map(|(v, c)| (v - c.g0).abs())
        .fold(0.0, f64::max);
    Ok(Verification {
        objective_error,
        constraint_error,
    })
}
