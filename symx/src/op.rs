//! The operation set of the expression graph: arity, numeric evaluation and printing names.

/// Every kind of node in the expression graph.
///
/// `Const` and `Sym` are leaves; the others take one, two or three operands.
/// Comparisons and logical operations return `1.0` for true and `0.0` for false.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[repr(u8)]
pub enum Op {
    /// A numeric constant.
    Const,
    /// A named symbol (a free variable of the graph).
    Sym,
    Neg,
    Sq,
    Sqrt,
    Exp,
    Log,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Abs,
    Sign,
    Not,
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Atan2,
    Min,
    Max,
    Lt,
    Le,
    Eq,
    Ne,
    And,
    Or,
    /// `a ⊛ b`: `a * b`, except that it is exactly `0` whenever `a == 0` (even if `b` is
    /// NaN or infinite). Automatic differentiation uses it for chain-rule products below a
    /// branch (`if_else`, `min`, `max`) so that the branch not taken never poisons
    /// derivatives with NaN.
    StrongMul,
    /// `if_else(c, a, b)`: `a` where `c != 0`, else `b`; the other branch never leaks NaN.
    IfElse,
    /// Largest integer not above the operand (derivative zero).
    Floor,
    /// Smallest integer not below the operand (derivative zero).
    Ceil,
    /// The error function.
    Erf,
    /// Inverse hyperbolic sine.
    Asinh,
    /// Inverse hyperbolic cosine.
    Acosh,
    /// Inverse hyperbolic tangent.
    Atanh,
    /// `ln(1 + x)`, accurate near 0.
    Log1p,
    /// `eˣ − 1`, accurate near 0.
    Expm1,
    /// Remainder of `a / b` with the sign of `a` (C's `fmod`, Rust's `%`).
    Fmod,
    /// `√(a² + b²)` without overflow.
    Hypot,
    /// A lookup table (see [`crate::Interpolant`]) applied to the operand; the node also
    /// records which table, so it prints as `interpolant#k(x)` and does not parse back.
    Interpolant,
    /// A 2-D lookup table (see [`crate::Interpolant2`]) applied to the two operands; the
    /// third slot records which table; prints as `interpolant#k(x,y)`, does not parse back.
    Interpolant2,
    /// A lookup table of any dimension: only the instruction of the compiled function an
    /// [`crate::InterpolantN`] calls (its operands are `b` consecutive registers from `a`),
    /// never a graph node.
    InterpolantN,
    /// A call of a compiled [`crate::Function`] (see [`crate::Function::apply`]); its
    /// operands (the argument entries) live in the graph's call table, so `arity` is 0.
    /// It has no value of its own: its outputs are `CallOutput` nodes.
    Call,
    /// Entry `k` (second slot) of the outputs of the `Call` node in the first slot.
    CallOutput,
}

impl Op {
    /// Number of operands.
    pub fn arity(self) -> usize {
        use Op::*;
        match self {
            Const | Sym | Call | InterpolantN => 0,
            Neg | Sq | Sqrt | Exp | Log | Sin | Cos | Tan | Asin | Acos | Atan | Sinh | Cosh
            | Tanh | Abs | Sign | Not | Floor | Ceil | Erf | Asinh | Acosh | Atanh | Log1p
            | Expm1 | Interpolant | CallOutput => 1,
            Add | Sub | Mul | Div | Pow | Atan2 | Min | Max | Lt | Le | Eq | Ne | And | Or
            | StrongMul | Fmod | Hypot | Interpolant2 => 2,
            IfElse => 3,
        }
    }

    /// Whether swapping the two operands leaves the value unchanged.
    pub fn is_commutative(self) -> bool {
        use Op::*;
        matches!(self, Add | Mul | Min | Max | Eq | Ne | And | Or | Hypot)
    }

    /// Operations whose derivative is identically zero (piecewise constant results).
    pub fn has_zero_derivative(self) -> bool {
        use Op::*;
        matches!(
            self,
            Sign | Not | Lt | Le | Eq | Ne | And | Or | Floor | Ceil
        )
    }

    /// Operations that select one operand at run time: adjoints below them may be an exact zero.
    pub fn is_selection(self) -> bool {
        matches!(self, Op::IfElse | Op::Min | Op::Max)
    }

