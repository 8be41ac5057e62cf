//! Parametric sensitivities of a solution: `dx*/dp`, `dλ*/dp` and the bound multipliers'
//! derivatives, from the KKT system at the solution with the active set held fixed (the
//! approach of sIPOPT: Pirnay, López-Negrete & Biegler, "Optimal sensitivity based on
//! IPOPT", Math. Prog. Comp. 4, 2012; Fiacco 1976).
//!
//! At a solution satisfying the second-order sufficient conditions, strict complementarity
//! and LICQ, differentiating `∇ₓL(x, λ, p) = 0` and the active rows `g_A(x, p) = bound`
//! (active bounds: `x_B` constant) with respect to `p` gives
//!
//! ```text
//! [ H_FF   J_AFᵀ ] [ dx_F ]     [ ∇²ₓₚL_F ]
//! [ J_AF   0     ] [ dλ_A ] = − [ ∂g_A/∂p ],    dx_B = 0,  dλ_inactive = 0,
//! ```
//!
//! with `F` the variables not at an active bound. `∇²ₓₚL` and `∂g/∂p` are derived
//! symbolically from the [`Problem`] and compiled once. The system is factorised by
//! the crate-internal KKT factorisation (`kkt::Kkt`) with the rows and columns of `B` and of the inactive rows replaced by
//! identity blocks, a small regularisation on the active rows that iterative refinement
//! removes, and an inertia check (`n` positive, `m` negative eigenvalues) that fails when
//! the reduced Hessian is not positive definite or the active Jacobian is rank deficient.
//!
//! A bound or row is active when its multiplier exceeds its slack (`z > x − x_l`,
//! `λ > g_u − g`, `−λ > g − g_l`; equality rows and fixed variables always): at an
//! interior-point solution `z·s ≈ μ`, so the two differ by orders of magnitude except at
//! weakly active constraints, where the sensitivity is not defined.
use crate::kkt::{Inertia, Kkt, KktError};
use crate::problem::{BuildError, Problem};
use crate::solution::{Solution, Status};
use symx::{Expr, Function, Matrix, Sparsity};
use thiserror::Error;

/// Why sensitivities could not be computed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SensitivityError {
    /// The problem has no parameters.
    #[error("the problem has no parameters to differentiate with respect to")]
    NoParameters,
    /// A vector of the wrong length.
    #[error("{what}: expected {expected} values, got {got}")]
    Size {
        what: String,
        expected: usize,
        got: usize,
    },
    /// The solution did not converge (sensitivities hold only at a KKT point).
    #[error("the solution's status is {0:?}, not a converged solve")]
    NotConverged(Status),
    /// The KKT matrix has the wrong inertia: the second-order sufficient conditions or
    /// the linear independence of the active constraints fail at the solution.
    #[error(
        "KKT inertia ({positive}, {negative}, {zero}) (positive, negative, zero), expected \
         ({n}, {m}, 0): SOSC or LICQ fails at the solution"
    )]
    Inertia {
        positive: usize,
        negative: usize,
        zero: usize,
        n: usize,
        m: usize,
    },
    /// A parameter value is not finite.
    #[error("parameter value {index} is {value}")]
    NotFinite { index: usize, value: f64 },
    /// The linear solver failed (its message).
    #[error("KKT linear solver: {0}")]
    LinearSolver(String),
    /// Iterative refinement did not reach an accurate solution of the KKT system.
    #[error("KKT solve residual {0:.1e} exceeds 1e-8")]
    Inaccurate(f64),
    /// Differentiating or compiling failed.
    #[error(transparent)]
    Build(#[from] BuildError),
}

impl From<KktError> for SensitivityError {
    fn from(e: KktError) -> Self {
        SensitivityError::LinearSolver(e.to_string())
    }
}

impl From<symx::SymxError> for SensitivityError {
    fn from(e: symx::SymxError) -> Self {
        SensitivityError::Build(e.into())
    }
}

