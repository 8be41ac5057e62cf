//! [`Function::to_rust`]: a function as a self-contained Rust module for deployment
//! (`no_std`, no allocation, no dependency: the math functions are the C library's, which
//! Rust's `std` calls too, but for square roots, the processor's instruction on x86-64).
//!
//! Nothing is copied per call: each generated function `exec(w, x, y)` reads its inputs
//! where the caller keeps them (`x[k]`), writes its outputs where the caller wants them
//! (`y[k]`), and has its constants as literals. Temporaries live in local variables of
//! the generated function of each chunk of the tape ([`Body`]); the work vector `w` holds
//! only those a later chunk reads, the outputs of calls and the arguments gathered for a
//! call of another function, packed ([`Slots`]): `WORK_SIZE` counts only those.
use super::places::{
    call_layout, callee_base, constant_outputs, first_temporary, operands, places,
    read_by_later_chunk, Place,
};
use super::{library_binary, library_unary, unsupported, SourceOptions};
use crate::error::SymxError;
use crate::function::{Function, Instr};
use crate::op::Op;
use rustc_hash::FxHashMap;
use std::fmt::Write;

/// Tape instructions per generated function (keeps rustc's compile time linear). With
/// the inputs as references ([`Writer::emit`]), 256 gave LLVM's scheduler the least
/// spilling on the gap model (instructions per call of ∇f / J / H against 1024: +2 % /
/// −7 % / −5 %; 128 and 512 in between).
const CHUNK: usize = 256;

/// The text of one generated function's body, noting the inputs and outputs it uses.
///
/// Within a body, values live in local variables (`let v{i}`: the result of instruction
/// `i`; `x{k}_{i}`: input entry `(k, i)`, loaded at its first read), which the compiler
/// keeps in registers; only results read by a later body go to the work vector, and
/// outputs are written once to the caller's output. (With every temporary in the work
/// vector, behind raw pointers that may alias the outputs, rustc had to store every
/// result and reload operands after each output store.)
struct Body<'a> {
    out: String,
    places: &'a [Place],
    slots: &'a Slots,
    inputs: Vec<bool>,
    outputs: Vec<bool>,
    /// The local variable holding each register's current value in this body.
    locals: FxHashMap<u32, String>,
}

