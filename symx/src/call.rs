//! Calls of compiled [`Function`]s inside an expression graph, without inlining.
//!
//! [`Function::apply`] adds one `Call` node (its operands: the argument entries) and one
//! `CallOutput` node per output entry. Identical calls (same function, same argument
//! nodes) are one call, as every node is hash-consed. The callee is shared by reference,
//! so an optimal-control problem of N stages holds its dynamics once.
//!
//! Derivatives go through two derived functions of the callee, built once from its tape
//! for each set of differentiated argument entries and kept in it (shared by clones):
//! * its **Jacobian function** (CasADi's `jac_f`): the callee's inputs, one output holding
//!   the structural nonzeros of `∂(outputs)/∂(inputs)`. A forward sweep reaching a call
//!   computes `ẏₖ = Σⱼ Jₖⱼ ẋⱼ`; a reverse sweep whose adjoints are constants (a Jacobian
//!   row's seed) or lie below a selection computes `x̄ⱼ = Σₖ ȳₖ Jₖⱼ` (guarded products
//!   below a selection), over the nonzeros only, from one call of the Jacobian function on
//!   the same arguments (shared by all sweeps, so a Jacobian evaluates it once per call
//!   site, and with unit seeds its entries are the Jacobian's entries);
//! * its **vector-Jacobian product** `x̄ = Jᵀȳ` (one reverse sweep of the callee with
//!   symbolic seeds, every product guarded so an exactly-zero adjoint never meets a NaN
//!   partial): used by reverse sweeps with other adjoints, e.g. the multipliers of a
//!   Lagrangian gradient. Differentiating that gradient again (a Hessian) then needs only
//!   the Jacobian of the vector-Jacobian product — the multiplier-weighted second
//!   derivatives, reverse over reverse — not the callee's whole second-derivative tensor.
//!
//! Both are `Function`s called through call nodes, so derivatives of any order work the
//! same way. Sparsity stays exact (the Jacobian function has the structural pattern; a
//! vector-Jacobian product is used only for the arguments its active outputs reach), and
//! the `if_else` rule holds inside the callee (its derivative functions are built by the
//! same sweeps) and around the call.
use crate::error::SymxError;
use crate::expr::Expr;
use crate::function::Function;
use crate::graph::{self, Graph, Node};
use crate::op::Op;
use std::sync::Arc;

/// Jacobian functions of one callee, by the input entries differentiated.
pub(crate) type JacobianCache = rustc_hash::FxHashMap<Vec<bool>, Arc<CallJacobian>>;

/// One call in the graph.
pub(crate) struct CallSite {
    pub function: Arc<Function>,
    /// Argument entries (inputs stacked).
    pub inputs: Vec<u32>,
    /// The `CallOutput` node of each output entry (outputs stacked).
    pub outputs: Vec<u32>,
}

/// One call on a tape: registers of the arguments, first register of the outputs.
#[derive(Clone, Debug)]
pub(crate) struct CallInstr {
    pub function: Arc<Function>,
    pub args: Vec<u32>,
    pub out: u32,
}

/// The Jacobian function of a callee, its pattern, and its vector-Jacobian product.
#[derive(Debug)]
pub(crate) struct CallJacobian {
    /// Same inputs as the callee; one output: the nonzeros, row by row.
    pub function: Arc<Function>,
    /// `x̄ = Jᵀȳ`: the callee's inputs plus one input `ȳ` (one entry per output entry);
    /// one output `x̄` (one entry per input entry), built by one reverse sweep whose
    /// products are all guarded (`0 ⊛ NaN = 0`), so an adjoint that is exactly 0 never
    /// meets a NaN partial derivative.
    pub vjp: Arc<Function>,
    /// Whether `vjp` is the callee's own reverse hook ([`Function::with_vjp`]), cheaper
    /// than the Jacobian: a single reverse sweep then calls it even with constant seeds.
    pub hook: bool,
    /// For each input entry `j`: `(output entry k, nonzero index)` of column `j`.
    pub by_input: Vec<Vec<(u32, u32)>>,
    /// For each output entry `k`: `(input entry j, nonzero index)` of row `k`.
    pub by_output: Vec<Vec<(u32, u32)>>,
}

impl Graph {
    /// The graph's shared copy of `f` (one per function identity).
    pub fn function_arc(&mut self, f: &Function) -> Arc<Function> {
        self.functions
            .entry(f.uid)
            .or_insert_with(|| Arc::new(f.clone()))
            .clone()
    }

