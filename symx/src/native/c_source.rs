//! [`Function::to_c`]: a function as a self-contained C file with CasADi's calling
//! convention, for embedding in firmware or in other languages (and for CasADi's
//! `external`).
//!
//! The file defines, for a function named `f` (CasADi's generated code exposes the same):
//! `int f(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem)`,
//! `f_n_in`, `f_n_out`, `f_name_in`, `f_name_out`, `f_sparsity_in`, `f_sparsity_out`,
//! `f_default_in`, `f_work`, `f_work_bytes`, `f_checkout`, `f_release`, `f_incref`,
//! `f_decref`. A null `arg[k]` reads as zeros and a null `res[k]` is not written, as in
//! CasADi. It allocates nothing and keeps no state: `w` (`f_work`'s `sz_w` numbers) is
//! the only scratch, so calls on distinct `w` may run in parallel. As in the generated Rust
//! (`super::places`), inputs are read where `arg` points, outputs written where `res`
//! points and constants are literals: `w` holds the temporaries only (plus the output
//! entries the computation reads back, which a null `res[k]` must not lose).
use super::places::{call_layout, constant_outputs, places, read, work_need, Place};
use super::{library_binary, library_unary, unsupported, SourceOptions};
use crate::error::SymxError;
use crate::function::{Function, Instr};
use crate::op::Op;
use crate::sparsity::Sparsity;
use rustc_hash::FxHashMap;
use std::fmt::Write;

/// Tape instructions per generated C function (keeps the C compiler's time linear).
const CHUNK: usize = 1024;

struct Writer {
    prefix: String,
    out: String,
    /// Generated function name of each function met, by identity.
    names: FxHashMap<u64, String>,
}

/// Where the C code of one function keeps its registers (see [`places`]). For the function
/// called through the interface (`top`), a null `res[k]` skips output `k`, as in CasADi:
/// its entries are written only `if (yk)`, and the entries the tape reads back get a slot
/// of their own in the work vector after everything else (`w[work_need(f) + j]`).
struct Registers {
    places: Vec<Place>,
    /// For each register of the top function, the output entry `(k, i)` it also goes to
    /// (only `if (yk)`), when it holds one.
    optional_output: Vec<Option<(usize, usize)>>,
    /// The work vector's length.
    work: usize,
}

impl Registers {
    fn of(f: &Function, top: bool) -> Self {
        let mut places = places(f);
        let mut optional_output = vec![None; f.work_size];
        let mut work = work_need(f);
        if top {
            let read = read(f);
            for (k, (&n, &at)) in f.output_sizes.iter().zip(&f.output_offsets).enumerate() {
                for i in 0..n {
                    optional_output[at + i] = Some((k, i));
                    if read[at + i] {
                        places[at + i] = Place::Work(work);
                        work += 1;
                    }
                }
            }
        }
        Registers {
            places,
            optional_output,
            work,
        }
    }

    /// The C expression reading register `r`.
    fn get(&self, r: u32) -> String {
        match self.places[r as usize] {
            Place::Input(k, i) => format!("x{k}[{i}]"),
            Place::Output(k, i) => format!("y{k}[{i}]"),
            Place::Constant(v) => literal(v),
            Place::Work(j) => format!("w[{j}]"),
        }
    }

    /// The C statements setting register `r` to `v`.
    fn set(&self, r: u32, v: &str) -> String {
        let optional = self.optional_output[r as usize];
        match (self.places[r as usize], optional) {
            (Place::Work(j), Some((k, i))) => {
                format!("  w[{j}] = {v};\n  if (y{k}) y{k}[{i}] = w[{j}];\n")
            }
            (_, Some((k, i))) => format!("  if (y{k}) y{k}[{i}] = {v};\n"),
            _ => format!("  {} = {v};\n", self.get(r)),
        }
    }
}

/// A C literal with the exact bits of `v`: Rust's shortest round-trip decimal, which C
/// compilers read back correctly rounded; infinities and NaNs by their bits.
fn literal(v: f64) -> String {
    if v.is_finite() {
        format!("{v:e}")
    } else {
        format!("symx_f64({:#x}ULL)", v.to_bits())
    }
}

/// The signature of every generated function running (part of) a tape: inputs at `x[k]`,
/// outputs to `y[k]`, temporaries in `w`.
const EXEC_PARAMS: &str = "(casadi_real* w, const casadi_real* const* x, casadi_real* const* y)";

