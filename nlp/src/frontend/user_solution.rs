//! The [`Solution`] both back ends return: the final point in the user's units, with the
//! multipliers already unscaled, its f and g, and the KKT measures reported there (dual
//! infeasibility, constraint violation, complementarity). f, g, ∇f and J are those the
//! back end evaluated at that point (the [`ScaledNlp`]'s unscaled values); only what it
//! did not evaluate there is evaluated (e.g. after the IPM's clamp to the original bounds
//! moved the point, or when the SQP's last trial point was rejected).

#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use super::point_values::Value;
use super::scaled::ScaledNlp;
use super::validate::Validated;
use crate::numeric::AffineCone;
use crate::solution::{Solution, Stats};

/// The final point and multipliers in the user's numbering and units.
#[cfg(test)] // the back ends use the `_into` forms
pub(crate) struct UserPoint {
    pub x: Vec<f64>,
    pub lambda: Vec<f64>,
    pub z_l: Vec<f64>,
    pub z_u: Vec<f64>,
}

/// Affine cones treated as cones (the SQP): their rows of g are left out of λ's terms, and
/// their multipliers (user units, stacked like the cone entries) enter the Lagrangian.
pub(crate) struct ConeDuals<'c> {
    pub cones: &'c [AffineCone],
    pub cone_row: &'c [bool],
    pub z_cone: &'c [f64],
}

/// The end of every solve, after [`user_solution_into`]: the evaluation counters and times of
/// `sc` written into `stats` (whose back-end parts are filled), the total and other times
/// from `start`, `stats` moved into `sol`, and at `print_level` ≥ 3 the summary and the
/// solution's message printed.
pub(crate) fn conclude(
    sol: &mut Solution,
    mut stats: Stats,
    sc: &ScaledNlp<'_>,
    start: Instant,
    print_level: u8,
) {
    sc.write_stats(&mut stats);
    stats.total_seconds = start.elapsed().as_secs_f64();
    stats.other_seconds =
        (stats.total_seconds - stats.eval_seconds - stats.factor_seconds).max(0.0);
    sol.stats = stats;
    if print_level >= 3 {
        crate::log::write_out(format_args!("{}", crate::log::format_summary(sol)));
        if !sol.message.is_empty() {
            crate::log::log_out!("{}", sol.message);
        }
    }
}

/// Violation of `lo ≤ v ≤ hi`.
fn viol(v: f64, lo: f64, hi: f64) -> f64 {
    (lo - v).max(v - hi).max(0.0)
}

/// f, ∇f, g and J at `p.x` (those not evaluated there yet evaluated and counted in `sc`)
/// and the solution built from them:
/// dual infeasibility ‖∇f + Jᵀλ − J_coneᵀz_cone − z_L + z_U‖∞, the violation of bounds,
/// rows and cones, and complementarity of the inequality rows and non-fixed bounds, all
/// in the user's units. A fixed variable's bound multipliers absorb its gradient of the
/// Lagrangian (only z_L − z_U is determined there). A cone's smooth row reports the
/// cone's multiplier z_t. `stats` are left at their defaults.
#[cfg(test)] // the back ends use the `_into` forms
pub(crate) fn user_solution(
    sc: &mut ScaledNlp<'_>,
    b: &Validated,
    p: UserPoint,
    cones: Option<ConeDuals<'_>>,
    status: crate::solution::Status,
    message: String,
) -> Solution {
    let UserPoint {
        x,
        lambda,
        z_l,
        z_u,
    } = p;
    let mut sol = Solution {
        status,
        x,
        lambda,
        z_l,
        z_u,
        g: Vec::new(),
        objective: 0.0,
        constr_viol: 0.0,
        dual_inf: 0.0,
        compl: 0.0,
        message,
        stats: Stats::default(),
        parameters: Vec::new(),
    };
    user_solution_into(sc, b, &mut sol, cones, &mut FinalScratch::default());
    sol
}

/// The vector [`user_solution_into`] works in, kept between solves.
#[derive(Default)]
pub(crate) struct FinalScratch {
    /// The gradient of the Lagrangian.
    r: Vec<f64>,
}

