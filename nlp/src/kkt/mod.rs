//! Assembly, factorisation (LDLᵀ without pivoting: faer's supernodal one, or our own
//! simplicial one on faer's symbolic analysis), inertia and solution of the symmetric
//! quasi-definite KKT system
//!
//! ```text
//! K = [ W + diag(dx)   Jᵀ         ]
//!     [ J             −diag(dc)   ]
//! ```
//!
//! The pattern, the AMD ordering and the symbolic factorisation are computed once in
//! [`Kkt::new`]; every [`Kkt::factorize`] only scatters values through precomputed maps.
//! When faer's analysis picks the simplicial factorisation, K is stored already permuted
//! and factorised by `Simplicial` (up-looking LDLᵀ with the rows of L precomputed).
//! faer has no inertia API, so the inertia is counted from the signs of D (Sylvester's law
//! of inertia). Unpivoted LDLᵀ needs `dc > 0` on every row (see docs/dependencies.md).
//!
//! The parts:
//! - `system`: [`Kkt`], its pattern, symbolic analysis and work space, built once;
//! - `inertia`: [`Inertia`];
//! - `assembly`: scattering the values into K and products with K;
//! - `pattern`: the upper triangle of K and the maps from the Hessian's and the
//!   Jacobian's entries into it;
//! - `factor`: the numeric factorisation, the inertia and ln |det K|;
//! - `simplicial`: our own up-looking LDLᵀ of the permuted K;
//! - `refine`: solves with residual-checked iterative refinement (`solve_shifted`);
//! - `error`: [`KktError`];
//! - `low_rank`: K plus a low-rank term (Sherman–Morrison–Woodbury), for L-BFGS.

mod assembly;
mod error;
mod factor;
mod inertia;
mod low_rank;
mod pattern;
mod refine;
mod simplicial;
mod system;
#[cfg(test)]
mod tests;

pub use error::KktError;
pub use inertia::Inertia;
pub(crate) use low_rank::{LowRankKkt, LowRankTerm};
pub use system::Kkt;
#[cfg(test)]
use system::KktFactorization;
