//! [`Function`]: expressions compiled to a flat instruction tape.
//!
//! Compilation orders the needed nodes depth-first from each output (so values are
//! consumed soon after they are produced), gives each node a register, and frees a
//! register after its last use so that later nodes reuse it (liveness-based allocation, as
//! CasADi's SX virtual machine does). Common subexpressions are already single nodes of
//! the graph, so each is evaluated once. The compiled function owns no graph handles: it is
//! `Send + Sync`, and evaluation writes only into the caller's work vector.
//!
//! The work vector is laid out as
//! `[inputs | constants | outputs | temporaries]`:
//! * the inputs are copied in with one `memcpy` per input vector (CasADi instead spends
//!   one `OP_INPUT` instruction per entry);
//! * constants and the constant entries of the outputs are one template copied in with one
//!   `memcpy`;
//! * each computed output entry is written by its operation straight into its output slot,
//!   and the slots are copied out with one `memcpy` per output vector (no `OP_OUTPUT`
//!   instructions);
//! * only the operations themselves remain on the tape: one byte of opcode and register
//!   numbers, dispatched by a single `match`.
use crate::error::SymxError;
use crate::expr::Expr;
use crate::graph::{self, Graph};
use crate::interpolant::Table;
use crate::op::{self, Op};
use crate::sparsity::{pattern_from_entries, Sparsity};
use rustc_hash::FxHashMap;
use std::sync::Arc;

/// One tape instruction: `w[d] = op(w[a], w[b], w[c])`; unary operations ignore `b`
/// (set to `a`), only `if_else` reads `c`. [`Op::Sym`] is reused as the copy `w[d] = w[a]`;
/// for [`Op::Interpolant`], `c` is the index of the table in [`Function`]'s own list.
#[derive(Clone, Copy, Debug)]
struct Instr {
    op: Op,
    d: u32,
    a: u32,
    b: u32,
    c: u32,
}

/// A compiled function from vectors of numbers to vectors of numbers.
///
/// ```
/// use symx::{Expr, Function, Matrix};
/// let x = Matrix::sym_vec("x", 2);
/// let f = x.sumsqr() * x[0];
/// let fun = Function::new(&[&x], &[&[f]]).unwrap();
/// let mut work = vec![0.0; fun.work_size()];
/// let mut out = [0.0];
/// fun.eval(&[&[1.0, 2.0]], &mut [&mut out], &mut work).unwrap();
/// assert_eq!(out[0], 5.0);
/// ```
#[derive(Clone, Debug)]
pub struct Function {
    input_sizes: Vec<usize>,
    output_sizes: Vec<usize>,
    /// Register of entry 0 of each input (entries are consecutive).
    input_offsets: Vec<usize>,
    /// Whether any instruction or output reads input `k` (unread inputs are not copied).
    input_used: Vec<bool>,
    /// Register of entry 0 of each output.
    output_offsets: Vec<usize>,
    tape: Vec<Instr>,
    /// Values of registers `template_start..template_start + template.len()`: the constants
    /// followed by the output slots (constant entries hold their value, others 0).
    template: Vec<f64>,
    template_start: usize,
    work_size: usize,
    /// Lookup tables read by `Interpolant` instructions.
    tables: Vec<Arc<Table>>,
}

impl Function {
    /// Compiles `outputs` as functions of `inputs` (each input a vector of distinct symbols).
    ///
    /// Errors: an input entry that is not a symbol, a symbol given twice, or an output that
    /// depends on a symbol not among the inputs.
    pub fn new(inputs: &[&[Expr]], outputs: &[&[Expr]]) -> Result<Function, SymxError> {
        let all: Vec<Expr> = inputs.iter().flat_map(|i| i.iter().copied()).collect();
        crate::ad::symbol_ids(&all, "Function inputs")?;
        graph::with(|g| compile(g, inputs, outputs))
    }

    /// Number of input vectors.
    pub fn n_inputs(&self) -> usize {
        self.input_sizes.len()
    }

