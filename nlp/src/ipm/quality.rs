//! IPOPT's quality-function μ oracle (IpQualityFunctionMuOracle; Nocedal, Wächter & Waltz,
//! "Adaptive barrier update strategies for nonlinear interior methods", SIAM J. Optim. 19,
//! 2009): the step for the barrier parameter μ = σ·avg is aff + σ·cen, with aff the
//! affine-scaling step (μ = 0) and cen the centring step (the step's derivative with
//! respect to σ). For each σ the oracle takes the fraction-to-the-boundary step sizes of
//! that step and predicts the KKT error after it, linearly for the dual and primal
//! infeasibilities (they shrink by 1 − α) and exactly for the complementarity products;
//! σ minimises this prediction by a golden-section search, below or above σ = 1.
//!
//! Only numbers live here (the complementarity pairs as flat slices), so that the search
//! can be tested against a brute-force minimisation of the same function.

use crate::options::{
    IpmOptions, QualityFunctionBalancingTerm, QualityFunctionCentrality, QualityFunctionNorm,
};

/// The norms of a vector that the quality function needs: Σ|r|, Σr², max|r| and the
/// number of entries (for the means).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Norms {
    pub(crate) sum_abs: f64,
    pub(crate) sum_sq: f64,
    pub(crate) max_abs: f64,
    pub(crate) len: usize,
}

impl Norms {
    /// The norms of the entries of `v`.
    pub(crate) fn of(v: impl IntoIterator<Item = f64>) -> Norms {
        let mut n = Norms::default();
        for x in v {
            n.sum_abs += x.abs();
            n.sum_sq += x * x;
            n.max_abs = n.max_abs.max(x.abs());
            n.len += 1;
        }
        n
    }

    /// The entry count as a divisor (at least 1).
    fn count(&self) -> f64 {
        self.len.max(1) as f64
    }
}

/// The KKT error of the parts (dual, primal, complementarity) in the norm `norm`, as
/// IPOPT's AdaptiveMuUpdate::quality_function_pd_system.
pub(crate) fn kkt_error(norm: QualityFunctionNorm, parts: [Norms; 3]) -> f64 {
    parts
        .iter()
        .map(|p| match norm {
            QualityFunctionNorm::OneNorm => p.sum_abs / p.count(),
            QualityFunctionNorm::TwoNormSquared => p.sum_sq / p.count(),
            QualityFunctionNorm::MaxNorm => p.max_abs,
            QualityFunctionNorm::TwoNorm => (p.sum_sq / p.count()).sqrt(),
        })
        .sum()
}

/// The complementarity pairs of one iterate, flattened: per pair k (a finite bound of a
/// variable or slack) its slack s_k and multiplier z_k, and the slack and multiplier
/// components of the affine step and of the centring step. Kept by the core as scratch
/// (cleared and refilled each free-mode iteration, no allocation once grown).
#[derive(Clone, Debug, Default)]
pub(crate) struct Pairs {
    pub(crate) slack: Vec<f64>,
    pub(crate) z: Vec<f64>,
    pub(crate) ds_aff: Vec<f64>,
    pub(crate) dz_aff: Vec<f64>,
    pub(crate) ds_cen: Vec<f64>,
    pub(crate) dz_cen: Vec<f64>,
}

impl Pairs {
    /// Empties every vector (keeping its capacity).
    pub(crate) fn clear(&mut self) {
        for v in [
            &mut self.slack,
            &mut self.z,
            &mut self.ds_aff,
            &mut self.dz_aff,
            &mut self.ds_cen,
            &mut self.dz_cen,
        ] {
            v.clear();
        }
    }

    /// Adds a pair with its affine step.
    pub(crate) fn push_affine(&mut self, slack: f64, z: f64, ds_aff: f64, dz_aff: f64) {
        self.slack.push(slack);
        self.z.push(z);
        self.ds_aff.push(ds_aff);
        self.dz_aff.push(dz_aff);
    }

    /// Adds the centring step of the next pair from its step at μ = avg (the step is
    /// affine in μ: centring = that step − the affine step).
    pub(crate) fn push_centring_from(&mut self, ds: f64, dz: f64) {
        let k = self.ds_cen.len();
        self.ds_cen.push(ds - self.ds_aff[k]);
        self.dz_cen.push(dz - self.dz_aff[k]);
    }
}

