//! [`Problem`]: an Opti-like builder of nonlinear programs over symx expressions.
use crate::compiled::Compiled;
use crate::constraint::{Constraint, Row};
use rustc_hash::FxHashMap;
use symx::{Expr, Matrix};
use thiserror::Error;

/// A mistake in a problem definition, naming the culprit.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BuildError {
    /// A lower bound above an upper bound.
    #[error("{what}: lower bound {lower} > upper bound {upper}")]
    InvertedBounds {
        what: String,
        lower: f64,
        upper: f64,
    },
    /// NaN (or ∞ where a finite value is required).
    #[error("{what}: {value} is not allowed")]
    NotFinite { what: String, value: f64 },
    /// Two lengths that must agree.
    #[error("{what}: expected {expected} values, got {got}")]
    Size {
        what: String,
        expected: usize,
        got: usize,
    },
    /// An expression used where a variable (or parameter) of this problem is required.
    #[error("{what}: entry {index} is not a {kind} of this problem")]
    NotDeclared {
        what: String,
        index: usize,
        kind: &'static str,
    },
    /// A parameter whose value was never set.
    #[error("parameter '{name}' has no value (call set_value)")]
    MissingParameterValue { name: String },
    /// An expression depends on a symbol that is neither a variable nor a parameter.
    #[error("{location} depends on symbol '{name}', which is neither a variable nor a parameter")]
    FreeSymbol { location: String, name: String },
    /// A constraint between matrices of different shapes.
    #[error("constraint '{name}': shapes {left:?} and {right:?} differ")]
    ShapeMismatch {
        name: String,
        left: (usize, usize),
        right: (usize, usize),
    },
    /// A constraint that does not involve any variable.
    #[error("constraint '{name}' row {row} does not depend on any variable")]
    ConstantConstraint { name: String, row: usize },
    /// A name used twice for variables or parameters.
    #[error("the name '{name}' is already used")]
    DuplicateName { name: String },
    /// An error from symx while differentiating or compiling.
    #[error(transparent)]
    Symx(#[from] symx::SymxError),
}

/// A named block of consecutive entries (a variable, a parameter or a constraint group).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Block {
    /// The name given when declaring it.
    pub name: String,
    /// First index.
    pub start: usize,
    /// Number of entries.
    pub len: usize,
}

impl Block {
    /// The index range.
    pub fn range(&self) -> std::ops::Range<usize> {
        self.start..self.start + self.len
    }
}

/// A nonlinear program `min f(x, p)  s.t.  g_l ≤ g(x, p) ≤ g_u,  x_l ≤ x ≤ x_u`, built
/// symbolically and compiled once with [`Problem::compile`].
///
/// ```
/// use nlp::{Problem, Relation, NumericNlp};
/// let mut pb = Problem::new();
/// let x = pb.variable("x", 2);
/// pb.minimize((1.0 - x[0]).sq() + 100.0 * (x[1] - x[0].sq()).sq());
/// pb.subject_to((x[0].sq() + x[1].sq()).le(2.0)).unwrap();
/// pb.subject_to(x[0].ge(-1.5)).unwrap(); // a bound on one variable stays a bound
/// let compiled = pb.compile().unwrap();
/// assert_eq!((compiled.n(), compiled.m()), (2, 1));
/// ```
#[derive(Default)]
pub struct Problem {
    variables: Vec<Expr>,
    variable_blocks: Vec<Block>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    initial: Vec<f64>,
    variable_index: FxHashMap<u32, usize>,
    parameters: Vec<Expr>,
    parameter_blocks: Vec<Block>,
    parameter_values: Vec<Option<f64>>,
    parameter_index: FxHashMap<u32, usize>,
    objective: Option<Expr>,
    rows: Vec<Row>,
    constraint_blocks: Vec<Block>,
    complementarity: Vec<(String, Expr, Expr)>,
    cones: Vec<Cone>,
}

/// Smoothing ε of the smooth form `√(‖v‖² + ε²) − t ≤ ε` of a second-order cone (see
/// [`Problem::subject_to_cone`]).
pub const CONE_SMOOTHING: f64 = 1e-8;

