//! The barrier-parameter update as one part, [`MuUpdate`]: IPOPT's monotone
//! Fiacco–McCormick rule (Wächter & Biegler 2006, eq. (7)) and the adaptive rule (free
//! mode with the LOQO, probing or quality-function oracle, globalised by IPOPT's
//! KKT-error test, falling back to the monotone rule). It owns μ, the
//! fraction-to-the-boundary parameter τ, the free/fixed mode, the reference errors and
//! the oracle's scratch. The core calls it once per iteration: [`MuUpdate::monotone`]
//! before the factorisation (monotone strategy), [`MuUpdate::adaptive_mode`] and then
//! [`MuUpdate::set_free_mu`] after it (adaptive strategy; the oracle's steps are solves
//! with the factorised KKT matrix, which the core does).

use crate::ipm::quality::{Norms, Pairs, QualityData, QualitySettings};
use crate::options::{IpmOptions, MuOracle, MuStrategy};

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

/// The options of the μ rules, copied from [`IpmOptions`] with the floors for the
/// problem's objective scale (so the part needs no options at each call).
#[derive(Clone, Copy, Debug)]
struct Rules {
    strategy: MuStrategy,
    oracle: MuOracle,
    /// κ_μ of eq. (7).
    linear_decrease: f64,
    /// θ_μ of eq. (7).
    superlinear_power: f64,
    /// κ_ε: the barrier problem is solved to E_μ ≤ κ_ε μ.
    barrier_tol_factor: f64,
    fast_decrease: bool,
    tau_min: f64,
    mu_max: f64,
    /// [`mu_floor`].
    floor: f64,
    /// [`mu_floor_adaptive`].
    floor_adaptive: f64,
    monotone_init_factor: f64,
    kkterror_red_fact: f64,
    kkterror_red_iters: usize,
    quality: QualitySettings,
}

/// What the adaptive rule's globalisation decided for this iteration
/// ([`MuUpdate::adaptive_mode`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum AdaptiveMode {
    /// Progress was insufficient in free mode: switched to the fixed mode with μ from
    /// the average complementarity (the filter must be emptied).
    SwitchedToFixed,
    /// Fixed mode without sufficient progress: the monotone rule applies.
    Fixed,
    /// Free mode: τ is set, the oracle chooses μ ([`MuUpdate::set_free_mu`]).
    Free,
}

/// The barrier-parameter update (see the module doc): μ, τ and the adaptive rule's
/// state.
#[derive(Clone, Debug)]
pub(crate) struct MuUpdate {
    mu: f64,
    tau: f64,
    rules: Rules,
    /// The adaptive rule is in free mode (an oracle chooses μ).
    free_mode: bool,
    /// The adaptive rule's reference KKT errors (the last `kkterror_red_iters`).
    kkt_refs: Vec<f64>,
    /// The quality-function oracle's complementarity pairs (scratch).
    pairs: Pairs,
}

impl Default for MuUpdate {
    fn default() -> Self {
        MuUpdate::new(
            0.1,
            MuStrategy::Monotone,
            &IpmOptions::default(),
            1.0,
            Vec::new(),
            Pairs::default(),
        )
    }
}

impl MuUpdate {
    /// The update starting from `mu_init` with `strategy` for a problem whose objective
    /// is scaled by `obj_scale`; `kkt_refs` and `pairs` are reused scratch (cleared).
    pub(crate) fn new(
        mu_init: f64,
        strategy: MuStrategy,
        opts: &IpmOptions,
        obj_scale: f64,
        mut kkt_refs: Vec<f64>,
        mut pairs: Pairs,
    ) -> MuUpdate {
        kkt_refs.clear();
        pairs.clear();
        let rules = Rules {
            strategy,
            oracle: opts.mu_oracle,
            linear_decrease: opts.mu_linear_decrease_factor,
            superlinear_power: opts.mu_superlinear_decrease_power,
            barrier_tol_factor: opts.barrier_tol_factor,
            fast_decrease: opts.mu_allow_fast_monotone_decrease,
            tau_min: opts.tau_min,
            mu_max: opts.mu_max,
            floor: mu_floor(opts, obj_scale),
            floor_adaptive: mu_floor_adaptive(opts, obj_scale),
            monotone_init_factor: opts.adaptive_mu_monotone_init_factor,
            kkterror_red_fact: opts.adaptive_mu_kkterror_red_fact,
            kkterror_red_iters: opts.adaptive_mu_kkterror_red_iters,
            quality: QualitySettings::from_options(opts),
        };
        MuUpdate {
            mu: mu_init,
            tau: tau(mu_init, opts),
            rules,
            free_mode: strategy == MuStrategy::Adaptive,
            kkt_refs,
            pairs,
        }
    }

