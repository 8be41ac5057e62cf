//! The tape compiled to machine code by Cranelift.
//!
//! Each function's tape is cut into chunks of [`CHUNK`] instructions, each compiled as one
//! machine-code function `fn(w: *mut f64)`, so that compile time stays linear in the tape's
//! length (register allocation of one huge straight-line function is not). Inside a chunk,
//! registers live in SSA values: a register is loaded from the work vector at its first read
//! in the chunk, and a result is stored back only if a later chunk, a call of a lookup table
//! or the caller (an output slot) reads it (a backward liveness pass decides). Constants are
//! immediates. A call of another function gathers its arguments into the scratch block and
//! calls that function's machine code, compiled once in the same module.
use super::SymxError;
use crate::function::{Function, Instr};
use crate::op::{self, Op};
use crate::table::Table;
use cranelift_codegen::ir::{
    condcodes::FloatCC, immediates::Ieee64, types, AbiParam, InstBuilder, MemFlags, SigRef,
    Signature, StackSlot, StackSlotData, StackSlotKind, Value,
};
use cranelift_codegen::settings::{self, Configurable};
use cranelift_codegen::Context;
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{FuncId, Linkage, Module};
use rustc_hash::FxHashMap;
use std::sync::Arc;

/// Tape instructions per machine-code function (1024 compiled the gap model's Hessian
/// 2.6× faster than 4096, and evaluated it no slower).
const CHUNK: usize = 1024;

/// Templates up to this length are written by immediate stores, longer ones by a copy.
const INLINE_TEMPLATE: usize = 64;

/// What the machine code needs alive: the code memory, the templates it copies and the
/// tables it reads (through raw pointers).
pub(crate) struct Owner {
    module: Option<JITModule>,
    _templates: Vec<Vec<f64>>,
    _tables: Vec<Arc<Table>>,
}

impl Drop for Owner {
    fn drop(&mut self) {
        if let Some(m) = self.module.take() {
            // SAFETY: the only pointers into the code are held by the `NativeCode` owning
            // this, which is being dropped.
            unsafe { m.free_memory() };
        }
    }
}

// SAFETY: after `finalize_definitions` the module is never used again (only freed on drop);
// the code is immutable and reentrant: it reads and writes only through its argument, and
// reads the templates and tables (never written) owned here.
unsafe impl Send for Owner {}
unsafe impl Sync for Owner {}

fn err(e: impl std::fmt::Display) -> SymxError {
    SymxError::Jit {
        message: e.to_string(),
    }
}

/// Compiles `f`: its entry point, the owner of the code, the number of machine-code
/// functions and of tape instructions compiled.
pub(crate) fn compile(
    f: &Function,
) -> Result<(unsafe extern "C" fn(*mut f64), Owner, usize, usize), SymxError> {
    let mut flags = settings::builder();
    let set = |flags: &mut settings::Builder, k: &str, v: &str| flags.set(k, v).map_err(err);
    // Cranelift's optimiser (opt_level "speed") made compilation slower and evaluation no
    // faster on the gap model (the tape has no common subexpressions left to find).
    set(&mut flags, "opt_level", "none")?;
    set(&mut flags, "is_pic", "false")?;
    set(&mut flags, "use_colocated_libcalls", "false")?;
    set(
        &mut flags,
        "enable_verifier",
        if cfg!(debug_assertions) {
            "true"
        } else {
            "false"
        },
    )?;
    let isa = cranelift_native::builder()
        .map_err(err)?
        .finish(settings::Flags::new(flags))
        .map_err(err)?;
    let module = JITModule::new(JITBuilder::with_isa(
        isa,
        cranelift_module::default_libcall_names(),
    ));
    let mut jit = Jit {
        ctx: module.make_context(),
        module,
        fbc: FunctionBuilderContext::new(),
        compiled: FxHashMap::default(),
        templates: Vec::new(),
        tables: Vec::new(),
        functions: 0,
        instructions: 0,
    };
    let id = jit.function(f)?;
    jit.module.finalize_definitions().map_err(err)?;
    let code = jit.module.get_finalized_function(id);
    // SAFETY: `id` was defined with the signature `fn(*mut f64)` (C calling convention).
    let entry = unsafe { std::mem::transmute::<*const u8, unsafe extern "C" fn(*mut f64)>(code) };
    let owner = Owner {
        module: Some(jit.module),
        _templates: jit.templates,
        _tables: jit.tables,
    };
    Ok((entry, owner, jit.functions, jit.instructions))
}

