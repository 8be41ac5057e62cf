//! Node construction with constant folding and cheap local simplifications.
//!
//! Every new node goes through [`Graph::unary`], [`Graph::binary`] or [`Graph::if_else`],
//! which fold constant operands, apply identities such as `x + 0 = x`, `x·1 = x`,
//! `x·0 = 0`, `−(−x) = x`, `x − x = 0`, move negations out of products and quotients,
//! fold `c·(2ᵏ·y)` into one product where that gives the same bits (`|c| ≥ 1`),
//! put commutative operands in a canonical order and
//! finally hash-cons the node. The rules are local: none looks deeper than the operands'
//! own operation.
use crate::graph::{Graph, Node};
use crate::op::Op;

pub(crate) const ZERO: u32 = 0;
pub(crate) const ONE: u32 = 1;

impl Graph {
    /// Creates `op(a)`, simplified.
    pub fn unary(&mut self, op: Op, a: u32) -> u32 {
        debug_assert_eq!(op.arity(), 1);
        debug_assert_ne!(
            op,
            Op::Interpolant,
            "lookups are built by Graph::interpolant"
        );
        if let Some(v) = self.value(a) {
            return self.constant(op.eval1(v));
        }
        let na = self.node(a);
        match op {
            Op::Neg if na.op == Op::Neg => return na.args[0],
            Op::Neg if na.op == Op::Sub => {
                return self.binary(Op::Sub, na.args[1], na.args[0]);
            }
            Op::Sq if na.op == Op::Neg || na.op == Op::Abs => {
                return self.unary(Op::Sq, na.args[0])
            }
            Op::Abs if matches!(na.op, Op::Abs | Op::Sq | Op::Exp | Op::Sqrt) => return a,
            Op::Abs if na.op == Op::Neg => return self.unary(Op::Abs, na.args[0]),
            _ => {}
        }
        self.intern(Node {
            op,
            args: [a, 0, 0],
        })
    }

    /// Creates `op(a, b)`, simplified.
    pub fn binary(&mut self, op: Op, a: u32, b: u32) -> u32 {
        debug_assert_eq!(op.arity(), 2);
        debug_assert_ne!(
            op,
            Op::Interpolant2,
            "lookups are built by Graph::interpolant2"
        );
        let (va, vb) = (self.value(a), self.value(b));
        if let (Some(x), Some(y)) = (va, vb) {
            return self.constant(op.eval2(x, y));
        }
        let is = |v: Option<f64>, c: f64| v == Some(c);
        match op {
            Op::Add => {
                if is(va, 0.0) {
                    return b;
                }
                if is(vb, 0.0) {
                    return a;
                }
                if self.node(b).op == Op::Neg {
                    return self.binary(Op::Sub, a, self.node(b).args[0]);
                }
                if self.node(a).op == Op::Neg {
                    return self.binary(Op::Sub, b, self.node(a).args[0]);
                }
            }
            Op::Sub => {
                if a == b {
                    return ZERO;
                }
                if is(vb, 0.0) {
                    return a;
                }
                if is(va, 0.0) {
                    return self.unary(Op::Neg, b);
                }
                if self.node(b).op == Op::Neg {
                    return self.binary(Op::Add, a, self.node(b).args[0]);
                }
            }
            Op::Mul => {
                if is(va, 0.0) || is(vb, 0.0) {
                    return ZERO;
                }
                if is(va, 1.0) {
                    return b;
                }
                if is(vb, 1.0) {
                    return a;
                }
                if is(va, -1.0) {
                    return self.unary(Op::Neg, b);
                }
                if is(vb, -1.0) {
                    return self.unary(Op::Neg, a);
                }
                if a == b {
                    return self.unary(Op::Sq, a);
                }
                if let Some(r) = self.pull_negation(Op::Mul, a, b) {
                    return r;
                }
                if let Some(r) = self.fold_scale(va, b).or_else(|| self.fold_scale(vb, a)) {
                    return r;
                }
            }
            Op::StrongMul => {
                if is(va, 0.0) || is(vb, 0.0) {
                    return ZERO;
                }
                if is(va, 1.0) {
                    return b;
                }
                if is(vb, 1.0) {
                    return a;
                }
                // A non-zero constant factor cannot be the exact zero the operation guards.
                if va.is_some() {
                    return self.binary(Op::Mul, a, b);
                }
            }
            Op::Div => {
                if is(vb, 1.0) {
                    return a;
                }
                if is(va, 0.0) {
                    return ZERO;
                }
                if a == b {
                    return ONE;
                }
                if is(vb, -1.0) {
                    return self.unary(Op::Neg, a);
                }
                if let Some(r) = self.pull_negation(Op::Div, a, b) {
                    return r;
                }
            }
            Op::Pow => {
                if is(vb, 0.0) {
                    return ONE;
                }
                if is(vb, 1.0) {
                    return a;
                }
                if is(vb, 2.0) {
                    return self.unary(Op::Sq, a);
                }
                if is(vb, 0.5) {
                    return self.unary(Op::Sqrt, a);
                }
                if is(va, 1.0) {
                    return ONE;
                }
            }
            Op::Min | Op::Max | Op::And | Op::Or if a == b => return a,
            Op::Le | Op::Eq if a == b => return ONE,
            Op::Lt | Op::Ne if a == b => return ZERO,
            _ => {}
        }
        let (a, b) = if op.is_commutative() && a > b {
            (b, a)
        } else {
            (a, b)
        };
        self.intern(Node {
            op,
            args: [a, b, 0],
        })
    }