/// A second-order cone `‖v‖ ≤ t` recorded by [`Problem::subject_to_cone`].
#[derive(Clone, Debug)]
pub struct Cone {
    /// The name given when declaring it (also the name of its smooth row).
    pub name: String,
    /// The row of g holding its smooth form.
    pub row: usize,
    /// The cone's `t`.
    pub t: Expr,
    /// The cone's `v`.
    pub v: Vec<Expr>,
    /// Whether t and every entry of v are affine in the variables (parameters allowed).
    pub affine: bool,
}

fn check_bound(what: impl Fn() -> String, lower: f64, upper: f64) -> Result<(), BuildError> {
    for v in [lower, upper] {
        if v.is_nan() {
            return Err(BuildError::NotFinite {
                what: what(),
                value: v,
            });
        }
    }
    if lower > upper {
        return Err(BuildError::InvertedBounds {
            what: what(),
            lower,
            upper,
        });
    }
    Ok(())
}

impl Problem {
    /// An empty problem.
    pub fn new() -> Problem {
        Problem::default()
    }

    fn check_name(&self, name: &str) -> Result<(), BuildError> {
        if self
            .variable_blocks
            .iter()
            .chain(&self.parameter_blocks)
            .any(|b| b.name == name)
        {
            return Err(BuildError::DuplicateName {
                name: name.to_string(),
            });
        }
        Ok(())
    }

    /// Declares a vector of `n` variables named `name[i]`: unbounded, initial value 0.
    ///
    /// Panics only if `name` is already used (use [`Problem::try_variable`] to get an error).
    pub fn variable(&mut self, name: &str, n: usize) -> Matrix {
        self.variable_matrix(name, n, 1)
    }

    /// Declares a scalar variable.
    pub fn scalar_variable(&mut self, name: &str) -> Expr {
        let x = Expr::sym(name);
        self.push_variables(name, &[x]);
        x
    }

    /// Declares a `rows × cols` matrix of variables.
    pub fn variable_matrix(&mut self, name: &str, rows: usize, cols: usize) -> Matrix {
        let x = Matrix::sym(name, rows, cols);
        self.push_variables(name, &x);
        x
    }

    /// Like [`Problem::variable`], but an error for a name already in use.
    pub fn try_variable(&mut self, name: &str, n: usize) -> Result<Matrix, BuildError> {
        self.check_name(name)?;
        Ok(self.variable(name, n))
    }

    fn push_variables(&mut self, name: &str, x: &[Expr]) {
        self.variable_blocks.push(Block {
            name: name.to_string(),
            start: self.variables.len(),
            len: x.len(),
        });
        for &e in x {
            self.variable_index.insert(e.id(), self.variables.len());
            self.variables.push(e);
            self.lower.push(f64::NEG_INFINITY);
            self.upper.push(f64::INFINITY);
            self.initial.push(0.0);
        }
    }

    /// Declares a vector of `n` parameters: values fixed during a solve, changeable between
    /// solves without recompiling ([`Compiled::set_parameter`]).
    pub fn parameter(&mut self, name: &str, n: usize) -> Matrix {
        let p = Matrix::sym_vec(name, n);
        self.push_parameters(name, &p);
        p
    }

    /// Declares a scalar parameter.
    pub fn scalar_parameter(&mut self, name: &str) -> Expr {
        let p = Expr::sym(name);
        self.push_parameters(name, &[p]);
        p
    }

    fn push_parameters(&mut self, name: &str, p: &[Expr]) {
        self.parameter_blocks.push(Block {
            name: name.to_string(),
            start: self.parameters.len(),
            len: p.len(),
        });
        for &e in p {
            self.parameter_index.insert(e.id(), self.parameters.len());
            self.parameters.push(e);
            self.parameter_values.push(None);
        }
    }

    fn indices(&self, x: &[Expr], what: &str, variables: bool) -> Result<Vec<usize>, BuildError> {
        let (map, kind) = if variables {
            (&self.variable_index, "variable")
        } else {
            (&self.parameter_index, "parameter")
        };
        x.iter()
            .enumerate()
            .map(|(index, e)| {
                map.get(&e.id())
                    .copied()
                    .ok_or_else(|| BuildError::NotDeclared {
                        what: what.to_string(),
                        index,
                        kind,
                    })
            })
            .collect()
    }

    fn variable_name(&self, i: usize) -> String {
        self.variables[i]
            .name()
            .unwrap_or_else(|| format!("x[{i}]"))
    }

