//! Options of the interior-point solver. Names and defaults follow IPOPT where the concept
//! is the same.

#![allow(clippy::neg_cmp_op_on_partial_ord)]

use serde::{Deserialize, Serialize};

use crate::error::SolveError;
use crate::frontend::CommonOptions;

/// Barrier parameter update strategy (IPOPT `mu_strategy`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MuStrategy {
    /// Fiacco–McCormick monotone decrease (IPOPT's default).
    Monotone,
    /// Adaptive μ chosen by an oracle each iteration, globalised by a KKT-error test.
    Adaptive,
}

/// Oracle for the adaptive barrier parameter (IPOPT `mu_oracle`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MuOracle {
    /// Mehrotra's probing heuristic (affine-scaling predictor step).
    Probing,
    /// LOQO's centrality rule.
    Loqo,
    /// IPOPT's default oracle: σ minimising a prediction of the KKT error after the
    /// step (golden-section search; `quality_function_*`, `sigma_min`, `sigma_max`).
    QualityFunction,
}

/// Norm of the quality function's parts (IPOPT `quality_function_norm_type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum QualityFunctionNorm {
    /// Mean absolute value.
    #[serde(rename = "1-norm")]
    OneNorm,
    /// Mean square (IPOPT's default).
    #[serde(rename = "2-norm-squared")]
    TwoNormSquared,
    /// Largest absolute value.
    #[serde(rename = "max-norm")]
    MaxNorm,
    /// Root mean square.
    #[serde(rename = "2-norm")]
    TwoNorm,
}

/// Centrality penalty of the quality function (IPOPT `quality_function_centrality`),
/// with ξ = min/mean of the predicted complementarity products.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum QualityFunctionCentrality {
    /// No penalty (IPOPT's default).
    None,
    /// −compl·ln ξ.
    Log,
    /// compl/ξ.
    Reciprocal,
    /// compl/ξ³.
    CubedReciprocal,
}

/// Balancing term of the quality function (IPOPT `quality_function_balancing_term`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum QualityFunctionBalancingTerm {
    /// None (IPOPT's default).
    None,
    /// max(0, max(dual, primal) − compl)³.
    Cubic,
}

/// NLP scaling method (IPOPT `nlp_scaling_method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ScalingMethod {
    /// No scaling.
    None,
    /// Scale f and each g_i so that the max-norm of its gradient at x0 is at most
    /// `nlp_scaling_max_gradient`.
    GradientBased,
}

/// Where the Hessian of the Lagrangian comes from (IPOPT `hessian_approximation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IpmHessian {
    /// The exact Hessian from [`NumericNlp::eval_hess_l`](crate::NumericNlp::eval_hess_l).
    Exact,
    /// A limited-memory quasi-Newton approximation built from gradients only
    /// (`eval_hess_l` is never called; an empty Hessian pattern is fine).
    LimitedMemory,
}

/// Quasi-Newton formula of the limited-memory Hessian (IPOPT `limited_memory_update_type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LimitedMemoryUpdate {
    /// BFGS, skipping pairs with sᵀy ≤ √ε‖s‖‖y‖ (positive definite approximation).
    Bfgs,
    /// Symmetric rank one (may be indefinite; the inertia correction handles that).
    Sr1,
}

/// How σ of B₀ = σI is chosen after each update (IPOPT `limited_memory_initialization`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LimitedMemoryInit {
    /// σ = sᵀy / sᵀs of the newest pair.
    Scalar1,
    /// σ = yᵀy / sᵀy of the newest pair.
    Scalar2,
    /// Arithmetic mean of scalar1 and scalar2.
    Scalar3,
    /// Geometric mean of scalar1 and scalar2.
    Scalar4,
    /// σ = `limited_memory_init_val` always.
    Constant,
}

