//! Automatic differentiation on the expression graph, producing new expressions.
//!
//! * [`forward`]: Jacobian-vector products (tangents propagated in topological order);
//! * [`reverse`]: vector-Jacobian products (adjoints propagated in reverse order);
//! * [`gradient`], [`jacobian`] (sparse), [`hessian`] (sparse, lower triangle) and
//!   [`lagrangian_hessian`] `σ∇²f + Σλᵢ∇²gᵢ` built from them.
//!
//! Every sweep visits only the cone of the requested outputs (found with an explicit stack,
//! never by recursion) and only the nodes that depend on the differentiation variables, so
//! a Jacobian costs in proportion to the rows' cones, not to the whole graph.
//!
//! Branches: below `if_else`, `min` and `max` an adjoint can be an exact zero at run time
//! while the partial derivatives of the branch not taken are NaN or ∞ (e.g. `sqrt(x)` at
//! `x < 0`). Chain-rule products in such regions use [`Op::StrongMul`] (`0 ⊛ NaN = 0`), so
//! derivatives of `if_else` never inherit NaN from the untaken branch (CasADi #1805).
use crate::error::SymxError;
use crate::expr::{balanced, Expr};
use crate::graph::{self, Graph};
use crate::matrix::SparseMatrix;
use crate::op::Op;
use crate::simplify::{ONE, ZERO};
use crate::sparsity::pattern_from_entries;

const NONE: u32 = u32::MAX;

/// Reusable per-node scratch arrays for sweeps, validated by stamps instead of clearing.
pub(crate) struct Sweep {
    stamp: Vec<u32>,
    current: u32,
    /// Adjoint or tangent node of each visited node (`NONE` if none yet).
    value: Vec<u32>,
    /// Whether the node depends on a differentiation variable.
    dep: Vec<bool>,
    /// Whether the node depends on any differentiation variable, also those beyond the
    /// limit of a Hessian row (so that all rows choose the same callee Jacobian).
    dep_all: Vec<bool>,
    /// Whether the node's adjoint may be an exact zero chosen by a branch.
    gated: Vec<bool>,
    /// Position of each differentiation variable, for variable nodes.
    wrt_pos: Vec<u32>,
    wrt_stamp: Vec<u32>,
    wrt_current: u32,
    cone: Vec<u32>,
    stack: Vec<u32>,
    /// A single reverse sweep (not a Jacobian's row): call nodes whose callee has a
    /// reverse hook call it even with constant seeds.
    single: bool,
}

impl Sweep {
    pub fn new(n: usize) -> Sweep {
        Sweep {
            stamp: vec![0; n],
            current: 0,
            value: vec![NONE; n],
            dep: vec![false; n],
            dep_all: vec![false; n],
            gated: vec![false; n],
            wrt_pos: vec![0; n],
            wrt_stamp: vec![0; n],
            wrt_current: 0,
            cone: Vec::new(),
            stack: Vec::new(),
            single: false,
        }
    }

    /// Declares the differentiation variables (symbol nodes) for the following sweeps.
    pub fn set_wrt(&mut self, wrt: &[u32]) {
        self.wrt_current += 1;
        for (k, &w) in wrt.iter().enumerate() {
            self.wrt_stamp[w as usize] = self.wrt_current;
            self.wrt_pos[w as usize] = k as u32;
        }
    }

    /// Position of `id` among the differentiation variables, if it is one of them.
    fn wrt_position(&self, id: u32) -> Option<u32> {
        (self.wrt_stamp[id as usize] == self.wrt_current).then(|| self.wrt_pos[id as usize])
    }

