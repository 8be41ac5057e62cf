//! [`Phase`]: where one transcribed phase of an optimal control problem lives in its
//! [`Problem`] — grid, state and control variables, final time — and how a solution reads
//! back from them as a [`Trajectory`].
use super::{CollocationStates, ControlInterpolation, Grid, OcpError, Trajectory};
use crate::problem::Problem;
use crate::solution::Solution;
use symx::{Expr, Matrix};

/// One phase's layout in a transcribed problem.
pub(crate) struct Phase {
    pub(crate) intervals: usize,
    pub(crate) grid: Grid,
    pub(crate) control_interpolation: ControlInterpolation,
    /// `X`, `nx × (N+1)`.
    pub(crate) states: Matrix,
    /// `U`, `nu × N` or `nu × (N+1)`.
    pub(crate) controls: Matrix,
    /// `Xc` (collocation) or `Xm` (separated Hermite–Simpson).
    pub(crate) collocation_states: Option<Matrix>,
    /// The duration: the variable `T` or a constant.
    pub(crate) final_time: Expr,
    /// Fractions of an interval of the collocation states (`0` first).
    pub(crate) tau: Vec<f64>,
    pub(crate) state_names: Vec<String>,
    pub(crate) control_names: Vec<String>,
    pub(crate) initial_state_parameter: Option<String>,
    /// The constraint groups written once per stage, in raw rows (before simple-bound
    /// detection), for [`super::Transcription::shift_plan`].
    pub(crate) staged_rows: Vec<StagedRows>,
}

impl Phase {
    /// The phase's duration in the solution `sol` of `pb`.
    pub(crate) fn duration(&self, pb: &Problem, sol: &Solution) -> Result<f64, OcpError> {
        Ok(match self.final_time.value() {
            Some(t) => t,
            None => sol.x[pb.variable_indices(&[self.final_time])?[0]],
        })
    }

    /// The solution `sol` of `pb` as a trajectory whose times start at `start`.
    pub(crate) fn trajectory(
        &self,
        pb: &Problem,
        sol: &Solution,
        start: f64,
    ) -> Result<Trajectory, OcpError> {
        let n_var = pb.n_variables();
        if sol.x.len() != n_var {
            return Err(OcpError::Size {
                what: "solution x".into(),
                expected: n_var,
                got: sol.x.len(),
            });
        }
        let values = |m: &Matrix| -> Result<Vec<Vec<f64>>, OcpError> {
            let idx = pb.variable_indices(m)?;
            let rows = m.nrows();
            Ok((0..rows)
                .map(|i| (0..m.ncols()).map(|k| sol.x[idx[k * rows + i]]).collect())
                .collect())
        };
        let t_f = self.duration(pb, sol)?;
        let (n, grid) = (self.intervals, &self.grid);
        let collocation = match &self.collocation_states {
            Some(xc) => {
                let d = self.tau.len() - 1;
                Some(CollocationStates {
                    time: (0..n * d)
                        .map(|i| start + grid.time_in(i / d, self.tau[i % d + 1], t_f))
                        .collect(),
                    states: values(xc)?,
                })
            }
            None => None,
        };
        let controls = if self.controls.nrows() > 0 {
            values(&self.controls)?
        } else {
            Vec::new()
        };
        // t_N exactly start + T.
        let time: Vec<f64> = (0..=n).map(|k| start + grid.time(k, t_f)).collect();
        Ok(Trajectory {
            state_names: self.state_names.clone(),
            states: values(&self.states)?,
            control_names: self.control_names.clone(),
            control_time: time[..self.controls.ncols()].to_vec(),
            control_interpolation: self.control_interpolation,
            time,
            controls,
            final_time: start + t_f,
            objective: sol.objective,
            status: sol.status,
            collocation,
        })
    }
}

/// A constraint group written once per stage: `stages` consecutive runs of `per_stage`
/// raw rows (rows as added, before simple-bound detection) from `start`.
#[derive(Clone, Debug)]
pub(crate) struct StagedRows {
    pub(crate) name: String,
    pub(crate) start: usize,
    pub(crate) stages: usize,
    pub(crate) per_stage: usize,
}
