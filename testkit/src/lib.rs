//! symnlp's test kit: every test problem and test helper that more than one test, bench
//! or crate uses, written once (`publish = false`; for the workspace's own tests and
//! benches).
//!
//! | module | what |
//! |---|---|
//! | [`hs`] | the Hock–Schittkowski problems and the harness of their suites (`hs_suite!`) |
//! | [`mpcc`] | MacMPEC-style complementarity problems with published optima |
//! | [`socp`] | second-order-cone problems with optima derived by hand |
//! | [`cart_pole_mpc`] | the MPC cart-pole NLP built by hand (issue 19's SQP benchmark) |
//! | [`solve_problems`] | the scalable problems of `benches/solve.rs` (hanging chain, Van der Pol) |
//! | [`hanging_chain`], [`quadrotor_ocp`] | the symbolic problems of `benches/symx_eval.rs` |
//! | [`trees`] | random expression trees with an independent evaluator (property tests) |
//! | [`ode`] | right-hand sides of the integrators' tests (Van der Pol, Robertson) |
//! | [`rti_loop`] | a real-time-iteration loop driven step by step, its feedbacks |
//! | [`special`] | special floating-point operands, the NaN-tolerant bit comparison (native evaluators against the tape) |
//! | [`alloc`] | counting global allocators (allocation-free spans) |
//! | [`corpus`] | the test corpus crate (optimal-control families, CUTEst-style problems), re-exported |
//!
//! Where a new test problem goes, and a new test: `docs/testing.md`.

pub mod alloc;
pub mod cart_pole_mpc;
pub mod hanging_chain;
pub mod hs;
pub mod mpcc;
pub mod ode;
pub mod quadrotor_ocp;
pub mod rti_loop;
pub mod socp;
pub mod solve_problems;
pub mod special;
pub mod trees;

/// The test corpus (its own crate, with its CLI and reference exports; docs/corpus.md).
pub use corpus;
