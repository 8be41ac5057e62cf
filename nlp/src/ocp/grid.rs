//! The time grid of a transcription and how the controls vary between its nodes.
use super::OcpError;

/// The nodes `0 = s₀ < s₁ < … < s_N = 1` of a transcription as fractions of the final time
/// `T` (node `k` is at `t_k = s_k T`, interval `k` has length `h_k = (s_{k+1} − s_k) T`), so
/// that one grid serves a fixed and a free final time alike.
///
/// ```
/// use nlp::ocp::Grid;
/// assert_eq!(Grid::uniform(4).unwrap().fractions(), [0.0, 0.25, 0.5, 0.75, 1.0]);
/// // Finer where the action is: a user-given grid.
/// let g = Grid::new(&[0.0, 0.1, 0.2, 0.5, 1.0]).unwrap();
/// assert_eq!(g.intervals(), 4);
/// assert!(Grid::new(&[0.0, 0.6, 0.5, 1.0]).is_err()); // not increasing: named in the error
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Grid {
    fractions: Vec<f64>,
    uniform: bool,
}

impl Grid {
    /// `n ≥ 1` intervals of equal length `T/n`.
    pub fn uniform(n: usize) -> Result<Grid, OcpError> {
        if n == 0 {
            return Err(OcpError::Invalid {
                what: "grid".into(),
                why: "needs at least one interval".into(),
            });
        }
        let mut fractions: Vec<f64> = (0..=n).map(|k| k as f64 / n as f64).collect();
        fractions[n] = 1.0;
        Ok(Grid {
            fractions,
            uniform: true,
        })
    }

    /// A user-given grid: fractions of `T` starting at exactly 0, ending at exactly 1 and
    /// strictly increasing (an error names the first entry that is not).
    pub fn new(fractions: &[f64]) -> Result<Grid, OcpError> {
        let bad = |why: String| {
            Err(OcpError::Invalid {
                what: "grid".into(),
                why,
            })
        };
        if fractions.len() < 2 {
            return bad(format!(
                "needs at least two nodes (0 and 1), got {}",
                fractions.len()
            ));
        }
        if fractions[0] != 0.0 || fractions[fractions.len() - 1] != 1.0 {
            return bad(format!(
                "fractions of T must run from 0 to 1, got {} … {}",
                fractions[0],
                fractions[fractions.len() - 1]
            ));
        }
        if let Some(k) = fractions
            .windows(2)
            .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
        {
            return bad(format!(
                "not strictly increasing at node {}: {} after {}",
                k + 1,
                fractions[k + 1],
                fractions[k]
            ));
        }
        Ok(Grid {
            fractions: fractions.to_vec(),
            uniform: false,
        })
    }

    /// Number of intervals N.
    pub fn intervals(&self) -> usize {
        self.fractions.len() - 1
    }

    /// The nodes `s₀ = 0 … s_N = 1`.
    pub fn fractions(&self) -> &[f64] {
        &self.fractions
    }

    /// Whether the grid was built by [`Grid::uniform`] (every interval `T/N`).
    pub fn is_uniform(&self) -> bool {
        self.uniform
    }

    /// The time of node `k` for the final time `t_f` (the last node exactly `t_f`).
    pub(crate) fn time(&self, k: usize, t_f: f64) -> f64 {
        if k == self.intervals() {
            t_f
        } else {
            self.time_in(k, 0.0, t_f)
        }
    }

    /// The time at the fraction `tau ∈ [0, 1]` of interval `k`.
    pub(crate) fn time_in(&self, k: usize, tau: f64, t_f: f64) -> f64 {
        if self.uniform {
            return (k as f64 + tau) * t_f / self.intervals() as f64;
        }
        let (a, b) = (self.fractions[k], self.fractions[k + 1]);
        (a + tau * (b - a)) * t_f
    }
}

/// How the controls vary on the grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ControlInterpolation {
    /// One value per interval, held over it (`U` is `nu × N`).
    #[default]
    PiecewiseConstant,
    /// One value per node, linear in time between nodes (`U` is `nu × (N+1)`), as the
    /// trapezoidal and Hermite–Simpson methods of Betts and of COPS write them.
    PiecewiseLinear,
}
