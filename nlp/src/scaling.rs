//! Gradient-based NLP scaling (IPOPT's `nlp_scaling_method = gradient-based`).

/// Scale factor for a function whose gradient at x0 has max-norm `grad_max`:
/// `min(1, max_gradient / grad_max)`, bounded below by `min_value`.
pub fn gradient_scale(grad_max: f64, max_gradient: f64, min_value: f64) -> f64 {
    if !grad_max.is_finite() || grad_max <= max_gradient {
        1.0
    } else {
        (max_gradient / grad_max).max(min_value)
    }
}

/// Row scale factors of a CSC Jacobian with `m` rows given its values.
pub fn jacobian_row_scales(
    m: usize,
    jac: &faer::sparse::SymbolicSparseColMat<usize>,
    values: &[f64],
    max_gradient: f64,
    min_value: f64,
    out: &mut [f64],
) {
    let mut row_max = vec![0.0f64; m];
    for c in 0..jac.ncols() {
        for p in jac.col_range(c) {
            let r = jac.row_idx()[p];
            row_max[r] = row_max[r].max(values[p].abs());
        }
    }
    for (o, g) in out.iter_mut().zip(&row_max) {
        *o = gradient_scale(*g, max_gradient, min_value);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales() {
        assert_eq!(gradient_scale(50.0, 100.0, 1e-8), 1.0);
        assert_eq!(gradient_scale(1000.0, 100.0, 1e-8), 0.1);
        assert_eq!(gradient_scale(1e20, 100.0, 1e-8), 1e-8);
    }
}
