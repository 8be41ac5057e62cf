//! The hierarchy of systems an [`Integrator`](super::Integrator) integrates: the ODE
//! (level 0) and the variational equations of each level (level k + 1).
use faer::MatMut;
use symx::{Expr, Function, Matrix, SymxError};

/// One right-hand side `(z, p) → ż` of the hierarchy (the first `nx` entries of `z` are
/// `x`), with the Jacobian `∂ż/∂z` when an implicit method needs it.
#[derive(Clone, Debug)]
pub(super) struct Level {
    /// `(z, p) → ż`.
    pub(super) rhs: Function,
    /// The state length.
    pub(super) nz: usize,
    /// `∂ż/∂z`, built on demand by [`Level::add_jacobian`].
    pub(super) jacobian: Option<Jacobian>,
}

/// A sparse Jacobian `∂ż/∂z` as a compiled function of `(z, p)` returning its nonzeros.
#[derive(Clone, Debug)]
pub(super) struct Jacobian {
    /// `(z, p) →` the nonzero values, in the order of `entries`.
    pub(super) values: Function,
    /// `(row, column)` of each nonzero.
    pub(super) entries: Vec<(usize, usize)>,
}

impl Level {
    /// The level `ż = zdot(z, p)` (`z` and `p` vectors of symbols).
    pub(super) fn new(
        name: &str,
        z: &[Expr],
        p: &[Expr],
        zdot: &[Expr],
    ) -> Result<Level, SymxError> {
        let rhs = Function::named(name, &[("z", z), ("p", p)], &[("zdot", zdot)])?;
        Ok(Level {
            rhs,
            nz: z.len(),
            jacobian: None,
        })
    }

    /// Builds `∂ż/∂z` by symx AD if not built yet.
    pub(super) fn add_jacobian(&mut self, np: usize) -> Result<(), SymxError> {
        if self.jacobian.is_some() {
            return Ok(());
        }
        let z = Matrix::sym_vec("z", self.nz);
        let p = Matrix::sym_vec("p", np);
        let zdot = self.rhs.apply(&[&z, &p])?.remove(0);
        let jac = symx::jacobian(&zdot, &z)?;
        let values = Function::named(
            "ode_jacobian",
            &[("z", &z), ("p", &p)],
            &[("values", jac.values())],
        )?;
        self.jacobian = Some(Jacobian {
            values,
            entries: symx::sparsity::entries(jac.sparsity()),
        });
        Ok(())
    }

    /// `I − c·∂ż/∂z` at `z` (its first `nz` entries) into `into` (dense, `nz × nz`), with
    /// `values` and `work` as scratch (at least the Jacobian's nonzeros and work size).
    /// The Jacobian must have been built ([`Level::add_jacobian`]).
    pub(super) fn iteration_matrix(
        &self,
        z: &[f64],
        p: &[f64],
        c: f64,
        values: &mut [f64],
        work: &mut [f64],
        mut into: MatMut<'_, f64>,
    ) {
        let jac = self
            .jacobian
            .as_ref()
            .expect("Jacobians built for the implicit method");
        let nnz = jac.entries.len();
        jac.values
            .eval(&[&z[..self.nz], p], &mut [&mut values[..nnz]], work)
            .expect("sizes fixed at construction");
        for col in 0..self.nz {
            for r in 0..self.nz {
                into[(r, col)] = 0.0;
            }
        }
        for (&v, &(r, col)) in values.iter().zip(&jac.entries) {
            into[(r, col)] = -c * v;
        }
        for i in 0..self.nz {
            into[(i, i)] += 1.0;
        }
    }

    /// The variational equations of this level with respect to `(x0, p)`: state
    /// `(z, S)`, `Ṡ = ż_z S + [0 ż_p]`, `S` column-major with `nx + np` columns.
    pub(super) fn variational(&self, nx: usize, np: usize) -> Result<Level, SymxError> {
        let nz = self.nz;
        let m = nx + np;
        let z = Matrix::sym_vec("z", nz);
        let s = Matrix::sym_vec("s", nz * m);
        let p = Matrix::sym_vec("p", np);
        let zdot = self.rhs.apply(&[&z, &p])?.remove(0);
        // Column by column: ṡ_j = ż_z s_j + ∂ż/∂x0_j (zero) or ∂ż/∂p_j.
        let mut out = zdot.clone();
        for j in 0..m {
            let sj = &s[j * nz..(j + 1) * nz];
            let mut tangent = symx::forward(&zdot, &z, sj)?;
            if j >= nx {
                let mut seed = vec![Expr::zero(); np];
                seed[j - nx] = Expr::one();
                let dp = symx::forward(&zdot, &p, &seed)?;
                tangent.iter_mut().zip(dp).for_each(|(t, d)| *t += d);
            }
            out.extend(tangent);
        }
        let state: Vec<Expr> = z.iter().chain(s.iter()).copied().collect();
        Level::new("variational", &state, &p, &out)
    }
}
