//! External functions: a [`Function`] whose values come from user code (a closure) rather
//! than from a tape — a simulator, an integrator, another solver — so that it can be called
//! inside expressions like any compiled function ([`Function::apply`] adds one call node).
//!
//! The closure receives the inputs stacked (`input_sizes()` summed) and writes the outputs
//! stacked. It must be deterministic: the same inputs give bit-identical outputs.
//!
//! Derivatives: an external function has none unless one is given with
//! [`Function::with_jacobian`]: a structural pattern (`outputs × inputs`, entries stacked)
//! and a function of the same inputs returning the pattern's nonzeros in column-major
//! order. That Jacobian function may itself be external (with a Jacobian of its own for
//! second derivatives) or a compiled expression. Differentiating a call then works as for
//! any callee (see the `call` module): forward sweeps multiply by the Jacobian, reverse
//! sweeps by its transpose, and Hessians differentiate the Jacobian's call in turn.
//! Differentiating an external function without a Jacobian (or a Jacobian without one of
//! its own, for a Hessian) is an error ([`SymxError::NoDerivative`]) from [`crate::jacobian`],
//! [`crate::gradient`], [`crate::hessian`] and the other derivative builders.
//!
//! A reverse hook ([`Function::with_vjp`]) adds a user-computed vector–Jacobian product
//! (say, an adjoint method), which a single reverse sweep (a gradient) calls instead of
//! the Jacobian.
//!
//! External functions cannot be compiled to native code ([`Function::jit`],
//! [`Function::to_rust`]): both refuse with an error naming the function.
use crate::error::SymxError;
use crate::function::{next_uid, Function};
use crate::interpret::Tape;
use crate::sparsity::{entries, Sparsity};
use std::sync::{Arc, OnceLock};

/// The evaluator of an external function: inputs stacked → outputs stacked.
pub type ExternalEval = dyn Fn(&[f64], &mut [f64]) + Send + Sync;

/// What makes a [`Function`] external: its evaluator and, if given, its Jacobian.
pub(crate) struct External {
    pub eval: Arc<ExternalEval>,
    /// Number of input entries and of output entries (the work vector holds both).
    pub n_in: usize,
    pub n_out: usize,
    /// The structural Jacobian (`outputs × inputs`, entries stacked) and the function of
    /// the same inputs that returns its nonzeros (column-major).
    pub jacobian: Option<(Sparsity, Arc<Function>)>,
    /// The reverse hook ([`Function::with_vjp`]): `x̄ = Jᵀȳ` computed by the user, a
    /// function of the inputs and `ȳ`.
    pub vjp: Option<Arc<Function>>,
    /// Set on a reverse hook's own call: the tape function equal to it (the
    /// vector–Jacobian product built from the Jacobian), which is differentiated in its
    /// place.
    pub derivative_as: Option<Arc<Function>>,
}

impl std::fmt::Debug for External {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.jacobian {
            Some((p, j)) => write!(
                f,
                "External(jacobian {} with {} nonzeros)",
                j.name,
                p.compute_nnz()
            ),
            None => write!(f, "External(no jacobian)"),
        }?;
        if let Some(v) = &self.vjp {
            write!(f, " with reverse hook {}", v.name)?;
        }
        Ok(())
    }
}

impl External {
    /// Runs the user's evaluator on a work vector `[inputs | outputs]`.
    ///
    /// # Safety
    /// `w` must point to at least `n_in + n_out` numbers.
    #[inline(always)]
    pub unsafe fn run(&self, w: *mut f64) {
        let x = std::slice::from_raw_parts(w, self.n_in);
        let y = std::slice::from_raw_parts_mut(w.add(self.n_in), self.n_out);
        (self.eval)(x, y)
    }
}

fn distinct(what: &'static str, names: &[(&str, usize)]) -> Result<(), SymxError> {
    for (k, (n, _)) in names.iter().enumerate() {
        if names[..k].iter().any(|(m, _)| m == n) {
            return Err(SymxError::DuplicateName {
                what,
                name: n.to_string(),
            });
        }
    }
    Ok(())
}

