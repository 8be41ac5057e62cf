//! Optimal-control families: direct transcriptions written with [`nlp::Problem`].
//!
//! - [`cops`]: the control problems of COPS 3.0 (Dolan, Moré, Munson, "Benchmarking
//!   optimization software with COPS 3.0", Argonne ANL/MCS-TM-273, 2004), in COPS's own
//!   transcriptions (trapezoidal rule, or Gauss collocation for catmix, channel and pinene);
//! - [`casadi`]: CasADi's examples (race car, Van der Pol);
//! - [`robotics`]: cart-pole swing-up, planar quadrotor point to point, two-link arm in
//!   minimum time.
//!
//! Sizes are numbers of intervals; every family's largest size has at least 20 000
//! variables.

pub mod casadi;
pub mod cops;
pub mod robotics;

use crate::{Family, Kind, Reference};
use nlp::{BuildError, Problem, Relation};
use symx::Expr;

/// Adds the trapezoidal-rule rows `x1 − x0 − h/2·(f0 + f1) = 0` (one per state) named `name`.
pub(crate) fn trapezoid(
    pb: &mut Problem,
    name: &str,
    x: [&[Expr]; 2],
    f: [&[Expr]; 2],
    h: Expr,
) -> Result<(), BuildError> {
    let rows = (0..x[0].len()).map(|s| (x[1][s] - x[0][s] - 0.5 * h * (f[0][s] + f[1][s])).eq(0.0));
    pb.subject_to_named(name, nlp::Constraint::all(rows))
}

/// One classical Runge–Kutta step of `ẋ = f(x)` (the control is captured by `f`).
pub(crate) fn rk4(f: &dyn Fn(&[Expr]) -> Vec<Expr>, x: &[Expr], h: Expr) -> Vec<Expr> {
    let shift = |k: &[Expr], c: f64| -> Vec<Expr> {
        x.iter().zip(k).map(|(&xi, &ki)| xi + c * h * ki).collect()
    };
    let k1 = f(x);
    let k2 = f(&shift(&k1, 0.5));
    let k3 = f(&shift(&k2, 0.5));
    let k4 = f(&shift(&k3, 1.0));
    (0..x.len())
        .map(|s| x[s] + h / 6.0 * (k1[s] + 2.0 * k2[s] + 2.0 * k3[s] + k4[s]))
        .collect()
}

/// Adds the RK4 multiple-shooting rows `x1 − RK4(x0) = 0` named `name`.
pub(crate) fn shooting(
    pb: &mut Problem,
    name: &str,
    f: &dyn Fn(&[Expr]) -> Vec<Expr>,
    x: [&[Expr]; 2],
    h: Expr,
) -> Result<(), BuildError> {
    let next = rk4(f, x[0], h);
    let rows = (0..x[0].len()).map(|s| (x[1][s] - next[s]).eq(0.0));
    pb.subject_to_named(name, nlp::Constraint::all(rows))
}

/// Fixes each `x[i]` to `values[i]` (a bound, not a row).
pub(crate) fn fix(pb: &mut Problem, x: &[Expr], values: &[f64]) -> Result<(), BuildError> {
    for (&xi, &v) in x.iter().zip(values) {
        pb.set_bounds(&[xi], v, v)?;
    }
    Ok(())
}

/// Column `k` of a state trajectory stored as one variable vector per state.
pub(crate) fn node(states: &[&[Expr]], k: usize) -> Vec<Expr> {
    states.iter().map(|s| s[k]).collect()
}

const COPS_OPTIMA: &str =
    "COPS 3.0 report (ANL/MCS-TM-273), as checked in MadNLP/COPSBenchmark.jl test/runtests.jl";