/// Derivatives of a solution with respect to the parameters (`Problem::parameters`
/// order); `[j][i]` is the derivative of entry `i` with respect to parameter `j`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sensitivity {
    /// `∂x*ᵢ/∂pⱼ`.
    pub dx_dp: Vec<Vec<f64>>,
    /// `∂λ*ᵢ/∂pⱼ` (constraint multipliers, [`Solution::lambda`]'s sign).
    pub dlambda_dp: Vec<Vec<f64>>,
    /// `∂z_Lᵢ/∂pⱼ` (non-zero only at active lower bounds).
    pub dz_l_dp: Vec<Vec<f64>>,
    /// `∂z_Uᵢ/∂pⱼ` (non-zero only at active upper bounds). For a fixed variable only
    /// `z_U − z_L` is determined; its derivative goes to the side whose multiplier is
    /// larger at the solution (`z_L` on a tie).
    pub dz_u_dp: Vec<Vec<f64>>,
    /// Rows of g held active (equalities included).
    pub active_rows: Vec<usize>,
    /// Variables held at a bound (fixed variables included).
    pub active_bounds: Vec<usize>,
    /// Inequality rows and bounds that are weakly active (multiplier and slack both below
    /// [`WEAK_ACTIVITY`]): there the solution is not differentiable — a change of p in one
    /// direction activates the constraint and in the other releases it — and the
    /// derivatives computed are those of the side the classification chose.
    pub weakly_active: Vec<String>,
    /// Largest relative residual of the linear solves.
    pub residual: f64,
}

impl Sensitivity {
    /// The first-order prediction `x + Σⱼ (∂x/∂pⱼ) Δpⱼ` of the solution after a parameter
    /// step `dp` (valid while the active set does not change).
    pub fn predict_x(&self, x: &[f64], dp: &[f64]) -> Vec<f64> {
        let mut out = x.to_vec();
        for (col, &d) in self.dx_dp.iter().zip(dp) {
            for (o, c) in out.iter_mut().zip(col) {
                *o += c * d;
            }
        }
        out
    }
}

/// Compiled derivatives of a problem with respect to its parameters, reusable for many
/// solutions: build once with [`ParametricSensitivity::new`], then
/// [`ParametricSensitivity::compute`] at each solution.
pub struct ParametricSensitivity {
    n: usize,
    m: usize,
    np: usize,
    x_l: Vec<f64>,
    x_u: Vec<f64>,
    g_l: Vec<f64>,
    g_u: Vec<f64>,
    hess: (Function, Sparsity),
    jac: (Function, Sparsity),
    lxp: (Function, Sparsity),
    gp: (Function, Sparsity),
    kkt: Kkt,
}

/// Threshold below which both a multiplier and its slack mean "weakly active". An
/// interior-point solution has z·s ≈ μ with a final μ of 1e-11…1e-9, so a weakly active
/// pair sits near √μ ≈ 3e-6…3e-5 (measured: slack 1.1e-5, multiplier 5.5e-6).
pub const WEAK_ACTIVITY: f64 = 1e-4;

/// Regularisation of the active rows in the factorisation (removed by refinement).
const DELTA_C: f64 = 1e-9;

impl ParametricSensitivity {
    /// Differentiates `problem` with respect to its parameters and compiles `∇²ₓₓL`,
    /// `∂g/∂x`, `∇²ₓₚL` and `∂g/∂p` as functions of `(x, p, λ)`.
    pub fn new(problem: &Problem) -> Result<Self, SensitivityError> {
        let parts = problem.parts()?;
        let (x, p) = (parts.variables, parts.parameters);
        if p.is_empty() {
            return Err(SensitivityError::NoParameters);
        }
        let f = problem.objective();
        let g = problem.constraint_expressions();
        let lambda = Matrix::sym_vec("lambda", g.len());
        let lagrangian = g
            .iter()
            .zip(lambda.iter())
            .fold(f, |acc, (&gi, &li)| acc + li * gi);
        let grad_l = symx::gradient(lagrangian, x)?;
        let hess = symx::lagrangian_hessian(f, &g, x, Expr::one(), &lambda)?;
        let jac = symx::jacobian(&g, x)?;
        let lxp = symx::jacobian(&grad_l, p)?;
        let gp = symx::jacobian(&g, p)?;
        let compile = |m: &symx::SparseMatrix| -> Result<(Function, Sparsity), SensitivityError> {
            Ok((
                Function::new(&[x, p, &lambda], &[m.values()])?,
                m.sparsity().clone(),
            ))
        };
        let kkt = Kkt::new(x.len(), g.len(), hess.sparsity(), jac.sparsity())?;
        Ok(ParametricSensitivity {
            n: x.len(),
            m: g.len(),
            np: p.len(),
            x_l: parts.lower.clone(),
            x_u: parts.upper.clone(),
            g_l: parts.rows.iter().map(|r| r.lower).collect(),
            g_u: parts.rows.iter().map(|r| r.upper).collect(),
            hess: compile(&hess)?,
            jac: compile(&jac)?,
            lxp: compile(&lxp)?,
            gp: compile(&gp)?,
            kkt,
        })
    }