    /// Number of output vectors.
    pub fn n_outputs(&self) -> usize {
        self.output_sizes.len()
    }

    /// Length of each input vector.
    pub fn input_sizes(&self) -> &[usize] {
        &self.input_sizes
    }

    /// Length of each output vector.
    pub fn output_sizes(&self) -> &[usize] {
        &self.output_sizes
    }

    /// Length of the work vector [`Function::eval`] needs: the inputs, the constants, the
    /// outputs and the temporaries (reused by liveness).
    pub fn work_size(&self) -> usize {
        self.work_size
    }

    /// Number of tape instructions: one per operation, plus one copy per output entry that
    /// is an input or repeats another entry (inputs, constants and outputs move in bulk).
    pub fn instruction_count(&self) -> usize {
        self.tape.len()
    }

    fn check(
        &self,
        inputs: &[&[f64]],
        outputs: &[&mut [f64]],
        work: &[f64],
        points: usize,
    ) -> Result<(), SymxError> {
        let count = |what, expected, got| {
            if expected == got {
                Ok(())
            } else {
                Err(SymxError::ArgumentCount {
                    what,
                    expected,
                    got,
                })
            }
        };
        count("inputs", self.input_sizes.len(), inputs.len())?;
        count("outputs", self.output_sizes.len(), outputs.len())?;
        for (index, (&n, x)) in self.input_sizes.iter().zip(inputs).enumerate() {
            if x.len() != n * points {
                return Err(SymxError::Length {
                    what: "input",
                    index,
                    expected: n * points,
                    got: x.len(),
                });
            }
        }
        for (index, (&n, y)) in self.output_sizes.iter().zip(outputs).enumerate() {
            if y.len() != n * points {
                return Err(SymxError::Length {
                    what: "output",
                    index,
                    expected: n * points,
                    got: y.len(),
                });
            }
        }
        if work.len() < self.work_size {
            return Err(SymxError::Length {
                what: "work vector",
                index: 0,
                expected: self.work_size,
                got: work.len(),
            });
        }
        Ok(())
    }

    /// Evaluates at one point: `inputs[k]` has length `input_sizes()[k]`, `outputs[k]` length
    /// `output_sizes()[k]`, `work` at least `work_size()`. Allocates nothing.
    pub fn eval(
        &self,
        inputs: &[&[f64]],
        outputs: &mut [&mut [f64]],
        work: &mut [f64],
    ) -> Result<(), SymxError> {
        self.check(inputs, outputs, work, 1)?;
        // SAFETY: sizes checked above; the tape's indices were bounded at compilation.
        unsafe { self.run(inputs, outputs, work, 0) };
        Ok(())
    }

    /// Evaluates at `points` points in one call. Input `k` holds the points one after the
    /// other (`points · input_sizes()[k]` numbers), and so does each output.
    pub fn eval_batch(
        &self,
        inputs: &[&[f64]],
        outputs: &mut [&mut [f64]],
        work: &mut [f64],
        points: usize,
    ) -> Result<(), SymxError> {
        self.check(inputs, outputs, work, points)?;
        for p in 0..points {
            // SAFETY: sizes checked above for all points.
            unsafe { self.run(inputs, outputs, work, p) };
        }
        Ok(())
    }

    /// Evaluates at one point, allocating the outputs and the work vector (convenient, not fast).
    pub fn call(&self, inputs: &[&[f64]]) -> Result<Vec<Vec<f64>>, SymxError> {
        let mut out: Vec<Vec<f64>> = self.output_sizes.iter().map(|&n| vec![0.0; n]).collect();
        let mut work = vec![0.0; self.work_size];
        let mut refs: Vec<&mut [f64]> = out.iter_mut().map(|v| v.as_mut_slice()).collect();
        self.eval(inputs, &mut refs, &mut work)?;
        Ok(out)
    }

