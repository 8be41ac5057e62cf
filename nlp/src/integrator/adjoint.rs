//! Adjoint sensitivities: `vᵀ ∂x(tf)/∂(x₀, p)` by a backward pass over the steps of the
//! forward integration (the discrete adjoint: the exact derivative of the numerical
//! solution, the transpose of the forward sensitivities up to rounding).
//!
//! The forward pass records each accepted step in a tape: its size and, for DOPRI5, its
//! starting point (the stages are recomputed backward, six `f` evaluations), for SDIRK4
//! its five converged stage points. Backward, each step maps the adjoint `λₙ₊₁` to `λₙ`
//! and accumulates the parameter adjoint. For a Runge–Kutta step with stages
//! `Kᵢ = f(Yᵢ)`, `Yᵢ = zₙ + hΣⱼ≤ᵢ aᵢⱼKⱼ`, `zₙ₊₁ = zₙ + hΣⱼ bⱼKⱼ`, the stage adjoints
//! solve `(I − h aᵢᵢ Jᵢᵀ) μᵢ = h bᵢ λₙ₊₁ + h Σⱼ>ᵢ aⱼᵢ Jⱼᵀ μⱼ` (`Jᵢ = f_x(Yᵢ)`; explicit
//! methods have `aᵢᵢ = 0`), then `λₙ = λₙ₊₁ + Σᵢ Jᵢᵀ μᵢ` and `p̄ += Σᵢ f_p(Yᵢ)ᵀ μᵢ`. The
//! products `Jᵀμ`, `f_pᵀμ` come from one compiled reverse-mode function of `f`; SDIRK4
//! factors `I − hγ J(Yᵢ)` at each stage (the matrix of its forward sensitivities).
use super::dopri::A as DOPRI_A;
use super::level::Level;
use super::lu::DenseLu;
use super::sdirk::{A as SDIRK_A, GAMMA};
use symx::{Expr, Function, Matrix, SymxError};

/// Tape entries per DOPRI5 step: `h`, then `zₙ`.
pub(super) fn dopri_record_len(nx: usize) -> usize {
    1 + nx
}

/// Tape entries per SDIRK4 step: `h`, then the five stage points.
pub(super) fn sdirk_record_len(nx: usize) -> usize {
    1 + 5 * nx
}

/// `(x, p, v) → (f_xᵀ v, f_pᵀ v)` of the ODE (level 0).
pub(super) fn vjp_function(ode: &Level, nx: usize, np: usize) -> Result<Function, SymxError> {
    let x = Matrix::sym_vec("x", nx);
    let p = Matrix::sym_vec("p", np);
    let v = Matrix::sym_vec("v", nx);
    let f = ode.rhs.apply(&[&x, &p])?.remove(0);
    let inputs: Vec<Expr> = x.iter().chain(p.iter()).copied().collect();
    let g = symx::reverse(&f, &inputs, &v)?;
    Function::named(
        "ode_vjp",
        &[("x", &x), ("p", &p), ("v", &v)],
        &[("xbar", &g[..nx]), ("pbar", &g[nx..])],
    )
}

/// The backward pass over a tape of level-0 steps.
pub(super) struct Backward<'a> {
    ode: &'a Level,
    vjp: &'a Function,
    p: &'a [f64],
    nx: usize,
    work: Vec<f64>,
    jac_values: Vec<f64>,
    /// `f_xᵀ v` and `f_pᵀ v` of the last product.
    xbar: Vec<f64>,
    pbar: Vec<f64>,
}

impl<'a> Backward<'a> {
    /// A backward pass for the ODE `ode` (with its Jacobian when the method is SDIRK4).
    pub(super) fn new(ode: &'a Level, vjp: &'a Function, p: &'a [f64], nx: usize) -> Self {
        let jac_work = ode.jacobian.as_ref().map_or(0, |j| j.values.work_size());
        let nnz = ode.jacobian.as_ref().map_or(0, |j| j.entries.len());
        Backward {
            ode,
            vjp,
            p,
            nx,
            work: vec![0.0; vjp.work_size().max(ode.rhs.work_size()).max(jac_work)],
            jac_values: vec![0.0; nnz],
            xbar: vec![0.0; nx],
            pbar: vec![0.0; p.len()],
        }
    }