    /// Collects the cone of `roots` (ascending), marking dependence on variables at
    /// positions `< wrt_limit`.
    fn collect(&mut self, g: &Graph, roots: &[u32], wrt_limit: u32) {
        self.current += 1;
        self.cone.clear();
        self.stack.clear();
        for &r in roots {
            if self.stamp[r as usize] != self.current {
                self.stamp[r as usize] = self.current;
                self.stack.push(r);
            }
        }
        while let Some(id) = self.stack.pop() {
            self.cone.push(id);
            for &a in g.operands(id) {
                if self.stamp[a as usize] != self.current {
                    self.stamp[a as usize] = self.current;
                    self.stack.push(a);
                }
            }
        }
        self.cone.sort_unstable();
        for &id in &self.cone {
            let i = id as usize;
            self.value[i] = NONE;
            self.gated[i] = false;
            (self.dep[i], self.dep_all[i]) = match self.wrt_position(id) {
                Some(p) => (p < wrt_limit, true),
                None => {
                    let ops = g.operands(id);
                    (
                        ops.iter().any(|&a| self.dep[a as usize]),
                        ops.iter().any(|&a| self.dep_all[a as usize]),
                    )
                }
            };
        }
    }
}

/// The partial derivative of node `y` with respect to its operand number `k`
/// (not for selection operations or `StrongMul`, which the sweeps treat themselves).
fn partial(g: &mut Graph, y: u32, k: usize) -> u32 {
    let n = g.node(y);
    let a = n.args[0];
    let b = n.args[1];
    match n.op {
        Op::Neg => g.constant(-1.0),
        Op::Sq => {
            let two = g.constant(2.0);
            g.binary(Op::Mul, two, a)
        }
        Op::Sqrt => {
            let half = g.constant(0.5);
            g.binary(Op::Div, half, y)
        }
        Op::Exp => y,
        Op::Log => g.binary(Op::Div, ONE, a),
        Op::Sin => g.unary(Op::Cos, a),
        Op::Cos => {
            let s = g.unary(Op::Sin, a);
            g.unary(Op::Neg, s)
        }
        Op::Tan => {
            let y2 = g.unary(Op::Sq, y);
            g.binary(Op::Add, ONE, y2)
        }
        Op::Asin | Op::Acos => {
            let a2 = g.unary(Op::Sq, a);
            let d = g.binary(Op::Sub, ONE, a2);
            let r = g.unary(Op::Sqrt, d);
            let num = if n.op == Op::Asin {
                ONE
            } else {
                g.constant(-1.0)
            };
            g.binary(Op::Div, num, r)
        }
        Op::Atan => {
            let a2 = g.unary(Op::Sq, a);
            let d = g.binary(Op::Add, ONE, a2);
            g.binary(Op::Div, ONE, d)
        }
        Op::Sinh => g.unary(Op::Cosh, a),
        Op::Cosh => g.unary(Op::Sinh, a),
        Op::Tanh => {
            let y2 = g.unary(Op::Sq, y);
            g.binary(Op::Sub, ONE, y2)
        }
        Op::Abs => g.unary(Op::Sign, a),
        Op::Erf => {
            // 2/√π · exp(−a²)
            let a2 = g.unary(Op::Sq, a);
            let m = g.unary(Op::Neg, a2);
            let e = g.unary(Op::Exp, m);
            let c = g.constant(std::f64::consts::FRAC_2_SQRT_PI);
            g.binary(Op::Mul, c, e)
        }
        Op::Asinh | Op::Acosh => {
            // 1/√(a² ± 1)
            let a2 = g.unary(Op::Sq, a);
            let r = if n.op == Op::Asinh {
                g.binary(Op::Add, a2, ONE)
            } else {
                g.binary(Op::Sub, a2, ONE)
            };
            let r = g.unary(Op::Sqrt, r);
            g.binary(Op::Div, ONE, r)
        }
        Op::Atanh => {
            let a2 = g.unary(Op::Sq, a);
            let d = g.binary(Op::Sub, ONE, a2);
            g.binary(Op::Div, ONE, d)
        }
        Op::Log1p => {
            let d = g.binary(Op::Add, ONE, a);
            g.binary(Op::Div, ONE, d)
        }
        Op::Expm1 => g.binary(Op::Add, y, ONE),
        Op::Fmod => {
            if k == 0 {
                ONE
            } else {
                // fmod(a,b) = a − trunc(a/b)·b, so ∂/∂b = −trunc(a/b) = (y − a)/b (CasADi's form).
                let r = g.binary(Op::Sub, y, a);
                g.binary(Op::Div, r, b)
            }
        }
        Op::Hypot => g.binary(Op::Div, if k == 0 { a } else { b }, y),
        Op::Interpolant => {
            let d = g.derivative_table(b, 0);
            g.interpolant(a, d)
        }
        Op::Interpolant2 => {
            let d = g.derivative_table(n.args[2], k);
            g.interpolant2(a, b, d)
        }
        Op::Add => ONE,
        Op::Sub => {
            if k == 0 {
                ONE
            } else {
                g.constant(-1.0)
            }
        }
        Op::Mul => {
            if k == 0 {
                b
            } else {
                a
            }
        }
        Op::Div => {
            if k == 0 {
                g.binary(Op::Div, ONE, b)
            } else {
                let q = g.binary(Op::Div, y, b);
                g.unary(Op::Neg, q)
            }
        }
        Op::Pow => {
            if k == 0 {
                // b · a^(b−1)
                let bm1 = g.binary(Op::Sub, b, ONE);
                let p = g.binary(Op::Pow, a, bm1);
                g.binary(Op::Mul, b, p)
            } else {
                // y · ln(a); only requested when the exponent is not constant.
                let l = g.unary(Op::Log, a);
                g.binary(Op::Mul, y, l)
            }
        }
        Op::Atan2 => {
            let a2 = g.unary(Op::Sq, a);
            let b2 = g.unary(Op::Sq, b);
            let r2 = g.binary(Op::Add, a2, b2);
            if k == 0 {
                g.binary(Op::Div, b, r2)
            } else {
                let q = g.binary(Op::Div, a, r2);
                g.unary(Op::Neg, q)
            }
        }
        op if op.has_zero_derivative() => ZERO,
        op => unreachable!("partial of {op:?}"),
    }
}