    /// `(−a)·b = −(a·b)`, `a·(−b) = −(a·b)`, `(−a)·(−b) = a·b` (and the same for `/`).
    ///
    /// Moving negations outwards lets them cancel against `−`, `+` and other negations
    /// further up; derivatives produce many (`∂(a−b)/∂b = −1`), and in a Lagrangian Hessian
    /// this removes about a third of the operations.
    fn pull_negation(&mut self, op: Op, a: u32, b: u32) -> Option<u32> {
        let (na, nb) = (self.node(a), self.node(b));
        match (na.op == Op::Neg, nb.op == Op::Neg) {
            (false, false) => None,
            (true, true) => Some(self.binary(op, na.args[0], nb.args[0])),
            (true, false) => {
                let p = self.binary(op, na.args[0], b);
                Some(self.unary(Op::Neg, p))
            }
            (false, true) => {
                let p = self.binary(op, a, nb.args[0]);
                Some(self.unary(Op::Neg, p))
            }
        }
    }

    /// `c·(s·y) = (c·s)·y` for constants with `|c| ≥ 1` and `s = ±2ᵏ`, `k ≥ 0`, when `c·s`
    /// is finite (so `c·s` is exact): the same bits for every `y`, NaN and ±0 included.
    ///
    /// Proof: `s·y` is exact unless it overflows (scaling by `2ᵏ`, `k ≥ 0`, drops no bit,
    /// subnormals included), and then both sides round the same real number `c·s·y` once.
    /// If `s·y` overflows, `|s·y|` is at least the overflow threshold, so is `|c·s·y|`
    /// since `|c| ≥ 1`: both sides are the same signed infinity. A NaN `y` comes out of
    /// both as `y`'s NaN, quieted (a product returns its one NaN operand's sign and
    /// payload). Derivatives make this shape: `w·(x − t)²` gives `w·(2·(x − t))`. (With
    /// `|c| < 1` it is not exact: `0.001·(2·y)` is infinite for `|y| > MAX/2`, `0.002·y`
    /// is not; a constant `s` other than `±2ᵏ` rounds `s·y` first.)
    fn fold_scale(&mut self, c: Option<f64>, m: u32) -> Option<u32> {
        let c = c.filter(|c| c.abs() >= 1.0 && c.is_finite())?;
        let n = self.node(m);
        if n.op != Op::Mul {
            return None;
        }
        let [p, q, _] = n.args;
        let (s, y) = match (self.value(p), self.value(q)) {
            (Some(s), None) => (s, q),
            (None, Some(s)) => (s, p),
            _ => return None,
        };
        let scale_up = s.abs() >= 1.0 && s.is_finite() && s.to_bits() << 12 == 0;
        let product = c * s;
        if !scale_up || !product.is_finite() {
            return None;
        }
        let k = self.constant(product);
        Some(self.binary(Op::Mul, k, y))
    }

    /// Creates `if_else(c, a, b)`, simplified.
    pub fn if_else(&mut self, c: u32, a: u32, b: u32) -> u32 {
        if let Some(v) = self.value(c) {
            return if v != 0.0 { a } else { b };
        }
        if a == b {
            return a;
        }
        self.intern(Node {
            op: Op::IfElse,
            args: [c, a, b],
        })
    }

    /// Creates a node with the given operation and operands, simplified.
    pub fn make(&mut self, op: Op, args: &[u32]) -> u32 {
        match args.len() {
            1 => self.unary(op, args[0]),
            2 => self.binary(op, args[0], args[1]),
            3 => self.if_else(args[0], args[1], args[2]),
            _ => unreachable!("make({op:?}) with {} operands", args.len()),
        }
    }
}