impl Writer {
    /// Emits `f` (callees first) and returns the name of its C function running the tape
    /// (see [`EXEC_PARAMS`]); `top` for the function called through the interface.
    fn function(&mut self, f: &Function, top: bool) -> Result<String, SymxError> {
        if let Some(n) = self.names.get(&f.uid) {
            return Ok(n.clone());
        }
        let mut callees = Vec::new();
        for c in &f.calls {
            callees.push(self.function(&c.function, false)?);
        }
        let name = format!("{}_exec{}", self.prefix, self.names.len());
        let regs = Registers::of(f, top);
        let mut chunks = Vec::new();
        for (k, part) in f.tape.chunks(CHUNK).enumerate() {
            let mut body = String::new();
            for ins in part {
                if ins.op == Op::Call {
                    call(&mut body, f, ins, &callees[ins.d as usize], &regs);
                    continue;
                }
                let v = value(ins, &regs)?;
                body.push_str(&regs.set(ins.d, &v));
            }
            let chunk = format!("{name}_{k}");
            self.emit(&chunk, f, &body);
            chunks.push(chunk);
        }
        let mut body = String::new();
        for (k, i, v) in constant_outputs(f) {
            let r = f.output_offsets[k] + i;
            body.push_str(&regs.set(r as u32, &literal(v)));
        }
        for c in &chunks {
            writeln!(body, "  {c}(w, x, y);").unwrap();
        }
        self.emit(&name, f, &body);
        self.names.insert(f.uid, name.clone());
        Ok(name)
    }

    /// Writes the C function `name` running `body`, binding the inputs and outputs it uses.
    fn emit(&mut self, name: &str, f: &Function, body: &str) {
        let o = &mut self.out;
        writeln!(o, "static void {name}{EXEC_PARAMS} {{").unwrap();
        for k in (0..f.input_sizes.len()).filter(|k| body.contains(&format!("x{k}["))) {
            writeln!(o, "  const casadi_real* x{k} = x[{k}];").unwrap();
        }
        for k in (0..f.output_sizes.len()).filter(|k| body.contains(&format!("y{k}"))) {
            writeln!(o, "  casadi_real* y{k} = y[{k}];").unwrap();
        }
        writeln!(o, "  (void)w; (void)x; (void)y;\n{body}}}\n").unwrap();
    }
}

/// The C expression of the value `ins` computes (any instruction but a call).
fn value(ins: &Instr, regs: &Registers) -> Result<String, SymxError> {
    let (a, b, c) = (regs.get(ins.a), regs.get(ins.b), regs.get(ins.c));
    let t = |cond: String| format!("(({cond}) ? 1.0 : 0.0)");
    Ok(match ins.op {
        Op::Add => format!("{a} + {b}"),
        Op::Sub => format!("{a} - {b}"),
        Op::Mul => format!("{a} * {b}"),
        Op::Div => format!("{a} / {b}"),
        Op::Neg => format!("-{a}"),
        Op::Sq => format!("{a} * {a}"),
        Op::Sym => a,
        Op::Abs => format!("fabs({a})"),
        Op::Sign => format!("symx_sign({a})"),
        Op::Not => t(format!("{a} == 0.0")),
        Op::Pow => format!("symx_pow({a}, {b})"),
        Op::Min => format!("symx_min({a}, {b})"),
        Op::Max => format!("symx_max({a}, {b})"),
        Op::Lt => t(format!("{a} < {b}")),
        Op::Le => t(format!("{a} <= {b}")),
        Op::Eq => t(format!("{a} == {b}")),
        Op::Ne => t(format!("{a} != {b}")),
        Op::And => t(format!("{a} != 0.0 && {b} != 0.0")),
        Op::Or => t(format!("{a} != 0.0 || {b} != 0.0")),
        Op::StrongMul => format!("{a} == 0.0 ? 0.0 : {a} * {b}"),
        Op::IfElse => format!("{a} != 0.0 ? {b} : {c}"),
        op => match (library_unary(op), library_binary(op)) {
            (Some(h), _) => format!("{h}({a})"),
            (_, Some(h)) => format!("{h}({a}, {b})"),
            _ => return Err(unsupported("C", op)),
        },
    })
}