/// The condition under which selection node `y` takes its first value operand.
///
/// For `min`/`max` this is `y == a`: exactly when the evaluated value is the first operand,
/// including the cases where the other operand is NaN (`f64::min` and `f64::max` return
/// the number, so the derivative must follow the number too). On ties the first operand
/// (in the graph's canonical operand order) is taken.
fn takes_first(g: &mut Graph, y: u32) -> u32 {
    let n = g.node(y);
    match n.op {
        Op::IfElse => n.args[0],
        Op::Min | Op::Max => g.binary(Op::Eq, y, n.args[0]),
        _ => unreachable!(),
    }
}

fn accumulate(g: &mut Graph, s: &mut Sweep, child: u32, contribution: u32, gated: bool) {
    let c = child as usize;
    s.value[c] = if s.value[c] == NONE {
        contribution
    } else {
        g.binary(Op::Add, s.value[c], contribution)
    };
    s.gated[c] |= gated;
}

/// Reverse sweep over the cone collected in `s`; the caller has set the seeds in `s.value`.
fn reverse_pass(g: &mut Graph, s: &mut Sweep) {
    for idx in (0..s.cone.len()).rev() {
        let v = s.cone[idx];
        let vi = v as usize;
        if g.nodes[vi].op == Op::Call {
            if s.dep[vi] {
                reverse_call(g, s, v);
            }
            continue;
        }
        let adj = s.value[vi];
        if adj == NONE || !s.dep[vi] || adj == ZERO {
            continue;
        }
        let n = g.node(v);
        if n.op.arity() == 0 {
            continue;
        }
        let gated = s.gated[vi];
        let product = |g: &mut Graph, p: u32| {
            if gated {
                g.binary(Op::StrongMul, adj, p)
            } else {
                g.binary(Op::Mul, adj, p)
            }
        };
        match n.op {
            Op::IfElse | Op::Min | Op::Max => {
                let (first, second) = if n.op == Op::IfElse {
                    (n.args[1], n.args[2])
                } else {
                    (n.args[0], n.args[1])
                };
                let cond = takes_first(g, v);
                if s.dep[first as usize] {
                    let c = g.if_else(cond, adj, ZERO);
                    accumulate(g, s, first, c, true);
                }
                if s.dep[second as usize] {
                    let c = g.if_else(cond, ZERO, adj);
                    accumulate(g, s, second, c, true);
                }
            }
            Op::StrongMul => {
                let (a, b) = (n.args[0], n.args[1]);
                if s.dep[a as usize] {
                    let c = product(g, b);
                    accumulate(g, s, a, c, gated);
                }
                if s.dep[b as usize] {
                    let c = g.binary(Op::StrongMul, a, adj);
                    accumulate(g, s, b, c, true);
                }
            }
            // The call node gathers the adjoints of its outputs.
            Op::CallOutput => {}
            op if op.has_zero_derivative() => {}
            _ => {
                for k in 0..n.op.arity() {
                    let a = n.args[k];
                    if !s.dep[a as usize] {
                        continue;
                    }
                    let p = partial(g, v, k);
                    let c = product(g, p);
                    accumulate(g, s, a, c, gated);
                }
            }
        }
    }
}