/// One iterate's data for the quality function: its complementarity pairs with the
/// affine and centring steps, and the norms of its infeasibilities.
pub(crate) struct QualityData<'a> {
    pub(crate) pairs: &'a Pairs,
    /// Dual infeasibility ∇L (all variables and slacks).
    pub(crate) dual: Norms,
    /// Primal infeasibility.
    pub(crate) primal: Norms,
    /// Fraction-to-the-boundary parameter.
    pub(crate) tau: f64,
}

/// The options of the search (IPOPT's names).
#[derive(Clone, Copy, Debug)]
pub(crate) struct QualitySettings {
    pub(crate) norm: QualityFunctionNorm,
    pub(crate) centrality: QualityFunctionCentrality,
    pub(crate) balancing: QualityFunctionBalancingTerm,
    pub(crate) sigma_max: f64,
    pub(crate) sigma_min: f64,
    pub(crate) max_section_steps: usize,
    pub(crate) section_sigma_tol: f64,
    pub(crate) section_qf_tol: f64,
}

impl QualitySettings {
    pub(crate) fn from_options(o: &IpmOptions) -> QualitySettings {
        QualitySettings {
            norm: o.quality_function_norm_type,
            centrality: o.quality_function_centrality,
            balancing: o.quality_function_balancing_term,
            sigma_max: o.sigma_max,
            sigma_min: o.sigma_min,
            max_section_steps: o.quality_function_max_section_steps,
            section_sigma_tol: o.quality_function_section_sigma_tol,
            section_qf_tol: o.quality_function_section_qf_tol,
        }
    }
}

/// Largest α ≤ 1 with v + α·dv ≥ (1 − τ)·v for every entry (v > 0).
fn frac_to_bound(tau: f64, v: &[f64], dv_aff: &[f64], dv_cen: &[f64], sigma: f64) -> f64 {
    let mut a: f64 = 1.0;
    for k in 0..v.len() {
        let d = dv_aff[k] + sigma * dv_cen[k];
        if d < 0.0 {
            a = a.min(tau * v[k] / -d);
        }
    }
    a
}

