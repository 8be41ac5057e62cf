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
    delta_w: f64,
    /// The last nonzero δ_w (0 if none was needed yet, or after a restoration phase).
    delta_w_last: f64,
    /// δ_c of the current factorisation.
    delta_c: f64,
    /// δ_c is applied from the start (after three singular iterations in a row).
    jac_degenerate: bool,
    /// Iterations in a row whose unregularised system was singular.
    singular_iters: usize,
    /// Iterations in a row that needed δ_w > 0.
    perturbed_iters: usize,
    /// A step was solved without δ_c: the Jacobian is not degenerate, and
    /// `jac_degenerate` can no longer be set (IPOPT's PDPerturbationHandler decides
    /// degeneracy once, in the first iterations: "Nj" in its info string).
    jac_determined: bool,
}

impl Perturbation {
    /// δ_w of the current factorisation.
    pub(super) fn delta_w(&self) -> f64 {
        self.delta_w
    }

    /// δ_c of the current factorisation.
    pub(super) fn delta_c(&self) -> f64 {
        self.delta_c
    }

    /// A restoration phase moved the iterate: the next δ_w starts afresh (from
    /// `first_hessian_perturbation`).
    pub(super) fn forget_last_delta_w(&mut self) {
        self.delta_w_last = 0.0;
    }

    /// A step was solved without δ_c: the Jacobian is not degenerate (decided for good).
    pub(super) fn solved_without_delta_c(&mut self) {
        self.singular_iters = 0;
        self.jac_determined = true;
    }

    /// The unregularised system was singular (IPOPT's regularised step): counts the
    /// singular iteration, marks the Jacobian degenerate at the third in a row unless
    /// it was found regular before, and returns δ_c(μ), the δ_c to refactorise with.
    pub(super) fn singular_system(&mut self, o: &IpmOptions, mu: f64) -> f64 {
        self.singular_iters += 1;
        if self.singular_iters >= 3 && !self.jac_determined {
            self.jac_degenerate = true;
        }
        self.delta_c = Self::delta_cd(o, mu);
        self.delta_c
    }

    /// The factorisation with δ_c failed: go on without it.
    pub(super) fn drop_delta_c(&mut self) {
        self.delta_c = 0.0;
    }

    /// δ_w raised by the regularised step is the current (and last) δ_w.
    pub(super) fn raise_delta_w(&mut self, delta_w: f64) {
        self.delta_w = delta_w;
        self.delta_w_last = delta_w;
    }

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
    use super::{Factored, Perturbation};
    use crate::options::IpmOptions;

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

    /// IPOPT's degeneracy decision: three singular systems in a row before any step was
    /// solved without δ_c mark the Jacobian degenerate (δ_c from the first trial on);
    /// once a step was solved without δ_c, singular systems no longer do.
    #[test]
    fn three_singular_systems_in_a_row_mark_the_jacobian_degenerate() {
        let o = IpmOptions::default();
        let mu: f64 = 1e-4;
        let dc = 1e-8 * mu.powf(0.25);
        let mut p = Perturbation::default();
        for k in 1..=3 {
            assert!(!p.jac_degenerate, "before singular system {k}");
            assert_eq!(p.singular_system(&o, mu), dc);
        }
        assert!(p.jac_degenerate);
        let (_, seen) = trials(&mut p, &o, mu, 0.0, false);
        assert!(close(&seen, &[(0.0, dc)]), "{seen:?}");
        let mut q = Perturbation::default();
        q.singular_system(&o, mu);
        q.solved_without_delta_c();
        for _ in 0..5 {
            q.singular_system(&o, mu);
        }
        assert!(
            !q.jac_degenerate,
            "decided regular once a step needed no δ_c"
        );
        q.drop_delta_c();
        assert_eq!(q.delta_c(), 0.0);
        // A raised δ_w is the next iteration's κ_w⁻·δ_w_last start; forgetting it
        // (after a restoration phase) restarts from first_hessian_perturbation.
        q.raise_delta_w(0.9);
        assert_eq!(q.next_delta_w(&o, 0.0), 0.3);
        q.forget_last_delta_w();
        assert_eq!(q.next_delta_w(&o, 0.0), o.first_hessian_perturbation);
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
