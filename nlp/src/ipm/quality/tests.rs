//! The golden-section search of the quality-function oracle against a brute-force
//! minimisation of the same quality function, written here a second time from its
//! definition (IPOPT's CalculateQualityFunction with the default 2-norm-squared, no
//! centrality or balancing term).

use super::{Norms, Pairs, QualityData, QualitySettings};
use crate::options::{
    QualityFunctionBalancingTerm, QualityFunctionCentrality, QualityFunctionNorm,
};
use crate::test_support::Rng;

/// A random iterate with Newton-like steps: the affine step solves s·dz + z·ds = −s·z
/// and the centring step s·dz + z·ds = avg, each split between ds and dz by a random
/// share (some shares outside [0, 1], so that some steps run into the boundary).
struct Instance {
    pairs: Pairs,
    dual: Vec<f64>,
    primal: Vec<f64>,
    avg: f64,
}

impl Instance {
    /// `hard`: every affine step runs 2–6 times past the boundary and the
    /// infeasibilities are large, so that the search above σ = 1 is exercised too.
    fn random(seed: u64, n: usize, hard: bool) -> Instance {
        let mut r = Rng(seed);
        let slack: Vec<f64> = (0..n).map(|_| 0.05 + 2.0 * r.next()).collect();
        let z: Vec<f64> = (0..n).map(|_| 0.05 + 2.0 * r.next()).collect();
        let avg = slack.iter().zip(&z).map(|(s, z)| s * z).sum::<f64>() / n as f64;
        let mut pairs = Pairs::default();
        for k in 0..n {
            let t = if hard {
                2.0 + 4.0 * r.next()
            } else {
                2.0 * r.next() - 0.5
            };
            pairs.push_affine(slack[k], z[k], -slack[k] * t, -z[k] * (1.0 - t));
            let p = r.next();
            pairs.ds_cen.push(avg * p / z[k]);
            pairs.dz_cen.push(avg * (1.0 - p) / slack[k]);
        }
        let scale = if hard { 10.0 } else { r.next() };
        let dual = r.vec(n + 2).iter().map(|v| v * scale).collect();
        let primal = r.vec(2).iter().map(|v| v * scale).collect();
        Instance {
            pairs,
            dual,
            primal,
            avg,
        }
    }

    fn data(&self, tau: f64) -> QualityData<'_> {
        QualityData {
            pairs: &self.pairs,
            dual: Norms::of(self.dual.iter().copied()),
            primal: Norms::of(self.primal.iter().copied()),
            tau,
        }
    }

    /// The quality function from its definition: the full step at σ, the largest step
    /// sizes keeping (1 − τ) of every slack and multiplier, then the mean squares of the
    /// dual and primal infeasibility scaled by (1 − α)² and of the products.
    fn brute_q(&self, sigma: f64, tau: f64) -> f64 {
        let p = &self.pairs;
        let n = p.slack.len();
        let ds: Vec<f64> = (0..n).map(|k| p.ds_aff[k] + sigma * p.ds_cen[k]).collect();
        let dz: Vec<f64> = (0..n).map(|k| p.dz_aff[k] + sigma * p.dz_cen[k]).collect();
        let largest = |v: &[f64], d: &[f64]| {
            // Shrink α to each entry's boundary in turn.
            let mut a = 1.0f64;
            for k in 0..n {
                if v[k] + a * d[k] < (1.0 - tau) * v[k] {
                    a = (tau * v[k]) / (-d[k]);
                }
            }
            a
        };
        let ap = largest(&p.slack, &ds);
        let az = largest(&p.z, &dz);
        let msq = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64;
        let prod: Vec<f64> = (0..n)
            .map(|k| (p.slack[k] + ap * ds[k]) * (p.z[k] + az * dz[k]))
            .collect();
        (1.0 - az).powi(2) * msq(&self.dual) + (1.0 - ap).powi(2) * msq(&self.primal) + msq(&prod)
    }
}

