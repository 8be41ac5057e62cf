//! The user-level result of an SQP solve: the point and multipliers unscaled, and the KKT
//! measures in the user's units.

#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use faer::sparse::SymbolicSparseColMat;

use super::geometry::{cone_viol, viol, Geometry};
use super::iterate::{lagrangian_gradient, Mult};
use super::scaled::Scaled;
use crate::numeric::AffineCone;
use crate::solution::{Solution, Stats, Status};

/// The user-level solution (unscaled) at x with the given multipliers.
#[allow(clippy::too_many_arguments)]
pub(super) fn finish(
    sc: &mut Scaled<'_>,
    geo: &Geometry,
    x: &[f64],
    mult: &Mult,
    status: Status,
    message: String,
    mut stats: Stats,
    start: Instant,
    cp: Option<&SymbolicSparseColMat<usize>>,
    cones: &[AffineCone],
) -> Solution {
    let n = x.len();
    let m = geo.g_l.len();
    let os = sc.obj_scale;
    let t = Instant::now();
    let nlp = &mut *sc.nlp;
    let objective = nlp.eval_f(x);
    let mut grad = vec![0.0; n];
    nlp.eval_grad_f(x, &mut grad);
    let mut g = vec![0.0; m];
    nlp.eval_g(x, &mut g);
    let jp = nlp.jac_g_sparsity().clone();
    let mut jv = vec![0.0; jp.row_idx().len()];
    nlp.eval_jac_g(x, &mut jv);
    let n_cone = mult.z_cone.len();
    let mut cone = vec![0.0; n_cone];
    let mut cv = vec![0.0; cp.map_or(0, |p| p.row_idx().len())];
    if n_cone > 0 {
        nlp.eval_cone_entries(x, &mut cone);
        nlp.eval_cone_jac(x, &mut cv);
    }
    sc.counters.f += 1;
    sc.counters.grad_f += 1;
    sc.counters.g += 1;
    sc.counters.jac_g += 1;
    sc.counters.seconds += t.elapsed().as_secs_f64();
    let mut lambda: Vec<f64> = (0..m)
        .map(|i| mult.lambda[i] * sc.g_scale[i] / os)
        .collect();
    let z_l: Vec<f64> = mult.z_l.iter().map(|v| v / os).collect();
    let z_u: Vec<f64> = mult.z_u.iter().map(|v| v / os).collect();
    let z_cone: Vec<f64> = mult.z_cone.iter().map(|v| v / os).collect();
    let um = Mult {
        lambda: lambda.clone(),
        z_l: z_l.clone(),
        z_u: z_u.clone(),
        z_cone: z_cone.clone(),
    };
    let mut r = vec![0.0; n];
    lagrangian_gradient(&grad, &jp, &jv, cp, &cv, &um, &geo.cone_row, &mut r);
    let dual_inf = (0..n).fold(0.0f64, |a, j| a.max((r[j] - z_l[j] + z_u[j]).abs()));
    // The smooth row of a cone reports the cone's multiplier z_t.
    for c in cones {
        lambda[c.row] = z_cone[c.offset];
    }
    let mut constr_viol: f64 = 0.0;
    let mut compl: f64 = 0.0;
    for j in 0..n {
        constr_viol = constr_viol.max(viol(x[j], geo.x_l[j], geo.x_u[j]));
        if geo.x_l[j] != geo.x_u[j] {
            if geo.x_l[j].is_finite() {
                compl = compl.max(((x[j] - geo.x_l[j]) * z_l[j]).abs());
            }
            if geo.x_u[j].is_finite() {
                compl = compl.max(((geo.x_u[j] - x[j]) * z_u[j]).abs());
            }
        }
    }
    for i in 0..m {
        if geo.cone_row[i] {
            continue;
        }
        let (l, u) = (geo.g_l[i] / sc.g_scale[i], geo.g_u[i] / sc.g_scale[i]);
        constr_viol = constr_viol.max(viol(g[i], l, u));
        if l != u {
            if l.is_finite() {
                compl = compl.max(((g[i] - l) * (-lambda[i]).max(0.0)).abs());
            }
            if u.is_finite() {
                compl = compl.max(((u - g[i]) * lambda[i].max(0.0)).abs());
            }
        }
    }
    for c in cones {
        constr_viol = constr_viol.max(cone_viol(&cone[c.offset..c.offset + c.dim]));
    }
    stats.n_eval_f = sc.counters.f;
    stats.n_eval_grad_f = sc.counters.grad_f;
    stats.n_eval_g = sc.counters.g;
    stats.n_eval_jac_g = sc.counters.jac_g;
    stats.n_eval_hess_l = sc.counters.hess_l;
    stats.eval_seconds = sc.counters.seconds;
    stats.total_seconds = start.elapsed().as_secs_f64();
    stats.other_seconds =
        (stats.total_seconds - stats.eval_seconds - stats.factor_seconds).max(0.0);
    Solution {
        status,
        x: x.to_vec(),
        lambda,
        z_l,
        z_u,
        g,
        objective,
        constr_viol,
        dual_inf,
        compl,
        message,
        stats,
    }
}