/// The optimal-control families.
pub static FAMILIES: &[Family] = &[
    Family {
        name: "rocket_trap",
        kind: Kind::Ocp,
        transcription: "trapezoidal",
        source: "COPS 3.0 §7 Goddard rocket (max final altitude); statement read in MadNLP/COPSBenchmark.jl ext/COPSBenchmarkJuMP/rocket.jl",
        sizes: &[400, 1600, 5000],
        build: cops::rocket,
        references: &[Reference { size: 400, value: -1.01283, source: COPS_OPTIMA }],
    },
    Family {
        name: "rocket_rows_trap",
        kind: Kind::Ocp,
        transcription: "trapezoidal",
        source: "COPS 3.0 §7 Goddard rocket as COPS writes it (boundary values as equality rows, their bounds dropped); statement read in MadNLP/COPSBenchmark.jl ext/COPSBenchmarkJuMP/rocket.jl",
        sizes: &[400, 1600, 6000],
        build: cops::rocket_rows,
        references: &[Reference { size: 400, value: -1.01283, source: COPS_OPTIMA }],
    },
    Family {
        name: "glider_trap",
        kind: Kind::Ocp,
        transcription: "trapezoidal",
        source: "COPS 3.0 §4 hang glider (max range); statement read in MadNLP/COPSBenchmark.jl ext/COPSBenchmarkJuMP/glider.jl",
        sizes: &[100, 1000, 4000],
        build: cops::glider,
        references: &[Reference { size: 100, value: -1.25505e3, source: COPS_OPTIMA }],
    },
    Family {
        name: "steering_trap",
        kind: Kind::Ocp,
        transcription: "trapezoidal",
        source: "COPS 3.0 §9 particle steering (min time); statement read in MadNLP/COPSBenchmark.jl ext/COPSBenchmarkJuMP/steering.jl",
        sizes: &[200, 1000, 4000],
        build: cops::steering,
        references: &[Reference { size: 200, value: 5.54577e-1, source: COPS_OPTIMA }],
    },
    Family {
        name: "robot_trap",
        kind: Kind::Ocp,
        transcription: "trapezoidal",
        source: "COPS 3.0 §8 robot arm (min time); statement read in MadNLP/COPSBenchmark.jl ext/COPSBenchmarkJuMP/robot.jl",
        sizes: &[200, 800, 2250],
        build: cops::robot,
        references: &[Reference { size: 200, value: 9.14138, source: COPS_OPTIMA }],
    },
    Family {
        name: "catmix_colloc",
        kind: Kind::Ocp,
        transcription: "collocation",
        source: "COPS 3.0 §13 catalyst mixing (3-point Gauss collocation); statement read in MadNLP/COPSBenchmark.jl ext/COPSBenchmarkJuMP/catmix.jl",
        sizes: &[100, 400, 870],
        build: cops::catmix,
        references: &[Reference { size: 100, value: -4.80556e-2, source: COPS_OPTIMA }],
    },
    Family {
        name: "channel_colloc",
        kind: Kind::Ocp,
        transcription: "collocation",
        source: "COPS 3.0 §3 flow in a channel (feasibility, 4-point Gauss collocation); statement read in MadNLP/COPSBenchmark.jl ext/COPSBenchmarkJuMP/channel.jl",
        sizes: &[100, 250, 500],
        build: cops::channel,
        references: &[],
    },
    Family {
        name: "pinene_colloc",
        kind: Kind::Ocp,
        transcription: "collocation",
        source: "COPS 3.0 §12 α-pinene isomerisation (parameter estimation, 3-point Gauss collocation); statement and data read in MadNLP/COPSBenchmark.jl ext/COPSBenchmarkJuMP/pinene.jl",
        sizes: &[100, 200, 400],
        build: cops::pinene,
        references: &[Reference { size: 100, value: 1.98721e1, source: COPS_OPTIMA }],
    },
    Family {
        name: "race_car_rk4",
        kind: Kind::Ocp,
        transcription: "rk4-shooting",
        source: "CasADi docs/examples/python/race_car.py (this repository's examples/src/race_car.rs)",
        sizes: &[100, 400, 6667],
        build: casadi::race_car,
        references: &[],
    },
    Family {
        name: "vdp_rk4",
        kind: Kind::Ocp,
        transcription: "rk4-shooting",
        source: "CasADi docs/examples/python/direct_multiple_shooting.py (Van der Pol, T = 10), one RK4 step per interval",
        sizes: &[20, 1000, 6667],
        build: casadi::vdp_rk4,
        references: &[],
    },
    Family {
        name: "vdp_trap",
        kind: Kind::Ocp,
        transcription: "trapezoidal",
        source: "CasADi docs/examples/python/direct_collocation.py's problem (Van der Pol, T = 10), trapezoidal rule",
        sizes: &[50, 1000, 6667],
        build: casadi::vdp_trap,
        references: &[],
    },
    Family {
        name: "cartpole_trap",
        kind: Kind::Ocp,
        transcription: "trapezoidal",
        source: "M. Kelly, An introduction to trajectory optimization, SIAM Review 59(4), 2017, §6 and Appendix E (cart-pole swing-up, min ∫u²)",
        sizes: &[50, 800, 4000],
        build: robotics::cartpole_trap,
        references: &[],
    },
    Family {
        name: "cartpole_rk4",
        kind: Kind::Ocp,
        transcription: "rk4-shooting",
        source: "M. Kelly, SIAM Review 59(4), 2017, §6 (cart-pole swing-up), RK4 multiple shooting with piecewise-constant force",
        sizes: &[50, 800, 4000],
        build: robotics::cartpole_rk4,
        references: &[],
    },
    Family {
        name: "quadrotor_rk4",
        kind: Kind::Ocp,
        transcription: "rk4-shooting",
        source: "planar quadrotor of R. Tedrake, Underactuated Robotics (MIT 6.832), ch. 3; point to point around a round obstacle, min ∫(u₁²+u₂²)",
        sizes: &[50, 500, 2500],
        build: robotics::quadrotor_rk4,
        references: &[],
    },
    Family {
        name: "arm2_trap",
        kind: Kind::Ocp,
        transcription: "trapezoidal",
        source: "two-link planar arm (point masses at the link ends, M. W. Spong et al., Robot Modeling and Control, 2006, §7.3), minimum time under torque limits",
        sizes: &[50, 800, 3333],
        build: robotics::arm2_trap,
        references: &[],
    },
];
