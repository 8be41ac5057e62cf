//! Small vector measures the core's parts share.

/// max |v_i|.
pub(super) fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, &b| a.max(b.abs()))
}

/// Σ |v_i|.
pub(super) fn one_norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x.abs()).sum()
}

/// No entry is NaN or infinite.
pub(super) fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// The first entry that is NaN or infinite.
pub(super) fn first_non_finite(v: &[f64]) -> Option<usize> {
    v.iter().position(|x| !x.is_finite())
}
