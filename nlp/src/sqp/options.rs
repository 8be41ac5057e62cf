//! [`SqpOptions`]: every option of the SQP method with its default, in one place.
//!
//! Termination options have the names, meanings and defaults of the interior-point
//! method's ([`IpmOptions`](crate::IpmOptions)), so a switch of back end keeps the
//! meaning of "converged".

use serde::{Deserialize, Serialize};

use crate::error::SolveError;
use crate::frontend::CommonOptions;

/// How the QP Hessian `B` is obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HessianApproximation {
    /// The exact Lagrangian Hessian, shifted by δ·I until it is positive definite (δ is
    /// found by trial factorisations of the KKT matrix (faer LDLᵀ) and counting the inertia,
    /// as IPOPT's inertia correction does). Default.
    Exact,
    /// Damped BFGS (Powell 1978) on a dense n×n matrix: for small problems or when
    /// second derivatives are unreliable.
    DampedBfgs,
}

/// All options of the SQP method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", default)]
pub struct SqpOptions {
    /// Termination, scaling bounds and output, the same options as the interior-point
    /// method's ([`CommonOptions`]; its fields read and write as fields of this struct).
    #[serde(flatten)]
    pub common: CommonOptions,
    // ---------- scaling ----------
    /// Gradient-based scaling of objective and constraints at the start. Default true.
    pub gradient_scaling: bool,
    // ---------- Hessian ----------
    /// Exact (shifted) Hessian or damped BFGS. Default exact.
    pub hessian_approximation: HessianApproximation,
    /// First trial shift δ when the Hessian is not positive definite. Default 1e-4.
    pub first_hessian_shift: f64,
    /// Smallest shift tried after a shifted iteration (δ_last/3, at least this). Default 1e-20.
    pub min_hessian_shift: f64,
    /// Largest shift before giving up with `ErrorInStepComputation`. Default 1e20.
    pub max_hessian_shift: f64,
    /// Largest augmented-Lagrangian weight ρ_a in B = H + δI + ρ_a·(J_AᵀJ_A + I_b); the
    /// test at this weight stands for "positive definite on the null space of the active
    /// constraints" when the shift δ is chosen. Default 1e6.
    pub max_augmented_weight: f64,
    // ---------- merit function and line search ----------
    /// Initial ℓ1 penalty ρ (merit φ = f + ρ·‖violation‖₁, also the cost of the QP's
    /// elastic variables). Default 10.
    pub penalty_init: f64,
    /// Largest penalty ρ. Default 1e8.
    pub penalty_max: f64,
    /// Factor by which ρ grows when the linearised constraints need the elastic
    /// variables (infeasible or nearly infeasible QP). Default 10.
    pub penalty_increase: f64,
    /// Individual merit weights (Powell 1978): the merit is f + Σ w_i·viol_i with
    /// w_i = max(|λ_i|, ½(w_i + |λ_i|)) from the QP multipliers, kept within
    /// [`penalty_weight_floor`·ρ, ρ]; false: w_i = ρ for every row (the classical ℓ1
    /// merit). Default true.
    pub individual_penalties: bool,
    /// Lower bound of the individual merit weights, as a fraction of ρ. Default 1e-3.
    pub penalty_weight_floor: f64,
    /// Armijo constant η in φ(x + αd) ≤ φ(x) − η·α·pred. Default 1e-4.
    pub armijo: f64,
    /// Backtracking factor. Default 0.5.
    pub backtrack: f64,
    /// Smallest step size before the line search fails. Default 1e-12.
    pub min_step: f64,
    /// Try a second-order correction when the full step is rejected. Default true.
    pub second_order_correction: bool,
    // ---------- QP (clarabel) ----------
    /// Clarabel's gap and feasibility tolerances for the QP subproblems. Default 1e-10.
    pub qp_tol: f64,
    /// Maximum clarabel iterations per QP. Default 200.
    pub qp_max_iter: u32,
    /// An elastic variable above this value means the linearised constraint could not be
    /// satisfied (elastic mode). Default 1e-8.
    pub elastic_tol: f64,
    /// Polish each QP step: solve the equality QP on clarabel's active set exactly with
    /// the faer LDLᵀ and keep it when it is a KKT point of the QP (not with cones or
    /// elastic variables in use). Clarabel's own accuracy is relative to its scaled
    /// problem; on reduced Hessians with curvatures far apart its step error stalled the
    /// SQP (benches/reference/results/performance-notebook.md, "SQP on the flagship"). Default true.
    pub qp_polish: bool,
    /// Solve each QP first with the warm-started primal-dual active-set method over the
    /// faer LDLᵀ (from the previous QP's working set), and with clarabel only when that
    /// fails (cycling, iteration limit, singular or non-convex working set, a multiplier
    /// above ρ) or cones or BFGS are in use. Default true.
    pub qp_active_set: bool,
    /// Most iterations (factorisations) of the active-set method per QP before clarabel
    /// takes over. Default 100 (one clarabel solve of the cold cart-pole's QPs costs
    /// about as many instructions as 100 active-set iterations).
    pub qp_active_set_max_iter: u32,
    // ---------- cold start ----------
    /// Without a warm start, solve first with the interior-point method ([`crate::Ipm`],
    /// with these common options) and start the SQP from its solution (x and the
    /// multipliers λ, z_L, z_U); a cold SQP start when the IPM does not succeed. The SQP
    /// then confirms a converged IPM solution in 0–2 iterations. From a cold start the
    /// SQP alone fails where the IPM does not (4 of the 15 optimal-control problems of
    /// the cold corpus, 3 of 73 Hock–Schittkowski problems: docs/solvers.md); with the
    /// start it solves every one, at 1.1–1.2× the IPM's time. `max_iter` and
    /// `max_wall_time` apply to each of the two solves; `Solution::stats` count both
    /// (`Stats::start_iterations` the IPM's share). When the SQP does not succeed from
    /// the IPM's solution, that solution is returned with the IPM's status (e.g. hs013,
    /// whose optimum has no KKT point) and a message saying so. Warm solves
    /// ([`Sqp::solve_warm`](crate::Sqp::solve_warm), a start passed in) are the SQP's
    /// alone. Default true; false runs the SQP alone from the problem's initial guess.
    pub cold_start_ipm: bool,
}

