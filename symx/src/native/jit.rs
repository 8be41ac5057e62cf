//! The tape compiled to machine code by Cranelift.
//!
//! Each function's tape is cut into chunks of [`CHUNK`] instructions, each compiled as one
//! machine-code function `fn(w, args, res)` ([`Entry`]), so that compile time stays linear
//! in the tape's length (register allocation of one huge straight-line function is not).
//! Inputs are read where the caller keeps them (`args[k]`) and outputs written where it
//! wants them (`res[k]`): no copy in or out. Inside a chunk, registers live in SSA values:
//! a register is loaded at its first read in the chunk, and a result is stored to the work
//! vector only if a later chunk or a lookup table reads it, or if it is read again more
//! than [`WINDOW`] instructions later (then reloaded, so that no value lives long enough
//! to be spilled); a backward liveness pass decides. An output's value is kept in the
//! caller's output alone and reloaded from there ([`Layout::in_output`]). Constants are
//! loaded from the template (or the pool of constant pairs), and only the constant outputs
//! of the template are written. A call of another function gathers its arguments into the
//! scratch block and calls that function's machine code, compiled once in the same module.
use super::constant_pairs::{ConstantPairs, Pair};
use super::lanes::{self, Operand, Step};
use super::places::written;
use super::{Entry, SymxError};
use crate::function::{Function, Instr};
use crate::op::{self, Op};
use crate::table::Table;
use cranelift_codegen::ir::{
    condcodes::FloatCC, immediates::Ieee64, types, AbiParam, ConstantData, Endianness, InstBuilder,
    MemFlags, SigRef, Signature, StackSlot, StackSlotData, StackSlotKind, Value,
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

/// A value accessed again more than this many instructions later is reloaded from the
/// work vector (or its constant re-materialised) rather than kept in a machine register
/// (see [`stores`]): on the gap model's Jacobian this cut the register allocator's spills
/// from 10 417 to 1 253 and the instructions executed by 7.5 %; 24 removed every spill
/// but executed more loads.
const WINDOW: usize = 48;

/// Runs of template entries shorter than this are written by immediate stores, longer
/// ones by a copy.
const INLINE_TEMPLATE: usize = 16;

/// What the machine code needs alive: the code memory, the templates it copies, the pools
/// of constant pairs it reads and the tables it reads (through raw pointers).
pub(crate) struct Owner {
    module: Option<JITModule>,
    _templates: Vec<Vec<f64>>,
    _pools: Vec<Vec<Pair>>,
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
pub(crate) fn compile(f: &Function) -> Result<(Entry, Owner, usize, usize), SymxError> {
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
        pools: Vec::new(),
        tables: Vec::new(),
        functions: 0,
        instructions: 0,
    };
    let id = jit.function(f)?;
    jit.module.finalize_definitions().map_err(err)?;
    let code = jit.module.get_finalized_function(id);
    // SAFETY: `id` was defined with the signature `fn(*mut f64)` (C calling convention).
    let entry = unsafe { std::mem::transmute::<*const u8, Entry>(code) };
    let owner = Owner {
        module: Some(jit.module),
        _templates: jit.templates,
        _pools: jit.pools,
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
    /// The constant pairs of each machine-code function's SIMD instructions (see
    /// [`ConstantPairs`]).
    pools: Vec<Vec<Pair>>,
    tables: Vec<Arc<Table>>,
    functions: usize,
    instructions: usize,
}

/// Per function being compiled: what each instruction's code needs to know.
struct Layout<'a> {
    f: &'a Function,
    /// Whether instruction `i`'s result must be stored to the work vector (never for a
    /// register kept in its output, see [`Layout::in_output`]).
    store: Vec<bool>,
    /// Registers whose value lives in the caller's output (output slots that no lookup
    /// table reads through a pointer): written there once, and read back from there, so
    /// that no second store goes to the work vector (a value with two uses, the two
    /// stores, also kept Cranelift from folding its operands' loads into its instruction).
    in_output: Vec<bool>,
    /// The last instruction reading instruction `i`'s result (see [`lanes::last_reader`]).
    last_reader: Vec<usize>,
    /// Registers holding a constant (never written, in the template): their values.
    constant: Vec<Option<f64>>,
    /// Which template entries the machine code must write (see [`template_stores`]).
    template_stores: Vec<bool>,
    /// For each register, the input or output entry `(k, i)` it holds, if any.
    input_of: Vec<Option<(u32, u32)>>,
    output_of: Vec<Option<(u32, u32)>>,
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
        // The template and, after it, the sign mask that negations load (see
        // [`Emitter::negate`]).
        let mut template = f.template.clone();
        template.push(-0.0);
        let constant = constants(f);
        let entries = |sizes: &[usize], offsets: &[usize]| {
            let mut of = vec![None; f.work_size];
            for (k, (&n, &at)) in sizes.iter().zip(offsets).enumerate() {
                for i in 0..n {
                    of[at + i] = Some((k as u32, i as u32));
                }
            }
            of
        };
        let mut layout = Layout {
            f,
            input_of: entries(&f.input_sizes, &f.input_offsets),
            output_of: entries(&f.output_sizes, &f.output_offsets),
            store: Vec::new(),
            in_output: Vec::new(),
            last_reader: lanes::last_reader(f, |ins, visit| {
                reads(f, ins, &mut *visit);
                if ins.op == Op::InterpolantN {
                    (ins.a..ins.a + ins.b).for_each(&mut *visit);
                }
            }),
            template_stores: template_stores(f, &constant),
            constant,
            callees,
            tables: f.tables.iter().map(|t| Arc::as_ptr(t) as i64).collect(),
            template: template.as_ptr(),
        };
        (layout.store, layout.in_output) = homes(f, &layout.output_of);
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

    /// `fn(w, args, res)`: see [`Entry`].
    fn signature(&self) -> Signature {
        let mut sig = self.module.make_signature();
        let p = AbiParam::new(self.module.target_config().pointer_type());
        sig.params.extend([p, p, p]);
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
        let params = prologue(&mut b, layout, None);
        let entry = params.entry;
        let mut e = Emitter::new(
            &mut b,
            &mut self.module,
            params,
            layout,
            ConstantPairs::default(),
        );
        e.template();
        for &c in chunk_ids {
            let r = e.module.declare_func_in_func(c, e.b.func);
            e.b.ins().call(r, &entry);
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
        let regs = lanes::Registers {
            constant: &layout.constant,
            input_of: &layout.input_of,
            output_of: &layout.output_of,
            store: &layout.store,
            last_reader: &layout.last_reader,
        };
        let steps: Vec<Step> = ranges
            .iter()
            .flat_map(|&(start, end)| lanes::steps(layout.f, &regs, start, end))
            .collect();
        let (pairs, pool) = ConstantPairs::of(&steps, &layout.constant);
        let mut b = FunctionBuilder::new(&mut self.ctx.func, &mut self.fbc);
        // No pool parameter (one register less) when no SIMD instruction has a constant pair.
        let pool_address = (!pool.is_empty()).then_some(pool.as_ptr() as i64);
        let params = prologue(&mut b, layout, pool_address);
        let mut e = Emitter::new(&mut b, &mut self.module, params, layout, pairs);
        if with_template {
            e.template();
        }
        for step in steps {
            match step {
                Step::Single(i) => e.instruction(i),
                Step::Pair {
                    start,
                    len,
                    operands,
                } => e.pair(start, len, &operands),
            }
        }
        // The pool's heap buffer does not move with the `Vec`: the address stays valid.
        self.pools.push(pool);
        b.ins().return_(&[]);
        b.finalize();
        self.module
            .define_function(id, &mut self.ctx)
            .map_err(err)?;
        self.module.clear_context(&mut self.ctx);
        Ok(())
    }
}

/// The arguments of a machine-code function and the addresses of the function's inputs
/// and outputs (`args[k]`/`res[k]`, or their registers in `w` when `args` is null).
#[derive(Clone)]
struct Params {
    w: Value,
    /// The function's own parameters `(w, args, res)`, passed on to the chunks.
    entry: [Value; 3],
    inputs: Vec<Value>,
    outputs: Vec<Value>,
    /// The address of the function's template (constants are loaded from there): a block
    /// parameter, kept in a register, where Cranelift would materialise a constant again
    /// at every use.
    template: Value,
    /// The address of this machine-code function's pool of constant pairs (see
    /// [`ConstantPairs`]), likewise.
    pool: Value,
}

/// The entry block of a machine-code function: the address of each input and output (from
/// `args` and `res`, or in `w` when `args` is null), of the template and of the pool of
/// constant pairs (`pool`, if the function has one), computed once.
fn prologue(b: &mut FunctionBuilder, layout: &Layout, pool: Option<i64>) -> Params {
    let f = layout.f;
    let entry_block = b.create_block();
    b.append_block_params_for_function_params(entry_block);
    b.switch_to_block(entry_block);
    b.seal_block(entry_block);
    let ps = b.block_params(entry_block);
    let (w, args, res) = (ps[0], ps[1], ps[2]);
    let mut params = Params {
        w,
        entry: [w, args, res],
        inputs: Vec::new(),
        outputs: Vec::new(),
        template: w,
        pool: w,
    };
    let ptr = types::I64;
    let flags = MemFlags::trusted();
    let (n_in, n_out) = (f.input_offsets.len(), f.output_offsets.len());
    let direct = b.create_block();
    let in_w = b.create_block();
    let body = b.create_block();
    let addresses = [Some(layout.template as i64), pool];
    let extra = addresses.iter().flatten().count();
    for _ in 0..n_in + n_out + extra {
        b.append_block_param(body, ptr);
    }
    b.ins().brif(args, direct, &[], in_w, &[]);
    b.switch_to_block(direct);
    b.seal_block(direct);
    let mut bases = Vec::new();
    for k in 0..n_in {
        bases.push(b.ins().load(ptr, flags, args, 8 * k as i32).into());
    }
    for k in 0..n_out {
        bases.push(b.ins().load(ptr, flags, res, 8 * k as i32).into());
    }
    for &a in addresses.iter().flatten() {
        bases.push(b.ins().iconst(ptr, a).into());
    }
    b.ins().jump(body, &bases);
    b.switch_to_block(in_w);
    b.seal_block(in_w);
    let offsets = f.input_offsets.iter().chain(&f.output_offsets);
    let mut bases: Vec<_> = offsets
        .map(|&at| b.ins().iadd_imm(w, 8 * at as i64).into())
        .collect();
    for &a in addresses.iter().flatten() {
        bases.push(b.ins().iconst(ptr, a).into());
    }
    b.ins().jump(body, &bases);
    b.switch_to_block(body);
    b.seal_block(body);
    let ps = b.block_params(body).to_vec();
    params.inputs = ps[..n_in].to_vec();
    params.outputs = ps[n_in..n_in + n_out].to_vec();
    params.template = ps[n_in + n_out];
    if pool.is_some() {
        params.pool = ps[n_in + n_out + 1];
    }
    params
}

/// The registers an instruction reads from the work vector by value.
fn reads(f: &Function, ins: &Instr, mut visit: impl FnMut(u32)) {
    match ins.op {
        Op::Call => f.calls[ins.d as usize].args.iter().for_each(|&r| visit(r)),
        // Read through a pointer: handled by the caller.
        Op::InterpolantN => {}
        _ => ins.value_operands().for_each(visit),
    }
}

/// Which instructions' results must be stored to the work vector: those read by a later
/// chunk or through a pointer (lookup tables of any dimension; outputs are stored to the
/// caller's output by the emitter), and those with two consecutive accesses (write or read) more than [`WINDOW`]
/// instructions apart, which the emitter reloads instead of keeping them live.
fn stores(f: &Function) -> Vec<bool> {
    const NONE: u32 = 0;
    const ALWAYS: u32 = u32::MAX;
    // Per register: 1 + the last chunk reading its current value (going backwards), or
    // NONE / ALWAYS.
    let mut reader = vec![NONE; f.work_size];
    // Per register: the next read of its current value (going backwards), and whether
    // two accesses of it lie more than `WINDOW` apart in one chunk.
    let mut next = vec![usize::MAX; f.work_size];
    let mut far = vec![false; f.work_size];
    let mut store = vec![false; f.tape.len()];
    let gap = |next: usize, i: usize| {
        next != usize::MAX && next / CHUNK == i / CHUNK && next - i > WINDOW
    };
    for (i, ins) in f.tape.iter().enumerate().rev() {
        let chunk = (i / CHUNK) as u32 + 1;
        if ins.op == Op::Call {
            let call = &f.calls[ins.d as usize];
            let n: usize = call.function.output_sizes.iter().sum();
            let out = call.out as usize;
            reader[out..out + n].iter_mut().for_each(|r| *r = NONE);
            next[out..out + n].iter_mut().for_each(|r| *r = usize::MAX);
            far[out..out + n].iter_mut().for_each(|r| *r = false);
        } else {
            let d = ins.d as usize;
            store[i] = reader[d] > chunk || far[d] || gap(next[d], i);
            reader[d] = NONE;
            next[d] = usize::MAX;
            far[d] = false;
        }
        if ins.op == Op::InterpolantN {
            let (a, n) = (ins.a as usize, ins.b as usize);
            reader[a..a + n].iter_mut().for_each(|r| *r = ALWAYS);
        }
        reads(f, ins, |r| {
            let r = r as usize;
            reader[r] = reader[r].max(chunk);
            far[r] |= gap(next[r], i);
            next[r] = i;
        });
    }
    store
}

/// Which results must be stored to the work vector ([`stores`]) and which registers live in
/// the caller's output instead ([`Layout::in_output`]): output slots, except those a lookup
/// table reads through a pointer (into the work vector).
fn homes(f: &Function, output_of: &[Option<(u32, u32)>]) -> (Vec<bool>, Vec<bool>) {
    let mut in_output: Vec<bool> = output_of.iter().map(Option::is_some).collect();
    for ins in f.tape.iter().filter(|i| i.op == Op::InterpolantN) {
        (ins.a as usize..(ins.a + ins.b) as usize).for_each(|r| in_output[r] = false);
    }
    let mut store = stores(f);
    for (s, ins) in store.iter_mut().zip(f.tape.iter()) {
        if ins.op != Op::Call && in_output[ins.d as usize] {
            *s = false;
        }
    }
    (store, in_output)
}

/// The registers that hold a constant throughout (in the template, never written).
fn constants(f: &Function) -> Vec<Option<f64>> {
    let written = written(f);
    let mut c = vec![None; f.work_size];
    for (k, &v) in f.template.iter().enumerate() {
        let r = f.template_start + k;
        c[r] = (!written[r]).then_some(v);
    }
    c
}

/// The template entries read from memory, which the machine code must write: constant
/// outputs (the caller copies the output slots) and constants a lookup table reads through
/// a pointer. Constants read by value are immediates, and every other output slot is
/// written by the tape.
fn template_stores(f: &Function, constant: &[Option<f64>]) -> Vec<bool> {
    let mut needed = vec![false; f.template.len()];
    let mut mark = |r: usize| {
        if constant[r].is_some() && r >= f.template_start && r < f.template_start + needed.len() {
            needed[r - f.template_start] = true;
        }
    };
    for (&n, &at) in f.output_sizes.iter().zip(&f.output_offsets) {
        (at..at + n).for_each(&mut mark);
    }
    for ins in f.tape.iter().filter(|i| i.op == Op::InterpolantN) {
        (ins.a as usize..(ins.a + ins.b) as usize).for_each(&mut mark);
    }
    needed
}

/// Emits the code of one machine-code function.
struct Emitter<'a, 'b> {
    b: &'a mut FunctionBuilder<'b>,
    module: &'a mut JITModule,
    w: Value,
    params: Params,
    layout: &'a Layout<'a>,
    /// The SSA value of each register read or written in this function so far, and the
    /// instruction of its last access.
    values: FxHashMap<u32, (Held, usize)>,
    /// The instruction being emitted.
    at: usize,
    flags: MemFlags,
    unary: Option<SigRef>,
    binary: Option<SigRef>,
    table: Option<SigRef>,
    copy: Option<SigRef>,
    slot: Option<StackSlot>,
    /// The sign mask loaded by [`Emitter::negate`] and the instruction of its last use.
    sign_mask: Option<(Value, usize)>,
    /// The zero vector compared with by [`Emitter::guard`] and the instruction of its
    /// last use.
    zero_vector: Option<(Value, usize)>,
    /// Where the constant pairs of this function's SIMD instructions lie in its pool.
    pairs: ConstantPairs,
}

/// How the machine code holds a register's value.
#[derive(Clone, Copy)]
enum Held {
    /// In a scalar SSA value.
    Scalar(Value),
    /// In a lane of an `f64x2` value, extracted only when read: an `extractlane` nobody
    /// reads would still count as a use of the vector for Cranelift, and a vector used more
    /// than once makes its operands' loads (constant pairs above all) unfit to fold into
    /// the instruction as memory operands.
    Lane(Value, u8),
}

type Unary = extern "C" fn(f64) -> f64;
type Binary = extern "C" fn(f64, f64) -> f64;

impl<'a, 'b> Emitter<'a, 'b> {
    fn new(
        b: &'a mut FunctionBuilder<'b>,
        module: &'a mut JITModule,
        params: Params,
        layout: &'a Layout<'a>,
        pairs: ConstantPairs,
    ) -> Self {
        Emitter {
            b,
            module,
            w: params.w,
            params,
            layout,
            values: FxHashMap::default(),
            at: 0,
            flags: MemFlags::trusted(),
            unary: None,
            binary: None,
            table: None,
            copy: None,
            slot: None,
            sign_mask: None,
            zero_vector: None,
            pairs,
        }
    }

    fn ptr(&self) -> types::Type {
        self.module.target_config().pointer_type()
    }

    fn constant(&mut self, v: f64) -> Value {
        self.b.ins().f64const(Ieee64::with_bits(v.to_bits()))
    }

    /// The value of register `r`: its SSA value if it was accessed at most [`WINDOW`]
    /// instructions ago, else reloaded (or the constant re-materialised) so that no value
    /// lives long enough to be spilled.
    fn get(&mut self, r: u32) -> Value {
        self.operand(r, false)
    }

    /// [`Emitter::get`]; with `first`, for the first operand of a commutative operation: a
    /// value loaded here is kept out of a memory operand ([`Emitter::unfoldable`]), because
    /// Cranelift folds a single-use load into the instruction by swapping the operands of
    /// `fadd`/`fmul`, and x86 returns the first operand's NaN when both are NaN: the swap
    /// would change a NaN's sign or payload.
    fn operand(&mut self, r: u32, first: bool) -> Value {
        if let Some((held, last)) = self.values.get_mut(&r) {
            // (A paired instruction may read before a later-positioned access of its pair.)
            if self.at.saturating_sub(*last) <= WINDOW {
                *last = (*last).max(self.at);
                return match *held {
                    Held::Scalar(v) => v,
                    Held::Lane(v, lane) => {
                        let x = self.b.ins().extractlane(v, lane);
                        *held = Held::Scalar(x);
                        x
                    }
                };
            }
        }
        let (base, offset) = match (
            self.layout.constant[r as usize],
            self.layout.input_of[r as usize],
        ) {
            (Some(c), _) if c.is_nan() || c.to_bits() == 0 => {
                let v = self.constant(c);
                self.values.insert(r, (Held::Scalar(v), self.at));
                return v;
            }
            // Loaded afresh at every use (not kept in a register), so that the load folds
            // into the arithmetic instruction as a memory operand.
            (Some(_), _) => return self.template_load(r),
            // Inputs are never written by the tape: read from the caller's input.
            (None, Some((k, i))) => (self.params.inputs[k as usize], 8 * i as i32),
            (None, None) => self.home(r),
        };
        let v = self.b.ins().load(types::F64, self.flags, base, offset);
        if first {
            self.unfoldable(v);
        }
        self.values.insert(r, (Held::Scalar(v), self.at));
        v
    }

    /// Where register `r` (neither a constant nor an input) is kept in memory: its entry of
    /// the caller's output if [`Layout::in_output`], else the work vector.
    fn home(&self, r: u32) -> (Value, i32) {
        match self.layout.output_of[r as usize] {
            Some((k, i)) if self.layout.in_output[r as usize] => {
                (self.params.outputs[k as usize], 8 * i as i32)
            }
            _ => (self.w, 8 * r as i32),
        }
    }

    /// Keeps the load `v` out of its user's memory operand: Cranelift folds only a load
    /// used once, and counts every use, a dead instruction's included; the dead `fabs`
    /// added here emits no code (an integer load moved to a float register, the way
    /// before, cost one instruction per load: 1 674 of the gap Jacobian's 50 384).
    fn unfoldable(&mut self, v: Value) {
        self.b.ins().fabs(v);
    }

    /// Constant register `r` loaded from the function's template, where it is kept (one
    /// instruction, or none when the load folds into its user, instead of an integer
    /// immediate moved to a float register).
    fn template_load(&mut self, r: u32) -> Value {
        let offset = 8 * (r as usize - self.layout.f.template_start) as i32;
        self.template_entry(offset)
    }

    /// The number at byte `offset` of the function's template (as extended by
    /// [`Jit::function`]).
    fn template_entry(&mut self, offset: i32) -> Value {
        let base = self.params.template;
        let flags = MemFlags::trusted().with_readonly();
        self.b.ins().load(types::F64, flags, base, offset)
    }

    /// `−a` (sign bit flipped, NaN included): `a` xor the sign mask, loaded from after the
    /// template and kept in a register while used within [`WINDOW`] instructions
    /// (Cranelift's own `fneg` builds the mask from an integer immediate every time).
    fn negate(&mut self, a: Value) -> Value {
        let mask = match self.sign_mask {
            Some((m, last)) if self.at.saturating_sub(last) <= WINDOW => m,
            _ => self.template_entry(8 * self.layout.f.template.len() as i32),
        };
        self.sign_mask = Some((mask, self.at));
        if self.b.func.dfg.value_type(a) == types::F64X2 {
            let masks = self.b.ins().splat(types::F64X2, mask);
            self.b.ins().bxor(a, masks)
        } else {
            self.b.ins().bxor(a, mask)
        }
    }

    /// `p` where `a ≠ 0` (NaN included), else `+0`: the result of `a ⊛ b` from its product
    /// `p = a·b` (scalars or `f64x2` lanes), without a branch: `p` and-ed with the mask of
    /// `a ≠ 0` (`cmpneqpd`: unordered or not equal), which is all zeros exactly where
    /// `a = ±0`. (Cranelift lowers a float `select` to two branches: on the derivative
    /// functions of call nodes, where half the instructions are guarded products, that
    /// code was twice as long and its taken branches filled the branch predictor.)
    fn guard(&mut self, a: Value, p: Value) -> Value {
        let ty = types::F64X2;
        let scalar = self.b.func.dfg.value_type(a) != ty;
        let lanes = if scalar { self.b.ins().splat(ty, a) } else { a };
        let zero = match self.zero_vector {
            Some((z, last)) if self.at.saturating_sub(last) <= WINDOW => z,
            _ => {
                let k = self
                    .b
                    .func
                    .dfg
                    .constants
                    .insert(ConstantData::from(vec![0u8; 16]));
                self.b.ins().vconst(ty, k)
            }
        };
        self.zero_vector = Some((zero, self.at));
        let mask = self.b.ins().fcmp(FloatCC::NotEqual, lanes, zero);
        let little = MemFlags::new().with_endianness(Endianness::Little);
        let mask = self.b.ins().bitcast(ty, little, mask);
        let mask = if scalar {
            self.b.ins().extractlane(mask, 0)
        } else {
            mask
        };
        self.b.ins().band(p, mask)
    }

    /// Whether register `r` holds a constant other than NaN: a commutative operation
    /// gives the same bits with its operands swapped when one of them is such a constant
    /// (x86 returns the one NaN operand, quieted, whichever side it is on).
    fn plain_constant(&self, r: u32) -> bool {
        self.layout.constant[r as usize].is_some_and(|c| !c.is_nan())
    }

    /// Where register `r` would be loaded from by [`Emitter::operand`] at instruction `at`
    /// (`None`: its SSA value is live, or it is a constant).
    fn memory(&self, r: u32, at: usize) -> Option<(Value, i32)> {
        if let Some(&(_, last)) = self.values.get(&r) {
            if at.saturating_sub(last) <= WINDOW {
                return None;
            }
        }
        match (
            self.layout.constant[r as usize],
            self.layout.input_of[r as usize],
        ) {
            (Some(_), _) => None,
            (None, Some((k, i))) => Some((self.params.inputs[k as usize], 8 * i as i32)),
            (None, None) => Some(self.home(r)),
        }
    }

    /// The two lanes `(r1 at at1, r2 at at2)` as one `f64x2`: one load when both lie
    /// side by side in memory, one constant when both are constants, else the two scalars
    /// put together. With `first` (the first operand of a commutative operation) a loaded
    /// vector is kept out of a memory operand, for the reason given at [`Emitter::operand`].
    fn lanes(&mut self, (r1, at1): (u32, usize), (r2, at2): (u32, usize), first: bool) -> Value {
        let ty = types::F64X2;
        let c = &self.layout.constant;
        if let (Some(x), Some(y)) = (c[r1 as usize], c[r2 as usize]) {
            // From the pool (the load folds into its user as a memory operand), except as
            // the first operand of a commutative operation (see [`Emitter::operand`]).
            if let Some(offset) = self.pairs.offset(x, y).filter(|_| !first) {
                // (Aligned: the pool's pairs are 16-byte aligned.)
                let flags = MemFlags::trusted().with_readonly();
                return self.b.ins().load(ty, flags, self.params.pool, offset);
            }
            let bytes: Vec<u8> = [x, y].iter().flat_map(|v| v.to_le_bytes()).collect();
            let k = self.b.func.dfg.constants.insert(ConstantData::from(bytes));
            return self.b.ins().vconst(ty, k);
        }
        if let (Some((b1, o1)), Some((b2, o2))) = (self.memory(r1, at1), self.memory(r2, at2)) {
            if b1 == b2 && o2 == o1 + 8 {
                let flags = MemFlags::new().with_notrap();
                let v = self.b.ins().load(ty, flags, b1, o1);
                if first {
                    self.unfoldable(v);
                }
                // The scalars stay reachable as lanes of the vector.
                for (r, at, lane) in [(r1, at1, 0), (r2, at2, 1)] {
                    self.values.insert(r, (Held::Lane(v, lane), at));
                }
                return v;
            }
        }
        self.at = at1;
        let x = self.operand(r1, first);
        self.at = at2;
        let y = self.operand(r2, first);
        let v = self.b.ins().scalar_to_vector(ty, x);
        self.b.ins().insertlane(v, y, 1)
    }

    /// Instructions `start..start + 2 len` as `len` SIMD instructions (see
    /// [`lanes::steps`]); the results then set their registers in tape order, so the work
    /// vector and the outputs end as the scalar code leaves them.
    fn pair(&mut self, start: usize, len: usize, operands: &[[Operand; 2]]) {
        let f = self.layout.f;
        let mut vectors: Vec<Value> = Vec::with_capacity(len);
        for (j, ops) in operands.iter().enumerate() {
            let op = f.tape[start + j].op;
            let (at1, at2) = (start + j, start + len + j);
            let commutative = matches!(op, Op::Add | Op::Mul);
            // Constants second (the same bits, see [`Emitter::plain_constant`]): a constant
            // vector then folds into the instruction as a memory operand.
            let plain = |e: &Self, o: &Operand| matches!(*o, Operand::External(r1, r2) if e.plain_constant(r1) && e.plain_constant(r2));
            let swap = commutative && plain(self, &ops[0]);
            let order = if swap { [1, 0] } else { [0, 1] };
            // (A load may be folded, operands swapped, when the other operand cannot be NaN.)
            let first = commutative && !plain(self, &ops[order[1]]);
            let get = |e: &mut Self, p: usize| match ops[order[p]] {
                Operand::Internal(m) => vectors[m],
                Operand::External(r1, r2) => e.lanes((r1, at1), (r2, at2), p == 0 && first),
            };
            let a = get(self, 0);
            let v = match op {
                Op::Neg => self.negate(a),
                Op::Sq => self.b.ins().fmul(a, a),
                Op::Sqrt => self.b.ins().sqrt(a),
                Op::Abs => self.b.ins().fabs(a),
                _ => {
                    let b = get(self, 1);
                    match op {
                        Op::Add => self.b.ins().fadd(a, b),
                        Op::Sub => self.b.ins().fsub(a, b),
                        Op::Mul => self.b.ins().fmul(a, b),
                        Op::Div => self.b.ins().fdiv(a, b),
                        Op::StrongMul => {
                            let p = self.b.ins().fmul(a, b);
                            self.guard(a, p)
                        }
                        _ => unreachable!("{op:?} is not paired (lanes::pairable)"),
                    }
                }
            };
            vectors.push(v);
        }
        self.commit(start, len, &vectors);
    }

    /// Sets the registers of a pair's instructions from their lanes, in tape order; an
    /// output entry and the next one written by the two lanes of one vector are stored
    /// together.
    fn commit(&mut self, start: usize, len: usize, vectors: &[Value]) {
        let f = self.layout.f;
        let window = &f.tape[start..start + 2 * len];
        let once = |d: u32| window.iter().filter(|w| w.d == d).count() == 1;
        let mut stored = vec![false; len];
        for lane in 0..2u8 {
            for (j, &v) in vectors.iter().enumerate() {
                let i = start + lane as usize * len + j;
                let d = f.tape[i].d;
                self.at = i;
                self.values.insert(d, (Held::Lane(v, lane), i));
                if lane == 1 && stored[j] {
                    continue;
                }
                let store = self.layout.store[i];
                let out = self.layout.output_of[d as usize];
                if lane == 0 {
                    let d2 = f.tape[i + len].d;
                    let out2 = self.layout.output_of[d2 as usize];
                    let side_by_side = matches!((out, out2), (Some((k, a)), Some((k2, b))) if k == k2 && b == a + 1);
                    if side_by_side
                        && store == self.layout.store[i + len]
                        && (!store || d2 == d + 1)
                        && once(d)
                        && once(d2)
                    {
                        let (k, a) = out.expect("an output");
                        let flags = MemFlags::new().with_notrap();
                        let base = self.params.outputs[k as usize];
                        self.b.ins().store(flags, v, base, 8 * a as i32);
                        if store {
                            self.b.ins().store(flags, v, self.w, 8 * d as i32);
                        }
                        stored[j] = true;
                        continue;
                    }
                }
                if store || out.is_some() {
                    let x = self.b.ins().extractlane(v, lane);
                    self.put(d, x, store);
                }
            }
        }
    }

    /// Sets register `r` to `v`: stored to the work vector if `store`, and to the caller's
    /// output if `r` is an output slot (written once by the tape).
    fn put(&mut self, r: u32, v: Value, store: bool) {
        self.values.insert(r, (Held::Scalar(v), self.at));
        if store {
            self.b.ins().store(self.flags, v, self.w, 8 * r as i32);
        }
        if let Some((k, i)) = self.layout.output_of[r as usize] {
            let base = self.params.outputs[k as usize];
            self.b.ins().store(self.flags, v, base, 8 * i as i32);
        }
    }

    /// Writes the template entries someone reads from memory into the work vector (the
    /// tape copies the whole template; here the other constants are immediates and the
    /// other output slots are written by the tape): runs of [`INLINE_TEMPLATE`] entries or
    /// more by a copy, shorter ones by immediate stores.
    fn template(&mut self) {
        let f = self.layout.f;
        let needed = &self.layout.template_stores;
        // Where template entry `j` goes: the caller's output, or the work vector.
        let dest = |j: usize| {
            let r = f.template_start + j;
            match self.layout.output_of[r] {
                Some((k, i)) => (Some(k), 8 * i as i32),
                None => (None, 8 * r as i32),
            }
        };
        // The integer constants stored recently, by bits, and the store of their last use.
        let mut recent = FxHashMap::default();
        let mut stored = 0;
        let mut k = 0;
        while k < needed.len() {
            if !needed[k] {
                k += 1;
                continue;
            }
            let group = dest(k).0;
            let end = (k..needed.len())
                .find(|&e| !needed[e] || dest(e).0 != group)
                .unwrap_or(needed.len());
            let base = group.map_or(self.w, |o| self.params.outputs[o as usize]);
            let offset = dest(k).1;
            if end - k < INLINE_TEMPLATE {
                for (j, &v) in f.template[k..end].iter().enumerate() {
                    let c = self.template_bits(&mut recent, v, stored);
                    stored += 1;
                    self.b
                        .ins()
                        .store(self.flags, c, base, offset + 8 * j as i32);
                }
            } else {
                self.copy_template(k, end, base, offset);
            }
            k = end;
        }
    }

    /// The bits of `v` as an integer for the `stored`-th immediate store of [`Emitter::template`]:
    /// the value of an earlier store of the same bits within [`WINDOW`] stores, else a new
    /// constant (storing the bits from an integer register takes one instruction where a
    /// float constant takes three: integer immediate, move to a float register, store;
    /// the gap Jacobian stores 823 constant outputs, mostly ±1 and ±0.5, at every call).
    fn template_bits(
        &mut self,
        recent: &mut FxHashMap<u64, (Value, usize)>,
        v: f64,
        stored: usize,
    ) -> Value {
        let bits = v.to_bits();
        let value = match recent.get(&bits) {
            Some(&(c, last)) if stored - last <= WINDOW => c,
            _ => self.b.ins().iconst(types::I64, bits as i64),
        };
        recent.insert(bits, (value, stored));
        value
    }

    /// Copies template entries `k..end` to `base + offset`.
    fn copy_template(&mut self, k: usize, end: usize, base: Value, offset: i32) {
        let sig = *self.copy.get_or_insert_with(|| {
            let p = AbiParam::new(self.module.target_config().pointer_type());
            let mut s = self.module.make_signature();
            s.params.extend([p, p, p]);
            self.b.import_signature(s)
        });
        let ptr = self.ptr();
        let dst = self.b.ins().iadd_imm(base, offset as i64);
        // SAFETY (of the address): `k < template.len()`.
        let src_addr = unsafe { self.layout.template.add(k) } as i64;
        let src = self.b.ins().iconst(ptr, src_addr);
        let n = self.b.ins().iconst(ptr, (end - k) as i64);
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
        self.at = i;
        let f = self.layout.f;
        let ins = f.tape[i];
        let store = self.layout.store[i];
        if ins.op == Op::Call {
            self.call(ins.d as usize);
            return;
        }
        if ins.op == Op::InterpolantN {
            // The table reads its operands from the work vector: inputs copied there.
            for r in ins.a..ins.a + ins.b {
                if self.layout.input_of[r as usize].is_some() {
                    let v = self.get(r);
                    self.b.ins().store(self.flags, v, self.w, 8 * r as i32);
                }
            }
            let x = self.b.ins().iadd_imm(self.w, 8 * ins.a as i64);
            let v = self.lookup(self.layout.tables[ins.c as usize], x, ins.b as usize);
            self.put(ins.d, v, store);
            return;
        }
        let commutative = matches!(ins.op, Op::Add | Op::Mul | Op::StrongMul);
        // `c ∘ x` as `x ∘ c` for a constant `c` (the same bits, see
        // [`Emitter::plain_constant`]): the constant's load then folds into the instruction.
        let swap = matches!(ins.op, Op::Add | Op::Mul) && self.plain_constant(ins.a);
        let (ra, rb) = if swap { (ins.b, ins.a) } else { (ins.a, ins.b) };
        // (A load may be folded, operands swapped, when the other operand cannot be NaN.)
        let a = self.operand(ra, commutative && !self.plain_constant(rb));
        let b = if ins.op.arity() >= 2 { self.get(rb) } else { a };
        let zero = || Ieee64::with_bits(0);
        let v = match ins.op {
            Op::Add => self.b.ins().fadd(a, b),
            Op::Sub => self.b.ins().fsub(a, b),
            Op::Mul => self.b.ins().fmul(a, b),
            Op::Div => self.b.ins().fdiv(a, b),
            Op::Neg => self.negate(a),
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
                let p = self.b.ins().fmul(a, b);
                self.guard(a, p)
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
        let ptr = self.ptr();
        let null = self.b.ins().iconst(ptr, 0);
        self.b.ins().call(r, &[s, null, null]);
        let mut q = 0;
        for (&n, &at) in g.output_sizes.iter().zip(&g.output_offsets) {
            for i in 0..n {
                let off = scratch + 8 * (at + i) as i32;
                let v = self.b.ins().load(types::F64, self.flags, self.w, off);
                let r = call.out + q;
                self.put(r, v, !self.layout.in_output[r as usize]);
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