    /// Sets `lower ≤ xᵢ ≤ upper` for every entry of `x` (±∞ for none).
    pub fn set_bounds(&mut self, x: &[Expr], lower: f64, upper: f64) -> Result<(), BuildError> {
        for i in self.indices(x, "set_bounds", true)? {
            check_bound(
                || format!("bounds of variable '{}'", self.variable_name(i)),
                lower,
                upper,
            )?;
            self.lower[i] = lower;
            self.upper[i] = upper;
        }
        Ok(())
    }

    /// Sets the initial guess of the entries of `x` (one finite value each).
    pub fn set_initial(&mut self, x: &[Expr], values: &[f64]) -> Result<(), BuildError> {
        let idx = self.indices(x, "set_initial", true)?;
        if values.len() != idx.len() {
            return Err(BuildError::Size {
                what: "set_initial".into(),
                expected: idx.len(),
                got: values.len(),
            });
        }
        for (&i, &v) in idx.iter().zip(values) {
            if !v.is_finite() {
                return Err(BuildError::NotFinite {
                    what: format!("initial value of '{}'", self.variable_name(i)),
                    value: v,
                });
            }
            self.initial[i] = v;
        }
        Ok(())
    }

    /// Sets the values of parameters (finite numbers).
    pub fn set_value(&mut self, p: &[Expr], values: &[f64]) -> Result<(), BuildError> {
        let idx = self.indices(p, "set_value", false)?;
        if values.len() != idx.len() {
            return Err(BuildError::Size {
                what: "set_value".into(),
                expected: idx.len(),
                got: values.len(),
            });
        }
        for (&i, &v) in idx.iter().zip(values) {
            if !v.is_finite() {
                let name = self.parameters[i].name().unwrap_or_default();
                return Err(BuildError::NotFinite {
                    what: format!("value of parameter '{name}'"),
                    value: v,
                });
            }
            self.parameter_values[i] = Some(v);
        }
        Ok(())
    }

    /// Sets the objective to minimise (replacing any previous one).
    pub fn minimize(&mut self, f: Expr) {
        self.objective = Some(f);
    }

    /// Adds a constraint, named `g<k>` after its position. See [`Problem::subject_to_named`].
    pub fn subject_to(&mut self, c: Constraint) -> Result<(), BuildError> {
        let name = format!("g{}", self.constraint_blocks.len());
        self.subject_to_named(&name, c)
    }

    /// Adds a named constraint (the name appears in errors, logs and [`Compiled`]'s blocks).
    ///
    /// A row `lo ≤ xᵢ ≤ hi` on a single variable becomes a bound of that variable (the
    /// intersection with its existing bounds), as IPOPT users expect; every other row
    /// becomes a row of `g`.
    pub fn subject_to_named(&mut self, name: &str, c: Constraint) -> Result<(), BuildError> {
        if let Some((left, right)) = c.mismatch {
            return Err(BuildError::ShapeMismatch {
                name: name.to_string(),
                left,
                right,
            });
        }
        let start = self.rows.len();
        for (k, row) in c.rows.iter().enumerate() {
            check_bound(
                || format!("constraint '{name}' row {k}"),
                row.lower,
                row.upper,
            )?;
            if row.expr.value().is_some() {
                return Err(BuildError::ConstantConstraint {
                    name: name.to_string(),
                    row: k,
                });
            }
        }
        for row in c.rows {
            if let Some(&i) = self.variable_index.get(&row.expr.id()) {
                let (lo, hi) = (self.lower[i].max(row.lower), self.upper[i].min(row.upper));
                check_bound(
                    || {
                        format!(
                            "bounds of variable '{}' (from constraint '{name}')",
                            self.variable_name(i)
                        )
                    },
                    lo,
                    hi,
                )?;
                self.lower[i] = lo;
                self.upper[i] = hi;
            } else {
                self.rows.push(row);
            }
        }
        if self.rows.len() > start {
            self.constraint_blocks.push(Block {
                name: name.to_string(),
                start,
                len: self.rows.len() - start,
            });
        }
        Ok(())
    }