impl QualityData<'_> {
    /// The quality function at σ (IPOPT's CalculateQualityFunction).
    pub(crate) fn eval(&self, sigma: f64, s: &QualitySettings) -> f64 {
        let p = self.pairs;
        let ap = frac_to_bound(self.tau, &p.slack, &p.ds_aff, &p.ds_cen, sigma);
        let ad = frac_to_bound(self.tau, &p.z, &p.dz_aff, &p.dz_cen, sigma);
        let (mut c_sum, mut c_sq, mut c_max, mut c_min) = (0.0, 0.0, 0.0f64, f64::INFINITY);
        for k in 0..p.slack.len() {
            let sk = p.slack[k] + ap * (p.ds_aff[k] + sigma * p.ds_cen[k]);
            let zk = p.z[k] + ad * (p.dz_aff[k] + sigma * p.dz_cen[k]);
            let c = sk * zk;
            c_sum += c.abs();
            c_sq += c * c;
            c_max = c_max.max(c.abs());
            c_min = c_min.min(c);
        }
        let n_comp = p.slack.len().max(1) as f64;
        let n_dual = self.dual.count();
        let n_pri = self.primal.count();
        let (fd, fp) = (1.0 - ad, 1.0 - ap);
        let (dual, primal, compl) = match s.norm {
            QualityFunctionNorm::OneNorm => (
                fd * self.dual.sum_abs / n_dual,
                fp * self.primal.sum_abs / n_pri,
                c_sum / n_comp,
            ),
            QualityFunctionNorm::TwoNormSquared => (
                fd * fd * self.dual.sum_sq / n_dual,
                fp * fp * self.primal.sum_sq / n_pri,
                c_sq / n_comp,
            ),
            QualityFunctionNorm::MaxNorm => {
                (fd * self.dual.max_abs, fp * self.primal.max_abs, c_max)
            }
            QualityFunctionNorm::TwoNorm => (
                fd * (self.dual.sum_sq / n_dual).sqrt(),
                fp * (self.primal.sum_sq / n_pri).sqrt(),
                (c_sq / n_comp).sqrt(),
            ),
        };
        let mut q = dual + primal + compl;
        // Centrality ξ = min / average of the predicted products (LOQO's measure).
        let xi = c_min / (c_sum / n_comp);
        q += match s.centrality {
            QualityFunctionCentrality::None => 0.0,
            QualityFunctionCentrality::Log => -compl * xi.ln(),
            QualityFunctionCentrality::Reciprocal => compl / xi,
            QualityFunctionCentrality::CubedReciprocal => compl / (xi * xi * xi),
        };
        if s.balancing == QualityFunctionBalancingTerm::Cubic {
            q += (dual.max(primal) - compl).max(0.0).powi(3);
        }
        q
    }

    /// σ chosen by IPOPT's rule (QualityFunctionMuOracle::CalculateMu) for the average
    /// complementarity `avg` and the range [mu_min, mu_max] of μ; μ = σ·avg.
    pub(crate) fn choose_sigma(
        &self,
        avg: f64,
        mu_min: f64,
        mu_max: f64,
        s: &QualitySettings,
    ) -> f64 {
        // The slope at σ = 1 decides whether to search above or below 1.
        let q1 = self.eval(1.0, s);
        let s1m = 1.0 - s.section_sigma_tol.max(1e-4);
        let q1m = self.eval(s1m, s);
        if q1m > q1 {
            let up = s.sigma_max.min(mu_max / avg);
            let lo = 1.0;
            if lo >= up {
                up
            } else {
                self.golden_section(up, None, lo, Some(q1), s)
            }
        } else {
            let lo = s.sigma_min.max(mu_min / avg);
            let up = lo.max(s1m).min(mu_max / avg);
            if lo >= up {
                lo
            } else {
                self.golden_section(up, Some(q1m), lo, None, s)
            }
        }
    }

    /// IPOPT's PerformGoldenSection on [lo, up] (in σ, not log σ); `q_up`/`q_lo` are the
    /// quality function at the ends when already known.
    fn golden_section(
        &self,
        up_in: f64,
        q_up_in: Option<f64>,
        lo_in: f64,
        q_lo_in: Option<f64>,
        s: &QualitySettings,
    ) -> f64 {
        let (mut up, mut lo) = (up_in, lo_in);
        let (mut q_up, mut q_lo) = (q_up_in, q_lo_in);
        let g = (3.0 - 5f64.sqrt()) / 2.0;
        let mut m1 = lo + g * (up - lo);
        let mut m2 = lo + (1.0 - g) * (up - lo);
        let mut q1 = self.eval(m1, s);
        let mut q2 = self.eval(m2, s);
        // IPOPT uses −100 for an end not evaluated; it only enters the qf-tolerance test.
        let known = |q: Option<f64>| q.unwrap_or(-100.0);
        let spread = |q_lo: Option<f64>, q_up: Option<f64>, q1: f64, q2: f64| {
            let v = [known(q_lo), known(q_up), q1, q2];
            let mn = v.iter().copied().fold(f64::INFINITY, f64::min);
            let mx = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            1.0 - mn / mx
        };
        let mut sections = 0;
        while up - lo >= s.section_sigma_tol * up
            && spread(q_lo, q_up, q1, q2) >= s.section_qf_tol
            && sections < s.max_section_steps
        {
            sections += 1;
            if q1 > q2 {
                lo = m1;
                q_lo = Some(q1);
                m1 = m2;
                q1 = q2;
                m2 = lo + (1.0 - g) * (up - lo);
                q2 = self.eval(m2, s);
            } else {
                up = m2;
                q_up = Some(q2);
                m2 = m1;
                q2 = q1;
                m1 = lo + g * (up - lo);
                q1 = self.eval(m1, s);
            }
        }
        if up - lo >= s.section_sigma_tol * up && spread(q_lo, q_up, q1, q2) < s.section_qf_tol {
            // Stopped by the qf tolerance: the best of the four points.
            let cands = [(known(q_lo), lo), (q1, m1), (q2, m2), (known(q_up), up)];
            let mn = cands.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
            return cands.iter().find(|c| c.0 == mn).map_or(m1, |c| c.1);
        }
        let (mut sigma, q) = if q1 < q2 { (m1, q1) } else { (m2, q2) };
        // The search never evaluates an end it started from; compare with it.
        if up == up_in {
            let qt = q_up.unwrap_or_else(|| self.eval(up, s));
            if qt < q {
                sigma = up;
            }
        } else if lo == lo_in {
            let qt = q_lo.unwrap_or_else(|| self.eval(lo, s));
            if qt < q {
                sigma = lo;
            }
        }
        sigma
    }
}

#[cfg(test)]
mod tests;
