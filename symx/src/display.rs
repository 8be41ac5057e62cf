//! Printing expressions, and parsing the printed form back.
//!
//! The printed form is fully parenthesised: `+ − * /` are infix, negation is `(-x)`, every
//! other operation is a call such as `pow(x,3)` or `if_else(c,a,b)`. A subexpression used
//! more than once is printed once as a binding `@1=...; ` before the result, as CasADi does,
//! so that printing a graph with sharing stays linear in its size. [`parse`] reads this
//! form back into the identical expression (same node).
use crate::error::SymxError;
use crate::expr::Expr;
use crate::graph::{self, Graph};
use crate::op::Op;
use rustc_hash::FxHashMap;
use std::fmt::{self, Write};

fn infix(op: Op) -> Option<char> {
    match op {
        Op::Add => Some('+'),
        Op::Sub => Some('-'),
        Op::Mul => Some('*'),
        Op::Div => Some('/'),
        _ => None,
    }
}

fn write_constant(out: &mut impl Write, v: f64) -> fmt::Result {
    if v == v.trunc() && v.abs() < 1e15 {
        write!(out, "{}", v as i64)
    } else {
        write!(out, "{v:?}")
    }
}

enum Task {
    Node(u32),
    Text(&'static str),
    /// `[k]`: an entry of a call's outputs.
    Index(u32),
}

/// Writes `root` with shared subexpressions bound to `@k` names.
fn write_expr(g: &Graph, root: u32, out: &mut impl Write) -> fmt::Result {
    // Count uses of each interior node inside the tree of `root`, iteratively.
    let mut uses: FxHashMap<u32, u32> = FxHashMap::default();
    let mut stack = vec![root];
    while let Some(id) = stack.pop() {
        let n = g.node(id);
        if matches!(n.op, Op::Const | Op::Sym) {
            continue;
        }
        let count = uses.entry(id).or_insert(0);
        *count += 1;
        if *count == 1 {
            stack.extend_from_slice(g.operands(id));
        }
    }
    // Shared nodes in ascending (topological) order get bindings.
    let mut shared: Vec<u32> = uses
        .iter()
        .filter(|&(&id, &c)| c > 1 && id != root)
        .map(|(&id, _)| id)
        .collect();
    shared.sort_unstable();
    let mut names: FxHashMap<u32, usize> = FxHashMap::default();
    for (k, &id) in shared.iter().enumerate() {
        write!(out, "@{}=", k + 1)?;
        write_tree(g, id, &names, out)?;
        out.write_str("; ")?;
        names.insert(id, k + 1);
    }
    write_tree(g, root, &names, out)
}

fn write_tree(
    g: &Graph,
    root: u32,
    names: &FxHashMap<u32, usize>,
    out: &mut impl Write,
) -> fmt::Result {
    let mut tasks = vec![Task::Node(root)];
    let mut top = true;
    while let Some(task) = tasks.pop() {
        let id = match task {
            Task::Text(t) => {
                out.write_str(t)?;
                continue;
            }
            Task::Index(k) => {
                write!(out, "[{k}]")?;
                continue;
            }
            Task::Node(id) => id,
        };
        let n = g.node(id);
        if !top {
            if let Some(k) = names.get(&id) {
                write!(out, "@{k}")?;
                continue;
            }
        }
        top = false;
        match n.op {
            Op::Const => write_constant(out, n.value().unwrap_or(f64::NAN))?,
            Op::Sym => out.write_str(g.symbol_name(id))?,
            Op::CallOutput => {
                tasks.push(Task::Index(n.args[1]));
                tasks.push(Task::Node(n.args[0]));
            }
            Op::Call => {
                let site = &g.calls[n.args[0] as usize];
                write!(out, "{}(", site.function.name())?;
                tasks.push(Task::Text(")"));
                for (i, &a) in site.inputs.iter().enumerate().rev() {
                    tasks.push(Task::Node(a));
                    if i > 0 {
                        tasks.push(Task::Text(","));
                    }
                }
            }
            Op::Interpolant => {
                write!(out, "interpolant#{}(", n.args[1])?;
                tasks.push(Task::Text(")"));
                tasks.push(Task::Node(n.args[0]));
            }
            Op::Interpolant2 => {
                write!(out, "interpolant#{}(", n.args[2])?;
                tasks.extend([
                    Task::Text(")"),
                    Task::Node(n.args[1]),
                    Task::Text(","),
                    Task::Node(n.args[0]),
                ]);
            }
            Op::Neg => {
                out.write_str("(-")?;
                tasks.push(Task::Text(")"));
                tasks.push(Task::Node(n.args[0]));
            }
            op => {
                let args = n.operands();
                if let Some(c) = infix(op) {
                    out.write_char('(')?;
                    tasks.push(Task::Text(")"));
                    tasks.push(Task::Node(args[1]));
                    tasks.push(Task::Text(match c {
                        '+' => "+",
                        '-' => "-",
                        '*' => "*",
                        _ => "/",
                    }));
                    tasks.push(Task::Node(args[0]));
                } else {
                    out.write_str(op.name())?;
                    out.write_char('(')?;
                    tasks.push(Task::Text(")"));
                    for (i, &a) in args.iter().enumerate().rev() {
                        tasks.push(Task::Node(a));
                        if i > 0 {
                            tasks.push(Task::Text(","));
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Render into a string first: the graph must not stay borrowed while the
        // formatter runs user code.
        let mut s = String::new();
        graph::with(|g| write_expr(g, self.id, &mut s))?;
        f.write_str(&s)
    }
}

/// Parses the printed form of an expression, resolving names against `symbols`.
///
/// Symbol names are letters, digits, `_`, `.` and `^`, optionally followed by bracketed
/// indices (`x[3]`, `A[1,2]`, `r_BR^3[0]`); other names do not parse back.
///
/// `parse(&e.to_string(), symbols)` returns `e` itself (the same node) when `symbols`
/// holds every symbol of `e` under distinct names.
pub fn parse(text: &str, symbols: &[Expr]) -> Result<Expr, SymxError> {
    let mut by_name = FxHashMap::default();
    for &s in symbols {
        let name = s.name().ok_or_else(|| SymxError::NotASymbol {
            what: "parse symbol table".into(),
            index: by_name.len(),
        })?;
        by_name.insert(name, s);
    }
    let mut p = Parser {
        s: text.as_bytes(),
        pos: 0,
        by_name,
        bindings: FxHashMap::default(),
    };
    loop {
        p.skip_ws();
        if p.peek() == Some(b'@') && p.s[p.pos..].contains(&b'=') && p.is_binding() {
            p.pos += 1;
            let k = p.integer()?;
            p.expect(b'=')?;
            let e = p.expr()?;
            p.expect(b';')?;
            p.bindings.insert(k, e);
        } else {
            break;
        }
    }
    let e = p.expr()?;
    p.skip_ws();
    if p.pos != p.s.len() {
        return Err(p.error("unexpected trailing text"));
    }
    Ok(e)
}

struct Parser<'a> {
    s: &'a [u8],
    pos: usize,
    by_name: FxHashMap<String, Expr>,
    bindings: FxHashMap<usize, Expr>,
}

/// Pending operators of the (non-recursive, shunting-yard) expression parser.
enum Pending {
    /// A binary operator `+ - * /`.
    Infix(u8),
    /// Prefix minus.
    Neg,
    /// An open parenthesis.
    Paren,
    /// An open function call with the number of arguments started so far.
    Call(Op, usize),
}

fn precedence(c: u8) -> u8 {
    if matches!(c, b'+' | b'-') {
        1
    } else {
        2
    }
}

impl Parser<'_> {
    fn error(&self, msg: &str) -> SymxError {
        SymxError::Parse {
            position: self.pos,
            message: msg.to_string(),
        }
    }
    fn skip_ws(&mut self) {
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }
    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.s.get(self.pos).copied()
    }
    fn expect(&mut self, c: u8) -> Result<(), SymxError> {
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.error(&format!("expected '{}'", c as char)))
        }
    }
    /// Whether the text at `pos` is `@k=` (a binding) rather than a use of `@k`.
    fn is_binding(&self) -> bool {
        let mut i = self.pos + 1;
        while i < self.s.len() && self.s[i].is_ascii_digit() {
            i += 1;
        }
        self.s.get(i) == Some(&b'=')
    }
    fn integer(&mut self) -> Result<usize, SymxError> {
        let start = self.pos;
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_digit() {
            self.pos += 1;
        }
        std::str::from_utf8(&self.s[start..self.pos])
            .ok()
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| self.error("expected an integer"))
    }

