//! Pairs of isomorphic instruction groups that the JIT evaluates two at a time in the two
//! lanes of one SIMD register (`f64x2`), the way gcc's straight-line (SLP) vectoriser
//! pairs the independent operations of CasADi's generated C.
//!
//! Two consecutive groups of `len` tape instructions form a pair when instruction `j` of
//! the second group has the same operation as instruction `j` of the first, and every
//! operand of both is either the result of the same earlier instruction of its own group
//! or a register that neither group writes before reading it (nothing flows from the
//! first group into the second). Only operations whose SIMD form computes exactly the
//! scalar IEEE result in each lane are paired (`+ − × ÷`, negation, square, square root,
//! absolute value, the guarded product `⊛`), so the lanes are bit-identical to the tape.
use crate::function::{Function, Instr};
use crate::op::Op;

/// Longest group tried (instructions per lane).
const MAX_GROUP: usize = 8;

/// What [`steps`] needs to know of the registers, besides the tape.
pub(crate) struct Registers<'a> {
    /// The constant each register holds throughout, if any.
    pub constant: &'a [Option<f64>],
    /// The input entry `(k, i)` each register holds, if any.
    pub input_of: &'a [Option<(u32, u32)>],
    /// The output entry `(k, i)` each register is, if any.
    pub output_of: &'a [Option<(u32, u32)>],
    /// Whether each instruction's result is stored to the work vector.
    pub store: &'a [bool],
    /// The last instruction reading each instruction's result ([`last_reader`]).
    pub last_reader: &'a [usize],
}

/// For each instruction, the last later instruction reading its result before the
/// register is written again (`usize::MAX` for a register read after the tape, i.e. an
/// output, and for calls; `0` if none).
pub(crate) fn last_reader(f: &Function, reads: impl Fn(&Instr, &mut dyn FnMut(u32))) -> Vec<usize> {
    let mut last = vec![usize::MAX; f.work_size];
    let mut out = vec![usize::MAX; f.tape.len()];
    for (i, ins) in f.tape.iter().enumerate().rev() {
        if ins.op != Op::Call {
            out[i] = last[ins.d as usize];
            last[ins.d as usize] = 0;
        }
        reads(ins, &mut |r| {
            let l = &mut last[r as usize];
            if *l == 0 {
                *l = i;
            }
        });
    }
    out
}

/// An operand of the `j`-th instruction pair of a [`Step::Pair`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Operand {
    /// The result of the group's `m`-th instruction (in each lane, its own group's).
    Internal(usize),
    /// Registers read from outside the groups: first lane, second lane.
    External(u32, u32),
}

/// One step of a chunk's code.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Step {
    /// Tape instruction `i`, alone.
    Single(usize),
    /// Instructions `start..start + len` (first lane) and `start + len..start + 2 len`
    /// (second lane), two at a time; `operands[j]` are the operands of pair `j` (one for a
    /// unary operation).
    Pair {
        start: usize,
        len: usize,
        operands: Vec<[Operand; 2]>,
    },
}

/// Whether `op` computes in SIMD lanes exactly what it computes on scalars (the guarded
/// product `a ⊛ b`: the product and-ed with the mask of `a ≠ 0`, as on scalars).
pub(crate) fn pairable(op: Op) -> bool {
    matches!(
        op,
        Op::Add
            | Op::Sub
            | Op::Mul
            | Op::Div
            | Op::Neg
            | Op::Sq
            | Op::Sqrt
            | Op::Abs
            | Op::StrongMul
    )
}

/// The steps of tape instructions `start..end` of `f`: greedily, from the front, the
/// shortest pair of groups starting at each instruction, else the instruction alone.
/// `constant` gives the registers holding a constant (a NaN constant is never paired, so
/// that operand order cannot change a NaN's payload).
pub(crate) fn steps(f: &Function, regs: &Registers, start: usize, end: usize) -> Vec<Step> {
    let mut out = Vec::new();
    let mut i = start;
    while i < end {
        let found = (1..=MAX_GROUP)
            .take_while(|&len| i + 2 * len <= end)
            .find_map(|len| pair(&f.tape[i..i + 2 * len], regs.constant).map(|ops| (len, ops)))
            .filter(|(len, ops)| pays(f, regs, i, *len, ops));
        match found {
            Some((len, operands)) => {
                out.push(Step::Pair {
                    start: i,
                    len,
                    operands,
                });
                i += 2 * len;
            }
            None => {
                out.push(Step::Single(i));
                i += 1;
            }
        }
    }
    out
}

/// The operands of `window` (two groups of `window.len() / 2` instructions) if they form a
/// pair.
fn pair(window: &[Instr], constant: &[Option<f64>]) -> Option<Vec<[Operand; 2]>> {
    let len = window.len() / 2;
    let (first, second) = window.split_at(len);
    if first[0].op != second[0].op {
        return None; // the common case, rejected early
    }
    let mut operands = Vec::with_capacity(len);
    for j in 0..len {
        let (x, y) = (&first[j], &second[j]);
        if x.op != y.op || !pairable(x.op) {
            return None;
        }
        let arity = if x.op.arity() == 2 { 2 } else { 1 };
        let mut ops = [Operand::Internal(0); 2];
        for (p, op) in ops.iter_mut().enumerate().take(arity) {
            let (rx, ry) = if p == 0 { (x.a, y.a) } else { (x.b, y.b) };
            let (ix, iy) = (source(first, j, rx), source(second, j, ry));
            *op = match (ix, iy) {
                (Some(m), Some(n)) if m == n => Operand::Internal(m),
                (None, None) => {
                    // The second lane must not read what the first group writes.
                    let written = first.iter().any(|w| w.d == ry);
                    let nan = |r: u32| constant[r as usize].is_some_and(f64::is_nan);
                    if written || nan(rx) || nan(ry) {
                        return None;
                    }
                    Operand::External(rx, ry)
                }
                _ => return None,
            };
        }
        operands.push(ops);
    }
    Some(operands)
}

