//! Scalable unconstrained CUTEst problems. Each builder takes the number of variables `n`
//! and follows the statement read in JuliaSmoothOptimizers/OptimizationProblems.jl
//! (`src/PureJuMP/<name>.jl`, itself from the CUTEst SIF file of the same name), with the
//! same starting point. Indices in the formulas are 1-based, as in the sources.
use nlp::{BuildError, Problem};
use symx::{Expr, Matrix};

/// Declares `x[0..n]` with starting values `x0(i)` (1-based `i`) and returns a 1-based
/// accessor.
pub(crate) fn vars(
    pb: &mut Problem,
    n: usize,
    x0: impl Fn(usize) -> f64,
) -> Result<Matrix, BuildError> {
    let x = pb.variable("x", n)?;
    pb.set_initial(&x, &(1..=n).map(x0).collect::<Vec<_>>())?;
    Ok(x)
}

fn sum(range: impl Iterator<Item = usize>, f: impl Fn(usize) -> Expr) -> Expr {
    range.fold(Expr::zero(), |acc, i| acc + f(i))
}

macro_rules! problem {
    ($(#[$doc:meta])* $name:ident, |$n:ident| $x0:expr, |$x:ident| $objective:expr) => {
        $(#[$doc])*
        pub fn $name($n: usize) -> Result<Problem, BuildError> {
            let mut pb = Problem::new();
            let v = vars(&mut pb, $n, $x0)?;
            let $x = |i: usize| v[i - 1];
            let f: Expr = $objective;
            pb.minimize(f);
            Ok(pb)
        }
    };
}

problem!(
    /// ARWHEAD: arrow-head quartic.
    arwhead, |n| |_| 1.0, |x| sum(1..n, |i| (x(i).sq() + x(n).sq()).sq() - 4.0 * x(i) + 3.0)
);
problem!(
    /// BDQRTIC: banded quartic.
    bdqrtic, |n| |_| 1.0,
    |x| 0.5 * sum(1..n - 3, |i| (3.0 - 4.0 * x(i)).sq()
        + (x(i).sq() + 2.0 * x(i + 1).sq() + 3.0 * x(i + 2).sq() + 4.0 * x(i + 3).sq() + 5.0 * x(n).sq()).sq())
);
problem!(
    /// BROYDN7D: Broyden 7-diagonal with `|·|^(7/3)` terms (n even).
    broydn7d, |n| |_| -1.0,
    |x| {
        let p = 7.0 / 3.0;
        let n2 = n / 2;
        (1.0 - 2.0 * x(2) + (3.0 - x(1) / 2.0) * x(1)).abs().powf(p)
            + sum(2..n, |i| (1.0 - x(i - 1) - 2.0 * x(i + 1) + (3.0 - x(i) / 2.0) * x(i)).abs().powf(p))
            + (1.0 - x(n - 1) + (3.0 - x(n) / 2.0) * x(n)).abs().powf(p)
            + sum(1..n2 + 1, |i| (x(i) + x(i + n2)).abs().powf(p))
    }
);
problem!(
    /// BRYBND: Broyden banded (ml = 5, mu = 1).
    brybnd, |n| |_| -1.0,
    |x| 0.5 * sum(1..n + 1, |i| {
        let band = sum(i.saturating_sub(5).max(1)..(i + 1).min(n) + 1, |j| if j == i { Expr::zero() } else { x(j) * (1.0 + x(j)) });
        (x(i) * (2.0 + 5.0 * x(i).sq()) + 1.0 - band).sq()
    })
);
problem!(
    /// CHAINWOO: chained Woods (n multiple of 4).
    chainwoo, |n| |i| match i { 1 | 3 => -3.0, 2 | 4 => -1.0, _ => -2.0 },
    |x| 1.0 + sum(1..n / 2, |i| {
        100.0 * (x(2 * i) - x(2 * i - 1).sq()).sq() + (1.0 - x(2 * i - 1)).sq()
            + 90.0 * (x(2 * i + 2) - x(2 * i + 1).sq()).sq() + (1.0 - x(2 * i + 1)).sq()
            + 10.0 * (x(2 * i) + x(2 * i + 2) - 2.0).sq() + 0.1 * (x(2 * i) - x(2 * i + 2)).sq()
    })
);
problem!(
    /// COSINE: sum of cosines.
    cosine, |n| |_| 1.0, |x| sum(1..n, |i| (x(i).sq() - 0.5 * x(i + 1)).cos())
);
problem!(
    /// CRAGGLVY: extended Cragg and Levy (n even).
    cragglvy, |n| |i| if i == 1 { 1.0 } else { 2.0 },
    |x| sum(1..n / 2, |i| {
        (x(2 * i - 1).exp() - x(2 * i)).powi(4) + 100.0 * (x(2 * i) - x(2 * i + 1)).powi(6)
            + ((x(2 * i + 1) - x(2 * i + 2)).tan() + x(2 * i + 1) - x(2 * i + 2)).powi(4)
            + x(2 * i - 1).powi(8) + (x(2 * i + 2) - 1.0).sq()
    })
);

/// DIXMAAN E–L (Dixon and Maany), n a multiple of 3: `power` 1 for E–H, 2 for I–L.
fn dixmaan(n: usize, power: i32, beta: f64, gamma: f64, delta: f64) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let v = vars(&mut pb, n, |_| 2.0)?;
    let x = |i: usize| v[i - 1];
    let m = n / 3;
    let w = |i: usize| (i as f64 / n as f64).powi(power);
    let f = 1.0
        + sum(1..n + 1, |i| w(i) * x(i).sq())
        + sum(1..n, |i| beta * x(i).sq() * (x(i + 1) + x(i + 1).sq()).sq())
        + sum(1..2 * m + 1, |i| gamma * x(i).sq() * x(i + m).powi(4))
        + sum(1..m + 1, |i| w(i) * delta * x(i) * x(i + 2 * m));
    pb.minimize(f);
    Ok(pb)
}

/// DIXMAANE.
pub fn dixmaane(n: usize) -> Result<Problem, BuildError> {
    dixmaan(n, 1, 0.0, 0.125, 0.125)
}
/// DIXMAANF.
pub fn dixmaanf(n: usize) -> Result<Problem, BuildError> {
    dixmaan(n, 1, 0.0625, 0.0625, 0.0625)
}
/// DIXMAANG.
pub fn dixmaang(n: usize) -> Result<Problem, BuildError> {
    dixmaan(n, 1, 0.125, 0.125, 0.125)
}
/// DIXMAANH.
pub fn dixmaanh(n: usize) -> Result<Problem, BuildError> {
    dixmaan(n, 1, 0.26, 0.26, 0.26)
}
/// DIXMAANI.
pub fn dixmaani(n: usize) -> Result<Problem, BuildError> {
    dixmaan(n, 2, 0.0, 0.125, 0.125)
}
/// DIXMAANJ.
pub fn dixmaanj(n: usize) -> Result<Problem, BuildError> {
    dixmaan(n, 2, 0.0625, 0.0625, 0.0625)
}
/// DIXMAANK.
pub fn dixmaank(n: usize) -> Result<Problem, BuildError> {
    dixmaan(n, 2, 0.125, 0.125, 0.125)
}
/// DIXMAANL.
pub fn dixmaanl(n: usize) -> Result<Problem, BuildError> {
    dixmaan(n, 2, 0.26, 0.26, 0.26)
}

problem!(
    /// DIXON3DQ: Dixon's tridiagonal quadratic.
    dixon3dq, |n| |_| -1.0,
    |x| 0.5 * (x(1) - 1.0).sq() + 0.5 * (x(n) - 1.0).sq() + 0.5 * sum(2..n - 1, |i| (x(i) - x(i + 1)).sq())
);
problem!(
    /// DQDRTIC: diagonal quadratic.
    dqdrtic, |n| |_| 3.0, |x| sum(1..n - 1, |i| x(i).sq() + 100.0 * (x(i + 1).sq() + x(i + 2).sq()))
);
problem!(
    /// DQRTIC: diagonal quartic.
    dqrtic, |n| |_| 2.0, |x| sum(1..n + 1, |i| (x(i) - i as f64).powi(4))
);
problem!(
    /// EDENSCH: extended Dennis–Schnabel.
    edensch, |n| |_| 0.0,
    |x| 16.0 + sum(1..n, |i| (x(i) - 2.0).powi(4) + (x(i) * x(i + 1) - 2.0 * x(i + 1)).sq() + (x(i + 1) + 1.0).sq())
);
problem!(
    /// ENGVAL1.
    engval1, |n| |_| 2.0, |x| sum(1..n, |i| (x(i).sq() + x(i + 1).sq()).sq() - 4.0 * x(i) + 3.0)
);
problem!(
    /// ERRINROS (modified): error in Rosenbrock.
    errinros_mod, |n| |_| -1.0,
    |x| 0.5 * sum(2..n + 1, |i| (x(i - 1) - 16.0 * x(i).sq() * (1.5 + (i as f64).sin()).powi(2)).sq())
        + 0.5 * sum(2..n + 1, |i| (1.0 - x(i)).sq())
);
problem!(
    /// EXTROSNB: extended Rosenbrock (starts at −1).
    extrosnb, |n| |_| -1.0, |x| 100.0 * sum(2..n + 1, |i| (x(i) - x(i - 1).sq()).sq()) + (1.0 - x(1)).sq()
);
problem!(
    /// FLETCHCR: Fletcher's chained Rosenbrock.
    fletchcr, |n| |_| 0.0, |x| 100.0 * sum(1..n, |i| (x(i + 1) - x(i) + 1.0 - x(i).sq()).sq())
);
problem!(
    /// FREUROTH: Freudenstein and Roth.
    freuroth, |n| |i| match i { 1 => 0.5, 2 => -2.0, _ => 0.0 },
    |x| 0.5 * sum(1..n, |i| ((5.0 - x(i + 1)) * x(i + 1).sq() + x(i) - 2.0 * x(i + 1) - 13.0).sq())
        + 0.5 * sum(1..n, |i| ((1.0 + x(i + 1)) * x(i + 1).sq() + x(i) - 14.0 * x(i + 1) - 29.0).sq())
);
problem!(
    /// GENHUMPS: generalised humps (ζ = 20).
    genhumps, |n| |i| if i == 1 { -506.0 } else { -506.2 },
    |x| sum(1..n, |i| (20.0 * x(i)).sin().sq() * (20.0 * x(i + 1)).sin().sq() + 0.05 * (x(i).sq() + x(i + 1).sq()))
);
problem!(
    /// GENROSE: generalised Rosenbrock.
    genrose, |n| |i| i as f64 / (n + 1) as f64,
    |x| 1.0 + 100.0 * sum(1..n, |i| (x(i + 1) - x(i).sq()).sq()) + sum(1..n, |i| (x(i) - 1.0).sq())
);
problem!(
    /// LIARWHD.
    liarwhd, |n| |_| 4.0, |x| sum(1..n + 1, |i| 4.0 * (x(i).sq() - x(1)).sq() + (x(i) - 1.0).sq())
);
problem!(
    /// MOREBV: Moré's boundary-value problem as least squares.
    morebv, |n| |_| 0.5,
    |x| {
        let h = 1.0 / (n + 1) as f64;
        0.5 * sum(2..n, |i| (2.0 * x(i) - x(i - 1) - x(i + 1) + (h * h / 2.0) * (x(i) + i as f64 * h + 1.0).powi(3)).sq())
            + 0.5 * (2.0 * x(1) - x(2) + (h * h / 2.0) * (x(1) + 1.0).powi(3)).sq()
            + 0.5 * (2.0 * x(n) - x(n - 1) + (h * h / 2.0) * (x(n) + n as f64 * h + 1.0).powi(3)).sq()
    }
);
problem!(
    /// NONCVXU2: nonconvex with cosines.
    noncvxu2, |n| |i| i as f64,
    |x| sum(1..n + 1, |i| {
        let s = x(i) + x((3 * i - 2) % n + 1) + x((7 * i - 3) % n + 1);
        s.sq() + 4.0 * s.cos()
    })
);
problem!(
    /// NONCVXUN: nonconvex with cosines.
    noncvxun, |n| |i| i as f64,
    |x| sum(1..n + 1, |i| {
        let s = x(i) + x((2 * i - 1) % n + 1) + x((3 * i - 1) % n + 1);
        s.sq() + 4.0 * s.cos()
    })
);
problem!(
    /// NONDIA: nondiagonal.
    nondia, |n| |_| -1.0, |x| (x(1) - 1.0).sq() + 100.0 * sum(2..n + 1, |i| (x(1) - x(i).sq()).sq())
);
problem!(
    /// NONDQUAR: nondiagonal quartic.
    nondquar, |n| |i| if i % 2 == 0 { -1.0 } else { 1.0 },
    |x| (x(1) - x(2)).sq() + (x(n - 1) - x(n)).sq() + sum(1..n - 1, |i| (x(i) + x(i + 1) + x(n)).powi(4))
);
problem!(
    /// PENALTY1: penalty function I (dense Hessian).
    penalty1, |n| |i| i as f64,
    |x| 0.5 * sum(1..n + 1, |i| 1e-5 * (x(i) - 1.0).sq()) + 0.5 * (sum(1..n + 1, |j| x(j).sq()) - 0.25).sq()
);
problem!(
    /// POWER: Oren's power function (dense Hessian).
    power, |n| |_| 1.0, |x| 0.5 * sum(1..n + 1, |i| i as f64 * x(i).sq()).sq()
);
problem!(
    /// QUARTC: quartic.
    quartc, |n| |_| 2.0, |x| sum(1..n + 1, |i| (x(i) - i as f64).powi(4))
);
problem!(
    /// SINQUAD.
    sinquad, |n| |_| 0.1,
    |x| (x(1) - 1.0).powi(4) + (x(n).sq() - x(1).sq()).sq() + sum(2..n, |i| ((x(i) - x(n)).sin() - x(1).sq() + x(i).sq()).sq())
);
problem!(
    /// SPARSINE: sparse sines.
    sparsine, |n| |_| 0.5,
    |x| 0.5 * sum(1..n + 1, |i| {
        let s = [1, 2, 3, 5, 7, 11].iter().fold(Expr::zero(), |acc, &k| {
            let j = if k == 1 { i } else { (k * i - 1) % n + 1 };
            acc + x(j).sin()
        });
        i as f64 * s.sq()
    })
);
problem!(
    /// SPARSQUR: sparse quartic.
    sparsqur, |n| |_| 0.5,
    |x| 0.125 * sum(1..n + 1, |i| {
        let s = [1, 2, 3, 5, 7, 11].iter().fold(Expr::zero(), |acc, &k| {
            let j = if k == 1 { i } else { (k * i - 1) % n + 1 };
            acc + x(j).sq()
        });
        i as f64 * s.sq()
    })
);
problem!(
    /// SROSENBR: separable Rosenbrock (n even).
    srosenbr, |n| |i| if i % 2 == 1 { -1.2 } else { 1.0 },
    |x| sum(1..n / 2 + 1, |i| 100.0 * (x(2 * i) - x(2 * i - 1).sq()).sq() + (x(2 * i - 1) - 1.0).sq())
);
problem!(
    /// TQUARTIC.
    tquartic, |n| |_| 0.1, |x| 0.5 * (x(1) - 1.0).sq() + 0.5 * sum(1..n - 1, |i| (x(1).sq() - x(i + 1).sq()).sq())
);
problem!(
    /// TRIDIA: Shanno's tridiagonal quadratic.
    tridia, |n| |_| 1.0, |x| (x(1) - 1.0).sq() + sum(2..n + 1, |i| i as f64 * (-x(i - 1) + 2.0 * x(i)).sq())
);
problem!(
    /// VARDIM: variable dimension (dense Hessian).
    vardim, |n| |i| 1.0 - i as f64 / n as f64,
    |x| {
        let s = sum(1..n + 1, |i| i as f64 * (x(i) - 1.0));
        sum(1..n + 1, |i| (x(i) - 1.0).sq()) + s.sq() + s.powi(4)
    }
);
problem!(
    /// WOODS: extended Woods (n multiple of 4).
    woods, |n| |i| if i % 2 == 0 { -1.0 } else { -3.0 },
    |x| sum(1..n / 4 + 1, |i| {
        100.0 * (x(4 * i - 2) - x(4 * i - 3).sq()).sq() + (1.0 - x(4 * i - 3)).sq()
            + 90.0 * (x(4 * i) - x(4 * i - 1).sq()).sq() + (1.0 - x(4 * i - 1)).sq()
            + 10.0 * (x(4 * i - 2) + x(4 * i) - 2.0).sq() + 0.1 * (x(4 * i - 2) - x(4 * i)).sq()
    })
);
problem!(
    /// SCHMVETT: Schmidt and Vetters.
    schmvett, |n| |_| 3.0,
    |x| sum(1..n - 1, |i| {
        -(1.0 / (1.0 + (x(i) - x(i + 1)).sq())) - ((std::f64::consts::PI * x(i + 1) + x(i + 2)) / 2.0).sin()
            - (-((x(i) + x(i + 2)) / x(i + 1) - 2.0).sq()).exp()
    })
);
problem!(
    /// TOINTGSS: Toint's Gaussian.
    tointgss, |n| |_| 3.0,
    |x| sum(1..n - 1, |i| (10.0 / (n + 2) as f64 + x(i + 2).sq())
        * (2.0 - (-(x(i) - x(i + 1)).sq() / (0.1 + x(i + 2).sq())).exp()))
);