/// All options of the interior-point method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(remote = "Self", default)]
pub struct IpmOptions {
    /// Termination, scaling bounds and output, shared with the SQP ([`CommonOptions`];
    /// its fields read and write as fields of this struct, see the `Deref` impl).
    #[serde(flatten)]
    pub common: CommonOptions,
    // ---------- barrier parameter ----------
    /// Barrier parameter update strategy. Default `None`, IPOPT's: monotone with the
    /// exact Hessian, adaptive with `hessian_approximation = limited-memory`; a value set
    /// here (or by name) always wins.
    pub mu_strategy: Option<MuStrategy>,
    /// Oracle for the adaptive strategy. Default quality-function (IPOPT's).
    pub mu_oracle: MuOracle,
    /// Largest centring parameter σ of the quality-function oracle. Default 100.
    pub sigma_max: f64,
    /// Smallest centring parameter σ of the quality-function oracle. Default 1e-6.
    pub sigma_min: f64,
    /// Norm of the quality function's parts. Default 2-norm-squared.
    pub quality_function_norm_type: QualityFunctionNorm,
    /// Centrality penalty of the quality function. Default none.
    pub quality_function_centrality: QualityFunctionCentrality,
    /// Balancing term of the quality function. Default none.
    pub quality_function_balancing_term: QualityFunctionBalancingTerm,
    /// Most golden-section steps of the quality-function oracle. Default 8.
    pub quality_function_max_section_steps: usize,
    /// The golden section stops when its bracket is below this × its upper end. Default 1e-2.
    pub quality_function_section_sigma_tol: f64,
    /// The golden section stops when 1 − min q / max q of its four points is below this.
    /// Default 0.
    pub quality_function_section_qf_tol: f64,
    /// Initial barrier parameter. Default 0.1.
    pub mu_init: f64,
    /// Maximum barrier parameter (adaptive strategy). Default 1e5.
    pub mu_max: f64,
    /// Minimum barrier parameter. Default 1e-11.
    pub mu_min: f64,
    /// κ_ε: the subproblem is solved when its error is below κ_ε·μ. Default 10.
    pub barrier_tol_factor: f64,
    /// κ_μ: linear decrease factor of μ. Default 0.2.
    pub mu_linear_decrease_factor: f64,
    /// θ_μ: superlinear decrease power of μ. Default 1.5.
    pub mu_superlinear_decrease_power: f64,
    /// Allow several μ decreases at one iterate. Default true.
    pub mu_allow_fast_monotone_decrease: bool,
    /// Lower bound of the fraction-to-the-boundary parameter τ. Default 0.99.
    pub tau_min: f64,
    /// Required KKT-error reduction factor in adaptive free mode. Default 0.9999.
    pub adaptive_mu_kkterror_red_fact: f64,
    /// Number of reference KKT errors kept in adaptive free mode. Default 4.
    pub adaptive_mu_kkterror_red_iters: usize,
    /// μ = this × average complementarity when switching to monotone mode. Default 0.8.
    pub adaptive_mu_monotone_init_factor: f64,
    // ---------- scaling ----------
    /// NLP scaling method. Default gradient-based.
    pub nlp_scaling_method: ScalingMethod,
    /// **Not an IPOPT option.** With gradient-based scaling, an equality row whose
    /// gradient max-norm at x0 is non-zero and below this is scaled *up* so that it
    /// becomes this value (factor at most `nlp_scaling_max_value`); IPOPT only scales
    /// down. Inequality rows are left alone (their slack's barrier term already
    /// regularises them; scaling them too took the gap-crossing crawl from 165 to 210
    /// iterations). Then `tol` bounds a constraint's violation in units of x rather than of
    /// g, and multipliers and KKT regularisation see O(1) rows. The objective is never
    /// scaled up (a sum of many small terms has small gradient entries without being
    /// small, and its multipliers would grow with the factor). 0 gives IPOPT's
    /// behaviour. Default 0.5: the hanging chain with 50 000 links (row gradients 8e-5,
    /// entries of g in units of 1.6e-9) fails without it and solves to the discrete
    /// catenary in 8 iterations with it (0.5, 1 and 2 all do); 1 and 2 also scale
    /// gap-crossing rows with gradients in [0.5, 2), which made one crawl scenario end in
    /// restoration failure (1) or the flat crawl take 223 instead of 173 iterations (2).
    /// See docs/solvers.md.
    pub nlp_scaling_min_gradient: f64,
    /// **Not an IPOPT option.** Largest factor of the upward scaling by
    /// `nlp_scaling_min_gradient` (a row whose gradient vanishes at x0 is left alone; one
    /// whose gradient is merely tiny there must not be blown up). Default 1e4.
    pub nlp_scaling_max_value: f64,
    /// User objective scaling factor (multiplies the automatic one). Default 1.
    pub obj_scaling_factor: f64,
    // ---------- initialisation ----------
    /// Absolute push of the initial point into the interior. Default 1e-2.
    pub bound_push: f64,
    /// Relative push of the initial point into the interior. Default 1e-2.
    pub bound_frac: f64,
    /// Absolute push of initial slacks. Default 1e-2.
    pub slack_bound_push: f64,
    /// Relative push of initial slacks. Default 1e-2.
    pub slack_bound_frac: f64,
    /// Relative relaxation of all bounds: each finite bound moves outwards by
    /// bound_relax_factor·max(1, |bound|). Default 1e-8.
    pub bound_relax_factor: f64,
    /// Project the final x onto the original (unrelaxed) variable bounds. The reported
    /// violations are those of the projected point. Default false (IPOPT 3.14's "no";
    /// IPOPT ≤ 3.13 defaulted to "yes").
    pub honor_original_bounds: bool,
    /// Initial bound multipliers. Default 1.
    pub bound_mult_init_val: f64,
    /// Least-squares multipliers larger than this are discarded (set to 0). Default 1e3.
    pub constr_mult_init_max: f64,
    /// Absolute bound push for warm starts. Default 1e-3.
    pub warm_start_bound_push: f64,
    /// Relative bound push for warm starts. Default 1e-3.
    pub warm_start_bound_frac: f64,
    /// Absolute slack push for warm starts. Default 1e-3.
    pub warm_start_slack_bound_push: f64,
    /// Relative slack push for warm starts. Default 1e-3.
    pub warm_start_slack_bound_frac: f64,
    /// Minimum bound multiplier for warm starts. Default 1e-3.
    pub warm_start_mult_bound_push: f64,
    /// Initial μ for [`Ipm::solve_warm`](crate::ipm::Ipm::solve_warm) (IPOPT users set
    /// mu_init small when warm starting). Default 1e-6.
    pub warm_start_mu_init: f64,
    // ---------- line search ----------
    /// Maximum number of second-order corrections. Default 4.
    pub max_soc: usize,
    /// κ_soc: required reduction of the infeasibility in each SOC. Default 0.99.
    pub kappa_soc: f64,
    /// θ_max = theta_max_fact·max(1, θ(x0)). Default 1e4.
    pub theta_max_fact: f64,
    /// θ_min = theta_min_fact·max(1, θ(x0)). Default 1e-4.
    pub theta_min_fact: f64,
    /// η_φ: Armijo relaxation. Default 1e-8.
    pub eta_phi: f64,
    /// δ of the switching condition. Default 1.
    pub delta: f64,
    /// s_φ of the switching condition. Default 2.3.
    pub s_phi: f64,
    /// s_θ of the switching condition. Default 1.1.
    pub s_theta: f64,
    /// γ_φ: filter margin on the barrier function. Default 1e-8.
    pub gamma_phi: f64,
    /// γ_θ: filter margin on the infeasibility. Default 1e-5.
    pub gamma_theta: f64,
    /// γ_α: safety factor for the minimal step size. Default 0.05.
    pub alpha_min_frac: f64,
    /// κ_d: weight of the linear damping term for variables bounded on one side only.
    /// Default 1e-5.
    pub kappa_d: f64,
    /// Backtracking factor. Default 0.5.
    pub alpha_red_factor: f64,
    /// κ_Σ: bound-multiplier safeguard. Default 1e10.
    pub kappa_sigma: f64,
    /// Relative step size below which a step is "tiny". Default 10·ε_mach.
    pub tiny_step_tol: f64,
    /// Dual step size below which a tiny step ends the run. Default 1e-2.
    pub tiny_step_y_tol: f64,
    /// IPOPT's soft restoration phase (nlp/src/ipm/core/soft_resto.rs): when the line
    /// search fails, the step with equal primal and dual step sizes is taken if it
    /// reduces the primal-dual system error to this factor of its current value (or is
    /// acceptable to the filter). 0 disables it. Default **0** (IPOPT: 1 − 1e-4): with
    /// IPOPT's value the rocket takes 46 / 83 / 78 iterations instead of 183 / 96 / 166
    /// (IPOPT 27 / 26 / 34), but chain_800 ends in RestorationFailed (101 iterations
    /// without; IPOPT 698) and the HS total goes from 944 to 952 (docs/performance.md,
    /// "Step regularisation: the decision").
    pub soft_resto_pderror_reduction_factor: f64,
    /// Most iterations in a row of the soft restoration phase. Default 10 (IPOPT's).
    pub max_soft_resto_iters: usize,
    /// Primal step size α_pr below which an accepted step counts toward
    /// `tiny_alpha_max_iter`. Default 1e-8. Not an IPOPT option (see there).
    pub tiny_alpha: f64,
    /// After this many accepted steps in a row with α_pr < `tiny_alpha`, the next
    /// iteration is treated as a failed line search: the restoration phase starts (in
    /// restoration: `RestorationFailed`; without constraints:
    /// `SearchDirectionBecomesTooSmall`, or `SolvedToAcceptableLevel` at an acceptable
    /// point). 0 disables. Default 10 (IPOPT's `watchdog_shortened_iter_trigger`: IPOPT
    /// leaves such a run of shortened steps by its watchdog, which symnlp does not have;
    /// without this rule catenary_999 took 1159 steps with α_pr < 1e-8 at μ = 0.1).
    pub tiny_alpha_max_iter: usize,
    // ---------- linear algebra / inertia correction ----------
    /// δ_w^0: first Hessian perturbation. Default 1e-4.
    pub first_hessian_perturbation: f64,
    /// δ_w^min. Default 1e-20.
    pub min_hessian_perturbation: f64,
    /// δ_w^max. Default 1e40.
    pub max_hessian_perturbation: f64,
    /// κ̄_w^+: increase factor for the first perturbation. Default 100.
    pub perturb_inc_fact_first: f64,
    /// κ_w^+: increase factor. Default 8.
    pub perturb_inc_fact: f64,
    /// κ_w^-: decrease factor. Default 1/3.
    pub perturb_dec_fact: f64,
    /// δ_c base value δ̄_c (δ_c = δ̄_c·μ^κ_c). Default 1e-8.
    pub jacobian_regularization_value: f64,
    /// After this many iterations in a row that needed δ_w > 0, the next inertia
    /// correction starts at κ_w⁻·δ_w_last instead of first trying δ_w = 0 (one
    /// factorisation less per iteration on nonconvex problems); 0 always tries δ_w = 0
    /// first, as IPOPT does. Default 20: on the gap-crossing crawl gait (106 of 115
    /// iterations need δ_w) it saves 31 % of the factorisations with the same iterates;
    /// on the HS suite it changes only hs025 (36 → 40) and hs027 (56 → 54).
    pub perturbation_skip_zero_after: usize,
    /// κ_c. Default 0.25.
    pub jacobian_regularization_exponent: f64,
    /// Static regularisation always applied to the constraint block (faer's unpivoted
    /// LDLᵀ needs a non-zero (2,2) block); iterative refinement removes its effect on the
    /// step. Default 1e-8.
    pub kkt_static_regularization: f64,
    /// Static regularisation always added to the Hessian block (faer's unpivoted LDLᵀ
    /// meets an exact zero pivot where the Hessian of the Lagrangian is singular, e.g. a
    /// variable that enters linearly, although the KKT matrix is not); iterative
    /// refinement removes its effect on the step, so the step is IPOPT's exact Newton
    /// step with δ_w = 0. 0 disables it. Default 1e-8.
    pub kkt_static_hessian_regularization: f64,
    /// Minimum iterative-refinement steps. Default 1.
    pub min_refinement_steps: usize,
    /// Maximum iterative-refinement steps. Default 10.
    pub max_refinement_steps: usize,
    /// Target relative residual of the linear solves. Default 1e-10.
    pub residual_ratio_max: f64,
    /// Iterative refinement goes on past `residual_ratio_max` while a step still halves
    /// the residual ratio (the ratio is a backward error dominated by the largest entries
    /// of the solution; the static regularisations are removed by refinement), until the
    /// ratio is at most this. Default 1e-13 (until session 18 refinement went on to
    /// 1e-14: on the gap-crossing default 3.6 solves with the factor per KKT solve; see
    /// benches/reference/results/performance-notebook.md, "Planner speed, session 18").
    /// A value of at least `residual_ratio_max` stops at the target, as IPOPT does. Not
    /// an IPOPT option.
    pub residual_ratio_floor: f64,
    /// IPOPT's `residual_ratio_singular`: a solve whose refinement ends above
    /// `residual_ratio_max` is taken as it is if its residual ratio is at most this, and
    /// treated as singular (δ_c, then δ_w) only above it. Default `None`: the value of
    /// `residual_ratio_max`, so every failed refinement counts as singular (IPOPT's
    /// default is 1e-5, after first refactorising with a stricter pivot tolerance; symnlp
    /// first refactorises with lowered static regularisation near the solution; measured
    /// in docs/solvers.md §6).
    pub residual_ratio_singular: Option<f64>,
    // ---------- Hessian ----------
    /// Exact Hessian or limited-memory quasi-Newton approximation. Default exact.
    pub hessian_approximation: IpmHessian,
    /// Number of (s, y) pairs kept by the limited-memory approximation. Default 6.
    pub limited_memory_max_history: usize,
    /// Quasi-Newton formula (BFGS or SR1). Default BFGS.
    pub limited_memory_update_type: LimitedMemoryUpdate,
    /// Choice of σ in B₀ = σI. Default scalar1 (σ = sᵀy/sᵀs).
    pub limited_memory_initialization: LimitedMemoryInit,
    /// σ before the first update, and always with `constant`. Default 1.
    pub limited_memory_init_val: f64,
    /// Upper safeguard of σ. Default 1e8.
    pub limited_memory_init_val_max: f64,
    /// Lower safeguard of σ. Default 1e-8.
    pub limited_memory_init_val_min: f64,
    /// After this many successive skipped updates the memory is reset. Default 2.
    pub limited_memory_max_skipping: usize,
    // ---------- restoration ----------
    /// κ_resto: required infeasibility reduction in restoration. Default 0.9.
    pub required_infeasibility_reduction: f64,
    /// ρ: ℓ1 penalty of the restoration problem. Default 1000.
    pub resto_penalty_parameter: f64,
    /// Weight of the proximity term ζ = weight·√μ. Default 1.
    pub resto_proximity_weight: f64,
    /// Maximum iterations of one restoration phase. Default 3000.
    pub max_resto_iter: usize,
    /// Bound multipliers larger than this are reset to 1 after restoration. Default 1e3.
    pub bound_mult_reset_threshold: f64,
    /// After restoration the constraint multipliers are the least-squares estimate if it
    /// is no larger than this (max-norm), else 0; 0 means always 0. Default 0.
    pub constr_mult_reset_threshold: f64,
    /// Start with a restoration phase. Default false.
    pub start_with_resto: bool,
    /// IPOPT's `recalc_y`: after every accepted step whose constraint violation (max-norm,
    /// scaled problem) is below `recalc_y_feas_tol`, replace the constraint multipliers by
    /// the least-squares estimate. `None` (default) follows IPOPT: on with
    /// `hessian_approximation = limited-memory`, off with the exact Hessian.
    pub recalc_y: Option<bool>,
    /// Feasibility threshold of `recalc_y`. Default 1e-6.
    pub recalc_y_feas_tol: f64,
}

