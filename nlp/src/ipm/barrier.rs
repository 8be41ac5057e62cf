//! Barrier-parameter updates: monotone Fiacco–McCormick and adaptive oracles.

use crate::options::IpmOptions;

/// Smallest μ the monotone rule may reach: IPOPT uses
/// max(mu_min, min(tol, compl_inf_tol) / (barrier_tol_factor + 1)).
pub(crate) fn mu_floor(opts: &IpmOptions) -> f64 {
    opts.mu_min
        .max(opts.tol.min(opts.compl_inf_tol) / (opts.barrier_tol_factor + 1.0))
}

/// Next monotone barrier parameter: max(floor, min(κ_μ μ, μ^θ_μ)).
pub(crate) fn monotone_next(mu: f64, opts: &IpmOptions) -> f64 {
    mu_floor(opts)
        .max((opts.mu_linear_decrease_factor * mu).min(mu.powf(opts.mu_superlinear_decrease_power)))
}

/// Fraction-to-the-boundary parameter τ = max(τ_min, 1 − μ).
pub(crate) fn tau(mu: f64, opts: &IpmOptions) -> f64 {
    opts.tau_min.max(1.0 - mu)
}

/// LOQO's rule: μ = σ·avg with σ = 0.1·min(0.05·(1−ξ)/ξ, 2)³, ξ = min/avg complementarity.
pub(crate) fn loqo_mu(avg: f64, min: f64) -> f64 {
    if avg <= 0.0 {
        return 0.0;
    }
    let xi = (min / avg).clamp(1e-300, 1.0);
    let s = (0.05 * (1.0 - xi) / xi).min(2.0);
    0.1 * s * s * s * avg
}

/// Mehrotra's probing rule: σ = (μ_aff/avg)³, μ = σ·avg.
pub(crate) fn probing_mu(avg: f64, avg_affine: f64) -> f64 {
    if avg <= 0.0 {
        return 0.0;
    }
    let r = (avg_affine / avg).clamp(0.0, 1.0);
    r * r * r * avg
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monotone_rule() {
        let o = IpmOptions::default();
        assert!((monotone_next(0.1, &o) - 0.02).abs() < 1e-15);
        // superlinear regime: 1e-4^1.5 = 1e-6 < 0.2e-4
        assert!((monotone_next(1e-4, &o) - 1e-6).abs() < 1e-18);
        assert!(monotone_next(1e-12, &o) >= mu_floor(&o));
        assert_eq!(tau(0.1, &o), 0.99);
    }

    #[test]
    fn oracles() {
        // perfectly centred: ξ = 1, σ = 0
        assert_eq!(loqo_mu(1.0, 1.0), 0.0);
        // badly centred: σ capped at 0.1·8
        assert!((loqo_mu(1.0, 1e-6) - 0.8).abs() < 1e-12);
        assert!((probing_mu(1.0, 0.5) - 0.125).abs() < 1e-15);
    }
}
