//! CUTEst-style problems (none from Hock–Schittkowski): scalable unconstrained CUTEst
//! problems ([`unconstrained`]), small Moré–Garbow–Hillstrom least-squares problems
//! ([`small`]) and constrained CUTEst/COPS problems ([`constrained`]).
//!
//! Statements were read in JuliaSmoothOptimizers/OptimizationProblems.jl
//! (`src/PureJuMP/<name>.jl`), each from the CUTEst SIF file of the same name (or the COPS
//! 3.0 report, or Moré, Garbow, Hillstrom, ACM TOMS 7(1), 1981); where that transcription's
//! data differ from MGH's paper (BARD y₁₂ = 0.96, KOWOSB u₉ = 0.0833, OSBORNE1 tᵢ = 10(i−1))
//! MGH's are used. References are given only where the optimum is published (MGH, COPS
//! 3.0) or exact by construction (a sum of squares or powers that reaches zero, or a sum of
//! terms each attaining its bound at one point).

pub mod constrained;
pub mod small;
pub mod unconstrained;

use crate::{Family, Kind, Reference};
use constrained as c;
use small as s;
use unconstrained as u;

const EXACT: &str = "exact by construction (every term reaches its lower bound at one point)";
const MGH: &str =
    "Moré, Garbow, Hillstrom, ACM TOMS 7(1), 1981 (sum of squares; ½ of the published value)";
const COPS: &str =
    "COPS 3.0 report (ANL/MCS-TM-273), as checked in MadNLP/COPSBenchmark.jl test/runtests.jl";

macro_rules! families {
    ($( $name:ident, $source:literal, $size:expr, $build:expr, [$($value:expr, $why:expr);*] );* $(;)?) => {
        /// The CUTEst-style families (one size each).
        pub static FAMILIES: &[Family] = &[$(
            Family {
                name: stringify!($name),
                kind: Kind::Cute,
                transcription: "-",
                source: $source,
                sizes: &[$size],
                build: $build,
                references: &[$(Reference { size: $size, value: $value, source: $why }),*],
            }
        ),*];
    };
}

