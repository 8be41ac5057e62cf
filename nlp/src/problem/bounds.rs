//! Variable bounds: per-entry bound values ([`PerEntry`]) and the detection of simple
//! bounds (constraint rows on a single variable turned into bounds, as CasADi's
//! `detect_simple_bounds` option does).
use super::{check_bound, row_name, Block, BuildError, Problem};

/// One number for every entry, or one number per entry: the `lower` and `upper` arguments
/// of [`Problem::set_bounds`].
///
/// Built implicitly by `From`: `0.0`, `&[0.0, 1.0]`, `&vec`, `&v[..]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PerEntry<'a> {
    /// The same value for every entry.
    All(f64),
    /// Entry k gets value k; the length must match.
    Each(&'a [f64]),
}

impl From<f64> for PerEntry<'_> {
    fn from(v: f64) -> Self {
        PerEntry::All(v)
    }
}
impl<'a> From<&'a [f64]> for PerEntry<'a> {
    fn from(v: &'a [f64]) -> Self {
        PerEntry::Each(v)
    }
}
impl<'a, const N: usize> From<&'a [f64; N]> for PerEntry<'a> {
    fn from(v: &'a [f64; N]) -> Self {
        PerEntry::Each(v)
    }
}
impl<'a> From<&'a Vec<f64>> for PerEntry<'a> {
    fn from(v: &'a Vec<f64>) -> Self {
        PerEntry::Each(v)
    }
}

impl PerEntry<'_> {
    /// Checks that there is a value for each of `n` entries; `what` names the argument.
    pub(crate) fn check_len(&self, n: usize, what: &str) -> Result<(), BuildError> {
        match self {
            PerEntry::Each(v) if v.len() != n => Err(BuildError::Size {
                what: what.to_string(),
                expected: n,
                got: v.len(),
            }),
            _ => Ok(()),
        }
    }

    /// The value of entry `k` (after [`PerEntry::check_len`]).
    pub(crate) fn get(&self, k: usize) -> f64 {
        match self {
            PerEntry::All(v) => *v,
            PerEntry::Each(v) => v[k],
        }
    }
}

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

impl Problem {
    /// The variable written row `i` is on, when detection is on and the row is a single
    /// variable (`lo ≤ xⱼ ≤ hi`).
    pub(crate) fn simple_bound_of(&self, i: usize) -> Option<usize> {
        if !self.detect_simple_bounds {
            return None;
        }
        self.variable_index.get(&self.rows[i].expr.id()).copied()
    }

    /// Applies simple bound detection: each row on a single variable intersects that
    /// variable's bounds; an empty intersection is an error naming both.
    pub(crate) fn layout(&self) -> Result<Layout, BuildError> {
        let (mut lower, mut upper) = (self.lower.clone(), self.upper.clone());
        let mut rows = Vec::with_capacity(self.rows.len());
        let mut row_of = Vec::with_capacity(self.rows.len());
        for (i, row) in self.rows.iter().enumerate() {
            match self.simple_bound_of(i) {
                Some(j) => {
                    let (lo, hi) = (lower[j].max(row.lower), upper[j].min(row.upper));
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
