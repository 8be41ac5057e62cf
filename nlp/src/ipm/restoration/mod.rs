//! IPOPT's ℓ1 feasibility restoration phase, solved by the same interior-point core
//! recursively:
//!
//! min ρ Σ (p + n) + ζ/2 ‖D_R (x − x_R)‖²   s.t.  g_l ≤ g(x) − p + n ≤ g_u,  x_l ≤ x ≤ x_u,
//! p, n ≥ 0,
//!
//! with ζ = resto_proximity_weight·√μ and D_R = diag(min(1, 1/|x_R|)). The inner loop stops
//! as soon as the original infeasibility is reduced by κ_resto and the point is acceptable
//! to the original filter. If the restoration problem converges instead, the original
//! problem is locally infeasible (unless that point happens to be feasible).

#![allow(clippy::needless_range_loop, clippy::result_large_err)]

use faer::sparse::SymbolicSparseColMat;

use crate::frontend::scaled::Scaling;
use crate::ipm::barrier::Barrier;
use crate::ipm::core::{Buffers, Core, Iterate, Layout, Setup, Shared, Start};
use crate::ipm::filter::Filter;
use crate::ipm::reduced::IpmProblem;
use crate::numeric::NumericNlp;
use crate::options::{IpmOptions, MuStrategy};
use crate::solution::Status;

pub(crate) mod handoff;

use handoff::{Ended, Entry};

struct Resto<'a> {
    outer: &'a mut dyn IpmProblem,
    n: usize,
    m: usize,
    rho: f64,
    zeta: f64,
    dr2: Vec<f64>,
    xr: Vec<f64>,
    jac: SymbolicSparseColMat<usize>,
    nnz_j_orig: usize,
    hess: SymbolicSparseColMat<usize>,
    hmap: Vec<usize>,
    hdiag: Vec<usize>,
    x_l: Vec<f64>,
    x_u: Vec<f64>,
    g_l: Vec<f64>,
    g_u: Vec<f64>,
    x0: Vec<f64>,
    hbuf: Vec<f64>,
    // acceptance test data (copied from the outer core)
    slack_of_row: Vec<usize>,
    g_eq: Vec<f64>,
    wl: Vec<f64>,
    wu: Vec<f64>,
    has_l: Vec<bool>,
    has_u: Vec<bool>,
    kappa_d: f64,
    mu_outer: f64,
    filter: Filter,
    /// IPOPT's exit test (`RestoFilterConvergenceCheck`): the original problem's
    /// max-norm infeasibility must fall to κ_resto × its value at the start.
    inf_pr_target: f64,
    theta_max: f64,
    gbuf: Vec<f64>,
    wbuf: Vec<f64>,
    /// The outer problem's scaling, for the iteration log.
    outer_scaling: Scaling,
}

impl NumericNlp for Resto<'_> {
    fn n(&self) -> usize {
        self.n + 2 * self.m
    }
    fn m(&self) -> usize {
        self.m
    }
    fn bounds(&self, x_l: &mut [f64], x_u: &mut [f64], g_l: &mut [f64], g_u: &mut [f64]) {
        x_l.copy_from_slice(&self.x_l);
        x_u.copy_from_slice(&self.x_u);
        g_l.copy_from_slice(&self.g_l);
        g_u.copy_from_slice(&self.g_u);
    }
    fn initial_point(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.x0);
    }
    fn jac_g_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        &self.jac
    }
    fn hess_l_sparsity(&self) -> &SymbolicSparseColMat<usize> {
        &self.hess
    }
    fn eval_f(&mut self, x: &[f64]) -> f64 {
        let (n, m) = (self.n, self.m);
        let pen: f64 = x[n..n + 2 * m].iter().sum();
        let mut prox = 0.0;
        for j in 0..n {
            let d = x[j] - self.xr[j];
            prox += self.dr2[j] * d * d;
        }
        self.rho * pen + 0.5 * self.zeta * prox
    }
    fn eval_grad_f(&mut self, x: &[f64], grad: &mut [f64]) {
        let n = self.n;
        for j in 0..n {
            grad[j] = self.zeta * self.dr2[j] * (x[j] - self.xr[j]);
        }
        grad[n..].iter_mut().for_each(|v| *v = self.rho);
    }
    fn eval_g(&mut self, x: &[f64], g: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        self.outer.eval_g(&x[..n], g);
        for i in 0..m {
            g[i] += -x[n + i] + x[n + m + i];
        }
    }
    fn eval_jac_g(&mut self, x: &[f64], values: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        let k = self.nnz_j_orig;
        self.outer.eval_jac_g(&x[..n], &mut values[..k]);
        values[k..k + m].iter_mut().for_each(|v| *v = -1.0);
        values[k + m..k + 2 * m].iter_mut().for_each(|v| *v = 1.0);
    }
    fn eval_hess_l(&mut self, x: &[f64], obj_factor: f64, lambda: &[f64], values: &mut [f64]) {
        let n = self.n;
        self.outer.eval_hess_l(&x[..n], 0.0, lambda, &mut self.hbuf);
        values.iter_mut().for_each(|v| *v = 0.0);
        for (p, &q) in self.hmap.iter().enumerate() {
            values[q] += self.hbuf[p];
        }
        for j in 0..n {
            values[self.hdiag[j]] += obj_factor * self.zeta * self.dr2[j];
        }
    }
    fn variable_name(&self, i: usize) -> String {
        let (n, m) = (self.n, self.m);
        if i < n {
            self.outer.variable_name(i)
        } else if i < n + m {
            format!("p[{}]", i - n)
        } else {
            format!("n[{}]", i - n - m)
        }
    }
    fn constraint_name(&self, i: usize) -> String {
        self.outer.constraint_name(i)
    }
}

