//! The user's problem as both back ends see it (IPOPT's `IpOrigIpoptNLP` with
//! `IpNLPScaling`): the objective scaled by s_f and row i of g by s_g,i, every evaluation
//! counted and timed, and the conversions of multipliers between the scaled problem and
//! the user's units.
//!
//! f, g, ∇f and J are evaluated once per point ([`PointValues`]): asked for again at the
//! same point, they are not evaluated (nor counted) again.
//!
//! The factors are chosen by each back end from [`ScaledNlp::unscaled_gradient_norms_into`]
//! with the rules of `scaling.rs`; the IPM layers its removal of fixed variables and
//! unbounded rows on top (`ipm/reduced.rs`).

use std::time::Instant;

use super::point_values::{PointValues, Value};
use crate::numeric::NumericNlp;
use crate::solution::Stats;

/// The scaling of a problem: the objective factor s_f and one factor s_g,i per row, with
/// the conversions of values and multipliers between the scaled problem and the user's
/// units. Both back ends unscale through it (the IPM's core holds the factors of its
/// reduced rows, see [`Scaling::restrict`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Scaling {
    /// Objective factor s_f.
    pub obj: f64,
    /// Row factors s_g,i.
    pub rows: Vec<f64>,
}

impl Default for Scaling {
    /// No rows, s_f = 1.
    fn default() -> Self {
        Scaling::unscaled(0)
    }
}

impl Scaling {
    /// All factors 1, for `m` rows.
    pub fn unscaled(m: usize) -> Self {
        Scaling {
            obj: 1.0,
            rows: vec![1.0; m],
        }
    }

    /// The factors of the rows `keep` (in that order), with the same s_f, into `out`
    /// (keeping its vector's capacity).
    pub fn restrict_into(&self, keep: &[usize], out: &mut Scaling) {
        out.obj = self.obj;
        out.rows.clear();
        out.rows.extend(keep.iter().map(|&i| self.rows[i]));
    }

    /// `self` set to `other` (keeping its vector's capacity).
    pub fn assign(&mut self, other: &Scaling) {
        self.obj = other.obj;
        self.rows.clone_from(&other.rows);
    }

    /// λ_i in the user's units from the multiplier `y` of scaled row i: y·s_g,i / s_f.
    pub fn lambda_to_user(&self, i: usize, y: f64) -> f64 {
        y * self.rows[i] / self.obj
    }

    /// Every λ in the user's units from the multipliers of the scaled rows
    /// ([`Scaling::lambda_to_user`] row by row) into `out`.
    pub fn lambdas_to_user(&self, scaled: &[f64], out: &mut [f64]) {
        for (i, (l, &y)) in out.iter_mut().zip(scaled).enumerate() {
            *l = self.lambda_to_user(i, y);
        }
    }

    /// A quantity in units of the objective (its value, a gradient or dual-infeasibility
    /// entry, complementarity) in the user's units: v / s_f.
    pub fn objective_to_user(&self, v: f64) -> f64 {
        v / self.obj
    }

    /// A quantity in units of scaled row i (its value, its violation) in the user's
    /// units: v / s_g,i.
    pub fn row_to_user(&self, i: usize, v: f64) -> f64 {
        v / self.rows[i]
    }

    /// The largest |c_i| / s_g,i: the max-norm of scaled row residuals `c` in the user's
    /// units.
    pub fn max_row_to_user(&self, c: &[f64]) -> f64 {
        c.iter()
            .zip(&self.rows)
            .fold(0.0f64, |a, (c, s)| a.max(c.abs() / s))
    }

    /// The multiplier of scaled row i from the user's λ_i: λ_i·s_f / s_g,i.
    pub fn lambda_from_user(&self, i: usize, lambda: f64) -> f64 {
        lambda * self.obj / self.rows[i]
    }

    /// A bound (or cone) multiplier in the user's units: z / s_f.
    pub fn z_to_user(&self, z: f64) -> f64 {
        z / self.obj
    }

    /// A bound multiplier of the scaled problem from the user's: z·s_f.
    pub fn z_from_user(&self, z: f64) -> f64 {
        z * self.obj
    }
}