    /// The scratch vectors, for a later run.
    pub(crate) fn into_scratch(self) -> (Vec<f64>, Pairs) {
        (self.kkt_refs, self.pairs)
    }

    /// The barrier parameter μ.
    pub(crate) fn mu(&self) -> f64 {
        self.mu
    }

    /// The fraction-to-the-boundary parameter τ.
    pub(crate) fn tau(&self) -> f64 {
        self.tau
    }

    /// The strategy (monotone or adaptive).
    pub(crate) fn strategy(&self) -> MuStrategy {
        self.rules.strategy
    }

    /// The oracle of the adaptive strategy.
    pub(crate) fn oracle(&self) -> MuOracle {
        self.rules.oracle
    }

    /// The adaptive rule is in free mode (the soft restoration then measures the
    /// error at μ = 0).
    pub(crate) fn free_mode(&self) -> bool {
        self.free_mode
    }

    /// μ is at the monotone rule's floor (to a relative 1e-12).
    pub(crate) fn at_floor(&self) -> bool {
        self.mu <= self.rules.floor * (1.0 + 1e-12)
    }

    /// The monotone rule (Wächter & Biegler 2006, Algorithm A step A-3): while the
    /// barrier problem's error `barrier_error(μ)` is at most κ_ε μ (or once when
    /// `force`, after a tiny step), μ ← max(floor, min(κ_μ μ, μ^θ_μ)) and τ ← max(τ_min,
    /// 1 − μ); several decreases in one call only with `mu_allow_fast_monotone_decrease`.
    /// Returns whether μ changed (the filter must then be emptied).
    pub(crate) fn monotone(
        &mut self,
        force: bool,
        mut barrier_error: impl FnMut(f64) -> f64,
    ) -> bool {
        let r = self.rules;
        let mut first = true;
        let mut changed = false;
        loop {
            if self.mu <= r.floor {
                return changed;
            }
            if !(force && first) && barrier_error(self.mu) > r.barrier_tol_factor * self.mu {
                return changed;
            }
            first = false;
            self.mu = r
                .floor
                .max((r.linear_decrease * self.mu).min(self.mu.powf(r.superlinear_power)));
            self.tau = r.tau_min.max(1.0 - self.mu);
            changed = true;
            if !r.fast_decrease {
                return changed;
            }
        }
    }

    /// The adaptive rule's globalisation (IPOPT's AdaptiveMuUpdate::CheckSufficientProgress)
    /// for an iterate with primal-dual error `pd_error` (at μ = 0), average
    /// complementarity `avg` and optimality error `e0`: progress is sufficient while
    /// fewer than `adaptive_mu_kkterror_red_iters` references exist, else when
    /// `pd_error` is below `adaptive_mu_kkterror_red_fact` times one of them. In free
    /// mode τ becomes max(τ_min, 1 − e0) and `pd_error` a reference.
    pub(crate) fn adaptive_mode(&mut self, pd_error: f64, avg: f64, e0: f64) -> AdaptiveMode {
        let r = self.rules;
        let sufficient = self.kkt_refs.len() < r.kkterror_red_iters
            || self
                .kkt_refs
                .iter()
                .any(|&k| pd_error <= r.kkterror_red_fact * k);
        if !sufficient {
            if !self.free_mode {
                return AdaptiveMode::Fixed;
            }
            self.free_mode = false;
            self.mu = (r.monotone_init_factor * avg).clamp(r.floor, r.mu_max);
            self.tau = r.tau_min.max(1.0 - self.mu);
            return AdaptiveMode::SwitchedToFixed;
        }
        self.free_mode = true;
        if self.kkt_refs.len() >= r.kkterror_red_iters {
            self.kkt_refs.remove(0);
        }
        self.kkt_refs.push(pd_error);
        self.tau = r.tau_min.max(1.0 - e0);
        AdaptiveMode::Free
    }

    /// Free mode: μ ← the oracle's `mu` clamped to [floor, mu_max]. Returns whether μ
    /// changed (the filter must then be emptied).
    pub(crate) fn set_free_mu(&mut self, mu: f64) -> bool {
        let mu = mu.clamp(self.rules.floor_adaptive, self.rules.mu_max);
        let changed = mu != self.mu;
        self.mu = mu;
        changed
    }

    /// The quality-function oracle's pairs, to be filled by the core with the affine and
    /// centring steps (take them out with `std::mem::take`, give them back with
    /// [`MuUpdate::quality_function_mu`]).
    pub(crate) fn pairs_mut(&mut self) -> &mut Pairs {
        &mut self.pairs
    }

