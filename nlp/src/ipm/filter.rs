//! The filter line search's acceptance (Wächter & Biegler 2006, §2.3–2.4; IPOPT's
//! `FilterLSAcceptor`): the (θ, φ) [`Filter`] and the [`Acceptance`] rules — sufficient
//! reduction of θ or φ_μ, the switching and Armijo conditions, the filter's margins,
//! α_min — for the constraint violation θ = ‖c‖₁ and the barrier function φ_μ.

use crate::options::IpmOptions;

/// A set of forbidden (θ, φ) corners: a trial is rejected if θ ≥ θ_j and φ ≥ φ_j for
/// some entry j.
#[derive(Debug, Clone, Default)]
pub struct Filter {
    entries: Vec<(f64, f64)>,
}

impl Filter {
    /// Removes all entries (done whenever μ changes).
    pub fn reset(&mut self) {
        self.entries.clear();
    }

    /// Number of entries.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// True if empty.
    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// True if (θ, φ) is not dominated by any entry.
    pub fn acceptable(&self, theta: f64, phi: f64) -> bool {
        self.entries.iter().all(|&(t, p)| theta < t || phi < p)
    }

    /// Adds the corner (θ, φ), dropping entries it dominates.
    pub fn add(&mut self, theta: f64, phi: f64) {
        self.entries.retain(|&(t, p)| !(t >= theta && p >= phi));
        self.entries.push((theta, phi));
    }
}

/// The acceptance rules of one run, with θ_min and θ_max from the starting point's
/// constraint violation θ₀ and the constants of `IpmOptions` (γ_θ, γ_φ, η_φ, δ, s_θ,
/// s_φ, the α_min fraction).
#[derive(Clone, Debug, Default)]
pub(crate) struct Acceptance {
    /// θ_min = theta_min_fact · max(1, θ₀): below it the switching condition can make a
    /// step f-type.
    pub theta_min: f64,
    /// θ_max = theta_max_fact · max(1, θ₀): no trial point with a larger θ is accepted.
    pub theta_max: f64,
    gamma_theta: f64,
    gamma_phi: f64,
    eta_phi: f64,
    delta: f64,
    s_theta: f64,
    s_phi: f64,
    alpha_min_frac: f64,
}

impl Acceptance {
    /// The rules of a run starting with constraint violation `theta0`.
    pub fn new(o: &IpmOptions, theta0: f64) -> Acceptance {
        Acceptance {
            theta_max: o.theta_max_fact * theta0.max(1.0),
            theta_min: o.theta_min_fact * theta0.max(1.0),
            gamma_theta: o.gamma_theta,
            gamma_phi: o.gamma_phi,
            eta_phi: o.eta_phi,
            delta: o.delta,
            s_theta: o.s_theta,
            s_phi: o.s_phi,
            alpha_min_frac: o.alpha_min_frac,
        }
    }

    /// The switching condition α (−∇φ_μᵀd)^s_φ > δ θ^s_θ (with ∇φ_μᵀd = `gpd` < 0).
    pub fn switching(&self, alpha: f64, theta: f64, gpd: f64) -> bool {
        gpd < 0.0 && alpha * (-gpd).powf(self.s_phi) > self.delta * theta.powf(self.s_theta)
    }

    /// The Armijo condition φ_t ≤ φ + η_φ α ∇φ_μᵀd (up to rounding in φ).
    fn armijo(&self, alpha: f64, phi: f64, gpd: f64, phi_t: f64) -> bool {
        let tol = 10.0 * f64::EPSILON * phi.abs();
        phi_t - phi - self.eta_phi * alpha * gpd <= tol
    }