    /// Adds the complementarity constraint `0 ≤ a ⊥ b ≥ 0` (a ≥ 0, b ≥ 0, a·b = 0).
    ///
    /// It is compiled as an ordinary NLP in the form of Fletcher & Leyffer (2004), "Solving
    /// mathematical programs with complementarity constraints as nonlinear programs",
    /// Optim. Methods Softw. 19(1): rows (or bounds) `a ≥ 0`, `b ≥ 0` and the product row
    /// `a·b ≤ 0` (named `name.a`, `name.b`, `name.ab`). The SQP back end solves this form
    /// directly, its elastic mode absorbing the QPs made degenerate by the product (no
    /// constraint qualification holds at a solution). The pair is recorded:
    /// [`Problem::complementarity_report`] gives the residual and the biactive set.
    pub fn complementarity(&mut self, name: &str, a: Expr, b: Expr) -> Result<(), BuildError> {
        use crate::constraint::Relation;
        self.subject_to_named(&format!("{name}.a"), a.ge(0.0))?;
        self.subject_to_named(&format!("{name}.b"), b.ge(0.0))?;
        self.subject_to_named(&format!("{name}.ab"), (a * b).le(0.0))?;
        self.complementarity.push((name.to_string(), a, b));
        Ok(())
    }

    /// The n-ary form: every `qᵢ ≥ 0` and at most one of them non-zero, i.e. the pairwise
    /// complementarity `qᵢ ⊥ qⱼ` for i < j (pairs named `name[i,j]`).
    pub fn complementarity_nary(&mut self, name: &str, q: &[Expr]) -> Result<(), BuildError> {
        for i in 0..q.len() {
            for j in i + 1..q.len() {
                self.complementarity(&format!("{name}[{i},{j}]"), q[i], q[j])?;
            }
        }
        Ok(())
    }

    /// Complementarity residual max over pairs of |min(a, b)| (zero iff a ≥ 0, b ≥ 0 and
    /// one of them is zero) at `x`, and the biactive pairs (both a and b ≤ `tol`).
    pub fn complementarity_report(
        &self,
        x: &[f64],
        tol: f64,
    ) -> Result<ComplementarityReport, BuildError> {
        let exprs: Vec<Expr> = self
            .complementarity
            .iter()
            .flat_map(|(_, a, b)| [*a, *b])
            .collect();
        let v = self.evaluate(&exprs, x)?;
        let mut residual: f64 = 0.0;
        let mut biactive = Vec::new();
        for (k, (name, _, _)) in self.complementarity.iter().enumerate() {
            let (a, b) = (v[2 * k], v[2 * k + 1]);
            residual = residual.max(a.min(b).abs());
            if a.abs() <= tol && b.abs() <= tol {
                biactive.push(name.clone());
            }
        }
        Ok(ComplementarityReport {
            residual,
            biactive,
            pairs: self.complementarity.len(),
        })
    }

    /// Adds the second-order cone constraint `‖v‖ ≤ t` (Euclidean norm).
    ///
    /// It becomes one row of g, named `name`, in the smooth convex form
    ///
    /// `√(‖v‖² + ε²) − t ≤ ε`, with ε = [`CONE_SMOOTHING`] = 1e-8,
    ///
    /// which solvers without cones (the interior-point method) solve as an ordinary
    /// constraint. It implies t ≥ 0 and is an outer approximation of the cone: it contains
    /// the cone and its points satisfy `‖v‖ − t ≤ ε` (the gap `‖v‖ + ε − √(‖v‖² + ε²)` is
    /// in [0, ε), largest at ‖v‖ ≫ ε); unlike `‖v‖ − t ≤ 0` it is differentiable at v = 0.
    ///
    /// When v and t are affine in the variables (their Hessians with respect to the
    /// variables are structurally zero; parameters are allowed), the cone is also recorded
    /// as an [`AffineCone`](crate::AffineCone) of the compiled problem: the SQP back end
    /// then replaces the smooth row by the exact cone, handed to clarabel as a second-order
    /// cone on the (exact) linearisation `‖v + ∇v·d‖ ≤ t + ∇t·d`. Otherwise the SQP
    /// linearises the smooth row like any other.
    pub fn subject_to_cone(&mut self, name: &str, v: &[Expr], t: Expr) -> Result<(), BuildError> {
        use crate::constraint::Relation;
        if v.is_empty() {
            return Err(BuildError::Size {
                what: format!("cone '{name}': entries of v"),
                expected: 1,
                got: 0,
            });
        }
        let mut affine = true;
        for &e in v.iter().chain(std::iter::once(&t)) {
            if e.value().is_none() && symx::hessian(e, &self.variables)?.nnz() != 0 {
                affine = false;
                break;
            }
        }
        let eps = CONE_SMOOTHING;
        let mut sum = Expr::constant(eps * eps);
        for &e in v {
            sum += e.sq();
        }
        let start = self.rows.len();
        self.subject_to_named(name, (sum.sqrt() - t).le(eps))?;
        debug_assert_eq!(self.rows.len(), start + 1);
        self.cones.push(Cone {
            name: name.to_string(),
            row: start,
            t,
            v: v.to_vec(),
            affine,
        });
        Ok(())
    }

