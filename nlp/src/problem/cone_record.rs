//! [`Cone`]: the record of a second-order cone constraint, and its smoothing.
use symx::Expr;

/// Smoothing ε of the smooth form `√(‖v‖² + ε²) − t ≤ ε` of a second-order cone (see
/// [`Problem::subject_to_cone`](crate::Problem::subject_to_cone)).
pub const CONE_SMOOTHING: f64 = 1e-8;

/// A second-order cone `‖v‖ ≤ t` recorded by [`Problem::subject_to_cone`](crate::Problem::subject_to_cone).
#[derive(Clone, Debug)]
pub struct Cone {
    /// The name given when declaring it (also the name of its smooth row).
    pub name: String,
    /// The constraint row (as written, before simple bound detection) holding its smooth
    /// form.
    pub(crate) row: usize,
    /// The cone's `t`.
    pub t: Expr,
    /// The cone's `v`.
    pub v: Vec<Expr>,
    /// Whether t and every entry of v are affine in the variables (parameters allowed).
    pub affine: bool,
}
