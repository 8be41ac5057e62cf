//! The order in which the tape runs its steps: the depth-first order of `compile`,
//! regrouped window by window so that steps of the same kind run back to back.
//!
//! The interpreter (`interpret::run`) dispatches every step through one indirect jump.
//! In depth-first order consecutive steps are rarely of the same kind (on the gap model's
//! Lagrangian Hessian a kind changes every 1.4 steps), so that jump is mispredicted most
//! of the time: the same tape with every step's code made equal ran in half the time.
//! [`group`] reorders the steps so that equal kinds follow each other, without changing
//! what any step computes (every value is bit-identical: each operation gets the same
//! operands; only the order of independent steps changes).
//!
//! - **Kinds** are the interpreter's codes: a plain operation, or a *pair* — an
//!   `Add`/`Sub`/`Mul` read once, by an `Add`/`Sub`/`Mul`/`Div` — that `interpret::Tape`
//!   fuses into one step when the two are adjacent. Pairs are chosen here (each step in at
//!   most one) and kept adjacent, so they fuse wherever the order puts them.
//! - **Windows.** The steps are taken [`WINDOW`] units at a time in depth-first order
//!   (a unit is a step or a pair, placed where its last step was); within a window a list
//!   scheduler emits ready units, staying with the kind it emitted last while one is ready,
//!   else switching to the kind with the most ready units. Every operand of a unit is
//!   computed earlier in depth-first order, hence in its window or an earlier one, so the
//!   order is valid; the window bounds how much longer values stay live than in
//!   depth-first order (registers are allocated afterwards, on the new order).
//! - **Only where it pays**: a tape whose depth-first order a model of the branch
//!   predictor already predicts ([`MISS_RATIO`]), typical of one stage's derivatives
//!   repeated, is left as it is.
//! - A tape with calls is left in depth-first order (so that calling functions, whose
//!   native code is generated from that order, need no reordering across calls).
use crate::function::{Function, Instr};
use crate::graph::Node;
use crate::interpret::Code;
use crate::op::Op;
use std::cmp::Reverse;

/// Units (steps or fused pairs) regrouped together; larger windows make longer runs of
/// one kind and keep values live longer. On the gap model's Lagrangian Hessian (45 681
/// instructions) windows of 256, 1 024, 4 096, 8 192 and 32 768 units ran in 183, 153,
/// 109, 96 and 69 µs (medians of 5 processes; the depth-first tape 165–191 µs in the same
/// program) with 10 517 … 17 040 registers (depth-first: 10 457).
const WINDOW: usize = 32_768;

/// The depth-first order is kept when a model of the dispatch's branch predictor
/// ([`predicted_misses`]) mispredicts fewer than one step in this many. Derivative tapes
/// of a repeated stage are periodic and predicted as they are (hanging chain, 1 000 links:
/// 6 of 6 000 steps of its Jacobian, 7 of 2 999 of its Hessian): regrouped, they ran no
/// faster (same program, criterion: Jacobian 10.0–11.1 µs either way, Hessian 11.4–13.4)
/// and took more registers. The gap model's are not (7 831 of 22 595 and 15 369 of
/// 41 313; 154 and 256 once regrouped).
const MISS_RATIO: usize = 10;

/// No step.
const NONE: u32 = u32::MAX;