families! {
    arwhead, "CUTEst ARWHEAD (Conn, Gould, Lescrenier, Toint 1988, problem 55)", 1000, u::arwhead, [0.0, EXACT];
    bdqrtic, "CUTEst BDQRTIC (Conn et al. 1988, problem 61)", 1000, u::bdqrtic, [];
    broydn7d, "CUTEst BROYDN7D (Broyden 1971; Toint 1978)", 1000, u::broydn7d, [];
    brybnd, "CUTEst BRYBND (MGH 31, Broyden banded)", 1000, u::brybnd, [0.0, EXACT];
    chainwoo, "CUTEst CHAINWOO (Conn et al. 1988, chained Woods)", 1000, u::chainwoo, [1.0, EXACT];
    cosine, "CUTEst COSINE (Nesterov's cosine function)", 1000, u::cosine, [];
    cragglvy, "CUTEst CRAGGLVY (Toint 1978, extended Cragg–Levy)", 1000, u::cragglvy, [];
    dixmaane, "CUTEst DIXMAANE (Dixon, Maany 1988)", 999, u::dixmaane, [1.0, EXACT];
    dixmaanf, "CUTEst DIXMAANF (Dixon, Maany 1988)", 999, u::dixmaanf, [1.0, EXACT];
    dixmaang, "CUTEst DIXMAANG (Dixon, Maany 1988)", 999, u::dixmaang, [1.0, EXACT];
    dixmaanh, "CUTEst DIXMAANH (Dixon, Maany 1988)", 999, u::dixmaanh, [1.0, EXACT];
    dixmaani, "CUTEst DIXMAANI (Dixon, Maany 1988)", 999, u::dixmaani, [1.0, EXACT];
    dixmaanj, "CUTEst DIXMAANJ (Dixon, Maany 1988)", 999, u::dixmaanj, [1.0, EXACT];
    dixmaank, "CUTEst DIXMAANK (Dixon, Maany 1988)", 999, u::dixmaank, [1.0, EXACT];
    dixmaanl, "CUTEst DIXMAANL (Dixon, Maany 1988)", 999, u::dixmaanl, [1.0, EXACT];
    dixon3dq, "CUTEst DIXON3DQ (Dixon's tridiagonal quadratic)", 1000, u::dixon3dq, [0.0, EXACT];
    dqdrtic, "CUTEst DQDRTIC (diagonal quadratic)", 1000, u::dqdrtic, [0.0, EXACT];
    dqrtic, "CUTEst DQRTIC (diagonal quartic)", 1000, u::dqrtic, [0.0, EXACT];
    edensch, "CUTEst EDENSCH (Li 1988, extended Dennis–Schnabel)", 1000, u::edensch, [];
    engval1, "CUTEst ENGVAL1 (Toint 1978)", 1000, u::engval1, [];
    errinros_mod, "CUTEst ERRINROS, modified as in OptimizationProblems.jl errinros_mod", 1000, u::errinros_mod, [];
    extrosnb, "CUTEst EXTROSNB (extended Rosenbrock)", 1000, u::extrosnb, [0.0, EXACT];
    fletchcr, "CUTEst FLETCHCR (Fletcher's chained Rosenbrock)", 1000, u::fletchcr, [0.0, EXACT];
    freuroth, "CUTEst FREUROTH (MGH 2, extended Freudenstein–Roth)", 1000, u::freuroth, [];
    genhumps, "CUTEst GENHUMPS (generalised humps)", 1000, u::genhumps, [0.0, EXACT];
    genrose, "CUTEst GENROSE (generalised Rosenbrock)", 1000, u::genrose, [1.0, EXACT];
    liarwhd, "CUTEst LIARWHD (Li 1988)", 1000, u::liarwhd, [0.0, EXACT];
    morebv, "CUTEst MOREBV (MGH 28, discrete boundary value)", 1000, u::morebv, [0.0, EXACT];
    noncvxu2, "CUTEst NONCVXU2 (nonconvex, cosines)", 1000, u::noncvxu2, [];
    noncvxun, "CUTEst NONCVXUN (nonconvex, cosines)", 1000, u::noncvxun, [];
    nondia, "CUTEst NONDIA (Shanno 1978)", 1000, u::nondia, [0.0, EXACT];
    nondquar, "CUTEst NONDQUAR (Conn et al. 1988)", 1000, u::nondquar, [0.0, EXACT];
    penalty1, "CUTEst PENALTY1 (MGH 23, penalty function I)", 100, u::penalty1, [];
    power, "CUTEst POWER (Oren 1974)", 100, u::power, [0.0, EXACT];
    quartc, "CUTEst QUARTC (quartic)", 1000, u::quartc, [0.0, EXACT];
    sinquad, "CUTEst SINQUAD (Conn et al. 1988)", 1000, u::sinquad, [];
    sparsine, "CUTEst SPARSINE (sparse sines)", 1000, u::sparsine, [0.0, EXACT];
    sparsqur, "CUTEst SPARSQUR (sparse quartic)", 1000, u::sparsqur, [0.0, EXACT];
    srosenbr, "CUTEst SROSENBR (MGH 21, separable extended Rosenbrock)", 1000, u::srosenbr, [0.0, EXACT];
    tquartic, "CUTEst TQUARTIC (Conn et al. 1988)", 1000, u::tquartic, [0.0, EXACT];
    tridia, "CUTEst TRIDIA (Shanno's tridiagonal quadratic)", 1000, u::tridia, [0.0, EXACT];
    vardim, "CUTEst VARDIM (MGH 25, variable dimension)", 100, u::vardim, [0.0, EXACT];
    woods, "CUTEst WOODS (MGH 14, extended Woods)", 1000, u::woods, [0.0, EXACT];
    schmvett, "CUTEst SCHMVETT (Schmidt, Vetters 1970)", 1000, u::schmvett, [-2994.0, EXACT];
    tointgss, "CUTEst TOINTGSS (Toint's Gaussian)", 1000, u::tointgss, [9980.0 / 1002.0, EXACT];
    powellsg, "CUTEst POWELLSG (MGH 13, extended Powell singular)", 1000, s::powellsg, [0.0, EXACT];
    beale, "CUTEst BEALE (MGH 5)", 2, s::beale, [0.0, EXACT];
    bard, "CUTEst BARD (MGH 8)", 3, s::bard, [4.107435e-3, MGH];
    brownbs, "CUTEst BROWNBS (MGH 4, Brown badly scaled)", 2, s::brownbs, [0.0, EXACT];
    kowosb, "CUTEst KOWOSB (MGH 15, Kowalik–Osborne)", 4, s::kowosb, [1.537525e-4, MGH];
    meyer3, "CUTEst MEYER3 (MGH 10, Meyer)", 3, s::meyer3, [43.9729, MGH];
    osborne1, "CUTEst OSBORNE1 (MGH 17)", 5, s::osborne1, [2.732445e-5, MGH];
    helical, "CUTEst HELIX (MGH 7, helical valley)", 3, s::helical, [0.0, EXACT];
    bt1, "CUTEst BT1 (Byrd, Tapia)", 2, c::bt1, [];
    catenary, "CUTEst CATENARY (3-D chain of 332 links)", 999, c::catenary, [];
    clnlbeam, "CLNLBEAM (clamped nonlinear beam, Vanderbei's AMPL models)", 3003, c::clnlbeam, [];
    hovercraft1d, "hovercraft1d (minimum-energy double integrator, OptimizationProblems.jl)", 300, c::hovercraft1d, [];
    controlinvestment, "controlinvestment (investment control, OptimizationProblems.jl)", 2000, c::controlinvestment, [];
    elec, "COPS 3.0 §2 ELEC (Thomson problem, 50 electrons)", 50, c::elec, [1.0552e3, COPS];
    torsion, "COPS 3.0 §11 TORSION (elastic-plastic torsion, 50×50 grid)", 50, c::torsion, [-4.18087e-1, COPS];
    chain, "COPS 3.0 §1 CHAIN (hanging chain, 800 intervals)", 800, c::chain, [5.06891, COPS];
    camshape, "COPS 3.0 §5 CAMSHAPE (1000 radii)", 1000, c::camshape, [];
    lincon, "lincon (linear constraints, OptimizationProblems.jl)", 15, c::lincon, [];
    allinit, "CUTEst ALLINIT", 4, c::allinit, [];
    allinitc, "CUTEst ALLINITC", 4, c::allinitc, [];
    zangwil3, "CUTEst ZANGWIL3 (feasibility)", 3, c::zangwil3, [0.0, EXACT];
}
