//! [`BuildError`]: mistakes in a problem definition or in setting its values.
use thiserror::Error;

/// A mistake in a problem definition, naming the culprit.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum BuildError {
    /// A lower bound above an upper bound.
    #[error("{what}: lower bound {lower} > upper bound {upper}")]
    InvertedBounds {
        /// What the bounds belong to.
        what: String,
        /// The lower bound.
        lower: f64,
        /// The upper bound.
        upper: f64,
    },
    /// NaN (or ∞ where a finite value is required).
    #[error("{what}: {value} is not allowed")]
    NotFinite {
        /// What the value belongs to.
        what: String,
        /// The value.
        value: f64,
    },
    /// Two lengths that must agree.
    #[error("{what}: expected {expected} values, got {got}")]
    Size {
        /// What was given.
        what: String,
        /// The length required.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// An expression used where a variable (or parameter) of this problem is required.
    #[error("{what}: entry {index} is not a {kind} of this problem")]
    NotDeclared {
        /// The call and the offending expression.
        what: String,
        /// Its position in the slice given.
        index: usize,
        /// "variable" or "parameter".
        kind: &'static str,
    },
    /// A name that no variable (or parameter) was declared under.
    #[error("no {kind} is named '{name}'")]
    UnknownName {
        /// "variable" or "parameter".
        kind: &'static str,
        /// The name given.
        name: String,
    },
    /// Handles used on a thread other than the one that built the problem.
    #[error(
        "{what}: symbolic handles belong to the thread that built the problem; \
         on another thread set parameters by name"
    )]
    ForeignThread {
        /// The call.
        what: String,
    },
    /// A parameter whose value was never set.
    #[error("parameter '{name}' has no value (call set_value)")]
    MissingParameterValue {
        /// The parameter entry.
        name: String,
    },
    /// An expression depends on a symbol that is neither a variable nor a parameter.
    #[error(
        "{location} depends on symbol '{name}', which is neither a variable nor a parameter \
         of this problem"
    )]
    FreeSymbol {
        /// Where the expression was used.
        location: String,
        /// The symbol.
        name: String,
    },
    /// A constraint between matrices of different shapes.
    #[error("constraint '{name}': shapes {left:?} and {right:?} differ")]
    ShapeMismatch {
        /// The constraint.
        name: String,
        /// Shape of the left side.
        left: (usize, usize),
        /// Shape of the right side.
        right: (usize, usize),
    },
    /// A constraint that does not involve any variable.
    #[error("constraint '{name}' row {row} does not depend on any variable")]
    ConstantConstraint {
        /// The constraint.
        name: String,
        /// The row within it.
        row: usize,
    },
    /// A name used twice for variables or parameters.
    #[error("the name '{name}' is already used by a variable or parameter")]
    DuplicateName {
        /// The name.
        name: String,
    },
    /// An error from symx while differentiating or compiling.
    #[error(transparent)]
    Symx(#[from] symx::SymxError),
}