impl Function {
    /// An external function named `name` with the given named inputs and outputs (name,
    /// length), evaluated by `eval(inputs stacked, outputs stacked)`. Its work vector is
    /// `[inputs | outputs]`; evaluation allocates nothing beyond what `eval` does.
    ///
    /// Every output is taken to depend on every input until a Jacobian pattern is given
    /// ([`Function::with_jacobian`]). `Err` if two inputs or two outputs share a name.
    ///
    /// ```
    /// use symx::{Function, Matrix};
    /// // y = (x0 * x1, sin x0), computed by plain Rust
    /// let f = Function::external("prod_sin", &[("x", 2)], &[("y", 2)], |x, y| {
    ///     y[0] = x[0] * x[1];
    ///     y[1] = x[0].sin();
    /// })
    /// .unwrap();
    /// let z = Matrix::sym_vec("z", 2);
    /// let y = f.apply(&[&z]).unwrap();
    /// let g = Function::new(&[&z], &[&[y[0][0] + y[0][1]]]).unwrap();
    /// assert_eq!(g.call(&[&[2.0, 3.0]]).unwrap()[0][0], 6.0 + 2f64.sin());
    /// ```
    pub fn external(
        name: &str,
        inputs: &[(&str, usize)],
        outputs: &[(&str, usize)],
        eval: impl Fn(&[f64], &mut [f64]) + Send + Sync + 'static,
    ) -> Result<Function, SymxError> {
        distinct("input", inputs)?;
        distinct("output", outputs)?;
        let input_sizes: Vec<usize> = inputs.iter().map(|p| p.1).collect();
        let output_sizes: Vec<usize> = outputs.iter().map(|p| p.1).collect();
        let offsets = |sizes: &[usize], start: usize| -> Vec<usize> {
            sizes
                .iter()
                .scan(start, |at, &n| {
                    let o = *at;
                    *at += n;
                    Some(o)
                })
                .collect()
        };
        let (n_in, n_out): (usize, usize) = (input_sizes.iter().sum(), output_sizes.iter().sum());
        let dense: Vec<Vec<u32>> = vec![(0..n_in as u32).collect(); n_out];
        Ok(Function {
            name: name.to_string(),
            input_names: inputs.iter().map(|p| p.0.to_string()).collect(),
            output_names: outputs.iter().map(|p| p.0.to_string()).collect(),
            uid: next_uid(),
            input_offsets: offsets(&input_sizes, 0),
            output_offsets: offsets(&output_sizes, n_in),
            input_used: vec![true; input_sizes.len()],
            input_sizes,
            output_sizes,
            tape: Tape::default(),
            template: Vec::new(),
            template_start: n_in + n_out,
            work_size: n_in + n_out,
            tables: Vec::new(),
            calls: Vec::new(),
            call_scratch: n_in + n_out,
            dependencies: OnceLock::from(Arc::new(dense)),
            jacobians: Default::default(),
            native: None,
            external: Some(Arc::new(External {
                eval: Arc::new(eval),
                n_in,
                n_out,
                jacobian: None,
                vjp: None,
                derivative_as: None,
            })),
        })
    }