    /// The second-order cones in the order they were added.
    pub fn cones(&self) -> &[Cone] {
        &self.cones
    }

    /// Largest violation `max(0, ‖v‖ − t)` over the cones at `x` (0 without cones).
    pub fn cone_residual(&self, x: &[f64]) -> Result<f64, BuildError> {
        let mut r: f64 = 0.0;
        for c in &self.cones {
            let mut exprs = vec![c.t];
            exprs.extend_from_slice(&c.v);
            let val = self.evaluate(&exprs, x)?;
            let norm = val[1..].iter().map(|a| a * a).sum::<f64>().sqrt();
            r = r.max(norm - val[0]);
        }
        Ok(r)
    }

    /// The complementarity pairs (name, a, b) in the order they were added.
    pub fn complementarity_pairs(&self) -> &[(String, Expr, Expr)] {
        &self.complementarity
    }

    /// A copy for the MPCC driver ([`crate::mpcc`]): the same variables, bounds, initial
    /// point, parameters, rows and pairs, with objective `objective`; without the product
    /// rows `name.ab` of the pairs unless `keep_products`.
    pub(crate) fn mpcc_copy(&self, objective: Expr, keep_products: bool) -> Problem {
        let products: std::collections::HashSet<String> = self
            .complementarity
            .iter()
            .map(|(name, _, _)| format!("{name}.ab"))
            .collect();
        let mut rows = Vec::with_capacity(self.rows.len());
        let mut constraint_blocks = Vec::with_capacity(self.constraint_blocks.len());
        let mut row_map = vec![None; self.rows.len()];
        for b in &self.constraint_blocks {
            if !keep_products && products.contains(&b.name) {
                continue;
            }
            for (k, r) in b.range().enumerate() {
                row_map[r] = Some(rows.len() + k);
            }
            constraint_blocks.push(Block {
                name: b.name.clone(),
                start: rows.len(),
                len: b.len,
            });
            rows.extend_from_slice(&self.rows[b.range()]);
        }
        Problem {
            variables: self.variables.clone(),
            variable_blocks: self.variable_blocks.clone(),
            lower: self.lower.clone(),
            upper: self.upper.clone(),
            initial: self.initial.clone(),
            variable_index: self.variable_index.clone(),
            parameters: self.parameters.clone(),
            parameter_blocks: self.parameter_blocks.clone(),
            parameter_values: self.parameter_values.clone(),
            parameter_index: self.parameter_index.clone(),
            objective: Some(objective),
            rows,
            constraint_blocks,
            complementarity: self.complementarity.clone(),
            cones: self
                .cones
                .iter()
                .filter_map(|c| row_map[c.row].map(|row| Cone { row, ..c.clone() }))
                .collect(),
        }
    }

    /// Number of variables.
    pub fn n_variables(&self) -> usize {
        self.variables.len()
    }

    /// Number of constraint rows (bounds on single variables are not rows).
    pub fn n_constraints(&self) -> usize {
        self.rows.len()
    }

    /// All variables, in the order of `x`.
    pub fn variables(&self) -> &[Expr] {
        &self.variables
    }

    /// All parameters, in declaration order.
    pub fn parameters(&self) -> &[Expr] {
        &self.parameters
    }

    /// The constraint expressions, in the order of `g`.
    pub fn constraint_expressions(&self) -> Vec<Expr> {
        self.rows.iter().map(|r| r.expr).collect()
    }

    /// The objective (zero if none was set).
    pub fn objective(&self) -> Expr {
        self.objective.unwrap_or_else(Expr::zero)
    }

    /// The name of constraint row `i`: `name` for a one-row group, `name[k]` otherwise.
    pub fn constraint_name(&self, i: usize) -> String {
        row_name(&self.constraint_blocks, i, "g")
    }

