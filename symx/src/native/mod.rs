//! Native evaluation of a [`Function`](crate::Function): its tape compiled to machine code
//! in-process by Cranelift ([`Function::jit`](crate::Function::jit)), and source code
//! generated for deployment.
//!
//! The tape stays the reference: the native code performs the same IEEE operations in the
//! same order on the same registers (no fused multiply-add, no reassociation), and the math
//! functions (`sin`, `exp`, `pow`, ...) call the very Rust functions the tape calls, so the
//! results are bit-identical to the tape's, NaN and infinities included.
mod c_source;
#[cfg(feature = "jit")]
mod constant_pairs;
#[cfg(feature = "jit")]
mod jit;
#[cfg(feature = "jit")]
mod lanes;
mod places;
mod rust_source;

use crate::error::SymxError;
use crate::function::Function;
use crate::op::Op;
use crate::sparsity::Sparsity;

/// Options of the generated source ([`Function::to_c_with`], [`Function::to_rust_with`]).
#[derive(Clone, Debug, Default)]
pub struct SourceOptions {
    /// The sparsity pattern of each output, by output index: the output's entries are the
    /// pattern's nonzeros in column-major order (as [`crate::SparseMatrix::values`] lists
    /// them), so its number of nonzeros must equal the output's size. `None` or missing:
    /// a dense column.
    pub output_sparsity: Vec<Option<Sparsity>>,
}

impl SourceOptions {
    /// The pattern of every output of `f` (a dense column where none is given); `Err`
    /// naming the output whose pattern does not match it.
    pub(crate) fn output_patterns(&self, f: &Function) -> Result<Vec<Sparsity>, SymxError> {
        if self.output_sparsity.len() > f.output_sizes.len() {
            return Err(SymxError::Jit {
                message: format!(
                    "{} output sparsity patterns given, but the function '{}' has {} outputs",
                    self.output_sparsity.len(),
                    f.name,
                    f.output_sizes.len()
                ),
            });
        }
        (0..f.output_sizes.len())
            .map(|k| match self.output_sparsity.get(k) {
                Some(Some(s)) if s.compute_nnz() != f.output_sizes[k] => Err(SymxError::Jit {
                    message: format!(
                        "the sparsity pattern of output {k} ('{}') has {} nonzeros, but the output has {} entries",
                        f.output_names[k],
                        s.compute_nnz(),
                        f.output_sizes[k]
                    ),
                }),
                Some(Some(s)) => Ok(s.clone()),
                _ => Ok(c_source::dense(f.output_sizes[k])),
            })
            .collect()
    }
}

/// The C library function computing a unary operation exactly as Rust's `std` does (the
/// same glibc function), for generated source.
fn library_unary(op: Op) -> Option<&'static str> {
    Some(match op {
        Op::Exp => "exp",
        Op::Log => "log",
        Op::Sin => "sin",
        Op::Cos => "cos",
        Op::Tan => "tan",
        Op::Asin => "asin",
        Op::Acos => "acos",
        Op::Atan => "atan",
        Op::Sinh => "sinh",
        Op::Cosh => "cosh",
        Op::Tanh => "tanh",
        Op::Log1p => "log1p",
        Op::Expm1 => "expm1",
        Op::Sqrt => "sqrt",
        Op::Floor => "floor",
        Op::Ceil => "ceil",
        _ => return None,
    })
}

/// The C library function computing a binary operation exactly as Rust's `std` does.
fn library_binary(op: Op) -> Option<&'static str> {
    Some(match op {
        Op::Atan2 => "atan2",
        Op::Hypot => "hypot",
        Op::Fmod => "fmod",
        _ => return None,
    })
}

/// The error for an operation that `language`'s generated source cannot compute exactly.
fn unsupported(language: &str, op: Op) -> SymxError {
    let why = match op {
        Op::Interpolant | Op::Interpolant2 | Op::InterpolantN => "lookup tables are not generated",
        Op::Erf | Op::Asinh | Op::Acosh | Op::Atanh => {
            "its C library function differs from the one symx uses"
        }
        _ => "not supported",
    };
    SymxError::Jit {
        message: format!(
            "{language} source generation does not support the operation '{}' ({why}); evaluate this function with the tape or the JIT",
            op.name()
        ),
    }
}

/// How a compiled [`Function`] evaluates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Evaluator {
    /// The instruction tape, run by an interpreter loop (always available; the reference).
    #[default]
    Tape,
    /// Machine code compiled from the tape by Cranelift when the function is compiled
    /// (needs the default cargo feature `jit`); bit-identical results, several times faster
    /// on large functions, at a compile time of about a microsecond per instruction.
    Jit,
}

/// Most inputs (and outputs) a native call passes by pointer arrays on the stack
/// ([`Entry`]); functions with more are run with their inputs and outputs in the work vector.
pub(crate) const MAX_DIRECT: usize = 16;

/// The machine code of a function: `entry(w, args, res)` reads input `k` from `args[k]`
/// and writes output `k` to `res[k]`, using `w` (the function's `work_size` numbers) as
/// scratch; with `args` and `res` null it reads the inputs from, and writes the outputs
/// to, their registers in `w`, as the tape does.
pub(crate) type Entry = unsafe extern "C" fn(*mut f64, *const *const f64, *const *mut f64);

/// The machine code of one function (and of the functions it calls), kept alive as long
/// as a [`Function`] refers to it.
#[cfg_attr(not(feature = "jit"), allow(dead_code))] // never built without the feature
pub(crate) struct NativeCode {
    /// Runs the function (see [`Entry`]).
    pub entry: Entry,
    #[cfg(feature = "jit")]
    #[allow(dead_code)] // owns the code memory and what the code reads
    owner: jit::Owner,
    /// Number of machine-code functions and tape instructions compiled (callees included).
    functions: usize,
    instructions: usize,
}

impl std::fmt::Debug for NativeCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "NativeCode({} functions, {} instructions)",
            self.functions, self.instructions
        )
    }
}

/// Compiles `f` (and every function it calls) to machine code.
#[cfg(feature = "jit")]
pub(crate) fn compile(f: &Function) -> Result<NativeCode, SymxError> {
    let (entry, owner, functions, instructions) = jit::compile(f)?;
    Ok(NativeCode {
        entry,
        owner,
        functions,
        instructions,
    })
}

/// Without the `jit` feature there is no native code.
#[cfg(not(feature = "jit"))]
pub(crate) fn compile(_f: &Function) -> Result<NativeCode, SymxError> {
    Err(SymxError::Jit {
        message: "symx was built without its `jit` feature".into(),
    })
}
