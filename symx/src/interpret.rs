//! The tape's interpreter: the program it runs, built from a [`Function`]'s tape, and the
//! loop that runs it.
//!
//! An interpreter's cost is mostly its dispatch (one indirect jump per instruction) and
//! the round trip of every result through the work vector, not the arithmetic. The
//! program is the tape with adjacent pairs fused into one step where the first
//! instruction's result is a temporary read only by the next one: `w[d] = (w[a] ∘ w[b]) •
//! w[c]` or `w[c] • (w[a] ∘ w[b])` for `∘` one of `+ − ×` and `•` one of `+ − × ÷`.
//! Derivative tapes are full of such chains (a Hessian's `a·b + c`, `a·b − c`, `(a·b)·k`):
//! the Lagrangian Hessian of one RK4 interval runs its 142 instructions in 93 steps.
//!
//! A fused step computes the two operations in the same order with the same roundings
//! (Rust never contracts `a·b + c` into a fused multiply-add), so its values are the
//! tape's bit for bit, NaN payloads included (x86 returns the first operand's NaN); only
//! the write of the temporary, which nothing reads, is skipped. The compiler is free to
//! swap the operands of a commutative operation, which changes which of two NaNs comes
//! out: additions and multiplications are written out on x86-64 ([`add`], [`mul`]), and
//! `−(w[a] ∘ w[b])` is not fused (the negation may move into the product).
//! `tests/jit.rs` compares every pair with the JIT on NaN payloads.
//!
//! The dispatch's jump is predicted when equal steps follow each other: compilation
//! orders the tape so that they do (`schedule.rs`), with the pairs to fuse kept adjacent.
//! A tape whose runs of equal steps are long then runs run by run, each run in a loop of
//! its own with the operation known (one dispatch per run, not per step: the gap model's
//! Jacobian and Hessian ran in half the time), and a tape in depth-first order step by
//! step ([`run`]).
//!
//! The instructions are stored only as this program ([`Tape`]); the native code
//! generators, the dependency analysis and serialization read them back exactly.
use crate::call::CallInstr;
use crate::function::{Function, Instr};
use crate::op::{self, Op};
use std::sync::OnceLock;

/// How a step computes its value (the tape's operations, then the fused pairs).
///
/// `XY` is `(w[a] X w[b]) Y w[c]`, `XYRev` is `w[c] Y (w[a] X w[b])`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(crate) enum Code {
    Sym,
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
    Not,
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Atan2,
    Min,
    Max,
    Lt,
    Le,
    Eq,
    Ne,
    And,
    Or,
    StrongMul,
    IfElse,
    Floor,
    Ceil,
    Erf,
    Asinh,
    Acosh,
    Atanh,
    Log1p,
    Expm1,
    Fmod,
    Hypot,
    Interpolant,
    Interpolant2,
    InterpolantN,
    Call,
    AddAdd,
    AddSub,
    AddMul,
    AddDiv,
    SubAdd,
    SubSub,
    SubMul,
    SubDiv,
    MulAdd,
    MulSub,
    MulMul,
    MulDiv,
    AddAddRev,
    AddSubRev,
    AddMulRev,
    AddDivRev,
    SubAddRev,
    SubSubRev,
    SubMulRev,
    SubDivRev,
    MulAddRev,
    MulSubRev,
    MulMulRev,
    MulDivRev,
}

