//! Random expression trees for the symx property tests (shared by symx/tests/ad.rs,
//! symx/tests/sparsity.rs and symx/tests/symx_expr.rs).
//!
//! A [`Tree`] is built both as a symx expression ([`Tree::build`]) and evaluated by an
//! independent plain-`f64` interpreter ([`Tree::eval`]) that also reports how close the
//! point is to a kink or jump (`abs`, `sign`, `min`/`max` ties, comparisons of `if_else`,
//! the branch cut of `atan2`): finite differences are only meaningful away from those.
//!
//! Every operation of symx appears. Functions with a restricted domain are applied to
//! arguments that are always inside it (`sqrt(1+a²)`, `log(1+a²)`, `asin(0.9·tanh a)`,
//! `tan(sin a)`, `a/(½+b²)`, `(½+a²)^sin b`), except in the `if_else` guards that are the
//! point of CasADi #1805 (`if_else(a>0, sqrt a, −a)`, `if_else(a>0, log a, a)`), whose
//! untaken branch is NaN on purpose.
#![allow(dead_code)]

use proptest::prelude::*;
use symx::Expr;

#[derive(Clone, Copy, Debug)]
pub enum Un {
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
    Cube,
    InvSq,
    SqrtIf,
    LogIf,
}

#[derive(Clone, Copy, Debug)]
pub enum Bin {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Atan2,
    Min,
    Max,
}

#[derive(Clone, Copy, Debug)]
pub enum Cmp {
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
}

#[derive(Clone, Debug)]
pub enum Cond {
    Cmp(Cmp, Box<Tree>, Box<Tree>),
    Not(Box<Cond>),
    And(Box<Cond>, Box<Cond>),
    Or(Box<Cond>, Box<Cond>),
}

#[derive(Clone, Debug)]
pub enum Tree {
    Var(usize),
    Const(f64),
    Un(Un, Box<Tree>),
    Bin(Bin, Box<Tree>, Box<Tree>),
    If(Box<Cond>, Box<Tree>, Box<Tree>),
}

const UN: [Un; 20] = [
    Un::Neg,
    Un::Sq,
    Un::Sqrt,
    Un::Exp,
    Un::Log,
    Un::Sin,
    Un::Cos,
    Un::Tan,
    Un::Asin,
    Un::Acos,
    Un::Atan,
    Un::Sinh,
    Un::Cosh,
    Un::Tanh,
    Un::Abs,
    Un::Sign,
    Un::Cube,
    Un::InvSq,
    Un::SqrtIf,
    Un::LogIf,
];
const BIN: [Bin; 8] = [
    Bin::Add,
    Bin::Sub,
    Bin::Mul,
    Bin::Div,
    Bin::Pow,
    Bin::Atan2,
    Bin::Min,
    Bin::Max,
];
const CMP: [Cmp; 6] = [Cmp::Lt, Cmp::Le, Cmp::Gt, Cmp::Ge, Cmp::Eq, Cmp::Ne];

/// Trees over `nvars` variables with at most `depth` levels.
pub fn tree(nvars: usize, depth: u32) -> impl Strategy<Value = Tree> {
    let leaf = prop_oneof![
        3 => (0..nvars).prop_map(Tree::Var),
        1 => prop_oneof![Just(0.0), Just(1.0), Just(-1.0), Just(2.0), -2.0..2.0f64].prop_map(Tree::Const),
    ];
    leaf.prop_recursive(depth, 24, 3, move |inner| {
        let cond = {
            let cmp = (prop::sample::select(&CMP[..]), inner.clone(), inner.clone())
                .prop_map(|(c, a, b)| Cond::Cmp(c, Box::new(a), Box::new(b)));
            prop_oneof![
                4 => cmp.clone(),
                1 => cmp.clone().prop_map(|c| Cond::Not(Box::new(c))),
                1 => (cmp.clone(), cmp.clone()).prop_map(|(a, b)| Cond::And(Box::new(a), Box::new(b))),
                1 => (cmp.clone(), cmp).prop_map(|(a, b)| Cond::Or(Box::new(a), Box::new(b))),
            ]
        };
        prop_oneof![
            4 => (prop::sample::select(&UN[..]), inner.clone())
                .prop_map(|(op, a)| Tree::Un(op, Box::new(a))),
            4 => (prop::sample::select(&BIN[..]), inner.clone(), inner.clone())
                .prop_map(|(op, a, b)| Tree::Bin(op, Box::new(a), Box::new(b))),
            1 => (cond, inner.clone(), inner)
                .prop_map(|(c, a, b)| Tree::If(Box::new(c), Box::new(a), Box::new(b))),
        ]
    })
}

/// Points with coordinates in `[-2, 2]`.
pub fn points(nvars: usize, count: usize) -> impl Strategy<Value = Vec<Vec<f64>>> {
    prop::collection::vec(prop::collection::vec(-2.0..2.0f64, nvars), count)
}

