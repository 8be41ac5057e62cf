//! Moving a solution of a transcription one stage forward in time, the warm start of a
//! receding-horizon (MPC) step: [`Transcription::shift_plan`] finds once where every
//! stage's variables and constraint rows live; [`Shift::apply`] then copies them in place.
use super::{OcpError, Transcription};
use crate::solution::Solution;
use symx::Matrix;

/// Where each stage of a [`Transcription`] lives in `x` and in `g`, to move a
/// [`Solution`] one stage forward: stage `k` receives stage `k + 1`'s states, controls,
/// collocation states, their bound multipliers `z_L`, `z_U`, and the multipliers `λ` and
/// values `g` of the per-stage constraint rows (`continuity`, `collocation`, the path
/// constraints). The **last stage keeps its values**: it is duplicated (the new last
/// stage equals the new second-to-last), the usual choice for a time-invariant problem
/// near a steady state. Everything else — a free final time, parameters, the `initial
/// state`, `final state` and boundary rows, rows or variables added through
/// [`Transcription::problem_mut`] — is left as it is.
///
/// A path-constraint row that is a simple bound (a row on one variable, turned into that
/// variable's bound when compiling) has no λ: its multiplier is the variable's `z_L`/`z_U`,
/// which moves with the variable.
///
/// ```
/// use nlp::ocp::{ButcherTableau, Method, Ocp};
/// use symx::Matrix;
/// let mut ocp = Ocp::new(&["x"], &["u"]);
/// ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![u[0] - x[0]]));
/// ocp.set_initial_state_parameter("x0", &[1.0]).unwrap();
/// ocp.set_horizon(nlp::ocp::Horizon::Fixed(1.0)).unwrap();
/// let tr = ocp.transcribe(&Method::multiple_shooting(ButcherTableau::rk4(), 1), 3).unwrap();
/// let shift = tr.shift_plan().unwrap();
/// // x = (X0, X1, X2, X3, U0, U1, U2): each stage takes the next one's value.
/// // g = (initial state, continuity of intervals 0, 1, 2).
/// let mut sol = nlp::Solution {
///     status: nlp::Status::SolveSucceeded,
///     x: vec![0.0, 1.0, 2.0, 3.0, 10.0, 11.0, 12.0],
///     lambda: vec![5.0, 20.0, 21.0, 22.0],
///     z_l: vec![0.0; 7], z_u: vec![0.0; 7], g: vec![0.0; 4],
///     objective: 0.0, constr_viol: 0.0, dual_inf: 0.0, compl: 0.0,
///     message: String::new(), stats: Default::default(), parameters: vec![1.0],
/// };
/// shift.apply(&mut sol).unwrap();
/// assert_eq!(sol.lambda, [5.0, 21.0, 22.0, 22.0]); // the initial state's row stays
/// assert_eq!(sol.x, [1.0, 2.0, 3.0, 3.0, 11.0, 12.0, 12.0]);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Shift {
    n: usize,
    m: usize,
    /// `(destination, source)` in `x`, in an order where no source is overwritten before
    /// it is read (stage by stage, forward).
    variable_moves: Vec<(usize, usize)>,
    /// `(destination, source)` in `g` (compiled rows), ordered the same way.
    row_moves: Vec<(usize, usize)>,
}

impl Shift {
    /// Moves `sol` one stage forward in place (see [`Shift`]); allocates nothing. An error
    /// names a vector whose length is not the transcription's.
    pub fn apply(&self, sol: &mut Solution) -> Result<(), OcpError> {
        for (what, len, expected) in [
            ("solution x", sol.x.len(), self.n),
            ("solution z_l", sol.z_l.len(), self.n),
            ("solution z_u", sol.z_u.len(), self.n),
            ("solution lambda", sol.lambda.len(), self.m),
            ("solution g", sol.g.len(), self.m),
        ] {
            if len != expected {
                return Err(OcpError::Size {
                    what: what.into(),
                    expected,
                    got: len,
                });
            }
        }
        for &(to, from) in &self.variable_moves {
            sol.x[to] = sol.x[from];
            sol.z_l[to] = sol.z_l[from];
            sol.z_u[to] = sol.z_u[from];
        }
        for &(to, from) in &self.row_moves {
            sol.lambda[to] = sol.lambda[from];
            sol.g[to] = sol.g[from];
        }
        Ok(())
    }

