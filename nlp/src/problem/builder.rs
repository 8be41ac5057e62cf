//! [`Problem`]: variables, parameters, objective and constraints declared over symx
//! expressions, compiled once into a [`Compiled`].
use super::block::{check_bound, row_name, Block};
use super::cone_record::Cone;
use super::error::BuildError;
use super::parts::ProblemParts;
use super::per_entry::PerEntry;
use crate::compiled::{CompileOptions, Compiled};
use crate::constraint::{Constraint, Row};
use crate::parameter::{ParameterIndex, ParameterKey};
use crate::solution::Solution;
use rustc_hash::FxHashMap;
use symx::{Expr, Matrix};

/// Default of [`Problem::set_detect_simple_bounds`]: on (CasADi's default is off); chosen
/// by measurement, see docs/problem.md.
pub const DETECT_SIMPLE_BOUNDS: bool = true;

/// A nonlinear program `min f(x, p)  s.t.  g_l ≤ g(x, p) ≤ g_u,  x_l ≤ x ≤ x_u`, built
/// symbolically and compiled once with [`Problem::compile`].
///
/// ```
/// use nlp::{Problem, Relation, NumericNlp};
/// let mut pb = Problem::new();
/// let x = pb.variable("x", 2)?;
/// pb.minimize((1.0 - x[0]).sq() + 100.0 * (x[1] - x[0].sq()).sq());
/// pb.subject_to((x[0].sq() + x[1].sq()).le(2.0))?;
/// pb.subject_to(x[0].ge(-1.5))?; // on one variable: a bound of x[0] (detected by default)
/// assert_eq!(pb.compile()?.m(), 1);
/// pb.set_detect_simple_bounds(false); // now x[0] ≥ -1.5 is a row of g, as written
/// assert_eq!(pb.compile()?.m(), 2);
/// # Ok::<(), nlp::BuildError>(())
/// ```
#[derive(Clone)]
pub struct Problem {
    pub(super) variables: Vec<Expr>,
    pub(super) variable_blocks: Vec<Block>,
    pub(super) lower: Vec<f64>,
    pub(super) upper: Vec<f64>,
    pub(super) initial: Vec<f64>,
    pub(super) variable_index: FxHashMap<u32, usize>,
    pub(super) parameters: Vec<Expr>,
    pub(super) parameter_index: ParameterIndex,
    pub(super) parameter_values: Vec<Option<f64>>,
    pub(super) objective: Option<Expr>,
    /// Every constraint row as written (simple bounds are detected when compiling).
    pub(super) rows: Vec<Row>,
    pub(super) constraint_blocks: Vec<Block>,
    pub(super) complementarity: Vec<(String, Expr, Expr)>,
    pub(super) cones: Vec<Cone>,
    pub(super) detect_simple_bounds: bool,
}

impl Default for Problem {
    fn default() -> Self {
        Problem {
            variables: Vec::new(),
            variable_blocks: Vec::new(),
            lower: Vec::new(),
            upper: Vec::new(),
            initial: Vec::new(),
            variable_index: FxHashMap::default(),
            parameters: Vec::new(),
            parameter_index: ParameterIndex::default(),
            parameter_values: Vec::new(),
            objective: None,
            rows: Vec::new(),
            constraint_blocks: Vec::new(),
            complementarity: Vec::new(),
            cones: Vec::new(),
            detect_simple_bounds: DETECT_SIMPLE_BOUNDS,
        }
    }
}

impl Problem {
    /// An empty problem.
    pub fn new() -> Problem {
        Problem::default()
    }