    /// # Safety
    /// `inputs`/`outputs` must hold `(p+1)·size` numbers per argument and `work` at least
    /// `work_size` numbers (checked by [`Function::check`]).
    #[inline(always)]
    unsafe fn run(
        &self,
        inputs: &[&[f64]],
        outputs: &mut [&mut [f64]],
        work: &mut [f64],
        p: usize,
    ) {
        let w = work.as_mut_ptr();
        for (k, x) in inputs.iter().enumerate() {
            if *self.input_used.get_unchecked(k) {
                let n = *self.input_sizes.get_unchecked(k);
                let at = *self.input_offsets.get_unchecked(k);
                std::ptr::copy_nonoverlapping(x.as_ptr().add(p * n), w.add(at), n);
            }
        }
        std::ptr::copy_nonoverlapping(
            self.template.as_ptr(),
            w.add(self.template_start),
            self.template.len(),
        );
        for ins in &self.tape {
            let a = *w.add(ins.a as usize);
            let b = *w.add(ins.b as usize);
            let v = match ins.op {
                Op::Add => a + b,
                Op::Sub => a - b,
                Op::Mul => a * b,
                Op::Div => a / b,
                Op::Neg => -a,
                Op::Sq => a * a,
                Op::Sym => a,
                Op::Sqrt => a.sqrt(),
                Op::Exp => a.exp(),
                Op::Log => a.ln(),
                Op::Sin => a.sin(),
                Op::Cos => a.cos(),
                Op::Tan => a.tan(),
                Op::Asin => a.asin(),
                Op::Acos => a.acos(),
                Op::Atan => a.atan(),
                Op::Sinh => a.sinh(),
                Op::Cosh => a.cosh(),
                Op::Tanh => a.tanh(),
                Op::Abs => a.abs(),
                Op::Sign => op::sign(a),
                Op::Not => f64::from(a == 0.0),
                Op::Pow => op::pow(a, b),
                Op::Atan2 => a.atan2(b),
                Op::Min => a.min(b),
                Op::Max => a.max(b),
                Op::Lt => f64::from(a < b),
                Op::Le => f64::from(a <= b),
                Op::Eq => f64::from(a == b),
                Op::Ne => f64::from(a != b),
                Op::And => f64::from(a != 0.0 && b != 0.0),
                Op::Or => f64::from(a != 0.0 || b != 0.0),
                Op::StrongMul => op::strong_mul(a, b),
                Op::Floor => a.floor(),
                Op::Ceil => a.ceil(),
                Op::Erf => libm::erf(a),
                Op::Asinh => a.asinh(),
                Op::Acosh => a.acosh(),
                Op::Atanh => a.atanh(),
                Op::Log1p => a.ln_1p(),
                Op::Expm1 => a.exp_m1(),
                Op::Fmod => a % b,
                Op::Hypot => a.hypot(b),
                Op::Interpolant => self.tables.get_unchecked(ins.c as usize).eval(a),
                Op::IfElse => {
                    if a != 0.0 {
                        b
                    } else {
                        *w.add(ins.c as usize)
                    }
                }
                Op::Const => std::hint::unreachable_unchecked(),
            };
            *w.add(ins.d as usize) = v;
        }
        for (k, y) in outputs.iter_mut().enumerate() {
            let n = *self.output_sizes.get_unchecked(k);
            let at = *self.output_offsets.get_unchecked(k);
            std::ptr::copy_nonoverlapping(w.add(at), y.as_mut_ptr().add(p * n), n);
        }
    }

