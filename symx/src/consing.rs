//! The hash-consing index of the expression arena: finds the existing node equal to a
//! new one, so that no node is stored twice.
//!
//! A node can only equal a node with the same operands, so a node with operands is filed
//! under its *anchor*, its newest operand (the largest index): each node keeps a short
//! list of the nodes anchored on it. A new node's operands are mostly nodes made moments
//! before, so the anchor's list and the nodes on it are still in cache; a global hash table
//! would instead cost a cache and TLB miss per lookup once the graph outgrows the caches
//! (millions of nodes: an OCP's Hessian, issue 13). Nodes without operands (constants,
//! calls) and nodes whose anchor's list is full go into a hash table (symbols are always
//! new and not indexed), so that a
//! popular operand (a multiplier shared by thousands of products) costs no long walks.
//!
//! Invariant: a node with operands is on its anchor's list if that list held fewer than
//! [`LIST_LIMIT`] nodes when it was made, else in the table. Lists only grow, so a lookup
//! walks the anchor's list and consults the table only if the list is full.
use crate::graph::Node;
use rustc_hash::FxHashMap;
use std::collections::hash_map::Entry;

/// Longest list of nodes anchored on one node (8 to 32 are equally fast on the OCP of
/// issue 13; 4 is slower: `examples/ocp_setup_scaling.rs`).
const LIST_LIMIT: u8 = 16;
const NONE: u32 = u32::MAX;

/// The index; its per-node arrays have one entry per node of the arena.
pub(crate) struct NodeIndex {
    table: FxHashMap<Node, u32>,
    /// Newest node anchored on each node (`NONE`: none).
    first: Vec<u32>,
    /// The next (older) node on the same anchor's list.
    next: Vec<u32>,
    /// Length of each node's list.
    count: Vec<u8>,
}

impl NodeIndex {
    pub fn new() -> NodeIndex {
        NodeIndex {
            table: FxHashMap::default(),
            first: Vec::new(),
            next: Vec::new(),
            count: Vec::new(),
        }
    }

    /// The index of the node of `nodes` equal to `node`, pushing it first if there is none.
    pub fn intern(&mut self, nodes: &mut Vec<Node>, node: Node) -> u32 {
        if let Some(anchor) = node.operands().iter().copied().max() {
            let a = anchor as usize;
            let mut p = self.first[a];
            while p != NONE {
                if nodes[p as usize] == node {
                    return p;
                }
                p = self.next[p as usize];
            }
            if self.count[a] < LIST_LIMIT {
                let id = self.push(nodes, node);
                self.next[id as usize] = self.first[a];
                self.first[a] = id;
                self.count[a] += 1;
                return id;
            }
        }
        let id = u32::try_from(nodes.len()).expect("symx graph exceeds 2^32 nodes");
        match self.table.entry(node) {
            Entry::Occupied(e) => *e.get(),
            Entry::Vacant(e) => {
                e.insert(id);
                self.push(nodes, node)
            }
        }
    }

    /// Pushes `node` without indexing it (a symbol: always distinct); returns its index.
    pub fn push(&mut self, nodes: &mut Vec<Node>, node: Node) -> u32 {
        let id = u32::try_from(nodes.len()).expect("symx graph exceeds 2^32 nodes");
        nodes.push(node);
        self.first.push(NONE);
        self.next.push(NONE);
        self.count.push(0);
        id
    }
}
