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

/// Upward scale factor (not an IPOPT rule) for a constraint whose gradient at x0 has
/// max-norm `grad_max`: `min_gradient / grad_max` when `0 < grad_max < min_gradient`,
/// capped at `max_value`; 1 otherwise (a zero gradient at x0 says nothing about the
/// row's scale, so it is left alone).
pub fn gradient_scale_up(grad_max: f64, min_gradient: f64, max_value: f64) -> f64 {
    if min_gradient > 0.0 && grad_max > 0.0 && grad_max.is_finite() && grad_max < min_gradient {
        (min_gradient / grad_max).min(max_value)
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::{gradient_scale, gradient_scale_up};

    #[test]
    fn scales() {
        assert_eq!(gradient_scale(50.0, 100.0, 1e-8), 1.0);
        assert_eq!(gradient_scale(1000.0, 100.0, 1e-8), 0.1);
        assert_eq!(gradient_scale(1e20, 100.0, 1e-8), 1e-8);
        assert_eq!(gradient_scale_up(1e-3, 1e-2, 1e4), 10.0);
        assert_eq!(gradient_scale_up(1e-9, 1e-2, 1e4), 1e4);
        assert_eq!(gradient_scale_up(0.0, 1e-2, 1e4), 1.0);
        assert_eq!(gradient_scale_up(0.5, 1e-2, 1e4), 1.0);
        assert_eq!(gradient_scale_up(1e-3, 0.0, 1e4), 1.0);
    }
}