    /// Which entries of output `output` depend on which entries of input `input`: the
    /// structural Jacobian pattern (`output_sizes()[output] × input_sizes()[input]`), found
    /// by propagating 64-column bit masks along the tape. Operations with zero derivative
    /// (comparisons, `sign`) and the conditions of `if_else` do not propagate dependence.
    pub fn dependency_sparsity(&self, input: usize, output: usize) -> Result<Sparsity, SymxError> {
        let (n_in, n_out) = (self.input_sizes.len(), self.output_sizes.len());
        if input >= n_in {
            return Err(SymxError::ArgumentCount {
                what: "input index bound",
                expected: n_in,
                got: input,
            });
        }
        if output >= n_out {
            return Err(SymxError::ArgumentCount {
                what: "output index bound",
                expected: n_out,
                got: output,
            });
        }
        let ncols = self.input_sizes[input];
        let first = self.input_offsets[input];
        let (out_first, nrows) = (self.output_offsets[output], self.output_sizes[output]);
        let mut bits = vec![0u64; self.work_size];
        let mut entries = Vec::new();
        for block in (0..ncols).step_by(64) {
            bits.iter_mut().for_each(|b| *b = 0);
            for j in block..ncols.min(block + 64) {
                bits[first + j] = 1u64 << (j - block);
            }
            for ins in &self.tape {
                bits[ins.d as usize] = match ins.op {
                    o if o.has_zero_derivative() => 0,
                    Op::IfElse => bits[ins.b as usize] | bits[ins.c as usize],
                    _ => bits[ins.a as usize] | bits[ins.b as usize],
                };
            }
            for i in 0..nrows {
                let mut m = bits[out_first + i];
                while m != 0 {
                    entries.push((i, block + m.trailing_zeros() as usize));
                    m &= m - 1;
                }
            }
        }
        Ok(pattern_from_entries(nrows, ncols, entries))
    }
}

