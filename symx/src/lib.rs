//! symx: a small CasADi-like scalar expression graph.
//!
//! * [`Expr`]: scalar expressions with operator overloading (`f64` on either side) and
//!   the usual math functions; [`Matrix`]: dense matrices and vectors of them.
//! * Automatic differentiation producing expressions: [`forward`], [`reverse`],
//!   [`gradient`], [`jacobian`], [`hessian`], [`lagrangian_hessian`].
//! * Structural sparsity ([`Sparsity`], faer's CSC pattern).
//! * [`Function`]: compilation to an allocation-free, `Send + Sync` evaluator.
//!
//! ```
//! use symx::{Function, Matrix, gradient};
//! let x = Matrix::sym_vec("x", 2);
//! let f = (1.0 - x[0]).sq() + 100.0 * (x[1] - x[0].sq()).sq(); // Rosenbrock
//! let grad = gradient(f, &x).unwrap();
//! let fun = Function::new(&[&x], &[&[f], &grad]).unwrap();
//! let out = fun.call(&[&[1.0, 1.0]]).unwrap();
//! assert_eq!(out, vec![vec![0.0], vec![0.0, 0.0]]);
//! ```
//!
//! Expressions live in a graph owned by the current thread; a compiled [`Function`] is
//! independent of it and can be shared across threads. [`with_fresh_arena`] runs a
//! build in a graph of its own and frees it afterwards.
mod ad;
mod assemble;
mod call;
mod compile;
mod consing;
mod display;
mod error;
mod expr;
mod external;
mod function;
mod graph;
mod interpolant;
mod interpret;
mod linalg;
mod map;
mod matrix;
mod native;
mod op;
mod schedule;
mod serialize;
mod simplify;
pub mod sparsity;
mod table;
mod team;

pub use ad::{forward, gradient, hessian, jacobian, lagrangian_hessian, reverse};
pub use display::parse;
pub use error::SymxError;
pub use expr::{and, eq, ge, gt, if_else, le, logsumexp, lt, ne, not, or, Expr};
pub use external::ExternalEval;
pub use function::Function;
pub use graph::{node_count, with_fresh_arena};
pub use interpolant::{Interpolant, Interpolant2, InterpolantN};
pub use map::Map;
pub use matrix::{Matrix, SparseMatrix};
pub use native::{Evaluator, SourceOptions};
pub use op::Op;
pub use serialize::{FunctionFileError, FUNCTION_FILE_FORMAT, FUNCTION_FILE_VERSION};
pub use sparsity::Sparsity;

/// The guide `docs/dsl.md`, compiled and run as doc tests so that its examples stay true.
#[cfg(doctest)]
#[doc = include_str!("../../docs/dsl.md")]
pub struct DslGuide;
