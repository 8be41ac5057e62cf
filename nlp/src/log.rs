//! IPOPT-style iteration table; usable by any solver that produces [`IterationRecord`]s.

use std::fmt::Write;

use crate::solution::{BackendColumns, IterationRecord, Solution};

/// Writes solver log text to standard output, best effort: when it is closed or fails
/// (the program's output piped into `head`, a closed terminal) the text is dropped and
/// the solve goes on; `print!` would panic mid-solve (use [`log_out!`](crate::log_out)).
pub(crate) fn write_out(args: std::fmt::Arguments<'_>) {
    use std::io::Write as _;
    let _ = std::io::stdout().lock().write_fmt(args);
}

/// `println!` for the solvers' logs that never panics ([`write_out`]).
macro_rules! log_out {
    ($($arg:tt)*) => {
        $crate::log::write_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}
pub(crate) use log_out;

/// The header line of a table of rows with columns `backend`: IPOPT's layout, the fifth
/// column the back end's own (`lg(mu)`: log10 μ of the interior point; `lg(ra)`: log10 ρ_a
/// of the SQP, "-" when 0). `lg(rg)` is log10 of the Hessian regularisation, `alpha_du`
/// and `alpha_pr` the step sizes.
pub(crate) fn header(backend: &BackendColumns) -> &'static str {
    match backend {
        BackendColumns::Ipm { .. } => {
            "iter    objective    inf_pr   inf_du lg(mu)  ||d||  lg(rg) alpha_du alpha_pr  ls"
        }
        BackendColumns::Sqp { .. } => {
            "iter    objective    inf_pr   inf_du lg(ra)  ||d||  lg(rg) alpha_du alpha_pr  ls"
        }
    }
}

/// One formatted table row, in the columns of the back end that wrote it
/// ([`IterationRecord::backend`]).
pub fn format_record(r: &IterationRecord) -> String {
    let lg = |v: f64| {
        if v > 0.0 {
            format!("{:6.1}", v.log10())
        } else {
            "     -".to_string()
        }
    };
    let own = match r.backend {
        BackendColumns::Ipm { mu, .. } => mu,
        BackendColumns::Sqp { augmented_weight } => augmented_weight,
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

/// The whole table (header every 10 rows, as IPOPT does) in the columns of the back end
/// that wrote the records.
pub fn format_table(records: &[IterationRecord]) -> String {
    let mut s = String::new();
    for (k, r) in records.iter().enumerate() {
        if k % 10 == 0 {
            let _ = writeln!(s, "{}", header(&r.backend));
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

#[cfg(test)]
mod tests {
    use super::{format_record, format_table};
    use crate::solution::{BackendColumns, IterationRecord};

    fn record(backend: BackendColumns) -> IterationRecord {
        IterationRecord {
            iter: 3,
            d_norm: 0.5,
            inf_pr: 1e-3,
            inf_du: 2e-4,
            alpha_du: 1.0,
            alpha_pr: 0.5,
            alpha_pr_char: 'f',
            ls: 2,
            ..IterationRecord::starting_point(1.5, backend)
        }
    }

    /// Each back end's table shows its own fifth column under its own name: μ for the
    /// IPM, ρ_a for the SQP, whatever the values.
    #[test]
    fn each_back_end_prints_its_own_column() {
        let ipm = record(BackendColumns::Ipm {
            mu: 1e-2,
            jacobian_regularization: 1e3,
        });
        let table = format_table(&[ipm]);
        assert!(
            table.starts_with("iter") && table.contains("lg(mu)"),
            "{table}"
        );
        assert!(table.contains("  -2.0"), "lg(mu) = log10(1e-2): {table}");
        // δ_c is not printed (as in IPOPT).
        assert!(!table.contains("   3.0"), "{table}");
        let sqp = format_table(&[record(BackendColumns::Sqp {
            augmented_weight: 1e3,
        })]);
        assert!(sqp.contains("lg(ra)") && !sqp.contains("lg(mu)"), "{sqp}");
        assert!(sqp.contains("   3.0"), "lg(ra) = log10(1e3): {sqp}");
        // A zero ρ_a (no convexification) is "-", not a guess at another back end.
        let plain = record(BackendColumns::Sqp {
            augmented_weight: 0.0,
        });
        assert!(format_table(&[plain]).contains("lg(ra)"));
        assert!(format_record(&plain).contains("     -"));
    }
}