impl Body<'_> {
    /// The expression reading register `r`: its local variable, or where it is kept.
    fn reg(&mut self, r: u32) -> String {
        if let Some(name) = self.locals.get(&r) {
            return name.clone();
        }
        match self.places[r as usize] {
            Place::Input(k, i) => {
                self.inputs[k] = true;
                let name = format!("x{k}_{i}");
                writeln!(self.out, "    let {name} = *x{k}.add({i});").unwrap();
                self.locals.insert(r, name.clone());
                name
            }
            Place::Output(k, i) => {
                self.outputs[k] = true;
                format!("*y{k}.add({i})")
            }
            Place::Constant(v) => lit(v),
            Place::Work(r) => format!("*w.add({r})"),
        }
    }

    /// Instruction `i` of `f` (other than a call): its value into the local `v{i}`,
    /// then to the caller's output if the register is an output slot, and to the work
    /// vector if `keep` (read by a later body).
    fn assign(&mut self, f: &Function, i: usize, keep: bool) -> Result<(), SymxError> {
        let ins = &f.tape[i];
        let v = self.value(f, ins)?;
        let name = format!("v{i}");
        writeln!(self.out, "    let {name} = {v};").unwrap();
        match self.places[ins.d as usize] {
            Place::Output(k, j) => {
                self.outputs[k] = true;
                writeln!(self.out, "    *y{k}.add({j}) = {name};").unwrap();
            }
            Place::Work(r) if keep => writeln!(self.out, "    *w.add({r}) = {name};").unwrap(),
            _ => {}
        }
        self.locals.insert(ins.d, name);
        Ok(())
    }

    /// The value computed by `ins`, other than a call.
    fn value(&mut self, f: &Function, ins: &Instr) -> Result<String, SymxError> {
        // Only the operands the instruction reads (the first read of an input loads it).
        let mut read = Vec::with_capacity(3);
        operands(f, ins, |r| read.push(r));
        let mut regs: Vec<String> = read.into_iter().map(|r| self.reg(r)).collect();
        regs.resize(3, String::new());
        let [a, b, c]: [String; 3] = regs.try_into().expect("three operands");
        Ok(match ins.op {
            Op::Add => format!("{a} + {b}"),
            Op::Sub => format!("{a} - {b}"),
            Op::Mul => format!("{a} * {b}"),
            Op::Div => format!("{a} / {b}"),
            Op::Neg => format!("-{a}"),
            Op::Sq => format!("{{ let a = {a}; a * a }}"),
            Op::Sym => a,
            Op::Abs => format!("f64::from_bits(({a}).to_bits() & !(1u64 << 63))"),
            Op::Sign => format!("{{ let a = {a}; if a > 0.0 {{ 1.0 }} else if a < 0.0 {{ -1.0 }} else {{ a * 0.0 }} }}"),
            Op::Not => format!("b2f({a} == 0.0)"),
            Op::Pow => format!("pow_({a}, {b})"),
            Op::Min => format!("f64::min({a}, {b})"),
            Op::Max => format!("f64::max({a}, {b})"),
            Op::Lt => format!("b2f({a} < {b})"),
            Op::Le => format!("b2f({a} <= {b})"),
            Op::Eq => format!("b2f({a} == {b})"),
            Op::Ne => format!("b2f({a} != {b})"),
            Op::And => format!("b2f({a} != 0.0 && {b} != 0.0)"),
            Op::Or => format!("b2f({a} != 0.0 || {b} != 0.0)"),
            Op::StrongMul => format!("{{ let a = {a}; if a == 0.0 {{ 0.0 }} else {{ a * {b} }} }}"),
            Op::IfElse => format!("if {a} != 0.0 {{ {b} }} else {{ {c} }}"),
            Op::Sqrt => format!("sqrt_({a})"),
            op => match (library_unary(op), library_binary(op)) {
                (Some(h), _) => format!("{h}({a})"),
                (_, Some(h)) => format!("{h}({a}, {b})"),
                _ => return Err(unsupported("Rust", op)),
            },
        })
    }

    /// A call of `g` (generated as `callee`): its arguments are gathered into the scratch
    /// block at `s`, laid out as `g`'s inputs, and its outputs written straight into the
    /// call's block of registers.
    fn call(&mut self, f: &Function, ins: &Instr, callee: &str) {
        let layout = call_layout(f, ins);
        let at = |x: usize| self.slots.at(x);
        let xs: Vec<String> = (layout.inputs.iter())
            .map(|&x| format!("w.add({}) as *const f64", at(x)))
            .collect();
        let ys: Vec<String> = (layout.outputs.iter())
            .map(|&x| format!("w.add({})", at(x)))
            .collect();
        let callee_work = at(layout.callee_work);
        for &(x, r) in &layout.args {
            let (x, v) = (self.slots.at(x), self.reg(r));
            writeln!(self.out, "    *w.add({x}) = {v};").unwrap();
        }
        writeln!(
            self.out,
            "    {{ let x = [{}]; let y = [{}]; {callee}(w.add({}), x.as_ptr(), y.as_ptr()); }}",
            xs.join(", "),
            ys.join(", "),
            callee_work
        )
        .unwrap();
        // The outputs are in the work vector now.
        let call = &f.calls[ins.d as usize];
        let n: u32 = call.function.output_sizes.iter().sum::<usize>() as u32;
        (call.out..call.out + n).for_each(|r| {
            self.locals.remove(&r);
        });
    }
}

struct Writer {
    out: String,
    /// Generated function name of each function met, by identity.
    names: FxHashMap<u64, String>,
}

