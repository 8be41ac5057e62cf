//! IPOPT-style iteration table; usable by any solver that produces [`IterationRecord`]s.

use std::fmt::Write;

use crate::solution::{IterationRecord, Solution};

/// Header line of the iteration table.
pub fn header() -> String {
    "iter    objective    inf_pr   inf_du lg(mu)  ||d||  lg(rg) alpha_du alpha_pr  ls".to_string()
}

/// One formatted table row. The lg(mu) column shows the interior point's μ, or in the
/// SQP's rows (μ = 0) its augmented weight ρ_a.
pub fn format_record(r: &IterationRecord) -> String {
    let lg = |v: f64| {
        if v > 0.0 {
            format!("{:6.1}", v.log10())
        } else {
            "     -".to_string()
        }
    };
    format!(
        "{:4}{} {:14.7e} {:8.2e} {:8.2e} {} {:8.2e} {} {:8.2e} {:8.2e}{} {:2}",
        r.iter,
        if r.restoration { 'r' } else { ' ' },
        r.objective,
        r.inf_pr,
        r.inf_du,
        lg(if r.mu > 0.0 { r.mu } else { r.augmented_weight }),
        r.d_norm,
        lg(r.regularization),
        r.alpha_du,
        r.alpha_pr,
        r.alpha_pr_char,
        r.ls
    )
}

/// The whole table (header every 10 rows, as IPOPT does).
pub fn format_table(records: &[IterationRecord]) -> String {
    let mut s = String::new();
    for (k, r) in records.iter().enumerate() {
        if k % 10 == 0 {
            let _ = writeln!(s, "{}", header());
        }
        let _ = writeln!(s, "{}", format_record(r));
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