    /// Applies the operator on top of `ops` to the operands on top of `out`.
    fn reduce(&self, ops: &mut Vec<Pending>, out: &mut Vec<Expr>) -> Result<(), SymxError> {
        let underflow = || self.error("missing operand");
        match ops.pop() {
            Some(Pending::Neg) => {
                let a = out.pop().ok_or_else(underflow)?;
                out.push(-a);
            }
            Some(Pending::Infix(c)) => {
                let b = out.pop().ok_or_else(underflow)?;
                let a = out.pop().ok_or_else(underflow)?;
                out.push(match c {
                    b'+' => a + b,
                    b'-' => a - b,
                    b'*' => a * b,
                    _ => a / b,
                });
            }
            _ => unreachable!("reduce called on a bracket"),
        }
        Ok(())
    }

    /// Reduces every operator above the innermost open bracket.
    fn reduce_to_bracket(
        &self,
        ops: &mut Vec<Pending>,
        out: &mut Vec<Expr>,
    ) -> Result<(), SymxError> {
        while matches!(ops.last(), Some(Pending::Neg | Pending::Infix(_))) {
            self.reduce(ops, out)?;
        }
        Ok(())
    }

    /// One expression, up to the first character that cannot continue it. Iterative (an
    /// explicit operator stack), so nesting depth is limited by memory, not by the stack.
    fn expr(&mut self) -> Result<Expr, SymxError> {
        let mut out: Vec<Expr> = Vec::new();
        let mut ops: Vec<Pending> = Vec::new();
        let mut expect_operand = true;
        loop {
            let c = self.peek();
            if expect_operand {
                match c {
                    Some(b'-') => {
                        self.pos += 1;
                        ops.push(Pending::Neg);
                    }
                    Some(b'(') => {
                        self.pos += 1;
                        ops.push(Pending::Paren);
                    }
                    _ => {
                        match self.operand()? {
                            Operand::Value(e) => {
                                out.push(e);
                                expect_operand = false;
                            }
                            Operand::Call(op) => {
                                self.pos += 1; // the '('
                                ops.push(Pending::Call(op, 1));
                            }
                        }
                    }
                }
                continue;
            }
            match c {
                Some(c @ (b'+' | b'-' | b'*' | b'/')) => {
                    let p = precedence(c);
                    loop {
                        match ops.last() {
                            Some(Pending::Neg) => self.reduce(&mut ops, &mut out)?,
                            Some(&Pending::Infix(t)) if precedence(t) >= p => {
                                self.reduce(&mut ops, &mut out)?
                            }
                            _ => break,
                        }
                    }
                    self.pos += 1;
                    ops.push(Pending::Infix(c));
                    expect_operand = true;
                }
                Some(b',') => {
                    self.reduce_to_bracket(&mut ops, &mut out)?;
                    match ops.last_mut() {
                        Some(Pending::Call(_, n)) => *n += 1,
                        _ => return Err(self.error("',' outside a function call")),
                    }
                    self.pos += 1;
                    expect_operand = true;
                }
                Some(b')') => {
                    self.reduce_to_bracket(&mut ops, &mut out)?;
                    match ops.pop() {
                        Some(Pending::Paren) => {}
                        Some(Pending::Call(op, n)) => {
                            if n != op.arity() {
                                return Err(self.error(&format!(
                                    "'{}' takes {} arguments, got {n}",
                                    op.name(),
                                    op.arity()
                                )));
                            }
                            let args: Vec<u32> =
                                out.split_off(out.len() - n).iter().map(|e| e.id).collect();
                            out.push(Expr::from_id(graph::with(|g| g.make(op, &args))));
                        }
                        _ => return Err(self.error("unbalanced ')'")),
                    }
                    self.pos += 1;
                }
                _ => break,
            }
        }
        self.reduce_to_bracket(&mut ops, &mut out)?;
        if !ops.is_empty() {
            return Err(self.error("expected ')'"));
        }
        debug_assert_eq!(out.len(), 1);
        out.pop()
            .ok_or_else(|| self.error("expected an expression"))
    }