/// The adjoint of node `o` in the current sweep, if it has a non-zero one.
fn live_adjoint(s: &Sweep, o: u32) -> Option<u32> {
    let (i, t) = (o as usize, s.value[o as usize]);
    (s.stamp[i] == s.current && s.dep[i] && t != NONE && t != ZERO).then_some(t)
}

/// Reverse sweep step at call node `v` (see `call.rs`): `x̄ⱼ += Σₖ ȳₖ Jₖⱼ`.
///
/// * Constant adjoints (a Jacobian row's seed) or adjoints below a selection: the
///   contraction is written out over the nonzeros of one call of the callee's Jacobian
///   function (with guarded products below a selection); with unit seeds it is just the
///   Jacobian's entries.
/// * Other adjoints (e.g. multipliers in a Lagrangian gradient): one call of the callee's
///   vector-Jacobian product, so that differentiating again (a Hessian) needs only that
///   function's Jacobian, not the callee's whole second-derivative tensor. So do constant
///   adjoints in a single reverse sweep (a gradient) when the callee has a reverse hook
///   (`Function::with_vjp`), cheaper than its Jacobian.
fn reverse_call(g: &mut Graph, s: &mut Sweep, v: u32) {
    let site = &g.calls[g.nodes[v as usize].args[0] as usize];
    let (function, inputs) = (site.function.clone(), site.inputs.clone());
    let adj: Vec<Option<u32>> = site.outputs.iter().map(|&o| live_adjoint(s, o)).collect();
    if adj.iter().all(Option::is_none) {
        return;
    }
    let gated = site
        .outputs
        .iter()
        .any(|&o| s.stamp[o as usize] == s.current && s.gated[o as usize]);
    let constant = adj.iter().flatten().all(|&t| g.value(t).is_some());
    let wrt: Vec<bool> = inputs.iter().map(|&a| s.dep_all[a as usize]).collect();
    let jac = crate::call::call_jacobian(g, &function, &wrt);
    if !gated && (!constant || (s.single && jac.hook)) {
        let mut args = inputs.clone();
        args.extend(adj.iter().map(|t| t.unwrap_or(ZERO)));
        let xbar = g.call(&jac.vjp, args);
        for (j, &a) in inputs.iter().enumerate() {
            let reached = jac.by_input[j]
                .iter()
                .any(|&(k, _)| adj[k as usize].is_some());
            if s.dep[a as usize] && reached {
                accumulate(g, s, a, xbar[j], false);
            }
        }
        return;
    }
    let jout = g.call(&jac.function, inputs.clone());
    let mul = if gated { Op::StrongMul } else { Op::Mul };
    for (j, &a) in inputs.iter().enumerate() {
        if !s.dep[a as usize] {
            continue;
        }
        let terms: Vec<u32> = jac.by_input[j]
            .iter()
            .filter_map(|&(k, nz)| adj[k as usize].map(|t| g.binary(mul, t, jout[nz as usize])))
            .collect();
        if !terms.is_empty() {
            let c = balanced(g, Op::Add, terms, ZERO);
            accumulate(g, s, a, c, gated);
        }
    }
}