impl Writer {
    /// Emits `f` (callees first) and returns the name of its `exec` function.
    fn function(&mut self, f: &Function) -> Result<String, SymxError> {
        if let Some(n) = self.names.get(&f.uid) {
            return Ok(n.clone());
        }
        let mut callees = Vec::new();
        for c in &f.calls {
            callees.push(self.function(&c.function)?);
        }
        let name = format!("exec{}", self.names.len());
        let keep = read_by_later_chunk(f, CHUNK);
        let slots = Slots::new(f, &keep);
        let places: Vec<Place> = places(f)
            .into_iter()
            .map(|p| match p {
                Place::Work(x) => Place::Work(slots.at(x)),
                p => p,
            })
            .collect();
        let mut chunks = Vec::new();
        for k in 0..f.tape.len().div_ceil(CHUNK) {
            let chunk = format!("{name}_{k}");
            let mut body = Body {
                out: String::new(),
                places: &places,
                slots: &slots,
                inputs: vec![false; f.input_sizes.len()],
                outputs: vec![false; f.output_sizes.len()],
                locals: FxHashMap::default(),
            };
            let range = k * CHUNK..((k + 1) * CHUNK).min(f.tape.len());
            for (i, ins) in range.clone().zip(&f.tape[range]) {
                if ins.op == Op::Call {
                    body.call(f, ins, &callees[ins.d as usize]);
                } else {
                    body.assign(f, i, keep[i])?;
                }
            }
            let args = self.emit(&chunk, &body);
            chunks.push((chunk, args));
        }
        let o = &mut self.out;
        writeln!(
            o,
            "/// Runs the tape: inputs at `x[k]`, outputs to `y[k]`, temporaries in `w`.\nunsafe fn {name}(w: *mut f64, x: *const *const f64, y: *const *mut f64) {{"
        )
        .unwrap();
        // The inputs as slices: the caller's (disjoint from the outputs and the work vector),
        // or, for a call node, the block of the caller's work vector holding the gathered
        // arguments, which nothing writes during the call.
        for (k, n) in f.input_sizes.iter().enumerate() {
            writeln!(
                o,
                "    let x{k} = core::slice::from_raw_parts(*x.add({k}), {n});"
            )
            .unwrap();
        }
        for (k, i, v) in constant_outputs(f) {
            writeln!(o, "    *(*y.add({k})).add({i}) = {};", lit(v)).unwrap();
        }
        for (c, args) in &chunks {
            writeln!(o, "    {c}(w, y{args});").unwrap();
        }
        writeln!(o, "}}\n").unwrap();
        self.names.insert(f.uid, name.clone());
        Ok(name)
    }

    /// Writes the generated function `name` with `body`; returns the arguments of its call
    /// after the work vector and the pointers to the outputs: the inputs it reads.
    ///
    /// It takes the inputs it reads as shared references, which rustc marks as neither
    /// aliasing nor changing behind the function's other pointers (`noalias`, `readonly`):
    /// LLVM may then load an input above a store to an output or to the work vector and
    /// pair neighbouring operations into SIMD instructions, as the JIT does (with the
    /// inputs behind raw pointers too, every store was a barrier to the loads after it).
    /// The work vector and the outputs stay raw pointers: references to them too let LLVM
    /// move loads and stores further, which lengthened the live ranges and the spills of
    /// larger bodies (the gap model's Hessian: +9 % instructions).
    fn emit(&mut self, name: &str, body: &Body) -> String {
        let inputs: Vec<usize> = (0..body.inputs.len()).filter(|&k| body.inputs[k]).collect();
        let mut params = String::from("w: *mut f64, y: *const *mut f64");
        let mut args = String::new();
        for k in &inputs {
            write!(params, ", x{k}: &[f64]").unwrap();
            write!(args, ", x{k}").unwrap();
        }
        let o = &mut self.out;
        writeln!(o, "#[inline(never)]\nunsafe fn {name}({params}) {{").unwrap();
        for k in &inputs {
            writeln!(o, "    let x{k} = x{k}.as_ptr();").unwrap();
        }
        for k in (0..body.outputs.len()).filter(|&k| body.outputs[k]) {
            writeln!(o, "    let y{k} = *y.add({k});").unwrap();
        }
        o.push_str(&body.out);
        writeln!(o, "}}\n").unwrap();
        args
    }
}

