//! A compiled problem as plain text, for solving the identical formulation elsewhere.
//!
//! [`ProblemDump::new`] writes every variable with its symbol name, bounds and initial
//! value, every constraint row with its expression printed by symx (`Display`), bounds,
//! name and value at the initial point, and the objective. The printed form is fully
//! parenthesised infix `+ - * /`, `(-x)` for negation, calls such as `sq(x)`, symbols by
//! name, and shared subexpressions as bindings `@1=...; @2=...; result`; the reference
//! scripts under `benches/reference/` read it into CasADi and solve it with IPOPT, so
//! both solvers see one formulation and no hand-written copy can drift.
//!
//! [`ProblemDump::verify`] parses every printed expression back with [`symx::parse`] and
//! evaluates it at the initial point with symx alone: the text describes the compiled
//! problem when the differences are zero up to rounding.
use crate::{Compiled, NumericNlp, Problem};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use symx::Expr;
use thiserror::Error;

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

/// The whole problem `min f(x)` s.t. `lower ≤ g(x) ≤ upper`, `x_l ≤ x ≤ x_u`, from `x0`,
/// as compiled (after simple bound detection).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProblemDump {
    /// What was dumped.
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
}

/// What [`ProblemDump::verify`] found: the largest differences between the printed and
/// parsed expressions and the compiled problem at the initial point.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct DumpVerification {
    /// `|f_parsed(x0) − f0|`.
    pub objective_error: f64,
    /// `max_i |g_parsed,i(x0) − g0_i|`.
    pub constraint_error: f64,
}

/// A dump whose text does not read back.
#[derive(Debug, Error)]
pub enum DumpError {
    /// Two variables share a name, so the expressions are ambiguous.
    #[error("variable name '{0}' appears twice")]
    DuplicateName(String),
    /// A printed expression does not parse.
    #[error("{what}: {message}")]
    Parse {
        /// The objective or the constraint's name.
        what: String,
        /// The parser's message.
        message: String,
    },
    /// The parsed expressions do not compile or evaluate.
    #[error("evaluating the parsed expressions: {0}")]
    Eval(#[from] symx::SymxError),
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

impl ProblemDump {
    /// Dumps `problem`, compiled as `compiled` (see the module documentation). A variable
    /// without a symbol name is named as the compiled problem names it.
    pub fn new(problem: &Problem, compiled: &mut Compiled, description: String) -> Self {
        let (n, m) = (compiled.n(), compiled.m());
        let (mut xl, mut xu) = (vec![0.0; n], vec![0.0; n]);
        let (mut gl, mut gu) = (vec![0.0; m], vec![0.0; m]);
        compiled.bounds(&mut xl, &mut xu, &mut gl, &mut gu);
        let mut x0 = vec![0.0; n];
        compiled.initial_point(&mut x0);
        let mut g0 = vec![0.0; m];
        compiled.eval_g(&x0, &mut g0);
        let f0 = compiled.eval_f(&x0);
        let variables = problem
            .variables()
            .iter()
            .enumerate()
            .map(|(i, v)| VariableDump {
                name: v.name().unwrap_or_else(|| compiled.variable_name(i)),
                lower: finite(xl[i]),
                upper: finite(xu[i]),
                x0: x0[i],
            })
            .collect();
        let constraints = problem
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
        ProblemDump {
            description,
            n,
            m,
            variables,
            constraints,
            objective: problem.objective().to_string(),
            f0,
        }
    }

    /// Parses every printed expression back with [`symx::parse`] (after [`indexed`],
    /// against fresh symbols `x[i]`) and evaluates it at the dumped initial point with symx
    /// alone (no nlp code).
    pub fn verify(&self) -> Result<DumpVerification, DumpError> {
        let mut names: HashMap<&str, usize> = HashMap::with_capacity(self.n);
        for (i, v) in self.variables.iter().enumerate() {
            if names.insert(v.name.as_str(), i).is_some() {
                return Err(DumpError::DuplicateName(v.name.clone()));
            }
        }
        let xs: Vec<Expr> = (0..self.n).map(|i| Expr::sym(&format!("x[{i}]"))).collect();
        let x0: Vec<f64> = self.variables.iter().map(|v| v.x0).collect();
        let parse = |what: &str, text: &str| {
            symx::parse(&indexed(text, &names), &xs).map_err(|e| DumpError::Parse {
                what: what.to_string(),
                message: e.to_string(),
            })
        };
        let mut exprs = Vec::with_capacity(self.m + 1);
        exprs.push(parse("objective", &self.objective)?);
        for c in &self.constraints {
            exprs.push(parse(&c.name, &c.expr)?);
        }
        let f = symx::Function::new(&[&xs], &[&exprs])?;
        let values = f.call(&[&x0])?.swap_remove(0);
        let constraint_error = values[1..]
            .iter()
            .zip(&self.constraints)
            .map(|(v, c)| (v - c.g0).abs())
            .fold(0.0, f64::max);
        Ok(DumpVerification {
            objective_error: (values[0] - self.f0).abs(),
            constraint_error,
        })
    }
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