    /// This external function with a Jacobian: `pattern` is its structural Jacobian
    /// (`Σ output_sizes × Σ input_sizes`, inputs and outputs stacked) and `jacobian` a
    /// function of the same inputs with one output holding the pattern's nonzeros in
    /// column-major (storage) order. The result is a new function (a new identity);
    /// its dependency sparsity is `pattern`.
    ///
    /// `Err` if `self` is not external, or if the sizes do not match.
    ///
    /// ```
    /// use symx::{gradient, sparsity::pattern_from_entries, Function, Matrix};
    /// let f = Function::external("prod", &[("x", 2)], &[("y", 1)], |x, y| y[0] = x[0] * x[1]).unwrap();
    /// // ∂y/∂x = [x1, x0]: nonzeros (0,0), (0,1) in column-major order
    /// let jac = Function::external("jac_prod", &[("x", 2)], &[("jac", 2)], |x, j| {
    ///     j[0] = x[1];
    ///     j[1] = x[0];
    /// })
    /// .unwrap();
    /// let f = f.with_jacobian(&pattern_from_entries(1, 2, [(0, 0), (0, 1)]), &jac).unwrap();
    /// let z = Matrix::sym_vec("z", 2);
    /// let y = f.apply(&[&z]).unwrap()[0][0];
    /// let g = Function::new(&[&z], &[&gradient(y, &z).unwrap()]).unwrap();
    /// assert_eq!(g.call(&[&[2.0, 3.0]]).unwrap()[0], vec![3.0, 2.0]);
    /// ```
    pub fn with_jacobian(
        &self,
        pattern: &Sparsity,
        jacobian: &Function,
    ) -> Result<Function, SymxError> {
        let Some(ext) = &self.external else {
            return Err(SymxError::NotExternal {
                name: self.name.clone(),
            });
        };
        let (n_in, n_out): (usize, usize) = (
            self.input_sizes.iter().sum(),
            self.output_sizes.iter().sum(),
        );
        if (pattern.nrows(), pattern.ncols()) != (n_out, n_in) {
            return Err(SymxError::Dimension {
                op: "with_jacobian: pattern against (outputs, inputs)",
                left: (pattern.nrows(), pattern.ncols()),
                right: (n_out, n_in),
            });
        }
        if jacobian.input_sizes != self.input_sizes {
            return Err(SymxError::ArgumentCount {
                what: "Jacobian function inputs (same as the function's)",
                expected: self.input_sizes.len(),
                got: jacobian.input_sizes.len(),
            }
            .or_lengths(&self.input_sizes, &jacobian.input_sizes));
        }
        let nnz = pattern.compute_nnz();
        if jacobian.output_sizes != [nnz] {
            return Err(SymxError::Length {
                what: "Jacobian function output (one, the pattern's nonzeros)",
                index: 0,
                expected: nnz,
                got: jacobian.output_sizes.iter().sum(),
            });
        }
        let mut rows: Vec<Vec<u32>> = vec![Vec::new(); n_out];
        for (i, j) in entries(pattern) {
            rows[i].push(j as u32);
        }
        rows.iter_mut().for_each(|r| r.sort_unstable());
        Ok(Function {
            uid: next_uid(),
            dependencies: OnceLock::from(Arc::new(rows)),
            jacobians: Default::default(),
            external: Some(Arc::new(External {
                eval: ext.eval.clone(),
                n_in,
                n_out,
                jacobian: Some((pattern.clone(), Arc::new(jacobian.clone()))),
                vjp: None,
                derivative_as: None,
            })),
            ..self.clone()
        })
    }