    /// The sensitivities at `sol`, a converged solution of the problem with parameter
    /// values `p` (in the order of `Problem::parameters`).
    pub fn compute(&mut self, sol: &Solution, p: &[f64]) -> Result<Sensitivity, SensitivityError> {
        self.check(sol, p)?;
        let (n, m) = (self.n, self.m);
        let [h, j, lxp, gp] = self.derivatives(sol, p)?;
        let bound = self.active_bounds(sol);
        let row = self.active_rows(sol);
        let (h_mod, j_mod) = self.reduced_kkt_values(&h, &j, &bound, &row);
        let (inertia, delta_x) = self.factorize(&h_mod, &j_mod, &bound, &row)?;
        check_inertia(inertia, n, m)?;
        let shift = refinement_shift(delta_x, &bound, &row);
        let lxp_cols = dense_columns(&self.lxp.1, &lxp, self.np);
        let gp_cols = dense_columns(&self.gp.1, &gp, self.np);
        let mut out = Sensitivity {
            dx_dp: Vec::with_capacity(self.np),
            dlambda_dp: Vec::with_capacity(self.np),
            dz_l_dp: Vec::with_capacity(self.np),
            dz_u_dp: Vec::with_capacity(self.np),
            active_rows: (0..m).filter(|&i| row[i]).collect(),
            active_bounds: (0..n).filter(|&i| bound[i].is_some()).collect(),
            weakly_active: self.weakly_active(sol),
            residual: 0.0,
        };
        for (lxp_j, gp_j) in lxp_cols.iter().zip(&gp_cols) {
            let mut rhs = parameter_rhs(lxp_j, gp_j, &bound, &row);
            let residual = self.kkt.solve_shifted(&mut rhs, Some(&shift))?;
            if residual.is_nan() || residual > 1e-8 {
                return Err(SensitivityError::Inaccurate(residual));
            }
            out.residual = out.residual.max(residual);
            let (dxj, dlj) = rhs.split_at(n);
            let (dzl, dzu) = self.bound_multiplier_steps(lxp_j, &h, &j, dxj, dlj, &bound);
            out.dx_dp.push(dxj.to_vec());
            out.dlambda_dp.push(dlj.to_vec());
            out.dz_l_dp.push(dzl);
            out.dz_u_dp.push(dzu);
        }
        Ok(out)
    }

    /// The values at `(sol.x, p, sol.lambda)` of the Lagrangian's Hessian, the
    /// constraints' Jacobian, `∇²ₓₚL` and `∂g/∂p`.
    fn derivatives(&self, sol: &Solution, p: &[f64]) -> Result<[Vec<f64>; 4], SensitivityError> {
        let eval = |f: &Function| -> Result<Vec<f64>, SensitivityError> {
            Ok(f.call(&[&sol.x, p, &sol.lambda])?.swap_remove(0))
        };
        Ok([
            eval(&self.hess.0)?,
            eval(&self.jac.0)?,
            eval(&self.lxp.0)?,
            eval(&self.gp.0)?,
        ])
    }

    /// The Hessian and Jacobian values of K with identity blocks for the bound-active
    /// variables and the inactive rows: their couplings are zeroed.
    fn reduced_kkt_values(
        &self,
        h: &[f64],
        j: &[f64],
        bound: &[Option<Side>],
        row: &[bool],
    ) -> (Vec<f64>, Vec<f64>) {
        let mut h_mod = h.to_vec();
        for_each_entry(&self.hess.1, |k, r, c| {
            if bound[r].is_some() || bound[c].is_some() {
                h_mod[k] = 0.0;
            }
        });
        let mut j_mod = j.to_vec();
        for_each_entry(&self.jac.1, |k, r, c| {
            if !row[r] || bound[c].is_some() {
                j_mod[k] = 0.0;
            }
        });
        (h_mod, j_mod)
    }

