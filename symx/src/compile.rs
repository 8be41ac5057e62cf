//! Compilation of expressions into a [`Function`]'s tape (see `function.rs` for the layout
//! of the work vector): depth-first ordering, output slots, liveness-based registers.
use crate::call::CallInstr;
use crate::error::SymxError;
use crate::expr::Expr;
use crate::function::{next_uid, Function, Instr};
use crate::graph::{Graph, Node};
use crate::interpret::Tape;
use crate::op::Op;
use crate::table::Table;
use rustc_hash::FxHashMap;
use std::sync::{Arc, OnceLock};

/// The nodes to compute, in depth-first post-order from the outputs, and the constants met.
struct Order {
    steps: Vec<u32>,
    /// The node of each step (read again in step order below: a copy here saves a cache
    /// miss per read in a graph of millions of nodes).
    step_nodes: Vec<Node>,
    const_ids: Vec<u32>,
    constants: Vec<f64>,
}

/// Per-node bookkeeping of one compilation: `seen[id]` is 0 for unvisited nodes, else
/// 1 + the node's local index into `register`.
struct Locals {
    seen: Vec<u32>,
    register: Vec<u32>,
    /// Whether the node's register may go back to the scalar free list (not a call's).
    freeable: Vec<bool>,
}

impl Locals {
    fn visit(&mut self, id: u32, reg: u32, op: Op) {
        self.register.push(reg);
        self.freeable.push(!matches!(op, Op::Call | Op::CallOutput));
        self.seen[id as usize] = self.register.len() as u32;
    }
    fn is_seen(&self, id: u32) -> bool {
        self.seen[id as usize] != 0
    }
    fn local(&self, id: u32) -> usize {
        self.seen[id as usize] as usize - 1
    }
}

fn order(g: &Graph, outputs: &[&[Expr]], loc: &mut Locals) -> Result<Order, SymxError> {
    let mut o = Order {
        steps: Vec::new(),
        step_nodes: Vec::new(),
        const_ids: Vec::new(),
        constants: Vec::new(),
    };
    let mut stack: Vec<(u32, u32)> = Vec::new();
    for (k, y) in outputs.iter().enumerate() {
        for e in y.iter() {
            stack.push((e.id, 0));
            while let Some(&mut (id, ref mut child)) = stack.last_mut() {
                let node = g.node(id);
                if *child == 0 {
                    if loc.is_seen(id) {
                        stack.pop();
                        continue;
                    }
                    match node.op {
                        Op::Const => {
                            o.const_ids.push(id);
                            o.constants.push(node.value().unwrap_or(f64::NAN));
                            loc.visit(id, u32::MAX, Op::Const);
                            stack.pop();
                            continue;
                        }
                        Op::Sym => {
                            return Err(SymxError::FreeSymbol {
                                output: k,
                                name: g.symbol_name(id).to_string(),
                            })
                        }
                        _ => {}
                    }
                }
                let operands = g.operands(id);
                if (*child as usize) < operands.len() {
                    let c = operands[*child as usize];
                    *child += 1;
                    if !loc.is_seen(c) {
                        stack.push((c, 0));
                    }
                } else {
                    loc.visit(id, u32::MAX, node.op);
                    o.steps.push(id);
                    o.step_nodes.push(node);
                    stack.pop();
                }
            }
        }
    }
    Ok(o)
}

/// Reorders the depth-first `steps` so that equal operations run back to back
/// ([`crate::schedule::group`]).
fn regroup(outputs: &[&[Expr]], loc: &Locals, steps: &mut Vec<u32>, step_nodes: &mut Vec<Node>) {
    let mut position = vec![u32::MAX; loc.register.len()];
    for (s, &id) in steps.iter().enumerate() {
        position[loc.local(id)] = s as u32;
    }
    let step_of = |id: u32| {
        let p = position[loc.local(id)];
        (p != u32::MAX).then_some(p as usize)
    };
    let output_steps = outputs
        .iter()
        .flat_map(|y| y.iter())
        .filter_map(|e| step_of(e.id));
    crate::schedule::group(steps, step_nodes, step_of, output_steps);
}

/// Tables and called functions referenced by a tape, each listed once.
#[derive(Default)]
struct Externals {
    tables: Vec<Arc<Table>>,
    table_of: FxHashMap<u32, u32>,
    calls: Vec<CallInstr>,
}

impl Externals {
    fn table(&mut self, g: &Graph, t: u32) -> u32 {
        *self.table_of.entry(t).or_insert_with(|| {
            self.tables.push(g.tables[t as usize].clone());
            self.tables.len() as u32 - 1
        })
    }
}

