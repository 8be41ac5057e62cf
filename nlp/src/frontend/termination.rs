//! One convergence test for both back ends: IPOPT's (Wächter & Biegler 2006, §2.1 and
//! the options `tol`, `dual_inf_tol`, `constr_viol_tol`, `compl_inf_tol` and
//! `acceptable_*`), on a [`KktResiduals`] each back end measures at its iterate.

use super::CommonOptions;
use crate::solution::Status;

/// The KKT error of an iterate: the scaled overall error that `tol` bounds and its
/// parts in the user's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct KktResiduals {
    /// IPOPT's E_0 = max(‖∇L‖/s_d, ‖c‖, ‖complementarity‖/s_c) on the scaled problem.
    pub overall: f64,
    /// Dual infeasibility, unscaled (max-norm).
    pub dual: f64,
    /// Constraint violation, unscaled (max-norm).
    pub primal: f64,
    /// Complementarity, unscaled (max-norm).
    pub compl: f64,
}

/// The state of the test across iterations: the count of consecutive acceptable
/// iterates and the previous objective.
#[derive(Debug, Clone)]
pub(crate) struct Termination {
    acceptable_count: usize,
    last_objective: f64,
}

impl Default for Termination {
    fn default() -> Self {
        Termination {
            acceptable_count: 0,
            last_objective: f64::INFINITY,
        }
    }
}

impl Termination {
    /// Tests the iterate with residuals `e` and (scaled) objective `f`:
    /// `SolveSucceeded` when every tolerance holds, `SolvedToAcceptableLevel` after
    /// `acceptable_iter` consecutive iterates within every `acceptable_*` tolerance
    /// (the relative objective change measured against the previous call's `f`),
    /// `None` otherwise. Call once per iteration.
    pub fn check(&mut self, e: &KktResiduals, f: f64, o: &CommonOptions) -> Option<Status> {
        let obj_change = (f - self.last_objective).abs() / f.abs().max(1.0);
        self.last_objective = f;
        if e.overall <= o.tol
            && e.dual <= o.dual_inf_tol
            && e.primal <= o.constr_viol_tol
            && e.compl <= o.compl_inf_tol
        {
            return Some(Status::SolveSucceeded);
        }
        if o.acceptable_iter > 0
            && e.overall <= o.acceptable_tol
            && e.dual <= o.acceptable_dual_inf_tol
            && e.primal <= o.acceptable_constr_viol_tol
            && e.compl <= o.acceptable_compl_inf_tol
            && obj_change <= o.acceptable_obj_change_tol
        {
            self.acceptable_count += 1;
            if self.acceptable_count >= o.acceptable_iter {
                return Some(Status::SolvedToAcceptableLevel);
            }
        } else {
            self.acceptable_count = 0;
        }
        None
    }

    /// Whether the last tested iterate was acceptable (the IPM ends a failed line search
    /// of an unconstrained problem as `SolvedToAcceptableLevel` then).
    pub fn last_was_acceptable(&self) -> bool {
        self.acceptable_count > 0
    }

    /// Forgets the previous objective without testing (an iteration that skips the
    /// test still moves the reference of the objective change).
    pub fn set_last_objective(&mut self, f: f64) {
        self.last_objective = f;
    }
}

#[cfg(test)]
mod tests {
    use super::{KktResiduals, Termination};
    use crate::frontend::CommonOptions;
    use crate::solution::Status;

    fn res(overall: f64, dual: f64, primal: f64, compl: f64) -> KktResiduals {
        KktResiduals {
            overall,
            dual,
            primal,
            compl,
        }
    }

    #[test]
    fn converged_needs_every_tolerance() {
        let o = CommonOptions::default();
        let mut t = Termination::default();
        assert_eq!(
            t.check(&res(1e-9, 0.1, 1e-5, 1e-5), 1.0, &o),
            Some(Status::SolveSucceeded)
        );
        // constr_viol_tol = 1e-4 fails although the scaled error is tiny
        assert_eq!(t.check(&res(1e-9, 0.1, 1e-3, 1e-5), 1.0, &o), None);
    }

    #[test]
    fn acceptable_honours_every_option() {
        let o = CommonOptions {
            acceptable_iter: 2,
            ..CommonOptions::default()
        };
        let ok = res(1e-7, 1.0, 1e-3, 1e-3);
        // Iteration 0 is never acceptable: no previous objective (change = ∞).
        let mut t = Termination::default();
        assert_eq!(t.check(&ok, 1.0, &o), None);
        assert_eq!(t.check(&ok, 1.0, &o), None);
        assert_eq!(t.check(&ok, 1.0, &o), Some(Status::SolvedToAcceptableLevel));
        // Each acceptable_* option breaks the streak on its own.
        for bad in [
            res(1e-5, 1.0, 1e-3, 1e-3),  // acceptable_tol 1e-6
            res(1e-7, 1e11, 1e-3, 1e-3), // acceptable_dual_inf_tol 1e10
            res(1e-7, 1.0, 1e-1, 1e-3),  // acceptable_constr_viol_tol 1e-2
            res(1e-7, 1.0, 1e-3, 1e-1),  // acceptable_compl_inf_tol 1e-2
        ] {
            let mut t = Termination::default();
            t.check(&ok, 1.0, &o);
            t.check(&ok, 1.0, &o);
            assert_eq!(t.check(&bad, 1.0, &o), None, "{bad:?}");
            assert!(!t.last_was_acceptable());
        }
        let tight = CommonOptions {
            acceptable_obj_change_tol: 1e-3,
            ..o
        };
        let mut t = Termination::default();
        t.check(&ok, 1.0, &tight);
        t.check(&ok, 1.0, &tight);
        assert_eq!(t.check(&ok, 2.0, &tight), None, "objective changed by 50 %");
    }
}
