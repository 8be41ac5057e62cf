//! Right-hand sides `f(x, p)` of the integrators' test problems, as symx functions of the
//! state and the parameters.
use symx::{Function, Matrix};

/// Van der Pol, `x' = (x₂, μ(1 − x₁²)x₂ − x₁)` with `p = (μ)`: non-stiff at μ = 1, stiff at
/// μ = 1000 (relaxation oscillations with period ≈ 1.6μ).
pub fn van_der_pol() -> Function {
    let x = Matrix::sym_vec("x", 2);
    let mu = Matrix::sym_vec("mu", 1);
    Function::new(
        &[&x, &mu],
        &[&[x[1], mu[0] * (1.0 - x[0].sq()) * x[1] - x[0]]],
    )
    .expect("van_der_pol")
}

/// Robertson's chemical kinetics with `p = (k₁, k₂, k₃)` (classically 0.04, 3e7, 1e4): the
/// stiff test problem of Hairer & Wanner, *Solving ODEs II*, §IV.1.
pub fn robertson() -> Function {
    let y = Matrix::sym_vec("y", 3);
    let k = Matrix::sym_vec("k", 3);
    Function::new(
        &[&y, &k],
        &[&[
            -k[0] * y[0] + k[1] * y[1] * y[2],
            k[0] * y[0] - k[1] * y[1] * y[2] - k[2] * y[1].sq(),
            k[2] * y[1].sq(),
        ]],
    )
    .expect("robertson")
}
