//! The KKT work: the KKT system of a run and the vectors it is assembled and solved in.

#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use crate::frontend::scaled::refill;
use crate::ipm::error::CoreError;
use crate::ipm::reduced::IpmProblem;
use crate::kkt::Kkt;
use crate::options::IpmOptions;

use super::layout::Layout;

/// Assembly and factorisation workspace of the KKT system.
pub(super) struct KktWork {
    pub(super) kkt: Kkt,
    /// Diagonal added to the Hessian block (Σ_x + δ_w + static regularisation).
    pub(super) kdx: Vec<f64>,
    /// Diagonal of the constraint block (−δ_c, regularisation or 1/Σ_s).
    pub(super) kdc: Vec<f64>,
    pub(super) rhs: Vec<f64>,
    pub(super) rhs_s: Vec<f64>,
    pub(super) rhs_copy: Vec<f64>,
    /// Σ_s + δ_w of each slack.
    pub(super) ds: Vec<f64>,
    /// The static regularisations in the last factorised matrix, with the sign that
    /// removes them in iterative refinement (set by `factor_kkt`).
    pub(super) shift: Vec<f64>,
    /// Static regularisation of each equality row (see `update_eq_reg`).
    pub(super) eq_reg: Vec<f64>,
    /// The regularisation of the current factorisation (see `step_eq_reg`).
    pub(super) eq_reg_step: Vec<f64>,
    /// Position of the diagonal entry of each Hessian column (usize::MAX: none).
    pub(super) hess_diag: Vec<usize>,
    pub(super) hzero: Vec<f64>,
    pub(super) work_nw: Vec<f64>,
    /// The limited-memory Hessian (`hessian_approximation = limited-memory`).
    pub(super) lm: Option<crate::lbfgs::LimitedMemoryHessian>,
    /// Factor applied to both static regularisations (1, or `QUALITY_REG_SCALE` while
    /// `Core::solve_with_higher_quality` refactorises).
    pub(super) reg_scale: f64,
}

impl KktWork {
    /// The KKT system analysed for `nlp`'s Hessian and Jacobian patterns, with empty
    /// work vectors (see [`KktWork::prepare`]).
    pub(super) fn new(nlp: &dyn IpmProblem) -> Result<KktWork, CoreError> {
        let kkt = Kkt::new(
            nlp.n(),
            nlp.m(),
            nlp.hess_l_sparsity(),
            nlp.jac_g_sparsity(),
        )?;
        Ok(KktWork {
            kkt,
            kdx: Vec::new(),
            kdc: Vec::new(),
            rhs: Vec::new(),
            rhs_s: Vec::new(),
            rhs_copy: Vec::new(),
            ds: Vec::new(),
            shift: Vec::new(),
            eq_reg: Vec::new(),
            eq_reg_step: Vec::new(),
            hess_diag: Vec::new(),
            hzero: Vec::new(),
            work_nw: Vec::new(),
            lm: None,
            reg_scale: 1.0,
        })
    }

    /// The state of a fresh run: the factor forgotten, the refinement options set, every
    /// work vector sized for `lay` and zeroed, the Hessian's diagonal positions found.
    pub(super) fn prepare(&mut self, nlp: &dyn IpmProblem, opts: &IpmOptions, lay: &Layout) {
        let (n, m, ni, nw) = (lay.n, lay.m, lay.ni, lay.nw);
        let nnz_h = nlp.hess_l_sparsity().row_idx().len();
        self.kkt.reset();
        self.kkt.min_refinement_steps = opts.min_refinement_steps;
        self.kkt.max_refinement_steps = opts.max_refinement_steps;
        self.kkt.residual_ratio_max = opts.residual_ratio_max;
        self.kkt.residual_ratio_floor = opts.residual_ratio_floor;
        for (v, len) in [
            (&mut self.kdx, n),
            (&mut self.kdc, m),
            (&mut self.rhs, n + m),
            (&mut self.rhs_s, ni),
            (&mut self.rhs_copy, n + m),
            (&mut self.ds, ni),
            // Refinement target: K without the static regularisation of equality rows.
            (&mut self.shift, n + m),
            (&mut self.eq_reg, m),
            (&mut self.eq_reg_step, m),
            (&mut self.hzero, nnz_h),
            (&mut self.work_nw, nw),
        ] {
            refill(v, len, 0.0);
        }
        refill(&mut self.hess_diag, n, usize::MAX);
        let hp = nlp.hess_l_sparsity();
        for (j, d) in self.hess_diag.iter_mut().enumerate() {
            for p in hp.col_range(j) {
                if hp.row_idx()[p] == j {
                    *d = p;
                }
            }
        }
        self.lm = crate::lbfgs::LimitedMemoryHessian::from_options(opts, n);
        self.reg_scale = 1.0;
    }

    /// Solves the factorised system for `rhs` in place (refined against K + diag(shift)).
    pub(super) fn solve_rhs(&mut self) -> Result<f64, crate::kkt::KktError> {
        match self.lm.as_mut() {
            Some(lm) => lm.solve_shifted(&mut self.kkt, &mut self.rhs, Some(&self.shift)),
            None => self.kkt.solve_shifted(&mut self.rhs, Some(&self.shift)),
        }
    }
}
