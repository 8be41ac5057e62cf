//! Optimal control on top of [`Problem`](crate::Problem): an [`Ocp`] states a continuous-time problem once
//! — dynamics `ẋ = f(x, u, p)`, Lagrange and Mayer costs, path and boundary constraints,
//! bounds, a fixed or free final time — and [`Ocp::transcribe`] turns it into a
//! [`Problem`](crate::Problem) by direct multiple shooting (any explicit Runge–Kutta tableau, `M` steps per
//! interval) or direct collocation (Legendre or Radau points of any degree). The
//! [`Transcription`] compiles like any problem, is solved by either solver with the same
//! options, and reads a [`Solution`](crate::Solution) back as a [`Trajectory`]
//! (time grid, states, controls; serde-serialisable). See `docs/ocp.md`.
//!
//! Functions of the model are Rust closures of expressions given once; the dynamics may
//! instead be a compiled [`symx::Function`] ([`Ocp::set_dynamics_function`]), which every
//! transcription then calls without inlining (one call node per evaluation, the dynamics
//! held once). Each transcription evaluates the dynamics through [`Dynamics::eval`].
//! Multiple shooting can also compile one interval's integration as a function and call
//! it once per interval ([`Method::multiple_shooting_with_calls`]).
//!
//! Several phases (a contact sequence) joined by linkage constraints are one
//! [`MultiPhaseOcp`], written as one problem.
mod butcher;
mod collocation;
mod definition;
mod error;
mod grid;
mod multi_phase;
mod phase;
mod shift;
mod simulator;
mod trajectory;
mod transcription;

pub use butcher::ButcherTableau;
pub use collocation::{Collocation, CollocationPoints};
pub use definition::{Dynamics, Horizon, Ocp};
pub use error::OcpError;
pub use grid::{ControlInterpolation, Grid};
pub use multi_phase::{MultiPhaseOcp, MultiPhaseTranscription, PhaseId};
pub use shift::Shift;
pub use simulator::Simulator;
pub use trajectory::{CollocationStates, Trajectory};
pub use transcription::{Method, Transcription};

/// The tutorial `docs/ocp.md`, compiled and run as doc tests so that its examples stay true.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/ocp.md")]
pub struct OcpGuide;
