//! Variable bounds: per-entry bound values ([`PerEntry`]) and the detection of simple
//! bounds (constraint rows on a single variable turned into bounds, as CasADi's
//! `detect_simple_bounds` option does).
pub use super::per_entry::PerEntry;

use super::block::{check_bound, row_name, Block};
use super::{BuildError, Problem};

/// The problem as compiled: variable bounds and the rows of g that remain after simple
/// bound detection (all written rows when it is off).
pub(crate) struct Layout {
    /// Variable bounds (intersected with the detected rows).
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    /// For each row of g, its index among the written rows.
    pub rows: Vec<usize>,
    /// Constraint groups over the rows of g (groups left without rows are dropped).
    pub blocks: Vec<Block>,
    /// For each written row, its row of g (None for a row turned into a bound).
    pub row_of: Vec<Option<usize>>,
}

/// A constraint row `lo ≤ a·xⱼ + b ≤ hi` on a single variable, as a bound of `xⱼ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SimpleBound {
    /// The variable's index j.
    pub var: usize,
    /// The coefficient a (finite, nonzero).
    pub scale: f64,
    /// The constant b.
    pub offset: f64,
}

impl SimpleBound {
    /// The bounds of xⱼ that `lo ≤ a·xⱼ + b ≤ hi` means.
    fn variable_bounds(&self, lo: f64, hi: f64) -> (f64, f64) {
        let (l, u) = (
            (lo - self.offset) / self.scale,
            (hi - self.offset) / self.scale,
        );
        if self.scale > 0.0 {
            (l, u)
        } else {
            (u, l)
        }
    }
}

/// How deep [`Problem::affine_in_one_variable`] looks into a row's expression: enough for
/// `a·(x − c)/d + e` as users write boundary values, without walking large graphs.
const AFFINE_DEPTH: usize = 8;

impl Problem {
    /// The variable written row `i` is on, when detection is on and the row is affine in a
    /// single variable (`lo ≤ a·xⱼ + b ≤ hi`, `a ≠ 0`, constants only).
    pub(crate) fn simple_bound_of(&self, i: usize) -> Option<usize> {
        self.simple_bound(i).map(|b| b.var)
    }

    /// Row `i` as a bound of one variable, when detection is on and the row is affine in
    /// a single variable with constant coefficients (as CasADi's `detect_simple_bounds`
    /// treats `x − 1`, `2·x − 1` or `3 − x`).
    pub(crate) fn simple_bound(&self, i: usize) -> Option<SimpleBound> {
        if !self.detect_simple_bounds {
            return None;
        }
        let (var, scale, offset) = self.affine_in_one_variable(self.rows[i].expr, AFFINE_DEPTH)?;
        let var = var?;
        (scale != 0.0 && scale.is_finite() && offset.is_finite()).then_some(SimpleBound {
            var,
            scale,
            offset,
        })
    }

    /// `e` as `a·xⱼ + b` with constant a, b (`None` for j when `e` is a constant), looking
    /// at most `depth` operations deep; `None` when it is not of that form.
    fn affine_in_one_variable(
        &self,
        e: symx::Expr,
        depth: usize,
    ) -> Option<(Option<usize>, f64, f64)> {
        use symx::Op;
        if let Some(c) = e.value() {
            return Some((None, 0.0, c));
        }
        if e.is_symbol() {
            // A parameter is not a variable: a row on it stays a row.
            return self
                .variable_index
                .get(&e.id())
                .map(|&j| (Some(j), 1.0, 0.0));
        }
        if depth == 0 {
            return None;
        }
        let args = e.operands();
        let sub = |k: usize| self.affine_in_one_variable(args[k], depth - 1);
        let same = |u: Option<usize>, v: Option<usize>| match (u, v) {
            (Some(a), Some(b)) if a != b => None,
            _ => Some(u.or(v)),
        };
        match e.op() {
            Op::Neg => sub(0).map(|(j, a, b)| (j, -a, -b)),
            Op::Add | Op::Sub => {
                let ((j, a, b), (k, c, d)) = (sub(0)?, sub(1)?);
                let sign = if e.op() == Op::Add { 1.0 } else { -1.0 };
                Some((same(j, k)?, a + sign * c, b + sign * d))
            }
            Op::Mul => match (sub(0)?, sub(1)?) {
                ((None, _, c), (j, a, b)) | ((j, a, b), (None, _, c)) => Some((j, c * a, c * b)),
                _ => None,
            },
            Op::Div => match (sub(0)?, sub(1)?) {
                ((j, a, b), (None, _, c)) if c != 0.0 => Some((j, a / c, b / c)),
                _ => None,
            },
            _ => None,
        }
    }

    /// Applies simple bound detection: each row on a single variable intersects that
    /// variable's bounds; an empty intersection is an error naming both.
    pub(crate) fn layout(&self) -> Result<Layout, BuildError> {
        let (mut lower, mut upper) = (self.lower.clone(), self.upper.clone());
        let mut rows = Vec::with_capacity(self.rows.len());
        let mut row_of = Vec::with_capacity(self.rows.len());
        for (i, row) in self.rows.iter().enumerate() {
            match self.simple_bound(i) {
                Some(bound) => {
                    let j = bound.var;
                    let (row_lo, row_hi) = bound.variable_bounds(row.lower, row.upper);
                    let (lo, hi) = (lower[j].max(row_lo), upper[j].min(row_hi));
                    check_bound(
                        || {
                            format!(
                                "bounds of variable '{}' (with constraint '{}')",
                                self.variable_name(j),
                                row_name(&self.constraint_blocks, i, "g")
                            )
                        },
                        lo,
                        hi,
                    )?;
                    (lower[j], upper[j]) = (lo, hi);
                    row_of.push(None);
                }
                None => {
                    row_of.push(Some(rows.len()));
                    rows.push(i);
                }
            }
        }
        let mut blocks = Vec::with_capacity(self.constraint_blocks.len());
        for b in &self.constraint_blocks {
            let kept: Vec<usize> = b.range().filter_map(|i| row_of[i]).collect();
            if let Some(&start) = kept.first() {
                blocks.push(Block {
                    name: b.name.clone(),
                    start,
                    len: kept.len(),
                });
            }
        }
        Ok(Layout {
            lower,
            upper,
            rows,
            blocks,
            row_of,
        })
    }
}