/// Where the generated Rust keeps a function's work vector: the temporaries a later body
/// reads ([`read_by_later_chunk`]) and the blocks of call outputs, packed in register
/// order, then the call scratch; every other temporary lives in a local variable.
struct Slots {
    /// The packed offset of each temporary (register `first_temporary(f) + x`), if kept.
    packed: Vec<usize>,
    /// The number of temporaries kept: where the call scratch starts.
    scratch: usize,
}

impl Slots {
    fn new(f: &Function, keep: &[bool]) -> Slots {
        let t = first_temporary(f);
        let mut kept = vec![false; f.call_scratch - t];
        for (i, ins) in f.tape.iter().enumerate() {
            if ins.op == Op::Call {
                let call = &f.calls[ins.d as usize];
                let n: usize = call.function.output_sizes.iter().sum();
                let out = call.out as usize - t;
                kept[out..out + n].fill(true);
            } else if keep[i] && ins.d as usize >= t {
                kept[ins.d as usize - t] = true;
            }
        }
        let mut packed = Vec::with_capacity(kept.len());
        let mut n = 0;
        for &k in &kept {
            packed.push(n);
            n += usize::from(k);
        }
        Slots { packed, scratch: n }
    }

    /// The packed offset of offset `x` of the unpacked layout ([`places`], [`call_layout`]).
    fn at(&self, x: usize) -> usize {
        match self.packed.get(x) {
            Some(&p) => p,
            None => self.scratch + (x - self.packed.len()),
        }
    }
}

/// `WORK_SIZE` of the generated Rust of `f`: its packed [`Slots`], then the largest
/// callee's gathered arguments and work vector.
fn packed_work_need(f: &Function) -> usize {
    let slots = Slots::new(f, &read_by_later_chunk(f, CHUNK));
    let callees = f
        .calls
        .iter()
        .map(|c| callee_base(&c.function) + packed_work_need(&c.function));
    slots.scratch + callees.max().unwrap_or(0)
}

/// An `f64` literal with the exact bits of `v`.
fn lit(v: f64) -> String {
    format!("f64::from_bits({:#x})", v.to_bits())
}

const PRELUDE: &str = r#"// The C library's math functions: the ones Rust's std calls, so results equal symx's.
unsafe extern "C" {
    fn exp(x: f64) -> f64;
    fn log(x: f64) -> f64;
    fn sin(x: f64) -> f64;
    fn cos(x: f64) -> f64;
    fn tan(x: f64) -> f64;
    fn asin(x: f64) -> f64;
    fn acos(x: f64) -> f64;
    fn atan(x: f64) -> f64;
    fn sinh(x: f64) -> f64;
    fn cosh(x: f64) -> f64;
    fn tanh(x: f64) -> f64;
    fn log1p(x: f64) -> f64;
    fn expm1(x: f64) -> f64;
    fn sqrt(x: f64) -> f64;
    fn floor(x: f64) -> f64;
    fn ceil(x: f64) -> f64;
    fn atan2(y: f64, x: f64) -> f64;
    fn hypot(x: f64, y: f64) -> f64;
    fn fmod(x: f64, y: f64) -> f64;
    fn pow(x: f64, y: f64) -> f64;
}

// Integer powers as Rust's `f64::powi` computes them (compiler-builtins).
unsafe extern "C" {
    fn __powidf2(a: f64, b: i32) -> f64;
}

#[inline(always)]
fn b2f(b: bool) -> f64 {
    if b { 1.0 } else { 0.0 }
}