/// Reorders `steps` (node ids in depth-first post-order) and `step_nodes` (their nodes)
/// as described in the module docs. `step_of_operand(id)` gives the position in `steps`
/// of the step computing node `id` (`None` for inputs and constants); `output_steps`
/// lists the positions of steps whose value is an output of the function (read after
/// the last step, so never fused away).
pub(crate) fn group(
    steps: &mut Vec<u32>,
    step_nodes: &mut Vec<Node>,
    step_of_operand: impl Fn(u32) -> Option<usize>,
    output_steps: impl Iterator<Item = usize>,
) {
    let n = steps.len();
    let calls = step_nodes
        .iter()
        .any(|node| matches!(node.op, Op::Call | Op::CallOutput));
    if n < 3 || calls {
        return;
    }
    if predicted_misses(step_nodes.iter().map(|node| node.op)) * MISS_RATIO < n {
        return;
    }
    // The step computing each operand of each step (`NONE`: an input or a constant),
    // looked up once.
    let operand_steps: Vec<[u32; 3]> = step_nodes
        .iter()
        .map(|node| {
            let mut at = [NONE; 3];
            for (slot, &a) in at.iter_mut().zip(node.operands()) {
                if let Some(t) = step_of_operand(a) {
                    *slot = t as u32;
                }
            }
            at
        })
        .collect();
    let operand_steps_of = |s: usize| {
        operand_steps[s]
            .iter()
            .filter(|&&t| t != NONE)
            .map(|&t| t as usize)
    };
    // How often each step's value is read (outputs count as a read).
    let mut reads = vec![0u32; n];
    for s in 0..n {
        for t in operand_steps_of(s) {
            reads[t] += 1;
        }
    }
    for t in output_steps {
        reads[t] += 1;
    }
    // Pairs: `first[q]` is the step fused before q.
    let mut first = vec![NONE; n];
    let mut in_pair = vec![false; n];
    for q in 0..n {
        let node = &step_nodes[q];
        if !matches!(node.op, Op::Add | Op::Sub | Op::Mul | Op::Div) {
            continue;
        }
        if node.operands()[0] == node.operands()[1] {
            continue;
        }
        for p in operand_steps[q][..2].iter().filter(|&&p| p != NONE) {
            let p = *p as usize;
            if reads[p] == 1
                && !in_pair[p]
                && matches!(step_nodes[p].op, Op::Add | Op::Sub | Op::Mul)
            {
                first[q] = p as u32;
                in_pair[p] = true;
                in_pair[q] = true;
                break;
            }
        }
    }
    let is_first = |s: usize| in_pair[s] && first[s] == NONE;
    // Units in the order of their last step, and the interpreter's code of each.
    let kind = |q: usize| -> u32 {
        let node = &step_nodes[q];
        let code = match first[q] {
            NONE => Some(Code::plain(node.op)),
            p => {
                let rev = operand_steps[q][1] == p;
                Code::fused(step_nodes[p as usize].op, node.op, rev)
            }
        };
        code.expect("pairs are of fusable operations") as u32
    };
    let units: Vec<u32> = (0..n).filter(|&s| !is_first(s)).map(|s| s as u32).collect();
    // Unit of each step (by its last step's position in `units`).
    let mut unit_of = vec![NONE; n];
    for (u, &q) in units.iter().enumerate() {
        unit_of[q as usize] = u as u32;
        if first[q as usize] != NONE {
            unit_of[first[q as usize] as usize] = u as u32;
        }
    }
    let kinds: Vec<u32> = units.iter().map(|&q| kind(q as usize)).collect();
    let n_kinds = kinds.iter().max().map_or(0, |&k| k as usize + 1);
    let n_units = units.len();

    // Dependencies inside each window: `pending[u]` operands of u computed by other
    // units of its window, and the units reading each unit (`children`, compressed rows
    // in the order the units read them), counted then filled by `each_edge`, which calls
    // `edge(v, u)` for every operand of unit u computed by another unit v of its window.
    let each_edge = |edge: &mut dyn FnMut(usize, usize)| {
        for (u, &q) in units.iter().enumerate() {
            let q = q as usize;
            for m in [first[q], q as u32].into_iter().filter(|&m| m != NONE) {
                for t in operand_steps_of(m as usize) {
                    let v = unit_of[t] as usize;
                    if v >= u - u % WINDOW && v != u {
                        edge(v, u);
                    }
                }
            }
        }
    };
    let mut pending = vec![0u32; n_units];
    let mut child_ptr = vec![0u32; n_units + 1];
    each_edge(&mut |v, u| {
        pending[u] += 1;
        child_ptr[v + 1] += 1;
    });
    for v in 0..n_units {
        child_ptr[v + 1] += child_ptr[v];
    }
    let mut children = vec![0u32; child_ptr[n_units] as usize];
    let mut fill: Vec<u32> = child_ptr[..n_units].to_vec();
    each_edge(&mut |v, u| {
        children[fill[v] as usize] = u as u32;
        fill[v] += 1;
    });

    let mut order: Vec<u32> = Vec::with_capacity(n);
    let mut ready = ReadySets::new(n_kinds, WINDOW.min(n_units));
    let mut start = 0;
    while start < n_units {
        let end = (start + WINDOW).min(n_units);
        for u in start..end {
            if pending[u] == 0 {
                ready.insert(kinds[u] as usize, u - start);
            }
        }
        // List scheduling: stay with the last kind while it has ready units, else take
        // the kind with the most.
        let mut current = kinds[start] as usize;
        for _ in start..end {
            if ready.len(current) == 0 {
                current = (0..n_kinds)
                    .max_by_key(|&k| (ready.len(k), Reverse(k)))
                    .expect("a window has kinds");
            }
            let u = start + ready.pop_lowest(current).expect("a ready unit");
            let q = units[u] as usize;
            if first[q] != NONE {
                order.push(first[q]);
            }
            order.push(q as u32);
            for &c in &children[child_ptr[u] as usize..child_ptr[u + 1] as usize] {
                let c = c as usize;
                pending[c] -= 1;
                if pending[c] == 0 {
                    ready.insert(kinds[c] as usize, c - start);
                }
            }
        }
        start = end;
    }
    debug_assert_eq!(order.len(), n);
    let new_steps: Vec<u32> = order.iter().map(|&s| steps[s as usize]).collect();
    let new_nodes: Vec<Node> = order.iter().map(|&s| step_nodes[s as usize]).collect();
    *steps = new_steps;
    *step_nodes = new_nodes;
}

