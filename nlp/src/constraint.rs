//! Constraints written as relations on expressions: `g.eq(c)`, `g.le(c)`, `g.ge(c)` and
//! [`bounded`]`(lo, g, hi)`.
use symx::{Expr, Matrix};

/// One or more scalar constraints `lower ≤ expr ≤ upper` built from a relation.
///
/// Bounds are numbers; a relation between two non-constant sides is moved to one side
/// (`g ≤ h` becomes `g − h ≤ 0`). Equalities have `lower == upper`.
#[derive(Clone, Debug)]
pub struct Constraint {
    pub(crate) rows: Vec<Row>,
    /// Shapes of an entrywise relation between matrices that do not match.
    pub(crate) mismatch: Option<((usize, usize), (usize, usize))>,
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Row {
    pub expr: Expr,
    pub lower: f64,
    pub upper: f64,
}

impl Constraint {
    fn single(row: Row) -> Constraint {
        Constraint {
            rows: vec![row],
            mismatch: None,
        }
    }

    /// Number of scalar rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether the constraint has no rows.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The constraint expressions, one per row.
    pub fn expressions(&self) -> Vec<Expr> {
        self.rows.iter().map(|r| r.expr).collect()
    }

    /// Lower bounds, one per row.
    pub fn lower_bounds(&self) -> Vec<f64> {
        self.rows.iter().map(|r| r.lower).collect()
    }

    /// Upper bounds, one per row.
    pub fn upper_bounds(&self) -> Vec<f64> {
        self.rows.iter().map(|r| r.upper).collect()
    }

    /// Joins several constraints into one group.
    pub fn all(parts: impl IntoIterator<Item = Constraint>) -> Constraint {
        let mut rows = Vec::new();
        let mut mismatch = None;
        for c in parts {
            rows.extend(c.rows);
            mismatch = mismatch.or(c.mismatch);
        }
        Constraint { rows, mismatch }
    }
}

enum Kind {
    Eq,
    Le,
    Ge,
}

fn relation(lhs: Expr, rhs: Expr, kind: Kind) -> Row {
    let inf = f64::INFINITY;
    match (lhs.value(), rhs.value(), kind) {
        (_, Some(c), Kind::Eq) => Row {
            expr: lhs,
            lower: c,
            upper: c,
        },
        (Some(c), None, Kind::Eq) => Row {
            expr: rhs,
            lower: c,
            upper: c,
        },
        (_, Some(c), Kind::Le) => Row {
            expr: lhs,
            lower: -inf,
            upper: c,
        },
        (Some(c), None, Kind::Le) => Row {
            expr: rhs,
            lower: c,
            upper: inf,
        },
        (_, Some(c), Kind::Ge) => Row {
            expr: lhs,
            lower: c,
            upper: inf,
        },
        (Some(c), None, Kind::Ge) => Row {
            expr: rhs,
            lower: -inf,
            upper: c,
        },
        (None, None, Kind::Eq) => Row {
            expr: lhs - rhs,
            lower: 0.0,
            upper: 0.0,
        },
        (None, None, Kind::Le) => Row {
            expr: lhs - rhs,
            lower: -inf,
            upper: 0.0,
        },
        (None, None, Kind::Ge) => Row {
            expr: lhs - rhs,
            lower: 0.0,
            upper: inf,
        },
    }
}

/// Relations that make constraints; implemented for [`Expr`] and [`Matrix`] (entrywise).
///
/// The right-hand side may be a number, an expression, or (for matrices) a matrix of
/// the same shape or a scalar broadcast to every entry.
pub trait Relation<Rhs> {
    /// `self == rhs`.
    fn eq(self, rhs: Rhs) -> Constraint;
    /// `self ≤ rhs`.
    fn le(self, rhs: Rhs) -> Constraint;
    /// `self ≥ rhs`.
    fn ge(self, rhs: Rhs) -> Constraint;
}

impl<T: Into<Expr>> Relation<T> for Expr {
    fn eq(self, rhs: T) -> Constraint {
        Constraint::single(relation(self, rhs.into(), Kind::Eq))
    }
    fn le(self, rhs: T) -> Constraint {
        Constraint::single(relation(self, rhs.into(), Kind::Le))
    }
    fn ge(self, rhs: T) -> Constraint {
        Constraint::single(relation(self, rhs.into(), Kind::Ge))
    }
}

fn broadcast(m: &Matrix, rhs: Expr, kind: fn() -> Kind) -> Constraint {
    Constraint {
        rows: m.iter().map(|&e| relation(e, rhs, kind())).collect(),
        mismatch: None,
    }
}

macro_rules! broadcast_relation {
    ($($rhs:ty),*) => {$(
        impl Relation<$rhs> for &Matrix {
            fn eq(self, rhs: $rhs) -> Constraint {
                broadcast(self, rhs.into(), || Kind::Eq)
            }
            fn le(self, rhs: $rhs) -> Constraint {
                broadcast(self, rhs.into(), || Kind::Le)
            }
            fn ge(self, rhs: $rhs) -> Constraint {
                broadcast(self, rhs.into(), || Kind::Ge)
            }
        }
    )*};
}
broadcast_relation!(f64, Expr);

/// Entrywise relations between matrices; a shape mismatch is reported by
/// [`crate::Problem::subject_to`].
fn entrywise(a: &Matrix, b: &Matrix, kind: fn() -> Kind) -> Constraint {
    Constraint {
        rows: a
            .iter()
            .zip(b.iter())
            .map(|(&x, &y)| relation(x, y, kind()))
            .collect(),
        mismatch: (a.shape() != b.shape()).then(|| (a.shape(), b.shape())),
    }
}

impl Relation<&Matrix> for &Matrix {
    fn eq(self, rhs: &Matrix) -> Constraint {
        entrywise(self, rhs, || Kind::Eq)
    }
    fn le(self, rhs: &Matrix) -> Constraint {
        entrywise(self, rhs, || Kind::Le)
    }
    fn ge(self, rhs: &Matrix) -> Constraint {
        entrywise(self, rhs, || Kind::Ge)
    }
}

/// The two-sided constraint `lower ≤ g ≤ upper` for every entry of `g`.
pub fn bounded(lower: f64, g: impl Into<Matrix>, upper: f64) -> Constraint {
    Constraint {
        rows: g
            .into()
            .iter()
            .map(|&expr| Row { expr, lower, upper })
            .collect(),
        mismatch: None,
    }
}