impl Resto<'_> {
    /// Residual of the outer problem's row `i` (its value in `gbuf`) with slacks `s`.
    fn outer_residual(&self, i: usize, s: &[f64]) -> f64 {
        match self.slack_of_row[i] {
            usize::MAX => self.gbuf[i] - self.g_eq[i],
            k => self.gbuf[i] - s[k],
        }
    }
}

impl IpmProblem for Resto<'_> {
    /// The x part of `[x, p, n]`; the restoration rows are the outer problem's rows.
    fn user_point(&self, x: &[f64], y: &[f64], x_user: &mut [f64], lambda_user: &mut [f64]) {
        self.outer.user_point(&x[..self.n], y, x_user, lambda_user);
    }

    fn original_measures(&mut self, w: &[f64]) -> Option<(f64, f64)> {
        let (n, m) = (self.n, self.m);
        let x = &w[..n];
        let s = &w[n + 2 * m..];
        let f = self.outer_scaling.objective_to_user(self.outer.eval_f(x));
        self.outer.eval_g(x, &mut self.gbuf);
        let mut viol: f64 = 0.0;
        for i in 0..m {
            viol = viol.max(
                self.outer_scaling
                    .row_to_user(i, self.outer_residual(i, s).abs()),
            );
        }
        Some((f, viol))
    }

    fn restoration_accepts(&mut self, w: &[f64]) -> bool {
        let (n, m) = (self.n, self.m);
        let x = &w[..n];
        let s = &w[n + 2 * m..];
        self.outer.eval_g(x, &mut self.gbuf);
        if self.gbuf.iter().any(|v| !v.is_finite()) {
            return false;
        }
        let (mut theta, mut inf_pr) = (0.0, 0.0f64);
        for i in 0..m {
            let c = self.outer_residual(i, s).abs();
            theta += c;
            inf_pr = inf_pr.max(c);
        }
        if inf_pr > self.inf_pr_target || theta > self.theta_max {
            return false;
        }
        let f = self.outer.eval_f(x);
        if !f.is_finite() {
            return false;
        }
        self.wbuf[..n].copy_from_slice(x);
        self.wbuf[n..].copy_from_slice(s);
        let barrier = Barrier {
            mu: self.mu_outer,
            kappa_d: self.kappa_d,
            wl: &self.wl,
            wu: &self.wu,
            has_l: &self.has_l,
            has_u: &self.has_u,
        };
        let phi = barrier.value(&self.wbuf, f);
        phi.is_finite() && self.filter.acceptable(theta, phi)
    }
}

/// Runs a restoration phase from the outer iteration's state `outer`; the outer
/// iteration goes on as [`Ended::next`] says.
pub(crate) fn restore(outer: Entry<'_>, shared: &mut Shared) -> Ended {
    let (n, m) = (outer.lay.n, outer.lay.m);
    let opts = outer.opts.clone();
    let mu = outer.mu.max(inf_norm(&outer.it.c));
    let rho = opts.resto_penalty_parameter;
    let (pv, nv) = initial_p_n(&outer.it.c, mu, rho);
    // Full inner iterate: w = [x, p, n, s].
    let mut w = outer.it.w[..n].to_vec();
    w.extend_from_slice(&pv);
    w.extend_from_slice(&nv);
    w.extend_from_slice(&outer.it.w[n..]);
    let [zl, zu] = resto_bound_multipliers(outer.lay, outer.it, &pv, &nv, mu, rho);
    // IPOPT's first 'r' row reports the failed line search of the outer iteration
    // (alpha_pr, 'R', ls).
    let failed_search = outer.failed_search;
    let x0 = w[..n + 2 * m].to_vec();
    let mut resto = resto_problem(outer, &opts, x0, mu);
    let unscaled = Scaling::unscaled(m);
    let setup = Setup {
        mu_init: mu,
        bound_relax_factor: 0.0,
        in_resto: true,
        scaling: &unscaled,
        mu_strategy: MuStrategy::Monotone,
        failed_search,
    };
    let mut inner_opts = opts.clone();
    inner_opts.acceptable_iter = 0;
    inner_opts.start_with_resto = false;
    let mut inner = match Core::new(&mut resto, &inner_opts, &setup, Buffers::default()) {
        Ok(c) => c,
        Err(e) => {
            return Ended {
                status: Status::RestorationFailed,
                message: e.to_string(),
                converged: false,
                point: None,
            }
        }
    };
    let y0 = vec![0.0; m];
    let start = Start::Exact {
        w: &w,
        y: &y0,
        zl: &zl,
        zu: &zu,
    };
    run_inner(&mut inner, shared, start, n, m)
}