    /// This external function (which has a Jacobian, [`Function::with_jacobian`]) with a
    /// reverse hook: `vjp` takes the function's inputs plus one input `ȳ` (one entry per
    /// output entry, stacked) and returns one output `x̄ = Jᵀȳ` (one entry per input
    /// entry, stacked) — e.g. computed by an adjoint method at the cost of one backward
    /// pass, where the Jacobian costs one forward pass per input entry.
    ///
    /// A single reverse sweep — [`crate::gradient`], [`crate::reverse`], and the
    /// vector–Jacobian products with symbolic seeds inside Lagrangian gradients — then
    /// calls `vjp` once per call node instead of the Jacobian. The rows of a Jacobian
    /// whose adjoints at the node are constants (a Jacobian of the node's outputs) still
    /// call the Jacobian function (once, shared by the rows), and forward sweeps
    /// multiply by it; other adjoints always went through a vector–Jacobian product,
    /// now the hook. Derivatives of the hook's own call are those of the
    /// vector–Jacobian product built from the Jacobian, unless `vjp` has a Jacobian of
    /// its own: a second derivative needs no more than it did without the hook.
    /// The result is a new function (a new identity); a later [`Function::with_jacobian`]
    /// removes the hook.
    ///
    /// `Err` if `self` is not external or has no Jacobian, or if the sizes do not match.
    ///
    /// ```
    /// use symx::{gradient, sparsity::pattern_from_entries, Function, Matrix};
    /// let f = Function::external("prod", &[("x", 2)], &[("y", 1)], |x, y| y[0] = x[0] * x[1]).unwrap();
    /// let jac = Function::external("jac_prod", &[("x", 2)], &[("jac", 2)], |x, j| {
    ///     j[0] = x[1];
    ///     j[1] = x[0];
    /// })
    /// .unwrap();
    /// // x̄ = ȳ·(x1, x0), computed directly
    /// let vjp = Function::external("adj_prod", &[("x", 2), ("adj", 1)], &[("adj_in", 2)], |a, xb| {
    ///     xb[0] = a[2] * a[1];
    ///     xb[1] = a[2] * a[0];
    /// })
    /// .unwrap();
    /// let f = f
    ///     .with_jacobian(&pattern_from_entries(1, 2, [(0, 0), (0, 1)]), &jac)
    ///     .unwrap()
    ///     .with_vjp(&vjp)
    ///     .unwrap();
    /// let z = Matrix::sym_vec("z", 2);
    /// let y = f.apply(&[&z]).unwrap()[0][0];
    /// let g = Function::new(&[&z], &[&gradient(3.0 * y, &z).unwrap()]).unwrap();
    /// assert_eq!(g.call(&[&[2.0, 5.0]]).unwrap()[0], vec![15.0, 6.0]);
    /// ```
    pub fn with_vjp(&self, vjp: &Function) -> Result<Function, SymxError> {
        let Some(ext) = &self.external else {
            return Err(SymxError::NotExternal {
                name: self.name.clone(),
            });
        };
        if ext.jacobian.is_none() {
            return Err(SymxError::NoDerivative {
                name: self.name.clone(),
            });
        }
        let mut expected = self.input_sizes.clone();
        expected.push(ext.n_out);
        if vjp.input_sizes != expected {
            return Err(SymxError::ArgumentCount {
                what: "vector-Jacobian product inputs (the function's, then one per output entry)",
                expected: expected.len(),
                got: vjp.input_sizes.len(),
            }
            .or_lengths(&expected, &vjp.input_sizes));
        }
        if vjp.output_sizes != [ext.n_in] {
            return Err(SymxError::Length {
                what: "vector-Jacobian product output (one, an entry per input entry)",
                index: 0,
                expected: ext.n_in,
                got: vjp.output_sizes.iter().sum(),
            });
        }
        Ok(Function {
            uid: next_uid(),
            jacobians: Default::default(),
            external: Some(Arc::new(External {
                eval: ext.eval.clone(),
                n_in: ext.n_in,
                n_out: ext.n_out,
                jacobian: ext.jacobian.clone(),
                vjp: Some(Arc::new(vjp.clone())),
                derivative_as: None,
            })),
            ..self.clone()
        })
    }

    /// The function a reverse sweep calls for this external function's reverse hook:
    /// `hook` itself, or (for an external hook without a Jacobian) `hook` differentiated
    /// as `equal`, the vector–Jacobian product built from the Jacobian.
    pub(crate) fn reverse_hook(hook: &Function, equal: &Arc<Function>) -> Function {
        match &hook.external {
            Some(ext) if ext.jacobian.is_none() => Function {
                uid: next_uid(),
                jacobians: Default::default(),
                external: Some(Arc::new(External {
                    eval: ext.eval.clone(),
                    n_in: ext.n_in,
                    n_out: ext.n_out,
                    jacobian: None,
                    vjp: None,
                    derivative_as: Some(equal.clone()),
                })),
                ..hook.clone()
            },
            _ => hook.clone(),
        }
    }

    /// Whether this function is external ([`Function::external`]).
    pub fn is_external(&self) -> bool {
        self.external.is_some()
    }

    /// `Err` naming the first external function this function is or calls, for the
    /// compilers to native code (`what`), which cannot call user closures.
    pub(crate) fn refuse_external(&self, what: &'static str) -> Result<(), SymxError> {
        if self.external.is_some() {
            return Err(SymxError::Jit {
                message: format!(
                    "{what}: function '{}' is external (user code) and cannot be compiled; evaluate it by its tape",
                    self.name
                ),
            });
        }
        self.calls
            .iter()
            .try_for_each(|c| c.function.refuse_external(what))
    }
}

impl SymxError {
    /// For a size mismatch of input lists: the first input whose length differs, if the
    /// counts agree.
    fn or_lengths(self, expected: &[usize], got: &[usize]) -> SymxError {
        if expected.len() != got.len() {
            return self;
        }
        match expected.iter().zip(got).position(|(a, b)| a != b) {
            Some(index) => SymxError::Length {
                what: "Jacobian function input",
                index,
                expected: expected[index],
                got: got[index],
            },
            None => self,
        }
    }
}