pub(crate) fn compile(
    g: &Graph,
    inputs: &[&[Expr]],
    outputs: &[&[Expr]],
) -> Result<Function, SymxError> {
    // Per-node scratch indexed by node id. Zero-initialised vectors are allocated lazily
    // by the OS, so a small function in a large graph only touches the pages of its cone.
    let mut loc = Locals {
        seen: vec![0u32; g.len()],
        register: Vec::new(),
        freeable: Vec::new(),
    };

    // Inputs occupy the first registers.
    let input_sizes: Vec<usize> = inputs.iter().map(|x| x.len()).collect();
    let output_sizes: Vec<usize> = outputs.iter().map(|y| y.len()).collect();
    let mut input_offsets = Vec::with_capacity(inputs.len());
    // Input number of each input entry, by local index (inputs are the first locals).
    let mut input_of: Vec<usize> = Vec::new();
    let mut next = 0usize;
    for (k, x) in inputs.iter().enumerate() {
        input_offsets.push(next);
        for e in x.iter() {
            input_of.push(k);
            loc.visit(e.id, next as u32, Op::Sym);
            next += 1;
        }
    }
    let mut input_used = vec![false; inputs.len()];
    let Order {
        mut steps,
        mut step_nodes,
        const_ids,
        constants,
    } = order(g, outputs, &mut loc)?;
    regroup(outputs, &loc, &mut steps, &mut step_nodes);

    // Constants, then output slots.
    let template_start = next;
    for (c, &id) in const_ids.iter().enumerate() {
        let l = loc.local(id);
        loc.register[l] = (template_start + c) as u32;
    }
    let outputs_start = template_start + constants.len();
    let mut template = constants;
    let mut output_offsets = Vec::with_capacity(outputs.len());
    let mut copies: Vec<Instr> = Vec::new();
    let mut call_copies: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    let mut pinned = vec![false; loc.register.len()];
    let mut slot = outputs_start;
    for y in outputs {
        output_offsets.push(slot);
        for e in y.iter() {
            let l = loc.local(e.id);
            let node = g.node(e.id);
            if let Some(v) = node.value() {
                template.push(v);
            } else if !matches!(node.op, Op::Sym | Op::Call | Op::CallOutput) && !pinned[l] {
                // The operation computing this entry writes its output slot directly.
                pinned[l] = true;
                loc.register[l] = slot as u32;
                template.push(0.0);
            } else if node.op == Op::CallOutput {
                // A call's output: copied to its slot right after the call.
                template.push(0.0);
                call_copies.entry(e.id).or_default().push(slot as u32);
            } else {
                // An input or a node already written to another slot: copy at the end.
                template.push(0.0);
                if node.op == Op::Sym {
                    input_used[input_of[l]] = true;
                }
                copies.push(Instr {
                    op: Op::Sym,
                    d: slot as u32,
                    a: e.id, // resolved to a register below
                    b: 0,
                    c: 0,
                });
            }
            slot += 1;
        }
    }

    // Last step reading each node (by local index).
    let mut last_use: Vec<usize> = vec![usize::MAX; loc.register.len()];
    for (s, (&id, node)) in steps.iter().zip(&step_nodes).enumerate() {
        let operands = if node.op == Op::Call {
            g.operands(id)
        } else {
            node.operands()
        };
        for &a in operands {
            let l = loc.local(a);
            last_use[l] = s;
            if let Some(&k) = input_of.get(l) {
                input_used[k] = true;
            }
        }
    }

    let temp_start = slot as u32;
    let mut ext = Externals::default();
    let plan = Plan {
        step_nodes: &step_nodes,
        pinned: &pinned,
        last_use: &last_use,
        call_copies: &call_copies,
        temp_start,
    };
    let (mut tape, work_size) = allocate(g, &steps, &mut loc, &plan, &mut ext);
    for mut copy in copies {
        let r = loc.register[loc.local(copy.a)];
        // All operand fields name the source, so that readers of `b` see it too.
        (copy.a, copy.b, copy.c) = (r, r, r);
        tape.push(copy);
    }
    // Callees run in one scratch block after everything else.
    let call_scratch = work_size as usize;
    let scratch = ext.calls.iter().map(|c| c.function.work_size).max();
    let work_size = call_scratch + scratch.map_or(0, |s| s.max(1));
    let output_ranges = output_offsets
        .iter()
        .zip(&output_sizes)
        .map(|(&at, &n)| at..at + n);
    let tape = Tape::new(tape, &ext.calls, work_size, output_ranges);
    Ok(Function {
        name: "f".into(),
        input_names: (0..inputs.len()).map(|k| format!("i{k}")).collect(),
        output_names: (0..outputs.len()).map(|k| format!("o{k}")).collect(),
        uid: next_uid(),
        input_sizes,
        output_sizes,
        input_offsets,
        input_used,
        output_offsets,
        tape,
        template,
        template_start,
        work_size,
        tables: ext.tables,
        calls: ext.calls,
        call_scratch,
        dependencies: OnceLock::new(),
        jacobians: Default::default(),
        native: None,
        external: None,
    })
}

/// What register allocation needs to know about the nodes (by local index).
struct Plan<'a> {
    /// The node of each step.
    step_nodes: &'a [Node],
    /// Nodes computed straight into their output slot.
    pinned: &'a [bool],
    /// Last step reading each node (`usize::MAX`: none).
    last_use: &'a [usize],
    /// Output slots of call outputs that are outputs of the function, by node.
    call_copies: &'a FxHashMap<u32, Vec<u32>>,
    /// First register after the output slots.
    temp_start: u32,
}

