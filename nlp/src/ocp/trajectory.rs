//! [`Trajectory`]: a solved optimal control problem as time series, ready to plot or save.
use super::ControlInterpolation;
use crate::solution::Status;
use std::fmt::Write;

/// The states at the collocation points (direct collocation only).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CollocationStates {
    /// Times of the collocation points, interval by interval.
    pub time: Vec<f64>,
    /// `states[i][j]`: state `i` at `time[j]`.
    pub states: Vec<Vec<f64>>,
}

/// A solution as trajectories: one series per state on the time grid `t₀ = 0 … t_N = T`
/// and one per control (piecewise constant, its value on `[t_k, t_{k+1})` stored at `t_k`;
/// or piecewise linear, its values at the nodes).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Trajectory {
    /// The grid nodes `t_k = s_k T`, `k = 0…N` (`t_k = k T / N` on a uniform grid).
    pub time: Vec<f64>,
    /// State names, in the order of `states`.
    pub state_names: Vec<String>,
    /// `states[i][k]`: state `i` at `time[k]`.
    pub states: Vec<Vec<f64>>,
    /// Control names, in the order of `controls`.
    pub control_names: Vec<String>,
    /// Start of each interval, `t_k`, `k = 0…N−1`; every node `k = 0…N` for
    /// piecewise-linear controls.
    pub control_time: Vec<f64>,
    /// `controls[j][k]`: control `j` on interval `k` (at node `k` for piecewise-linear
    /// controls).
    pub controls: Vec<Vec<f64>>,
    /// How the controls vary between `control_time`s (files without it: piecewise constant).
    #[serde(default)]
    pub control_interpolation: ControlInterpolation,
    /// The final time T.
    pub final_time: f64,
    /// The optimal objective.
    pub objective: f64,
    /// The solver's status.
    pub status: Status,
    /// States at the collocation points, for direct collocation.
    pub collocation: Option<CollocationStates>,
}

impl Trajectory {
    /// The series of the state named `name`.
    pub fn state(&self, name: &str) -> Option<&[f64]> {
        let i = self.state_names.iter().position(|s| s == name)?;
        Some(&self.states[i])
    }

    /// The series of the control named `name`.
    pub fn control(&self, name: &str) -> Option<&[f64]> {
        let j = self.control_names.iter().position(|s| s == name)?;
        Some(&self.controls[j])
    }

    /// The states at the grid point `k` (one value per state).
    pub fn state_at_grid(&self, k: usize) -> Vec<f64> {
        self.states.iter().map(|s| s[k]).collect()
    }

    /// The states at time `t`, interpolated linearly between grid points (clamped to
    /// `[0, T]`).
    pub fn states_at(&self, t: f64) -> Vec<f64> {
        let (k, s) = self.locate(t);
        self.states
            .iter()
            .map(|x| match x.get(k + 1) {
                Some(&next) => x[k] + s * (next - x[k]),
                None => x[k],
            })
            .collect()
    }

    /// The controls at time `t` (piecewise constant or linear, as solved; clamped to
    /// `[0, T]`).
    pub fn controls_at(&self, t: f64) -> Vec<f64> {
        let (k, s) = self.locate(t);
        let k = k.min(self.control_time.len().saturating_sub(1));
        let linear = self.control_interpolation == ControlInterpolation::PiecewiseLinear;
        self.controls
            .iter()
            .map(|u| match (linear, u.get(k + 1)) {
                (true, Some(&next)) => u[k] + s * (next - u[k]),
                _ => u[k],
            })
            .collect()
    }

    /// Interval index k and fraction s ∈ [0, 1] of time t on the grid `time`.
    fn locate(&self, t: f64) -> (usize, f64) {
        let n = self.time.len() - 1;
        if n == 0 || self.final_time <= 0.0 {
            return (0, 0.0);
        }
        let t = t.clamp(0.0, self.final_time);
        // The last node at or before t, at most N − 1.
        let k = self.time[1..n].partition_point(|&tk| tk <= t);
        let (a, b) = (self.time[k], self.time[k + 1]);
        (k, ((t - a) / (b - a)).clamp(0.0, 1.0))
    }

    /// The grid as CSV: a header `t,<states>,<controls>` and one line per grid point (the
    /// controls of the last point repeat the last interval's, for step plots).
    pub fn to_csv(&self) -> String {
        let mut out = String::from("t");
        for name in self.state_names.iter().chain(&self.control_names) {
            out.push(',');
            out.push_str(name);
        }
        out.push('\n');
        for (k, t) in self.time.iter().enumerate() {
            let _ = write!(out, "{t}");
            for x in &self.states {
                let _ = write!(out, ",{}", x[k]);
            }
            for u in &self.controls {
                let _ = write!(out, ",{}", u[k.min(u.len().saturating_sub(1))]);
            }
            out.push('\n');
        }
        out
    }
}
