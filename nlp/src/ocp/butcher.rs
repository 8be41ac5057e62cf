//! Explicit Runge–Kutta integration from a Butcher tableau, producing expressions.
//!
//! A tableau `(A, b, c)` with `A` strictly lower triangular defines the step
//! `kᵢ = f(x + h Σⱼ<ᵢ aᵢⱼ kⱼ)`, `x⁺ = x + h Σᵢ bᵢ kᵢ` (Hairer, Nørsett & Wanner, *Solving
//! Ordinary Differential Equations I*, §II.1). The right-hand side is any closure of
//! expressions, so the step is an expression of the initial state (and of whatever the
//! closure captures: controls, parameters, a symbolic step length).
use super::OcpError;
use symx::{Expr, Matrix};

/// The coefficients of an explicit Runge–Kutta method.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ButcherTableau {
    name: String,
    /// `a[i][j]` for `j < i` (row `i` has `i` entries).
    a: Vec<Vec<f64>>,
    b: Vec<f64>,
    c: Vec<f64>,
}

impl ButcherTableau {
    /// A tableau from its coefficients: `a` is `s × s` and strictly lower triangular (an
    /// explicit method), `b` and `c` have length `s ≥ 1`, all finite, and the weights sum
    /// to 1 (order ≥ 1).
    pub fn new(name: &str, a: &[Vec<f64>], b: &[f64], c: &[f64]) -> Result<Self, OcpError> {
        let bad = |why: String| {
            Err(OcpError::Tableau {
                name: name.to_string(),
                why,
            })
        };
        let s = b.len();
        if s == 0 {
            return bad("no stages".into());
        }
        if a.len() != s || c.len() != s {
            return bad(format!(
                "A has {} rows and c {} entries for {s} weights",
                a.len(),
                c.len()
            ));
        }
        let mut lower = Vec::with_capacity(s);
        for (i, row) in a.iter().enumerate() {
            if row.len() != s {
                return bad(format!(
                    "row {i} of A has {} entries, expected {s}",
                    row.len()
                ));
            }
            if let Some(j) = (i..s).find(|&j| row[j] != 0.0) {
                return bad(format!(
                    "a[{i}][{j}] ≠ 0: only explicit methods are supported"
                ));
            }
            lower.push(row[..i].to_vec());
        }
        if a.iter().flatten().chain(b).chain(c).any(|v| !v.is_finite()) {
            return bad("a coefficient is not finite".into());
        }
        if (b.iter().sum::<f64>() - 1.0).abs() > 1e-12 {
            return bad(format!(
                "the weights b sum to {}, not 1",
                b.iter().sum::<f64>()
            ));
        }
        Ok(ButcherTableau {
            name: name.to_string(),
            a: lower,
            b: b.to_vec(),
            c: c.to_vec(),
        })
    }

    /// Explicit (forward) Euler, order 1.
    pub fn euler() -> Self {
        Self::known("euler", &[vec![0.0]], &[1.0], &[0.0])
    }

    /// The explicit midpoint rule (RK2), order 2.
    pub fn midpoint() -> Self {
        Self::known(
            "midpoint",
            &[vec![0.0, 0.0], vec![0.5, 0.0]],
            &[0.0, 1.0],
            &[0.0, 0.5],
        )
    }

    /// Heun's method (explicit trapezoidal rule), order 2.
    pub fn heun() -> Self {
        Self::known(
            "heun",
            &[vec![0.0, 0.0], vec![1.0, 0.0]],
            &[0.5, 0.5],
            &[0.0, 1.0],
        )
    }

    /// The classical fourth-order Runge–Kutta method (RK4).
    pub fn rk4() -> Self {
        Self::known(
            "rk4",
            &[
                vec![0.0, 0.0, 0.0, 0.0],
                vec![0.5, 0.0, 0.0, 0.0],
                vec![0.0, 0.5, 0.0, 0.0],
                vec![0.0, 0.0, 1.0, 0.0],
            ],
            &[1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
            &[0.0, 0.5, 0.5, 1.0],
        )
    }

    /// A tableau by name: `euler`, `midpoint` (or `rk2`), `heun`, `rk4`.
    pub fn by_name(name: &str) -> Result<Self, OcpError> {
        match name.to_ascii_lowercase().as_str() {
            "euler" => Ok(Self::euler()),
            "midpoint" | "rk2" => Ok(Self::midpoint()),
            "heun" => Ok(Self::heun()),
            "rk4" => Ok(Self::rk4()),
            _ => Err(OcpError::Tableau {
                name: name.to_string(),
                why: "unknown method (known: euler, midpoint, rk2, heun, rk4)".into(),
            }),
        }
    }

    fn known(name: &str, a: &[Vec<f64>], b: &[f64], c: &[f64]) -> Self {
        Self::new(name, a, b, c).expect("built-in tableau is valid")
    }

    /// The method's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of stages `s`.
    pub fn stages(&self) -> usize {
        self.b.len()
    }

    /// The weights `b`.
    pub fn weights(&self) -> &[f64] {
        &self.b
    }

    /// The nodes `c`.
    pub fn nodes(&self) -> &[f64] {
        &self.c
    }

    /// One step of length `h` from `x` for `ẋ = f(x)`, as expressions.
    ///
    /// `f` must return a vector of the length of `x`; stages with a zero coefficient add
    /// no term, so e.g. RK4 gives exactly `x + h/6 (k₁ + 2k₂ + 2k₃ + k₄)` in the graph.
    pub fn step(&self, f: &dyn Fn(&Matrix) -> Matrix, x: &Matrix, h: Expr) -> Matrix {
        let mut k: Vec<Matrix> = Vec::with_capacity(self.stages());
        for row in &self.a {
            let mut xi = x.clone();
            for (kj, &aij) in k.iter().zip(row) {
                if aij != 0.0 {
                    xi = &xi + (h * aij) * kj;
                }
            }
            k.push(f(&xi));
        }
        let mut sum: Option<Matrix> = None;
        for (ki, &bi) in k.iter().zip(&self.b) {
            if bi != 0.0 {
                let term = bi * ki;
                sum = Some(match sum {
                    None => term,
                    Some(s) => s + term,
                });
            }
        }
        match sum {
            Some(s) => x + h * s,
            None => x.clone(),
        }
    }

    /// `m` steps of length `h / m` from `x` (`m ≥ 1`).
    pub fn integrate(
        &self,
        f: &dyn Fn(&Matrix) -> Matrix,
        x: &Matrix,
        h: Expr,
        m: usize,
    ) -> Matrix {
        let dt = h / m.max(1) as f64;
        (0..m.max(1)).fold(x.clone(), |xk, _| self.step(f, &xk, dt))
    }
}
