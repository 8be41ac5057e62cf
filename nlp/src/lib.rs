//! Nonlinear programs: problem builder and solvers (work in progress).

pub mod callback;
pub mod compiled;
pub mod constraint;
pub mod derivative_check;
pub mod dump;
pub mod error;
pub mod frontend;
pub mod integrator;
pub mod ipm;
pub(crate) mod kkt;
pub(crate) mod lbfgs;
pub(crate) mod log;
pub mod mpc;
pub mod mpcc;
pub mod numeric;
pub mod ocp;
pub mod option_names;
pub mod options;
pub mod parameter;
pub mod problem;
pub(crate) mod scaling;
pub mod sensitivity;
pub mod solution;
pub mod solution_file;
pub mod sqp;
#[cfg(test)]
mod test_support;

pub use callback::{IterationCallback, IterationView, PhaseLabel};
pub use compiled::{CompileOptions, Compiled};
pub use constraint::{bounded, Constraint, Relation};
pub use derivative_check::{check_derivatives, DerivativeCheckOptions, DerivativeReport};
pub use dump::{DumpError, DumpVerification, ProblemDump};
pub use error::SolveError;
pub use frontend::{CommonOptions, Solver, SolverOptions};
pub use integrator::{Integrator, IntegratorError, IntegratorOptions};
pub use ipm::Ipm;
pub use parameter::ParameterKey;
pub use problem::{
    linspace, Block, BuildError, ComplementarityReport, PerEntry, Problem, ProblemFileError,
    SolverFunction, ToFunctionError, PROBLEM_FILE_VERSION,
};

pub use log::{format_summary, format_table};
pub use mpc::{ClosedLoop, Mpc, MpcError, StepReport};
pub use mpcc::{
    solve_mpcc, solve_mpcc_with_callback, MpccBackend, MpccError, MpccOptions, MpccPhase,
    MpccSolution,
};
pub use numeric::{AffineCone, NumericNlp};
pub use ocp::{Horizon, Method, Ocp, OcpError, Trajectory};
pub use option_names::{NamedOptions, OptionError};
pub use options::{
    IpmHessian, IpmOptions, LimitedMemoryInit, LimitedMemoryUpdate, MuOracle, MuStrategy,
    QualityFunctionBalancingTerm, QualityFunctionCentrality, QualityFunctionNorm, ScalingMethod,
};
pub use sensitivity::{ParametricSensitivity, Sensitivity, SensitivityError};
pub use solution::{BackendColumns, IterationRecord, Solution, Stats, Status};
pub use solution_file::{SolutionFileError, SOLUTION_FILE_VERSION};
pub use sqp::{HessianApproximation, Rti, RtiError, Sqp, SqpOptions};