/// Emits the instructions of `steps` with registers for temporaries allocated after
/// `temp_start` and reused after their last use. A call gets a block of registers for its
/// outputs (its output nodes are names for those registers and emit nothing); the block is
/// reused by a later call with as many outputs once no step reads the outputs any more.
/// Returns the tape and the number of registers used.
fn allocate(
    g: &Graph,
    steps: &[u32],
    loc: &mut Locals,
    plan: &Plan,
    ext: &mut Externals,
) -> (Vec<Instr>, u32) {
    let Plan {
        step_nodes,
        pinned,
        last_use,
        call_copies,
        temp_start,
    } = *plan;
    let mut free: Vec<u32> = Vec::new();
    let mut work_size = temp_start;
    let mut tape = Vec::with_capacity(steps.len());
    // Registers inside call blocks are never put on the scalar free list; whole blocks
    // are freed after their last reader (`block_ends[s]`: blocks whose last reader is
    // step s) into free lists by size.
    // (A map, not a vector per step: most tapes have no calls, and a vector per step of a
    // Hessian's millions would be 24 bytes each.)
    let mut block_ends: FxHashMap<usize, Vec<(u32, u32)>> = FxHashMap::default();
    let mut free_blocks: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    for (s, &id) in steps.iter().enumerate() {
        if s > 0 && !block_ends.is_empty() {
            for (block, size) in block_ends.remove(&(s - 1)).into_iter().flatten() {
                free_blocks.entry(size).or_default().push(block);
            }
        }
        let node = step_nodes[s];
        let l = loc.local(id);
        match node.op {
            Op::CallOutput => {
                let block = loc.register[loc.local(node.args[0])];
                loc.register[l] = block + node.args[1];
                continue;
            }
            Op::Call => {
                let site = &g.calls[node.args[0] as usize];
                let args: Vec<u32> = site
                    .inputs
                    .iter()
                    .map(|&a| loc.register[loc.local(a)])
                    .collect();
                let mut dying: Vec<u32> = site
                    .inputs
                    .iter()
                    .filter(|&&a| last_use[loc.local(a)] == s && loc.freeable[loc.local(a)])
                    .map(|&a| loc.register[loc.local(a)])
                    .filter(|&r| r >= temp_start)
                    .collect();
                dying.sort_unstable();
                dying.dedup();
                free.extend(dying);
                let size = site.outputs.len() as u32;
                let block = match free_blocks.get_mut(&size).and_then(Vec::pop) {
                    Some(b) => b,
                    None => {
                        work_size += size;
                        work_size - size
                    }
                };
                // The last step reading any output (outputs of the function are copied
                // right after the call, so they do not keep the block).
                let end = site
                    .outputs
                    .iter()
                    .filter(|&&o| loc.is_seen(o))
                    .map(|&o| match last_use[loc.local(o)] {
                        usize::MAX => s,
                        e => e,
                    })
                    .max()
                    .unwrap_or(s);
                block_ends.entry(end).or_default().push((block, size));
                loc.register[l] = block;
                tape.push(Instr {
                    op: Op::Call,
                    d: ext.calls.len() as u32,
                    a: 0,
                    b: 0,
                    c: 0,
                });
                ext.calls.push(CallInstr {
                    function: site.function.clone(),
                    args,
                    out: block,
                });
                // Outputs of the function that are outputs of this call.
                for (k, o) in site.outputs.iter().enumerate() {
                    for &slot in call_copies.get(o).into_iter().flatten() {
                        let r = block + k as u32;
                        tape.push(Instr {
                            op: Op::Sym,
                            d: slot,
                            a: r,
                            b: r,
                            c: r,
                        });
                    }
                }
                continue;
            }
            _ => {}
        }
        let arity = node.op.arity();
        let mut regs = [0u32; 3];
        for (r, &a) in regs.iter_mut().zip(&node.args[..arity]) {
            *r = loc.register[loc.local(a)];
        }
        // Operands whose last use is here free their registers first, so the result may
        // take one of them (operands are read before the write).
        for k in 0..arity {
            let a = node.args[k];
            if last_use[loc.local(a)] == s
                && regs[k] >= temp_start
                && loc.freeable[loc.local(a)]
                && !regs[..k].contains(&regs[k])
            {
                free.push(regs[k]);
            }
        }
        let d = if pinned[l] {
            loc.register[l]
        } else {
            let d = free.pop().unwrap_or_else(|| {
                work_size += 1;
                work_size - 1
            });
            loc.register[l] = d;
            d
        };
        let c = if node.op == Op::Interpolant {
            ext.table(g, node.args[1])
        } else if node.op == Op::Interpolant2 {
            ext.table(g, node.args[2])
        } else if arity == 3 {
            regs[2]
        } else {
            regs[0]
        };
        tape.push(Instr {
            op: node.op,
            d,
            a: regs[0],
            b: if arity >= 2 { regs[1] } else { regs[0] },
            c,
        });
    }
    (tape, work_size)
}