    /// The output nodes of the call `f(inputs)` (inputs stacked), creating it if new.
    pub fn call(&mut self, f: &Arc<Function>, inputs: Vec<u32>) -> Vec<u32> {
        let key = (f.uid, inputs);
        if let Some(&c) = self.call_index.get(&key) {
            return self.calls[c as usize].outputs.clone();
        }
        let c = self.calls.len() as u32;
        self.calls.push(CallSite {
            function: f.clone(),
            inputs: key.1.clone(),
            outputs: Vec::new(),
        });
        let node = self.intern(Node {
            op: Op::Call,
            args: [c, 0, 0],
        });
        let n_out: usize = f.output_sizes.iter().sum();
        let outputs: Vec<u32> = (0..n_out as u32)
            .map(|k| {
                self.intern(Node {
                    op: Op::CallOutput,
                    args: [node, k, 0],
                })
            })
            .collect();
        self.calls[c as usize].outputs = outputs.clone();
        self.call_index.insert(key, c);
        outputs
    }
}

impl Function {
    /// Calls this function on expressions, without inlining it: one call node in the
    /// graph, evaluated by running this function's tape (see the module notes on
    /// derivatives). `args[k]` has length `input_sizes()[k]`; the result has one vector per
    /// output.
    ///
    /// ```
    /// use symx::{gradient, Function, Matrix};
    /// let x = Matrix::sym_vec("x", 2);
    /// let f = Function::named("f", &[("x", &x)], &[("y", &[x[0] * x[1].sin()])]).unwrap();
    /// let z = Matrix::sym_vec("z", 2);
    /// let y = f.apply(&[&[z[1], z[0] * 2.0]]).unwrap()[0][0];   // z₁·sin(2z₀)
    /// let g = gradient(y, &z).unwrap();
    /// let h = Function::new(&[&z], &[&[y], &g]).unwrap();
    /// let out = h.call(&[&[0.3, 1.5]]).unwrap();
    /// assert!((out[0][0] - 1.5 * 0.6f64.sin()).abs() < 1e-15);
    /// assert!((out[1][0] - 3.0 * 0.6f64.cos()).abs() < 1e-15 && (out[1][1] - 0.6f64.sin()).abs() < 1e-15);
    /// ```
    pub fn apply(&self, args: &[&[Expr]]) -> Result<Vec<Vec<Expr>>, SymxError> {
        self.check_args(args)?;
        let flat: Vec<u32> = args.iter().flat_map(|a| a.iter().map(|e| e.id)).collect();
        let outs = graph::with(|g| {
            let f = g.function_arc(self);
            g.call(&f, flat)
        });
        Ok(self.split_outputs(outs))
    }

    /// As many arguments as inputs, each of the input's length.
    fn check_args(&self, args: &[&[Expr]]) -> Result<(), SymxError> {
        if args.len() != self.input_sizes.len() {
            return Err(SymxError::ArgumentCount {
                what: "arguments",
                expected: self.input_sizes.len(),
                got: args.len(),
            });
        }
        for (index, (a, &n)) in args.iter().zip(&self.input_sizes).enumerate() {
            if a.len() != n {
                return Err(SymxError::Length {
                    what: "argument",
                    index,
                    expected: n,
                    got: a.len(),
                });
            }
        }
        Ok(())
    }

    /// The function's computation written out on `args` as expressions — the operations
    /// of its tape, in order, with no call node (the calls it makes stay calls) — where
    /// [`Function::apply`] adds one call node. Errors as [`Function::apply`], and for an
    /// external function or a lookup table, which have no expressions
    /// ([`SymxError::NoDerivative`], naming the function).
    ///
    /// ```
    /// use symx::{Function, Matrix};
    /// let x = Matrix::sym_vec("x", 2);
    /// let f = Function::new(&[&x], &[&[x[0] * x[1].sin()]]).unwrap();
    /// let z = Matrix::sym_vec("z", 2);
    /// let y = f.inline(&[&[z[1], z[0]]]).unwrap()[0][0];
    /// assert_eq!(y.to_string(), "(z[1]*sin(z[0]))");
    /// ```
    pub fn inline(&self, args: &[&[Expr]]) -> Result<Vec<Vec<Expr>>, SymxError> {
        self.check_args(args)?;
        if self.external.is_some() || self.lookup_table().is_some() {
            return Err(SymxError::NoDerivative {
                name: self.name.clone(),
            });
        }
        let flat: Vec<u32> = args.iter().flat_map(|a| a.iter().map(|e| e.id)).collect();
        let outs = graph::with(|g| instantiate_on(g, self, flat));
        Ok(self.split_outputs(outs))
    }

