//! Native evaluation of a [`Function`](crate::Function): its tape compiled to machine code
//! in-process by Cranelift ([`Function::jit`](crate::Function::jit)), and source code
//! generated for deployment.
//!
//! The tape stays the reference: the native code performs the same IEEE operations in the
//! same order on the same registers (no fused multiply-add, no reassociation), and the math
//! functions (`sin`, `exp`, `pow`, ...) call the very Rust functions the tape calls, so the
//! results are bit-identical to the tape's, NaN and infinities included.
#[cfg(feature = "jit")]
mod jit;
mod rust_source;

use crate::error::SymxError;
use crate::function::Function;

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

/// The machine code of one function (and of the functions it calls), kept alive as long
/// as a [`Function`] refers to it.
#[cfg_attr(not(feature = "jit"), allow(dead_code))] // never built without the feature
pub(crate) struct NativeCode {
    /// Runs the function on a work vector whose input registers are filled (the tape's
    /// `exec`: template copy included).
    pub entry: unsafe extern "C" fn(*mut f64),
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
