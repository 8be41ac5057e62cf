//! The perturbation handler (IPOPT's `PDPerturbationHandler`; Wächter & Biegler 2006,
//! §3.1, Algorithm IC): the Hessian perturbation δ_w and the Jacobian perturbation δ_c,
//! their state across iterations and the rules that choose the next trial. The handler
//! does not factorise: [`Perturbation::correct_inertia`] asks its caller to factorise
//! K with each trial (δ_w, δ_c) and is told what inertia came out.

use crate::options::IpmOptions;

/// What a trial factorisation of K = [[W + Σ + δ_w I, Aᵀ], [A, −δ_c I]] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Factored {
    /// Inertia (n, m, 0): the step can be computed.
    Correct,
    /// Zero eigenvalues, or the factorisation failed: K is singular.
    Singular,
    /// Nonsingular with the wrong inertia: W is not positive definite on the null
    /// space of A.
    WrongInertia,
}

impl Factored {
    /// The outcome of a factorisation of K with `n` variables and `m` rows.
    pub(super) fn of<E>(res: &Result<crate::kkt::Inertia, E>, n: usize, m: usize) -> Factored {
        match res {
            Ok(i) if i.positive == n && i.negative == m && i.zero == 0 => Factored::Correct,
            Ok(i) if i.zero == 0 => Factored::WrongInertia,
            _ => Factored::Singular,
        }
    }
}

/// State of the inertia correction across iterations.
#[derive(Default)]
pub(super) struct Perturbation {
    /// δ_w of the current factorisation.
    pub(super) delta_w: f64,
    /// The last nonzero δ_w (0 if none was needed yet, or after a restoration phase).
    pub(super) delta_w_last: f64,
    /// δ_c of the current factorisation.
    pub(super) delta_c: f64,
    /// δ_c is applied from the start (after three singular iterations in a row).
    pub(super) jac_degenerate: bool,
    /// Iterations in a row whose unregularised system was singular.
    pub(super) singular_iters: usize,
    /// Iterations in a row that needed δ_w > 0.
    pub(super) perturbed_iters: usize,
    /// A step was solved without δ_c: the Jacobian is not degenerate, and
    /// `jac_degenerate` can no longer be set (IPOPT's PDPerturbationHandler decides
    /// degeneracy once, in the first iterations: "Nj" in its info string).
    pub(super) jac_determined: bool,
}

impl Perturbation {
    /// δ_c = jacobian_regularization_value · μ^jacobian_regularization_exponent.
    pub(super) fn delta_cd(opts: &IpmOptions, mu: f64) -> f64 {
        opts.jacobian_regularization_value * mu.powf(opts.jacobian_regularization_exponent)
    }

    /// IPOPT's next trial δ_w: the first one is `first_hessian_perturbation`, or
    /// κ_w⁻·δ_w_last when an earlier iteration needed one; then ×κ_w⁺ (×κ̄_w⁺ while no
    /// earlier iteration needed one).
    pub(super) fn next_delta_w(&self, o: &IpmOptions, delta_w: f64) -> f64 {
        if delta_w == 0.0 {
            if self.delta_w_last == 0.0 {
                o.first_hessian_perturbation
            } else {
                o.min_hessian_perturbation
                    .max(o.perturb_dec_fact * self.delta_w_last)
            }
        } else if self.delta_w_last == 0.0 {
            delta_w * o.perturb_inc_fact_first
        } else {
            delta_w * o.perturb_inc_fact
        }
    }