impl Code {
    /// The step running one tape instruction of operation `op` as it is.
    pub(crate) fn plain(op: Op) -> Code {
        match op {
            Op::Sym => Code::Sym,
            Op::Neg => Code::Neg,
            Op::Sq => Code::Sq,
            Op::Sqrt => Code::Sqrt,
            Op::Exp => Code::Exp,
            Op::Log => Code::Log,
            Op::Sin => Code::Sin,
            Op::Cos => Code::Cos,
            Op::Tan => Code::Tan,
            Op::Asin => Code::Asin,
            Op::Acos => Code::Acos,
            Op::Atan => Code::Atan,
            Op::Sinh => Code::Sinh,
            Op::Cosh => Code::Cosh,
            Op::Tanh => Code::Tanh,
            Op::Abs => Code::Abs,
            Op::Sign => Code::Sign,
            Op::Not => Code::Not,
            Op::Add => Code::Add,
            Op::Sub => Code::Sub,
            Op::Mul => Code::Mul,
            Op::Div => Code::Div,
            Op::Pow => Code::Pow,
            Op::Atan2 => Code::Atan2,
            Op::Min => Code::Min,
            Op::Max => Code::Max,
            Op::Lt => Code::Lt,
            Op::Le => Code::Le,
            Op::Eq => Code::Eq,
            Op::Ne => Code::Ne,
            Op::And => Code::And,
            Op::Or => Code::Or,
            Op::StrongMul => Code::StrongMul,
            Op::IfElse => Code::IfElse,
            Op::Floor => Code::Floor,
            Op::Ceil => Code::Ceil,
            Op::Erf => Code::Erf,
            Op::Asinh => Code::Asinh,
            Op::Acosh => Code::Acosh,
            Op::Atanh => Code::Atanh,
            Op::Log1p => Code::Log1p,
            Op::Expm1 => Code::Expm1,
            Op::Fmod => Code::Fmod,
            Op::Hypot => Code::Hypot,
            Op::Interpolant => Code::Interpolant,
            Op::Interpolant2 => Code::Interpolant2,
            Op::InterpolantN => Code::InterpolantN,
            Op::Call => Code::Call,
            // Constants live in the template, call outputs in their call's block.
            Op::Const | Op::CallOutput => unreachable!("{op:?} is never a tape instruction"),
        }
    }

    /// The step computing `second(first(w[a], w[b]), w[c])` (`rev`: `second(w[c], …)`),
    /// or `None` if that pair has no step.
    pub(crate) fn fused(first: Op, second: Op, rev: bool) -> Option<Code> {
        let i = FIRST.iter().position(|&o| o == first)?;
        let j = SECOND.iter().position(|&o| o == second)?;
        Some(FUSED[usize::from(rev)][i][j])
    }

    /// The `(first, second, rev)` a fused code runs ([`Code::fused`] inverted).
    fn pair(self) -> Option<(Op, Op, bool)> {
        (0..2).find_map(|rev| {
            (0..FIRST.len()).find_map(|i| {
                (0..SECOND.len())
                    .find(|&j| FUSED[rev][i][j] == self)
                    .map(|j| (FIRST[i], SECOND[j], rev == 1))
            })
        })
    }
}

/// The first operations a fused step can run, the second ones, and the code of each pair
/// (`FUSED[rev][first][second]`).
const FIRST: [Op; 3] = [Op::Add, Op::Sub, Op::Mul];
const SECOND: [Op; 4] = [Op::Add, Op::Sub, Op::Mul, Op::Div];
const FUSED: [[[Code; 4]; 3]; 2] = {
    use Code::*;
    [
        [
            [AddAdd, AddSub, AddMul, AddDiv],
            [SubAdd, SubSub, SubMul, SubDiv],
            [MulAdd, MulSub, MulMul, MulDiv],
        ],
        [
            [AddAddRev, AddSubRev, AddMulRev, AddDivRev],
            [SubAddRev, SubSubRev, SubMulRev, SubDivRev],
            [MulAddRev, MulSubRev, MulMulRev, MulDivRev],
        ],
    ]
};

/// One step of the program: `w[d] = code(w[a], w[b], w[c])`, registers (and table or
/// call indices) as in the tape's [`Instr`]; `op` is the instruction's operation (the code
/// of a fused pair says both). A fused pair also records the register `t` its first
/// instruction wrote, which its second read beside its other operand `w[c]`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Step {
    code: Code,
    op: Op,
    d: u32,
    a: u32,
    b: u32,
    c: u32,
    t: u32,
}