/// symx's `pow`: integer exponents up to 64 by `powi`, others by the C library's `pow`.
#[inline(always)]
unsafe fn pow_(a: f64, b: f64) -> f64 {
    if b == trunc(b) && f64::from_bits(b.to_bits() & !(1u64 << 63)) <= 64.0 {
        __powidf2(a, b as i32)
    } else {
        // Hidden from the optimiser, which would turn `pow(a, 0.5)` into a square root.
        pow(a, core::hint::black_box(b))
    }
}

unsafe extern "C" {
    fn trunc(x: f64) -> f64;
}

/// The square root (IEEE, correctly rounded, as `f64::sqrt`). On x86-64 the SSE2
/// instruction itself: the C library's `sqrt`, which LLVM inlines as that instruction
/// behind a test and a call for negative arguments (to set `errno`), cut the code into
/// basic blocks at every square root.
#[inline(always)]
fn sqrt_(a: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    #[allow(unused_unsafe)]
    unsafe {
        use core::arch::x86_64::{_mm_cvtsd_f64, _mm_set_sd, _mm_sqrt_pd};
        _mm_cvtsd_f64(_mm_sqrt_pd(_mm_set_sd(a)))
    }
    #[cfg(not(target_arch = "x86_64"))]
    unsafe {
        sqrt(a)
    }
}
"#;

impl Function {
    /// This function as the text of a self-contained Rust module: `no_std`, no allocation,
    /// no dependency (the math functions are the C library's, which Rust's `std` calls
    /// too, and square roots correctly rounded as `f64::sqrt`, so the results equal the
    /// tape's bit for bit on the same platform, but for the sign and payload of NaNs,
    /// which rustc need not keep). It defines the constants `INPUT_SIZES`, `OUTPUT_SIZES`
    /// and `WORK_SIZE` and
    /// `pub fn eval(inputs: &[&[f64]], outputs: &mut [&mut [f64]], work: &mut [f64]) -> Result<(), &'static str>`
    /// (wrong counts or lengths are an `Err` naming the argument). Include it with
    /// `include!` from a build script's output (docs/dsl.md has the recipe).
    ///
    /// `Err` for operations the module cannot compute exactly without a dependency:
    /// lookup tables, `erf`, `asinh`, `acosh`, `atanh`.
    pub fn to_rust(&self) -> Result<String, SymxError> {
        self.to_rust_with(&SourceOptions::default())
    }