    /// The quality-function oracle (`crate::ipm::quality`) on `pairs` (kept as scratch),
    /// with the infeasibilities' norms `dual` and `primal` and the average
    /// complementarity `avg`: μ = σ·avg with σ minimising the quality function, `None`
    /// when the pairs lack their centring steps (a failed solve) or μ is not finite.
    pub(crate) fn quality_function_mu(
        &mut self,
        pairs: Pairs,
        dual: Norms,
        primal: Norms,
        avg: f64,
    ) -> Option<f64> {
        self.pairs = pairs;
        let p = &self.pairs;
        let complete = p.ds_cen.len() == p.ds_aff.len();
        let data = QualityData {
            pairs: p,
            dual,
            primal,
            tau: self.tau,
        };
        let r = &self.rules;
        let sigma =
            complete.then(|| data.choose_sigma(avg, r.floor_adaptive, r.mu_max, &r.quality));
        let mu = sigma? * avg;
        mu.is_finite().then_some(mu)
    }
}

#[cfg(test)]
mod tests {
    use super::{loqo_mu, mu_floor, mu_floor_adaptive, probing_mu, tau, AdaptiveMode, MuUpdate};
    use crate::ipm::quality::{Norms, Pairs, QualityData, QualitySettings};
    use crate::options::{IpmOptions, MuStrategy};

    #[test]
    fn floors_and_tau() {
        let o = IpmOptions::default();
        // Unscaled objective: min(1e-8, 1e-4)/11. Objective scaled by 1e-7: the floor
        // follows compl_inf_tol · 1e-7 = 1e-11 (/11).
        assert!((mu_floor(&o, 1.0) - 1e-8 / 11.0).abs() < 1e-22);
        assert!((mu_floor(&o, 1e-7) - 1e-11 / 11.0).abs() < 1e-25);
        assert_eq!(mu_floor_adaptive(&o, 1.0), 1e-10);
        assert!((mu_floor_adaptive(&o, 1e-7) - 5e-12).abs() < 1e-26);
        assert_eq!(tau(0.1, &o), 0.99);
    }

    fn monotone(o: &IpmOptions, mu: f64) -> MuUpdate {
        MuUpdate::new(
            mu,
            MuStrategy::Monotone,
            o,
            1.0,
            Vec::new(),
            Pairs::default(),
        )
    }

    /// Wächter & Biegler 2006, eq. (7): μ⁺ = max(ε_tol/10, min(κ_μ μ, μ^θ_μ)) with
    /// κ_μ = 0.2, θ_μ = 1.5 (IPOPT's floor min(tol, compl_inf_tol)/(κ_ε + 1) in place of
    /// ε_tol/10), applied once E_μ ≤ κ_ε μ, κ_ε = 10; τ = max(τ_min, 1 − μ⁺).
    #[test]
    fn monotone_rule_follows_eq_7() {
        let o = IpmOptions::default();
        let mut m = monotone(&o, 0.1);
        // E_μ = 2 > κ_ε μ = 1: no decrease, the error is tested at μ = 0.1.
        let mut tested = Vec::new();
        assert!(!m.monotone(false, |mu| {
            tested.push(mu);
            2.0
        }));
        assert_eq!((m.mu(), tested), (0.1, vec![0.1]));
        // E_μ = 0.5 ≤ 1: linear regime, 0.2 · 0.1 = 0.02 < 0.1^1.5 = 0.0316; τ = 0.99
        // (τ_min) since 1 − 0.02 = 0.98 < 0.99. Fast decrease is on by default: the
        // rule tests again at 0.02 (E = 0.5 > 0.2) and stops.
        let mut tested = Vec::new();
        assert!(m.monotone(false, |mu| {
            tested.push(mu);
            0.5
        }));
        assert!((m.mu() - 0.02).abs() < 1e-17);
        assert_eq!(m.tau(), 0.99);
        assert_eq!(tested.len(), 2);
        // Superlinear regime: 1e-4^1.5 = 1e-6 < 0.2 · 1e-4; without fast decrease one
        // step only even though the error is 0.
        let slow = IpmOptions {
            mu_allow_fast_monotone_decrease: false,
            ..IpmOptions::default()
        };
        let mut m = monotone(&slow, 1e-4);
        assert!(m.monotone(false, |_| 0.0));
        assert!((m.mu() - 1e-6).abs() < 1e-20);
        // Fast decrease with error 0 runs down to the floor 1e-8/11 and stops there:
        // 1e-6 → 1e-9 (1e-6^1.5) → floor (1e-9^1.5 = 3.2e-14 < floor).
        let mut m = monotone(&o, 1e-6);
        assert!(m.monotone(false, |_| 0.0));
        assert_eq!(m.mu(), mu_floor(&o, 1.0));
        assert!(m.at_floor());
        assert!(!m.monotone(true, |_| 0.0), "no decrease below the floor");
        // `force` (after a tiny step) decreases once without testing the error.
        let mut m = monotone(&slow, 0.1);
        assert!(m.monotone(true, |_| panic!("forced: not tested")));
        assert!((m.mu() - 0.02).abs() < 1e-17);
    }