/// A function's instructions, kept as the program that runs them ([`Tape::new`]).
///
/// Iterating gives the instructions back exactly as compiled, without allocating; the
/// native code generators, which index them, dereference the tape to a slice made on
/// first use (so only a function compiled to native code keeps both).
#[derive(Clone, Debug, Default)]
pub(crate) struct Tape {
    steps: Vec<Step>,
    /// Where each maximal run of equal codes ends (run k is
    /// `steps[run_ends[k-1]..run_ends[k]]`); empty when the program runs step by step.
    run_ends: Vec<u32>,
    len: usize,
    instrs: OnceLock<Vec<Instr>>,
}

/// Runs of equal codes must average this many steps for the program to run run by run
/// ([`run`]). Each run ends with a loop exit the branch predictor cannot know in advance;
/// on short runs that costs more than the dispatch it saves. Measured in one program
/// (criterion, an environment switch between the two loops): the gap model's regrouped
/// tapes (≈ 300 steps per run) ran ∇f / J / H in 1.9–2.1 / 22–25 / 36–44 µs run by run
/// against 2.3–2.7 / 45–53 / 74–81 µs step by step; the hanging chain's Hessian
/// (depth-first, 1.67 steps per run) in 23–24 µs against 10–11.
const MIN_STEPS_PER_RUN: usize = 4;

/// Where the maximal runs of equal codes of `steps` end, or nothing when the runs are too
/// short to pay ([`MIN_STEPS_PER_RUN`]).
fn run_ends(steps: &[Step]) -> Vec<u32> {
    let ends =
        || (1..=steps.len()).filter(|&k| k == steps.len() || steps[k].code != steps[k - 1].code);
    if ends().count() * MIN_STEPS_PER_RUN > steps.len() {
        return Vec::new();
    }
    ends().map(|k| k as u32).collect()
}

impl Tape {
    /// The tape of `instrs`, whose `calls` are the function's, in a work vector of
    /// `work_size` registers of which `outputs` (ranges) are read after the last step.
    pub(crate) fn new(
        instrs: Vec<Instr>,
        calls: &[CallInstr],
        work_size: usize,
        outputs: impl Iterator<Item = std::ops::Range<usize>>,
    ) -> Tape {
        let dead = dead_after_next(&instrs, calls, work_size, outputs);
        let mut steps = Vec::with_capacity(instrs.len());
        let mut i = 0;
        while i < instrs.len() {
            let ins = instrs[i];
            match instrs
                .get(i + 1)
                .filter(|_| dead[i])
                .and_then(|&n| fuse(ins, n))
            {
                Some(step) => {
                    steps.push(step);
                    i += 2;
                }
                None => {
                    steps.push(Step {
                        code: Code::plain(ins.op),
                        op: ins.op,
                        d: ins.d,
                        a: ins.a,
                        b: ins.b,
                        c: ins.c,
                        t: ins.d,
                    });
                    i += 1;
                }
            }
        }
        steps.shrink_to_fit();
        let run_ends = run_ends(&steps);
        Tape {
            run_ends,
            steps,
            len: instrs.len(),
            instrs: OnceLock::new(),
        }
    }

    /// The steps, in the order they run.
    #[cfg(test)]
    pub(crate) fn steps(&self) -> &[Step] {
        &self.steps
    }

    /// Number of instructions.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// The instructions, exactly as compiled.
    pub(crate) fn instructions(&self) -> impl Iterator<Item = Instr> + '_ {
        self.steps.iter().flat_map(|s| {
            let (instrs, n) = s.instrs();
            instrs.into_iter().take(n)
        })
    }
}

impl std::ops::Deref for Tape {
    type Target = [Instr];
    fn deref(&self) -> &[Instr] {
        self.instrs.get_or_init(|| self.instructions().collect())
    }
}