/// Forward sweep step at call node `v`: `ẏₖ = Σⱼ Jₖⱼ ẋⱼ`, written to the output nodes.
fn forward_call(g: &mut Graph, s: &mut Sweep, v: u32) {
    let site = &g.calls[g.nodes[v as usize].args[0] as usize];
    let (function, inputs, outputs) = (
        site.function.clone(),
        site.inputs.clone(),
        site.outputs.clone(),
    );
    let tangents: Vec<u32> = inputs
        .iter()
        .map(|&a| {
            let t = s.value[a as usize];
            if s.dep[a as usize] && t != NONE {
                t
            } else {
                ZERO
            }
        })
        .collect();
    if tangents.iter().all(|&t| t == ZERO) {
        return;
    }
    let wrt: Vec<bool> = tangents.iter().map(|&t| t != ZERO).collect();
    let jac = crate::call::call_jacobian(g, &function, &wrt);
    let jout = g.call(&jac.function, inputs);
    for (k, &o) in outputs.iter().enumerate() {
        if s.stamp[o as usize] != s.current {
            continue;
        }
        let terms: Vec<u32> = jac.by_output[k]
            .iter()
            .filter(|&&(j, _)| tangents[j as usize] != ZERO)
            .map(|&(j, nz)| g.binary(Op::Mul, jout[nz as usize], tangents[j as usize]))
            .collect();
        s.value[o as usize] = balanced(g, Op::Add, terms, ZERO);
    }
}

/// Forward sweep over the cone collected in `s`; the caller has set the variables' tangents.
fn forward_pass(g: &mut Graph, s: &mut Sweep) {
    for idx in 0..s.cone.len() {
        let v = s.cone[idx];
        let vi = v as usize;
        if !s.dep[vi] || s.value[vi] != NONE {
            continue;
        }
        let n = g.node(v);
        let tangent = |s: &Sweep, a: u32| {
            let t = s.value[a as usize];
            if s.dep[a as usize] && t != NONE {
                t
            } else {
                ZERO
            }
        };
        s.value[vi] = match n.op {
            Op::Sym | Op::Const => ZERO,
            Op::Call => {
                forward_call(g, s, v);
                ZERO
            }
            // (Set by its call when it has a tangent.)
            Op::CallOutput => ZERO,
            Op::IfElse | Op::Min | Op::Max => {
                let (first, second) = if n.op == Op::IfElse {
                    (n.args[1], n.args[2])
                } else {
                    (n.args[0], n.args[1])
                };
                let (t1, t2) = (tangent(s, first), tangent(s, second));
                let cond = takes_first(g, v);
                g.if_else(cond, t1, t2)
            }
            Op::StrongMul => {
                let (a, b) = (n.args[0], n.args[1]);
                let (ta, tb) = (tangent(s, a), tangent(s, b));
                let l = g.binary(Op::StrongMul, ta, b);
                let r = g.binary(Op::StrongMul, a, tb);
                g.binary(Op::Add, l, r)
            }
            op if op.has_zero_derivative() => ZERO,
            _ => {
                let mut terms = Vec::with_capacity(2);
                for k in 0..n.op.arity() {
                    let a = n.args[k];
                    let t = tangent(s, a);
                    if t == ZERO {
                        continue;
                    }
                    let p = partial(g, v, k);
                    terms.push(g.binary(Op::Mul, p, t));
                }
                balanced(g, Op::Add, terms, ZERO)
            }
        };
    }
}

/// Checks that `exprs` are distinct symbols; returns their node indices.
pub(crate) fn symbol_ids(exprs: &[Expr], what: &str) -> Result<Vec<u32>, SymxError> {
    graph::with(|g| {
        let mut seen = rustc_hash::FxHashSet::default();
        exprs
            .iter()
            .enumerate()
            .map(|(index, e)| {
                if g.node(e.id).op != Op::Sym {
                    return Err(SymxError::NotASymbol {
                        what: what.to_string(),
                        index,
                    });
                }
                if !seen.insert(e.id) {
                    return Err(SymxError::DuplicateSymbol {
                        what: what.to_string(),
                        name: g.symbol_name(e.id).to_string(),
                    });
                }
                Ok(e.id)
            })
            .collect()
    })
}

fn check_len(what: &'static str, expected: usize, got: usize) -> Result<(), SymxError> {
    if expected == got {
        Ok(())
    } else {
        Err(SymxError::ArgumentCount {
            what,
            expected,
            got,
        })
    }
}

