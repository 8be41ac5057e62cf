//! The barrier function φ_μ of the barrier problem (Wächter & Biegler 2006, eq. (3)) with
//! IPOPT's damping of one-sided bounds (κ_d) and its directional derivative, used by the
//! line search, the filter and the restoration phase.

/// The barrier function for one μ on the bounds of w = [x; s].
pub(crate) struct Barrier<'a> {
    pub mu: f64,
    /// IPOPT's κ_d: one-sided bounds add κ_d μ · slack.
    pub kappa_d: f64,
    pub wl: &'a [f64],
    pub wu: &'a [f64],
    pub has_l: &'a [bool],
    pub has_u: &'a [bool],
}

impl Barrier<'_> {
    /// φ_μ(w) = f − μ Σ ln(slack) + κ_d μ Σ slack (one-sided bounds only).
    pub(crate) fn value(&self, w: &[f64], f: f64) -> f64 {
        let (mu, kd) = (self.mu, self.kappa_d * self.mu);
        let mut phi = f;
        for (j, &wj) in w.iter().enumerate() {
            if self.has_l[j] {
                let s = wj - self.wl[j];
                phi -= mu * s.ln();
                if !self.has_u[j] {
                    phi += kd * s;
                }
            }
            if self.has_u[j] {
                let s = self.wu[j] - wj;
                phi -= mu * s.ln();
                if !self.has_l[j] {
                    phi += kd * s;
                }
            }
        }
        phi
    }

    /// ∇φ_μ(w)ᵀ dw, with `grad` the objective's gradient in x (the first `grad.len()`
    /// entries of w; the slacks have none).
    pub(crate) fn dir_deriv(&self, w: &[f64], grad: &[f64], dw: &[f64]) -> f64 {
        let (mu, kd) = (self.mu, self.kappa_d * self.mu);
        let mut d = 0.0;
        for (j, &wj) in w.iter().enumerate() {
            let mut gj = grad.get(j).copied().unwrap_or(0.0);
            if self.has_l[j] {
                gj -= mu / (wj - self.wl[j]);
                if !self.has_u[j] {
                    gj += kd;
                }
            }
            if self.has_u[j] {
                gj += mu / (self.wu[j] - wj);
                if !self.has_l[j] {
                    gj -= kd;
                }
            }
            d += gj * dw[j];
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::Barrier;

    /// One variable per kind of bound (lower, upper, both, none) and a slack.
    fn barrier(mu: f64) -> Barrier<'static> {
        Barrier {
            mu,
            kappa_d: 1e-5,
            wl: &[0.0, f64::NEG_INFINITY, -1.0, f64::NEG_INFINITY, 0.5],
            wu: &[f64::INFINITY, 2.0, 1.0, f64::INFINITY, f64::INFINITY],
            has_l: &[true, false, true, false, true],
            has_u: &[false, true, true, false, false],
        }
    }

    #[test]
    fn value_sums_the_log_barrier_and_the_damping_of_one_sided_bounds() {
        let b = barrier(0.1);
        let w = [1.0, 1.5, 0.0, 7.0, 2.5];
        // By hand: f − μ[ln 1 + ln 0.5 + ln 1 + ln 1 + ln 2] + κ_d μ (1 + 0.5 + 2).
        let expected = 3.0 - 0.1 * (0.5f64.ln() + 2.0f64.ln()) + 1e-6 * 3.5;
        assert!((b.value(&w, 3.0) - expected).abs() < 1e-15);
    }

    #[test]
    fn dir_deriv_matches_a_central_difference_of_value() {
        let b = barrier(0.3);
        let w = [0.7, 1.2, 0.4, -3.0, 1.1];
        let grad = [0.5, -1.0, 2.0, 0.25];
        let dw = [0.3, -0.2, 0.5, 1.0, -0.4];
        // f linear with gradient `grad` in x (the slack has none).
        let f = |w: &[f64]| grad.iter().zip(w).map(|(g, x)| g * x).sum::<f64>();
        let h = 1e-6;
        let plus: Vec<f64> = w.iter().zip(&dw).map(|(x, d)| x + h * d).collect();
        let minus: Vec<f64> = w.iter().zip(&dw).map(|(x, d)| x - h * d).collect();
        let fd = (b.value(&plus, f(&plus)) - b.value(&minus, f(&minus))) / (2.0 * h);
        // Central difference error O(h²·φ''') ≈ 1e-12 here; 1e-8 leaves room for
        // cancellation in φ(+) − φ(−) (φ ≈ 1, ε/h ≈ 2e-10).
        assert!((b.dir_deriv(&w, &grad, &dw) - fd).abs() < 1e-8);
    }
}