    /// One iteration's inertia correction (Algorithm IC): `factor(δ_w, δ_c)` factorises
    /// K with these perturbations. Starts from δ_w = 0 (or, after
    /// `perturbation_skip_zero_after` perturbed iterations in a row, from κ_w⁻·δ_w_last)
    /// and δ_c = 0 (δ_c(μ) once the Jacobian was found degenerate); a singular K first
    /// gets δ_c(μ) (once, when `has_rows`), then δ_w grows by [`Self::next_delta_w`].
    /// True with the accepted (δ_w, δ_c) in `delta_w`, `delta_c`; false once δ_w would
    /// exceed `max_hessian_perturbation`.
    pub(super) fn correct_inertia(
        &mut self,
        o: &IpmOptions,
        mu: f64,
        has_rows: bool,
        mut factor: impl FnMut(f64, f64) -> Factored,
    ) -> bool {
        let mut delta_w = 0.0;
        self.delta_c = if self.jac_degenerate && has_rows {
            Self::delta_cd(o, mu)
        } else {
            0.0
        };
        let mut tried_delta_c = self.delta_c > 0.0;
        // After `perturbation_skip_zero_after` iterations in a row that needed δ_w > 0,
        // start from IPOPT's second trial κ_w⁻·δ_w_last and skip the δ_w = 0 trial
        // (saves one factorisation per iteration on nonconvex problems). δ_w then keeps
        // shrinking by κ_w⁻ per iteration while the inertia allows it.
        let skip = o.perturbation_skip_zero_after;
        if skip > 0 && self.perturbed_iters >= skip && self.delta_w_last > 0.0 {
            delta_w = self.next_delta_w(o, 0.0);
        }
        loop {
            let singular = match factor(delta_w, self.delta_c) {
                Factored::Correct => {
                    self.delta_w = delta_w;
                    if delta_w > 0.0 {
                        self.delta_w_last = delta_w;
                        self.perturbed_iters += 1;
                    } else {
                        self.perturbed_iters = 0;
                    }
                    return true;
                }
                Factored::Singular => true,
                Factored::WrongInertia => false,
            };
            if singular && !tried_delta_c && has_rows {
                tried_delta_c = true;
                self.delta_c = Self::delta_cd(o, mu);
                if self.delta_c > 0.0 {
                    continue;
                }
            }
            delta_w = self.next_delta_w(o, delta_w);
            if delta_w > o.max_hessian_perturbation {
                self.delta_w = delta_w;
                return false;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs one correction whose factorisation has the right inertia once δ_w ≥
    /// `needed` (singular below it when `singular`), returning the trials (δ_w, δ_c).
    fn trials(
        p: &mut Perturbation,
        o: &IpmOptions,
        mu: f64,
        needed: f64,
        singular: bool,
    ) -> (bool, Vec<(f64, f64)>) {
        let mut seen = Vec::new();
        let ok = p.correct_inertia(o, mu, true, |dw, dc| {
            seen.push((dw, dc));
            if dw >= needed {
                Factored::Correct
            } else if singular {
                Factored::Singular
            } else {
                Factored::WrongInertia
            }
        });
        (ok, seen)
    }

    fn close(a: &[(f64, f64)], b: &[(f64, f64)]) -> bool {
        let eq = |x: f64, y: f64| (x - y).abs() <= 1e-15 * y.abs().max(1e-300);
        a.len() == b.len() && a.iter().zip(b).all(|(p, q)| eq(p.0, q.0) && eq(p.1, q.1))
    }

    /// W&B 2006 Alg. IC with IPOPT's defaults (δ̄_w⁰ = 1e-4, κ̄_w⁺ = 100, κ_w⁺ = 8,
    /// κ_w⁻ = 1/3): the first perturbed iteration tries 0, 1e-4, 1e-2, 1 (×κ̄_w⁺ while
    /// no δ_w was needed before); the next one starts at κ_w⁻·δ_w_last = 1/3 and grows
    /// by κ_w⁺ = 8; an iteration whose K is fine at δ_w = 0 keeps δ_w = 0.
    #[test]
    fn delta_w_sequence_follows_ipopts_rules() {
        let o = IpmOptions::default();
        let mut p = Perturbation::default();
        let (ok, seen) = trials(&mut p, &o, 0.1, 0.5, false);
        assert!(ok);
        assert!(close(
            &seen,
            &[(0.0, 0.0), (1e-4, 0.0), (1e-2, 0.0), (1.0, 0.0)]
        ));
        assert_eq!(
            (p.delta_w, p.delta_w_last, p.perturbed_iters),
            (1.0, 1.0, 1)
        );
        let (ok, seen) = trials(&mut p, &o, 0.1, 2.0, false);
        assert!(ok);
        let third = 1.0 / 3.0;
        assert!(close(
            &seen,
            &[(0.0, 0.0), (third, 0.0), (third * 8.0, 0.0)]
        ));
        assert_eq!((p.delta_w_last, p.perturbed_iters), (third * 8.0, 2));
        let (ok, seen) = trials(&mut p, &o, 0.1, 0.0, false);
        assert!(ok && close(&seen, &[(0.0, 0.0)]));
        assert_eq!((p.delta_w, p.perturbed_iters), (0.0, 0));
        assert_eq!(
            p.delta_w_last,
            third * 8.0,
            "δ_w_last survives a δ_w = 0 iteration"
        );
    }

    /// A singular K first gets δ_c = 1e-8·μ^¼ (once), then δ_w grows with δ_c kept.
    #[test]
    fn singular_matrix_gets_delta_c_first() {
        let o = IpmOptions::default();
        let mut p = Perturbation::default();
        let mu: f64 = 1e-4;
        let dc = 1e-8 * mu.powf(0.25); // = 1e-9
        let (ok, seen) = trials(&mut p, &o, mu, 1e-3, true);
        assert!(ok);
        assert!(close(
            &seen,
            &[(0.0, 0.0), (0.0, dc), (1e-4, dc), (1e-2, dc)]
        ));
        assert_eq!((p.delta_c, p.delta_w), (dc, 1e-2));
        // With the Jacobian known degenerate, δ_c is there from the first trial.
        p.jac_degenerate = true;
        p.delta_w_last = 0.0;
        let (_, seen) = trials(&mut p, &o, mu, 0.0, true);
        assert!(close(&seen, &[(0.0, dc)]));
        // Without rows there is no δ_c to try.
        let mut q = Perturbation::default();
        let mut seen = Vec::new();
        q.correct_inertia(&o, mu, false, |dw, dc| {
            seen.push((dw, dc));
            if dw > 0.0 {
                Factored::Correct
            } else {
                Factored::Singular
            }
        });
        assert!(close(&seen, &[(0.0, 0.0), (1e-4, 0.0)]));
    }

    /// After `perturbation_skip_zero_after` perturbed iterations in a row the δ_w = 0
    /// trial is skipped; beyond `max_hessian_perturbation` the correction fails.
    #[test]
    fn skip_zero_trial_and_give_up_above_the_maximum() {
        let o = IpmOptions {
            perturbation_skip_zero_after: 2,
            max_hessian_perturbation: 1.0,
            ..IpmOptions::default()
        };
        let mut p = Perturbation::default();
        trials(&mut p, &o, 0.1, 1e-4, false);
        trials(&mut p, &o, 0.1, 1e-5, false);
        assert_eq!(p.perturbed_iters, 2);
        let last = p.delta_w_last;
        let (_, seen) = trials(&mut p, &o, 0.1, 1e-6, false);
        assert!(close(&seen, &[(last / 3.0, 0.0)]), "{seen:?}");
        let mut q = Perturbation::default();
        let (ok, seen) = trials(&mut q, &o, 0.1, f64::INFINITY, false);
        assert!(!ok);
        assert!(close(
            &seen,
            &[(0.0, 0.0), (1e-4, 0.0), (1e-2, 0.0), (1.0, 0.0)]
        ));
        assert_eq!(q.delta_w, 100.0, "the δ_w that exceeded the maximum");
    }
}
