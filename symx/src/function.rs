//! [`Function`]: expressions compiled to a flat instruction tape.
//!
//! Compilation orders the needed nodes depth-first from each output (so values are
//! consumed soon after they are produced), regroups that order window by window so that
//! equal operations run back to back where its sequence of operations is irregular
//! (`schedule.rs`: the interpreter's dispatch then predicts its jumps; the gap model's
//! Lagrangian Hessian ran 1.2–2.4× faster; native code is generated from the depth-first
//! order), gives each node a register, and frees a register after its last use so that
//! later nodes reuse it (liveness-based allocation, as CasADi's SX virtual machine does).
//! Common subexpressions are already single nodes of the graph, so each is evaluated once.
//! The compiled function owns no graph handles: it is `Send + Sync`, and evaluation writes
//! only into the caller's work vector.
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
//!   numbers, dispatched by a single `match`, with two operations in a row fused into one
//!   step where the first's result is a temporary only the second reads (see
//!   `interpret.rs`: about a third fewer steps on a Lagrangian Hessian).
//!
//! A call of another compiled function (a `Call` node, see [`Function::apply`]) is one
//! instruction: it gathers the argument registers into a scratch block at the end of the
//! work vector laid out as the callee's own work vector, runs the callee's tape there and
//! scatters the callee's outputs into a block of registers of its own. The callee is
//! shared (`Arc`), not copied, and the evaluation still allocates nothing.
use crate::call::{CallInstr, JacobianCache};
use crate::error::SymxError;
use crate::expr::Expr;
use crate::external::External;
use crate::graph;
use crate::interpret::{self, Tape};
use crate::native::{self, Evaluator, NativeCode};
use crate::op::Op;
use crate::sparsity::{pattern_from_entries, Sparsity};
use crate::table::Table;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

/// One tape instruction: `w[d] = op(w[a], w[b], w[c])`; unary operations ignore `b`
/// (set to `a`), only `if_else` reads `c`. [`Op::Sym`] is reused as the copy `w[d] = w[a]`;
/// for [`Op::Interpolant`] and [`Op::Interpolant2`], `c` is the index of the table in [`Function`]'s own list
/// ([`Op::InterpolantN`] also, reading the `b` registers from `a`, `b` < the work size); for
/// [`Op::Call`], `d` is the index of the call in [`Function`]'s list and `a = b = c = 0`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Instr {
    pub op: Op,
    pub d: u32,
    pub a: u32,
    pub b: u32,
    pub c: u32,
}

impl Instr {
    /// The registers the instruction reads by value, in operand order: `a`, `b` for a
    /// binary operation, `a`, `b`, `c` for `if_else`, `a` otherwise (a copy included).
    /// Not for [`Op::Call`] (its arguments are in its call) or [`Op::InterpolantN`] (it
    /// reads a range).
    pub(crate) fn value_operands(&self) -> impl Iterator<Item = u32> {
        let n = match self.op.arity() {
            3 => 3,
            2 => 2,
            _ => 1,
        };
        [self.a, self.b, self.c].into_iter().take(n)
    }
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
    pub(crate) name: String,
    pub(crate) input_names: Vec<String>,
    pub(crate) output_names: Vec<String>,
    /// Identity shared by clones: the graph's call table recognises a function by it.
    pub(crate) uid: u64,
    pub(crate) input_sizes: Vec<usize>,
    pub(crate) output_sizes: Vec<usize>,
    /// Register of entry 0 of each input (entries are consecutive).
    pub(crate) input_offsets: Vec<usize>,
    /// Whether any instruction or output reads input `k` (unread inputs are not copied).
    pub(crate) input_used: Vec<bool>,
    /// Register of entry 0 of each output.
    pub(crate) output_offsets: Vec<usize>,
    /// The instructions, with the interpreter's program running them.
    pub(crate) tape: Tape,
    /// Values of registers `template_start..template_start + template.len()`: the constants
    /// followed by the output slots (constant entries hold their value, others 0).
    pub(crate) template: Vec<f64>,
    pub(crate) template_start: usize,
    pub(crate) work_size: usize,
    /// Lookup tables read by `Interpolant` instructions.
    pub(crate) tables: Vec<Arc<Table>>,
    /// Functions called by `Call` instructions.
    pub(crate) calls: Vec<CallInstr>,
    /// First register of the scratch block where callees run.
    pub(crate) call_scratch: usize,
    /// For each output entry (outputs stacked), the input entries (stacked) it depends on.
    pub(crate) dependencies: OnceLock<Arc<Vec<Vec<u32>>>>,
    /// The Jacobian functions used to differentiate calls of this function, by the set
    /// of input entries differentiated (built on first use; shared by clones).
    pub(crate) jacobians: Arc<Mutex<JacobianCache>>,
    /// Machine code computing what the tape computes (see [`Function::jit`]).
    pub(crate) native: Option<Arc<NativeCode>>,
    /// User code computing the outputs, for an external function (its tape is empty).
    pub(crate) external: Option<Arc<External>>,
}