    /// `f_xᵀ v` and `f_pᵀ v` at `y` into `self.xbar`, `self.pbar`.
    fn product(&mut self, y: &[f64], v: &[f64]) {
        self.vjp
            .eval(
                &[y, self.p, v],
                &mut [&mut self.xbar, &mut self.pbar],
                &mut self.work,
            )
            .expect("sizes fixed at construction");
    }

    /// Maps `lambda` = `λₙ₊₁` to `λₙ` over the DOPRI5 step `record` (`h`, `zₙ`), adding
    /// the step's parameter adjoint to `pbar`.
    pub(super) fn dopri_step(&mut self, record: &[f64], lambda: &mut [f64], pbar: &mut [f64]) {
        let n = self.nx;
        let (h, z) = (record[0], &record[1..]);
        // The six stages, recomputed as the forward step computed them.
        let mut points = vec![0.0; 6 * n];
        let mut k = vec![0.0; 6 * n];
        for s in 0..6 {
            for i in 0..n {
                let mut acc = 0.0;
                for (j, &a) in DOPRI_A[s][..s].iter().enumerate() {
                    acc += a * k[j * n + i];
                }
                points[s * n + i] = z[i] + h * acc;
            }
            let (point, ks) = (&points[s * n..(s + 1) * n], &mut k[s * n..(s + 1) * n]);
            self.ode
                .rhs
                .eval(&[point, self.p], &mut [ks], &mut self.work)
                .expect("sizes fixed at construction");
        }
        // Stage adjoints, last to first: μₛ = h bₛ λ + h Σⱼ>ₛ aⱼₛ Jⱼᵀ μⱼ (stored as Jⱼᵀ μⱼ).
        let mut back = vec![0.0; 6 * n];
        let mut mu = vec![0.0; n];
        for s in (0..6).rev() {
            for i in 0..n {
                let mut acc = DOPRI_A[6][s] * lambda[i];
                for (j, row) in DOPRI_A.iter().enumerate().take(6).skip(s + 1) {
                    acc += row[s] * back[j * n + i];
                }
                mu[i] = h * acc;
            }
            self.product(&points[s * n..(s + 1) * n], &mu);
            back[s * n..(s + 1) * n].copy_from_slice(&self.xbar);
            pbar.iter_mut().zip(&self.pbar).for_each(|(a, b)| *a += b);
        }
        add_stage_adjoints(lambda, &back);
    }

    /// Maps `lambda` = `λₙ₊₁` to `λₙ` over the SDIRK4 step `record` (`h`, the stage
    /// points), adding the step's parameter adjoint to `pbar`.
    pub(super) fn sdirk_step(&mut self, record: &[f64], lambda: &mut [f64], pbar: &mut [f64]) {
        let n = self.nx;
        let (h, points) = (record[0], &record[1..]);
        // The solution is the last stage: its weights are the last row of A and γ.
        let b = [
            SDIRK_A[4][0],
            SDIRK_A[4][1],
            SDIRK_A[4][2],
            SDIRK_A[4][3],
            GAMMA,
        ];
        let mut back = vec![0.0; 5 * n];
        let mut mu = vec![0.0; n];
        let mut lu = DenseLu::default();
        lu.reserve(n, 1);
        for i in (0..5).rev() {
            for e in 0..n {
                let mut acc = b[i] * lambda[e];
                for (j, row) in SDIRK_A.iter().enumerate().skip(i + 1) {
                    acc += row[i] * back[j * n + e];
                }
                mu[e] = h * acc;
            }
            let point = &points[i * n..(i + 1) * n];
            self.ode.iteration_matrix(
                point,
                self.p,
                h * GAMMA,
                &mut self.jac_values,
                &mut self.work,
                lu.matrix.as_mut(),
            );
            lu.factor();
            lu.solve(&mut mu, true);
            self.product(point, &mu);
            back[i * n..(i + 1) * n].copy_from_slice(&self.xbar);
            pbar.iter_mut().zip(&self.pbar).for_each(|(a, b)| *a += b);
        }
        add_stage_adjoints(lambda, &back);
    }
}

/// `λ += Σᵢ Jᵢᵀ μᵢ` (the blocks of `back`).
fn add_stage_adjoints(lambda: &mut [f64], back: &[f64]) {
    let n = lambda.len();
    for block in back.chunks(n.max(1)) {
        lambda.iter_mut().zip(block).for_each(|(l, b)| *l += b);
    }
}
