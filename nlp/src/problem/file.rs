//! [`Problem`]s saved to and loaded from a versioned JSON file, following the solution
//! file's conventions (`nlp::solution_file`).
//!
//! The file is one JSON object `{"format": "symnlp.problem", "version": 1, "problem":
//! {...}}` whose `problem` holds:
//!
//! | field | meaning |
//! |---|---|
//! | `variables`, `parameters`, `constraints` | the named blocks (`name`, `start`, `len`) in declaration order |
//! | `lower`, `upper` | variable bounds, `null` for −∞ (lower) and +∞ (upper) |
//! | `initial` | the initial point |
//! | `parameter_values` | the parameters' values, `null` where unset |
//! | `row_lower`, `row_upper` | every constraint row's bounds as written, `null` for ∓∞ |
//! | `detect_simple_bounds` | [`Problem::set_detect_simple_bounds`] |
//! | `function` | a `symx.function` file (`symx::Function::to_json`) of `(x, p) ↦ (f, g)`: the objective and every row, compiled with common subexpressions shared |
//!
//! Loading declares the same variables and parameters (same names, order and values) and
//! writes the function's operations out again as expressions
//! ([`symx::Function::inline`]): the loaded problem's objective and constraints evaluate
//! bit-identically. Its derivatives are built again by automatic differentiation on the
//! loaded graph, whose nodes are numbered differently, so sums of adjoints may associate
//! differently: iterates agree to rounding (a few ulps on a Van der Pol OCP, bit for bit on
//! HS071; `nlp/tests/problem_file.rs`). Solver
//! options are not part of a problem: save them with serde (`IpmOptions`, `SqpOptions`
//! are serde types). Complementarity constraints and cones are not held by version 1
//! (an error names them), nor external functions (a `symx` error names them).
use super::{Block, Problem};
use crate::constraint::{bounded, Constraint};
use serde::{Deserialize, Serialize};
use symx::{Expr, Function, FunctionFileError};
use thiserror::Error;

/// The `format` field of a problem file.
pub const PROBLEM_FILE_FORMAT: &str = "symnlp.problem";
/// The format version this build writes and reads.
pub const PROBLEM_FILE_VERSION: u32 = 1;

