//! Where generated source code keeps each register of a function's tape: inputs read
//! where the caller keeps them, constants as literals, outputs written where the caller
//! wants them, and only the temporaries (and the arguments gathered for a call of another
//! function) in the work vector, already reused by liveness when the tape was compiled
//! ([`Function::to_rust`], [`Function::to_c`]).
use crate::function::{Function, Instr};
use crate::op::Op;

/// Where the generated code finds a register of one function.
#[derive(Clone, Copy)]
pub(super) enum Place {
    /// Entry `i` of input `k`, read where the caller keeps it.
    Input(usize, usize),
    /// Entry `i` of output `k`, written (and read back) where the caller wants it.
    Output(usize, usize),
    /// A constant (a template register no instruction writes): a literal.
    Constant(f64),
    /// Entry `r` of the work vector.
    Work(usize),
}

/// The first register of `f`'s temporaries: the tape's registers before it are its inputs,
/// constants and output slots (`[inputs | constants | outputs | temporaries | call
/// scratch]`), which the generated code keeps elsewhere; register `r` from here on is
/// `w[r - first_temporary(f)]`.
pub(super) fn first_temporary(f: &Function) -> usize {
    f.template_start + f.template.len()
}

/// The length of the work vector of `f`'s generated code: its temporaries, then, when it
/// calls other functions, the largest callee's gathered arguments and work vector.
pub(super) fn work_need(f: &Function) -> usize {
    let callees = f
        .calls
        .iter()
        .map(|c| callee_base(&c.function) + work_need(&c.function));
    f.call_scratch - first_temporary(f) + callees.max().unwrap_or(0)
}

/// Where a callee's own work vector starts in its scratch block: after its arguments,
/// gathered there in the layout of its inputs.
pub(super) fn callee_base(g: &Function) -> usize {
    g.template_start
}

/// The place of every register of `f`. Inputs and constants are never written (compilation
/// gives temporaries only registers after the output slots).
pub(super) fn places(f: &Function) -> Vec<Place> {
    let t = first_temporary(f);
    let mut p: Vec<Place> = (0..f.work_size)
        .map(|r| Place::Work(r.saturating_sub(t)))
        .collect();
    for (k, &v) in f.template.iter().enumerate() {
        p[f.template_start + k] = Place::Constant(v);
    }
    for (k, (&n, &at)) in f.input_sizes.iter().zip(&f.input_offsets).enumerate() {
        (0..n).for_each(|i| p[at + i] = Place::Input(k, i));
    }
    for (k, (&n, &at)) in f.output_sizes.iter().zip(&f.output_offsets).enumerate() {
        (0..n).for_each(|i| p[at + i] = Place::Output(k, i));
    }
    p
}

/// Whether each register of `f` is written by some instruction of its tape (its
/// destination, or an output of a call).
pub(super) fn written(f: &Function) -> Vec<bool> {
    let mut written = vec![false; f.work_size];
    for ins in f.tape.iter() {
        if ins.op == Op::Call {
            let call = &f.calls[ins.d as usize];
            let n: usize = call.function.output_sizes.iter().sum();
            let out = call.out as usize;
            written[out..out + n].iter_mut().for_each(|w| *w = true);
        } else {
            written[ins.d as usize] = true;
        }
    }
    written
}

/// The output entries no instruction writes (constant outputs), with their values.
pub(super) fn constant_outputs(f: &Function) -> Vec<(usize, usize, f64)> {
    let written = written(f);
    let mut c = Vec::new();
    for (k, (&n, &at)) in f.output_sizes.iter().zip(&f.output_offsets).enumerate() {
        for i in (0..n).filter(|&i| !written[at + i]) {
            c.push((k, i, f.template[at + i - f.template_start]));
        }
    }
    c
}

/// Whether each register of `f` is read by some instruction of its tape (an operand, or
/// an argument of a call).
pub(super) fn read(f: &Function) -> Vec<bool> {
    let mut read = vec![false; f.work_size];
    for ins in f.tape.iter() {
        operands(f, ins, |r| read[r as usize] = true);
    }
    read
}

/// Visits the registers instruction `ins` of `f` reads: its operands, or a call's arguments.
pub(super) fn operands(f: &Function, ins: &Instr, mut visit: impl FnMut(u32)) {
    let n = match ins.op {
        Op::Call => {
            f.calls[ins.d as usize].args.iter().for_each(|&r| visit(r));
            0
        }
        // The copy `w[d] = w[a]`.
        Op::Sym => 1,
        op => op.arity().min(3),
    };
    for &r in &[ins.a, ins.b, ins.c][..n] {
        visit(r);
    }
}

/// Where a call node's data lives in the generated code's work vector (offsets from the
/// first temporary): the arguments gathered in the callee's input layout, the callee's
/// own work, and its outputs written straight into the call's block of registers.
pub(super) struct CallLayout {
    /// (work offset, caller's register) of every argument, in order.
    pub args: Vec<(usize, u32)>,
    /// Work offset of each input of the callee.
    pub inputs: Vec<usize>,
    /// Work offset of each output of the callee.
    pub outputs: Vec<usize>,
    /// Work offset of the callee's own work.
    pub callee_work: usize,
}

/// The layout of the call node `ins` of `f` ([`CallLayout`]).
pub(super) fn call_layout(f: &Function, ins: &Instr) -> CallLayout {
    let call = &f.calls[ins.d as usize];
    let g = &call.function;
    let s = f.call_scratch - first_temporary(f);
    let mut args = Vec::with_capacity(call.args.len());
    let mut p = 0;
    for (&n, &at) in g.input_sizes.iter().zip(&g.input_offsets) {
        for i in 0..n {
            args.push((s + at + i, call.args[p]));
            p += 1;
        }
    }
    let mut q = call.out as usize - first_temporary(f);
    let outputs = g
        .output_sizes
        .iter()
        .map(|n| {
            q += n;
            q - n
        })
        .collect();
    CallLayout {
        args,
        inputs: g.input_offsets.iter().map(|at| s + at).collect(),
        outputs,
        callee_work: s + callee_base(g),
    }
}

/// For each instruction of `f`'s tape: whether its result is read by an instruction of a
/// later chunk (chunks of `chunk` instructions) before its register is written again, so
/// that code keeping values in local variables within a chunk must also keep it in memory.
pub(super) fn read_by_later_chunk(f: &Function, chunk: usize) -> Vec<bool> {
    // Per register: 1 + the last chunk reading its current value (going backwards), or 0.
    let mut reader = vec![0; f.work_size];
    let mut later = vec![false; f.tape.len()];
    for (i, ins) in f.tape.iter().enumerate().rev() {
        let c = i / chunk + 1;
        if ins.op == Op::Call {
            let call = &f.calls[ins.d as usize];
            let n: usize = call.function.output_sizes.iter().sum();
            let out = call.out as usize;
            reader[out..out + n].fill(0);
        } else {
            later[i] = reader[ins.d as usize] > c;
            reader[ins.d as usize] = 0;
        }
        operands(f, ins, |r| reader[r as usize] = reader[r as usize].max(c));
    }
    later
}