    /// Evaluates a unary operation.
    #[inline(always)]
    pub fn eval1(self, a: f64) -> f64 {
        use Op::*;
        match self {
            Neg => -a,
            Sq => a * a,
            Sqrt => a.sqrt(),
            Exp => a.exp(),
            Log => a.ln(),
            Sin => a.sin(),
            Cos => a.cos(),
            Tan => a.tan(),
            Asin => a.asin(),
            Acos => a.acos(),
            Atan => a.atan(),
            Sinh => a.sinh(),
            Cosh => a.cosh(),
            Tanh => a.tanh(),
            Abs => a.abs(),
            Sign => sign(a),
            Not => b2f(a == 0.0),
            Floor => a.floor(),
            Ceil => a.ceil(),
            Erf => libm::erf(a),
            Asinh => a.asinh(),
            Acosh => a.acosh(),
            Atanh => a.atanh(),
            Log1p => a.ln_1p(),
            Expm1 => a.exp_m1(),
            _ => unreachable!("eval1 on {self:?}"),
        }
    }

    /// Evaluates a binary operation.
    #[inline(always)]
    pub fn eval2(self, a: f64, b: f64) -> f64 {
        use Op::*;
        match self {
            Add => a + b,
            Sub => a - b,
            Mul => a * b,
            Div => a / b,
            Pow => pow(a, b),
            Atan2 => a.atan2(b),
            Min => a.min(b),
            Max => a.max(b),
            Lt => b2f(a < b),
            Le => b2f(a <= b),
            Eq => b2f(a == b),
            Ne => b2f(a != b),
            And => b2f(a != 0.0 && b != 0.0),
            Or => b2f(a != 0.0 || b != 0.0),
            StrongMul => strong_mul(a, b),
            Fmod => a % b,
            Hypot => a.hypot(b),
            _ => unreachable!("eval2 on {self:?}"),
        }
    }

    /// The function name used by `Display` and the parser, for function-call syntax.
    pub fn name(self) -> &'static str {
        use Op::*;
        match self {
            Const => "const",
            Sym => "sym",
            Neg => "neg",
            Sq => "sq",
            Sqrt => "sqrt",
            Exp => "exp",
            Log => "log",
            Sin => "sin",
            Cos => "cos",
            Tan => "tan",
            Asin => "asin",
            Acos => "acos",
            Atan => "atan",
            Sinh => "sinh",
            Cosh => "cosh",
            Tanh => "tanh",
            Abs => "abs",
            Sign => "sign",
            Not => "not",
            Add => "add",
            Sub => "sub",
            Mul => "mul",
            Div => "div",
            Pow => "pow",
            Atan2 => "atan2",
            Min => "min",
            Max => "max",
            Lt => "lt",
            Le => "le",
            Eq => "eq",
            Ne => "ne",
            And => "and",
            Or => "or",
            StrongMul => "strong_mul",
            IfElse => "if_else",
            Floor => "floor",
            Ceil => "ceil",
            Erf => "erf",
            Asinh => "asinh",
            Acosh => "acosh",
            Atanh => "atanh",
            Log1p => "log1p",
            Expm1 => "expm1",
            Fmod => "fmod",
            Hypot => "hypot",
            Interpolant | Interpolant2 | InterpolantN => "interpolant",
            Call => "call",
            CallOutput => "call_output",
        }
    }

    /// All operations with operands, for the parser's name lookup.
    /// (`Interpolant` is not listed: its table cannot be named in text.)
    pub(crate) const WITH_OPERANDS: [Op; 43] = {
        use Op::*;
        [
            Neg, Sq, Sqrt, Exp, Log, Sin, Cos, Tan, Asin, Acos, Atan, Sinh, Cosh, Tanh, Abs, Sign,
            Not, Add, Sub, Mul, Div, Pow, Atan2, Min, Max, Lt, Le, Eq, Ne, And, Or, StrongMul,
            IfElse, Floor, Ceil, Erf, Asinh, Acosh, Atanh, Log1p, Expm1, Fmod, Hypot,
        ]
    };
}

#[inline(always)]
fn b2f(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

/// `sign(x)`: −1, 0 or 1 (NaN stays NaN).
#[inline(always)]
pub fn sign(a: f64) -> f64 {
    if a > 0.0 {
        1.0
    } else if a < 0.0 {
        -1.0
    } else {
        a * 0.0
    }
}

/// `a ⊛ b` (see [`Op::StrongMul`]).
#[inline(always)]
pub fn strong_mul(a: f64, b: f64) -> f64 {
    if a == 0.0 {
        0.0
    } else {
        a * b
    }
}

/// Power with an integer fast path (exact for integer exponents, defined for negative bases).
#[inline(always)]
pub fn pow(a: f64, b: f64) -> f64 {
    if b == b.trunc() && b.abs() <= 64.0 {
        a.powi(b as i32)
    } else {
        a.powf(b)
    }
}
