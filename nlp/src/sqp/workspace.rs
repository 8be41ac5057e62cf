//! What an [`Sqp`](crate::Sqp) keeps between solves, as the IPM's workspace does: the KKT
//! matrix of the active-set method and the convexity test (its pattern, AMD ordering and
//! symbolic factorisation) and the layouts of the QP (with and without the augmented
//! term), for the structure they were built for, and the vectors every solve works in
//! ([`Buffers`]). A warm re-solve of a problem with the same structure then skips the
//! symbolic analysis and the QP layout, and allocates nothing (see
//! [`Sqp::solve_warm_into`](crate::Sqp::solve_warm_into)).
//!
//! The [`Solver`](crate::Solver) trait takes `&self`, so the parts sit behind a mutex: a
//! solve takes them and puts them back at the end; a solve that finds them taken (another
//! thread is solving with the same solver) builds its own. Nothing numeric is carried
//! over: the KKT matrix forgets its factor ([`Kkt::reset`]), the QPs their clarabel
//! solver ([`Qp::reset`]), and every value is written again before it is read, so the
//! iterates are bit-identical to a fresh solver's (`nlp/tests/sqp_chain.rs`,
//! `warm_sequence_with_kept_parts_is_bit_identical`).

use std::sync::Mutex;

use faer::sparse::SymbolicSparseColMat;

use super::active_set::Scratch as ActiveSetScratch;
use super::convexify::{ConvexifyScratch, Curvature};
use super::geometry::Geometry;
use super::iterate::{Iterate, TrialPoint};
use super::polish::WorkingSet;
use super::qp::{Qp, QpResult};
use super::shape::Shape;
use crate::frontend::scaled::{NormScratch, ScaledBuffers};
use crate::frontend::user_solution::FinalScratch;
use crate::frontend::validate::Validated;
use crate::ipm::reduced::same_pattern;
use crate::kkt::Kkt;

/// The structure the kept parts were built for: the sizes, the Hessian and Jacobian
/// patterns and which bounds are finite or equal (they decide the QP's rows).
pub(super) struct Structure {
    n: usize,
    m: usize,
    hess: SymbolicSparseColMat<usize>,
    jac: SymbolicSparseColMat<usize>,
    /// Per variable, then per row: [`bound_code`] of its bounds.
    bounds: Vec<u8>,
}

/// Which of a lower and an upper bound are finite and whether they are equal.
fn bound_code(l: f64, u: f64) -> u8 {
    u8::from(l.is_finite()) | u8::from(u.is_finite()) << 1 | u8::from(l == u) << 2
}

impl Structure {
    /// The structure of `shape` and `geo` (copied).
    fn new(shape: &Shape, geo: &Geometry) -> Structure {
        let vars = geo.x_l.iter().zip(&geo.x_u);
        let rows = geo.g_l.iter().zip(&geo.g_u);
        Structure {
            n: shape.n,
            m: shape.m,
            hess: shape.hp.clone(),
            jac: shape.jp.clone(),
            bounds: vars.chain(rows).map(|(&l, &u)| bound_code(l, u)).collect(),
        }
    }

    /// True if `shape` and `geo` have this structure.
    fn is(&self, shape: &Shape, geo: &Geometry) -> bool {
        let vars = geo.x_l.iter().zip(&geo.x_u);
        let rows = geo.g_l.iter().zip(&geo.g_u);
        self.n == shape.n
            && self.m == shape.m
            && self.bounds.len() == shape.n + shape.m
            && same_pattern(&self.hess, &shape.hp)
            && same_pattern(&self.jac, &shape.jp)
            && vars
                .chain(rows)
                .zip(&self.bounds)
                .all(|((&l, &u), &c)| bound_code(l, u) == c)
    }
}

/// The parts one solve hands to the next.
pub(super) struct Parts {
    structure: Structure,
    kkt: Kkt,
    /// The QP without and with the augmented term (each once it was needed).
    plain: Option<Qp>,
    aug: Option<Qp>,
}

/// Everything a solver keeps: the parts of one structure (if any) and the vectors every
/// solve works in, whatever its structure (resized by the next solve; no allocation once
/// they have grown to its sizes).
#[derive(Default)]
pub(super) struct Kept {
    parts: Option<Parts>,
    pub bufs: Buffers,
}

/// The vectors an SQP solve works in, kept between solves. Every value is written again
/// before it is read, so a re-solve in them is bit-identical to a fresh solver's.
#[derive(Default)]
pub(super) struct Buffers {
    pub validated: Validated,
    pub scaled: ScaledBuffers,
    pub norms: NormScratch,
    pub last: FinalScratch,
    /// The shape and geometry of the last solve (reused when the patterns are the same).
    pub layout: Option<(Shape, Geometry)>,
    pub it: Option<Iterate>,
    pub curv: Option<Curvature>,
    pub steps: StepBuffers,
}