/// The ready units of a window by kind, each kind's as a set of offsets in the window
/// from which the lowest is taken first: a bitset with one summary bit per word, so that
/// taking the lowest scans at most `width / 4096` summary words (a binary heap per kind
/// spent a third of [`group`]'s time in its sift-down).
struct ReadySets {
    /// Words of `bits` per kind (one bit per offset).
    words: usize,
    /// Words of `summary` per kind (one bit per word of `bits`, set when it is non-zero).
    summary_words: usize,
    bits: Vec<u64>,
    summary: Vec<u64>,
    len: Vec<usize>,
}

impl ReadySets {
    /// Empty sets of `n_kinds` kinds over offsets `0..width`.
    fn new(n_kinds: usize, width: usize) -> ReadySets {
        let words = width.div_ceil(64);
        let summary_words = words.div_ceil(64);
        ReadySets {
            words,
            summary_words,
            bits: vec![0; n_kinds * words],
            summary: vec![0; n_kinds * summary_words],
            len: vec![0; n_kinds],
        }
    }

    /// Number of offsets in kind `k`'s set.
    fn len(&self, k: usize) -> usize {
        self.len[k]
    }

    /// Adds `offset` (not in the set) to kind `k`'s set.
    fn insert(&mut self, k: usize, offset: usize) {
        let w = offset / 64;
        self.bits[k * self.words + w] |= 1 << (offset % 64);
        self.summary[k * self.summary_words + w / 64] |= 1 << (w % 64);
        self.len[k] += 1;
    }

    /// Removes and returns the lowest offset of kind `k`'s set.
    fn pop_lowest(&mut self, k: usize) -> Option<usize> {
        let summary = &mut self.summary[k * self.summary_words..(k + 1) * self.summary_words];
        let (s, &sw) = summary.iter().enumerate().find(|(_, &sw)| sw != 0)?;
        let w = s * 64 + sw.trailing_zeros() as usize;
        let word = &mut self.bits[k * self.words + w];
        let offset = w * 64 + word.trailing_zeros() as usize;
        *word &= *word - 1;
        if *word == 0 {
            summary[s] &= !(1 << (w % 64));
        }
        self.len[k] -= 1;
        Some(offset)
    }
}