    /// IPOPT's acceptance test of a trial point (θ_t, φ_t) from (θ, φ)
    /// (`CheckAcceptabilityOfTrialPoint`): θ_t ≤ θ_max, then, when θ ≤ θ_min and the
    /// switching condition holds, Armijo on φ_μ, else sufficient reduction of θ or φ_μ;
    /// and acceptable to `filter`. `alpha` is the step size of the switching and Armijo
    /// conditions (for a second-order correction, the step of the rejected trial).
    /// A NaN θ_t is rejected (hence the negated comparison).
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn is_acceptable(
        &self,
        filter: &Filter,
        alpha: f64,
        (theta, phi): (f64, f64),
        gpd: f64,
        (theta_t, phi_t): (f64, f64),
    ) -> bool {
        if !(theta_t <= self.theta_max) || !phi_t.is_finite() {
            return false;
        }
        let tol = 10.0 * f64::EPSILON * phi.abs();
        let ok = if theta <= self.theta_min && self.switching(alpha, theta, gpd) {
            self.armijo(alpha, phi, gpd, phi_t)
        } else {
            theta_t <= (1.0 - self.gamma_theta) * theta
                || phi_t - (phi - self.gamma_phi * theta) <= tol
        };
        ok && filter.acceptable(theta_t, phi_t)
    }

    /// After an accepted step (Algorithm A step A-8, `UpdateForNextIteration`): an
    /// f-type step satisfies the switching and Armijo conditions, whether or not θ ≤
    /// θ_min; any other step augments `filter` with the current point (θ, φ). True for
    /// an f-type step.
    pub fn after_step(
        &self,
        filter: &mut Filter,
        alpha: f64,
        (theta, phi): (f64, f64),
        gpd: f64,
        phi_t: f64,
    ) -> bool {
        let ftype = self.switching(alpha, theta, gpd) && self.armijo(alpha, phi, gpd, phi_t);
        if !ftype {
            self.augment(filter, theta, phi);
        }
        ftype
    }

    /// Adds the point (θ, φ) to `filter` with the margins: the corner
    /// ((1 − γ_θ) θ, φ − γ_φ θ).
    pub fn augment(&self, filter: &mut Filter, theta: f64, phi: f64) {
        filter.add(
            (1.0 - self.gamma_theta) * theta,
            phi - self.gamma_phi * theta,
        );
    }

    /// The smallest step size the backtracking tries (eq. (23)), times the α_min
    /// fraction, at least machine epsilon.
    pub fn alpha_min(&self, theta: f64, gpd: f64) -> f64 {
        let a = if gpd < 0.0 {
            let mut a = self.gamma_theta.min(self.gamma_phi * theta / -gpd);
            if theta <= self.theta_min {
                a = a.min(self.delta * theta.powf(self.s_theta) / (-gpd).powf(self.s_phi));
            }
            a
        } else {
            self.gamma_theta
        };
        (self.alpha_min_frac * a).max(f64::EPSILON)
    }
}

#[cfg(test)]
mod tests {
    use super::{Acceptance, Filter};
    use crate::options::IpmOptions;

    #[test]
    fn filter_dominance() {
        let mut f = Filter::default();
        assert!(f.acceptable(1.0, 1.0));
        f.add(1.0, 1.0);
        assert!(!f.acceptable(1.0, 1.0));
        assert!(!f.acceptable(2.0, 2.0));
        assert!(f.acceptable(0.5, 2.0));
        assert!(f.acceptable(2.0, 0.5));
        f.add(0.5, 0.5);
        assert_eq!(f.len(), 1);
        f.reset();
        assert!(f.is_empty());
    }

    /// IPOPT's defaults: γ_θ = 1e-5, γ_φ = 1e-8, η_φ = 1e-8, δ = 1, s_θ = 1.1,
    /// s_φ = 2.3, θ_max = 1e4·max(1, θ₀), θ_min = 1e-4·max(1, θ₀).
    fn rules(theta0: f64) -> Acceptance {
        Acceptance::new(&IpmOptions::default(), theta0)
    }

    #[test]
    fn theta_bounds_follow_the_start() {
        let a = rules(50.0);
        assert_eq!((a.theta_max, a.theta_min), (1e4 * 50.0, 1e-4 * 50.0));
        let a = rules(0.1);
        assert_eq!((a.theta_max, a.theta_min), (1e4, 1e-4));
    }