/// Sets `v` to `len` copies of `value`, keeping its capacity (no allocation once `v`
/// has grown to `len`).
pub(crate) fn refill<T: Clone>(v: &mut Vec<T>, len: usize, value: T) {
    v.clear();
    v.resize(len, value);
}

/// The vectors of a [`ScaledNlp`], kept between solves.
#[derive(Default)]
pub(crate) struct ScaledBuffers {
    rows: Vec<f64>,
    lam: Vec<f64>,
    values: PointValues,
}

/// The result of [`ScaledNlp::unscaled_gradient_norms_into`], kept between solves.
#[derive(Default)]
pub(crate) struct NormScratch {
    /// The unscaled max-norm of each row of the Jacobian over the kept columns.
    pub rmax: Vec<f64>,
}

/// Evaluation counters and time spent in user callbacks.
#[derive(Debug, Clone, Default)]
pub(crate) struct EvalCounters {
    pub f: usize,
    pub grad_f: usize,
    pub g: usize,
    pub jac_g: usize,
    pub hess_l: usize,
    pub seconds: f64,
}

/// The user's NLP with scaling, counters and timing; x is always in the user's numbering
/// and units (scaling changes only function values and multipliers).
pub(crate) struct ScaledNlp<'a> {
    user: &'a mut dyn NumericNlp,
    /// The factors s_f and s_g (1 where not scaled).
    pub scaling: Scaling,
    pub counters: EvalCounters,
    /// Scratch: the user's multipliers for the Hessian.
    lam: Vec<f64>,
    /// The unscaled values at the last point evaluated.
    values: PointValues,
}

impl<'a> ScaledNlp<'a> {
    /// The unscaled problem (all factors 1).
    #[cfg(test)] // the back ends use the `_into` forms
    pub fn new(user: &'a mut dyn NumericNlp) -> Self {
        Self::with_buffers(user, ScaledBuffers::default())
    }

    /// The unscaled problem (all factors 1) in the vectors of `buffers` (kept from an earlier solve with
    /// [`ScaledNlp::into_buffers`]; no allocation once they have grown to the sizes).
    pub fn with_buffers(user: &'a mut dyn NumericNlp, buffers: ScaledBuffers) -> Self {
        let (n, m) = (user.n(), user.m());
        let ScaledBuffers {
            mut rows,
            mut lam,
            mut values,
        } = buffers;
        refill(&mut rows, m, 1.0);
        refill(&mut lam, m, 0.0);
        values.reset(n, m, user.jac_g_sparsity().row_idx().len());
        ScaledNlp {
            user,
            scaling: Scaling { obj: 1.0, rows },
            counters: EvalCounters::default(),
            lam,
            values,
        }
    }

    /// The vectors, for [`ScaledNlp::with_buffers`] in a later solve.
    pub fn into_buffers(self) -> ScaledBuffers {
        ScaledBuffers {
            rows: self.scaling.rows,
            lam: self.lam,
            values: self.values,
        }
    }

    /// The user's problem (evaluations through it are neither scaled nor counted).
    pub fn user(&self) -> &dyn NumericNlp {
        &*self.user
    }

    /// The user's problem, mutably (evaluations through it are neither scaled nor
    /// counted: count them in `counters`).
    pub fn user_mut(&mut self) -> &mut dyn NumericNlp {
        self.user
    }