    pub(super) fn check_name(&self, name: &str) -> Result<(), BuildError> {
        if self
            .variable_blocks
            .iter()
            .chain(self.parameter_index.blocks())
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
    /// Names identify variables in logs, errors and [`Compiled::variable_values`]: a name
    /// already used by a variable or parameter is an error ([`BuildError::DuplicateName`]).
    pub fn variable(&mut self, name: &str, n: usize) -> Result<Matrix, BuildError> {
        self.variable_matrix(name, n, 1)
    }

    /// Declares a scalar variable (a name already in use is an error).
    pub fn scalar_variable(&mut self, name: &str) -> Result<Expr, BuildError> {
        self.check_name(name)?;
        let x = Expr::sym(name);
        self.push_variables(name, &[x]);
        Ok(x)
    }

    /// Declares a `rows × cols` matrix of variables (a name already in use is an error).
    pub fn variable_matrix(
        &mut self,
        name: &str,
        rows: usize,
        cols: usize,
    ) -> Result<Matrix, BuildError> {
        self.check_name(name)?;
        let x = Matrix::sym(name, rows, cols);
        self.push_variables(name, &x);
        Ok(x)
    }

    pub(super) fn push_variables(&mut self, name: &str, x: &[Expr]) {
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

    /// Declares a vector of `n` parameters: values fixed during a solve, set with
    /// [`Problem::set_value`] and changeable between solves without recompiling
    /// ([`Compiled::set_value`]). A name already in use is an error.
    pub fn parameter(&mut self, name: &str, n: usize) -> Result<Matrix, BuildError> {
        self.check_name(name)?;
        let p = Matrix::sym_vec(name, n);
        self.push_parameters(name, &p);
        Ok(p)
    }

    /// Declares a scalar parameter (a name already in use is an error).
    pub fn scalar_parameter(&mut self, name: &str) -> Result<Expr, BuildError> {
        self.check_name(name)?;
        let p = Expr::sym(name);
        self.push_parameters(name, &[p]);
        Ok(p)
    }

    pub(super) fn push_parameters(&mut self, name: &str, p: &[Expr]) {
        self.parameter_index.push(name, p);
        self.parameters.extend_from_slice(p);
        self.parameter_values.resize(self.parameters.len(), None);
    }

    pub(super) fn variable_positions(
        &self,
        x: &[Expr],
        what: &str,
    ) -> Result<Vec<usize>, BuildError> {
        x.iter()
            .enumerate()
            .map(|(index, e)| {
                self.variable_index
                    .get(&e.id())
                    .copied()
                    .ok_or_else(|| BuildError::NotDeclared {
                        what: format!("{what} ('{e}')"),
                        index,
                        kind: "variable",
                    })
            })
            .collect()
    }

    pub(super) fn variable_name(&self, i: usize) -> String {
        self.variables[i]
            .name()
            .unwrap_or_else(|| format!("x[{i}]"))
    }

    /// Sets `lower ≤ xₖ ≤ upper` for the entries of `x` (±∞ for none), replacing their
    /// bounds. Each of `lower` and `upper` is one number for all entries or a slice with
    /// one number per entry:
    ///
    /// ```
    /// # let mut pb = nlp::Problem::new();
    /// let x = pb.variable("x", 3)?;
    /// pb.set_bounds(&x, 0.0, &[1.0, 2.0, f64::INFINITY])?;
    /// assert!(pb.set_bounds(&x, 0.0, &[1.0, 2.0]).is_err()); // 2 values for 3 entries
    /// # Ok::<(), nlp::BuildError>(())
    /// ```
    pub fn set_bounds<'a>(
        &mut self,
        x: &[Expr],
        lower: impl Into<PerEntry<'a>>,
        upper: impl Into<PerEntry<'a>>,
    ) -> Result<(), BuildError> {
        let (lower, upper) = (lower.into(), upper.into());
        let idx = self.variable_positions(x, "set_bounds")?;
        lower.check_len(idx.len(), "set_bounds: lower bounds")?;
        upper.check_len(idx.len(), "set_bounds: upper bounds")?;
        for (k, &i) in idx.iter().enumerate() {
            let (lo, hi) = (lower.get(k), upper.get(k));
            check_bound(
                || format!("bounds of variable '{}'", self.variable_name(i)),
                lo,
                hi,
            )?;
        }
        for (k, &i) in idx.iter().enumerate() {
            self.lower[i] = lower.get(k);
            self.upper[i] = upper.get(k);
        }
        Ok(())
    }

    /// The initial guess of every variable, in variable order (0 where none was set).
    pub fn initial_point(&self) -> &[f64] {
        &self.initial
    }

    /// Sets the initial guess of the entries of `x` (one finite value each).
    pub fn set_initial(&mut self, x: &[Expr], values: &[f64]) -> Result<(), BuildError> {
        let idx = self.variable_positions(x, "set_initial")?;
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
        }
        for (&i, &v) in idx.iter().zip(values) {
            self.initial[i] = v;
        }
        Ok(())
    }