/// A call of another function (generated as `callee`): its arguments gathered into the
/// scratch block, laid out as its inputs, its outputs written straight into the call's
/// block of registers (as the generated Rust does).
fn call(o: &mut String, f: &Function, ins: &Instr, callee: &str, regs: &Registers) {
    let layout = call_layout(f, ins);
    for &(at, r) in &layout.args {
        writeln!(o, "  w[{at}] = {};", regs.get(r)).unwrap();
    }
    let xs: Vec<String> = layout.inputs.iter().map(|at| format!("w + {at}")).collect();
    let ys: Vec<String> = layout
        .outputs
        .iter()
        .map(|at| format!("w + {at}"))
        .collect();
    let one = |v: Vec<String>| {
        if v.is_empty() {
            "0".to_string()
        } else {
            v.join(", ")
        }
    };
    writeln!(
        o,
        "  {{ const casadi_real* const xc[] = {{{}}}; casadi_real* const yc[] = {{{}}}; {callee}(w + {}, xc, yc); }}",
        one(xs),
        one(ys),
        layout.callee_work
    )
    .unwrap();
}

/// CasADi's compressed column format: `nrow, ncol, colind[ncol + 1], row[nnz]`.
fn casadi_sparsity(s: &Sparsity) -> Vec<usize> {
    let mut v = vec![s.nrows(), s.ncols()];
    v.extend(s.col_ptr());
    v.extend(s.row_idx());
    v
}

/// A `switch` over `items` returning each, `default_` otherwise.
fn switch(items: &[String], default_: &str) -> String {
    let mut s = String::from("  switch (i) {\n");
    for (k, it) in items.iter().enumerate() {
        writeln!(s, "    case {k}: return {it};").unwrap();
    }
    writeln!(s, "    default: return {default_};\n  }}").unwrap();
    s
}

/// A C string literal of `s` (printable ASCII kept, everything else escaped as octal).
fn c_string(s: &str) -> String {
    let mut out = String::from("\"");
    for b in s.bytes() {
        match b {
            b'"' | b'\\' => {
                out.push('\\');
                out.push(b as char);
            }
            0x20..=0x7e => out.push(b as char),
            _ => write!(out, "\\{b:03o}").unwrap(),
        }
    }
    out.push('"');
    out
}

const PRELUDE: &str = r#"#include <math.h>
#include <string.h>

#ifndef casadi_real
#define casadi_real double
#endif

#ifndef casadi_int
#define casadi_int long long int
#endif

/* The generated code copies IEEE doubles by their bits: casadi_real must be double. */
typedef char PREFIX_casadi_real_is_double[sizeof(casadi_real) == 8 ? 1 : -1];

#ifndef CASADI_SYMBOL_EXPORT
  #if defined(_WIN32) || defined(__WIN32__) || defined(__CYGWIN__)
    #if defined(STATIC_LINKED)
      #define CASADI_SYMBOL_EXPORT
    #else
      #define CASADI_SYMBOL_EXPORT __declspec(dllexport)
    #endif
  #elif defined(__GNUC__) && defined(GCC_HASCLASSVISIBILITY)
    #define CASADI_SYMBOL_EXPORT __attribute__ ((visibility ("default")))
  #else
    #define CASADI_SYMBOL_EXPORT
  #endif
#endif

/* The double with the bits b (the infinite and NaN constants, payloads included). */
static inline casadi_real symx_f64(unsigned long long b) {
  casadi_real v;
  memcpy(&v, &b, sizeof v);
  return v;
}

/* symx's sign: 1 above 0, -1 below, else a * 0 (signed zeros, NaN). */
static inline casadi_real symx_sign(casadi_real a) {
  return a > 0.0 ? 1.0 : a < 0.0 ? -1.0 : a * 0.0;
}

/* Rust's f64::min and f64::max as compiled for x86-64 (a NaN operand yields the other;
   of two equal operands, zeros of either sign, the first). */
static inline casadi_real symx_min(casadi_real a, casadi_real b) {
  return a != a ? b : b < a ? b : a;
}
static inline casadi_real symx_max(casadi_real a, casadi_real b) {
  return a != a ? b : b > a ? b : a;
}

/* Integer powers by squaring, the products Rust's f64::powi computes. */
static inline casadi_real symx_powi(casadi_real a, int b) {
  unsigned int n = b < 0 ? 0u - (unsigned int)b : (unsigned int)b;
  casadi_real r = 1.0;
  for (;;) {
    if (n & 1u) r *= a;
    n >>= 1;
    if (n == 0) break;
    a *= a;
  }
  return b < 0 ? 1.0 / r : r;
}