struct Jit {
    module: JITModule,
    ctx: Context,
    fbc: FunctionBuilderContext,
    /// Functions compiled, by identity: their entry points.
    compiled: FxHashMap<u64, FuncId>,
    templates: Vec<Vec<f64>>,
    tables: Vec<Arc<Table>>,
    functions: usize,
    instructions: usize,
}

/// Per function being compiled: what each instruction's code needs to know.
struct Layout<'a> {
    f: &'a Function,
    /// Whether instruction `i`'s result must be stored to the work vector.
    store: Vec<bool>,
    /// Registers holding a constant (never written, in the template): their values.
    constant: Vec<Option<f64>>,
    /// Entry points of the called functions, by call index.
    callees: Vec<FuncId>,
    /// Addresses of the tables, by table index.
    tables: Vec<i64>,
    template: *const f64,
}

impl Jit {
    /// Declares and defines the machine code of `f` (and of its callees), once per function.
    fn function(&mut self, f: &Function) -> Result<FuncId, SymxError> {
        if let Some(&id) = self.compiled.get(&f.uid) {
            return Ok(id);
        }
        let mut callees = Vec::with_capacity(f.calls.len());
        for c in &f.calls {
            callees.push(self.function(&c.function)?);
        }
        let template = f.template.clone();
        let layout = Layout {
            f,
            store: stores(f),
            constant: constants(f),
            callees,
            tables: f.tables.iter().map(|t| Arc::as_ptr(t) as i64).collect(),
            template: template.as_ptr(),
        };
        self.templates.push(template);
        self.tables.extend(f.tables.iter().cloned());
        self.instructions += f.tape.len();

        let chunks: Vec<(usize, usize)> = (0..f.tape.len().div_ceil(CHUNK).max(1))
            .map(|k| (k * CHUNK, ((k + 1) * CHUNK).min(f.tape.len())))
            .collect();
        let mut chunk_ids = Vec::new();
        if chunks.len() > 1 {
            for &range in &chunks {
                let id = self.declare()?;
                self.define(id, &layout, false, &[range])?;
                chunk_ids.push(id);
            }
        }
        let id = self.declare()?;
        self.compiled.insert(f.uid, id);
        if chunks.len() > 1 {
            self.define_main(id, &layout, &chunk_ids)?;
        } else {
            self.define(id, &layout, true, &chunks)?;
        }
        Ok(id)
    }

    fn signature(&self) -> Signature {
        let mut sig = self.module.make_signature();
        sig.params
            .push(AbiParam::new(self.module.target_config().pointer_type()));
        sig
    }

    fn declare(&mut self) -> Result<FuncId, SymxError> {
        self.functions += 1;
        let sig = self.signature();
        self.module
            .declare_function(&format!("symx{}", self.functions), Linkage::Local, &sig)
            .map_err(err)
    }

    /// A function copying the template and calling the chunks in order.
    fn define_main(
        &mut self,
        id: FuncId,
        layout: &Layout,
        chunk_ids: &[FuncId],
    ) -> Result<(), SymxError> {
        self.ctx.func.signature = self.signature();
        let mut b = FunctionBuilder::new(&mut self.ctx.func, &mut self.fbc);
        let block = b.create_block();
        b.append_block_params_for_function_params(block);
        b.switch_to_block(block);
        b.seal_block(block);
        let w = b.block_params(block)[0];
        let mut e = Emitter::new(&mut b, &mut self.module, w, layout);
        e.template();
        for &c in chunk_ids {
            let r = e.module.declare_func_in_func(c, e.b.func);
            e.b.ins().call(r, &[w]);
        }
        b.ins().return_(&[]);
        b.finalize();
        self.module
            .define_function(id, &mut self.ctx)
            .map_err(err)?;
        self.module.clear_context(&mut self.ctx);
        Ok(())
    }

