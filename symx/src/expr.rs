//! [`Expr`]: a small `Copy` handle to a node of this thread's expression graph.
use crate::graph::{self, Graph};
use crate::op::Op;
use std::marker::PhantomData;
use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

/// A scalar symbolic expression.
///
/// `Expr` is a `Copy` handle (a `u32` index) into a graph owned by the current thread, so
/// it cannot be sent to another thread; compile it into a [`crate::Function`], which can.
/// Identical expressions share one node: building `x * y` twice returns the same handle.
///
/// ```
/// use symx::Expr;
/// let x = Expr::sym("x");
/// let y = Expr::sym("y");
/// let f = (x * y + 1.0).sin() / 2.0 - x.powi(3);
/// assert_eq!(f.to_string(), "((sin((1+(x*y)))/2)-pow(x,3))");
/// ```
#[derive(Clone, Copy)]
pub struct Expr {
    pub(crate) id: u32,
    _thread_local: PhantomData<*const ()>,
}

impl Expr {
    pub(crate) fn from_id(id: u32) -> Expr {
        Expr {
            id,
            _thread_local: PhantomData,
        }
    }

    /// A new named scalar symbol, distinct from every other symbol (even one with the same name).
    pub fn sym(name: &str) -> Expr {
        Expr::from_id(graph::with(|g| g.symbol(name)))
    }

    /// A numeric constant.
    pub fn constant(v: f64) -> Expr {
        Expr::from_id(graph::with(|g| g.constant(v)))
    }

    /// The constant zero.
    pub fn zero() -> Expr {
        Expr::from_id(crate::simplify::ZERO)
    }

    /// The constant one.
    pub fn one() -> Expr {
        Expr::from_id(crate::simplify::ONE)
    }

    /// The node index: equal indices mean structurally identical expressions.
    pub fn id(self) -> u32 {
        self.id
    }

    /// Whether `self` and `other` are the same node (structural identity, not numeric equality).
    pub fn is(self, other: Expr) -> bool {
        self.id == other.id
    }

    /// The operation at the root of this expression.
    pub fn op(self) -> Op {
        graph::with(|g| g.node(self.id).op)
    }

    /// The operands of the root operation.
    pub fn operands(self) -> Vec<Expr> {
        graph::with(|g| {
            g.operands(self.id)
                .iter()
                .map(|&a| Expr::from_id(a))
                .collect()
        })
    }

    /// The value, if this expression is a constant.
    pub fn value(self) -> Option<f64> {
        graph::with(|g| g.value(self.id))
    }

    /// Whether this is the constant `v`.
    pub fn is_constant_value(self, v: f64) -> bool {
        self.value() == Some(v)
    }

    /// Whether this is a symbol.
    pub fn is_symbol(self) -> bool {
        self.op() == Op::Sym
    }

    /// The symbol's name, if this is a symbol.
    pub fn name(self) -> Option<String> {
        graph::with(|g| (g.node(self.id).op == Op::Sym).then(|| g.symbol_name(self.id).to_string()))
    }

    pub(crate) fn un(self, op: Op) -> Expr {
        Expr::from_id(graph::with(|g| g.unary(op, self.id)))
    }

    pub(crate) fn bin(self, op: Op, other: impl Into<Expr>) -> Expr {
        let b = other.into().id;
        Expr::from_id(graph::with(|g| g.binary(op, self.id, b)))
    }

