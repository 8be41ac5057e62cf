//! [`Layout`]: how the primal vector w = [x; s] is laid out and bounded.

#![allow(clippy::needless_range_loop)]

use crate::frontend::scaled::refill;
use crate::ipm::reduced::IpmProblem;

/// How the primal vector w = [x; s] is laid out and bounded: fixed for a run.
#[derive(Clone, Default)]
pub(crate) struct Layout {
    pub(crate) n: usize,
    pub(crate) m: usize,
    /// Number of inequality rows (slacks).
    pub(crate) ni: usize,
    /// n + ni.
    pub(crate) nw: usize,
    /// row → slack index (usize::MAX for equality rows).
    pub(crate) slack_of_row: Vec<usize>,
    /// slack index → row.
    pub(crate) row_of_slack: Vec<usize>,
    /// Right-hand side of equality rows.
    pub(crate) g_eq: Vec<f64>,
    pub(crate) wl: Vec<f64>,
    pub(crate) wu: Vec<f64>,
    pub(crate) has_l: Vec<bool>,
    pub(crate) has_u: Vec<bool>,
}

impl Layout {
    /// The layout of w = [x; s] for `nlp`'s bounds (relaxed by `bound_relax_factor`), in
    /// this layout's vectors; `bounds` is scratch for the problem's bounds.
    pub(super) fn fill(
        &mut self,
        nlp: &dyn IpmProblem,
        bound_relax_factor: f64,
        bounds: &mut [Vec<f64>; 4],
    ) {
        let (n, m) = (nlp.n(), nlp.m());
        let [x_l, x_u, g_l, g_u] = bounds;
        refill(x_l, n, 0.0);
        refill(x_u, n, 0.0);
        refill(g_l, m, 0.0);
        refill(g_u, m, 0.0);
        nlp.bounds(x_l, x_u, g_l, g_u);
        refill(&mut self.slack_of_row, m, usize::MAX);
        self.row_of_slack.clear();
        refill(&mut self.g_eq, m, 0.0);
        for i in 0..m {
            if g_l[i] == g_u[i] {
                self.g_eq[i] = g_l[i];
            } else {
                self.slack_of_row[i] = self.row_of_slack.len();
                self.row_of_slack.push(i);
            }
        }
        let ni = self.row_of_slack.len();
        let nw = n + ni;
        refill(&mut self.wl, nw, f64::NEG_INFINITY);
        refill(&mut self.wu, nw, f64::INFINITY);
        self.wl[..n].copy_from_slice(x_l);
        self.wu[..n].copy_from_slice(x_u);
        for (k, &i) in self.row_of_slack.iter().enumerate() {
            self.wl[n + k] = g_l[i];
            self.wu[n + k] = g_u[i];
        }
        let rf = bound_relax_factor;
        for j in 0..nw {
            if self.wl[j].is_finite() {
                self.wl[j] -= rf * self.wl[j].abs().max(1.0);
            }
            if self.wu[j].is_finite() {
                self.wu[j] += rf * self.wu[j].abs().max(1.0);
            }
        }
        self.has_l.clear();
        self.has_l.extend(self.wl.iter().map(|v| v.is_finite()));
        self.has_u.clear();
        self.has_u.extend(self.wu.iter().map(|v| v.is_finite()));
        (self.n, self.m, self.ni, self.nw) = (n, m, ni, nw);
    }
}
