//! Parameters: one way to set their values on a [`Problem`](crate::Problem) and on a
//! [`Compiled`](crate::Compiled), by handle or by name ([`ParameterKey`]).
use crate::problem::{Block, BuildError};
use rustc_hash::FxHashMap;
use std::thread::ThreadId;
use symx::{Expr, Matrix};

/// Which parameter entries to set: the handles returned by
/// [`Problem::parameter`](crate::Problem::parameter) (any subset, in any order) or the name
/// of a whole parameter block.
///
/// Handles are symx expressions, which live in the expression graph of the thread that
/// built the problem; on another thread (say, a worker solving a clone of a
/// [`Compiled`](crate::Compiled)) set parameters by name.
///
/// Built implicitly by `From`: `set_value(&p, ..)` for a `Matrix` `p`, `set_value(&[a, b], ..)`,
/// `set_value(a, ..)` for one `Expr`, `set_value("p", ..)`.
#[derive(Clone, Copy, Debug)]
pub enum ParameterKey<'a> {
    /// These parameter entries, in this order.
    Handles(&'a [Expr]),
    /// One parameter entry.
    Handle(Expr),
    /// Every entry of the parameter declared under this name, in order.
    Name(&'a str),
}

impl<'a> From<&'a [Expr]> for ParameterKey<'a> {
    fn from(p: &'a [Expr]) -> Self {
        ParameterKey::Handles(p)
    }
}
impl<'a, const N: usize> From<&'a [Expr; N]> for ParameterKey<'a> {
    fn from(p: &'a [Expr; N]) -> Self {
        ParameterKey::Handles(p)
    }
}
impl<'a> From<&'a Vec<Expr>> for ParameterKey<'a> {
    fn from(p: &'a Vec<Expr>) -> Self {
        ParameterKey::Handles(p)
    }
}
impl<'a> From<&'a Matrix> for ParameterKey<'a> {
    fn from(p: &'a Matrix) -> Self {
        ParameterKey::Handles(p)
    }
}
impl From<Expr> for ParameterKey<'_> {
    fn from(p: Expr) -> Self {
        ParameterKey::Handle(p)
    }
}
impl<'a> From<&'a str> for ParameterKey<'a> {
    fn from(name: &'a str) -> Self {
        ParameterKey::Name(name)
    }
}
impl<'a> From<&'a String> for ParameterKey<'a> {
    fn from(name: &'a String) -> Self {
        ParameterKey::Name(name)
    }
}

/// Where each parameter entry sits: blocks by name, symx ids of the handles, entry names.
///
/// Holds symbol ids, not expressions, so a [`Compiled`](crate::Compiled) owning one stays
/// `Send`; `thread` is the thread whose expression graph the ids refer to.
#[derive(Clone, Debug)]
pub(crate) struct ParameterIndex {
    blocks: Vec<Block>,
    names: Vec<String>,
    ids: FxHashMap<u32, usize>,
    thread: ThreadId,
}

impl Default for ParameterIndex {
    fn default() -> Self {
        ParameterIndex {
            blocks: Vec::new(),
            names: Vec::new(),
            ids: FxHashMap::default(),
            thread: std::thread::current().id(),
        }
    }
}

impl ParameterIndex {
    /// Records a block of new parameter entries named `name`.
    pub fn push(&mut self, name: &str, p: &[Expr]) {
        self.blocks.push(Block {
            name: name.to_string(),
            start: self.names.len(),
            len: p.len(),
        });
        for &e in p {
            self.ids.insert(e.id(), self.names.len());
            self.names.push(
                e.name()
                    .unwrap_or_else(|| format!("p[{}]", self.names.len())),
            );
        }
    }

    /// The blocks, in declaration order.
    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }

    /// The name of entry `i` (e.g. `p[2]`).
    pub fn name(&self, i: usize) -> &str {
        &self.names[i]
    }

    /// The entry index of `e`, if it is a parameter handle (of this thread's graph).
    pub fn index_of(&self, e: Expr) -> Option<usize> {
        self.ids.get(&e.id()).copied()
    }

    /// The entries selected by `key`, checked against `values` (same count, all finite).
    pub fn resolve(&self, key: ParameterKey<'_>, values: &[f64]) -> Result<Vec<usize>, BuildError> {
        let idx = match key {
            ParameterKey::Name(name) => {
                let b = self.blocks.iter().find(|b| b.name == name).ok_or_else(|| {
                    BuildError::UnknownName {
                        kind: "parameter",
                        name: name.to_string(),
                    }
                })?;
                b.range().collect()
            }
            ParameterKey::Handle(e) => self.handles(std::slice::from_ref(&e))?,
            ParameterKey::Handles(p) => self.handles(p)?,
        };
        if values.len() != idx.len() {
            return Err(BuildError::Size {
                what: "set_value: values".into(),
                expected: idx.len(),
                got: values.len(),
            });
        }
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(BuildError::NotFinite {
                what: format!("value of parameter '{}'", self.names[idx[k]]),
                value: values[k],
            });
        }
        Ok(idx)
    }

    fn handles(&self, p: &[Expr]) -> Result<Vec<usize>, BuildError> {
        if std::thread::current().id() != self.thread {
            return Err(BuildError::ForeignThread {
                what: "set_value".into(),
            });
        }
        p.iter()
            .enumerate()
            .map(|(index, &e)| {
                self.index_of(e).ok_or_else(|| BuildError::NotDeclared {
                    what: format!("set_value ('{e}')"),
                    index,
                    kind: "parameter",
                })
            })
            .collect()
    }
}
