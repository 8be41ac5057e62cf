//! [`ProblemParts`]: a problem's pieces as compiled, handed from the builder to
//! [`Compiled`](crate::Compiled).
use super::block::Block;
use super::cone_record::Cone;
use crate::constraint::Row;
use crate::parameter::ParameterIndex;
use symx::Expr;

/// The pieces of a problem handed to [`Compiled::new`]: bounds, rows and blocks as
/// compiled (after simple bound detection).
pub(crate) struct ProblemParts<'a> {
    pub variables: &'a [Expr],
    pub parameters: &'a [Expr],
    pub parameter_index: &'a ParameterIndex,
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    pub initial: &'a [f64],
    pub rows: Vec<Row>,
    pub variable_blocks: &'a [Block],
    pub constraint_blocks: Vec<Block>,
    /// Each cone with its row of g.
    pub cones: Vec<(usize, &'a Cone)>,
}
