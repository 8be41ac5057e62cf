//! Complementarity constraints `0 ≤ a ⊥ b ≥ 0` and the copies the MPCC driver solves.
use super::{Block, BuildError, Cone, Problem};
use crate::constraint::Relation;
use symx::Expr;

/// Complementarity at a point: see [`Problem::complementarity_report`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ComplementarityReport {
    /// max over pairs of |min(a, b)|.
    pub residual: f64,
    /// Names of the pairs with both sides within the tolerance of zero.
    pub biactive: Vec<String>,
    /// Number of pairs.
    pub pairs: usize,
}

impl Problem {
    /// Adds the complementarity constraint `0 ≤ a ⊥ b ≥ 0` (a ≥ 0, b ≥ 0, a·b = 0).
    ///
    /// It is compiled as an ordinary NLP in the form of Fletcher & Leyffer (2004), "Solving
    /// mathematical programs with complementarity constraints as nonlinear programs",
    /// Optim. Methods Softw. 19(1): rows (or bounds) `a ≥ 0`, `b ≥ 0` and the product row
    /// `a·b ≤ 0` (named `name.a`, `name.b`, `name.ab`). The SQP back end solves this form
    /// directly, its elastic mode absorbing the QPs made degenerate by the product (no
    /// constraint qualification holds at a solution). The pair is recorded:
    /// [`Problem::complementarity_report`] gives the residual and the biactive set.
    pub fn complementarity(&mut self, name: &str, a: Expr, b: Expr) -> Result<(), BuildError> {
        self.subject_to_named(&format!("{name}.a"), a.ge(0.0))?;
        self.subject_to_named(&format!("{name}.b"), b.ge(0.0))?;
        self.subject_to_named(&format!("{name}.ab"), (a * b).le(0.0))?;
        self.complementarity.push((name.to_string(), a, b));
        Ok(())
    }

    /// The n-ary form: every `qᵢ ≥ 0` and at most one of them non-zero, i.e. the pairwise
    /// complementarity `qᵢ ⊥ qⱼ` for i < j (pairs named `name[i,j]`).
    pub fn complementarity_nary(&mut self, name: &str, q: &[Expr]) -> Result<(), BuildError> {
        for i in 0..q.len() {
            for j in i + 1..q.len() {
                self.complementarity(&format!("{name}[{i},{j}]"), q[i], q[j])?;
            }
        }
        Ok(())
    }

    /// Complementarity residual max over pairs of |min(a, b)| (zero iff a ≥ 0, b ≥ 0 and
    /// one of them is zero) at `x`, and the biactive pairs (both a and b ≤ `tol`).
    pub fn complementarity_report(
        &self,
        x: &[f64],
        tol: f64,
    ) -> Result<ComplementarityReport, BuildError> {
        let exprs: Vec<Expr> = self
            .complementarity
            .iter()
            .flat_map(|(_, a, b)| [*a, *b])
            .collect();
        let v = self.evaluate(&exprs, x)?;
        let mut residual: f64 = 0.0;
        let mut biactive = Vec::new();
        for (k, (name, _, _)) in self.complementarity.iter().enumerate() {
            let (a, b) = (v[2 * k], v[2 * k + 1]);
            residual = residual.max(a.min(b).abs());
            if a.abs() <= tol && b.abs() <= tol {
                biactive.push(name.clone());
            }
        }
        Ok(ComplementarityReport {
            residual,
            biactive,
            pairs: self.complementarity.len(),
        })
    }

    /// The complementarity pairs (name, a, b) in the order they were added.
    pub fn complementarity_pairs(&self) -> &[(String, Expr, Expr)] {
        &self.complementarity
    }

    /// A copy for the MPCC driver ([`crate::mpcc`]): the same variables, bounds, initial
    /// point, parameters, rows and pairs, with objective `objective`; without the product
    /// rows `name.ab` of the pairs unless `keep_products`.
    pub(crate) fn mpcc_copy(&self, objective: Expr, keep_products: bool) -> Problem {
        let products: std::collections::HashSet<String> = self
            .complementarity
            .iter()
            .map(|(name, _, _)| format!("{name}.ab"))
            .collect();
        let mut rows = Vec::with_capacity(self.rows.len());
        let mut constraint_blocks = Vec::with_capacity(self.constraint_blocks.len());
        let mut row_map = vec![None; self.rows.len()];
        for b in &self.constraint_blocks {
            if !keep_products && products.contains(&b.name) {
                continue;
            }
            for (k, r) in b.range().enumerate() {
                row_map[r] = Some(rows.len() + k);
            }
            constraint_blocks.push(Block {
                name: b.name.clone(),
                start: rows.len(),
                len: b.len,
            });
            rows.extend_from_slice(&self.rows[b.range()]);
        }
        Problem {
            objective: Some(objective),
            rows,
            constraint_blocks,
            cones: self
                .cones
                .iter()
                .filter_map(|c| row_map[c.row].map(|row| Cone { row, ..c.clone() }))
                .collect(),
            ..self.clone()
        }
    }
}
