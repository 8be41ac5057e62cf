//! The Python package `symnlp` (module `symnlp._symnlp`): thin PyO3 wrappers over the
//! Rust crates `symx` (expressions, derivatives, compiled functions), `nlp` (problem
//! builder, IPM and SQP back ends) and `gap_crossing` (the planner). No algorithm lives
//! here: every call converts its arguments, calls the Rust API and converts the result.
//!
//! Expressions live in the graph of the thread that made them (symx's thread-local
//! arena), so `Expr` and `Problem` objects are bound to their thread (`unsendable`);
//! compiled functions and solutions are not. Compilation and solves release the GIL.
mod error;
mod expr;
mod function;
mod gap;
mod method;
mod mpc;
mod ocp;
mod problem;
mod same_thread;
mod solution;
mod trajectory;
mod transcription;

use pyo3::prelude::*;

/// The native module; `symnlp/__init__.py` re-exports its contents.
#[pymodule]
fn _symnlp(m: &Bound<'_, PyModule>) -> PyResult<()> {
    error::register(m)?;
    expr::register(m)?;
    function::register(m)?;
    problem::register(m)?;
    solution::register(m)?;
    gap::register(m)?;
    method::register(m)?;
    ocp::register(m)?;
    transcription::register(m)?;
    trajectory::register(m)?;
    mpc::register(m)?;
    Ok(())
}