fn compile(g: &Graph, inputs: &[&[Expr]], outputs: &[&[Expr]]) -> Result<Function, SymxError> {
    // Per-node scratch indexed by node id. Zero-initialised vectors are allocated lazily
    // by the OS, so a small function in a large graph only touches the pages of its cone.
    // `seen[id]`: 0 = not visited, else 1 + the node's local index.
    let mut seen = vec![0u32; g.len()];
    let mut register: Vec<u32> = Vec::new();
    fn visit(seen: &mut [u32], id: u32, reg: u32, register: &mut Vec<u32>) {
        register.push(reg);
        seen[id as usize] = register.len() as u32;
    }

    // Inputs occupy the first registers.
    let input_sizes: Vec<usize> = inputs.iter().map(|x| x.len()).collect();
    let output_sizes: Vec<usize> = outputs.iter().map(|y| y.len()).collect();
    let mut input_offsets = Vec::with_capacity(inputs.len());
    let mut input_of: FxHashMap<u32, usize> = FxHashMap::default();
    let mut next = 0usize;
    for (k, x) in inputs.iter().enumerate() {
        input_offsets.push(next);
        for e in x.iter() {
            input_of.insert(e.id, k);
            visit(&mut seen, e.id, next as u32, &mut register);
            next += 1;
        }
    }
    let mut input_used = vec![false; inputs.len()];

    // Depth-first post-order of the computed nodes; constants are collected on the way.
    let mut constants: Vec<f64> = Vec::new();
    let mut const_ids: Vec<u32> = Vec::new();
    let mut steps: Vec<u32> = Vec::new();
    let mut stack: Vec<(u32, u8)> = Vec::new();
    let is_seen = |seen: &[u32], id: u32| seen[id as usize] != 0;
    for (k, y) in outputs.iter().enumerate() {
        for e in y.iter() {
            stack.push((e.id, 0));
            while let Some(&mut (id, ref mut child)) = stack.last_mut() {
                let node = g.node(id);
                if *child == 0 {
                    if is_seen(&seen, id) {
                        stack.pop();
                        continue;
                    }
                    match node.op {
                        Op::Const => {
                            const_ids.push(id);
                            constants.push(node.value().unwrap_or(f64::NAN));
                            visit(&mut seen, id, u32::MAX, &mut register);
                            stack.pop();
                            continue;
                        }
                        Op::Sym => {
                            return Err(SymxError::FreeSymbol {
                                output: k,
                                name: g.symbol_name(id).to_string(),
                            })
                        }
                        _ => {}
                    }
                }
                let operands = node.operands();
                if (*child as usize) < operands.len() {
                    let c = operands[*child as usize];
                    *child += 1;
                    if !is_seen(&seen, c) {
                        stack.push((c, 0));
                    }
                } else {
                    visit(&mut seen, id, u32::MAX, &mut register);
                    steps.push(id);
                    stack.pop();
                }
            }
        }
    }
    let local = |id: u32| seen[id as usize] as usize - 1;

    // Constants, then output slots.
    let template_start = next;
    for (c, &id) in const_ids.iter().enumerate() {
        register[local(id)] = (template_start + c) as u32;
    }
    let outputs_start = template_start + constants.len();
    let mut template = constants;
    let mut output_offsets = Vec::with_capacity(outputs.len());
    let mut copies: Vec<Instr> = Vec::new();
    let mut pinned = vec![false; register.len()];
    let mut slot = outputs_start;
    for y in outputs {
        output_offsets.push(slot);
        for e in y.iter() {
            let l = local(e.id);
            let node = g.node(e.id);
            if let Some(v) = node.value() {
                template.push(v);
            } else if node.op != Op::Sym && !pinned[l] {
                // The operation computing this entry writes its output slot directly.
                pinned[l] = true;
                register[l] = slot as u32;
                template.push(0.0);
            } else {
                // An input, or a node already written to another slot: copy at the end.
                template.push(0.0);
                if node.op == Op::Sym {
                    input_used[input_of[&e.id]] = true;
                }
                copies.push(Instr {
                    op: Op::Sym,
                    d: slot as u32,
                    a: e.id, // resolved to a register below
                    b: 0,
                    c: 0,
                });
            }
            slot += 1;
        }
    }

    // Last step reading each node (by local index).
    let mut last_use: Vec<usize> = vec![usize::MAX; register.len()];
    for (s, &id) in steps.iter().enumerate() {
        for &a in g.node(id).operands() {
            last_use[local(a)] = s;
            if g.node(a).op == Op::Sym {
                input_used[input_of[&a]] = true;
            }
        }
    }

    // Temporaries: allocated after the output slots, reused after their last use.
    let temp_start = slot as u32;
    let mut free: Vec<u32> = Vec::new();
    let mut work_size = temp_start;
    let mut tables: Vec<Arc<Table>> = Vec::new();
    let mut table_of: FxHashMap<u32, u32> = FxHashMap::default();
    let mut tape = Vec::with_capacity(steps.len() + copies.len());
    for (s, &id) in steps.iter().enumerate() {
        let node = g.node(id);
        let arity = node.op.arity();
        let mut regs = [0u32; 3];
        for k in 0..arity {
            regs[k] = register[local(node.args[k])];
        }
        // Operands whose last use is here free their registers first, so the result may
        // take one of them (operands are read before the write).
        for k in 0..arity {
            let l = local(node.args[k]);
            if last_use[l] == s && regs[k] >= temp_start && !regs[..k].contains(&regs[k]) {
                free.push(regs[k]);
            }
        }
        let l = local(id);
        let d = if pinned[l] {
            register[l]
        } else {
            let d = free.pop().unwrap_or_else(|| {
                work_size += 1;
                work_size - 1
            });
            register[l] = d;
            d
        };
        let c = if node.op == Op::Interpolant {
            *table_of.entry(node.args[1]).or_insert_with(|| {
                tables.push(g.tables[node.args[1] as usize].clone());
                tables.len() as u32 - 1
            })
        } else if arity == 3 {
            regs[2]
        } else {
            regs[0]
        };
        tape.push(Instr {
            op: node.op,
            d,
            a: regs[0],
            b: if arity >= 2 { regs[1] } else { regs[0] },
            c,
        });
    }
    for mut copy in copies {
        let r = register[local(copy.a)];
        // All operand fields name the source, so that readers of `b` see it too.
        (copy.a, copy.b, copy.c) = (r, r, r);
        tape.push(copy);
    }
    Ok(Function {
        input_sizes,
        output_sizes,
        input_offsets,
        input_used,
        output_offsets,
        tape,
        template,
        template_start,
        work_size: work_size as usize,
        tables,
    })
}