    /// The steps of `(z_L, z_U)` from the stationarity rows of the active bounds:
    /// `d(z_U − z_L) = −(H dx + Jᵀ dλ + ∇²ₓₚL)`.
    fn bound_multiplier_steps(
        &self,
        lxp_j: &[f64],
        h: &[f64],
        j: &[f64],
        dxj: &[f64],
        dlj: &[f64],
        bound: &[Option<Side>],
    ) -> (Vec<f64>, Vec<f64>) {
        let n = self.n;
        let mut net = lxp_j.to_vec();
        symmetric_product(&self.hess.1, h, dxj, &mut net);
        for_each_entry(&self.jac.1, |k, r, c| net[c] += j[k] * dlj[r]);
        let (mut dzl, mut dzu) = (vec![0.0; n], vec![0.0; n]);
        for i in 0..n {
            match bound[i] {
                Some(Side::Lower) => dzl[i] = net[i],
                Some(Side::Upper) => dzu[i] = -net[i],
                None => {}
            }
        }
        (dzl, dzu)
    }

    /// Factorises the modified KKT matrix; when an exact zero pivot occurs (a variable
    /// with no curvature ordered before its constraints), retries with a small `δ_x` on
    /// the free variables. Returns the inertia and the `δ_x` used.
    fn factorize(
        &mut self,
        h: &[f64],
        j: &[f64],
        bound: &[Option<Side>],
        row: &[bool],
    ) -> Result<(Inertia, f64), SensitivityError> {
        let dc: Vec<f64> = row.iter().map(|&a| if a { DELTA_C } else { 1.0 }).collect();
        let mut last = KktError::NotFactorized;
        for delta_x in [0.0, 1e-10, 1e-8, 1e-6] {
            let dx: Vec<f64> = bound
                .iter()
                .map(|b| if b.is_some() { 1.0 } else { delta_x })
                .collect();
            match self.kkt.factorize(h, &dx, j, &dc) {
                Ok(inertia) => return Ok((inertia, delta_x)),
                Err(e @ (KktError::ZeroPivot(_) | KktError::NonFinite)) => last = e,
                Err(e) => return Err(e.into()),
            }
        }
        Err(last.into())
    }

    fn check(&self, sol: &Solution, p: &[f64]) -> Result<(), SensitivityError> {
        if !sol.status.is_success() {
            return Err(SensitivityError::NotConverged(sol.status));
        }
        for (what, got, expected) in [
            ("parameter values", p.len(), self.np),
            ("solution x", sol.x.len(), self.n),
            ("solution lambda", sol.lambda.len(), self.m),
            ("solution z_l", sol.z_l.len(), self.n),
            ("solution z_u", sol.z_u.len(), self.n),
        ] {
            if got != expected {
                return Err(SensitivityError::Size {
                    what: what.into(),
                    expected,
                    got,
                });
            }
        }
        if let Some(index) = p.iter().position(|v| !v.is_finite()) {
            return Err(SensitivityError::NotFinite {
                index,
                value: p[index],
            });
        }
        Ok(())
    }

    /// Which bound each variable is held at, if any.
    fn active_bounds(&self, sol: &Solution) -> Vec<Option<Side>> {
        (0..self.n)
            .map(|i| {
                let (x, l, u) = (sol.x[i], self.x_l[i], self.x_u[i]);
                if l == u {
                    Some(if sol.z_l[i] >= sol.z_u[i] {
                        Side::Lower
                    } else {
                        Side::Upper
                    })
                } else if l.is_finite() && sol.z_l[i] > x - l {
                    Some(Side::Lower)
                } else if u.is_finite() && sol.z_u[i] > u - x {
                    Some(Side::Upper)
                } else {
                    None
                }
            })
            .collect()
    }