    /// [`Function::to_rust`], with each output's sparsity pattern from `options` in the
    /// constant `OUTPUT_SPARSITY: [Pattern; n_outputs]` (a `Pattern` holds `nrows`, `ncols`,
    /// `col_ptr` and `row_idx`, compressed columns; a dense column where none is given).
    ///
    /// ```
    /// use symx::{jacobian, Function, Matrix, SourceOptions};
    /// let x = Matrix::sym_vec("x", 2);
    /// let j = jacobian(&[x[0] * x[1], x[1].sin()], &x).unwrap();
    /// let f = Function::new(&[&x], &[j.values()]).unwrap();
    /// let options = SourceOptions { output_sparsity: vec![Some(j.sparsity().clone())] };
    /// let module = f.to_rust_with(&options).unwrap();
    /// assert!(module.contains("pub const OUTPUT_SPARSITY: [Pattern; 1]"));
    /// ```
    pub fn to_rust_with(&self, options: &SourceOptions) -> Result<String, SymxError> {
        self.refuse_external("to_rust")?;
        let patterns = options.output_patterns(self)?;
        let mut w = Writer {
            out: String::new(),
            names: FxHashMap::default(),
        };
        let native = self.for_native();
        let main = w.function(&native)?;
        let mut o = String::new();
        let list = |v: &[usize]| {
            v.iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        writeln!(
            o,
            "// Generated by symx from the function '{}'. Do not edit.",
            self.name
        )
        .unwrap();
        writeln!(o, "#[allow(clippy::all, unused_parens, unused_unsafe, unsafe_op_in_unsafe_fn, dead_code, unused_variables)]").unwrap();
        writeln!(o, "mod generated {{").unwrap();
        o.push_str(PRELUDE);
        o.push_str(&w.out);
        writeln!(
            o,
            "/// Entries of each input.\npub const INPUT_SIZES: [usize; {}] = [{}];",
            self.input_sizes.len(),
            list(&self.input_sizes)
        )
        .unwrap();
        writeln!(
            o,
            "/// Entries of each output.\npub const OUTPUT_SIZES: [usize; {}] = [{}];",
            self.output_sizes.len(),
            list(&self.output_sizes)
        )
        .unwrap();
        writeln!(
            o,
            "/// Length of the work vector (the temporaries only).\npub const WORK_SIZE: usize = {};",
            packed_work_need(&native)
        )
        .unwrap();
        writeln!(
            o,
            "/// A sparsity pattern in compressed columns: the nonzeros of column `j` are in rows\n/// `row_idx[col_ptr[j]..col_ptr[j + 1]]`.\n#[derive(Clone, Copy, Debug)]\npub struct Pattern {{\n    pub nrows: usize,\n    pub ncols: usize,\n    pub col_ptr: &'static [usize],\n    pub row_idx: &'static [usize],\n}}"
        )
        .unwrap();
        let patterns: Vec<String> = patterns
            .iter()
            .map(|p| {
                format!(
                    "Pattern {{ nrows: {}, ncols: {}, col_ptr: &[{}], row_idx: &[{}] }}",
                    p.nrows(),
                    p.ncols(),
                    list(p.col_ptr()),
                    list(p.row_idx())
                )
            })
            .collect();
        writeln!(
            o,
            "/// The sparsity pattern of each output (its entries are the nonzeros, column by column).\npub const OUTPUT_SPARSITY: [Pattern; {}] = [{}];",
            patterns.len(),
            patterns.join(", ")
        )
        .unwrap();
        write!(
            o,
            r#"/// Evaluates: `inputs[k]` holds `INPUT_SIZES[k]` numbers, `outputs[k]` `OUTPUT_SIZES[k]`,
/// `work` at least `WORK_SIZE`. Allocates nothing.
pub fn eval(inputs: &[&[f64]], outputs: &mut [&mut [f64]], work: &mut [f64]) -> Result<(), &'static str> {{
    if inputs.len() != INPUT_SIZES.len() {{ return Err("wrong number of inputs"); }}
    if outputs.len() != OUTPUT_SIZES.len() {{ return Err("wrong number of outputs"); }}
    if inputs.iter().zip(INPUT_SIZES).any(|(x, n)| x.len() != n) {{ return Err("an input has the wrong length"); }}
    if outputs.iter().zip(OUTPUT_SIZES).any(|(y, n)| y.len() != n) {{ return Err("an output has the wrong length"); }}
    if work.len() < WORK_SIZE {{ return Err("the work vector is too short"); }}
    let mut x = [core::ptr::null::<f64>(); {ni}];
    for (p, v) in x.iter_mut().zip(inputs) {{ *p = v.as_ptr(); }}
    let mut y = [core::ptr::null_mut::<f64>(); {no}];
    for (p, v) in y.iter_mut().zip(outputs.iter_mut()) {{ *p = v.as_mut_ptr(); }}
    // SAFETY: every input and output has its length and the work vector holds WORK_SIZE
    // numbers, the bound of every temporary.
    unsafe {{ {main}(work.as_mut_ptr(), x.as_ptr(), y.as_ptr()) }};
    Ok(())
}}
}}
#[allow(unused_imports)]
pub use generated::{{eval, Pattern, INPUT_SIZES, OUTPUT_SIZES, OUTPUT_SPARSITY, WORK_SIZE}};
"#,
            ni = self.input_offsets.len(),
            no = self.output_offsets.len(),
        )
        .unwrap();
        Ok(o)
    }
}