fn ids(exprs: &[Expr]) -> Vec<u32> {
    exprs.iter().map(|e| e.id).collect()
}

/// Jacobian-vector product: `Σⱼ ∂outputᵢ/∂inputⱼ · seedⱼ` for each output.
///
/// `inputs` must be distinct symbols; `seeds` has one expression per input.
pub fn forward(outputs: &[Expr], inputs: &[Expr], seeds: &[Expr]) -> Result<Vec<Expr>, SymxError> {
    let wrt = symbol_ids(inputs, "forward: inputs")?;
    check_len("seeds (one per input)", inputs.len(), seeds.len())?;
    let out = ids(outputs);
    checked(|g| {
        let mut s = Sweep::new(g.len());
        s.set_wrt(&wrt);
        s.collect(g, &out, u32::MAX);
        for (&w, seed) in wrt.iter().zip(seeds) {
            if s.stamp[w as usize] == s.current {
                s.value[w as usize] = seed.id;
            }
        }
        forward_pass(g, &mut s);
        out.iter()
            .map(|&o| {
                let t = s.value[o as usize];
                Expr::from_id(if s.dep[o as usize] && t != NONE {
                    t
                } else {
                    ZERO
                })
            })
            .collect()
    })
}

/// Vector-Jacobian product: `Σᵢ seedᵢ · ∂outputᵢ/∂inputⱼ` for each input.
///
/// `inputs` must be distinct symbols; `seeds` has one expression per output.
pub fn reverse(outputs: &[Expr], inputs: &[Expr], seeds: &[Expr]) -> Result<Vec<Expr>, SymxError> {
    let wrt = symbol_ids(inputs, "reverse: inputs")?;
    check_len("seeds (one per output)", outputs.len(), seeds.len())?;
    let out = ids(outputs);
    checked(|g| {
        let mut s = Sweep::new(g.len());
        s.single = true;
        s.set_wrt(&wrt);
        s.collect(g, &out, u32::MAX);
        for (&o, seed) in out.iter().zip(seeds) {
            if s.dep[o as usize] {
                accumulate(g, &mut s, o, seed.id, false);
            }
        }
        reverse_pass(g, &mut s);
        wrt.iter().map(|&w| Expr::from_id(adjoint(&s, w))).collect()
    })
}

/// Runs a derivative sweep on this thread's graph; `Err` if it met an external function
/// without a Jacobian (the expressions it built for it are then not used).
fn checked<R>(sweep: impl FnOnce(&mut Graph) -> R) -> Result<R, SymxError> {
    graph::with(|g| {
        g.derivative_error = None;
        let r = sweep(g);
        match g.derivative_error.take() {
            Some(e) => Err(e),
            None => Ok(r),
        }
    })
}

/// `Σᵢ seedᵢ ∂outputᵢ/∂inputⱼ` for symbol nodes `inputs`, with every product guarded
/// (`0 ⊛ NaN = 0`): the body of a callee's vector-Jacobian-product function, whose seeds
/// are exactly 0 for outputs the caller does not use.
pub(crate) fn guarded_vjp(
    g: &mut Graph,
    outputs: &[u32],
    inputs: &[u32],
    seeds: &[u32],
) -> Vec<u32> {
    let mut s = Sweep::new(g.len());
    s.set_wrt(inputs);
    s.collect(g, outputs, u32::MAX);
    for (&o, &seed) in outputs.iter().zip(seeds) {
        if s.dep[o as usize] {
            accumulate(g, &mut s, o, seed, true);
        }
    }
    reverse_pass(g, &mut s);
    inputs.iter().map(|&w| adjoint(&s, w)).collect()
}

fn adjoint(s: &Sweep, w: u32) -> u32 {
    if s.stamp[w as usize] == s.current && s.value[w as usize] != NONE {
        s.value[w as usize]
    } else {
        ZERO
    }
}