/// The solution at the final point, in place: `sol.x`, `sol.lambda`, `sol.z_l` and `sol.z_u` hold the
/// point (user numbering and units); its values, measures and parameters are written
/// into `sol` (status, message and stats are left as they are). Allocates nothing once
/// `sol`'s and `scratch`'s vectors have the problem's sizes and without cones.
pub(crate) fn user_solution_into(
    sc: &mut ScaledNlp<'_>,
    b: &Validated,
    sol: &mut Solution,
    cones: Option<ConeDuals<'_>>,
    scratch: &mut FinalScratch,
) {
    let (n, m) = (sol.x.len(), sol.lambda.len());
    let FinalScratch { r } = scratch;
    sol.parameters.clear();
    sol.parameters
        .extend_from_slice(sc.user().parameter_values());
    for value in [Value::F, Value::G, Value::Grad, Value::Jac] {
        sc.evaluate(value, &sol.x);
    }
    let at = sc.values();
    sol.objective = at.f();
    sol.g.clear();
    sol.g.extend_from_slice(at.g());
    r.clear();
    r.extend_from_slice(at.grad());
    let jv = at.jac();
    debug_assert_eq!((r.len(), sol.g.len()), (n, m));
    let is_cone_row = |i: usize| cones.as_ref().is_some_and(|c| c.cone_row[i]);
    // r = ∇f + Jᵀλ − J_coneᵀ z_cone
    let jp = sc.user().jac_g_sparsity();
    for c in 0..n {
        for q in jp.col_range(c) {
            let i = jp.row_idx()[q];
            if !is_cone_row(i) {
                r[c] += jv[q] * sol.lambda[i];
            }
        }
    }
    let mut constr_viol: f64 = 0.0;
    if let Some(cd) = &cones {
        constr_viol = cone_terms(sc, cd, &sol.x, r, &mut sol.lambda);
    }
    let mut dual_inf: f64 = 0.0;
    let mut compl: f64 = 0.0;
    let (x, z_l, z_u) = (&sol.x, &mut sol.z_l, &mut sol.z_u);
    for j in 0..n {
        let (lo, hi) = (b.x_l[j], b.x_u[j]);
        if lo == hi {
            // Fixed variable: its bound multipliers absorb the gradient.
            z_l[j] = r[j].max(0.0);
            z_u[j] = (-r[j]).max(0.0);
        } else {
            if lo.is_finite() {
                compl = compl.max(((x[j] - lo) * z_l[j]).abs());
            }
            if hi.is_finite() {
                compl = compl.max(((hi - x[j]) * z_u[j]).abs());
            }
        }
        dual_inf = dual_inf.max((r[j] - z_l[j] + z_u[j]).abs());
        constr_viol = constr_viol.max(viol(x[j], lo, hi));
    }
    let (g, lambda) = (&sol.g, &sol.lambda);
    for i in (0..m).filter(|&i| !is_cone_row(i)) {
        let (lo, hi) = (b.g_l[i], b.g_u[i]);
        constr_viol = constr_viol.max(viol(g[i], lo, hi));
        if lo != hi {
            if lo.is_finite() {
                compl = compl.max(((g[i] - lo) * (-lambda[i]).max(0.0)).abs());
            }
            if hi.is_finite() {
                compl = compl.max(((hi - g[i]) * lambda[i].max(0.0)).abs());
            }
        }
    }
    sol.constr_viol = constr_viol;
    sol.dual_inf = dual_inf;
    sol.compl = compl;
}

/// The cones' part of the measures: their multipliers' term subtracted from `r`, each
/// cone's multiplier z_t reported as its smooth row's λ; returns the largest cone
/// violation.
fn cone_terms(
    sc: &mut ScaledNlp<'_>,
    cd: &ConeDuals<'_>,
    x: &[f64],
    r: &mut [f64],
    lambda: &mut [f64],
) -> f64 {
    let mut constr_viol: f64 = 0.0;
    let Some(cp) = sc.user().cone_jac_sparsity().cloned() else {
        return constr_viol;
    };
    let n_cone = cd.z_cone.len();
    let mut entries = vec![0.0; n_cone];
    let mut cv = vec![0.0; cp.row_idx().len()];
    if n_cone > 0 {
        let u = sc.user_mut();
        u.eval_cone_entries(x, &mut entries);
        u.eval_cone_jac(x, &mut cv);
    }
    for (c, rc) in r.iter_mut().enumerate() {
        for q in cp.col_range(c) {
            *rc -= cv[q] * cd.z_cone[cp.row_idx()[q]];
        }
    }
    for k in cd.cones {
        let e = &entries[k.offset..k.offset + k.dim];
        let nv = e[1..].iter().map(|v| v * v).sum::<f64>().sqrt();
        constr_viol = constr_viol.max(nv - e[0]);
        lambda[k.row] = cd.z_cone[k.offset];
    }
    constr_viol
}

#[cfg(test)]
mod tests {
    use super::{user_solution, UserPoint};
    use crate::frontend::scaled::ScaledNlp;
    use crate::frontend::validate::validate;
    use crate::solution::Status;
    use crate::{Problem, Relation};

    /// min (x₀ − 1)² + x₁² s.t. x₀ + x₁ ≥ 0, x₁ fixed at 2. Measures by hand at two points.
    #[test]
    fn measures_in_user_units_and_fixed_variables_absorb_the_gradient() {
        let mut pb = Problem::new();
        let x = pb.variable("x", 2).unwrap();
        pb.minimize((x[0] - 1.0) * (x[0] - 1.0) + x[1] * x[1]);
        pb.subject_to((x[0] + x[1]).ge(0.0)).unwrap();
        pb.set_bounds(&x[1..], 2.0, 2.0).unwrap();
        let mut c = pb.compile().unwrap();
        let v = validate(&c, None).unwrap();
        let mut sc = ScaledNlp::new(&mut c);
        let point = |x0: f64, lambda: f64| UserPoint {
            x: vec![x0, 2.0],
            lambda: vec![lambda],
            z_l: vec![0.0; 2],
            z_u: vec![0.0; 2],
        };
        // At the solution (1, 2): ∇f = (0, 4); the fixed x₁ takes z_L = 4.
        let s = user_solution(
            &mut sc,
            &v,
            point(1.0, 0.0),
            None,
            Status::SolveSucceeded,
            String::new(),
        );
        assert_eq!(
            (s.objective, s.dual_inf, s.constr_viol, s.compl),
            (4.0, 0.0, 0.0, 0.0)
        );
        assert_eq!(
            (s.z_l.clone(), s.z_u.clone()),
            (vec![0.0, 4.0], vec![0.0, 0.0])
        );
        // At (−3, 2) with λ = −0.5: g = −1 (violation 1), ∇f + λ∇g = (−8.5, 3.5) → the
        // free x₀ leaves 8.5; complementarity |(g − 0)·0.5| = 0.5.
        let s = user_solution(
            &mut sc,
            &v,
            point(-3.0, -0.5),
            None,
            Status::SolveSucceeded,
            String::new(),
        );
        assert_eq!((s.dual_inf, s.constr_viol, s.compl), (8.5, 1.0, 0.5));
        assert_eq!(s.g, vec![-1.0]);
        assert_eq!(sc.counters.f, 2);
    }
}