    /// A function running the tape's instructions in `ranges` (after copying the template
    /// if `with_template`).
    fn define(
        &mut self,
        id: FuncId,
        layout: &Layout,
        with_template: bool,
        ranges: &[(usize, usize)],
    ) -> Result<(), SymxError> {
        self.ctx.func.signature = self.signature();
        let mut b = FunctionBuilder::new(&mut self.ctx.func, &mut self.fbc);
        let block = b.create_block();
        b.append_block_params_for_function_params(block);
        b.switch_to_block(block);
        b.seal_block(block);
        let w = b.block_params(block)[0];
        let mut e = Emitter::new(&mut b, &mut self.module, w, layout);
        if with_template {
            e.template();
        }
        for &(start, end) in ranges {
            for i in start..end {
                e.instruction(i);
            }
        }
        b.ins().return_(&[]);
        b.finalize();
        self.module
            .define_function(id, &mut self.ctx)
            .map_err(err)?;
        self.module.clear_context(&mut self.ctx);
        Ok(())
    }
}

/// The registers an instruction reads from the work vector by value.
fn reads(f: &Function, ins: &Instr, mut visit: impl FnMut(u32)) {
    match ins.op {
        Op::Call => f.calls[ins.d as usize].args.iter().for_each(|&r| visit(r)),
        // Read through a pointer: handled by the caller.
        Op::InterpolantN => {}
        Op::IfElse => {
            visit(ins.a);
            visit(ins.b);
            visit(ins.c);
        }
        op if op.arity() == 2 => {
            visit(ins.a);
            visit(ins.b);
        }
        _ => visit(ins.a),
    }
}

/// Which instructions' results must be stored to the work vector: those read by a later
/// chunk, through a pointer (lookup tables of any dimension) or after the tape (outputs).
fn stores(f: &Function) -> Vec<bool> {
    const NONE: u32 = 0;
    const ALWAYS: u32 = u32::MAX;
    // Per register: 1 + the last chunk reading its current value (going backwards), or
    // NONE / ALWAYS.
    let mut reader = vec![NONE; f.work_size];
    for (&n, &at) in f.output_sizes.iter().zip(&f.output_offsets) {
        reader[at..at + n].iter_mut().for_each(|r| *r = ALWAYS);
    }
    let mut store = vec![false; f.tape.len()];
    for (i, ins) in f.tape.iter().enumerate().rev() {
        let chunk = (i / CHUNK) as u32 + 1;
        if ins.op == Op::Call {
            let call = &f.calls[ins.d as usize];
            let n: usize = call.function.output_sizes.iter().sum();
            let out = call.out as usize;
            reader[out..out + n].iter_mut().for_each(|r| *r = NONE);
        } else {
            let d = ins.d as usize;
            store[i] = reader[d] > chunk;
            reader[d] = NONE;
        }
        if ins.op == Op::InterpolantN {
            let (a, n) = (ins.a as usize, ins.b as usize);
            reader[a..a + n].iter_mut().for_each(|r| *r = ALWAYS);
        }
        reads(f, ins, |r| {
            let r = &mut reader[r as usize];
            *r = (*r).max(chunk);
        });
    }
    store
}

/// The registers that hold a constant throughout (in the template, never written).
fn constants(f: &Function) -> Vec<Option<f64>> {
    let mut c = vec![None; f.work_size];
    for (k, &v) in f.template.iter().enumerate() {
        c[f.template_start + k] = Some(v);
    }
    for ins in &f.tape {
        if ins.op == Op::Call {
            let call = &f.calls[ins.d as usize];
            let n: usize = call.function.output_sizes.iter().sum();
            let out = call.out as usize;
            c[out..out + n].iter_mut().for_each(|r| *r = None);
        } else {
            c[ins.d as usize] = None;
        }
    }
    c
}

/// Emits the code of one machine-code function.
struct Emitter<'a, 'b> {
    b: &'a mut FunctionBuilder<'b>,
    module: &'a mut JITModule,
    w: Value,
    layout: &'a Layout<'a>,
    /// The SSA value of each register read or written in this function so far.
    values: FxHashMap<u32, Value>,
    flags: MemFlags,
    unary: Option<SigRef>,
    binary: Option<SigRef>,
    table: Option<SigRef>,
    copy: Option<SigRef>,
    slot: Option<StackSlot>,
}

type Unary = extern "C" fn(f64) -> f64;
type Binary = extern "C" fn(f64, f64) -> f64;