    fn split_outputs(&self, outs: Vec<u32>) -> Vec<Vec<Expr>> {
        let mut it = outs.into_iter().map(Expr::from_id);
        self.output_sizes
            .iter()
            .map(|&n| it.by_ref().take(n).collect())
            .collect()
    }
}

/// Fresh symbols for `f`'s input entries (stacked).
fn input_symbols(g: &mut Graph, f: &Function) -> Vec<u32> {
    let mut inputs = Vec::new();
    for (k, &n) in f.input_sizes.iter().enumerate() {
        for i in 0..n {
            inputs.push(g.symbol(&format!("{}.{}[{i}]", f.name, f.input_names[k])));
        }
    }
    inputs
}

/// Rebuilds `f`'s computation in `g` on fresh symbols: the input symbols (stacked) and the
/// output nodes (stacked).
fn instantiate(g: &mut Graph, f: &Function) -> (Vec<u32>, Vec<u32>) {
    let inputs = input_symbols(g, f);
    let outputs = instantiate_on(g, f, inputs.clone());
    (inputs, outputs)
}

/// Rebuilds `f`'s computation in `g` on the nodes `inputs` (stacked): the output nodes
/// (stacked).
fn instantiate_on(g: &mut Graph, f: &Function, inputs: Vec<u32>) -> Vec<u32> {
    const UNSET: u32 = u32::MAX;
    let mut reg = vec![UNSET; f.work_size];
    let mut p = 0;
    for (&n, &at) in f.input_sizes.iter().zip(&f.input_offsets) {
        reg[at..at + n].copy_from_slice(&inputs[p..p + n]);
        p += n;
    }
    for (i, &v) in f.template.iter().enumerate() {
        reg[f.template_start + i] = g.constant(v);
    }
    for ins in f.tape.instructions() {
        let (a, b, c) = (ins.a as usize, ins.b as usize, ins.c as usize);
        let v = match ins.op {
            Op::Call => {
                let call = &f.calls[ins.d as usize];
                let args = call.args.iter().map(|&r| reg[r as usize]).collect();
                let outs = g.call(&call.function, args);
                for (q, o) in outs.into_iter().enumerate() {
                    reg[call.out as usize + q] = o;
                }
                continue;
            }
            Op::Sym => reg[a],
            Op::Interpolant => {
                let t = g.table_id(&f.tables[c]);
                g.interpolant(reg[a], t)
            }
            Op::Interpolant2 => {
                let t = g.table_id(&f.tables[c]);
                g.interpolant2(reg[a], reg[b], t)
            }
            Op::IfElse => g.if_else(reg[a], reg[b], reg[c]),
            Op::InterpolantN => unreachable!("lookup functions are differentiated by their tables"),
            op if op.arity() == 1 => g.unary(op, reg[a]),
            op => g.binary(op, reg[a], reg[b]),
        };
        reg[ins.d as usize] = v;
    }
    f.output_ranges().flatten().map(|r| reg[r]).collect()
}