/// The output slices as raw pointers, for [`Function::run`]: `&mut [f64]` and
/// `*mut [f64]` have the same layout, and no reference to the slices' contents is made,
/// so threads may write disjoint points through them.
pub(crate) fn output_pointers(outputs: &mut [&mut [f64]]) -> *const *mut [f64] {
    outputs.as_mut_ptr().cast::<*mut [f64]>()
}

/// A fresh function identity.
pub(crate) fn next_uid() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// Checks that `names` are distinct.
fn distinct(what: &'static str, names: &[&str]) -> Result<(), SymxError> {
    for (k, n) in names.iter().enumerate() {
        if names[..k].contains(n) {
            return Err(SymxError::DuplicateName {
                what,
                name: n.to_string(),
            });
        }
    }
    Ok(())
}

impl Function {
    /// Compiles `outputs` as functions of `inputs` (each input a vector of distinct symbols).
    ///
    /// Errors: an input entry that is not a symbol, a symbol given twice, or an output that
    /// depends on a symbol not among the inputs.
    ///
    /// The function is named `f`, its inputs `i0, i1, …` and its outputs `o0, o1, …`
    /// (CasADi's defaults); [`Function::named`] chooses the names.
    pub fn new(inputs: &[&[Expr]], outputs: &[&[Expr]]) -> Result<Function, SymxError> {
        let all: Vec<Expr> = inputs.iter().flat_map(|i| i.iter().copied()).collect();
        crate::ad::symbol_ids(&all, "Function inputs")?;
        graph::with(|g| crate::compile::compile(g, inputs, outputs))
    }

    /// Compiles like [`Function::new`], with a name for the function and for each input
    /// and output; `Err` if two inputs or two outputs share a name.
    ///
    /// ```
    /// use symx::{Function, Matrix};
    /// let x = Matrix::sym_vec("x", 2);
    /// let u = Matrix::sym_vec("u", 1);
    /// let xdot = Matrix::from_vec(vec![x[1], u[0] - x[0]]);
    /// let f = Function::named("ode", &[("x", &x), ("u", &u)], &[("xdot", &xdot)]).unwrap();
    /// assert_eq!((f.name(), f.input_index("u"), f.output_names()), ("ode", Some(1), &["xdot".to_string()][..]));
    /// ```
    pub fn named(
        name: &str,
        inputs: &[(&str, &[Expr])],
        outputs: &[(&str, &[Expr])],
    ) -> Result<Function, SymxError> {
        let in_names: Vec<&str> = inputs.iter().map(|p| p.0).collect();
        let out_names: Vec<&str> = outputs.iter().map(|p| p.0).collect();
        distinct("input", &in_names)?;
        distinct("output", &out_names)?;
        let ins: Vec<&[Expr]> = inputs.iter().map(|p| p.1).collect();
        let outs: Vec<&[Expr]> = outputs.iter().map(|p| p.1).collect();
        let mut f = Function::new(&ins, &outs)?;
        f.name = name.to_string();
        f.input_names = in_names.iter().map(|s| s.to_string()).collect();
        f.output_names = out_names.iter().map(|s| s.to_string()).collect();
        Ok(f)
    }

    /// The function's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The names of the inputs, in order.
    pub fn input_names(&self) -> &[String] {
        &self.input_names
    }

    /// The names of the outputs, in order.
    pub fn output_names(&self) -> &[String] {
        &self.output_names
    }

    /// The position of the input called `name`.
    pub fn input_index(&self, name: &str) -> Option<usize> {
        self.input_names.iter().position(|n| n == name)
    }

