//! What an [`Sqp`](crate::Sqp) keeps between solves, as the IPM's workspace does: the KKT
//! matrix of the active-set method and the convexity test (its pattern, AMD ordering and
//! symbolic factorisation) and the layouts of the QP (with and without the augmented
//! term), for the structure they were built for. A warm re-solve of a problem with the
//! same structure then skips the symbolic analysis and the QP layout.
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

use super::geometry::Geometry;
use super::qp::Qp;
use super::shape::Shape;
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
pub(crate) struct Workspace(Mutex<Option<Box<Parts>>>);

impl Workspace {
    /// The kept parts if they were built for the structure of `shape` and `geo` (reset
    /// to the state of new ones), nothing otherwise.
    /// `qp_limits`: the QP tolerance and iteration limit of this solve's options.
    pub(super) fn take(&self, shape: &Shape, geo: &Geometry, qp_limits: (f64, u32)) -> Reused {
        let parts = self.0.try_lock().ok().and_then(|mut g| g.take());
        match parts {
            Some(p) if keepable(shape) && p.structure.is(shape, geo) => {
                let Parts {
                    structure,
                    mut kkt,
                    mut plain,
                    mut aug,
                } = *p;
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
    /// [`Workspace::take`] returned, if any.
    pub(super) fn keep(
        &self,
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
        if let Ok(mut guard) = self.0.try_lock() {
            *guard = Some(Box::new(Parts {
                structure,
                kkt,
                plain,
                aug,
            }));
        }
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