impl Step {
    /// How this step computes its value.
    #[cfg(test)]
    pub(crate) fn code(&self) -> Code {
        self.code
    }

    /// The one or two instructions this step runs (the first `n` of the array).
    fn instrs(&self) -> ([Instr; 2], usize) {
        let (d, a, b, c) = (self.d, self.a, self.b, self.c);
        let Some((op, second, rev)) = self.code.pair() else {
            let op = self.op;
            return ([Instr { op, d, a, b, c }; 2], 1);
        };
        let (t, o) = (self.t, self.c);
        let first = Instr {
            op,
            d: t,
            a,
            b,
            c: a,
        };
        let (a, b, c) = if rev { (o, t, o) } else { (t, o, t) };
        let op = second;
        ([first, Instr { op, d, a, b, c }], 2)
    }
}

/// The fused step running `first` then `second`, which reads `first`'s result exactly
/// once, or `None` if that pair has no code. Only pairs laid out as compilation lays them
/// out (a binary operation's `c` is its `a`) are fused, so that [`Tape::instructions`]
/// gives them back exactly.
fn fuse(first: Instr, second: Instr) -> Option<Step> {
    let t = first.d;
    if first.c != first.a || second.c != second.a {
        return None;
    }
    let (rev, other) = match (second.a == t, second.b == t) {
        (true, false) => (false, second.b),
        (false, true) => (true, second.a),
        _ => return None,
    };
    Some(Step {
        code: Code::fused(first.op, second.op, rev)?,
        op: first.op,
        d: second.d,
        a: first.a,
        b: first.b,
        c: other,
        t,
    })
}

/// For each instruction `i`: whether the value it writes is dead after instruction `i + 1`
/// (overwritten there, or not read later before being written again, and not an output), computed by
/// one backward pass over the tape. Irregular writes (a call's outputs) are ignored, which
/// only ever keeps a register live.
fn dead_after_next(
    tape: &[Instr],
    calls: &[CallInstr],
    work_size: usize,
    outputs: impl Iterator<Item = std::ops::Range<usize>>,
) -> Vec<bool> {
    let mut live = vec![false; work_size];
    for r in outputs {
        for slot in live.iter_mut().take(r.end).skip(r.start) {
            *slot = true;
        }
    }
    let mut dead = vec![false; tape.len()];
    for (i, ins) in tape.iter().enumerate().rev() {
        if i > 0 && tape[i - 1].op != Op::Call {
            // The value instruction `i − 1` wrote is dead after `i` if `i` overwrites it
            // or nothing later reads the register before it is written again.
            let t = tape[i - 1].d as usize;
            let overwritten = ins.op != Op::Call && ins.d as usize == t;
            dead[i - 1] = overwritten || !live[t];
        }
        match ins.op {
            Op::Call => {
                for &r in &calls[ins.d as usize].args {
                    live[r as usize] = true;
                }
            }
            Op::InterpolantN => {
                live[ins.d as usize] = false;
                for slot in &mut live[ins.a as usize..(ins.a + ins.b) as usize] {
                    *slot = true;
                }
            }
            _ => {
                live[ins.d as usize] = false;
                for r in ins.value_operands() {
                    live[r as usize] = true;
                }
            }
        }
    }
    dead
}

/// `a + b` computed with `a` as the first operand, so that of two NaNs `a`'s is returned
/// (as x86 does for the first operand and the JIT's code does): the compiler may swap a
/// commutative operation's operands, which changes which NaN comes out; on x86-64 the
/// instruction is written out to prevent that.
#[inline(always)]
fn add(a: f64, b: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        let mut v = a;
        // SAFETY: one SSE2 addition of two registers (SSE2 is part of x86-64).
        unsafe {
            std::arch::asm!("addsd {v}, {b}", v = inout(xmm_reg) v, b = in(xmm_reg) b,
                options(pure, nomem, nostack, preserves_flags));
        }
        v
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        a + b
    }
}