crate::frontend::strict_options_serde!(IpmOptions);

impl Default for IpmOptions {
    fn default() -> Self {
        IPOPT_DEFAULTS
    }
}

/// IPOPT's defaults (its option documentation), written out once as a constant so that
/// `IpmOptions::default` is one line.
const IPOPT_DEFAULTS: IpmOptions = IpmOptions {
    common: CommonOptions::DEFAULTS,
    mu_strategy: None,
    mu_oracle: MuOracle::QualityFunction,
    sigma_max: 100.0,
    sigma_min: 1e-6,
    quality_function_norm_type: QualityFunctionNorm::TwoNormSquared,
    quality_function_centrality: QualityFunctionCentrality::None,
    quality_function_balancing_term: QualityFunctionBalancingTerm::None,
    quality_function_max_section_steps: 8,
    quality_function_section_sigma_tol: 1e-2,
    quality_function_section_qf_tol: 0.0,
    mu_init: 0.1,
    mu_max: 1e5,
    mu_min: 1e-11,
    barrier_tol_factor: 10.0,
    mu_linear_decrease_factor: 0.2,
    mu_superlinear_decrease_power: 1.5,
    mu_allow_fast_monotone_decrease: true,
    tau_min: 0.99,
    adaptive_mu_kkterror_red_fact: 0.9999,
    adaptive_mu_kkterror_red_iters: 4,
    adaptive_mu_monotone_init_factor: 0.8,
    nlp_scaling_method: ScalingMethod::GradientBased,
    nlp_scaling_min_gradient: 0.5,
    nlp_scaling_max_value: 1e4,
    obj_scaling_factor: 1.0,
    bound_push: 1e-2,
    bound_frac: 1e-2,
    slack_bound_push: 1e-2,
    slack_bound_frac: 1e-2,
    bound_relax_factor: 1e-8,
    honor_original_bounds: false,
    bound_mult_init_val: 1.0,
    constr_mult_init_max: 1e3,
    warm_start_bound_push: 1e-3,
    warm_start_bound_frac: 1e-3,
    warm_start_slack_bound_push: 1e-3,
    warm_start_slack_bound_frac: 1e-3,
    warm_start_mult_bound_push: 1e-3,
    warm_start_mu_init: 1e-6,
    max_soc: 4,
    kappa_soc: 0.99,
    theta_max_fact: 1e4,
    theta_min_fact: 1e-4,
    eta_phi: 1e-8,
    delta: 1.0,
    s_phi: 2.3,
    s_theta: 1.1,
    gamma_phi: 1e-8,
    gamma_theta: 1e-5,
    alpha_min_frac: 0.05,
    kappa_d: 1e-5,
    alpha_red_factor: 0.5,
    kappa_sigma: 1e10,
    tiny_step_tol: 10.0 * f64::EPSILON,
    tiny_step_y_tol: 1e-2,
    soft_resto_pderror_reduction_factor: 0.0,
    max_soft_resto_iters: 10,
    tiny_alpha: 1e-8,
    tiny_alpha_max_iter: 10,
    first_hessian_perturbation: 1e-4,
    min_hessian_perturbation: 1e-20,
    max_hessian_perturbation: 1e40,
    perturb_inc_fact_first: 100.0,
    perturb_inc_fact: 8.0,
    perturb_dec_fact: 1.0 / 3.0,
    jacobian_regularization_value: 1e-8,
    jacobian_regularization_exponent: 0.25,
    perturbation_skip_zero_after: 20,
    kkt_static_regularization: 1e-8,
    kkt_static_hessian_regularization: 1e-8,
    min_refinement_steps: 1,
    max_refinement_steps: 10,
    residual_ratio_max: 1e-10,
    residual_ratio_floor: 1e-13,
    residual_ratio_singular: None,
    hessian_approximation: IpmHessian::Exact,
    limited_memory_max_history: 6,
    limited_memory_update_type: LimitedMemoryUpdate::Bfgs,
    limited_memory_initialization: LimitedMemoryInit::Scalar1,
    limited_memory_init_val: 1.0,
    limited_memory_init_val_max: 1e8,
    limited_memory_init_val_min: 1e-8,
    limited_memory_max_skipping: 2,
    required_infeasibility_reduction: 0.9,
    resto_penalty_parameter: 1000.0,
    resto_proximity_weight: 1.0,
    max_resto_iter: 3000,
    bound_mult_reset_threshold: 1e3,
    constr_mult_reset_threshold: 1e3,
    recalc_y: None,
    recalc_y_feas_tol: 1e-6,
    start_with_resto: false,
};

