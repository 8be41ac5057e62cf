//! Named blocks of entries ([`Block`]), the names of single entries, and the check of a
//! pair of bounds: the vocabulary shared by the builder, the compiled problem and the
//! parameters.
use super::error::BuildError;

/// A named block of consecutive entries (a variable, a parameter or a constraint group).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Block {
    /// The name given when declaring it.
    pub name: String,
    /// First index.
    pub start: usize,
    /// Number of entries.
    pub len: usize,
}

impl Block {
    /// The index range.
    pub fn range(&self) -> std::ops::Range<usize> {
        self.start..self.start + self.len
    }
}

/// Name of entry `i` given named blocks: `name` for a one-entry block, `name[k]` otherwise.
pub(crate) fn row_name(blocks: &[Block], i: usize, fallback: &str) -> String {
    match blocks.iter().find(|b| b.range().contains(&i)) {
        Some(b) if b.len == 1 => b.name.clone(),
        Some(b) => format!("{}[{}]", b.name, i - b.start),
        None => format!("{fallback}[{i}]"),
    }
}

/// `Err` naming `what` if a bound is NaN or `lower > upper`.
pub(crate) fn check_bound(
    what: impl Fn() -> String,
    lower: f64,
    upper: f64,
) -> Result<(), BuildError> {
    for v in [lower, upper] {
        if v.is_nan() {
            return Err(BuildError::NotFinite {
                what: what(),
                value: v,
            });
        }
    }
    if lower > upper {
        return Err(BuildError::InvertedBounds {
            what: what(),
            lower,
            upper,
        });
    }
    Ok(())
}