    /// Away from feasibility (θ > θ_min) a trial is accepted when θ or φ decreases by
    /// its margin: θ_t ≤ (1 − 1e-5) θ or φ_t ≤ φ − 1e-8 θ; never above θ_max; and never
    /// when the filter holds a corner that dominates it.
    #[test]
    fn sufficient_reduction_and_filter() {
        let a = rules(1.0);
        let f = Filter::default();
        let (theta, phi) = (1.0, 10.0);
        // θ down by more than the margin, φ up: accepted.
        assert!(a.is_acceptable(&f, 1.0, (theta, phi), -1.0, (0.99998, 11.0)));
        // θ down by less than 1e-5 θ, φ up: rejected; φ down by 1e-8 θ instead: accepted.
        assert!(!a.is_acceptable(&f, 1.0, (theta, phi), -1.0, (0.999995, 11.0)));
        assert!(a.is_acceptable(&f, 1.0, (theta, phi), -1.0, (0.999995, 10.0 - 2e-8)));
        // Above θ_max = 1e4: rejected whatever φ does.
        assert!(!a.is_acceptable(&f, 1.0, (2e4, phi), -1.0, (1.5e4, -1e9)));
        // A corner that dominates the trial point rejects it.
        let mut f = Filter::default();
        a.augment(&mut f, 0.5, 9.0);
        assert!(!a.is_acceptable(&f, 1.0, (theta, phi), -1.0, (0.6, 9.5)));
        assert!(a.is_acceptable(&f, 1.0, (theta, phi), -1.0, (0.4, 9.5)));
    }

    /// Near feasibility (θ ≤ θ_min) with the switching condition α (−gpd)^2.3 > θ^1.1,
    /// only Armijo counts: φ_t ≤ φ + 1e-8 α gpd. Such a step is f-type (no filter
    /// entry); an h-type step adds ((1 − 1e-5) θ, φ − 1e-8 θ).
    #[test]
    fn armijo_switching_and_augmentation() {
        let a = rules(1.0);
        let mut f = Filter::default();
        let (theta, phi, gpd) = (1e-6, 5.0, -1.0);
        assert!(a.switching(1.0, theta, gpd));
        assert!(!a.switching(1.0, theta, 0.5), "not a descent direction");
        assert!(
            !a.switching(1e-7, 1e-4, -1e-3),
            "1e-7·1e-3^2.3 < (1e-4)^1.1"
        );
        // θ decreases a lot but φ does not decrease by η_φ α |gpd| = 1e-8: rejected.
        assert!(!a.is_acceptable(&f, 1.0, (theta, phi), gpd, (0.0, phi)));
        assert!(a.is_acceptable(&f, 1.0, (theta, phi), gpd, (0.0, phi - 2e-8)));
        assert!(a.after_step(&mut f, 1.0, (theta, phi), gpd, phi - 2e-8));
        assert!(f.is_empty(), "an f-type step leaves the filter");
        assert!(!a.after_step(&mut f, 1.0, (0.5, phi), gpd, phi + 1.0));
        assert!(!f.acceptable(0.5 * (1.0 - 1e-5), phi - 1e-8 * 0.5));
        assert!(f.acceptable(0.5 * (1.0 - 1e-5) - 1e-9, phi + 1.0));
    }

    /// α_min = 0.05·min(γ_θ, γ_φ θ/(−gpd), δ θ^s_θ/(−gpd)^s_φ [θ ≤ θ_min]), or 0.05 γ_θ
    /// for an ascent direction; at least machine epsilon.
    #[test]
    fn alpha_min_by_hand() {
        let a = rules(1.0);
        assert_eq!(a.alpha_min(1.0, 1.0), 0.05 * 1e-5);
        // γ_φ θ / −gpd = 1e-8·1/1e-2 = 1e-6 < γ_θ.
        assert!((a.alpha_min(1.0, -1e-2) - 0.05 * 1e-6).abs() < 1e-22);
        // θ = 1e-5 ≤ θ_min: δ θ^1.1 / 1 = 1e-5.5 > γ_φ θ = 1e-13 → 0.05·1e-13.
        assert!((a.alpha_min(1e-5, -1.0) - 0.05 * 1e-13).abs() < 1e-28);
        assert_eq!(a.alpha_min(0.0, -1.0), f64::EPSILON);
    }
}