    #[test]
    fn adaptive_globalisation() {
        // IPOPT's defaults: 4 references, reduction factor 0.9999, monotone init 0.8.
        let o = IpmOptions::default();
        let mut m = MuUpdate::new(
            0.1,
            MuStrategy::Adaptive,
            &o,
            1.0,
            Vec::new(),
            Pairs::default(),
        );
        assert!(m.free_mode());
        // Fewer than 4 references: free mode, τ = max(0.99, 1 − e0).
        for (k, err) in [10.0, 9.0, 8.0, 7.0].into_iter().enumerate() {
            assert_eq!(m.adaptive_mode(err, 1.0, 0.001), AdaptiveMode::Free, "{k}");
        }
        assert!((m.tau() - 0.999).abs() < 1e-15);
        // 7.5 ≤ 0.9999 · 8: sufficient (the oldest reference 10 is dropped).
        assert_eq!(m.adaptive_mode(7.5, 1.0, 0.5), AdaptiveMode::Free);
        assert_eq!(m.tau(), 0.99);
        // The oracle's μ is clamped to [max(mu_min, 1e-2 tol), mu_max].
        assert!(m.set_free_mu(1e-20));
        assert_eq!(m.mu(), 1e-10);
        assert!(!m.set_free_mu(1e-30), "already at the floor");
        // 9 > 0.9999 · max(9, 8, 7, 7.5): insufficient, switch to the fixed mode with
        // μ = 0.8 · avg = 0.4 and τ = max(0.99, 0.6).
        assert_eq!(
            m.adaptive_mode(9.0, 0.5, 0.5),
            AdaptiveMode::SwitchedToFixed
        );
        assert!(!m.free_mode());
        assert_eq!((m.mu(), m.tau()), (0.4, 0.99));
        // Still insufficient: the monotone rule applies; sufficient again: free mode.
        assert_eq!(m.adaptive_mode(9.0, 0.5, 0.5), AdaptiveMode::Fixed);
        assert_eq!(m.adaptive_mode(1.0, 0.5, 0.5), AdaptiveMode::Free);
        assert!(m.free_mode());
    }

    /// The quality-function oracle on a hand-made iterate of two complementarity pairs
    /// (s, z) = (1, 1) and (1, 4), average 2.5: σ is the minimiser of the quality
    /// function (checked against a fine grid of the same function), and a pair without
    /// its centring step (a failed solve) gives `None`.
    #[test]
    fn quality_function_oracle_on_a_hand_made_iterate() {
        let o = IpmOptions::default();
        let mut m = MuUpdate::new(
            1.0,
            MuStrategy::Adaptive,
            &o,
            1.0,
            Vec::new(),
            Pairs::default(),
        );
        m.adaptive_mode(1.0, 2.5, 0.0);
        let mut p = Pairs::default();
        // The affine step drives both products to zero (s + ds = 0 would hit the bound;
        // here ds = −s/2, dz = −z/2), the centring step restores them.
        p.push_affine(1.0, 1.0, -0.5, -0.5);
        p.push_affine(1.0, 4.0, -0.5, -2.0);
        p.push_centring_from(-0.5 + 0.3, -0.5 + 0.3);
        p.push_centring_from(-0.5 + 0.2, -2.0 + 0.6);
        let dual = Norms::of([0.5, -0.5]);
        let primal = Norms::of([0.25]);
        let mu = m
            .quality_function_mu(p.clone(), dual, primal, 2.5)
            .expect("complete pairs");
        let data = QualityData {
            pairs: &p,
            dual,
            primal,
            tau: m.tau(),
        };
        let s = QualitySettings::from_options(&o);
        let q = |sigma: f64| data.eval(sigma, &s);
        let best = (1..=10_000)
            .map(|k| k as f64 * 1e-4)
            .fold((f64::INFINITY, 0.0), |b, sg| {
                if q(sg) < b.0 {
                    (q(sg), sg)
                } else {
                    b
                }
            });
        // The golden section stops at a bracket of 1e-2 σ (section_sigma_tol) or after 8
        // steps: its σ's quality is within 1 % of the grid's best (the function is flat
        // there), not its σ to the grid spacing.
        let sigma = mu / 2.5;
        assert!(
            q(sigma) <= best.0 * 1.01 + 1e-12,
            "σ {sigma}: {} vs grid {best:?}",
            q(sigma)
        );
        let mut incomplete = p.clone();
        incomplete.ds_cen.pop();
        incomplete.dz_cen.pop();
        assert_eq!(m.quality_function_mu(incomplete, dual, primal, 2.5), None);
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
