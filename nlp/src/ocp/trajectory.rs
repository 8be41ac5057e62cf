//! [`Trajectory`]: a solved optimal control problem as time series, ready to plot or save.
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
/// and one per control (piecewise constant, its value on `[t_k, t_{k+1})` stored at `t_k`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Trajectory {
    /// The grid `t_k = k T / N`, `k = 0…N`.
    pub time: Vec<f64>,
    /// State names, in the order of `states`.
    pub state_names: Vec<String>,
    /// `states[i][k]`: state `i` at `time[k]`.
    pub states: Vec<Vec<f64>>,
    /// Control names, in the order of `controls`.
    pub control_names: Vec<String>,
    /// Start of each interval, `t_k`, `k = 0…N−1`.
    pub control_time: Vec<f64>,
    /// `controls[j][k]`: control `j` on interval `k`.
    pub controls: Vec<Vec<f64>>,
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

    /// The controls at time `t` (piecewise constant; clamped to `[0, T]`).
    pub fn controls_at(&self, t: f64) -> Vec<f64> {
        let (k, _) = self.locate(t);
        let k = k.min(self.control_time.len().saturating_sub(1));
        self.controls.iter().map(|u| u[k]).collect()
    }

    /// Interval index k and fraction s ∈ [0, 1] of time t.
    fn locate(&self, t: f64) -> (usize, f64) {
        let n = self.time.len() - 1;
        if n == 0 || self.final_time <= 0.0 {
            return (0, 0.0);
        }
        let r = (t / self.final_time).clamp(0.0, 1.0) * n as f64;
        let k = (r.floor() as usize).min(n - 1);
        (k, r - k as f64)
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