    /// Positions of `x` entries in the solution vector.
    pub fn variable_indices(&self, x: &[Expr]) -> Result<Vec<usize>, BuildError> {
        self.indices(x, "variable_indices", true)
    }

    /// Evaluates expressions of the variables and parameters at a primal point `x`
    /// (parameters at their current values), e.g. to read a solution.
    pub fn evaluate(&self, exprs: &[Expr], x: &[f64]) -> Result<Vec<f64>, BuildError> {
        if x.len() != self.variables.len() {
            return Err(BuildError::Size {
                what: "evaluate: x".into(),
                expected: self.variables.len(),
                got: x.len(),
            });
        }
        let p = self.parameter_vector()?;
        let f = self.function(exprs, "evaluate")?;
        Ok(f.call(&[x, &p])?.swap_remove(0))
    }

    fn parameter_vector(&self) -> Result<Vec<f64>, BuildError> {
        self.parameter_values
            .iter()
            .enumerate()
            .map(|(i, v)| {
                v.ok_or_else(|| BuildError::MissingParameterValue {
                    name: self.parameters[i].name().unwrap_or_default(),
                })
            })
            .collect()
    }

    /// Compiles `exprs` as a function of `(x, p)`; a free symbol is reported with `location`.
    fn function(&self, exprs: &[Expr], location: &str) -> Result<symx::Function, BuildError> {
        symx::Function::new(&[&self.variables, &self.parameters], &[exprs]).map_err(|e| match e {
            symx::SymxError::FreeSymbol { name, .. } => BuildError::FreeSymbol {
                location: location.to_string(),
                name,
            },
            e => e.into(),
        })
    }

    /// Differentiates and compiles the problem once: evaluators for f, ∇f, g, the sparse
    /// Jacobian of g and the sparse Lagrangian Hessian, with fixed sparsity.
    pub fn compile(&self) -> Result<Compiled, BuildError> {
        let params = self.parameter_vector()?;
        let f = self.objective();
        let g = self.constraint_expressions();
        // Name the culprit of a free symbol before the bulk compilation.
        self.function(&[f], "the objective")?;
        if let Err(e @ BuildError::FreeSymbol { .. }) = self.function(&g, "constraints") {
            for (i, row) in self.rows.iter().enumerate() {
                self.function(
                    &[row.expr],
                    &format!("constraint '{}'", self.constraint_name(i)),
                )?;
            }
            return Err(e);
        }
        Compiled::new(self, f, &g, params)
    }

    pub(crate) fn parts(&self) -> ProblemParts<'_> {
        ProblemParts {
            variables: &self.variables,
            parameters: &self.parameters,
            lower: &self.lower,
            upper: &self.upper,
            initial: &self.initial,
            rows: &self.rows,
            variable_blocks: &self.variable_blocks,
            parameter_blocks: &self.parameter_blocks,
            constraint_blocks: &self.constraint_blocks,
            cones: &self.cones,
        }
    }
}

/// Complementarity at a point: see [`Problem::complementarity_report`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ComplementarityReport {
    /// max over pairs of |min(a, b)|.
    pub residual: f64,
    /// Names of the pairs with both sides within the tolerance of zero.
    pub biactive: Vec<String>,
    /// Number of pairs.
    pub pairs: usize,
}

/// Borrowed pieces of a problem handed to [`Compiled::new`].
pub(crate) struct ProblemParts<'a> {
    pub variables: &'a [Expr],
    pub parameters: &'a [Expr],
    pub lower: &'a [f64],
    pub upper: &'a [f64],
    pub initial: &'a [f64],
    pub rows: &'a [Row],
    pub variable_blocks: &'a [Block],
    pub parameter_blocks: &'a [Block],
    pub constraint_blocks: &'a [Block],
    pub cones: &'a [Cone],
}

/// Name of entry `i` given named blocks: `name` for a one-entry block, `name[k]` otherwise.
pub(crate) fn row_name(blocks: &[Block], i: usize, fallback: &str) -> String {
    match blocks.iter().find(|b| b.range().contains(&i)) {
        Some(b) if b.len == 1 => b.name.clone(),
        Some(b) => format!("{}[{}]", b.name, i - b.start),
        None => format!("{fallback}[{i}]"),
    }
}