    /// Names of the weakly active bounds (`x[i] lower`/`upper`) and rows (`g[i] lower`/`upper`).
    fn weakly_active(&self, sol: &Solution) -> Vec<String> {
        let weak = |mult: f64, slack: f64| mult.abs() < WEAK_ACTIVITY && slack < WEAK_ACTIVITY;
        let mut out = Vec::new();
        for i in (0..self.n).filter(|&i| self.x_l[i] < self.x_u[i]) {
            if weak(sol.z_l[i], sol.x[i] - self.x_l[i]) {
                out.push(format!("x[{i}] lower"));
            }
            if weak(sol.z_u[i], self.x_u[i] - sol.x[i]) {
                out.push(format!("x[{i}] upper"));
            }
        }
        for i in (0..self.m).filter(|&i| self.g_l[i] < self.g_u[i]) {
            let lam = sol.lambda[i];
            if weak(lam.min(0.0), sol.g[i] - self.g_l[i]) {
                out.push(format!("g[{i}] lower"));
            }
            if weak(lam.max(0.0), self.g_u[i] - sol.g[i]) {
                out.push(format!("g[{i}] upper"));
            }
        }
        out
    }

    /// Whether each row of g is held active.
    fn active_rows(&self, sol: &Solution) -> Vec<bool> {
        (0..self.m)
            .map(|i| {
                let (g, l, u, lam) = (sol.g[i], self.g_l[i], self.g_u[i], sol.lambda[i]);
                l == u || (u.is_finite() && lam > u - g) || (l.is_finite() && -lam > g - l)
            })
            .collect()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Lower,
    Upper,
}

/// Checks that the reduced KKT matrix has the inertia `(n, m, 0)` of a strict local
/// minimiser satisfying LICQ.
fn check_inertia(inertia: Inertia, n: usize, m: usize) -> Result<(), SensitivityError> {
    let expected = Inertia {
        positive: n,
        negative: m,
        zero: 0,
    };
    if inertia != expected {
        return Err(SensitivityError::Inertia {
            positive: inertia.positive,
            negative: inertia.negative,
            zero: inertia.zero,
            n,
            m,
        });
    }
    Ok(())
}

/// The factor is of K + diag(δ_x on F, −δ_c on active rows); refinement solves the
/// exact system with this shift (−δ_x on the free variables, +δ_c on active rows).
fn refinement_shift(delta_x: f64, bound: &[Option<Side>], row: &[bool]) -> Vec<f64> {
    let n = bound.len();
    let mut shift = vec![0.0; n + row.len()];
    for (s, b) in shift[..n].iter_mut().zip(bound) {
        if b.is_none() {
            *s = -delta_x;
        }
    }
    for (s, &a) in shift[n..].iter_mut().zip(row) {
        if a {
            *s = DELTA_C;
        }
    }
    shift
}

/// The right-hand side `−(∇²ₓₚL, ∂g/∂p)` of one parameter's column, zero on the
/// bound-active variables and the inactive rows.
fn parameter_rhs(lxp_j: &[f64], gp_j: &[f64], bound: &[Option<Side>], row: &[bool]) -> Vec<f64> {
    let n = bound.len();
    let mut rhs = vec![0.0; n + row.len()];
    for i in 0..n {
        if bound[i].is_none() {
            rhs[i] = -lxp_j[i];
        }
    }
    for i in 0..row.len() {
        if row[i] {
            rhs[n + i] = -gp_j[i];
        }
    }
    rhs
}

/// Calls `f(storage index, row, column)` for every stored entry of a CSC pattern.
fn for_each_entry(s: &Sparsity, mut f: impl FnMut(usize, usize, usize)) {
    let (cp, ri) = (s.col_ptr(), s.row_idx());
    for c in 0..s.ncols() {
        for (k, &r) in ri.iter().enumerate().take(cp[c + 1]).skip(cp[c]) {
            f(k, r, c);
        }
    }
}

/// The columns of a sparse `rows × cols` matrix as dense vectors.
fn dense_columns(s: &Sparsity, values: &[f64], cols: usize) -> Vec<Vec<f64>> {
    let mut out = vec![vec![0.0; s.nrows()]; cols];
    for_each_entry(s, |k, r, c| out[c][r] = values[k]);
    out
}

/// `y += H v` for a symmetric `H` stored as its lower triangle.
fn symmetric_product(s: &Sparsity, values: &[f64], v: &[f64], y: &mut [f64]) {
    for_each_entry(s, |k, r, c| {
        y[r] += values[k] * v[c];
        if r != c {
            y[c] += values[k] * v[r];
        }
    });
}