/// The instructions of `f`'s tape back in depth-first order from the outputs (the order
/// `compile` produces before [`group`]), with the temporaries renamed as `compile`
/// allocates them, and the work size they need. Native code wants this order: a chain of
/// dependent operations, not a run of equal ones, is what SIMD lanes (`native::lanes`)
/// pair and what a compiler keeps in machine registers (the JIT ran the gap model's
/// Hessian 1.6× slower in grouped order). `None` for a tape with calls or lookup
/// functions (never grouped), or one whose instructions are not all reached from the
/// outputs.
pub(crate) fn depth_first(f: &Function) -> Option<(Vec<Instr>, usize)> {
    let tape: &[Instr] = &f.tape;
    if tape
        .iter()
        .any(|i| matches!(i.op, Op::Call | Op::InterpolantN))
    {
        return None;
    }
    let n = tape.len();
    let temp_start = (f.template_start + f.template.len()) as u32;
    // The instruction whose value each operand reads (NONE: an input or a constant).
    let mut writer = vec![NONE; f.work_size];
    let mut source = vec![[NONE; 3]; n];
    let mut arity = vec![0usize; n];
    for (i, ins) in tape.iter().enumerate() {
        for (m, r) in ins.value_operands().enumerate() {
            source[i][m] = writer[r as usize];
            arity[i] = m + 1;
        }
        writer[ins.d as usize] = i as u32;
    }
    // Copies of computed values into output slots run last, as `compile` emits them.
    let is_copy = |i: usize| tape[i].op == Op::Sym;
    let mut visited = vec![false; n];
    let mut order: Vec<u32> = Vec::with_capacity(n);
    let mut stack: Vec<(u32, usize)> = Vec::new();
    for slot in f.output_ranges().flatten() {
        let w = writer[slot];
        if w == NONE {
            continue;
        }
        let root = if is_copy(w as usize) {
            source[w as usize][0]
        } else {
            w
        };
        if root == NONE || visited[root as usize] {
            continue;
        }
        stack.push((root, 0));
        visited[root as usize] = true;
        while let Some(&mut (i, ref mut next)) = stack.last_mut() {
            if *next < arity[i as usize] {
                let s = source[i as usize][*next];
                *next += 1;
                if s != NONE && !visited[s as usize] && !is_copy(s as usize) {
                    visited[s as usize] = true;
                    stack.push((s, 0));
                }
            } else {
                order.push(i);
                stack.pop();
            }
        }
    }
    order.extend((0..n as u32).filter(|&i| is_copy(i as usize)));
    if order.len() != n {
        return None;
    }
    // Registers: outputs' slots, inputs and constants stay; temporaries are allocated in
    // the new order, each freed after its last reader (before the reader's result takes
    // one, as in `compile`).
    let mut last_read = vec![0usize; n];
    for (p, &i) in order.iter().enumerate() {
        for &s in &source[i as usize][..arity[i as usize]] {
            if s != NONE {
                last_read[s as usize] = p;
            }
        }
    }
    let mut register = vec![NONE; n];
    let mut free: Vec<u32> = Vec::new();
    let mut work = temp_start;
    let mut out = Vec::with_capacity(n);
    for (p, &i) in order.iter().enumerate() {
        let ins = tape[i as usize];
        let k = arity[i as usize];
        let mut new = [ins.a, ins.b, ins.c];
        for m in 0..k {
            let s = source[i as usize][m];
            if s != NONE {
                new[m] = register[s as usize];
                if last_read[s as usize] == p && new[m] >= temp_start && !new[..m].contains(&new[m])
                {
                    free.push(new[m]);
                }
            }
        }
        let d = if ins.d < temp_start {
            ins.d
        } else {
            free.pop().unwrap_or_else(|| {
                work += 1;
                work - 1
            })
        };
        register[i as usize] = d;
        // Compile's layout: a unary operation's `b` is its `a`; `c` is `a` too, except
        // for `if_else` and the lookups (whose `c` is a table index).
        let (a, b) = (new[0], if k >= 2 { new[1] } else { new[0] });
        let c = match ins.op {
            Op::Interpolant | Op::Interpolant2 => ins.c,
            _ if k == 3 => new[2],
            _ => new[0],
        };
        out.push(Instr {
            op: ins.op,
            d,
            a,
            b,
            c,
        });
    }
    Some((out, work as usize))
}