impl<'a, 'b> Emitter<'a, 'b> {
    fn new(
        b: &'a mut FunctionBuilder<'b>,
        module: &'a mut JITModule,
        w: Value,
        layout: &'a Layout<'a>,
    ) -> Self {
        Emitter {
            b,
            module,
            w,
            layout,
            values: FxHashMap::default(),
            flags: MemFlags::trusted(),
            unary: None,
            binary: None,
            table: None,
            copy: None,
            slot: None,
        }
    }

    fn ptr(&self) -> types::Type {
        self.module.target_config().pointer_type()
    }

    fn constant(&mut self, v: f64) -> Value {
        self.b.ins().f64const(Ieee64::with_bits(v.to_bits()))
    }

    /// The value of register `r`.
    fn get(&mut self, r: u32) -> Value {
        if let Some(&v) = self.values.get(&r) {
            return v;
        }
        let v = match self.layout.constant[r as usize] {
            Some(c) => self.constant(c),
            None => self
                .b
                .ins()
                .load(types::F64, self.flags, self.w, 8 * r as i32),
        };
        self.values.insert(r, v);
        v
    }

    fn put(&mut self, r: u32, v: Value, store: bool) {
        self.values.insert(r, v);
        if store {
            self.b.ins().store(self.flags, v, self.w, 8 * r as i32);
        }
    }

    /// Writes the template into the work vector (the tape's first step).
    fn template(&mut self) {
        let f = self.layout.f;
        if f.template.len() <= INLINE_TEMPLATE {
            for (k, &v) in f.template.iter().enumerate() {
                let c = self.constant(v);
                let at = 8 * (f.template_start + k) as i32;
                self.b.ins().store(self.flags, c, self.w, at);
            }
            return;
        }
        let sig = *self.copy.get_or_insert_with(|| {
            let p = AbiParam::new(self.module.target_config().pointer_type());
            let mut s = self.module.make_signature();
            s.params.extend([p, p, p]);
            self.b.import_signature(s)
        });
        let ptr = self.ptr();
        let dst = self.b.ins().iadd_imm(self.w, 8 * f.template_start as i64);
        let src = self.b.ins().iconst(ptr, self.layout.template as i64);
        let n = self.b.ins().iconst(ptr, f.template.len() as i64);
        let callee = self.b.ins().iconst(ptr, copy_helper as *const () as i64);
        self.b.ins().call_indirect(sig, callee, &[dst, src, n]);
    }

    fn call1(&mut self, h: Unary, a: Value) -> Value {
        let sig = *self.unary.get_or_insert_with(|| {
            let mut s = self.module.make_signature();
            s.params.push(AbiParam::new(types::F64));
            s.returns.push(AbiParam::new(types::F64));
            self.b.import_signature(s)
        });
        let ptr = self.ptr();
        let callee = self.b.ins().iconst(ptr, h as *const () as i64);
        let call = self.b.ins().call_indirect(sig, callee, &[a]);
        self.b.inst_results(call)[0]
    }

    fn call2(&mut self, h: Binary, a: Value, b: Value) -> Value {
        let sig = *self.binary.get_or_insert_with(|| {
            let mut s = self.module.make_signature();
            s.params.extend([AbiParam::new(types::F64); 2]);
            s.returns.push(AbiParam::new(types::F64));
            self.b.import_signature(s)
        });
        let ptr = self.ptr();
        let callee = self.b.ins().iconst(ptr, h as *const () as i64);
        let call = self.b.ins().call_indirect(sig, callee, &[a, b]);
        self.b.inst_results(call)[0]
    }

    /// `table(x)` for the table at `table` and the `n` coordinates at `x`.
    fn lookup(&mut self, table: i64, x: Value, n: usize) -> Value {
        let ptr = self.ptr();
        let sig = *self.table.get_or_insert_with(|| {
            let p = AbiParam::new(ptr);
            let mut s = self.module.make_signature();
            s.params.extend([p, p, p]);
            s.returns.push(AbiParam::new(types::F64));
            self.b.import_signature(s)
        });
        let t = self.b.ins().iconst(ptr, table);
        let n = self.b.ins().iconst(ptr, n as i64);
        let callee = self.b.ins().iconst(ptr, table_helper as *const () as i64);
        let call = self.b.ins().call_indirect(sig, callee, &[t, x, n]);
        self.b.inst_results(call)[0]
    }