/* symx's pow: integer exponents up to 64 by powi, others by the C library's pow. */
static inline casadi_real symx_pow(casadi_real a, casadi_real b) {
  return (b == trunc(b) && fabs(b) <= 64.0) ? symx_powi(a, (int)b) : pow(a, b);
}

"#;

impl Function {
    /// This function as a self-contained C file with CasADi's calling convention (what
    /// `casadi.Function.generate` writes), named after the function ([`Function::named`];
    /// `f` by default): `int f(const casadi_real** arg, casadi_real** res, casadi_int* iw,
    /// casadi_real* w, int mem)` and `f_n_in`, `f_n_out`, `f_name_in`, `f_name_out`,
    /// `f_sparsity_in`, `f_sparsity_out`, `f_default_in`, `f_work`, `f_work_bytes`,
    /// `f_checkout`, `f_release`, `f_incref`, `f_decref`. Every input and output is a dense
    /// column; [`Function::to_c_with`] gives outputs a sparsity pattern. No allocation, no
    /// state: `w` (`f_work`'s `sz_w` numbers, the temporaries only, plus the output
    /// entries the computation reads back) is the only scratch; `iw` is unused.
    ///
    /// Compiled without contraction of multiplies and adds into FMAs (`-ffp-contract=off`,
    /// which gcc's and clang's ISO modes `-std=c99`/`c11` imply; never `-ffast-math`), it
    /// computes what the tape computes bit for bit on the same platform (the math
    /// functions are the C library's, which Rust's `std` calls too), up to the sign and
    /// payload of NaNs.
    ///
    /// `Err` naming what cannot be generated: a function name that is not a C identifier,
    /// lookup tables, `erf`, `asinh`, `acosh`, `atanh` (no exact C library counterpart).
    ///
    /// ```
    /// use symx::{Function, Matrix};
    /// let x = Matrix::sym_vec("x", 2);
    /// let f = Function::named("rosen", &[("x", &x)], &[("r", &[x[0] * x[1].sin()])]).unwrap();
    /// let c = f.to_c().unwrap();
    /// assert!(c.contains("int rosen(const casadi_real** arg, casadi_real** res"));
    /// ```
    pub fn to_c(&self) -> Result<String, SymxError> {
        self.to_c_with(&SourceOptions::default())
    }

