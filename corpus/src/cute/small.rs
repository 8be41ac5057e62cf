//! Small unconstrained least-squares problems of Moré, Garbow and Hillstrom ("Testing
//! unconstrained optimization software", ACM TOMS 7(1), 1981; "MGH" below), as in CUTEst
//! and JuliaSmoothOptimizers/OptimizationProblems.jl (`src/PureJuMP/<name>.jl`, objectives
//! with the factor ½ of that collection). The size argument is ignored except by POWELLSG.
use super::unconstrained::vars;
use nlp::{BuildError, Problem};
use symx::Expr;

fn least_squares(
    x0: &[f64],
    residuals: impl Fn(&dyn Fn(usize) -> Expr) -> Vec<Expr>,
) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let v = vars(&mut pb, x0.len(), |i| x0[i - 1])?;
    let x = |i: usize| v[i - 1];
    let r = residuals(&x);
    pb.minimize(0.5 * r.into_iter().fold(Expr::zero(), |acc, ri| acc + ri.sq()));
    Ok(pb)
}

/// BEALE (MGH 5).
pub fn beale(_: usize) -> Result<Problem, BuildError> {
    least_squares(&[1.0, 1.0], |x| {
        vec![
            1.5 - x(1) * (1.0 - x(2)),
            2.25 - x(1) * (1.0 - x(2).sq()),
            2.625 - x(1) * (1.0 - x(2).powi(3)),
        ]
    })
}

/// BARD (MGH 8).
pub fn bard(_: usize) -> Result<Problem, BuildError> {
    let y = [
        0.14, 0.18, 0.22, 0.25, 0.29, 0.32, 0.35, 0.39, 0.37, 0.58, 0.73, 0.96, 1.34, 2.10, 4.39,
    ];
    least_squares(&[1.0, 1.0, 1.0], |x| {
        (1..=15usize)
            .map(|i| {
                let (u, v, w) = (i as f64, (16 - i) as f64, i.min(16 - i) as f64);
                y[i - 1] - (x(1) + u / (v * x(2) + w * x(3)))
            })
            .collect()
    })
}

/// BROWNBS: Brown's badly scaled (MGH 4).
pub fn brownbs(_: usize) -> Result<Problem, BuildError> {
    least_squares(&[1.0, 1.0], |x| {
        vec![x(1) - 1e6, x(2) - 2e-6, x(1) * x(2) - 2.0]
    })
}

/// KOWOSB: Kowalik and Osborne (MGH 15), with MGH's data (u₉ = 0.0833).
pub fn kowosb(_: usize) -> Result<Problem, BuildError> {
    let y = [
        0.1957, 0.1947, 0.1735, 0.1600, 0.0844, 0.0627, 0.0456, 0.0342, 0.0323, 0.0235, 0.0246,
    ];
    let u = [
        4.0, 2.0, 1.0, 0.5, 0.25, 0.167, 0.125, 0.1, 0.0833, 0.0714, 0.0625,
    ];
    least_squares(&[0.25, 0.39, 0.415, 0.39], |x| {
        (0..11)
            .map(|i| y[i] - x(1) * (u[i] * u[i] + u[i] * x(2)) / (u[i] * u[i] + u[i] * x(3) + x(4)))
            .collect()
    })
}

/// MEYER3: Meyer (MGH 10).
pub fn meyer3(_: usize) -> Result<Problem, BuildError> {
    let y = [
        34780.0, 28610.0, 23650.0, 19630.0, 16370.0, 13720.0, 11540.0, 9744.0, 8261.0, 7030.0,
        6005.0, 5147.0, 4427.0, 3820.0, 3307.0, 2872.0,
    ];
    least_squares(&[0.02, 4000.0, 250.0], |x| {
        (1..=16)
            .map(|i| x(1) * (x(2) / (45.0 + 5.0 * i as f64 + x(3))).exp() - y[i - 1])
            .collect()
    })
}

/// OSBORNE1: Osborne 1 (MGH 17).
pub fn osborne1(_: usize) -> Result<Problem, BuildError> {
    let y = [
        0.844, 0.908, 0.932, 0.936, 0.925, 0.908, 0.881, 0.850, 0.818, 0.784, 0.751, 0.718, 0.685,
        0.658, 0.628, 0.603, 0.580, 0.558, 0.538, 0.522, 0.506, 0.490, 0.478, 0.467, 0.457, 0.448,
        0.438, 0.431, 0.424, 0.420, 0.414, 0.411, 0.406,
    ];
    least_squares(&[0.5, 1.5, -1.0, 0.01, 0.02], |x| {
        (1..=33)
            .map(|j| {
                let t = 10.0 * (j - 1) as f64;
                y[j - 1] - (x(1) + x(2) * (-t * x(4)).exp() + x(3) * (-t * x(5)).exp())
            })
            .collect()
    })
}

/// HELICAL: helical valley (MGH 7).
pub fn helical(_: usize) -> Result<Problem, BuildError> {
    least_squares(&[-1.0, 0.0, 0.0], |x| {
        let theta = ((x(2) / x(1)).atan() - 0.25 * (x(1) - x(1).abs()) / x(1))
            / (2.0 * std::f64::consts::PI);
        vec![
            10.0 * (x(3) - 10.0 * theta),
            10.0 * ((x(1).sq() + x(2).sq()).sqrt() - 1.0),
            x(3),
        ]
    })
}

/// POWELLSG: extended Powell singular (MGH 13), n a multiple of 4.
pub fn powellsg(n: usize) -> Result<Problem, BuildError> {
    let x0: Vec<f64> = (0..n).map(|i| [3.0, -1.0, 0.0, 1.0][i % 4]).collect();
    let mut pb = Problem::new();
    let v = vars(&mut pb, n, |i| x0[i - 1])?;
    let x = |i: usize| v[i - 1];
    let f = (1..=n).step_by(4).fold(Expr::zero(), |acc, j| {
        acc + (x(j) + 10.0 * x(j + 1)).sq()
            + 5.0 * (x(j + 2) - x(j + 3)).sq()
            + (x(j + 1) - 2.0 * x(j + 2)).powi(4)
            + 10.0 * (x(j) - x(j + 3)).powi(4)
    });
    pb.minimize(f);
    Ok(pb)
}