/// Mispredictions of a simple model of an indirect-branch predictor running `ops` in
/// order: each operation is predicted to be the one that last followed the same two
/// operations.
fn predicted_misses(ops: impl Iterator<Item = Op>) -> usize {
    let mut next = [u8::MAX; 64 * 64];
    let (mut before, mut last) = (0usize, 0usize);
    let mut misses = 0;
    for op in ops {
        let op = op as usize % 64;
        let seen = &mut next[before * 64 + last];
        if usize::from(*seen) != op {
            misses += 1;
            *seen = op as u8;
        }
        (before, last) = (last, op);
    }
    misses
}

#[cfg(test)]
mod tests {
    use crate::interpret::Code;
    use crate::{Expr, Function};

    fn codes(f: &Function) -> Vec<Code> {
        f.tape.steps().iter().map(|s| s.code()).collect()
    }

    fn bits(f: &Function, x: &[f64]) -> Vec<u64> {
        let out = f.call(&[x]).unwrap();
        out.iter().flatten().map(|v| v.to_bits()).collect()
    }

    /// Two independent `sin(a) + b`: depth-first they alternate (Sin, Add, Sin, Add); the
    /// tape runs both sines, then both sums, and the native order is depth-first again,
    /// with the same values bit for bit.
    #[test]
    fn equal_operations_run_back_to_back_and_native_code_gets_depth_first() {
        let x: Vec<Expr> = (0..4).map(|k| Expr::sym(&format!("x{k}"))).collect();
        let outs = [x[0].sin() + x[1], x[2].sin() + x[3]];
        let f = Function::new(&[&x], &[&outs]).unwrap();
        assert_eq!(codes(&f), [Code::Sin, Code::Sin, Code::Add, Code::Add]);
        let native = f.for_native();
        assert_eq!(codes(&native), [Code::Sin, Code::Add, Code::Sin, Code::Add]);
        let at = [0.3, -1.2, 2.5, 1e-3];
        assert_eq!(bits(&f, &at), bits(&native, &at));
        // The reference values, computed directly.
        assert_eq!(
            bits(&f, &at),
            [
                (0.3f64.sin() - 1.2).to_bits(),
                (2.5f64.sin() + 1e-3).to_bits()
            ]
        );
    }

    /// The ready sets give each kind's offsets lowest first, as a sorted set does, across
    /// summary words and interleaved with insertions.
    #[test]
    fn ready_sets_take_the_lowest_offset_first() {
        use std::collections::BTreeSet;
        let width = 10_000;
        let mut sets = super::ReadySets::new(3, width);
        let mut model = [BTreeSet::new(), BTreeSet::new(), BTreeSet::new()];
        let mut x: usize = 12_345;
        for round in 0..20_000 {
            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let k = (x >> 40) % 3;
            let offset = (x >> 20) % width;
            if round % 3 != 2 && !model[k].contains(&offset) {
                sets.insert(k, offset);
                model[k].insert(offset);
            } else {
                assert_eq!(sets.pop_lowest(k), model[k].pop_first());
            }
            assert_eq!(sets.len(k), model[k].len());
        }
        for (k, set) in model.iter_mut().enumerate() {
            while let Some(lowest) = set.pop_first() {
                assert_eq!(sets.pop_lowest(k), Some(lowest));
            }
            assert_eq!(sets.pop_lowest(k), None);
        }
    }

    /// A product read once by a sum is fused with it wherever the regrouping puts them:
    /// four independent `a·b + c` are four fused steps (one kind, one run).
    #[test]
    fn fusable_pairs_stay_adjacent() {
        let x: Vec<Expr> = (0..6).map(|k| Expr::sym(&format!("x{k}"))).collect();
        let outs: Vec<Expr> = (0..4).map(|k| x[k] * x[k + 1] + x[k + 2]).collect();
        let f = Function::new(&[&x], &[&outs]).unwrap();
        let c = codes(&f);
        assert_eq!(c.len(), 4, "{c:?}");
        assert!(matches!(c[0], Code::MulAdd | Code::MulAddRev), "{c:?}");
        assert!(c.iter().all(|&k| k == c[0]), "{c:?}");
        let at: [f64; 6] = [1.5, -2.0, 0.25, 3.0, -0.5, 7.0];
        let want: Vec<u64> = (0..4)
            .map(|k| (at[k] * at[k + 1] + at[k + 2]).to_bits())
            .collect();
        assert_eq!(bits(&f, &at), want);
    }
}