/// Why a problem could not be saved or loaded.
#[derive(Debug, Error)]
pub enum ProblemFileError {
    /// Reading or writing the file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The system's error.
        source: std::io::Error,
    },
    /// The text is not a problem file (not JSON, another `format`, missing fields, sizes
    /// that disagree).
    #[error("not a valid symnlp problem file: {why}")]
    Format {
        /// What is wrong.
        why: String,
    },
    /// The file was written in another format version.
    #[error("problem file format version {found} cannot be read by this build, which reads version {expected}")]
    Version {
        /// The file's version.
        found: u64,
        /// The version this build reads.
        expected: u32,
    },
    /// Something the format cannot hold.
    #[error("cannot save the problem: {what}")]
    Unsupported {
        /// What it is.
        what: String,
    },
    /// The embedded function could not be written or read.
    #[error(transparent)]
    Function(#[from] FunctionFileError),
    /// Rebuilding the problem failed.
    #[error(transparent)]
    Build(#[from] super::BuildError),
    /// An error from symx.
    #[error(transparent)]
    Symx(#[from] symx::SymxError),
}

#[derive(Serialize, Deserialize)]
struct ProblemData {
    variables: Vec<Block>,
    lower: Vec<Option<f64>>,
    upper: Vec<Option<f64>>,
    initial: Vec<f64>,
    parameters: Vec<Block>,
    parameter_values: Vec<Option<f64>>,
    constraints: Vec<Block>,
    row_lower: Vec<Option<f64>>,
    row_upper: Vec<Option<f64>>,
    detect_simple_bounds: bool,
    function: serde_json::Value,
}

#[derive(Serialize, Deserialize)]
struct Envelope {
    format: String,
    version: u64,
    problem: ProblemData,
}

#[derive(Deserialize)]
struct Header {
    format: Option<String>,
    version: Option<u64>,
}

fn bad(why: String) -> ProblemFileError {
    ProblemFileError::Format { why }
}

/// `v` with `None` for the infinity `open` (−∞ for lower bounds, +∞ for upper ones); NaN,
/// the other infinity and (with `open` 0) any infinity cannot be written.
fn encode(what: &str, v: &[f64], open: f64) -> Result<Vec<Option<f64>>, ProblemFileError> {
    v.iter()
        .enumerate()
        .map(|(i, &x)| match x {
            x if x.is_finite() => Ok(Some(x)),
            x if x == open && open != 0.0 => Ok(None),
            x => Err(ProblemFileError::Unsupported {
                what: format!("{what}[{i}] is {x}, which the file cannot hold"),
            }),
        })
        .collect()
}

fn decode(v: &[Option<f64>], open: f64) -> Vec<f64> {
    v.iter().map(|x| x.unwrap_or(open)).collect()
}

impl Problem {
    /// This problem as the text of a problem file (see the module notes). Errors: a
    /// complementarity constraint or a cone, a non-finite initial value or parameter value,
    /// an external function in an expression.
    ///
    /// ```
    /// use nlp::{Ipm, Problem, Relation};
    /// let mut pb = Problem::new();
    /// let x = pb.variable("x", 2)?;
    /// let p = pb.scalar_parameter("p")?;
    /// pb.set_value(p, &[3.0])?;
    /// pb.minimize((x[0] - p).sq() + x[1].sq());
    /// pb.subject_to((x[0] + x[1]).ge(1.0))?;
    /// let loaded = Problem::from_json(&pb.to_json()?)?;
    /// let a = Ipm::default().solve(&mut pb.compile()?)?;
    /// let b = Ipm::default().solve(&mut loaded.compile()?)?;
    /// assert!((a.x[0] - b.x[0]).abs() < 1e-12); // same optimum (to rounding)
    /// assert_eq!(loaded.evaluate(&[loaded.objective()], &b.x)?[0].to_bits(),
    ///            pb.evaluate(&[pb.objective()], &b.x)?[0].to_bits()); // f bit for bit
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn to_json(&self) -> Result<String, ProblemFileError> {
        if let Some((name, _, _)) = self.complementarity.first() {
            return Err(ProblemFileError::Unsupported {
                what: format!("complementarity constraint '{name}' (not in version 1)"),
            });
        }
        if !self.cones.is_empty() {
            return Err(ProblemFileError::Unsupported {
                what: "a cone constraint (not in version 1)".into(),
            });
        }
        let mut outputs = vec![self.objective()];
        outputs.extend(self.rows.iter().map(|r| r.expr));
        let f = Function::named(
            "problem",
            &[("x", &self.variables), ("p", &self.parameters)],
            &[("f", &outputs[..1]), ("g", &outputs[1..])],
        )?;
        let lower: Vec<f64> = self.rows.iter().map(|r| r.lower).collect();
        let upper: Vec<f64> = self.rows.iter().map(|r| r.upper).collect();
        let values: Vec<f64> = self.parameter_values.iter().flatten().copied().collect();
        encode("parameter value", &values, 0.0)?;
        let data = ProblemData {
            variables: self.variable_blocks.clone(),
            lower: encode("variable lower bound", &self.lower, f64::NEG_INFINITY)?,
            upper: encode("variable upper bound", &self.upper, f64::INFINITY)?,
            initial: encode("initial value", &self.initial, 0.0)?
                .into_iter()
                .flatten()
                .collect(),
            parameters: self.parameter_index.blocks().to_vec(),
            parameter_values: self.parameter_values.clone(),
            constraints: self.constraint_blocks.clone(),
            row_lower: encode("constraint lower bound", &lower, f64::NEG_INFINITY)?,
            row_upper: encode("constraint upper bound", &upper, f64::INFINITY)?,
            detect_simple_bounds: self.detect_simple_bounds,
            function: serde_json::from_str(&f.to_json()?).map_err(|e| bad(e.to_string()))?,
        };
        let file = Envelope {
            format: PROBLEM_FILE_FORMAT.into(),
            version: PROBLEM_FILE_VERSION.into(),
            problem: data,
        };
        serde_json::to_string(&file).map_err(|e| bad(e.to_string()))
    }

    /// A problem from the text of a problem file (see the module notes). Errors: not a
    /// problem file or a damaged one ([`ProblemFileError::Format`]), another version
    /// ([`ProblemFileError::Version`]).
    pub fn from_json(text: &str) -> Result<Problem, ProblemFileError> {
        let header: Header = serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
        if header.format.as_deref() != Some(PROBLEM_FILE_FORMAT) {
            return Err(bad(format!(
                "the field \"format\" is {:?}, expected \"{PROBLEM_FILE_FORMAT}\"",
                header.format
            )));
        }
        match header.version {
            Some(v) if v == u64::from(PROBLEM_FILE_VERSION) => {}
            Some(found) => {
                return Err(ProblemFileError::Version {
                    found,
                    expected: PROBLEM_FILE_VERSION,
                })
            }
            None => return Err(bad("no \"version\" field".into())),
        }
        let file: Envelope = serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
        rebuild(file.problem)
    }

    /// Saves this problem to the file `path` ([`Problem::to_json`]).
    pub fn save(&self, path: impl AsRef<std::path::Path>) -> Result<(), ProblemFileError> {
        let path = path.as_ref();
        std::fs::write(path, self.to_json()?).map_err(|source| ProblemFileError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// Loads a problem saved by [`Problem::save`].
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<Problem, ProblemFileError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| ProblemFileError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Problem::from_json(&text)
    }
}

/// Blocks that tile `0..n` in order.
fn check_blocks(what: &str, blocks: &[Block], n: usize) -> Result<(), ProblemFileError> {
    let mut next = 0;
    for b in blocks {
        if b.start != next {
            return Err(bad(format!(
                "{what} '{}' starts at {}, expected {next}",
                b.name, b.start
            )));
        }
        next += b.len;
    }
    if next != n {
        return Err(bad(format!(
            "{what} blocks cover {next} entries, the file has {n}"
        )));
    }
    Ok(())
}

/// The problem described by `d`.
fn rebuild(d: ProblemData) -> Result<Problem, ProblemFileError> {
    let f = Function::from_json(&d.function.to_string())?;
    let (n, m) = (d.lower.len(), d.row_lower.len());
    let sizes_agree = d.upper.len() == n
        && d.initial.len() == n
        && d.row_upper.len() == m
        && f.input_sizes() == [n, d.parameter_values.len()]
        && f.output_sizes() == [1, m];
    if !sizes_agree {
        return Err(bad(
            "the sizes of the bounds, values and function disagree".into()
        ));
    }
    check_blocks("variable", &d.variables, n)?;
    check_blocks("parameter", &d.parameters, d.parameter_values.len())?;
    check_blocks("constraint", &d.constraints, m)?;
    let mut pb = Problem::new();
    pb.set_detect_simple_bounds(d.detect_simple_bounds);
    let (lower, upper) = (
        decode(&d.lower, f64::NEG_INFINITY),
        decode(&d.upper, f64::INFINITY),
    );
    for b in &d.variables {
        let x = pb.variable(&b.name, b.len)?;
        for (k, &xi) in x.iter().enumerate() {
            pb.set_bounds(&[xi], lower[b.start + k], upper[b.start + k])?;
        }
        pb.set_initial(&x, &d.initial[b.range()])?;
    }
    for b in &d.parameters {
        let p = pb.parameter(&b.name, b.len)?;
        for (k, &pk) in p.iter().enumerate() {
            if let Some(v) = d.parameter_values[b.start + k] {
                pb.set_value(pk, &[v])?;
            }
        }
    }
    let (x, p) = (pb.variables.clone(), pb.parameters.clone());
    let mut out = f.inline(&[&x, &p])?.into_iter();
    let objective = out.next().unwrap_or_default();
    let rows: Vec<Expr> = out.next().unwrap_or_default();
    pb.minimize(objective[0]);
    let (row_lower, row_upper) = (
        decode(&d.row_lower, f64::NEG_INFINITY),
        decode(&d.row_upper, f64::INFINITY),
    );
    for b in &d.constraints {
        let c = Constraint::all(
            b.range()
                .map(|i| bounded(row_lower[i], rows[i], row_upper[i])),
        );
        pb.subject_to_named(&b.name, c)?;
    }
    Ok(pb)
}
