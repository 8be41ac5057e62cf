//! Barrier-parameter updates: monotone Fiacco–McCormick and adaptive oracles.

use crate::options::IpmOptions;

/// Smallest μ the monotone rule may reach, IPOPT's (IpMonotoneMuUpdate):
/// min(tol, compl_inf_tol · s_f) / (barrier_tol_factor + 1), with s_f the objective's
/// scale factor. μ lives in the scaled problem while `compl_inf_tol` bounds the
/// *unscaled* complementarity (scaled / s_f), hence the factor: with s_f = 2.2e-7 a floor
/// of min(tol, compl_inf_tol)/(κ_ε + 1) = 9.1e-10 held the unscaled complementarity at
/// ≈ 4e-3 > 1e-4 and the solve could not succeed (nlp/tests/objective_scaling.rs).
pub(crate) fn mu_floor(opts: &IpmOptions, obj_scale: f64) -> f64 {
    opts.tol.min(opts.compl_inf_tol * obj_scale) / (opts.barrier_tol_factor + 1.0)
}

/// Smallest μ of the adaptive rule's oracle: max(mu_min, 1e-2 · tol), lowered to
/// ½ · compl_inf_tol · s_f when the objective is scaled down that far (IPOPT's
/// IpAdaptiveMuUpdate lowers its default mu_min to ½ · min(tol, compl_inf_tol · s_f)).
pub(crate) fn mu_floor_adaptive(opts: &IpmOptions, obj_scale: f64) -> f64 {
    opts.mu_min
        .max(opts.tol * 1e-2)
        .min(0.5 * opts.compl_inf_tol * obj_scale)
}

/// Next monotone barrier parameter: max(floor, min(κ_μ μ, μ^θ_μ)).
pub(crate) fn monotone_next(mu: f64, opts: &IpmOptions, obj_scale: f64) -> f64 {
    mu_floor(opts, obj_scale)
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
        assert!((monotone_next(0.1, &o, 1.0) - 0.02).abs() < 1e-15);
        // superlinear regime: 1e-4^1.5 = 1e-6 < 0.2e-4
        assert!((monotone_next(1e-4, &o, 1.0) - 1e-6).abs() < 1e-18);
        assert!(monotone_next(1e-12, &o, 1.0) >= mu_floor(&o, 1.0));
        // Unscaled objective: min(1e-8, 1e-4)/11. Objective scaled by 1e-7: the floor
        // follows compl_inf_tol · 1e-7 = 1e-11 (/11).
        assert!((mu_floor(&o, 1.0) - 1e-8 / 11.0).abs() < 1e-22);
        assert!((mu_floor(&o, 1e-7) - 1e-11 / 11.0).abs() < 1e-25);
        assert_eq!(mu_floor_adaptive(&o, 1.0), 1e-10);
        assert!((mu_floor_adaptive(&o, 1e-7) - 5e-12).abs() < 1e-26);
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
