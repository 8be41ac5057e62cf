//! [`Function`]s saved to and loaded from a versioned JSON file, so that a function
//! compiled in one process evaluates bit-identically in another.
//!
//! The file is one JSON object
//! `{"format": "symx.function", "version": 1, "functions": [...]}`. `functions` lists the
//! saved function last and, before it, every function it calls (callees before callers,
//! each once). Each entry is the compiled tape itself, not the expressions it came from:
//!
//! | field | meaning |
//! |---|---|
//! | `name`, `input_names`, `output_names`, `input_sizes`, `output_sizes` | the signature |
//! | `work_size` | registers of the work vector |
//! | `input_offsets`, `output_offsets` | register of entry 0 of each input / output |
//! | `input_used` | whether the tape reads each input |
//! | `tape` | instructions `[op, d, a, b, c]`: `op` an [`crate::Op`] variant name, `d` the destination register (for `Call` the call's index), `a`, `b`, `c` operand registers (`c` a table's index for lookups) |
//! | `template_start`, `constants` | values copied to registers `template_start…` before each run: the constants and the output slots |
//! | `tables` | lookup tables: `grids`, `coeffs` (`4^d` per cell), `extrapolate` |
//! | `calls`, `call_scratch` | calls: `function` (its index in `functions`), `args` (argument registers), `out` (first output register); callees run at register `call_scratch` |
//!
//! Numbers are written in the shortest form that reads back to the same `f64` bit for bit
//! (`-0.0` included); `±∞` and NaN, which JSON lacks, as the strings `"inf"`, `"-inf"`,
//! `"nan"`. Loading checks every register, call and table index against the sizes, so a
//! damaged file is an error, never an out-of-bounds access. External functions (user
//! code: [`Function::external`]) cannot be saved ([`FunctionFileError::External`]); a
//! function compiled to native code is saved as its tape and loads as a tape function
//! (the same values: native code agrees with the tape bit for bit).
//!
//! A file of another format version is refused with an error naming both versions
//! ([`FunctionFileError::Version`]); [`FUNCTION_FILE_VERSION`] is the version written.
use crate::call::CallInstr;
use crate::function::{next_uid, Function, Instr};
use crate::interpret::Tape;
use crate::op::Op;
use crate::table::Table;
use serde::{Deserialize, Serialize};
use std::sync::{Arc, Mutex, OnceLock};
use thiserror::Error;

/// The `format` field of a function file.
pub const FUNCTION_FILE_FORMAT: &str = "symx.function";
/// The format version this build writes and reads.
pub const FUNCTION_FILE_VERSION: u32 = 1;

/// Why a function could not be saved or loaded.
#[derive(Debug, Error)]
pub enum FunctionFileError {
    /// Reading or writing the file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The system's error.
        source: std::io::Error,
    },
    /// The text is not a function file, or it is damaged (not JSON, another `format`,
    /// missing fields, an index out of range).
    #[error("not a valid symx function file: {why}")]
    Format {
        /// What is wrong.
        why: String,
    },
    /// The file was written in another format version.
    #[error("function file format version {found} cannot be read by this build, which reads version {expected}")]
    Version {
        /// The file's version.
        found: u64,
        /// The version this build reads.
        expected: u32,
    },
    /// The function is or calls an external function (user code), which a file cannot hold.
    #[error("function '{name}' is external (user code) and cannot be saved to a file")]
    External {
        /// The external function's name.
        name: String,
    },
}

/// A number that may be non-finite: a JSON number, or `"inf"`, `"-inf"`, `"nan"`.
#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum Number {
    Finite(f64),
    Special(String),
}

impl Number {
    fn new(v: f64) -> Number {
        match v {
            v if v.is_finite() => Number::Finite(v),
            v if v.is_nan() => Number::Special("nan".into()),
            v if v > 0.0 => Number::Special("inf".into()),
            _ => Number::Special("-inf".into()),
        }
    }

    fn value(&self) -> Result<f64, FunctionFileError> {
        match self {
            Number::Finite(v) => Ok(*v),
            Number::Special(s) => match s.as_str() {
                "nan" => Ok(f64::NAN),
                "inf" => Ok(f64::INFINITY),
                "-inf" => Ok(f64::NEG_INFINITY),
                _ => Err(bad(format!("'{s}' is not a number"))),
            },
        }
    }
}

#[derive(Serialize, Deserialize)]
struct CallData {
    function: usize,
    args: Vec<u32>,
    out: u32,
}

#[derive(Serialize, Deserialize)]
struct FunctionData {
    name: String,
    input_names: Vec<String>,
    output_names: Vec<String>,
    input_sizes: Vec<usize>,
    output_sizes: Vec<usize>,
    work_size: usize,
    input_offsets: Vec<usize>,
    output_offsets: Vec<usize>,
    input_used: Vec<bool>,
    tape: Vec<(Op, u32, u32, u32, u32)>,
    template_start: usize,
    constants: Vec<Number>,
    tables: Vec<Table>,
    calls: Vec<CallData>,
    call_scratch: usize,
}