/// `a · b` with `a` as the first operand (see [`add`]).
#[inline(always)]
fn mul(a: f64, b: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        let mut v = a;
        // SAFETY: one SSE2 multiplication of two registers.
        unsafe {
            std::arch::asm!("mulsd {v}, {b}", v = inout(xmm_reg) v, b = in(xmm_reg) b,
                options(pure, nomem, nostack, preserves_flags));
        }
        v
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        a * b
    }
}

/// The value of every step code but `Call`, as `Code => expression`, handed to `$then!`
/// after the names it must bind: the step `$s` and its first operands `$a`, `$b` (`$r`
/// reads a register, `$f` is the function, `$w` the work vector). The one list of what
/// each code computes, for both loops of [`run`].
macro_rules! step_values {
    ($then:ident, $f:ident, $w:ident, $r:ident, $s:ident, $a:ident, $b:ident) => {
        $then! { $s, $a, $b;
            Add => add($a, $b),
            Sub => $a - $b,
            Mul => mul($a, $b),
            Div => $a / $b,
            Neg => -$a,
            Sq => $a * $a,
            Sym => $a,
            AddAdd => add(add($a, $b), $r($s.c)),
            AddSub => add($a, $b) - $r($s.c),
            AddMul => mul(add($a, $b), $r($s.c)),
            AddDiv => add($a, $b) / $r($s.c),
            SubAdd => add($a - $b, $r($s.c)),
            SubSub => $a - $b - $r($s.c),
            SubMul => mul($a - $b, $r($s.c)),
            SubDiv => ($a - $b) / $r($s.c),
            MulAdd => add(mul($a, $b), $r($s.c)),
            MulSub => mul($a, $b) - $r($s.c),
            MulMul => mul(mul($a, $b), $r($s.c)),
            MulDiv => mul($a, $b) / $r($s.c),
            AddAddRev => add($r($s.c), add($a, $b)),
            AddSubRev => $r($s.c) - add($a, $b),
            AddMulRev => mul($r($s.c), add($a, $b)),
            AddDivRev => $r($s.c) / add($a, $b),
            SubAddRev => add($r($s.c), $a - $b),
            SubSubRev => $r($s.c) - ($a - $b),
            SubMulRev => mul($r($s.c), $a - $b),
            SubDivRev => $r($s.c) / ($a - $b),
            MulAddRev => add($r($s.c), mul($a, $b)),
            MulSubRev => $r($s.c) - mul($a, $b),
            MulMulRev => mul($r($s.c), mul($a, $b)),
            MulDivRev => $r($s.c) / mul($a, $b),
            Sqrt => $a.sqrt(),
            Exp => $a.exp(),
            Log => $a.ln(),
            Sin => $a.sin(),
            Cos => $a.cos(),
            Tan => $a.tan(),
            Asin => $a.asin(),
            Acos => $a.acos(),
            Atan => $a.atan(),
            Sinh => $a.sinh(),
            Cosh => $a.cosh(),
            Tanh => $a.tanh(),
            Abs => $a.abs(),
            Sign => op::sign($a),
            Not => f64::from($a == 0.0),
            Pow => op::pow($a, $b),
            Atan2 => $a.atan2($b),
            Min => $a.min($b),
            Max => $a.max($b),
            Lt => f64::from($a < $b),
            Le => f64::from($a <= $b),
            Eq => f64::from($a == $b),
            Ne => f64::from($a != $b),
            And => f64::from($a != 0.0 && $b != 0.0),
            Or => f64::from($a != 0.0 || $b != 0.0),
            StrongMul => op::strong_mul($a, $b),
            Floor => $a.floor(),
            Ceil => $a.ceil(),
            Erf => libm::erf($a),
            Asinh => $a.asinh(),
            Acosh => $a.acosh(),
            Atanh => $a.atanh(),
            Log1p => $a.ln_1p(),
            Expm1 => $a.exp_m1(),
            Fmod => $a % $b,
            Hypot => $a.hypot($b),
            Interpolant => $f.tables.get_unchecked($s.c as usize).eval(&[$a]),
            Interpolant2 => $f.tables.get_unchecked($s.c as usize).eval(&[$a, $b]),
            InterpolantN => $f
                .tables
                .get_unchecked($s.c as usize)
                .eval(std::slice::from_raw_parts($w.add($s.a as usize), $s.b as usize)),
            IfElse => if $a != 0.0 { $b } else { $r($s.c) },
        }
    };
}