    /// The position of the output called `name`.
    pub fn output_index(&self, name: &str) -> Option<usize> {
        self.output_names.iter().position(|n| n == name)
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

    /// This function evaluated by machine code compiled from its tape (and the tapes of the
    /// functions it calls) with Cranelift: same inputs, outputs, work vector and
    /// allocation-free, `Send + Sync` evaluation, bit-identical results (the same IEEE
    /// operations in the same order, and the very Rust math functions the tape calls). The
    /// tape is kept as the reference ([`Function::tape`] gives it back). Compile time is
    /// linear in the tape's length (the tape is compiled in chunks).
    ///
    /// `Err` if symx was built without its default `jit` feature, or if Cranelift fails
    /// (e.g. an unsupported processor).
    ///
    /// ```
    /// use symx::{Evaluator, Function, Matrix};
    /// let x = Matrix::sym_vec("x", 2);
    /// let f = Function::new(&[&x], &[&[(x[0] * x[1]).sin() + x[1].powi(3)]]).unwrap();
    /// let native = f.jit().unwrap();
    /// assert_eq!(native.evaluator(), Evaluator::Jit);
    /// let (a, b) = (f.call(&[&[0.3, 1.7]]).unwrap(), native.call(&[&[0.3, 1.7]]).unwrap());
    /// assert_eq!(a[0][0].to_bits(), b[0][0].to_bits());
    /// ```
    pub fn jit(&self) -> Result<Function, SymxError> {
        if self.native.is_some() {
            return Ok(self.clone());
        }
        self.refuse_external("jit")?;
        let source = self.for_native();
        let code = native::compile(&source)?;
        Ok(Function {
            native: Some(Arc::new(code)),
            ..self.clone()
        })
    }

    /// The registers of each output, in output order.
    pub(crate) fn output_ranges(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.output_offsets
            .iter()
            .zip(&self.output_sizes)
            .map(|(&at, &n)| at..at + n)
    }

    /// This function as native code is generated from it: its tape in depth-first order
    /// ([`crate::schedule::depth_first`]), and so are its callees'; itself when nothing
    /// changes. The work size stays: a tape whose depth-first order needs more registers
    /// than its grouped order (it happens on small functions: 110 against 107 on one
    /// corpus Hessian) keeps the grouped order, so that a work vector sized for a
    /// function fits its native form too.
    pub(crate) fn for_native(&self) -> std::borrow::Cow<'_, Function> {
        use std::borrow::Cow;
        if !self.calls.is_empty() {
            // Calls are never regrouped (`schedule::group`): only the callees change.
            let mut changed = false;
            let calls: Vec<CallInstr> = self
                .calls
                .iter()
                .map(|c| {
                    let function = match c.function.for_native() {
                        Cow::Borrowed(_) => c.function.clone(),
                        Cow::Owned(f) => {
                            changed = true;
                            Arc::new(f)
                        }
                    };
                    CallInstr {
                        function,
                        args: c.args.clone(),
                        out: c.out,
                    }
                })
                .collect();
            return if changed {
                Cow::Owned(Function {
                    calls,
                    ..self.clone()
                })
            } else {
                Cow::Borrowed(self)
            };
        }
        let Some((instrs, work_size)) = crate::schedule::depth_first(self)
            .filter(|&(_, work_size)| work_size <= self.work_size)
        else {
            return Cow::Borrowed(self);
        };
        // Without calls, the callees' scratch block after the temporaries is empty.
        Cow::Owned(Function {
            tape: Tape::new(instrs, &[], work_size, self.output_ranges()),
            work_size,
            call_scratch: work_size,
            ..self.clone()
        })
    }

    /// This function evaluated by `evaluator`: [`Function::jit`] or [`Function::tape`].
    pub fn with_evaluator(&self, evaluator: Evaluator) -> Result<Function, SymxError> {
        match evaluator {
            Evaluator::Tape => Ok(self.tape()),
            Evaluator::Jit => self.jit(),
        }
    }

    /// This function evaluated by its tape (the interpreter; native code dropped).
    pub fn tape(&self) -> Function {
        Function {
            native: None,
            ..self.clone()
        }
    }

    /// How this function evaluates.
    pub fn evaluator(&self) -> Evaluator {
        if self.native.is_some() {
            Evaluator::Jit
        } else {
            Evaluator::Tape
        }
    }

    /// Number of tape instructions: one per operation, plus one copy per output entry that
    /// is an input or repeats another entry (inputs, constants and outputs move in bulk).
    pub fn instruction_count(&self) -> usize {
        self.tape.len()
    }

    /// Checks argument counts and lengths for `points` points.
    pub(crate) fn check_batch(
        &self,
        inputs: &[&[f64]],
        outputs: &[&mut [f64]],
        work: &[f64],
        points: usize,
    ) -> Result<(), SymxError> {
        self.check(inputs, outputs, work, points)
    }