fn bad(field: &'static str, reason: impl Into<String>) -> SolveError {
    SolveError::InvalidOption {
        field,
        reason: reason.into(),
    }
}

/// `[(name, value)]` for the named `f64` fields of an options struct.
macro_rules! named_fields {
    ($s:expr; $($f:ident),* $(,)?) => {
        [$((stringify!($f), $s.$f)),*]
    };
}

/// The first field whose value breaks `rule` (`ok` false, NaN included) as an
/// error "must be {rule}, got {value}".
fn check_each(
    fields: &[(&'static str, f64)],
    rule: &str,
    ok: impl Fn(f64) -> bool,
) -> Result<(), SolveError> {
    match fields.iter().find(|&&(_, v)| !ok(v)) {
        Some(&(field, v)) => Err(bad(field, format!("must be {rule}, got {v}"))),
        None => Ok(()),
    }
}

impl IpmOptions {
    /// The residual ratio above which a solve counts as singular
    /// (`residual_ratio_singular`, by default `residual_ratio_max`).
    pub fn singular_residual_ratio(&self) -> f64 {
        self.residual_ratio_singular
            .unwrap_or(self.residual_ratio_max)
    }

    /// The barrier strategy in effect: `mu_strategy` if set, else IPOPT's default for
    /// the Hessian in use (adaptive with the limited-memory approximation, as IPOPT's
    /// AlgorithmBuilder chooses, monotone with the exact Hessian).
    pub fn effective_mu_strategy(&self) -> MuStrategy {
        self.mu_strategy
            .unwrap_or(match self.hessian_approximation {
                IpmHessian::Exact => MuStrategy::Monotone,
                IpmHessian::LimitedMemory => MuStrategy::Adaptive,
            })
    }

    /// Checks every option; the error names the first bad field.
    pub fn validate(&self) -> Result<(), SolveError> {
        self.common.validate()?;
        self.check_ranges()?;
        self.check_barrier()?;
        self.check_globalisation()?;
        self.check_initial_point()?;
        self.check_linear_algebra()?;
        self.check_quasi_newton()?;
        if !(self.nlp_scaling_max_value >= 1.0) {
            return Err(bad("nlp_scaling_max_value", "must be >= 1"));
        }
        Ok(())
    }

    /// Every number that must be positive, non-negative or in (0, 1).
    fn check_ranges(&self) -> Result<(), SolveError> {
        self.check_positive()?;
        self.check_nonnegative()?;
        self.check_open_unit()?;
        self.check_section_tolerances()
    }

    /// The numbers that must be finite and > 0.
    fn check_positive(&self) -> Result<(), SolveError> {
        let fields = named_fields!(
            self;
            mu_init,
            mu_max,
            sigma_max,
            mu_min,
            barrier_tol_factor,
            nlp_scaling_max_value,
            obj_scaling_factor,
            bound_mult_init_val,
            warm_start_bound_push,
            warm_start_bound_frac,
            warm_start_slack_bound_push,
            warm_start_slack_bound_frac,
            warm_start_mult_bound_push,
            warm_start_mu_init,
            theta_max_fact,
            theta_min_fact,
            delta,
            first_hessian_perturbation,
            min_hessian_perturbation,
            max_hessian_perturbation,
            perturb_inc_fact_first,
            perturb_inc_fact,
            resto_penalty_parameter,
            bound_mult_reset_threshold,
            residual_ratio_max,
            residual_ratio_floor,
            recalc_y_feas_tol,
            kkt_static_regularization,
            limited_memory_init_val,
            limited_memory_init_val_max,
            limited_memory_init_val_min
        );
        check_each(&fields, "finite and > 0", |v| v > 0.0 && v.is_finite())
    }

    /// The numbers that must be finite and >= 0.
    fn check_nonnegative(&self) -> Result<(), SolveError> {
        let fields = named_fields!(
            self;
            bound_push,
            bound_frac,
            slack_bound_push,
            slack_bound_frac,
            bound_relax_factor,
            nlp_scaling_min_gradient,
            constr_mult_init_max,
            constr_mult_reset_threshold,
            tiny_step_tol,
            tiny_step_y_tol,
            sigma_min,
            tiny_alpha,
            soft_resto_pderror_reduction_factor,
            kappa_d,
            jacobian_regularization_value,
            jacobian_regularization_exponent,
            kkt_static_hessian_regularization,
            resto_proximity_weight
        );
        check_each(&fields, "finite and >= 0", |v| v >= 0.0 && v.is_finite())
    }

    /// The numbers that must lie in the open interval (0, 1).
    fn check_open_unit(&self) -> Result<(), SolveError> {
        let fields = named_fields!(
            self;
            mu_linear_decrease_factor,
            tau_min,
            adaptive_mu_kkterror_red_fact,
            adaptive_mu_monotone_init_factor,
            kappa_soc,
            eta_phi,
            gamma_phi,
            gamma_theta,
            alpha_min_frac,
            alpha_red_factor,
            perturb_dec_fact,
            required_infeasibility_reduction
        );
        check_each(&fields, "in (0, 1)", |v| v > 0.0 && v < 1.0)
    }

    /// The quality function's section-search tolerances, in [0, 1).
    fn check_section_tolerances(&self) -> Result<(), SolveError> {
        if !(0.0..1.0).contains(&self.quality_function_section_sigma_tol) {
            return Err(bad(
                "quality_function_section_sigma_tol",
                "must be in [0, 1)",
            ));
        }
        if !(0.0..1.0).contains(&self.quality_function_section_qf_tol) {
            return Err(bad("quality_function_section_qf_tol", "must be in [0, 1)"));
        }
        Ok(())
    }

    /// The barrier parameter's range and update.
    fn check_barrier(&self) -> Result<(), SolveError> {
        if !(self.mu_superlinear_decrease_power > 1.0 && self.mu_superlinear_decrease_power < 2.0) {
            return Err(bad("mu_superlinear_decrease_power", "must be in (1, 2)"));
        }
        if self.mu_min > self.mu_init {
            return Err(bad("mu_min", "must not exceed mu_init"));
        }
        if self.mu_max < self.mu_init {
            return Err(bad("mu_max", "must not be below mu_init"));
        }
        if self.sigma_min > self.sigma_max {
            return Err(bad("sigma_min", "must not exceed sigma_max"));
        }
        if self.adaptive_mu_kkterror_red_iters == 0 {
            return Err(bad("adaptive_mu_kkterror_red_iters", "must be >= 1"));
        }
        Ok(())
    }

    /// The filter's switching condition.
    fn check_globalisation(&self) -> Result<(), SolveError> {
        if !(self.s_phi > 1.0) || !self.s_phi.is_finite() {
            return Err(bad("s_phi", "must be > 1"));
        }
        if !(self.s_theta > 1.0) || !self.s_theta.is_finite() {
            return Err(bad("s_theta", "must be > 1"));
        }
        Ok(())
    }

    /// The push of the starting point (cold and warm) into the bounds.
    fn check_initial_point(&self) -> Result<(), SolveError> {
        if self.bound_frac > 0.5 {
            return Err(bad("bound_frac", "must be <= 0.5"));
        }
        if self.slack_bound_frac > 0.5 {
            return Err(bad("slack_bound_frac", "must be <= 0.5"));
        }
        if self.warm_start_bound_frac > 0.5 {
            return Err(bad("warm_start_bound_frac", "must be <= 0.5"));
        }
        if self.warm_start_slack_bound_frac > 0.5 {
            return Err(bad("warm_start_slack_bound_frac", "must be <= 0.5"));
        }
        if self.bound_push == 0.0 && self.bound_frac == 0.0 {
            return Err(bad(
                "bound_push",
                "bound_push and bound_frac cannot both be 0",
            ));
        }
        Ok(())
    }

    /// The inertia correction and iterative refinement of the KKT solves.
    fn check_linear_algebra(&self) -> Result<(), SolveError> {
        if self.min_hessian_perturbation > self.max_hessian_perturbation {
            return Err(bad(
                "min_hessian_perturbation",
                "must not exceed max_hessian_perturbation",
            ));
        }
        if self.perturb_inc_fact <= 1.0 {
            return Err(bad("perturb_inc_fact", "must be > 1"));
        }
        if self.perturb_inc_fact_first <= 1.0 {
            return Err(bad("perturb_inc_fact_first", "must be > 1"));
        }
        if self.min_refinement_steps > self.max_refinement_steps {
            return Err(bad(
                "min_refinement_steps",
                "must not exceed max_refinement_steps",
            ));
        }
        if let Some(r) = self.residual_ratio_singular {
            if !(r >= self.residual_ratio_max) || !r.is_finite() {
                return Err(bad(
                    "residual_ratio_singular",
                    format!("must be finite and not smaller than residual_ratio_max, got {r}"),
                ));
            }
        }
        Ok(())
    }

    /// The limited-memory Hessian approximation.
    fn check_quasi_newton(&self) -> Result<(), SolveError> {
        if self.limited_memory_init_val_min > self.limited_memory_init_val_max {
            return Err(bad(
                "limited_memory_init_val_min",
                "must not exceed limited_memory_init_val_max",
            ));
        }
        if self.limited_memory_max_skipping == 0 {
            return Err(bad("limited_memory_max_skipping", "must be >= 1"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::IpmOptions;
    use crate::error::SolveError;

    /// Each relation between options, broken alone, is refused and named: one case per
    /// concern of `validate`.
    #[test]
    fn every_relation_names_its_field() {
        assert!(IpmOptions::default().validate().is_ok());
        type Case = (&'static str, fn(&mut IpmOptions));
        let cases: [Case; 12] = [
            ("tau_min", |o| o.tau_min = 1.0),
            ("mu_min", |o| o.mu_min = 2.0 * o.mu_init),
            ("mu_max", |o| o.mu_max = 0.5 * o.mu_init),
            ("adaptive_mu_kkterror_red_iters", |o| {
                o.adaptive_mu_kkterror_red_iters = 0
            }),
            ("s_theta", |o| o.s_theta = 1.0),
            ("warm_start_bound_frac", |o| o.warm_start_bound_frac = 0.6),
            ("bound_push", |o| {
                o.bound_push = 0.0;
                o.bound_frac = 0.0
            }),
            ("min_hessian_perturbation", |o| {
                o.min_hessian_perturbation = 2.0 * o.max_hessian_perturbation
            }),
            ("min_refinement_steps", |o| {
                o.min_refinement_steps = o.max_refinement_steps + 1
            }),
            ("limited_memory_max_skipping", |o| {
                o.limited_memory_max_skipping = 0
            }),
            ("nlp_scaling_max_value", |o| o.nlp_scaling_max_value = 0.5),
            ("kappa_d", |o| o.kappa_d = f64::NAN),
        ];
        for (want, set) in cases {
            let mut o = IpmOptions::default();
            set(&mut o);
            match o.validate() {
                Err(SolveError::InvalidOption { field, .. }) => assert_eq!(field, want),
                other => panic!("{want}: {other:?}"),
            }
        }
    }
}
