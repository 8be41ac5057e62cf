#![doc = include_str!("../README.md")]
//!
//! This crate re-exports the two building blocks: [`symx`] (expressions, derivatives,
//! sparsity, compiled functions) and [`nlp`] (problem builder and solvers).
pub use nlp;
pub use symx;