    /// A shifted copy of `sol` (see [`Shift::apply`]).
    pub fn shifted(&self, sol: &Solution) -> Result<Solution, OcpError> {
        let mut out = sol.clone();
        self.apply(&mut out)?;
        Ok(out)
    }

    /// The `(destination, source)` pairs of entries of `x` (also of `z_L`, `z_U`).
    pub fn variable_moves(&self) -> &[(usize, usize)] {
        &self.variable_moves
    }

    /// The `(destination, source)` pairs of rows of `g` (also of `λ`).
    pub fn row_moves(&self) -> &[(usize, usize)] {
        &self.row_moves
    }
}

impl Transcription {
    /// The plan of [`Shift`] for this transcription (computed once; apply it every MPC
    /// step). Call it after any [`Transcription::problem_mut`] additions. An error names a
    /// per-stage constraint group whose rows are simple bounds at some stages only, or a
    /// grid that is not uniform.
    pub fn shift_plan(&self) -> Result<Shift, OcpError> {
        if !self.grid().is_uniform() {
            // One stage is one sampling period only when every interval has the same length.
            return Err(OcpError::Invalid {
                what: "shift".into(),
                why: "needs a uniform grid (Grid::uniform): one stage must be one sampling period"
                    .into(),
            });
        }
        let pb = self.problem();
        let n = self.intervals();
        let mut variable_moves = Vec::new();
        let mut columns = |m: &Matrix, stages: usize, per_stage: usize| -> Result<(), OcpError> {
            let idx = pb.variable_indices(m)?;
            let run = m.nrows() * per_stage; // entries of one stage, column-major
            for k in 0..stages.saturating_sub(1) {
                for r in 0..run {
                    variable_moves.push((idx[k * run + r], idx[(k + 1) * run + r]));
                }
            }
            Ok(())
        };
        columns(self.states(), n + 1, 1)?;
        if self.controls().nrows() > 0 {
            columns(self.controls(), self.controls().ncols(), 1)?;
        }
        if let Some(xc) = self.collocation_states() {
            columns(xc, n, xc.ncols() / n)?;
        }
        // Compiled row of each raw row (rows turned into bounds have none).
        let raw = self
            .staged_rows()
            .iter()
            .map(|g| g.start + g.stages * g.per_stage)
            .max()
            .unwrap_or(0);
        let mut compiled = Vec::with_capacity(raw);
        let mut next = 0;
        for i in 0..raw {
            compiled.push(pb.simple_bound_of(i).is_none().then(|| {
                next += 1;
                next - 1
            }));
        }
        let mut row_moves = Vec::new();
        for g in self.staged_rows() {
            for k in 0..g.stages - 1 {
                for r in 0..g.per_stage {
                    let to = compiled[g.start + k * g.per_stage + r];
                    let from = compiled[g.start + (k + 1) * g.per_stage + r];
                    match (to, from) {
                        (Some(to), Some(from)) => row_moves.push((to, from)),
                        (None, None) => {}
                        _ => {
                            return Err(OcpError::Invalid {
                                what: format!("constraint '{}' row {r}", g.name),
                                why: format!(
                                "a simple bound at stage {} but a row at stage {}: cannot shift",
                                if to.is_none() { k } else { k + 1 },
                                if to.is_none() { k + 1 } else { k },
                            ),
                            })
                        }
                    }
                }
            }
        }
        Ok(Shift {
            n: pb.n_variables(),
            m: pb.n_constraints(),
            variable_moves,
            row_moves,
        })
    }

    /// `sol` moved one stage forward (see [`Shift`]); for repeated use prefer
    /// [`Transcription::shift_plan`] once and [`Shift::apply`].
    pub fn shift(&self, sol: &Solution) -> Result<Solution, OcpError> {
        self.shift_plan()?.shifted(sol)
    }
}