    /// The address of a stack slot holding `values`.
    fn on_stack(&mut self, values: &[Value]) -> Value {
        let slot = *self.slot.get_or_insert_with(|| {
            self.b
                .create_sized_stack_slot(StackSlotData::new(StackSlotKind::ExplicitSlot, 16, 3))
        });
        for (k, &v) in values.iter().enumerate() {
            self.b.ins().stack_store(v, slot, 8 * k as i32);
        }
        let ptr = self.ptr();
        self.b.ins().stack_addr(ptr, slot, 0)
    }

    /// `1.0` where `c` (an `i8` condition) holds, else `0.0`.
    fn truth(&mut self, c: Value) -> Value {
        let (one, zero) = (self.constant(1.0), self.constant(0.0));
        self.b.ins().select(c, one, zero)
    }

    fn instruction(&mut self, i: usize) {
        let f = self.layout.f;
        let ins = f.tape[i];
        let store = self.layout.store[i];
        if ins.op == Op::Call {
            self.call(ins.d as usize);
            return;
        }
        if ins.op == Op::InterpolantN {
            let x = self.b.ins().iadd_imm(self.w, 8 * ins.a as i64);
            let v = self.lookup(self.layout.tables[ins.c as usize], x, ins.b as usize);
            self.put(ins.d, v, store);
            return;
        }
        let a = self.get(ins.a);
        let b = if ins.op.arity() >= 2 {
            self.get(ins.b)
        } else {
            a
        };
        let zero = || Ieee64::with_bits(0);
        let v = match ins.op {
            Op::Add => self.b.ins().fadd(a, b),
            Op::Sub => self.b.ins().fsub(a, b),
            Op::Mul => self.b.ins().fmul(a, b),
            Op::Div => self.b.ins().fdiv(a, b),
            Op::Neg => self.b.ins().fneg(a),
            Op::Sq => self.b.ins().fmul(a, a),
            Op::Sym => a,
            Op::Sqrt => self.b.ins().sqrt(a),
            Op::Abs => self.b.ins().fabs(a),
            Op::Floor => self.b.ins().floor(a),
            Op::Ceil => self.b.ins().ceil(a),
            Op::Sign => {
                // As `op::sign`: 1 above 0, −1 below, else `a · 0` (±0, NaN).
                let z = self.b.ins().f64const(zero());
                let s0 = self.b.ins().fmul(a, z);
                let m1 = self.constant(-1.0);
                let lt = self.b.ins().fcmp(FloatCC::LessThan, a, z);
                let s1 = self.b.ins().select(lt, m1, s0);
                let p1 = self.constant(1.0);
                let gt = self.b.ins().fcmp(FloatCC::GreaterThan, a, z);
                self.b.ins().select(gt, p1, s1)
            }
            Op::Not => {
                let z = self.b.ins().f64const(zero());
                let c = self.b.ins().fcmp(FloatCC::Equal, a, z);
                self.truth(c)
            }
            Op::Lt | Op::Le | Op::Eq | Op::Ne => {
                let cc = match ins.op {
                    Op::Lt => FloatCC::LessThan,
                    Op::Le => FloatCC::LessThanOrEqual,
                    Op::Eq => FloatCC::Equal,
                    _ => FloatCC::NotEqual, // unordered or different, as Rust's `!=`
                };
                let c = self.b.ins().fcmp(cc, a, b);
                self.truth(c)
            }
            Op::And | Op::Or => {
                let z = self.b.ins().f64const(zero());
                let ca = self.b.ins().fcmp(FloatCC::NotEqual, a, z);
                let cb = self.b.ins().fcmp(FloatCC::NotEqual, b, z);
                let c = if ins.op == Op::And {
                    self.b.ins().band(ca, cb)
                } else {
                    self.b.ins().bor(ca, cb)
                };
                self.truth(c)
            }
            Op::StrongMul => {
                let z = self.b.ins().f64const(zero());
                let p = self.b.ins().fmul(a, b);
                let c = self.b.ins().fcmp(FloatCC::Equal, a, z);
                self.b.ins().select(c, z, p)
            }
            Op::IfElse => {
                let c = self.get(ins.c);
                let z = self.b.ins().f64const(zero());
                let t = self.b.ins().fcmp(FloatCC::NotEqual, a, z);
                self.b.ins().select(t, b, c)
            }
            Op::Interpolant | Op::Interpolant2 => {
                let n = ins.op.arity();
                let x = self.on_stack(&[a, b][..n]);
                self.lookup(self.layout.tables[ins.c as usize], x, n)
            }
            op if op.arity() == 1 => self.call1(unary_helper(op), a),
            op => self.call2(binary_helper(op), a, b),
        };
        self.put(ins.d, v, store);
    }

