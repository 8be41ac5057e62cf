//! The vectors a run of the core works in — the layout of w, the iterate and trial
//! point, the directions, the KKT system and its work vectors, the filter and the μ
//! oracles' scratch — as one value an [`Ipm`](crate::Ipm)'s workspace keeps between
//! solves of the same structure, so that a warm re-solve allocates nothing.
//!
//! Every run starts by [`Buffers::prepare`]: each vector is cleared and refilled with
//! the values a fresh run starts from, so a run on kept buffers is bit-identical to a
//! run on new ones (only the capacity is reused).

use crate::frontend::scaled::{refill, Scaling};
use crate::ipm::error::CoreError;
use crate::ipm::filter::Filter;
use crate::ipm::quality::Pairs;
use crate::ipm::reduced::IpmProblem;
use crate::options::IpmOptions;

use super::direction::Direction;
use super::iterate::{Iterate, Trial};
use super::kkt_work::KktWork;
use super::Layout;

/// The vectors of one run of the core (see the module doc).
#[derive(Default)]
pub(crate) struct Buffers {
    pub(super) lay: Layout,
    pub(super) it: Iterate,
    pub(super) trial: Trial,
    pub(super) dir: Direction,
    pub(super) dir_soc: Direction,
    pub(super) c_soc: Vec<f64>,
    /// `None` until the first run builds the KKT system for the structure.
    pub(super) kw: Option<KktWork>,
    pub(super) filter: Filter,
    pub(super) kkt_refs: Vec<f64>,
    pub(super) quality_pairs: Pairs,
    pub(super) scaling: Scaling,
    /// The problem's starting point (scratch of `Core::initialize`).
    pub(super) x_start: Vec<f64>,
    /// The multipliers before a least-squares re-estimate (scratch of `recalc_y`).
    pub(super) y_saved: Vec<f64>,
    /// The problem's bounds x_l, x_u, g_l, g_u (scratch of `Layout::fill`).
    pub(super) bounds: [Vec<f64>; 4],
}

impl Buffers {
    /// The final iterate of the last run.
    pub(crate) fn iterate(&self) -> &Iterate {
        &self.it
    }

    /// Every vector set to a fresh run's starting values for `nlp` (the KKT system built
    /// on the first run, its numeric state reset on later ones); `scaling` copied in.
    pub(super) fn prepare(
        &mut self,
        nlp: &dyn IpmProblem,
        opts: &IpmOptions,
        bound_relax_factor: f64,
        scaling: &Scaling,
    ) -> Result<(), CoreError> {
        self.lay.fill(nlp, bound_relax_factor, &mut self.bounds);
        let (n, m, nw) = (self.lay.n, self.lay.m, self.lay.nw);
        let nnz_j = nlp.jac_g_sparsity().row_idx().len();
        let nnz_h = nlp.hess_l_sparsity().row_idx().len();
        self.it.prepare(n, m, nw, nnz_j, nnz_h);
        self.trial.prepare(n, m, nw, nnz_j, nnz_h);
        self.dir.prepare(nw, m);
        self.dir_soc.prepare(nw, m);
        refill(&mut self.c_soc, m, 0.0);
        let kw = match self.kw.take() {
            Some(kw) => kw,
            None => KktWork::new(nlp)?,
        };
        self.kw = Some(kw);
        if let Some(kw) = self.kw.as_mut() {
            kw.prepare(nlp, opts, &self.lay);
        }
        self.filter.reset();
        self.kkt_refs.clear();
        self.quality_pairs.clear();
        self.scaling.assign(scaling);
        refill(&mut self.x_start, n, 0.0);
        refill(&mut self.y_saved, m, 0.0);
        Ok(())
    }
}

impl Layout {
    /// The layout of w = [x; s] for `nlp`'s bounds (relaxed by `bound_relax_factor`), in
    /// this layout's vectors; `bounds` is scratch for the problem's bounds.
    fn fill(&mut self, nlp: &dyn IpmProblem, bound_relax_factor: f64, bounds: &mut [Vec<f64>; 4]) {
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
