//! A summary of an IPM solve's iteration records, to see *how* a slow or failed solve goes:
//! how many steps were tiny, regularised, second-order corrected or in restoration, and
//! where the barrier parameter and the errors ended.
use nlp::Solution;
use serde::Serialize;

/// Counts over the iteration records of one solve (row 0, the starting point, excluded).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Diagnosis {
    /// Iterations.
    pub iterations: usize,
    /// Iterations in restoration.
    pub restoration: usize,
    /// Steps with primal step size α < 1e-8.
    pub tiny_alpha: usize,
    /// Steps with α < 1e-3.
    pub small_alpha: usize,
    /// First iteration with α < 1e-8.
    pub first_tiny_alpha: Option<usize>,
    /// Steps whose Hessian was regularised (δ_w > 0).
    pub regularized: usize,
    /// Largest δ_w.
    pub max_regularization: f64,
    /// Steps whose equality rows carried the Jacobian regularisation δ_c > 0.
    pub jacobian_regularized: usize,
    /// First iteration with δ_c > 0.
    pub first_jacobian_regularized: Option<usize>,
    /// f-type steps (IPOPT's 'f'/'F').
    pub f_steps: usize,
    /// h-type steps ('h'/'H').
    pub h_steps: usize,
    /// Steps with a second-order correction (upper-case step character).
    pub soc_steps: usize,
    /// Backtracking trials, summed.
    pub line_search_trials: usize,
    /// Objective (unscaled) at the last iteration.
    pub final_objective: f64,
    /// μ at the last iteration.
    pub final_mu: f64,
    /// Primal infeasibility at the last iteration.
    pub final_inf_pr: f64,
    /// Dual infeasibility at the last iteration.
    pub final_inf_du: f64,
}

/// Summarises `sol.stats.records`.
pub fn diagnose(sol: &Solution) -> Diagnosis {
    let mut d = Diagnosis {
        iterations: sol.stats.iterations,
        restoration: sol.stats.restoration_iterations,
        ..Default::default()
    };
    for r in sol.stats.records.iter().skip(1) {
        if r.alpha_pr < 1e-8 {
            d.tiny_alpha += 1;
            d.first_tiny_alpha.get_or_insert(r.iter);
        }
        d.small_alpha += usize::from(r.alpha_pr < 1e-3);
        if r.regularization > 0.0 {
            d.regularized += 1;
            d.max_regularization = d.max_regularization.max(r.regularization);
        }
        if r.jacobian_regularization() > 0.0 {
            d.jacobian_regularized += 1;
            d.first_jacobian_regularized.get_or_insert(r.iter);
        }
        match r.alpha_pr_char {
            'f' => d.f_steps += 1,
            'F' => {
                d.f_steps += 1;
                d.soc_steps += 1
            }
            'h' => d.h_steps += 1,
            'H' => {
                d.h_steps += 1;
                d.soc_steps += 1
            }
            _ => {}
        }
        d.line_search_trials += r.ls;
    }
    if let Some(last) = sol.stats.records.last() {
        d.final_objective = last.objective;
        d.final_mu = last.mu().unwrap_or(0.0);
        d.final_inf_pr = last.inf_pr;
        d.final_inf_du = last.inf_du;
    }
    d
}