    /// A call: arguments into the scratch block, the callee's code there, its outputs into
    /// the call's registers.
    fn call(&mut self, k: usize) {
        let f = self.layout.f;
        let call = &f.calls[k];
        let g = &call.function;
        let scratch = 8 * f.call_scratch as i32;
        let mut p = 0;
        for (&n, &at) in g.input_sizes.iter().zip(&g.input_offsets) {
            for i in 0..n {
                let v = self.get(call.args[p]);
                let off = scratch + 8 * (at + i) as i32;
                self.b.ins().store(self.flags, v, self.w, off);
                p += 1;
            }
        }
        let s = self.b.ins().iadd_imm(self.w, scratch as i64);
        let r = self
            .module
            .declare_func_in_func(self.layout.callees[k], self.b.func);
        self.b.ins().call(r, &[s]);
        let mut q = 0;
        for (&n, &at) in g.output_sizes.iter().zip(&g.output_offsets) {
            for i in 0..n {
                let off = scratch + 8 * (at + i) as i32;
                let v = self.b.ins().load(types::F64, self.flags, self.w, off);
                self.put(call.out + q, v, true);
                q += 1;
            }
        }
    }
}

extern "C" fn copy_helper(dst: *mut f64, src: *const f64, n: usize) {
    // SAFETY: called by the generated code with the template (n numbers) and the work
    // vector's template registers.
    unsafe { std::ptr::copy_nonoverlapping(src, dst, n) }
}

extern "C" fn table_helper(t: *const Table, x: *const f64, n: usize) -> f64 {
    // SAFETY: called by the generated code with a table owned by the `Owner` and `n`
    // coordinates in the work vector or on the stack.
    unsafe { (*t).eval(std::slice::from_raw_parts(x, n)) }
}

/// The Rust function computing a unary operation: the very one the tape's loop calls.
fn unary_helper(op: Op) -> Unary {
    macro_rules! h {
        ($e:expr) => {{
            extern "C" fn h(a: f64) -> f64 {
                #[allow(clippy::redundant_closure_call)]
                ($e)(a)
            }
            h
        }};
    }
    match op {
        Op::Exp => h!(f64::exp),
        Op::Log => h!(f64::ln),
        Op::Sin => h!(f64::sin),
        Op::Cos => h!(f64::cos),
        Op::Tan => h!(f64::tan),
        Op::Asin => h!(f64::asin),
        Op::Acos => h!(f64::acos),
        Op::Atan => h!(f64::atan),
        Op::Sinh => h!(f64::sinh),
        Op::Cosh => h!(f64::cosh),
        Op::Tanh => h!(f64::tanh),
        Op::Erf => h!(libm::erf),
        Op::Asinh => h!(f64::asinh),
        Op::Acosh => h!(f64::acosh),
        Op::Atanh => h!(f64::atanh),
        Op::Log1p => h!(f64::ln_1p),
        Op::Expm1 => h!(f64::exp_m1),
        // Every other unary operation is emitted inline above.
        _ => unreachable!("no helper for {op:?}"),
    }
}

/// The Rust function computing a binary operation: the very one the tape's loop calls.
fn binary_helper(op: Op) -> Binary {
    macro_rules! h {
        ($e:expr) => {{
            extern "C" fn h(a: f64, b: f64) -> f64 {
                #[allow(clippy::redundant_closure_call)]
                ($e)(a, b)
            }
            h
        }};
    }
    match op {
        Op::Pow => h!(op::pow),
        Op::Atan2 => h!(f64::atan2),
        Op::Min => h!(f64::min),
        Op::Max => h!(f64::max),
        Op::Fmod => h!(|a: f64, b: f64| a % b),
        Op::Hypot => h!(f64::hypot),
        // Every other binary operation is emitted inline above.
        _ => unreachable!("no helper for {op:?}"),
    }
}
