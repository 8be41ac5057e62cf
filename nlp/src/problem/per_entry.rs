//! [`PerEntry`]: one bound value for every entry, or one per entry.
use super::error::BuildError;

/// One number for every entry, or one number per entry: the `lower` and `upper` arguments
/// of [`Problem::set_bounds`](crate::Problem::set_bounds).
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
