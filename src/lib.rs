//! symnlp: write nonlinear programs symbolically and solve them.
//!
//! This crate re-exports the two building blocks:
//! - [`symx`]: the expression graph, automatic differentiation, sparsity and compiled evaluators;
//! - [`nlp`]: the problem builder and the solvers.
pub use nlp;
pub use symx;