crate::frontend::strict_options_serde!(SqpOptions);

impl Default for SqpOptions {
    fn default() -> Self {
        SqpOptions {
            common: CommonOptions::default(),
            gradient_scaling: true,
            hessian_approximation: HessianApproximation::Exact,
            first_hessian_shift: 1e-4,
            min_hessian_shift: 1e-20,
            max_hessian_shift: 1e20,
            max_augmented_weight: 1e6,
            penalty_init: 10.0,
            penalty_max: 1e8,
            penalty_increase: 10.0,
            individual_penalties: true,
            penalty_weight_floor: 1e-3,
            armijo: 1e-4,
            backtrack: 0.5,
            min_step: 1e-12,
            second_order_correction: true,
            qp_tol: 1e-10,
            qp_max_iter: 200,
            elastic_tol: 1e-8,
            qp_polish: true,
            qp_active_set: true,
            qp_active_set_max_iter: 100,
            cold_start_ipm: true,
        }
    }
}

fn bad(field: &'static str, reason: impl Into<String>) -> SolveError {
    SolveError::InvalidOption {
        field,
        reason: reason.into(),
    }
}

impl SqpOptions {
    /// Checks every option; the error names the first bad field.
    pub fn validate(&self) -> Result<(), SolveError> {
        self.common.validate()?;
        macro_rules! positive {
            ($($f:ident),*) => {$(
                if self.$f.is_nan() || self.$f <= 0.0 || !self.$f.is_finite() {
                    return Err(bad(stringify!($f), format!("must be finite and > 0, got {}", self.$f)));
                }
            )*};
        }
        macro_rules! open_unit {
            ($($f:ident),*) => {$(
                if self.$f.is_nan() || self.$f <= 0.0 || self.$f >= 1.0 {
                    return Err(bad(stringify!($f), format!("must be in (0, 1), got {}", self.$f)));
                }
            )*};
        }
        positive!(
            first_hessian_shift,
            min_hessian_shift,
            max_hessian_shift,
            max_augmented_weight,
            penalty_init,
            penalty_max,
            penalty_weight_floor,
            qp_tol,
            elastic_tol,
            min_step
        );
        open_unit!(armijo, backtrack);
        if self.penalty_increase <= 1.0 || !self.penalty_increase.is_finite() {
            return Err(bad(
                "penalty_increase",
                format!("must be finite and > 1, got {}", self.penalty_increase),
            ));
        }
        if self.penalty_init > self.penalty_max {
            return Err(bad(
                "penalty_init",
                format!(
                    "{} exceeds penalty_max {}",
                    self.penalty_init, self.penalty_max
                ),
            ));
        }
        if self.min_hessian_shift > self.first_hessian_shift
            || self.first_hessian_shift > self.max_hessian_shift
        {
            return Err(bad(
                "first_hessian_shift",
                "need min_hessian_shift <= first_hessian_shift <= max_hessian_shift",
            ));
        }
        if self.qp_max_iter == 0 {
            return Err(bad("qp_max_iter", "must be at least 1"));
        }
        if self.qp_active_set_max_iter == 0 {
            return Err(bad("qp_active_set_max_iter", "must be at least 1"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::SqpOptions;
    use crate::error::SolveError;

    #[test]
    fn defaults_validate_and_round_trip() {
        let o = SqpOptions::default();
        o.validate().unwrap();
        let s = serde_json::to_string(&o).unwrap();
        let back: SqpOptions = serde_json::from_str(&s).unwrap();
        assert_eq!(o, back);
        let err = serde_json::from_str::<SqpOptions>("{\"tol\": 1e-6, \"toll\": 1}");
        assert!(err.is_err());
        let o = SqpOptions {
            armijo: 1.5,
            ..SqpOptions::default()
        };
        assert!(matches!(
            o.validate(),
            Err(SolveError::InvalidOption {
                field: "armijo",
                ..
            })
        ));
    }
}