    /// Makes `value` known at `x` ([`ScaledNlp::values`]): evaluated (unscaled, counted
    /// and timed) unless it was evaluated at this point (same bits) already. When the
    /// problem [evaluates pairs together](NumericNlp::evaluates_together), f and g (∇f and
    /// J) are evaluated, stored and counted together.
    pub fn evaluate(&mut self, value: Value, x: &[f64]) {
        if self.values.has(value, x) {
            return;
        }
        let t = Instant::now();
        let (u, c) = (&mut *self.user, &mut self.counters);
        let together = u.evaluates_together();
        match value {
            Value::F | Value::G if together => {
                let f = u.eval_f_g(x, self.values.store(Value::G, x));
                self.values.store_f(x, f);
                c.f += 1;
                c.g += 1;
            }
            Value::Grad | Value::Jac if together => {
                let (grad, jac) = self.values.store_grad_jac(x);
                u.eval_grad_f_jac_g(x, grad, jac);
                c.grad_f += 1;
                c.jac_g += 1;
            }
            Value::F => {
                let f = u.eval_f(x);
                self.values.store_f(x, f);
                c.f += 1;
            }
            Value::G => {
                u.eval_g(x, self.values.store(value, x));
                c.g += 1;
            }
            Value::Grad => {
                u.eval_grad_f(x, self.values.store(value, x));
                c.grad_f += 1;
            }
            Value::Jac => {
                u.eval_jac_g(x, self.values.store(value, x));
                c.jac_g += 1;
            }
        }
        c.seconds += t.elapsed().as_secs_f64();
    }

    /// The unscaled values at the last point evaluated (those [`ScaledNlp::evaluate`]
    /// made known at a point are there until another point is evaluated).
    pub fn values(&self) -> &PointValues {
        &self.values
    }

    /// Scaled objective s_f·f(x).
    pub fn f(&mut self, x: &[f64]) -> f64 {
        self.evaluate(Value::F, x);
        self.values.f() * self.scaling.obj
    }

    /// Scaled gradient s_f·∇f(x).
    pub fn grad(&mut self, x: &[f64], out: &mut [f64]) {
        self.evaluate(Value::Grad, x);
        for (v, &u) in out.iter_mut().zip(self.values.grad()) {
            *v = u * self.scaling.obj;
        }
    }

    /// Scaled rows s_g,i·g_i(x).
    pub fn g(&mut self, x: &[f64], out: &mut [f64]) {
        self.evaluate(Value::G, x);
        for ((v, &u), s) in out.iter_mut().zip(self.values.g()).zip(&self.scaling.rows) {
            *v = u * s;
        }
    }

    /// Scaled Jacobian values (row i times s_g,i), in the user's pattern order.
    pub fn jac(&mut self, x: &[f64], out: &mut [f64]) {
        self.evaluate(Value::Jac, x);
        let rows = self.user.jac_g_sparsity().row_idx();
        for ((v, &u), &r) in out.iter_mut().zip(self.values.jac()).zip(rows) {
            *v = u * self.scaling.rows[r];
        }
    }

    /// Hessian of the scaled Lagrangian σ·f̃ + λ̃ᵀg̃ for multipliers λ̃ of the scaled rows
    /// (the user's Hessian with σ·s_f and λ̃_i·s_g,i).
    pub fn hess(&mut self, x: &[f64], obj_factor: f64, lambda: &[f64], out: &mut [f64]) {
        for ((l, &y), s) in self.lam.iter_mut().zip(lambda).zip(&self.scaling.rows) {
            *l = y * s;
        }
        let t = Instant::now();
        self.user
            .eval_hess_l(x, obj_factor * self.scaling.obj, &self.lam, out);
        self.counters.hess_l += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
    }

    /// The stacked affine-cone entries (not scaled; timed with the evaluations).
    pub fn cone_entries(&mut self, x: &[f64], out: &mut [f64]) {
        let t = Instant::now();
        self.user.eval_cone_entries(x, out);
        self.counters.seconds += t.elapsed().as_secs_f64();
    }

    /// The cone-entry Jacobian (not scaled; timed with the evaluations).
    pub fn cone_jac(&mut self, x: &[f64], out: &mut [f64]) {
        let t = Instant::now();
        self.user.eval_cone_jac(x, out);
        self.counters.seconds += t.elapsed().as_secs_f64();
    }

    /// Unscaled, counted evaluations for choosing the factors: max-norm of ∇f(x) over the
    /// columns in `cols` (all when `None`) and of each row of the Jacobian over the same
    /// columns (the Jacobian is not evaluated when there are no rows). A row with a
    /// non-finite entry reports NaN (the gradient-based rule then leaves it unscaled).
    #[cfg(test)] // the back ends use the `_into` forms
    pub fn unscaled_gradient_norms(&mut self, x: &[f64], cols: Option<&[bool]>) -> (f64, Vec<f64>) {
        let mut scratch = NormScratch::default();
        let gmax = self.unscaled_gradient_norms_into(x, cols, &mut scratch);
        (gmax, scratch.rmax)
    }