    /// Number of instructions one evaluation executes: this tape's, plus those of every
    /// called function's tape per call (a measure of evaluation work).
    pub fn executed_instruction_count(&self) -> usize {
        self.tape.len()
            + self
                .calls
                .iter()
                .map(|c| c.function.executed_instruction_count())
                .sum::<usize>()
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
        let outs = output_pointers(outputs);
        // SAFETY: sizes checked above; the tape's indices were bounded at compilation.
        unsafe { self.run(inputs, outs, work.as_mut_ptr(), 0) };
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
        let outs = output_pointers(outputs);
        for p in 0..points {
            // SAFETY: sizes checked above for all points.
            unsafe { self.run(inputs, outs, work.as_mut_ptr(), p) };
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

    /// Evaluates point `p`: reads `inputs`, writes output `k` at `outputs[k]` (see
    /// [`output_pointers`]) and uses the work vector at `w`.
    ///
    /// # Safety
    /// `inputs` and the `n_outputs()` slices behind `outputs` must hold `(p+1)·size`
    /// numbers per argument and `w` at least `work_size` numbers (checked by
    /// [`Function::check`]); no other thread may access point `p` of the outputs or `w`.
    #[inline(always)]
    pub(crate) unsafe fn run(
        &self,
        inputs: &[&[f64]],
        outputs: *const *mut [f64],
        w: *mut f64,
        p: usize,
    ) {
        if self.native.is_some() && self.run_native(inputs, outputs, w, p) {
            return;
        }
        for (k, x) in inputs.iter().enumerate() {
            if *self.input_used.get_unchecked(k) {
                let n = *self.input_sizes.get_unchecked(k);
                let at = *self.input_offsets.get_unchecked(k);
                std::ptr::copy_nonoverlapping(x.as_ptr().add(p * n), w.add(at), n);
            }
        }
        self.exec(w);
        for (k, (&n, &at)) in self
            .output_sizes
            .iter()
            .zip(&self.output_offsets)
            .enumerate()
        {
            let y = (*outputs.add(k)).cast::<f64>();
            std::ptr::copy_nonoverlapping(w.add(at), y.add(p * n), n);
        }
    }

    /// [`Function::run`] by the machine code reading the inputs and writing the outputs in
    /// place; `false` (nothing done) if there are too many inputs or outputs for that.
    /// Kept out of line so that the tape's loop in `run` is compiled as before.
    ///
    /// # Safety
    /// As for [`Function::run`].
    #[inline(never)]
    unsafe fn run_native(
        &self,
        inputs: &[&[f64]],
        outputs: *const *mut [f64],
        w: *mut f64,
        p: usize,
    ) -> bool {
        let Some(native) = &self.native else {
            return false;
        };
        let (n_in, n_out) = (inputs.len(), self.output_sizes.len());
        if n_in > crate::native::MAX_DIRECT || n_out > crate::native::MAX_DIRECT {
            return false;
        }
        let mut args = [std::ptr::null::<f64>(); crate::native::MAX_DIRECT];
        let mut res = [std::ptr::null_mut::<f64>(); crate::native::MAX_DIRECT];
        for (k, x) in inputs.iter().enumerate() {
            args[k] = x.as_ptr().add(p * self.input_sizes.get_unchecked(k));
        }
        for (k, r) in res.iter_mut().enumerate().take(n_out) {
            let n = *self.output_sizes.get_unchecked(k);
            *r = (*outputs.add(k)).cast::<f64>().add(p * n);
        }
        (native.entry)(w, args.as_ptr(), res.as_ptr());
        true
    }

    /// Runs the tape on a work vector whose input registers are filled.
    ///
    /// # Safety
    /// `w` must point to at least `work_size` numbers.
    #[inline(always)]
    pub(crate) unsafe fn exec(&self, w: *mut f64) {
        if let Some(native) = &self.native {
            // SAFETY: the code does what the tape does (same registers, same template).
            return (native.entry)(w, std::ptr::null(), std::ptr::null());
        }
        if let Some(ext) = &self.external {
            // SAFETY: the work vector of an external function is `[inputs | outputs]`.
            return ext.run(w);
        }
        std::ptr::copy_nonoverlapping(
            self.template.as_ptr(),
            w.add(self.template_start),
            self.template.len(),
        );
        interpret::run(self, w);
    }

    /// Runs one call: arguments into the scratch block, the callee's tape there, its
    /// outputs into the call's output registers.
    ///
    /// # Safety
    /// As [`Function::exec`]; the registers of `call` were bounded at compilation.
    #[inline(never)]
    pub(crate) unsafe fn exec_call(&self, call: &CallInstr, w: *mut f64) {
        let f = &*call.function;
        let s = w.add(self.call_scratch);
        let mut p = 0;
        for (&n, &at) in f.input_sizes.iter().zip(&f.input_offsets) {
            for i in 0..n {
                *s.add(at + i) = *w.add(*call.args.get_unchecked(p) as usize);
                p += 1;
            }
        }
        f.exec(s);
        let out = w.add(call.out as usize);
        let mut q = 0;
        for (&n, &at) in f.output_sizes.iter().zip(&f.output_offsets) {
            std::ptr::copy_nonoverlapping(s.add(at), out.add(q), n);
            q += n;
        }
    }

    /// Which entries of output `output` depend on which entries of input `input`: the
    /// structural Jacobian pattern (`output_sizes()[output] × input_sizes()[input]`), found
    /// by propagating 64-column bit masks along the tape. Operations with zero derivative
    /// (comparisons, `sign`) and the conditions of `if_else` do not propagate dependence;
    /// a call propagates the dependencies of the called function.
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
        let col0: usize = self.input_sizes[..input].iter().sum();
        let row0: usize = self.output_sizes[..output].iter().sum();
        let (ncols, nrows) = (self.input_sizes[input], self.output_sizes[output]);
        let rows = &self.dependency_rows()[row0..row0 + nrows];
        let entries = rows.iter().enumerate().flat_map(|(i, cols)| {
            cols.iter()
                .map(|&j| j as usize)
                .filter(|&j| j >= col0 && j < col0 + ncols)
                .map(move |j| (i, j - col0))
        });
        Ok(pattern_from_entries(nrows, ncols, entries))
    }

    /// For each output entry (outputs stacked), the sorted input entries (inputs stacked)
    /// it depends on; computed once and kept.
    pub(crate) fn dependency_rows(&self) -> &Arc<Vec<Vec<u32>>> {
        self.dependencies.get_or_init(|| {
            let n_in: usize = self.input_sizes.iter().sum();
            let mut rows: Vec<Vec<u32>> = vec![Vec::new(); self.output_sizes.iter().sum()];
            let input_regs: Vec<usize> = (0..self.input_sizes.len())
                .flat_map(|k| (0..self.input_sizes[k]).map(move |i| (k, i)))
                .map(|(k, i)| self.input_offsets[k] + i)
                .collect();
            let output_regs: Vec<usize> = (0..self.output_sizes.len())
                .flat_map(|k| (0..self.output_sizes[k]).map(move |i| (k, i)))
                .map(|(k, i)| self.output_offsets[k] + i)
                .collect();
            let mut bits = vec![0u64; self.work_size];
            for block in (0..n_in).step_by(64) {
                bits.iter_mut().for_each(|b| *b = 0);
                for j in block..n_in.min(block + 64) {
                    bits[input_regs[j]] = 1u64 << (j - block);
                }
                self.propagate_bits(&mut bits);
                for (row, &r) in rows.iter_mut().zip(&output_regs) {
                    let mut m = bits[r];
                    while m != 0 {
                        row.push((block + m.trailing_zeros() as usize) as u32);
                        m &= m - 1;
                    }
                }
            }
            Arc::new(rows)
        })
    }

    /// Propagates dependence bit masks along the tape (`bits` has `work_size` entries).
    fn propagate_bits(&self, bits: &mut [u64]) {
        for ins in self.tape.instructions() {
            match ins.op {
                Op::Call => {
                    let call = &self.calls[ins.d as usize];
                    let deps = call.function.dependency_rows();
                    for (q, cols) in deps.iter().enumerate() {
                        let m = cols
                            .iter()
                            .fold(0, |m, &j| m | bits[call.args[j as usize] as usize]);
                        bits[call.out as usize + q] = m;
                    }
                }
                Op::InterpolantN => {
                    let (a, n) = (ins.a as usize, ins.b as usize);
                    bits[ins.d as usize] = bits[a..a + n].iter().fold(0, |m, &b| m | b);
                }
                o if o.has_zero_derivative() => bits[ins.d as usize] = 0,
                Op::IfElse => bits[ins.d as usize] = bits[ins.b as usize] | bits[ins.c as usize],
                _ => bits[ins.d as usize] = bits[ins.a as usize] | bits[ins.b as usize],
            }
        }
    }
}