fn settings(steps: usize, sigma_tol: f64) -> QualitySettings {
    QualitySettings {
        norm: QualityFunctionNorm::TwoNormSquared,
        centrality: QualityFunctionCentrality::None,
        balancing: QualityFunctionBalancingTerm::None,
        sigma_max: 100.0,
        sigma_min: 1e-6,
        max_section_steps: steps,
        section_sigma_tol: sigma_tol,
        section_qf_tol: 0.0,
    }
}

/// σ of the golden section (IPOPT's rule: search below or above 1 by the slope at 1)
/// against the brute-force minimiser of the same function on a grid of 20 001 points of
/// the side searched, on 80 random instances of which those whose grid values are
/// unimodal are compared. With 200 sections and σ tolerance 1e-12 the search must find
/// the grid minimum (to 1e-9 relative in q, plus the grid's own resolution in σ); with
/// IPOPT's defaults (8 sections, tolerance 1e-2) σ must lie within the final bracket,
/// 0.618⁸ of the side's width, of the minimiser.
#[test]
fn golden_section_matches_brute_force_minimiser() {
    let tau = 0.99;
    let (mut compared, mut above) = (0, 0);
    for seed in 1..=40u64 {
        for hard in [false, true] {
            let inst = Instance::random(seed * 7919, 6, hard);
            let d = inst.data(tau);
            let def = settings(8, 1e-2);
            // The oracle's quality function is the definition's.
            for sigma in [1e-6, 0.01, 0.5, 0.99, 1.0, 3.0, 50.0] {
                let (q, b) = (d.eval(sigma, &def), inst.brute_q(sigma, tau));
                assert!(
                    (q - b).abs() <= 1e-12 * b.max(1.0),
                    "seed {seed}: q({sigma}) {q} vs {b}"
                );
            }
            let up = inst.brute_q(0.99, tau) > inst.brute_q(1.0, tau);
            let (lo, hi) = if up { (1.0, 100.0) } else { (1e-6, 0.99) };
            let n = 20_000;
            let grid: Vec<(f64, f64)> = (0..=n)
                .map(|i| {
                    let s = lo + (hi - lo) * i as f64 / n as f64;
                    (s, inst.brute_q(s, tau))
                })
                .collect();
            let k = (0..=n).fold(0, |b, i| if grid[i].1 < grid[b].1 { i } else { b });
            let unimodal = grid[..=k].windows(2).all(|w| w[1].1 <= w[0].1)
                && grid[k..].windows(2).all(|w| w[1].1 >= w[0].1);
            if !unimodal {
                continue;
            }
            compared += 1;
            above += up as usize;
            let (s_best, q_best) = grid[k];
            let h = (hi - lo) / n as f64;
            let fine = d.choose_sigma(inst.avg, 0.0, 1e10, &settings(200, 1e-12));
            assert!(
                inst.brute_q(fine, tau) <= q_best * (1.0 + 1e-9) && (fine - s_best).abs() <= h,
                "seed {seed} hard {hard}: σ {fine} vs grid minimiser {s_best}"
            );
            let coarse = d.choose_sigma(inst.avg, 0.0, 1e10, &def);
            let bracket = 0.618034f64.powi(8) * (hi - lo);
            assert!(
                (coarse - s_best).abs() <= bracket + h,
                "seed {seed} hard {hard}: σ {coarse} vs grid minimiser {s_best}"
            );
        }
    }
    assert!(
        compared >= 40 && above >= 3,
        "{compared} compared, {above} above 1"
    );
}

/// The range of μ limits σ: μ_max/avg caps the search above 1 and μ_min/avg is the
/// lowest σ below 1.
#[test]
fn mu_range_limits_sigma() {
    let inst = Instance::random(7919, 6, false);
    let d = inst.data(0.99);
    let s = settings(8, 1e-2);
    let free = d.choose_sigma(inst.avg, 0.0, 1e10, &s);
    let floor = 2.0 * free;
    let sigma = d.choose_sigma(inst.avg, floor * inst.avg, 1e10, &s);
    assert!(
        sigma >= floor * (1.0 - 1e-12),
        "σ {sigma} below μ_min/avg {floor}"
    );
    // When σ_lo ≥ the upper end of the lower side, IPOPT takes σ_lo without a search.
    assert_eq!(d.choose_sigma(inst.avg, 5.0 * inst.avg, 1e10, &s), 5.0);
}