    /// The norms the gradient-based scaling needs, in the vectors of `scratch` (no allocation
    /// once they have grown to the problem's sizes): returns max |∇f|, the row norms are
    /// left in `scratch.rmax`.
    pub fn unscaled_gradient_norms_into(
        &mut self,
        x: &[f64],
        cols: Option<&[bool]>,
        scratch: &mut NormScratch,
    ) -> f64 {
        let (n, m) = (self.user.n(), self.user.m());
        let keep = |j: usize| cols.is_none_or(|c| c[j]);
        self.evaluate(Value::Grad, x);
        if m > 0 {
            self.evaluate(Value::Jac, x);
        }
        let NormScratch { rmax } = scratch;
        let (grad, jv) = (self.values.grad(), self.values.jac());
        let gmax = (0..n)
            .filter(|&j| keep(j))
            .map(|j| grad[j].abs())
            .fold(0.0, f64::max);
        refill(rmax, m, 0.0f64);
        let jp = self.user.jac_g_sparsity();
        for c in (0..n).filter(|&c| keep(c)) {
            for p in jp.col_range(c) {
                let (r, v) = (jp.row_idx()[p], jv[p].abs());
                // NaN stays: `f64::max` would drop it at the row's next entry.
                rmax[r] = if v.is_finite() && !rmax[r].is_nan() {
                    rmax[r].max(v)
                } else {
                    f64::NAN
                };
            }
        }
        gmax
    }

