//! Nonlinear programs: problem builder and solvers (work in progress).