/// The switching quantities met while evaluating a tree: their smallest distance from a
/// switching point and their signs (two points with equal signs lie in the same smooth piece).
#[derive(Debug, Clone, PartialEq)]
pub struct Probe {
    pub kink: f64,
    pub signs: Vec<bool>,
}

impl Default for Probe {
    fn default() -> Probe {
        Probe {
            kink: f64::INFINITY,
            signs: Vec::new(),
        }
    }
}

impl Probe {
    fn note(&mut self, d: f64) {
        self.kink = self.kink.min(d.abs());
        self.signs.push(d > 0.0);
    }

    /// Like [`Probe::note`] for a switch at a singularity of the taken branch (`ln`, `sqrt`
    /// at 0): a point is tested only at distance [`SINGULAR`] or more. Central differences
    /// of ln at distance d err by about h²/(3d²) relative to the derivative 1/d: 3·10⁻⁵ at
    /// d = 1.1·10⁻³ (above [`KINK`]; a proptest case failed there), 4·10⁻⁸ at d = 3·10⁻².
    fn note_singular(&mut self, d: f64) {
        self.kink = self.kink.min(d.abs() * (KINK / SINGULAR));
        self.signs.push(d > 0.0);
    }
}

impl Tree {
    /// The symx expression.
    pub fn build(&self, x: &[Expr]) -> Expr {
        match self {
            Tree::Var(k) => x[*k],
            Tree::Const(c) => Expr::constant(*c),
            Tree::Un(op, a) => {
                let a = a.build(x);
                match op {
                    Un::Neg => -a,
                    Un::Sq => a.sq(),
                    Un::Sqrt => (1.0 + a.sq()).sqrt(),
                    Un::Exp => a.exp(),
                    Un::Log => (1.0 + a.sq()).ln(),
                    Un::Sin => a.sin(),
                    Un::Cos => a.cos(),
                    Un::Tan => a.sin().tan(),
                    Un::Asin => (0.9 * a.tanh()).asin(),
                    Un::Acos => (0.9 * a.tanh()).acos(),
                    Un::Atan => a.atan(),
                    Un::Sinh => a.sinh(),
                    Un::Cosh => a.cosh(),
                    Un::Tanh => a.tanh(),
                    Un::Abs => a.abs(),
                    Un::Sign => a.sign(),
                    Un::Cube => a.powi(3),
                    Un::InvSq => (1.0 + a.sq()).powi(-2),
                    Un::SqrtIf => symx::if_else(symx::gt(a, 0.0), a.sqrt(), -a),
                    Un::LogIf => symx::if_else(symx::gt(a, 0.0), a.ln(), a),
                }
            }
            Tree::Bin(op, a, b) => {
                let (a, b) = (a.build(x), b.build(x));
                match op {
                    Bin::Add => a + b,
                    Bin::Sub => a - b,
                    Bin::Mul => a * b,
                    Bin::Div => a / (0.5 + b.sq()),
                    Bin::Pow => (0.5 + a.sq()).pow(b.sin()),
                    Bin::Atan2 => a.atan2(b),
                    Bin::Min => a.min(b),
                    Bin::Max => a.max(b),
                }
            }
            Tree::If(c, a, b) => symx::if_else(c.build(x), a.build(x), b.build(x)),
        }
    }

    /// The value at `x`; `probe` records every switching quantity.
    pub fn eval(&self, x: &[f64], probe: &mut Probe) -> f64 {
        match self {
            Tree::Var(k) => x[*k],
            Tree::Const(c) => *c,
            Tree::Un(op, a) => {
                let a = a.eval(x, probe);
                match op {
                    Un::Neg => -a,
                    Un::Sq => a * a,
                    Un::Sqrt => (1.0 + a * a).sqrt(),
                    Un::Exp => a.exp(),
                    Un::Log => (1.0 + a * a).ln(),
                    Un::Sin => a.sin(),
                    Un::Cos => a.cos(),
                    Un::Tan => a.sin().tan(),
                    Un::Asin => (0.9 * a.tanh()).asin(),
                    Un::Acos => (0.9 * a.tanh()).acos(),
                    Un::Atan => a.atan(),
                    Un::Sinh => a.sinh(),
                    Un::Cosh => a.cosh(),
                    Un::Tanh => a.tanh(),
                    Un::Abs => {
                        probe.note(a);
                        a.abs()
                    }
                    Un::Sign => {
                        probe.note(a);
                        if a > 0.0 {
                            1.0
                        } else if a < 0.0 {
                            -1.0
                        } else {
                            0.0
                        }
                    }
                    Un::Cube => a * a * a,
                    Un::InvSq => (1.0 + a * a).powi(-2),
                    Un::SqrtIf => {
                        probe.note_singular(a);
                        if a > 0.0 {
                            a.sqrt()
                        } else {
                            -a
                        }
                    }
                    Un::LogIf => {
                        probe.note_singular(a);
                        if a > 0.0 {
                            a.ln()
                        } else {
                            a
                        }
                    }
                }
            }
            Tree::Bin(op, a, b) => {
                let (a, b) = (a.eval(x, probe), b.eval(x, probe));
                match op {
                    Bin::Add => a + b,
                    Bin::Sub => a - b,
                    Bin::Mul => a * b,
                    Bin::Div => a / (0.5 + b * b),
                    Bin::Pow => (0.5 + a * a).powf(b.sin()),
                    Bin::Atan2 => {
                        probe.note(a.hypot(b));
                        probe.note(if b < 0.0 { a } else { 1.0 });
                        a.atan2(b)
                    }
                    Bin::Min => {
                        probe.note(a - b);
                        a.min(b)
                    }
                    Bin::Max => {
                        probe.note(a - b);
                        a.max(b)
                    }
                }
            }
            Tree::If(c, a, b) => {
                let c = c.eval(x, probe);
                let (a, b) = (a.eval(x, probe), b.eval(x, probe));
                if c {
                    a
                } else {
                    b
                }
            }
        }
    }
}