    /// Writes the evaluation counts, their time and s_f into `stats`.
    pub fn write_stats(&self, stats: &mut Stats) {
        let c = &self.counters;
        stats.n_eval_f = c.f;
        stats.n_eval_grad_f = c.grad_f;
        stats.n_eval_g = c.g;
        stats.n_eval_jac_g = c.jac_g;
        stats.n_eval_hess_l = c.hess_l;
        stats.eval_seconds = c.seconds;
        stats.obj_scaling = self.scaling.obj;
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::ScaledNlp;
    use crate::numeric::NumericNlp;
    use crate::solution::Stats;
    use crate::{Problem, Relation};

    /// f = 3x₀² + x₁, g₀ = x₀x₁ = 1, g₁ = 100x₀ + x₁ ≤ 500; derivatives by hand at
    /// x = (2, 3): ∇f = (12, 1), J = [[3, 2], [100, 1]], ∇²f = diag(6, 0), ∇²g₀ = [[0, 1],
    /// [1, 0]].
    fn problem() -> crate::Compiled {
        let mut pb = Problem::new();
        let x = pb.variable("x", 2).unwrap();
        pb.minimize(3.0 * x[0] * x[0] + x[1]);
        pb.subject_to((x[0] * x[1]).eq(1.0)).unwrap();
        pb.subject_to((100.0 * x[0] + x[1]).le(500.0)).unwrap();
        pb.compile().unwrap()
    }

    /// Dense lower triangle of a 2×2 Hessian from pattern values.
    fn dense(nlp: &dyn NumericNlp, v: &[f64]) -> [[f64; 2]; 2] {
        let p = nlp.hess_l_sparsity();
        let mut h = [[0.0; 2]; 2];
        for c in 0..2 {
            for q in p.col_range(c) {
                h[p.row_idx()[q]][c] += v[q];
            }
        }
        h
    }

    #[test]
    fn evaluations_are_scaled_counted_and_unscaled_back() {
        let mut c = problem();
        let mut sc = ScaledNlp::new(&mut c);
        let x = [2.0, 3.0];
        let (gmax, rmax) = sc.unscaled_gradient_norms(&x, None);
        assert_eq!((gmax, rmax.clone()), (12.0, vec![3.0, 100.0]));
        let (gmax, rmax) = sc.unscaled_gradient_norms(&x, Some(&[false, true]));
        assert_eq!((gmax, rmax), (1.0, vec![2.0, 1.0]));
        sc.scaling.obj = 0.5;
        sc.scaling.rows = vec![2.0, 0.01];
        // Factors are powers of two or exact decimals times small integers: the scaled
        // values below are exact, so equality is the test.
        assert_eq!(sc.f(&x), 0.5 * 15.0);
        let mut v = [0.0; 2];
        sc.grad(&x, &mut v);
        assert_eq!(v, [6.0, 0.5]);
        sc.g(&x, &mut v);
        assert_eq!(v, [12.0, 203.0 * 0.01]);
        let jp = sc.user().jac_g_sparsity().clone();
        let mut jv = vec![0.0; jp.row_idx().len()];
        sc.jac(&x, &mut jv);
        let want = [[3.0 * 2.0, 2.0 * 2.0], [100.0 * 0.01, 0.01]];
        for col in 0..2 {
            for q in jp.col_range(col) {
                let r = jp.row_idx()[q];
                assert_eq!(jv[q], want[r][col], "J[{r}][{col}]");
            }
        }
        // σ = 2, λ̃ = (3, 7): ∇²(2·0.5·f + 3·2·g₀ + 7·0.01·g₁) = [[6, ·], [6, 0]].
        let mut hv = vec![0.0; sc.user().hess_l_sparsity().row_idx().len()];
        sc.hess(&x, 2.0, &[3.0, 7.0], &mut hv);
        assert_eq!(dense(sc.user(), &hv), [[6.0, 0.0], [6.0, 0.0]]);
        // Everything at one point: ∇f and J evaluated once for the two norms and the
        // scaled values (the Hessian is not cached).
        let c = &sc.counters;
        assert_eq!((c.f, c.grad_f, c.g, c.jac_g, c.hess_l), (1, 1, 1, 1, 1));
        sc.f(&[2.0, 4.0]);
        sc.g(&x, &mut v);
        assert_eq!(v, [12.0, 203.0 * 0.01]);
        // A compiled problem evaluates f and g together: each evaluation counts both.
        let c = &sc.counters;
        assert_eq!(
            (c.f, c.grad_f, c.g, c.jac_g),
            (3, 1, 3, 1),
            "another point between"
        );
        // λ_user = λ̃·s_g/s_f and back; z_user = z/s_f and back.
        assert_eq!(sc.scaling.lambda_to_user(0, 3.0), 12.0);
        assert_eq!(sc.scaling.lambda_from_user(0, 12.0), 3.0);
        assert_eq!(sc.scaling.z_to_user(1.5), 3.0);
        assert_eq!(sc.scaling.z_from_user(3.0), 1.5);
        let mut lam = [0.0; 2];
        sc.scaling.lambdas_to_user(&[3.0, 7.0], &mut lam);
        assert_eq!(lam, [12.0, 7.0 * 0.01 / 0.5]);
        assert_eq!(sc.scaling.objective_to_user(1.5), 3.0);
        assert_eq!(
            (
                sc.scaling.row_to_user(0, 3.0),
                sc.scaling.row_to_user(1, 0.5)
            ),
            (1.5, 50.0)
        );
        let mut stats = Stats::default();
        sc.write_stats(&mut stats);
        assert_eq!((stats.n_eval_jac_g, stats.obj_scaling), (1, 0.5));
    }

    #[test]
    fn a_row_with_a_non_finite_gradient_reports_nan() {
        let mut pb = Problem::new();
        let x = pb.variable("x", 2).unwrap();
        pb.minimize(x[0] + x[1]);
        // d/dx₀ (1/x₀) = −∞ at x₀ = 0; the second row stays finite.
        pb.subject_to((1.0 / x[0] + x[1]).ge(0.0)).unwrap();
        pb.subject_to((x[0] + 4.0 * x[1]).ge(0.0)).unwrap();
        let mut c = pb.compile().unwrap();
        let mut sc = ScaledNlp::new(&mut c);
        let (_, rmax) = sc.unscaled_gradient_norms(&[0.0, 1.0], None);
        assert!(rmax[0].is_nan(), "{rmax:?}");
        assert_eq!(rmax[1], 4.0);
    }
}
