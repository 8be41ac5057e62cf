//! IPOPT-style iteration table; usable by any solver that produces [`IterationRecord`]s.

use std::fmt::Write;

use crate::solution::{IterationRecord, Solution};

/// The columns of one back end's iteration table. Both tables share IPOPT's layout; the
/// fifth column is the back end's own: the interior point's barrier parameter μ, or the
/// SQP's augmented weight ρ_a (its records carry μ = 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Columns {
    /// IPOPT's: `lg(mu)` is log10 μ, `lg(rg)` log10 δ_w, `alpha_du`, `alpha_pr`.
    Ipm,
    /// The SQP's: `lg(ra)` is log10 ρ_a ("-" when 0), `lg(rg)` log10 of the Hessian
    /// shift, `alpha_du` and `alpha_pr` its line search's step.
    Sqp,
}

impl Columns {
    /// The back end that wrote `r`: the interior point's μ is always positive, the SQP
    /// writes μ = 0.
    pub(crate) fn of(r: &IterationRecord) -> Columns {
        if r.mu > 0.0 {
            Columns::Ipm
        } else {
            Columns::Sqp
        }
    }

    /// The header line.
    pub(crate) fn header(self) -> &'static str {
        match self {
            Columns::Ipm => {
                "iter    objective    inf_pr   inf_du lg(mu)  ||d||  lg(rg) alpha_du alpha_pr  ls"
            }
            Columns::Sqp => {
                "iter    objective    inf_pr   inf_du lg(ra)  ||d||  lg(rg) alpha_du alpha_pr  ls"
            }
        }
    }

    /// One row: `r` in these columns.
    pub(crate) fn format(self, r: &IterationRecord) -> String {
        let lg = |v: f64| {
            if v > 0.0 {
                format!("{:6.1}", v.log10())
            } else {
                "     -".to_string()
            }
        };
        let own = match self {
            Columns::Ipm => r.mu,
            Columns::Sqp => r.augmented_weight,
        };
        format!(
            "{:4}{} {:14.7e} {:8.2e} {:8.2e} {} {:8.2e} {} {:8.2e} {:8.2e}{} {:2}",
            r.iter,
            if r.restoration { 'r' } else { ' ' },
            r.objective,
            r.inf_pr,
            r.inf_du,
            lg(own),
            r.d_norm,
            lg(r.regularization),
            r.alpha_du,
            r.alpha_pr,
            r.alpha_pr_char,
            r.ls
        )
    }
}

/// One formatted table row in the columns of the back end that wrote it
/// ([`Columns::of`]).
pub fn format_record(r: &IterationRecord) -> String {
    Columns::of(r).format(r)
}

/// The whole table (header every 10 rows, as IPOPT does) in the columns of the back end
/// that wrote the records.
pub fn format_table(records: &[IterationRecord]) -> String {
    let mut s = String::new();
    let columns = records.first().map_or(Columns::Ipm, Columns::of);
    for (k, r) in records.iter().enumerate() {
        if k % 10 == 0 {
            let _ = writeln!(s, "{}", columns.header());
        }
        let _ = writeln!(s, "{}", columns.format(r));
    }
    s
}

/// A short summary of a solution (status, objective, errors, counters, timers).
pub fn format_summary(sol: &Solution) -> String {
    let st = &sol.stats;
    let mut s = String::new();
    let _ = writeln!(s, "Number of iterations....: {}", st.iterations);
    let _ = writeln!(s, "Objective...............: {:.16e}", sol.objective);
    let _ = writeln!(s, "Constraint violation....: {:.16e}", sol.constr_viol);
    let _ = writeln!(s, "Dual infeasibility......: {:.16e}", sol.dual_inf);
    let _ = writeln!(s, "Complementarity.........: {:.16e}", sol.compl);
    let _ = writeln!(
        s,
        "Evaluations: f {}, grad_f {}, g {}, jac_g {}, hess_l {}; factorizations {}",
        st.n_eval_f,
        st.n_eval_grad_f,
        st.n_eval_g,
        st.n_eval_jac_g,
        st.n_eval_hess_l,
        st.n_factorizations
    );
    let _ = writeln!(
        s,
        "Time: total {:.3}s, eval {:.3}s, factor {:.3}s, other {:.3}s",
        st.total_seconds, st.eval_seconds, st.factor_seconds, st.other_seconds
    );
    if st.n_qp_solves > 0 {
        let _ = writeln!(
            s,
            "QP solves: {} ({} QP iterations, {:.3}s)",
            st.n_qp_solves, st.qp_iterations, st.qp_seconds
        );
    }
    let _ = writeln!(s, "EXIT: {:?}", sol.status);
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(mu: f64, augmented_weight: f64) -> IterationRecord {
        IterationRecord {
            iter: 3,
            restoration: false,
            objective: 1.5,
            inf_pr: 1e-3,
            inf_du: 2e-4,
            mu,
            d_norm: 0.5,
            regularization: 0.0,
            jacobian_regularization: 0.0,
            augmented_weight,
            alpha_du: 1.0,
            alpha_pr: 0.5,
            alpha_pr_char: 'f',
            ls: 2,
        }
    }

    /// Each back end's table shows its own fifth column under its own name: μ for the
    /// IPM, ρ_a for the SQP (whose records carry μ = 0).
    #[test]
    fn each_back_end_prints_its_own_column() {
        let ipm = format_table(&[record(1e-2, 0.0)]);
        assert!(ipm.starts_with("iter") && ipm.contains("lg(mu)"), "{ipm}");
        assert!(ipm.contains("  -2.0"), "lg(mu) = log10(1e-2): {ipm}");
        let sqp = format_table(&[record(0.0, 1e3)]);
        assert!(sqp.contains("lg(ra)") && !sqp.contains("lg(mu)"), "{sqp}");
        assert!(sqp.contains("   3.0"), "lg(ra) = log10(1e3): {sqp}");
        // An IPM record never shows ρ_a, an SQP record never μ.
        let both = record(1e-2, 1e3);
        assert_eq!(Columns::of(&both), Columns::Ipm);
        assert!(!Columns::Ipm.format(&both).contains("   3.0"));
        assert!(Columns::Sqp.format(&record(0.0, 0.0)).contains("     -"));
    }
}