    /// `x²`.
    pub fn sq(self) -> Expr {
        self.un(Op::Sq)
    }
    /// `√x`.
    pub fn sqrt(self) -> Expr {
        self.un(Op::Sqrt)
    }
    /// `eˣ`.
    pub fn exp(self) -> Expr {
        self.un(Op::Exp)
    }
    /// Natural logarithm.
    pub fn ln(self) -> Expr {
        self.un(Op::Log)
    }
    /// Natural logarithm (alias of [`Expr::ln`], CasADi's name).
    pub fn log(self) -> Expr {
        self.ln()
    }
    /// Sine.
    pub fn sin(self) -> Expr {
        self.un(Op::Sin)
    }
    /// Cosine.
    pub fn cos(self) -> Expr {
        self.un(Op::Cos)
    }
    /// Tangent.
    pub fn tan(self) -> Expr {
        self.un(Op::Tan)
    }
    /// Arcsine.
    pub fn asin(self) -> Expr {
        self.un(Op::Asin)
    }
    /// Arccosine.
    pub fn acos(self) -> Expr {
        self.un(Op::Acos)
    }
    /// Arctangent.
    pub fn atan(self) -> Expr {
        self.un(Op::Atan)
    }
    /// Hyperbolic sine.
    pub fn sinh(self) -> Expr {
        self.un(Op::Sinh)
    }
    /// Hyperbolic cosine.
    pub fn cosh(self) -> Expr {
        self.un(Op::Cosh)
    }
    /// Hyperbolic tangent.
    pub fn tanh(self) -> Expr {
        self.un(Op::Tanh)
    }
    /// Absolute value.
    pub fn abs(self) -> Expr {
        self.un(Op::Abs)
    }
    /// Sign: −1, 0 or 1 (derivative zero).
    pub fn sign(self) -> Expr {
        self.un(Op::Sign)
    }
    /// Largest integer `≤ x` (derivative zero).
    pub fn floor(self) -> Expr {
        self.un(Op::Floor)
    }
    /// Smallest integer `≥ x` (derivative zero).
    pub fn ceil(self) -> Expr {
        self.un(Op::Ceil)
    }
    /// The error function `erf(x) = 2/√π ∫₀ˣ e^(−t²) dt` (evaluated by the `libm` crate).
    pub fn erf(self) -> Expr {
        self.un(Op::Erf)
    }
    /// Inverse hyperbolic sine.
    pub fn asinh(self) -> Expr {
        self.un(Op::Asinh)
    }
    /// Inverse hyperbolic cosine (defined for `x ≥ 1`).
    pub fn acosh(self) -> Expr {
        self.un(Op::Acosh)
    }
    /// Inverse hyperbolic tangent (defined for `|x| < 1`).
    pub fn atanh(self) -> Expr {
        self.un(Op::Atanh)
    }
    /// `ln(1 + x)`, accurate for small `x`.
    pub fn log1p(self) -> Expr {
        self.un(Op::Log1p)
    }
    /// `eˣ − 1`, accurate for small `x`.
    pub fn expm1(self) -> Expr {
        self.un(Op::Expm1)
    }
    /// Remainder of `self / y` with the sign of `self` (C's `fmod`); derivatives `1` and
    /// `−trunc(self / y)`.
    pub fn fmod(self, y: impl Into<Expr>) -> Expr {
        self.bin(Op::Fmod, y)
    }
    /// `√(self² + y²)`, without intermediate overflow.
    pub fn hypot(self, y: impl Into<Expr>) -> Expr {
        self.bin(Op::Hypot, y)
    }
    /// Real power `selfʸ`.
    pub fn pow(self, y: impl Into<Expr>) -> Expr {
        self.bin(Op::Pow, y)
    }
    /// Integer power.
    pub fn powi(self, n: i32) -> Expr {
        self.bin(Op::Pow, n as f64)
    }
    /// Real power with a constant exponent.
    pub fn powf(self, y: f64) -> Expr {
        self.bin(Op::Pow, y)
    }
    /// Four-quadrant arctangent of `self / x` (like `f64::atan2`).
    pub fn atan2(self, x: impl Into<Expr>) -> Expr {
        self.bin(Op::Atan2, x)
    }
    /// Minimum, as `f64::min` (a NaN operand is ignored); its derivative follows the operand
    /// whose value is returned (on ties, one of the two).
    pub fn min(self, other: impl Into<Expr>) -> Expr {
        self.bin(Op::Min, other)
    }
    /// Maximum, as `f64::max` (a NaN operand is ignored); its derivative follows the operand
    /// whose value is returned (on ties, one of the two).
    pub fn max(self, other: impl Into<Expr>) -> Expr {
        self.bin(Op::Max, other)
    }
}

/// `if_else(c, a, b)`: `a` where `c ≠ 0`, else `b`.
///
/// Unlike `c·a + (1−c)·b`, the branch not taken never contaminates the value or any
/// derivative with NaN or ∞ (CasADi issue #1805):
/// ```
/// use symx::{Expr, if_else, gt, gradient, Function};
/// let x = Expr::sym("x");
/// let f = if_else(gt(x, 0.0), x.sqrt(), -x);
/// let df = gradient(f, &[x]).unwrap();
/// let fun = Function::new(&[&[x]], &[&df]).unwrap();
/// assert_eq!(fun.call(&[&[-4.0]]).unwrap()[0], vec![-1.0]);
/// ```
pub fn if_else(c: impl Into<Expr>, a: impl Into<Expr>, b: impl Into<Expr>) -> Expr {
    let (c, a, b) = (c.into().id, a.into().id, b.into().id);
    Expr::from_id(graph::with(|g| g.if_else(c, a, b)))
}