/// Whether a pair costs fewer machine instructions than its scalar code, by a count of
/// what each costs beyond one instruction per operation: putting two scalars into one
/// vector (nothing for two constants, one load for two inputs side by side, else about
/// two), taking the second lane out of a vector for later scalar use or a lone store, and
/// one store instead of two for results going to neighbouring output entries.
fn pays(
    f: &Function,
    regs: &Registers,
    start: usize,
    len: usize,
    operands: &[[Operand; 2]],
) -> bool {
    let scalar = 2 * len
        + (start..start + 2 * len)
            .map(|i| stores(regs, f.tape[i].d, i))
            .sum::<usize>();
    let mut vector = len;
    for (j, ops) in operands.iter().enumerate() {
        let i = start + j;
        let arity = if f.tape[i].op.arity() == 2 { 2 } else { 1 };
        for op in &ops[..arity] {
            if let Operand::External(r1, r2) = *op {
                let (c1, c2) = (regs.constant[r1 as usize], regs.constant[r2 as usize]);
                let side_by_side = matches!(
                    (regs.input_of[r1 as usize], regs.input_of[r2 as usize]),
                    (Some((k, a)), Some((l, b))) if k == l && b == a + 1
                );
                vector += if c1.is_some() && c2.is_some() {
                    0
                } else if side_by_side {
                    1
                } else {
                    2
                };
            }
        }
        let (d1, d2) = (f.tape[i].d, f.tape[i + len].d);
        let neighbours = matches!(
            (regs.output_of[d1 as usize], regs.output_of[d2 as usize]),
            (Some((k, a)), Some((l, b))) if k == l && b == a + 1
        );
        let (s1, s2) = (stores(regs, d1, i), stores(regs, d2, i + len));
        vector += if neighbours { s1.max(s2) } else { s1 + s2 };
        // The second lane taken out for a reader after the pair or a lone store.
        let escapes =
            regs.last_reader[i + len] >= start + 2 * len && regs.output_of[d2 as usize].is_none();
        if escapes || (!neighbours && s2 > 0) {
            vector += 1;
        }
    }
    vector < scalar
}

/// Stores of instruction `i`'s result to `d`: to the work vector, to an output.
fn stores(regs: &Registers, d: u32, i: usize) -> usize {
    usize::from(regs.store[i]) + usize::from(regs.output_of[d as usize].is_some())
}

/// The last instruction before `j` of `group` that writes `r`.
fn source(group: &[Instr], j: usize, r: u32) -> Option<usize> {
    (0..j).rev().find(|&m| group[m].d == r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Expr, Function};

    /// The steps of the whole tape, no result stored to the work vector.
    fn all_steps(f: &Function) -> Vec<Step> {
        let entries = |sizes: &[usize], offsets: &[usize]| {
            let mut of = vec![None; f.work_size];
            for (k, (&n, &at)) in sizes.iter().zip(offsets).enumerate() {
                for i in 0..n {
                    of[at + i] = Some((k as u32, i as u32));
                }
            }
            of
        };
        let constant: Vec<Option<f64>> = vec![None; f.work_size];
        let later = last_reader(f, |ins, visit| {
            visit(ins.a);
            if ins.op.arity() == 2 {
                visit(ins.b);
            }
        });
        let regs = Registers {
            constant: &constant,
            input_of: &entries(&f.input_sizes, &f.input_offsets),
            output_of: &entries(&f.output_sizes, &f.output_offsets),
            store: &vec![false; f.tape.len()],
            last_reader: &later,
        };
        steps(f, &regs, 0, f.tape.len())
    }

    #[test]
    fn independent_lanes_pair_and_dependent_ones_do_not() {
        let x: Vec<Expr> = (0..4).map(|k| Expr::sym(&format!("x{k}"))).collect();
        // Four independent `x·x + x`, to neighbouring outputs: pairs.
        let outs: Vec<Expr> = x.iter().map(|&v| v * v + v).collect();
        // (Native code is generated from the depth-first order, `Function::for_native`.)
        let f = Function::new(&[&x], &[&outs])
            .unwrap()
            .for_native()
            .into_owned();
        let s = all_steps(&f);
        assert!(s.iter().any(|s| matches!(s, Step::Pair { .. })), "{s:?}");
        // A chain: each element depends on the previous one, nothing pairs.
        let mut acc = x[0];
        let mut chain = Vec::new();
        for &v in &x[1..] {
            acc = acc * v + 1.0;
            chain.push(acc);
        }
        let g = Function::new(&[&x], &[&chain])
            .unwrap()
            .for_native()
            .into_owned();
        let s = all_steps(&g);
        assert!(s.iter().all(|s| matches!(s, Step::Single(_))), "{s:?}");
    }
}
