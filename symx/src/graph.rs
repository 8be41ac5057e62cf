//! The expression arena: nodes stored in a thread-local vector, children before parents.
//!
//! Every node is identified by a `u32` index. Nodes are hash-consed when created (a
//! structurally identical node is never stored twice; the index is in `consing.rs`), so
//! common subexpressions are shared by construction and constants are interned. Because a
//! node can only refer to nodes that already exist, ascending index order is a topological
//! order of the whole graph; every traversal in this crate relies on that and none of them
//! recurses.
use crate::call::CallSite;
use crate::consing::NodeIndex;
use crate::op::Op;
use crate::table::Table;
use rustc_hash::FxHashMap;
use std::cell::RefCell;
use std::sync::Arc;

/// One node: an operation and up to three operand indices.
///
/// For `Const` the two first slots hold the bits of the value; for `Sym` the first slot
/// holds the symbol's number.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct Node {
    pub op: Op,
    pub args: [u32; 3],
}

impl Node {
    pub fn constant(v: f64) -> Node {
        // One zero: -0.0 and 0.0 intern to the same node; one NaN (the payload and sign of
        // a NaN produced by folding, e.g. 0/0, are not printable, so they must not matter).
        let v = if v == 0.0 {
            0.0
        } else if v.is_nan() {
            f64::NAN
        } else {
            v
        };
        let bits = v.to_bits();
        Node {
            op: Op::Const,
            args: [bits as u32, (bits >> 32) as u32, 0],
        }
    }

    /// The value of a `Const` node.
    pub fn value(&self) -> Option<f64> {
        (self.op == Op::Const)
            .then(|| f64::from_bits(self.args[0] as u64 | ((self.args[1] as u64) << 32)))
    }

    /// The operand indices actually used by this node.
    pub fn operands(&self) -> &[u32] {
        &self.args[..self.op.arity()]
    }
}

/// The arena of one thread.
pub(crate) struct Graph {
    pub nodes: Vec<Node>,
    /// The hash-consing index (`consing.rs`).
    index: NodeIndex,
    pub symbol_names: Vec<Box<str>>,
    /// Node index of each symbol, by symbol number.
    pub symbol_nodes: Vec<u32>,
    /// Lookup tables used by `Interpolant` nodes, by table number.
    pub tables: Vec<Arc<Table>>,
    /// Table number of each registered table, by address (the graph keeps the `Arc`, so an
    /// address is never reused while registered).
    table_index: FxHashMap<usize, u32>,
    /// Table number of each table's partial derivatives (by axis), once built.
    table_derivative: Vec<[Option<u32>; 2]>,
    /// Calls of compiled functions, by call number (`Call` nodes hold the number).
    pub calls: Vec<CallSite>,
    /// Call number of each (function, argument nodes) pair: identical calls are one call.
    pub call_index: FxHashMap<(u64, Vec<u32>), u32>,
    /// The called functions, by [`crate::Function`] identity, shared by their call sites.
    pub functions: FxHashMap<u64, Arc<crate::Function>>,
    /// The first failure of the derivative sweep running (an external function without a
    /// Jacobian), returned by the public derivative builders.
    pub derivative_error: Option<crate::SymxError>,
}

thread_local! {
    static GRAPH: RefCell<Graph> = RefCell::new(Graph::new());
}

/// Runs `f` with exclusive access to this thread's graph.
///
/// Must not be nested: code inside `f` works on the `&mut Graph` it receives.
pub(crate) fn with<R>(f: impl FnOnce(&mut Graph) -> R) -> R {
    GRAPH.with(|g| f(&mut g.borrow_mut()))
}

impl Graph {
    fn new() -> Graph {
        let mut g = Graph {
            nodes: Vec::new(),
            index: NodeIndex::new(),
            symbol_names: Vec::new(),
            symbol_nodes: Vec::new(),
            tables: Vec::new(),
            table_index: FxHashMap::default(),
            table_derivative: Vec::new(),
            calls: Vec::new(),
            call_index: FxHashMap::default(),
            functions: FxHashMap::default(),
            derivative_error: None,
        };
        // Indices 0 and 1 are the constants 0 and 1, used everywhere.
        g.intern(Node::constant(0.0));
        g.intern(Node::constant(1.0));
        g
    }

    /// Adds `node` unless an identical one exists; returns its index.
    pub fn intern(&mut self, node: Node) -> u32 {
        self.index.intern(&mut self.nodes, node)
    }

    /// Creates a new, distinct symbol.
    pub fn symbol(&mut self, name: &str) -> u32 {
        let number = self.symbol_names.len() as u32;
        let node = Node {
            op: Op::Sym,
            args: [number, 0, 0],
        };
        let id = self.index.push(&mut self.nodes, node);
        self.symbol_names.push(name.into());
        self.symbol_nodes.push(id);
        id
    }

