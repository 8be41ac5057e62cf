//! Python exceptions carrying the Rust error messages.
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    symnlp,
    SymnlpError,
    PyException,
    "Base class of every error raised by symnlp."
);
create_exception!(
    symnlp,
    BuildError,
    SymnlpError,
    "A problem, expression or function could not be built (the message names what is wrong)."
);
create_exception!(
    symnlp,
    OptionError,
    SymnlpError,
    "A solver option was refused: unknown name (with suggestions), bad value or out of range."
);
create_exception!(
    symnlp,
    SolveError,
    SymnlpError,
    "A solve could not run (invalid input, evaluation error)."
);

/// Converts a Rust error into [`BuildError`].
pub fn build_err(e: impl std::fmt::Display) -> PyErr {
    BuildError::new_err(e.to_string())
}

/// Converts a Rust error into [`OptionError`].
pub fn option_err(e: impl std::fmt::Display) -> PyErr {
    OptionError::new_err(e.to_string())
}

/// Converts a Rust error into [`SolveError`].
pub fn solve_err(e: impl std::fmt::Display) -> PyErr {
    SolveError::new_err(e.to_string())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SymnlpError", py.get_type::<SymnlpError>())?;
    m.add("BuildError", py.get_type::<BuildError>())?;
    m.add("OptionError", py.get_type::<OptionError>())?;
    m.add("SolveError", py.get_type::<SolveError>())?;
    Ok(())
}