impl Cond {
    pub fn build(&self, x: &[Expr]) -> Expr {
        match self {
            Cond::Cmp(c, a, b) => {
                let (a, b) = (a.build(x), b.build(x));
                match c {
                    Cmp::Lt => symx::lt(a, b),
                    Cmp::Le => symx::le(a, b),
                    Cmp::Gt => symx::gt(a, b),
                    Cmp::Ge => symx::ge(a, b),
                    Cmp::Eq => symx::eq(a, b),
                    Cmp::Ne => symx::ne(a, b),
                }
            }
            Cond::Not(c) => symx::not(c.build(x)),
            Cond::And(a, b) => symx::and(a.build(x), b.build(x)),
            Cond::Or(a, b) => symx::or(a.build(x), b.build(x)),
        }
    }

    pub fn eval(&self, x: &[f64], probe: &mut Probe) -> bool {
        match self {
            Cond::Cmp(c, a, b) => {
                let (a, b) = (a.eval(x, probe), b.eval(x, probe));
                probe.note(a - b);
                match c {
                    Cmp::Lt => a < b,
                    Cmp::Le => a <= b,
                    Cmp::Gt => a > b,
                    Cmp::Ge => a >= b,
                    Cmp::Eq => a == b,
                    Cmp::Ne => a != b,
                }
            }
            Cond::Not(c) => !c.eval(x, probe),
            Cond::And(a, b) => {
                let (a, b) = (a.eval(x, probe), b.eval(x, probe));
                a && b
            }
            Cond::Or(a, b) => {
                let (a, b) = (a.eval(x, probe), b.eval(x, probe));
                a || b
            }
        }
    }
}

/// Central finite difference of `f` along coordinate `j` at `x`, step `h·max(1, |x_j|)`.
pub fn central_difference(
    f: &mut impl FnMut(&[f64]) -> Vec<f64>,
    x: &[f64],
    j: usize,
    h: f64,
) -> Vec<f64> {
    let step = h * x[j].abs().max(1.0);
    let mut xp = x.to_vec();
    let mut xm = x.to_vec();
    xp[j] += step;
    xm[j] -= step;
    let (fp, fm) = (f(&xp), f(&xm));
    fp.iter()
        .zip(&fm)
        .map(|(a, b)| (a - b) / (2.0 * step))
        .collect()
}

/// `|a − b| ≤ tol · max(1, |a|, |b|)`.
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1.0)
}

/// Smallest distance of a switching quantity from its switching point at which a point is
/// tested (much larger than the finite-difference steps).
pub const KINK: f64 = 1e-3;

/// Smallest distance from a singular switching point (see `Probe::note_singular`).
pub const SINGULAR: f64 = 3e-2;

/// The reference values of `trees` at `x` if `x` is a good test point: values finite and
/// below 10⁶, no switching quantity within [`KINK`], and every point of the central
/// differences (step `h·max(1,|x_j|)` along each axis) in the same smooth piece.
pub fn smooth_values(trees: &[&Tree], x: &[f64], h: f64) -> Option<Vec<f64>> {
    let probe_all = |p: &[f64]| {
        let mut probe = Probe::default();
        let v: Vec<f64> = trees.iter().map(|t| t.eval(p, &mut probe)).collect();
        (v, probe)
    };
    let (values, probe) = probe_all(x);
    if probe.kink <= KINK || values.iter().any(|v| !v.is_finite() || v.abs() > 1e6) {
        return None;
    }
    for j in 0..x.len() {
        for s in [-1.0, 1.0] {
            let mut p = x.to_vec();
            p[j] += s * h * x[j].abs().max(1.0);
            let (v, q) = probe_all(&p);
            if q.signs != probe.signs || v.iter().any(|v| !v.is_finite()) {
                return None;
            }
        }
    }
    Some(values)
}