    /// The number of `table` in this graph, registering it on first use.
    pub fn table_id(&mut self, table: &Arc<Table>) -> u32 {
        let key = Arc::as_ptr(table) as usize;
        if let Some(&t) = self.table_index.get(&key) {
            return t;
        }
        let t = self.tables.len() as u32;
        self.tables.push(table.clone());
        self.table_derivative.push([None; 2]);
        self.table_index.insert(key, t);
        t
    }

    /// The number of the partial derivative of table `t` along `axis`, built once.
    pub fn derivative_table(&mut self, t: u32, axis: usize) -> u32 {
        if let Some(d) = self.table_derivative[t as usize][axis] {
            return d;
        }
        let d = Arc::new(self.tables[t as usize].derivative(axis));
        let d = self.table_id(&d);
        self.table_derivative[t as usize][axis] = Some(d);
        d
    }

    /// `table_t(x)`: a 1-D lookup node (folded when `x` is a constant).
    pub fn interpolant(&mut self, x: u32, t: u32) -> u32 {
        debug_assert_eq!(self.tables[t as usize].dims(), 1);
        if let Some(v) = self.value(x) {
            let y = self.tables[t as usize].eval(&[v]);
            return self.constant(y);
        }
        self.intern(Node {
            op: Op::Interpolant,
            args: [x, t, 0],
        })
    }

    /// `table_t(x, y)`: a 2-D lookup node (folded when `x` and `y` are constants).
    pub fn interpolant2(&mut self, x: u32, y: u32, t: u32) -> u32 {
        debug_assert_eq!(self.tables[t as usize].dims(), 2);
        if let (Some(u), Some(v)) = (self.value(x), self.value(y)) {
            let z = self.tables[t as usize].eval(&[u, v]);
            return self.constant(z);
        }
        self.intern(Node {
            op: Op::Interpolant2,
            args: [x, y, t],
        })
    }

    pub fn constant(&mut self, v: f64) -> u32 {
        self.intern(Node::constant(v))
    }

    #[inline]
    pub fn node(&self, id: u32) -> Node {
        self.nodes[id as usize]
    }

    /// The operand indices of node `id` (for a `Call`, its argument entries).
    #[inline]
    pub fn operands(&self, id: u32) -> &[u32] {
        let n = &self.nodes[id as usize];
        if n.op == Op::Call {
            &self.calls[n.args[0] as usize].inputs
        } else {
            n.operands()
        }
    }

    #[inline]
    pub fn value(&self, id: u32) -> Option<f64> {
        self.nodes[id as usize].value()
    }

    pub fn symbol_name(&self, id: u32) -> &str {
        let n = self.node(id);
        debug_assert_eq!(n.op, Op::Sym);
        &self.symbol_names[n.args[0] as usize]
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }
}

/// Runs `f` with a new, empty expression graph on this thread, then drops that graph
/// (releasing its memory) and restores the one that was current before, also when `f`
/// panics. Scopes nest.
///
/// The graph only grows while a program builds expressions; a long-running program that
/// builds many models one after the other wraps each build in a scope, keeps the compiled
/// [`crate::Function`]s (they hold no reference to any graph) and lets the rest go.
///
/// The rule that keeps it sound: an [`crate::Expr`] belongs to the graph it was made in.
/// The bounds make crossing the scope impossible by construction: `f` must be `Send`, so
/// it cannot capture an `Expr` (or a `Matrix`, or a reference to one) from outside, and
/// the result must be `Send`, so no `Expr` comes out. (What the bounds cannot see is an
/// `Expr` smuggled through a `thread_local!` or a global of the caller's own: don't.)
///
/// ```
/// use symx::{node_count, with_fresh_arena, Expr, Function};
/// let before = node_count();
/// let f = with_fresh_arena(|| {
///     let x = Expr::sym("x");
///     Function::new(&[&[x]], &[&[x.sin() * x]]).unwrap()
/// });
/// assert_eq!(node_count(), before); // the scope's nodes are gone...
/// assert_eq!(f.call(&[&[2.0]]).unwrap()[0][0], 2.0f64.sin() * 2.0); // ...its function works
/// ```
/// An `Expr` from outside cannot be used inside, nor one from inside outside:
/// ```compile_fail
/// let x = symx::Expr::sym("x");
/// symx::with_fresh_arena(|| symx::Function::new(&[&[x]], &[&[x.sin()]]).unwrap());
/// ```
/// ```compile_fail
/// let y = symx::with_fresh_arena(|| symx::Expr::sym("y"));
/// ```
pub fn with_fresh_arena<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    /// Puts the outer graph back when the scope ends, normally or by unwinding.
    struct Restore(Option<Graph>);
    impl Drop for Restore {
        fn drop(&mut self) {
            if let Some(outer) = self.0.take() {
                let inner = with(|g| std::mem::replace(g, outer));
                drop(inner);
            }
        }
    }
    let _restore = Restore(Some(with(|g| std::mem::replace(g, Graph::new()))));
    f()
}

/// Number of nodes in this thread's graph (a measure of memory use).
pub fn node_count() -> usize {
    with(|g| g.len())
}
