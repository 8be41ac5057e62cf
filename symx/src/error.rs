//! Errors of the symx crate.
use thiserror::Error;

/// What can go wrong when building derivatives, compiling or evaluating.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SymxError {
    /// An expression used where a symbol is required (e.g. differentiating with respect to `x*y`).
    #[error("{what}: entry {index} is not a symbol")]
    NotASymbol { what: String, index: usize },
    /// A symbol listed twice among a function's or derivative's inputs.
    #[error("{what}: symbol '{name}' appears more than once")]
    DuplicateSymbol { what: String, name: String },
    /// An output depends on a symbol that is not among the inputs.
    #[error("output {output} depends on symbol '{name}', which is not an input")]
    FreeSymbol { output: usize, name: String },
    /// Wrong number of input or output arguments.
    #[error("expected {expected} {what}, got {got}")]
    ArgumentCount {
        what: &'static str,
        expected: usize,
        got: usize,
    },
    /// An input or output slice of the wrong length.
    #[error("{what} {index} has length {got}, expected {expected}")]
    Length {
        what: &'static str,
        index: usize,
        expected: usize,
        got: usize,
    },
    /// Matrix dimensions that do not fit the operation.
    #[error("dimension mismatch in {op}: {left:?} and {right:?}")]
    Dimension {
        op: &'static str,
        left: (usize, usize),
        right: (usize, usize),
    },
    /// Two inputs or two outputs of a function with the same name.
    #[error("{what} name '{name}' appears more than once")]
    DuplicateName { what: &'static str, name: String },
    /// The thread pool of a parallel [`crate::Map`] could not be built.
    #[error("could not start threads: {message}")]
    Threads { message: String },
    /// Bad data for a lookup table ([`crate::Interpolant`]).
    #[error("interpolant: {reason}")]
    Table { reason: String },
    /// Native code could not be generated ([`crate::Function::jit`]), or symx was built
    /// without its `jit` feature.
    #[error("native code generation failed: {message}")]
    Jit { message: String },
    /// [`crate::Function::with_jacobian`] on a function that is not external.
    #[error("function '{name}' is not external: only an external function takes a user-supplied Jacobian")]
    NotExternal { name: String },
    /// A derivative through an external function that has none (see
    /// [`crate::Function::with_jacobian`]); for a second derivative, `name` is the
    /// Jacobian function (give it a Jacobian of its own).
    #[error("cannot differentiate external function '{name}': it has no Jacobian (give one with Function::with_jacobian)")]
    NoDerivative { name: String },
    /// A syntax error in [`crate::parse`].
    #[error("parse error at byte {position}: {message}")]
    Parse { position: usize, message: String },
}
