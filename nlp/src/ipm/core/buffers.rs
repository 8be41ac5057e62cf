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
use super::layout::Layout;

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