/// The Jacobian function of `f` with respect to the input entries where `wrt` is true
/// (the other columns are left out, and the vector-Jacobian product gives 0 for them),
/// built on first use (in `g`) and kept in `f` for that choice of columns.
pub(crate) fn call_jacobian(g: &mut Graph, f: &Arc<Function>, wrt: &[bool]) -> Arc<CallJacobian> {
    fn cache(f: &Function) -> std::sync::MutexGuard<'_, JacobianCache> {
        f.jacobians.lock().unwrap_or_else(|e| e.into_inner())
    }
    if let Some(j) = cache(f).get(wrt) {
        return j.clone();
    }
    // A reverse hook's call is differentiated as the tape function equal to it.
    if let Some(equal) = f.external.as_ref().and_then(|e| e.derivative_as.clone()) {
        return call_jacobian(g, &equal, wrt);
    }
    // A lookup function (`InterpolantN`) has no graph form: its partial derivatives are
    // calls of the lookup functions of its derivative tables. An external function has
    // none either: its partial derivatives are the outputs of a call of its Jacobian
    // function (or, without one, an error for the caller of the derivative builder).
    let lookup = f.lookup_table().cloned();
    let external = f.external.as_ref().map(|e| e.jacobian.clone());
    let missing = matches!(external, Some(None));
    if missing {
        g.derivative_error.get_or_insert(SymxError::NoDerivative {
            name: f.name.clone(),
        });
    }
    let (inputs, outputs) = match (&lookup, &external) {
        (None, None) => instantiate(g, f),
        _ => (input_symbols(g, f), Vec::new()),
    };
    let columns: Vec<usize> = (0..inputs.len()).filter(|&j| wrt[j]).collect();
    let wrt_syms: Vec<u32> = columns.iter().map(|&j| inputs[j]).collect();
    let entries: Vec<(usize, usize, u32)> = match (&lookup, &external) {
        (Some(table), _) => columns
            .iter()
            .enumerate()
            .map(|(c, &j)| {
                let d = g.function_arc(&Function::lookup(Arc::new(table.derivative(j))));
                (0, c, g.call(&d, inputs.clone())[0])
            })
            .collect(),
        (None, Some(Some((pattern, jac)))) => {
            let jac = g.function_arc(jac);
            let nonzeros = g.call(&jac, inputs.clone());
            let mut column_of = vec![usize::MAX; inputs.len()];
            for (c, &j) in columns.iter().enumerate() {
                column_of[j] = c;
            }
            let mut e: Vec<(usize, usize, u32)> = crate::sparsity::entries(pattern)
                .into_iter()
                .zip(nonzeros)
                .filter(|&((_, j), _)| wrt[j])
                .map(|((i, j), v)| (i, column_of[j], v))
                .collect();
            e.sort_unstable_by_key(|&(i, c, _)| (i, c));
            e
        }
        (None, Some(None)) => Vec::new(),
        (None, None) => crate::ad::jacobian_rows(g, &outputs, &wrt_syms, false),
    };
    let (n_in, n_out) = (inputs.len(), f.output_sizes.iter().sum());
    let mut by_input = vec![Vec::new(); n_in];
    let mut by_output = vec![Vec::new(); n_out];
    for (nz, &(k, c, _)) in entries.iter().enumerate() {
        let j = columns[c];
        by_input[j].push((k as u32, nz as u32));
        by_output[k].push((j as u32, nz as u32));
    }
    let values: Vec<Expr> = entries.iter().map(|e| Expr::from_id(e.2)).collect();
    let syms: Vec<Expr> = inputs.iter().map(|&s| Expr::from_id(s)).collect();
    let mut groups: Vec<&[Expr]> = Vec::new();
    let mut rest = &syms[..];
    for &n in &f.input_sizes {
        let (head, tail) = rest.split_at(n);
        groups.push(head);
        rest = tail;
    }
    let mut jf = crate::compile::compile(g, &groups, &[&values])
        .expect("a Jacobian depends only on the callee's inputs");
    jf.name = format!("jac_{}", f.name);
    jf.input_names = f.input_names.clone();
    jf.output_names = vec!["jac".into()];
    // The vector-Jacobian product: one guarded reverse sweep with symbolic seeds.
    let ybar: Vec<u32> = (0..n_out)
        .map(|k| g.symbol(&format!("{}.adj[{k}]", f.name)))
        .collect();
    let mut xbar = vec![Expr::zero(); n_in];
    let vjp = match (&lookup, &external) {
        (None, None) => crate::ad::guarded_vjp(g, &outputs, &wrt_syms, &ybar),
        // x̄_c = Σₖ ȳₖ ⊛ Jₖc over the nonzeros.
        _ => {
            let mut sums = vec![Expr::zero().id; columns.len()];
            for &(k, c, e) in &entries {
                let term = g.binary(Op::StrongMul, ybar[k], e);
                sums[c] = g.binary(Op::Add, sums[c], term);
            }
            sums
        }
    };
    for (&j, d) in columns.iter().zip(vjp) {
        xbar[j] = Expr::from_id(d);
    }
    let ybar: Vec<Expr> = ybar.into_iter().map(Expr::from_id).collect();
    groups.push(&ybar);
    let mut vf = crate::compile::compile(g, &groups, &[&xbar])
        .expect("a vector-Jacobian product depends only on its inputs");
    vf.name = format!("adj_{}", f.name);
    vf.input_names = f.input_names.clone();
    vf.input_names.push("adj".into());
    vf.output_names = vec!["adj_in".into()];
    let vf = g.function_arc(&vf);
    let hook = f.external.as_ref().and_then(|e| e.vjp.as_ref());
    let jac = Arc::new(CallJacobian {
        function: g.function_arc(&jf),
        vjp: match hook {
            Some(h) => g.function_arc(&Function::reverse_hook(h, &vf)),
            None => vf,
        },
        hook: hook.is_some(),
        by_input,
        by_output,
    });
    if missing {
        // Not kept: the derivative builder returns the error, and a later attempt
        // (after the user adds a Jacobian, a new function) must fail again.
        return jac;
    }
    cache(f).entry(wrt.to_vec()).or_insert(jac).clone()
}