/// The restoration problem around the outer iterate, starting at `x0 = [x, p, n]` with
/// barrier parameter `mu`; it evaluates through the outer problem.
fn resto_problem<'a>(outer: Entry<'a>, opts: &IpmOptions, x0: Vec<f64>, mu: f64) -> Resto<'a> {
    let lay = outer.lay;
    let (n, m, ni) = (lay.n, lay.m, lay.ni);
    let xr: Vec<f64> = x0[..n].to_vec();
    let dr2: Vec<f64> = xr
        .iter()
        .map(|x| (1.0f64).min(1.0 / x.abs()).powi(2))
        .collect();
    let jac_o = outer.nlp.jac_g_sparsity().clone();
    let nnz_j_orig = jac_o.row_idx().len();
    let (jac, hess, hmap, hdiag) = resto_patterns(&jac_o, outer.nlp.hess_l_sparsity(), n, m);
    let hbuf_len = outer.nlp.hess_l_sparsity().row_idx().len();
    let ([x_l, x_u], [g_l, g_u]) = resto_bounds(lay);
    Resto {
        n,
        m,
        rho: opts.resto_penalty_parameter,
        zeta: opts.resto_proximity_weight * mu.sqrt(),
        dr2,
        xr,
        jac,
        nnz_j_orig,
        hess,
        hmap,
        hdiag,
        x_l,
        x_u,
        g_l,
        g_u,
        x0,
        hbuf: vec![0.0; hbuf_len],
        slack_of_row: lay.slack_of_row.clone(),
        g_eq: lay.g_eq.clone(),
        wl: lay.wl.clone(),
        wu: lay.wu.clone(),
        has_l: lay.has_l.clone(),
        has_u: lay.has_u.clone(),
        kappa_d: opts.kappa_d,
        mu_outer: outer.mu,
        filter: outer.filter.clone(),
        inf_pr_target: (opts.required_infeasibility_reduction * inf_norm(&outer.it.c))
            .max(opts.tol.min(opts.constr_viol_tol)),
        theta_max: outer.theta_max,
        gbuf: vec![0.0; m],
        wbuf: vec![0.0; n + ni],
        outer_scaling: outer.scaling.clone(),
        outer: outer.nlp,
    }
}

/// The inner core's solve from `start`, with its final point mapped back to the outer
/// variables: `x = w[..n]`, `s = w[n+2m..]` (none after an invalid number: the outer
/// iteration then stays where it is).
fn run_inner(
    inner: &mut Core<'_>,
    shared: &mut Shared,
    start: Start<'_>,
    n: usize,
    m: usize,
) -> Ended {
    // The inner core never restores (it is the restoration phase); `restore` stands
    // for the argument.
    let outcome = inner.run(shared, start, restore);
    let point = (outcome.status != Status::InvalidNumberDetected).then(|| {
        let w_inner = &inner.iterate().w;
        let mut w_o = w_inner[..n].to_vec();
        w_o.extend_from_slice(&w_inner[n + 2 * m..]);
        w_o
    });
    Ended {
        status: outcome.status,
        message: outcome.message,
        converged: outcome.resto_converged,
        point,
    }
}

/// The initial elastic variables `p, n` for constraint values `c`: IPOPT's closed
/// form of `c − p + n = 0` with complementarity `μ` and penalty `ρ`.
fn initial_p_n(c: &[f64], mu: f64, rho: f64) -> (Vec<f64>, Vec<f64>) {
    let m = c.len();
    let mut pv = vec![0.0; m];
    let mut nv = vec![0.0; m];
    for i in 0..m {
        let c = c[i];
        let a = (mu - rho * c) / (2.0 * rho);
        let nn = a + (a * a + mu * c / (2.0 * rho)).sqrt();
        nv[i] = nn.max(1e-300);
        pv[i] = (c + nn).max(1e-300);
    }
    (pv, nv)
}

