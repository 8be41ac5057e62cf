//! [`Function`]: expressions compiled to a flat instruction tape.
//!
//! Compilation orders the needed nodes depth-first from each output (so values are
//! consumed soon after they are produced), gives each node a register, and frees a
//! register after its last use so that later nodes reuse it (liveness-based allocation, as
//! CasADi's SX virtual machine does). Common subexpressions are already single nodes of
//! the graph, so each is evaluated once. The compiled function owns no graph handles: it is
//! `Send + Sync`, and evaluation writes only into the caller's work vector.
use crate::error::SymxError;
use crate::expr::Expr;
use crate::graph::{self, Graph};
use crate::op::{self, Op};
use crate::sparsity::{pattern_from_entries, Sparsity};
use rustc_hash::FxHashMap;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Code {
    /// `w[d] = input[a][b]`
    Load,
    /// `output[a][b] = w[c]`
    Store,
    /// `w[d] = op(w[a], w[b], w[c])`
    Calc(Op),
}

#[derive(Clone, Copy, Debug)]
struct Instr {
    code: Code,
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
    tape: Vec<Instr>,
    /// Values of registers `0..constants.len()`, written at the start of every evaluation.
    constants: Vec<f64>,
    work_size: usize,
}

enum Step {
    Node(u32),
    Store { output: u32, offset: u32, node: u32 },
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

    /// Length of the work vector [`Function::eval`] needs.
    pub fn work_size(&self) -> usize {
        self.work_size
    }

    /// Number of tape instructions (loads, operations and stores).
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
        std::ptr::copy_nonoverlapping(self.constants.as_ptr(), w, self.constants.len());
        let r = |i: u32| *w.add(i as usize);
        for ins in &self.tape {
            let v = match ins.code {
                Code::Load => {
                    let (k, off) = (ins.a as usize, ins.b as usize);
                    let n = *self.input_sizes.get_unchecked(k);
                    *inputs.get_unchecked(k).get_unchecked(p * n + off)
                }
                Code::Store => {
                    let (k, off) = (ins.a as usize, ins.b as usize);
                    let n = *self.output_sizes.get_unchecked(k);
                    *outputs.get_unchecked_mut(k).get_unchecked_mut(p * n + off) = r(ins.c);
                    continue;
                }
                Code::Calc(o) => {
                    let a = r(ins.a);
                    match o {
                        Op::Add => a + r(ins.b),
                        Op::Sub => a - r(ins.b),
                        Op::Mul => a * r(ins.b),
                        Op::Div => a / r(ins.b),
                        Op::Neg => -a,
                        Op::Sq => a * a,
                        Op::Sqrt => a.sqrt(),
                        Op::Exp => a.exp(),
                        Op::Log => a.ln(),
                        Op::Sin => a.sin(),
                        Op::Cos => a.cos(),
                        Op::Pow => op::pow(a, r(ins.b)),
                        Op::StrongMul => op::strong_mul(a, r(ins.b)),
                        Op::IfElse => op::select(a, r(ins.b), r(ins.c)),
                        o if o.arity() == 1 => o.eval1(a),
                        o => o.eval2(a, r(ins.b)),
                    }
                }
            };
            *w.add(ins.d as usize) = v;
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
        let mut bits = vec![0u64; self.work_size];
        let mut entries = Vec::new();
        for block in (0..ncols).step_by(64) {
            bits.iter_mut().for_each(|b| *b = 0);
            for ins in &self.tape {
                let v = match ins.code {
                    Code::Load => {
                        let off = ins.b as usize;
                        if ins.a as usize == input && off >= block && off < block + 64 {
                            1u64 << (off - block)
                        } else {
                            0
                        }
                    }
                    Code::Store => {
                        if ins.a as usize == output {
                            let mut m = bits[ins.c as usize];
                            while m != 0 {
                                let t = m.trailing_zeros() as usize;
                                entries.push((ins.b as usize, block + t));
                                m &= m - 1;
                            }
                        }
                        continue;
                    }
                    Code::Calc(o) if o.has_zero_derivative() => 0,
                    Code::Calc(Op::IfElse) => bits[ins.b as usize] | bits[ins.c as usize],
                    Code::Calc(o) => {
                        let mut m = bits[ins.a as usize];
                        if o.arity() > 1 {
                            m |= bits[ins.b as usize];
                        }
                        m
                    }
                };
                bits[ins.d as usize] = v;
            }
        }
        Ok(pattern_from_entries(
            self.output_sizes[output],
            ncols,
            entries,
        ))
    }
}