#[derive(Serialize, Deserialize)]
struct FileData {
    format: String,
    version: u64,
    functions: Vec<FunctionData>,
}

#[derive(Deserialize)]
struct Header {
    format: Option<String>,
    version: Option<u64>,
}

fn bad(why: String) -> FunctionFileError {
    FunctionFileError::Format { why }
}

/// Lists `f` and its callees, callees first, each once (by identity).
fn collect<'a>(f: &'a Function, out: &mut Vec<&'a Function>) -> Result<usize, FunctionFileError> {
    if let Some(k) = out.iter().position(|g| g.uid == f.uid) {
        return Ok(k);
    }
    if f.external.is_some() {
        return Err(FunctionFileError::External {
            name: f.name.clone(),
        });
    }
    for call in &f.calls {
        collect(&call.function, out)?;
    }
    out.push(f);
    Ok(out.len() - 1)
}

fn to_data(f: &Function, list: &[&Function]) -> FunctionData {
    let index = |g: &Function| list.iter().position(|h| h.uid == g.uid).expect("listed");
    FunctionData {
        name: f.name.clone(),
        input_names: f.input_names.clone(),
        output_names: f.output_names.clone(),
        input_sizes: f.input_sizes.clone(),
        output_sizes: f.output_sizes.clone(),
        work_size: f.work_size,
        input_offsets: f.input_offsets.clone(),
        output_offsets: f.output_offsets.clone(),
        input_used: f.input_used.clone(),
        tape: f
            .tape
            .instructions()
            .map(|i| (i.op, i.d, i.a, i.b, i.c))
            .collect(),
        template_start: f.template_start,
        constants: f.template.iter().map(|&v| Number::new(v)).collect(),
        tables: f.tables.iter().map(|t| t.as_ref().clone()).collect(),
        calls: f
            .calls
            .iter()
            .map(|c| CallData {
                function: index(&c.function),
                args: c.args.clone(),
                out: c.out,
            })
            .collect(),
        call_scratch: f.call_scratch,
    }
}

/// Checks that every register, call and table index of `d` is in range, given the
/// functions loaded before it.
fn check(d: &FunctionData, loaded: &[Arc<Function>]) -> Result<(), FunctionFileError> {
    let w = d.work_size;
    let what = |s: &str| format!("function '{}': {s}", d.name);
    let (n_in, n_out) = (d.input_sizes.len(), d.output_sizes.len());
    if d.input_names.len() != n_in
        || d.input_offsets.len() != n_in
        || d.input_used.len() != n_in
        || d.output_names.len() != n_out
        || d.output_offsets.len() != n_out
    {
        return Err(bad(what("inputs or outputs of unequal counts")));
    }
    let fits = |at: usize, n: usize| at.checked_add(n).is_some_and(|e| e <= w);
    let ranges = d.input_offsets.iter().zip(&d.input_sizes);
    let ranges = ranges.chain(d.output_offsets.iter().zip(&d.output_sizes));
    if ranges.clone().any(|(&at, &n)| !fits(at, n)) || !fits(d.template_start, d.constants.len()) {
        return Err(bad(what(
            "an input, output or constant beyond the work vector",
        )));
    }
    let lookup = matches!(d.tape.as_slice(), [(Op::InterpolantN, ..)]);
    for (k, &(op, dst, a, b, c)) in d.tape.iter().enumerate() {
        let reg = |r: u32| (r as usize) < w;
        let table = |dims: usize| d.tables.get(c as usize).is_some_and(|t| t.dims() == dims);
        let ok = reg(a)
            && reg(b)
            && match op {
                Op::Const | Op::CallOutput => false,
                Op::Call => {
                    let Some(call) = d.calls.get(dst as usize) else {
                        return Err(bad(what(&format!("instruction {k} calls no call"))));
                    };
                    let Some(g) = loaded.get(call.function) else {
                        return Err(bad(what(&format!(
                            "call {dst} of a function not before it"
                        ))));
                    };
                    call.args.len() == g.input_sizes.iter().sum::<usize>()
                        && call.args.iter().all(|&r| reg(r))
                        && fits(call.out as usize, g.output_sizes.iter().sum())
                        && fits(d.call_scratch, g.work_size)
                }
                Op::Interpolant => reg(dst) && table(1),
                Op::Interpolant2 => reg(dst) && table(2),
                Op::InterpolantN => {
                    lookup && reg(dst) && fits(a as usize, b as usize) && table(b as usize)
                }
                Op::IfElse => reg(dst) && reg(c),
                _ => reg(dst),
            };
        if !ok {
            return Err(bad(what(&format!("instruction {k} ({op:?}) out of range"))));
        }
    }
    for (k, t) in d.tables.iter().enumerate() {
        t.check()
            .map_err(|why| bad(what(&format!("table {k}: {why}"))))?;
    }
    Ok(())
}