macro_rules! comparison {
    ($($(#[$doc:meta])* $name:ident => $op:expr, swap: $swap:expr;)*) => {$(
        $(#[$doc])*
        pub fn $name(a: impl Into<Expr>, b: impl Into<Expr>) -> Expr {
            let (a, b) = (a.into().id, b.into().id);
            let (a, b) = if $swap { (b, a) } else { (a, b) };
            Expr::from_id(graph::with(|g| g.binary($op, a, b)))
        }
    )*};
}

comparison! {
    /// `a < b` as 1 or 0.
    lt => Op::Lt, swap: false;
    /// `a ≤ b` as 1 or 0.
    le => Op::Le, swap: false;
    /// `a > b` as 1 or 0.
    gt => Op::Lt, swap: true;
    /// `a ≥ b` as 1 or 0.
    ge => Op::Le, swap: true;
    /// `a == b` as 1 or 0.
    eq => Op::Eq, swap: false;
    /// `a ≠ b` as 1 or 0.
    ne => Op::Ne, swap: false;
    /// Logical and of two conditions (non-zero is true).
    and => Op::And, swap: false;
    /// Logical or of two conditions (non-zero is true).
    or => Op::Or, swap: false;
}

/// `ln Σ eˣⁱ`, computed as CasADi does: `m + ln Σ e^(xᵢ − m)` with `m = max xᵢ`, so that
/// large entries do not overflow. The derivative is the softmax (the terms through `m`
/// cancel). An empty slice gives `−∞`, one entry gives the entry itself.
pub fn logsumexp(x: &[Expr]) -> Expr {
    match x {
        [] => Expr::constant(f64::NEG_INFINITY),
        [only] => *only,
        [first, rest @ ..] => {
            let m = rest.iter().fold(*first, |m, &e| m.max(e));
            m + x.iter().map(|&e| (e - m).exp()).sum::<Expr>().ln()
        }
    }
}

/// Logical negation of a condition.
pub fn not(a: impl Into<Expr>) -> Expr {
    a.into().un(Op::Not)
}

impl From<f64> for Expr {
    fn from(v: f64) -> Expr {
        Expr::constant(v)
    }
}

impl From<i32> for Expr {
    fn from(v: i32) -> Expr {
        Expr::constant(v as f64)
    }
}

impl Neg for Expr {
    type Output = Expr;
    fn neg(self) -> Expr {
        self.un(Op::Neg)
    }
}

macro_rules! arithmetic {
    ($($trait:ident $method:ident $assign_trait:ident $assign:ident => $op:expr;)*) => {$(
        impl<T: Into<Expr>> $trait<T> for Expr {
            type Output = Expr;
            fn $method(self, rhs: T) -> Expr {
                self.bin($op, rhs)
            }
        }
        impl $trait<Expr> for f64 {
            type Output = Expr;
            fn $method(self, rhs: Expr) -> Expr {
                Expr::constant(self).bin($op, rhs)
            }
        }
        impl<T: Into<Expr>> $assign_trait<T> for Expr {
            fn $assign(&mut self, rhs: T) {
                *self = self.bin($op, rhs);
            }
        }
    )*};
}

arithmetic! {
    Add add AddAssign add_assign => Op::Add;
    Sub sub SubAssign sub_assign => Op::Sub;
    Mul mul MulAssign mul_assign => Op::Mul;
    Div div DivAssign div_assign => Op::Div;
}

impl std::iter::Sum for Expr {
    /// Sums as a balanced tree, so that long sums stay shallow.
    fn sum<I: Iterator<Item = Expr>>(iter: I) -> Expr {
        let terms: Vec<u32> = iter.map(|e| e.id).collect();
        Expr::from_id(graph::with(|g| {
            balanced(g, Op::Add, terms, crate::simplify::ZERO)
        }))
    }
}

impl std::iter::Product for Expr {
    fn product<I: Iterator<Item = Expr>>(iter: I) -> Expr {
        let terms: Vec<u32> = iter.map(|e| e.id).collect();
        Expr::from_id(graph::with(|g| {
            balanced(g, Op::Mul, terms, crate::simplify::ONE)
        }))
    }
}

/// Reduces `terms` with an associative operation as a balanced binary tree.
pub(crate) fn balanced(g: &mut Graph, op: Op, mut terms: Vec<u32>, empty: u32) -> u32 {
    if terms.is_empty() {
        return empty;
    }
    while terms.len() > 1 {
        let mut next = Vec::with_capacity(terms.len().div_ceil(2));
        for pair in terms.chunks(2) {
            next.push(if pair.len() == 2 {
                g.binary(op, pair[0], pair[1])
            } else {
                pair[0]
            });
        }
        terms = next;
    }
    terms[0]
}

impl std::fmt::Debug for Expr {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Expr#{}({})", self.id, self)
    }
}