    /// [`Function::to_c`] with output sparsity patterns (`f_sparsity_out`) from `options`.
    pub fn to_c_with(&self, options: &SourceOptions) -> Result<String, SymxError> {
        self.refuse_external("to_c")?;
        let name = self.name.as_str();
        let valid = name
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !valid {
            return Err(SymxError::Jit {
                message: format!(
                    "the function name '{name}' is not a C identifier (name it with Function::named)"
                ),
            });
        }
        let outputs = options.output_patterns(self)?;
        let mut w = Writer {
            prefix: format!("{name}_symx"),
            out: String::new(),
            names: FxHashMap::default(),
        };
        let native = self.for_native();
        let main = w.function(&native, true)?;
        let mut o = String::new();
        writeln!(
            o,
            "/* Generated by symx from the function '{name}' (CasADi's calling convention). Do not edit.\n   Compile without FMA contraction (-ffp-contract=off, implied by -std=c99) for results\n   bit-identical to symx's. */\n#ifdef __cplusplus\nextern \"C\" {{\n#endif\n"
        )
        .unwrap();
        o.push_str(&PRELUDE.replace("PREFIX", name));
        o.push_str(&w.out);

        let (n_in, n_out) = (self.input_sizes.len(), self.output_sizes.len());
        let inputs: Vec<Sparsity> = self.input_sizes.iter().map(|&n| dense(n)).collect();
        for (k, s) in inputs.iter().chain(&outputs).enumerate() {
            let v = casadi_sparsity(s);
            let list: Vec<String> = v.iter().map(|x| x.to_string()).collect();
            writeln!(
                o,
                "static const casadi_int {name}_s{k}[{}] = {{{}}};",
                v.len(),
                list.join(", ")
            )
            .unwrap();
        }
        let sp_in: Vec<String> = (0..n_in).map(|k| format!("{name}_s{k}")).collect();
        let sp_out: Vec<String> = (0..n_out)
            .map(|k| format!("{name}_s{}", n_in + k))
            .collect();
        let names_in: Vec<String> = self.input_names.iter().map(|s| c_string(s)).collect();
        let names_out: Vec<String> = self.output_names.iter().map(|s| c_string(s)).collect();

        let mut bind = String::new();
        for k in 0..n_in {
            writeln!(bind, "  x[{k}] = arg[{k}] ? arg[{k}] : {name}_zeros;").unwrap();
        }
        for k in 0..n_out {
            writeln!(bind, "  y[{k}] = res[{k}];").unwrap();
        }
        let zeros = self.input_sizes.iter().copied().max().unwrap_or(0).max(1);
        let work = Registers::of(&native, true).work;
        write!(
            o,
            r#"
/* Read for a null arg[k]. */
static const casadi_real {name}_zeros[{zeros}] = {{0}};

/* {name}: the inputs are read where arg points (null: zeros), the outputs written where res
   points (null: skipped); w holds {work} numbers: the temporaries only (and the output
   entries the computation reads back). */
CASADI_SYMBOL_EXPORT int {name}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {{
  const casadi_real* x[{xn}];
  casadi_real* y[{yn}];
  (void)iw; (void)mem;
{bind}  {main}(w, x, y);
  return 0;
}}

CASADI_SYMBOL_EXPORT int {name}_alloc_mem(void) {{ return 0; }}
CASADI_SYMBOL_EXPORT int {name}_init_mem(int mem) {{ (void)mem; return 0; }}
CASADI_SYMBOL_EXPORT void {name}_free_mem(int mem) {{ (void)mem; }}
CASADI_SYMBOL_EXPORT int {name}_checkout(void) {{ return 0; }}
CASADI_SYMBOL_EXPORT void {name}_release(int mem) {{ (void)mem; }}
CASADI_SYMBOL_EXPORT void {name}_incref(void) {{}}
CASADI_SYMBOL_EXPORT void {name}_decref(void) {{}}

CASADI_SYMBOL_EXPORT casadi_int {name}_n_in(void) {{ return {n_in}; }}
CASADI_SYMBOL_EXPORT casadi_int {name}_n_out(void) {{ return {n_out}; }}

CASADI_SYMBOL_EXPORT casadi_real {name}_default_in(casadi_int i) {{
  (void)i;
  return 0;
}}

CASADI_SYMBOL_EXPORT const char* {name}_name_in(casadi_int i) {{
{names_in}}}

CASADI_SYMBOL_EXPORT const char* {name}_name_out(casadi_int i) {{
{names_out}}}

CASADI_SYMBOL_EXPORT const casadi_int* {name}_sparsity_in(casadi_int i) {{
{sp_in}}}

CASADI_SYMBOL_EXPORT const casadi_int* {name}_sparsity_out(casadi_int i) {{
{sp_out}}}

CASADI_SYMBOL_EXPORT int {name}_work(casadi_int* sz_arg, casadi_int* sz_res, casadi_int* sz_iw, casadi_int* sz_w) {{
  if (sz_arg) *sz_arg = {n_in};
  if (sz_res) *sz_res = {n_out};
  if (sz_iw) *sz_iw = 0;
  if (sz_w) *sz_w = {work};
  return 0;
}}

CASADI_SYMBOL_EXPORT int {name}_work_bytes(casadi_int* sz_arg, casadi_int* sz_res, casadi_int* sz_iw, casadi_int* sz_w) {{
  if (sz_arg) *sz_arg = {n_in} * sizeof(const casadi_real*);
  if (sz_res) *sz_res = {n_out} * sizeof(casadi_real*);
  if (sz_iw) *sz_iw = 0;
  if (sz_w) *sz_w = {work} * sizeof(casadi_real);
  return 0;
}}

#ifdef __cplusplus
}} /* extern "C" */
#endif
"#,
            xn = n_in.max(1),
            yn = n_out.max(1),
            names_in = switch(&names_in, "0"),
            names_out = switch(&names_out, "0"),
            sp_in = switch(&sp_in, "0"),
            sp_out = switch(&sp_out, "0"),
        )
        .unwrap();
        Ok(o)
    }
}

/// The dense `n × 1` column pattern.
pub(super) fn dense(n: usize) -> Sparsity {
    Sparsity::new_checked(n, 1, vec![0, n], None, (0..n).collect())
}