fn from_data(d: FunctionData, loaded: &[Arc<Function>]) -> Result<Function, FunctionFileError> {
    check(&d, loaded)?;
    let template = d
        .constants
        .iter()
        .map(Number::value)
        .collect::<Result<Vec<f64>, _>>()?;
    let calls: Vec<CallInstr> = d
        .calls
        .into_iter()
        .map(|c| CallInstr {
            function: loaded[c.function].clone(),
            args: c.args,
            out: c.out,
        })
        .collect();
    let instrs = d
        .tape
        .into_iter()
        .map(|(op, d, a, b, c)| Instr { op, d, a, b, c });
    let outputs = d
        .output_offsets
        .iter()
        .zip(&d.output_sizes)
        .map(|(&at, &n)| at..at + n);
    let tape = Tape::new(instrs.collect(), &calls, d.work_size, outputs);
    Ok(Function {
        name: d.name,
        input_names: d.input_names,
        output_names: d.output_names,
        uid: next_uid(),
        input_sizes: d.input_sizes,
        output_sizes: d.output_sizes,
        input_offsets: d.input_offsets,
        input_used: d.input_used,
        output_offsets: d.output_offsets,
        tape,
        template,
        template_start: d.template_start,
        work_size: d.work_size,
        tables: d.tables.into_iter().map(Arc::new).collect(),
        calls,
        call_scratch: d.call_scratch,
        dependencies: OnceLock::new(),
        jacobians: Arc::new(Mutex::new(Default::default())),
        native: None,
        external: None,
    })
}

impl Function {
    /// This function as the text of a function file (see the module notes of
    /// `symx::serialize`): its tape, constants, tables and callees. Errors: an external
    /// function, here or among the callees ([`FunctionFileError::External`]).
    ///
    /// ```
    /// use symx::{Function, Matrix};
    /// let x = Matrix::sym_vec("x", 2);
    /// let f = Function::named("f", &[("x", &x)], &[("y", &[x[0].sin() * x[1] / 3.0])]).unwrap();
    /// let g = Function::from_json(&f.to_json().unwrap()).unwrap();
    /// let (a, b) = (f.call(&[&[0.7, 1.1]]).unwrap(), g.call(&[&[0.7, 1.1]]).unwrap());
    /// assert_eq!(a[0][0].to_bits(), b[0][0].to_bits());
    /// assert_eq!((g.name(), g.input_names()), ("f", &["x".to_string()][..]));
    /// ```
    pub fn to_json(&self) -> Result<String, FunctionFileError> {
        let mut list = Vec::new();
        collect(self, &mut list)?;
        let file = FileData {
            format: FUNCTION_FILE_FORMAT.into(),
            version: FUNCTION_FILE_VERSION.into(),
            functions: list.iter().map(|f| to_data(f, &list)).collect(),
        };
        serde_json::to_string(&file).map_err(|e| bad(e.to_string()))
    }

    /// A function from the text of a function file; it evaluates bit-identically to the
    /// function saved, can be called in expressions ([`Function::apply`]) and
    /// differentiated like any compiled function. Errors: not a function file, a damaged
    /// one ([`FunctionFileError::Format`]), another version ([`FunctionFileError::Version`]).
    pub fn from_json(text: &str) -> Result<Function, FunctionFileError> {
        let header: Header = serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
        if header.format.as_deref() != Some(FUNCTION_FILE_FORMAT) {
            return Err(bad(format!(
                "the field \"format\" is {:?}, expected \"{FUNCTION_FILE_FORMAT}\"",
                header.format
            )));
        }
        match header.version {
            Some(v) if v == u64::from(FUNCTION_FILE_VERSION) => {}
            Some(found) => {
                return Err(FunctionFileError::Version {
                    found,
                    expected: FUNCTION_FILE_VERSION,
                })
            }
            None => return Err(bad("no \"version\" field".into())),
        }
        let file: FileData = serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
        let mut loaded: Vec<Arc<Function>> = Vec::with_capacity(file.functions.len());
        for d in file.functions {
            let f = from_data(d, &loaded)?;
            loaded.push(Arc::new(f));
        }
        let last = loaded.pop().ok_or_else(|| bad("no function".into()))?;
        Ok(Arc::try_unwrap(last).unwrap_or_else(|f| (*f).clone()))
    }

    /// Saves this function to the file `path` ([`Function::to_json`]).
    pub fn save(&self, path: impl AsRef<std::path::Path>) -> Result<(), FunctionFileError> {
        let path = path.as_ref();
        std::fs::write(path, self.to_json()?).map_err(|source| FunctionFileError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// Loads a function saved by [`Function::save`].
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<Function, FunctionFileError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| FunctionFileError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Function::from_json(&text)
    }
}