    /// A number, symbol, binding use or the name of a call (followed by `(`).
    fn operand(&mut self) -> Result<Operand, SymxError> {
        match self.peek() {
            Some(b'@') => {
                self.pos += 1;
                let k = self.integer()?;
                self.bindings
                    .get(&k)
                    .copied()
                    .map(Operand::Value)
                    .ok_or_else(|| self.error(&format!("unknown binding @{k}")))
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => self.number().map(Operand::Value),
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let start = self.pos;
                while self.pos < self.s.len() {
                    let c = self.s[self.pos];
                    if c.is_ascii_alphanumeric() || matches!(c, b'_' | b'.' | b'^') {
                        self.pos += 1;
                    } else if c == b'[' {
                        // Indexed names such as `x[3]` or `A[1,2]`.
                        match self.s[self.pos..].iter().position(|&c| c == b']') {
                            Some(close) => self.pos += close + 1,
                            None => return Err(self.error("unclosed '['")),
                        }
                    } else {
                        break;
                    }
                }
                let name = String::from_utf8_lossy(&self.s[start..self.pos]).into_owned();
                if self.peek() == Some(b'(') {
                    return Op::WITH_OPERANDS
                        .iter()
                        .copied()
                        .find(|op| op.name() == name)
                        .map(Operand::Call)
                        .ok_or_else(|| self.error(&format!("unknown function '{name}'")));
                }
                match name.as_str() {
                    "inf" => return Ok(Operand::Value(Expr::constant(f64::INFINITY))),
                    "NaN" => return Ok(Operand::Value(Expr::constant(f64::NAN))),
                    _ => {}
                }
                self.by_name
                    .get(&name)
                    .copied()
                    .map(Operand::Value)
                    .ok_or_else(|| self.error(&format!("unknown symbol '{name}'")))
            }
            _ => Err(self.error("expected an expression")),
        }
    }

    fn number(&mut self) -> Result<Expr, SymxError> {
        let start = self.pos;
        while self.pos < self.s.len() {
            let c = self.s[self.pos];
            let exp_sign = matches!(c, b'+' | b'-')
                && self.pos > start
                && matches!(self.s[self.pos - 1], b'e' | b'E');
            if c.is_ascii_digit() || matches!(c, b'.' | b'e' | b'E') || exp_sign {
                self.pos += 1;
            } else {
                break;
            }
        }
        std::str::from_utf8(&self.s[start..self.pos])
            .ok()
            .and_then(|t| t.parse::<f64>().ok())
            .map(Expr::constant)
            .ok_or_else(|| self.error("malformed number"))
    }
}

enum Operand {
    Value(Expr),
    Call(Op),
}