    /// Sets parameter values (finite numbers): by handle (any entries of the matrices
    /// returned by [`Problem::parameter`]) or by the name of a whole parameter, see
    /// [`ParameterKey`]. [`Compiled::set_value`] is the same call on a compiled problem.
    ///
    /// ```
    /// # let mut pb = nlp::Problem::new();
    /// let p = pb.parameter("p", 2)?;
    /// pb.set_value(&p, &[1.0, 2.0])?; // both entries by handle
    /// pb.set_value(p[1], &[3.0])?; // one entry
    /// pb.set_value("p", &[4.0, 5.0])?; // by name
    /// # Ok::<(), nlp::BuildError>(())
    /// ```
    pub fn set_value<'a>(
        &mut self,
        p: impl Into<ParameterKey<'a>>,
        values: &[f64],
    ) -> Result<(), BuildError> {
        let idx = self.parameter_index.resolve(p.into(), values)?;
        for (i, &v) in idx.into_iter().zip(values) {
            self.parameter_values[i] = Some(v);
        }
        Ok(())
    }

    /// Turns constraint rows on a single variable (`lo ≤ xⱼ ≤ hi`, as written or after
    /// simplification: `x[0] - 0.0` is `x[0]`) into bounds of that variable when the
    /// problem is compiled, intersected with its bounds — CasADi's `detect_simple_bounds`.
    ///
    /// On by default ([`DETECT_SIMPLE_BOUNDS`]; CasADi's default is off): symnlp's solvers
    /// take fewer iterations with bounds than with the same rows (docs/problem.md has the
    /// measurements). Turn it off to solve the problem exactly as written, e.g. to compare
    /// iteration counts with IPOPT under CasADi's defaults. The setting applies at
    /// [`Problem::compile`], whenever it is made.
    ///
    /// Only rows whose expression is a single variable with constant limits become bounds:
    /// a row on one variable that involves a **parameter** (`x.ge(p)`, `x.eq(p)`, written as
    /// `x − p` against constant limits) **stays a row** of g, so that the parameter can
    /// change between solves without recompiling; its multiplier is in `λ`, not in
    /// `z_L`/`z_U`.
    ///
    /// ```
    /// let mut pb = nlp::Problem::new();
    /// let x = pb.scalar_variable("x")?;
    /// let p = pb.scalar_parameter("p")?;
    /// pb.set_value(p, &[1.0])?;
    /// pb.minimize(x.sq());
    /// use nlp::{NumericNlp, Relation};
    /// pb.subject_to(x.ge(p))?; // one variable, but a parameter: a row
    /// pb.subject_to(x.le(5.0))?; // one variable, a constant: a bound
    /// assert_eq!(pb.compile()?.m(), 1);
    /// # Ok::<(), nlp::BuildError>(())
    /// ```
    pub fn set_detect_simple_bounds(&mut self, detect: bool) {
        self.detect_simple_bounds = detect;
    }

    /// Whether simple bounds are detected (see [`Problem::set_detect_simple_bounds`]).
    pub fn detect_simple_bounds(&self) -> bool {
        self.detect_simple_bounds
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

    /// Adds several constraints, each as by [`Problem::subject_to`] (CasADi's
    /// `opti.subject_to([c1, c2, …])`); stops at the first error.
    ///
    /// ```
    /// use nlp::Relation;
    /// let mut pb = nlp::Problem::new();
    /// let x = pb.variable("x", 2)?;
    /// pb.minimize(x[0] + x[1]);
    /// pb.subject_to_all([x[0].eq(x[1]), (x[0] + x[1]).ge(1.0)])?;
    /// assert_eq!(pb.compile()?.constraint_blocks().len(), 2);
    /// # Ok::<(), nlp::BuildError>(())
    /// ```
    pub fn subject_to_all(
        &mut self,
        constraints: impl IntoIterator<Item = Constraint>,
    ) -> Result<(), BuildError> {
        constraints.into_iter().try_for_each(|c| self.subject_to(c))
    }

    /// Adds a named constraint (the name appears in errors, logs and [`Compiled`]'s blocks).
    ///
    /// Every row becomes a row of `g`, except rows on a single variable when
    /// [`Problem::set_detect_simple_bounds`] is on.
    pub fn subject_to_named(&mut self, name: &str, c: Constraint) -> Result<(), BuildError> {
        if let Some((left, right)) = c.mismatch {
            return Err(BuildError::ShapeMismatch {
                name: name.to_string(),
                left,
                right,
            });
        }
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
        if !c.rows.is_empty() {
            self.constraint_blocks.push(Block {
                name: name.to_string(),
                start: self.rows.len(),
                len: c.rows.len(),
            });
            self.rows.extend(c.rows);
        }
        Ok(())
    }

    /// Number of variables.
    pub fn n_variables(&self) -> usize {
        self.variables.len()
    }

    /// Number of rows of g as compiled (without the rows turned into bounds when
    /// [`Problem::set_detect_simple_bounds`] is on).
    pub fn n_constraints(&self) -> usize {
        (0..self.rows.len())
            .filter(|&i| self.simple_bound_of(i).is_none())
            .count()
    }

    /// Number of constraint rows as added, before rows become simple bounds.
    pub(crate) fn n_raw_rows(&self) -> usize {
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

    /// The constraint expressions, in the order of `g` as compiled.
    pub fn constraint_expressions(&self) -> Vec<Expr> {
        (0..self.rows.len())
            .filter(|&i| self.simple_bound_of(i).is_none())
            .map(|i| self.rows[i].expr)
            .collect()
    }

    /// The objective (zero if none was set).
    pub fn objective(&self) -> Expr {
        self.objective.unwrap_or_else(Expr::zero)
    }

    /// Positions of `x` entries in the solution vector.
    pub fn variable_indices(&self, x: &[Expr]) -> Result<Vec<usize>, BuildError> {
        self.variable_positions(x, "variable_indices")
    }

    /// Evaluates expressions of the variables and parameters at a primal point `x`
    /// (parameters at their current values), e.g. to read a solution.
    pub fn evaluate(&self, exprs: &[Expr], x: &[f64]) -> Result<Vec<f64>, BuildError> {
        self.evaluate_named(exprs, x, None, "evaluate")
    }

    /// Evaluates `exprs` at `x` with the parameter values `p` (this problem's when `None`).
    pub(super) fn evaluate_named(
        &self,
        exprs: &[Expr],
        x: &[f64],
        p: Option<&[f64]>,
        what: &str,
    ) -> Result<Vec<f64>, BuildError> {
        if x.len() != self.variables.len() {
            return Err(BuildError::Size {
                what: format!("{what}: x"),
                expected: self.variables.len(),
                got: x.len(),
            });
        }
        let p = match p {
            Some(p) if p.len() != self.parameters.len() => {
                return Err(BuildError::Size {
                    what: format!("{what}: solution parameters"),
                    expected: self.parameters.len(),
                    got: p.len(),
                })
            }
            Some(p) => p.to_vec(),
            None => self.parameter_vector()?,
        };
        let f = self.function(exprs, what)?;
        Ok(f.call(&[x, &p])?.swap_remove(0))
    }

    /// Evaluates `exprs` at a solution, with the parameter values it was solved with.
    pub(super) fn evaluate_solution(
        &self,
        exprs: &[Expr],
        solution: &Solution,
        what: &str,
    ) -> Result<Vec<f64>, BuildError> {
        // A solution without parameter values (hand-built, or from an older file) falls
        // back to this problem's.
        let p = (!solution.parameters.is_empty()).then_some(solution.parameters.as_slice());
        self.evaluate_named(exprs, &solution.x, p, what)
    }

    /// The value of `e`, an expression of this problem's variables and parameters, at a
    /// solution — Opti's `sol.value(e)`. Parameters take the values the solution was
    /// solved with ([`Solution::parameters`]), whatever was set since on this problem or
    /// on a [`Compiled`]; a solution that does not carry them (built by hand, or read from
    /// a file written before that field existed) uses the values set on this problem.
    ///
    /// ```
    /// use nlp::{Ipm, Problem};
    /// let mut pb = Problem::new();
    /// let x = pb.scalar_variable("x")?;
    /// let p = pb.scalar_parameter("p")?;
    /// pb.set_value(p, &[2.0])?;
    /// pb.minimize((x - p).sq());
    /// let mut compiled = pb.compile()?;
    /// compiled.set_value("p", &[4.0])?; // changed on the compiled problem only
    /// let sol = Ipm::default().solve(&mut compiled)?;
    /// assert_eq!(sol.parameters, [4.0]);
    /// assert!((pb.value(x - p, &sol)? - 0.0).abs() < 1e-8); // evaluated with p = 4
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// An expression using a symbol that is neither a variable nor a parameter of this
    /// problem is an error ([`BuildError::FreeSymbol`]), as is a solution whose `x` does
    /// not have one entry per variable.
    pub fn value(&self, e: Expr, solution: &Solution) -> Result<f64, BuildError> {
        Ok(self.evaluate_solution(&[e], solution, "value")?[0])
    }

    /// The values of the entries of `e` at a solution (see [`Problem::value`]); for a
    /// [`Matrix`], its entries in column-major order.
    pub fn values(&self, e: &[Expr], solution: &Solution) -> Result<Vec<f64>, BuildError> {
        self.evaluate_solution(e, solution, "values")
    }

    /// The values of the matrix `m` at a solution as rows: `v[i][j]` is entry (i, j) (see
    /// [`Problem::value`]).
    pub fn value_matrix(
        &self,
        m: &Matrix,
        solution: &Solution,
    ) -> Result<Vec<Vec<f64>>, BuildError> {
        let flat = self.evaluate_solution(m, solution, "value_matrix")?;
        let (rows, cols) = m.shape();
        Ok((0..rows)
            .map(|i| (0..cols).map(|j| flat[i + j * rows]).collect())
            .collect())
    }

    /// The parameter values with NaN for an entry never set: what a [`Compiled`] starts
    /// from (its setters accept finite values only, so NaN marks "unset" there).
    pub(super) fn parameter_vector_or_unset(&self) -> Vec<f64> {
        self.parameter_values
            .iter()
            .map(|v| v.unwrap_or(f64::NAN))
            .collect()
    }

    pub(super) fn parameter_vector(&self) -> Result<Vec<f64>, BuildError> {
        self.parameter_values
            .iter()
            .enumerate()
            .map(|(i, v)| {
                v.ok_or_else(|| BuildError::MissingParameterValue {
                    name: self.parameter_index.name(i).to_string(),
                })
            })
            .collect()
    }

    /// Compiles `exprs` as a function of `(x, p)`; a free symbol is reported with `location`.
    pub(super) fn function(
        &self,
        exprs: &[Expr],
        location: &str,
    ) -> Result<symx::Function, BuildError> {
        symx::Function::new(&[&self.variables, &self.parameters], &[exprs]).map_err(|e| match e {
            symx::SymxError::FreeSymbol { name, .. } => BuildError::FreeSymbol {
                location: location.to_string(),
                name,
            },
            e => e.into(),
        })
    }

    /// Differentiates and compiles the problem once: evaluators for f, ∇f, g, the sparse
    /// Jacobian of g and the sparse Lagrangian Hessian, with fixed sparsity. Simple bounds
    /// are detected here when [`Problem::set_detect_simple_bounds`] is on.
    ///
    /// Parameters need no value yet (as with CasADi's Opti, values are checked at solve):
    /// set them on the [`Compiled`] with [`Compiled::set_value`]. A solve while one is
    /// still unset fails with [`SolveError::MissingParameterValue`](crate::SolveError)
    /// naming it.
    ///
    /// ```
    /// use nlp::{Ipm, Problem, SolveError, Solver};
    /// let mut pb = Problem::new();
    /// let x = pb.scalar_variable("x")?;
    /// let p = pb.scalar_parameter("p")?;
    /// pb.minimize((x - p).sq());
    /// let mut compiled = pb.compile()?; // p has no value yet
    /// let err = Ipm::default().solve(&mut compiled).unwrap_err();
    /// assert_eq!(err, SolveError::MissingParameterValue { name: "p".into() });
    /// compiled.set_value(p, &[3.0])?;
    /// assert!((Ipm::default().solve(&mut compiled)?.x[0] - 3.0).abs() < 1e-8);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn compile(&self) -> Result<Compiled, BuildError> {
        let params = self.parameter_vector_or_unset();
        let f = self.objective();
        self.parts()
            .and_then(|parts| Compiled::new(parts, f, params))
            .map_err(|e| self.culprit(f).err().unwrap_or(e))
    }

    /// Why a compilation failed, when an expression fails on its own: the objective's
    /// error, or a free symbol of the constraints named with its constraint. Run only
    /// after a failure (each check compiles its expressions once more); `Ok` when every
    /// expression compiles on its own.
    fn culprit(&self, f: Expr) -> Result<(), BuildError> {
        self.function(&[f], "the objective")?;
        let written: Vec<Expr> = self.rows.iter().map(|r| r.expr).collect();
        if let Err(e @ BuildError::FreeSymbol { .. }) = self.function(&written, "constraints") {
            for (i, row) in self.rows.iter().enumerate() {
                let name = row_name(&self.constraint_blocks, i, "g");
                self.function(&[row.expr], &format!("constraint '{name}'"))?;
            }
            return Err(e);
        }
        Ok(())
    }

    /// As [`Problem::compile`], with options: e.g. native evaluators, so that every solver
    /// evaluates with machine code without other changes.
    ///
    /// ```
    /// use nlp::{CompileOptions, Problem};
    /// use symx::Evaluator;
    /// let mut p = Problem::new();
    /// let x = p.variable("x", 1).unwrap();
    /// p.minimize((x[0] - 2.0).sq());
    /// let options = CompileOptions { evaluator: Evaluator::Jit };
    /// assert_eq!(p.compile_with(options).unwrap().evaluator(), Evaluator::Jit);
    /// ```
    pub fn compile_with(&self, options: CompileOptions) -> Result<Compiled, BuildError> {
        self.compile()?.with_evaluator(options.evaluator)
    }

    /// The pieces [`Compiled::new`] needs, after simple bound detection.
    pub(crate) fn parts(&self) -> Result<ProblemParts<'_>, BuildError> {
        let layout = self.layout()?;
        Ok(ProblemParts {
            variables: &self.variables,
            parameters: &self.parameters,
            parameter_index: &self.parameter_index,
            initial: &self.initial,
            rows: layout.rows.iter().map(|&i| self.rows[i]).collect(),
            variable_blocks: &self.variable_blocks,
            cones: self
                .cones
                .iter()
                .filter_map(|c| layout.row_of[c.row].map(|row| (row, c)))
                .collect(),
            lower: layout.lower,
            upper: layout.upper,
            constraint_blocks: layout.blocks,
        })
    }
}