fn compile(g: &Graph, inputs: &[&[Expr]], outputs: &[&[Expr]]) -> Result<Function, SymxError> {
    // Per-node scratch indexed by node id. Zero-initialised vectors are allocated lazily
    // by the OS, so a small function in a large graph only touches the pages of its cone.
    // `seen[id]`: 0 = not visited, else 1 + the node's position in `order`.
    let n = g.len();
    let mut seen = vec![0u32; n];

    // Where each input symbol is read from.
    let mut source: FxHashMap<u32, (u32, u32)> = FxHashMap::default();
    for (k, x) in inputs.iter().enumerate() {
        for (off, e) in x.iter().enumerate() {
            source.insert(e.id, (k as u32, off as u32));
        }
    }

    // Constants get the first registers (their values are copied in before every run).
    let mut constants = Vec::new();

    // Depth-first post-order from each output entry; stores follow their node.
    let mut steps: Vec<Step> = Vec::new();
    let mut stack: Vec<(u32, u8)> = Vec::new();
    // Register of each visited node (constants: their constant slot).
    let mut register: Vec<u32> = Vec::new();
    for (k, y) in outputs.iter().enumerate() {
        for (off, e) in y.iter().enumerate() {
            if seen[e.id as usize] == 0 {
                stack.push((e.id, 0));
            }
            while let Some(&mut (id, ref mut next)) = stack.last_mut() {
                let node = g.node(id);
                if *next == 0 {
                    if seen[id as usize] != 0 {
                        stack.pop();
                        continue;
                    }
                    match node.op {
                        Op::Const => {
                            register.push(constants.len() as u32);
                            seen[id as usize] = register.len() as u32;
                            constants.push(node.value().unwrap_or(f64::NAN));
                            stack.pop();
                            continue;
                        }
                        Op::Sym if !source.contains_key(&id) => {
                            return Err(SymxError::FreeSymbol {
                                output: k,
                                name: g.symbol_name(id).to_string(),
                            });
                        }
                        _ => {}
                    }
                }
                let operands = node.operands();
                if (*next as usize) < operands.len() {
                    let child = operands[*next as usize];
                    *next += 1;
                    if seen[child as usize] == 0 {
                        stack.push((child, 0));
                    }
                } else {
                    register.push(u32::MAX);
                    seen[id as usize] = register.len() as u32;
                    steps.push(Step::Node(id));
                    stack.pop();
                }
            }
            steps.push(Step::Store {
                output: k as u32,
                offset: off as u32,
                node: e.id,
            });
        }
    }
    // Dense local index of each visited node.
    let local = |id: u32| seen[id as usize] as usize - 1;

    // Last step that reads each node (by local index).
    let mut last_use: Vec<usize> = vec![usize::MAX; register.len()];
    for (s, step) in steps.iter().enumerate() {
        match *step {
            Step::Node(id) => {
                for &a in g.node(id).operands() {
                    last_use[local(a)] = s;
                }
            }
            Step::Store { node, .. } => {
                last_use[local(node)] = s;
            }
        }
    }

    // Register allocation with reuse after last use.
    let n_const = constants.len() as u32;
    let mut free: Vec<u32> = Vec::new();
    let mut work_size = n_const;
    let mut tape = Vec::with_capacity(steps.len());
    for (s, step) in steps.iter().enumerate() {
        match *step {
            Step::Node(id) => {
                let node = g.node(id);
                let args = node.args;
                let arity = node.op.arity();
                let mut regs = [0u32; 3];
                for k in 0..arity {
                    regs[k] = register[local(args[k])];
                }
                // Operands whose last use is here free their registers first, so the
                // result may take one of them (operands are read before the write).
                for k in 0..arity {
                    let l = local(args[k]);
                    if last_use[l] == s && regs[k] >= n_const && !regs[..k].contains(&regs[k]) {
                        free.push(regs[k]);
                    }
                }
                let d = free.pop().unwrap_or_else(|| {
                    work_size += 1;
                    work_size - 1
                });
                register[local(id)] = d;
                let ins = if node.op == Op::Sym {
                    let (k, off) = source[&id];
                    Instr {
                        code: Code::Load,
                        d,
                        a: k,
                        b: off,
                        c: 0,
                    }
                } else {
                    Instr {
                        code: Code::Calc(node.op),
                        d,
                        a: regs[0],
                        b: regs[1],
                        c: regs[2],
                    }
                };
                tape.push(ins);
            }
            Step::Store {
                output,
                offset,
                node,
            } => {
                let l = local(node);
                let c = register[l];
                tape.push(Instr {
                    code: Code::Store,
                    d: 0,
                    a: output,
                    b: offset,
                    c,
                });
                if last_use[l] == s && c >= n_const {
                    free.push(c);
                }
            }
        }
    }
    Ok(Function {
        input_sizes: inputs.iter().map(|x| x.len()).collect(),
        output_sizes: outputs.iter().map(|y| y.len()).collect(),
        tape,
        constants,
        work_size: work_size as usize,
    })
}