/// Gradient of a scalar with respect to symbols (one reverse sweep).
///
/// ```
/// use symx::{Expr, gradient};
/// let x = Expr::sym("x");
/// let y = Expr::sym("y");
/// let g = gradient(x * y + x.sin(), &[x, y]).unwrap();
/// assert_eq!(g[1].to_string(), "x");
/// ```
pub fn gradient(f: Expr, inputs: &[Expr]) -> Result<Vec<Expr>, SymxError> {
    reverse(&[f], inputs, &[Expr::one()])
}

/// Rows of a Jacobian as `(column, expression)` lists, one reverse sweep per output over its
/// own cone; with `lower_only`, row `i` keeps only columns `≤ i` (for Hessians).
pub(crate) fn jacobian_rows(
    g: &mut Graph,
    out: &[u32],
    wrt: &[u32],
    lower_only: bool,
) -> Vec<(usize, usize, u32)> {
    let mut s = Sweep::new(g.len());
    s.set_wrt(wrt);
    let mut entries = Vec::new();
    for (i, &o) in out.iter().enumerate() {
        let limit = if lower_only { i as u32 + 1 } else { u32::MAX };
        s.collect(g, &[o], limit);
        if !s.dep[o as usize] {
            continue;
        }
        s.value[o as usize] = ONE;
        reverse_pass(g, &mut s);
        // Variables in this row's cone, in column order.
        let mut row: Vec<(usize, u32)> = s
            .cone
            .iter()
            .filter_map(|&id| {
                let p = s.wrt_position(id)?;
                (p < limit).then(|| (p as usize, s.value[id as usize]))
            })
            .filter(|&(_, d)| d != NONE && d != ZERO)
            .collect();
        row.sort_unstable_by_key(|&(j, _)| j);
        entries.extend(row.into_iter().map(|(j, d)| (i, j, d)));
    }
    entries
}

fn sparse_from_entries(
    nrows: usize,
    ncols: usize,
    mut entries: Vec<(usize, usize, u32)>,
) -> SparseMatrix {
    entries.sort_unstable_by_key(|&(i, j, _)| (j, i));
    let pattern = pattern_from_entries(nrows, ncols, entries.iter().map(|&(i, j, _)| (i, j)));
    let values = entries
        .into_iter()
        .map(|(_, _, e)| Expr::from_id(e))
        .collect();
    SparseMatrix::new(pattern, values).expect("pattern and values built together")
}

/// The sparse Jacobian `∂outputs/∂inputs` (`outputs.len() × inputs.len()`).
///
/// Structural zeros are not stored: the pattern holds exactly the entries whose derivative
/// is not identically zero.
pub fn jacobian(outputs: &[Expr], inputs: &[Expr]) -> Result<SparseMatrix, SymxError> {
    let wrt = symbol_ids(inputs, "jacobian: inputs")?;
    let out = ids(outputs);
    let entries = checked(|g| jacobian_rows(g, &out, &wrt, false))?;
    Ok(sparse_from_entries(outputs.len(), inputs.len(), entries))
}

/// The Hessian of a scalar, as its lower triangle (`row ≥ column`) in a sparse matrix.
pub fn hessian(f: Expr, inputs: &[Expr]) -> Result<SparseMatrix, SymxError> {
    let grad = gradient(f, inputs)?;
    let wrt = symbol_ids(inputs, "hessian: inputs")?;
    let out = ids(&grad);
    let entries = checked(|g| jacobian_rows(g, &out, &wrt, true))?;
    Ok(sparse_from_entries(inputs.len(), inputs.len(), entries))
}

/// The lower triangle of the Lagrangian Hessian `σ∇²f + Σᵢ λᵢ∇²gᵢ`.
///
/// `sigma` and `lambda` are usually symbols, so that the result can be compiled into one
/// function of `(x, σ, λ)`.
pub fn lagrangian_hessian(
    f: Expr,
    g: &[Expr],
    inputs: &[Expr],
    sigma: Expr,
    lambda: &[Expr],
) -> Result<SparseMatrix, SymxError> {
    check_len("multipliers (one per constraint)", g.len(), lambda.len())?;
    let lagrangian = std::iter::once(sigma * f)
        .chain(g.iter().zip(lambda).map(|(&gi, &li)| li * gi))
        .sum();
    hessian(lagrangian, inputs)
}