/// The vectors of the steps of an iteration (see `SqpState`'s uses).
#[derive(Default)]
pub(super) struct StepBuffers {
    /// Merit weights w_i.
    pub merit_w: Vec<f64>,
    /// ∇L scratch of the KKT error.
    pub lgrad: Vec<f64>,
    /// The multipliers ∇²L is evaluated with (cone rows zeroed).
    pub hess_lambda: Vec<f64>,
    /// The active rows and bounds of the convexification.
    pub active: (Vec<bool>, Vec<bool>),
    pub convexify: ConvexifyScratch,
    pub active_set: ActiveSetScratch,
    /// QP results not in use (their vectors are written into by the next QPs).
    pub results: Vec<QpResult>,
    /// The working set of the last QP, and one not in use.
    pub working_set: Option<WorkingSet>,
    pub spare_working_set: Option<WorkingSet>,
    /// Trial points not in use.
    pub points: Vec<TrialPoint>,
    pub model: ModelBuffers,
    /// The cone multipliers in the user's units.
    pub z_cone_user: Vec<f64>,
}

/// The vectors of the line search's model and second-order correction, kept between
/// iterations.
#[derive(Default)]
pub(super) struct ModelBuffers {
    pub jd: Vec<f64>,
    pub cd: Vec<f64>,
    pub lin_g: Vec<f64>,
    pub lin_c: Vec<f64>,
    pub gh: Vec<f64>,
    pub chat: Vec<f64>,
}

/// What a solve starts from: the kept KKT matrix and QPs of its structure, if any, and
/// that structure (handed back to [`Workspace::keep`]).
#[derive(Default)]
pub(super) struct Reused {
    pub kkt: Option<Kkt>,
    pub plain: Option<Qp>,
    pub aug: Option<Qp>,
    pub structure: Option<Structure>,
}

/// Whether a problem of this shape can use kept parts: the exact Hessian (the KKT matrix
/// exists) and no cones (the QP layout's key does not cover them).
pub(super) fn keepable(shape: &Shape) -> bool {
    !shape.dense && shape.n_cone == 0
}

/// The kept parts of one solver (empty when cloned).
#[derive(Default)]
pub(crate) struct Workspace(Mutex<Option<Box<Kept>>>);

impl Workspace {
    /// What this solver kept (new, empty buffers when nothing was kept or another thread
    /// is solving with it).
    pub(super) fn take(&self) -> Box<Kept> {
        let kept = self.0.try_lock().ok().and_then(|mut g| g.take());
        kept.unwrap_or_default()
    }

    /// Keeps `kept` for the next solve.
    pub(super) fn put(&self, kept: Box<Kept>) {
        if let Ok(mut guard) = self.0.try_lock() {
            *guard = Some(kept);
        }
    }
}

impl Kept {
    /// The kept parts if they were built for the structure of `shape` and `geo` (reset
    /// to the state of new ones), nothing otherwise.
    /// `qp_limits`: the QP tolerance and iteration limit of this solve's options.
    pub(super) fn reuse(&mut self, shape: &Shape, geo: &Geometry, qp_limits: (f64, u32)) -> Reused {
        match self.parts.take() {
            Some(p) if keepable(shape) && p.structure.is(shape, geo) => {
                let Parts {
                    structure,
                    mut kkt,
                    mut plain,
                    mut aug,
                } = p;
                kkt.reset();
                for qp in plain.iter_mut().chain(aug.iter_mut()) {
                    qp.reset(qp_limits.0, qp_limits.1);
                }
                Reused {
                    kkt: Some(kkt),
                    plain,
                    aug,
                    structure: Some(structure),
                }
            }
            _ => Reused::default(),
        }
    }

    /// Keeps the KKT matrix and the QPs of a solve of `shape` and `geo` for the next
    /// solve (not for problems that cannot use them, [`keepable`]); `structure`: the one
    /// [`Kept::reuse`] returned, if any.
    pub(super) fn keep(
        &mut self,
        (shape, geo): (&Shape, &Geometry),
        structure: Option<Structure>,
        kkt: Option<Kkt>,
        qps: [Option<Qp>; 2],
    ) {
        let Some(kkt) = kkt.filter(|_| keepable(shape)) else {
            return;
        };
        let structure = structure.unwrap_or_else(|| Structure::new(shape, geo));
        let [a, b] = qps;
        let (mut plain, mut aug) = (None, None);
        for qp in [a, b].into_iter().flatten() {
            if qp.has_aug() {
                aug = Some(qp);
            } else {
                plain = Some(qp);
            }
        }
        self.parts = Some(Parts {
            structure,
            kkt,
            plain,
            aug,
        });
    }
}

impl Clone for Workspace {
    /// A clone starts with nothing kept.
    fn clone(&self) -> Self {
        Workspace::default()
    }
}

impl std::fmt::Debug for Workspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Workspace")
    }
}