/// Runs `f`'s program on a work vector whose input and template registers are filled:
/// run by run of equal codes when the tape has long runs (each run in a loop of its own,
/// so that the dispatch's indirect jump is taken once per run), else step by step.
///
/// # Safety
/// `w` must point to at least `f.work_size` numbers.
#[inline(always)]
pub(crate) unsafe fn run(f: &Function, w: *mut f64) {
    if f.tape.run_ends.is_empty() {
        run_steps(f, w)
    } else {
        run_runs(f, w)
    }
}

/// [`run`] run by run.
///
/// # Safety
/// As [`run`]; `f.tape.run_ends` cover its steps.
#[inline(always)]
unsafe fn run_runs(f: &Function, w: *mut f64) {
    let r = |k: u32| *w.add(k as usize);
    let steps = &f.tape.steps;
    let mut start = 0;
    for &end in &f.tape.run_ends {
        let run_steps = steps.get_unchecked(start..end as usize);
        start = end as usize;
        // One loop per code: `w[d] = value` for every step of the run.
        macro_rules! loop_per_code {
            ($s:ident, $a:ident, $b:ident; $($code:ident => $value:expr,)*) => {
                match run_steps[0].code {
                    $(Code::$code => {
                        for $s in run_steps {
                            #[allow(unused_variables)]
                            let ($a, $b) = (r($s.a), r($s.b));
                            *w.add($s.d as usize) = $value;
                        }
                    })*
                    Code::Call => {
                        for s in run_steps {
                            f.exec_call(f.calls.get_unchecked(s.d as usize), w);
                        }
                    }
                }
            };
        }
        step_values!(loop_per_code, f, w, r, s, a, b);
    }
}