/// The restoration problem's variable bounds `[x_l, x_u]` (x's own, `p, n ≥ 0`) and
/// constraint bounds `[g_l, g_u]` (the equality value, or the slack's bounds).
fn resto_bounds(lay: &Layout) -> ([Vec<f64>; 2], [Vec<f64>; 2]) {
    let (n, m) = (lay.n, lay.m);
    let mut x_l = vec![0.0; n + 2 * m];
    let mut x_u = vec![f64::INFINITY; n + 2 * m];
    x_l[..n].copy_from_slice(&lay.wl[..n]);
    x_u[..n].copy_from_slice(&lay.wu[..n]);
    let mut g_l = vec![0.0; m];
    let mut g_u = vec![0.0; m];
    for i in 0..m {
        let k = lay.slack_of_row[i];
        if k == usize::MAX {
            g_l[i] = lay.g_eq[i];
            g_u[i] = lay.g_eq[i];
        } else {
            g_l[i] = lay.wl[n + k];
            g_u[i] = lay.wu[n + k];
        }
    }
    ([x_l, x_u], [g_l, g_u])
}

/// The inner start's bound multipliers `[z_L, z_U]` on `w = [x, p, n, s]` from the outer
/// iterate `it`: its own capped at `ρ` for x and s, `μ/p` and `μ/n` for the elastic
/// variables.
fn resto_bound_multipliers(
    lay: &Layout,
    it: &Iterate,
    pv: &[f64],
    nv: &[f64],
    mu: f64,
    rho: f64,
) -> [Vec<f64>; 2] {
    let (n, m, ni) = (lay.n, lay.m, lay.ni);
    let nwi = n + 2 * m + ni;
    let mut zl = vec![0.0; nwi];
    let mut zu = vec![0.0; nwi];
    for j in 0..n {
        zl[j] = it.zl[j].min(rho);
        zu[j] = it.zu[j].min(rho);
    }
    for i in 0..m {
        zl[n + i] = mu / pv[i];
        zl[n + m + i] = mu / nv[i];
    }
    for k in 0..ni {
        zl[n + 2 * m + k] = it.zl[n + k].min(rho);
        zu[n + 2 * m + k] = it.zu[n + k].min(rho);
    }
    [zl, zu]
}

/// (Jacobian pattern, Hessian pattern, hmap, hdiag) of the restoration problem.
type RestoPatterns = (
    SymbolicSparseColMat<usize>,
    SymbolicSparseColMat<usize>,
    Vec<usize>,
    Vec<usize>,
);

/// The restoration problem's sparsity patterns from the original Jacobian `jac_o` and
/// Hessian `h_o` (n variables, m rows): J_R = [J, −I, I] and the Hessian with every
/// diagonal entry of x present; `hmap` maps each original Hessian entry to its position,
/// `hdiag` gives the diagonal entry of each x column.
fn resto_patterns(
    jac_o: &SymbolicSparseColMat<usize>,
    h_o: &SymbolicSparseColMat<usize>,
    n: usize,
    m: usize,
) -> RestoPatterns {
    let mut cp: Vec<usize> = jac_o.col_ptr()[..=n].to_vec();
    let mut ri: Vec<usize> = Vec::with_capacity(jac_o.row_idx().len() + 2 * m);
    for j in 0..n {
        ri.extend(jac_o.row_idx_of_col_raw(j).iter().copied());
    }
    // Compact in case the original pattern had gaps.
    cp.clear();
    cp.push(0);
    let mut acc = 0;
    for j in 0..n {
        acc += jac_o.row_idx_of_col_raw(j).len();
        cp.push(acc);
    }
    for i in 0..m {
        ri.push(i);
        cp.push(ri.len());
    }
    for i in 0..m {
        ri.push(i);
        cp.push(ri.len());
    }
    let jac = SymbolicSparseColMat::new_checked(m, n + 2 * m, cp, None, ri);
    let mut hcp = vec![0usize];
    let mut hri = Vec::new();
    let mut hmap = vec![0usize; h_o.row_idx().len()];
    let mut hdiag = vec![0usize; n];
    for j in 0..n {
        let mut rows: Vec<usize> = h_o.row_idx_of_col_raw(j).to_vec();
        rows.push(j);
        rows.sort_unstable();
        rows.dedup();
        let base = hri.len();
        for p in h_o.col_range(j) {
            let r = h_o.row_idx()[p];
            hmap[p] = base + rows.binary_search(&r).unwrap_or(0);
        }
        hdiag[j] = base + rows.binary_search(&j).unwrap_or(0);
        hri.extend(rows);
        hcp.push(hri.len());
    }
    for _ in 0..2 * m {
        hcp.push(hri.len());
    }
    let hess = SymbolicSparseColMat::new_checked(n + 2 * m, n + 2 * m, hcp, None, hri);
    (jac, hess, hmap, hdiag)
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, &b| a.max(b.abs()))
}