/// [`run`] step by step.
///
/// # Safety
/// As [`run`].
#[inline(always)]
unsafe fn run_steps(f: &Function, w: *mut f64) {
    let r = |k: u32| *w.add(k as usize);
    for s in &f.tape.steps {
        // One dispatch per step: `w[d] = value`.
        macro_rules! value_by_code {
            ($s:ident, $a:ident, $b:ident; $($code:ident => $value:expr,)*) => {{
                #[allow(unused_variables)]
                let ($a, $b) = (r($s.a), r($s.b));
                match $s.code {
                    $(Code::$code => $value,)*
                    Code::Call => {
                        f.exec_call(f.calls.get_unchecked($s.d as usize), w);
                        continue;
                    }
                }
            }};
        }
        *w.add(s.d as usize) = step_values!(value_by_code, f, w, r, s, a, b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{hessian, Expr, Matrix};

    fn ins(op: Op, d: u32, a: u32, b: u32) -> Instr {
        let c = a;
        Instr { op, d, a, b, c }
    }

    fn fused_steps(tape: &Tape) -> usize {
        tape.steps
            .iter()
            .filter(|s| s.code.pair().is_some())
            .count()
    }

    fn same(a: &[Instr], b: &[Instr]) -> bool {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(x, y)| (x.op, x.d, x.a, x.b, x.c) == (y.op, y.d, y.a, y.b, y.c))
    }

    /// Registers 0–2 inputs, 3 the output, 4–5 temporaries.
    fn tape_of(instrs: &[Instr]) -> Tape {
        Tape::new(instrs.to_vec(), &[], 6, std::iter::once(3..4))
    }

    #[test]
    fn a_temporary_read_once_fuses_and_comes_back_exactly() {
        // w4 = w0·w1; w3 = w2 − w4 (the temporary on the right: `rev`).
        let instrs = [ins(Op::Mul, 4, 0, 1), ins(Op::Sub, 3, 2, 4)];
        let tape = tape_of(&instrs);
        assert_eq!(tape.steps.len(), 1);
        assert_eq!(tape.steps[0].code, Code::MulSubRev);
        assert!(same(&tape.instructions().collect::<Vec<_>>(), &instrs));
    }

    #[test]
    fn a_temporary_read_again_later_is_kept() {
        // w4 = w0 + w1; w5 = w4 · w2; w3 = w5 − w4: w4 is read after the pair.
        let instrs = [
            ins(Op::Add, 4, 0, 1),
            ins(Op::Mul, 5, 4, 2),
            ins(Op::Sub, 3, 5, 4),
        ];
        let tape = tape_of(&instrs);
        // Only the second and third fuse (w5 is dead after the third).
        assert_eq!(tape.steps.len(), 2);
        assert_eq!(tape.steps[1].code, Code::MulSub);
        assert!(same(&tape.instructions().collect::<Vec<_>>(), &instrs));
    }

    #[test]
    fn a_temporary_overwritten_by_its_reader_fuses() {
        // w4 = w0 · w4; w4 = w1 + w4 (registers reused in place), then w3 = w4.
        let instrs = [
            ins(Op::Mul, 4, 0, 4),
            ins(Op::Add, 4, 1, 4),
            ins(Op::Sym, 3, 4, 4),
        ];
        let tape = tape_of(&instrs);
        assert_eq!(tape.steps[0].code, Code::MulAddRev);
        assert_eq!(tape.steps.len(), 2);
        assert!(same(&tape.instructions().collect::<Vec<_>>(), &instrs));
    }

    #[test]
    fn an_output_or_a_twice_read_result_is_not_skipped() {
        // w3 (an output) = w0 · w1, then w4 = w3 + w2: the output must be written.
        let output_first = [ins(Op::Mul, 3, 0, 1), ins(Op::Add, 4, 3, 2)];
        assert_eq!(fused_steps(&tape_of(&output_first)), 0);
        // w4 = w0 · w1; w3 = w4 · w4 reads it twice.
        let twice = [ins(Op::Mul, 4, 0, 1), ins(Op::Mul, 3, 4, 4)];
        assert_eq!(fused_steps(&tape_of(&twice)), 0);
        // w4 = w0 · w1; w3 = −w4: a negation is not fused.
        let negated = [ins(Op::Mul, 4, 0, 1), ins(Op::Neg, 3, 4, 4)];
        assert_eq!(fused_steps(&tape_of(&negated)), 0);
    }

    #[test]
    fn outputs_that_are_also_operands_evaluate_right() {
        let (x, y, z) = (Expr::sym("x"), Expr::sym("y"), Expr::sym("z"));
        let p = x * y;
        let f = Function::new(&[&[x, y, z]], &[&[p, p + z, (x + y) * z - y]]).unwrap();
        let out = f.call(&[&[2.0, 3.0, 5.0]]).unwrap();
        assert_eq!(out[0], [6.0, 11.0, 22.0]);
    }

    /// One explicit RK4 step of a damped pendulum with a control, `[θ, ω, u] ↦ [θ⁺, ω⁺]`.
    fn rk4_pendulum(x: &Matrix) -> [Expr; 2] {
        let rhs = |th: Expr, om: Expr| [om, x[2] - 9.81 * th.sin() - 0.2 * om];
        let h = 0.05;
        let k1 = rhs(x[0], x[1]);
        let k2 = rhs(x[0] + h / 2.0 * k1[0], x[1] + h / 2.0 * k1[1]);
        let k3 = rhs(x[0] + h / 2.0 * k2[0], x[1] + h / 2.0 * k2[1]);
        let k4 = rhs(x[0] + h * k3[0], x[1] + h * k3[1]);
        [0, 1].map(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }

    #[test]
    fn a_hessian_runs_in_far_fewer_steps_than_instructions() {
        // The Lagrangian Hessian of one multiple-shooting interval, as an OCP has.
        let x = Matrix::sym_vec("x", 3);
        let l = Matrix::sym_vec("l", 2);
        let next = rk4_pendulum(&x);
        let f = l[0] * next[0] + l[1] * next[1] + x[0].sq() + 0.1 * x[2].sq();
        let h = hessian(f, &x).unwrap();
        let fun = Function::new(&[&x, &l], &[h.values()]).unwrap();
        let (steps, instrs) = (fun.tape.steps.len(), fun.tape.len());
        assert!(
            steps * 4 < instrs * 3,
            "{steps} steps for {instrs} instructions"
        );
        let back: Vec<Instr> = fun.tape.instructions().collect();
        assert_eq!(back.len(), instrs);
        // The instructions rebuilt into a tape give the same program and instructions.
        let again = Tape::new(back.clone(), &fun.calls, fun.work_size, fun.output_ranges());
        assert!(same(&again.instructions().collect::<Vec<_>>(), &back));
        assert_eq!(again.steps.len(), steps);
    }

    /// Runs of equal codes are kept only when they average `MIN_STEPS_PER_RUN` steps.
    #[test]
    fn only_long_runs_run_run_by_run() {
        // w3 = w0 + w1 four times over: one run of four steps.
        let adds = [ins(Op::Add, 3, 0, 1); 4];
        let tape = tape_of(&adds);
        assert_eq!(tape.run_ends, [4]);
        assert_eq!(tape.steps[0].code, Code::Add);
        // Alternating operations: four runs of one step, run step by step.
        let mixed = [0, 1, 2, 3].map(|k| ins([Op::Add, Op::Sin][k % 2], 3, 0, 1));
        assert!(tape_of(&mixed).run_ends.is_empty());
    }

    /// A regrouped tape of independent terms runs run by run and gives the step-by-step
    /// loop's values bit for bit, and those of the same operations on f64.
    #[test]
    fn run_by_run_equals_step_by_step() {
        // Terms of pseudo-random kinds, so that the depth-first order is not predicted
        // and the tape is regrouped.
        let kind = |i: usize| (i * 7 + i * i / 3) % 4;
        let x = Matrix::sym_vec("x", 65);
        let terms: Vec<Expr> = (0..64)
            .map(|i| match kind(i) {
                0 => x[i].sin() * x[i + 1],
                1 => x[i].cos() / x[i + 1],
                2 => x[i].exp() + x[i + 1],
                _ => x[i].sqrt() - x[i + 1],
            })
            .collect();
        let f = Function::new(&[&x], &[&terms]).unwrap();
        assert!(
            !f.tape.run_ends.is_empty(),
            "the regrouped tape has long runs"
        );
        let mut by_steps = f.clone();
        by_steps.tape.run_ends.clear();
        let xs: Vec<f64> = (0..65).map(|i| 0.3 + 0.17 * i as f64).collect();
        let (runs, steps) = (f.call(&[&xs]).unwrap(), by_steps.call(&[&xs]).unwrap());
        for (i, (a, b)) in runs[0].iter().zip(&steps[0]).enumerate() {
            let (u, v) = (xs[i], xs[i + 1]);
            let direct = match kind(i) {
                0 => u.sin() * v,
                1 => u.cos() / v,
                2 => u.exp() + v,
                _ => u.sqrt() - v,
            };
            assert_eq!(a.to_bits(), b.to_bits());
            assert_eq!(a.to_bits(), direct.to_bits());
        }
    }
}
