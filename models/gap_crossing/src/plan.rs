//! The solution file and the flat variable layout.
//!
//! A [`SolutionFile`] is exactly the JSON schema of `docs/gap-crossing.md`:
//! `{ scenario, solver: {name, status, iterations, objective, max_constraint_violation,
//! solve_seconds}, stances: [{com: {B, F}, feet: {BR, BL, FR, FL}, forces: {BR, ...}}] }`.
//!
//! # Flat layout
//! Decision variables are stored stance after stance, [`STANCE_LEN`] = 30 numbers per
//! stance k (0-based here; the spec's stance k+1):
//!
//! | offset in stance | variable |
//! |---|---|
//! | 0..3   | r_B (back CoM x, y, z) |
//! | 3..6   | r_F (front CoM) |
//! | 6..9   | r_BR (foot) |
//! | 9..12  | r_BL |
//! | 12..15 | r_FR |
//! | 15..18 | r_FL |
//! | 18..21 | F_BR (contact force, ground on robot) |
//! | 21..24 | F_BL |
//! | 24..27 | F_FR |
//! | 27..30 | F_FL |
//!
//! so the variable vector has 30 · n_step entries; [`com_offset`], [`foot_offset`] and
//! [`force_offset`] give the index of the x component.

use crate::scenario::{Biped, Coms, Feet, Foot, Scenario, Vec3};
use serde::{Deserialize, Deserializer, Serialize};
use std::path::{Path, PathBuf};

/// Number of decision variables per stance.
pub const STANCE_LEN: usize = 30;

/// Index of the x component of biped `j`'s CoM at stance `k` (0-based).
pub fn com_offset(k: usize, j: Biped) -> usize {
    k * STANCE_LEN
        + match j {
            Biped::B => 0,
            Biped::F => 3,
        }
}

/// Index of the x component of foot `i`'s position at stance `k` (0-based).
pub fn foot_offset(k: usize, i: Foot) -> usize {
    k * STANCE_LEN + 6 + 3 * i.index()
}

/// Index of the x component of foot `i`'s contact force at stance `k` (0-based).
pub fn force_offset(k: usize, i: Foot) -> usize {
    k * STANCE_LEN + 18 + 3 * i.index()
}

/// One quasi-static stance: CoMs, feet and contact forces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stance {
    /// CoM of each biped (m).
    pub com: Coms,
    /// Foot positions (m).
    pub feet: Feet,
    /// Contact forces, exerted by the ground on the robot (N).
    pub forces: Feet,
}

/// What the solver reports about the run that produced the plan.
///
/// Optional in a file, and every field in it too (a plan written by another tool may
/// have none, some, or other fields, which are ignored): missing fields take the
/// [`Default`] (`"unknown"`, 0, NaN), and `null` reads as NaN for the numbers (serde
/// writes a NaN as `null`). The checker does not use it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SolverInfo {
    /// Solver name (`ipm`, `sqp`, or `guess` for an initial guess written as a plan).
    pub name: String,
    /// Final status (`solved`, ...).
    pub status: String,
    /// Iterations taken.
    pub iterations: usize,
    /// Objective (1) at the returned point.
    #[serde(deserialize_with = "nullable_f64")]
    pub objective: f64,
    /// Free gait: objective (1) of the problem without (10) (every foot may move at
    /// every transition), a reference for what (10) costs (`solve::objective_without_10`);
    /// absent for the crawl gait or when that solve failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub objective_without_10: Option<f64>,
    /// Largest constraint violation at the returned point, as the solver measures it.
    #[serde(deserialize_with = "nullable_f64")]
    pub max_constraint_violation: f64,
    /// Wall time of the solve (s).
    #[serde(deserialize_with = "nullable_f64")]
    pub solve_seconds: f64,
    /// Why the plan is not `solved`, in numbers (a certificate that no plan exists, how
    /// far the plan ends from its goal, the solver's failure, the checker's findings);
    /// absent for a solved plan.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

impl Default for SolverInfo {
    fn default() -> SolverInfo {
        SolverInfo {
            name: "unknown".into(),
            status: "unknown".into(),
            iterations: 0,
            objective: f64::NAN,
            objective_without_10: None,
            max_constraint_violation: f64::NAN,
            solve_seconds: f64::NAN,
            reason: None,
        }
    }
}

/// A number that may be `null` (read as NaN).
fn nullable_f64<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// A sequence of stances, the numeric content of a plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Stances 1..n_step, in order.
    pub stances: Vec<Stance>,
}

/// Why a plan or solution file could not be built, read or written.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// A flat vector whose length is not 30 · n_step.
    #[error("flat plan has {len} numbers, expected {STANCE_LEN} per stance × n_step {n_step} = {}", STANCE_LEN * n_step)]
    Length {
        /// Length given.
        len: usize,
        /// The scenario's n_step.
        n_step: usize,
    },
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not a valid solution file.
    #[error("{path}: not a valid solution file: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

impl Plan {
    /// Splits a flat vector (layout in the module docs) into stances; its length must
    /// be 30 · `scenario.n_step`.
    pub fn from_flat(scenario: &Scenario, x: &[f64]) -> Result<Plan, PlanError> {
        if x.len() != STANCE_LEN * scenario.n_step {
            return Err(PlanError::Length {
                len: x.len(),
                n_step: scenario.n_step,
            });
        }
        let v3 = |o: usize| -> Vec3 { [x[o], x[o + 1], x[o + 2]] };
        let stances = (0..scenario.n_step)
            .map(|k| Stance {
                com: Coms {
                    b: v3(com_offset(k, Biped::B)),
                    f: v3(com_offset(k, Biped::F)),
                },
                feet: Feet::from_array(Foot::ALL.map(|i| v3(foot_offset(k, i)))),
                forces: Feet::from_array(Foot::ALL.map(|i| v3(force_offset(k, i)))),
            })
            .collect();
        Ok(Plan { stances })
    }

    /// The cost (1): w_CoM Σ_k Σ_j ‖r_j^k − goal_j‖² + w_F Σ_k Σ_i ‖F_i^k‖².
    pub fn cost(&self, scenario: &Scenario) -> f64 {
        let sq = |v: Vec3| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        let mut com = 0.0;
        let mut force = 0.0;
        for s in &self.stances {
            for j in Biped::ALL {
                let (r, g) = (s.com.get(j), scenario.goal.get(j));
                com += sq([r[0] - g[0], r[1] - g[1], r[2] - g[2]]);
            }
            for f in s.forces.to_array() {
                force += sq(f);
            }
        }
        scenario.weights.com * com + scenario.weights.force * force
    }

    /// The flat vector of this plan (layout in the module docs).
    pub fn to_flat(&self) -> Vec<f64> {
        let mut x = vec![0.0; STANCE_LEN * self.stances.len()];
        for (k, s) in self.stances.iter().enumerate() {
            let mut put = |o: usize, v: Vec3| x[o..o + 3].copy_from_slice(&v);
            for j in Biped::ALL {
                put(com_offset(k, j), s.com.get(j));
            }
            for i in Foot::ALL {
                put(foot_offset(k, i), s.feet.get(i));
                put(force_offset(k, i), s.forces.get(i));
            }
        }
        x
    }
}

/// The solution file written by the CLI and read by the checker.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolutionFile {
    /// The full scenario, defaults filled in. On reading, missing fields take their
    /// defaults and unknown ones are rejected, as for a scenario file.
    #[serde(deserialize_with = "scenario_with_defaults")]
    pub scenario: Scenario,
    /// The solver's report (optional on reading, see [`SolverInfo`]).
    #[serde(default, deserialize_with = "lenient_solver")]
    pub solver: SolverInfo,
    /// Stances 1..n_step.
    pub stances: Vec<Stance>,
    /// Present when the plan was re-planned from a measured stance
    /// (`gap-crossing replan`, [`crate::replan`]); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replanned: Option<Replanned>,
}

/// How a re-planned file was made ([`crate::replan`]): stances before `stance` are the
/// earlier plan's, stance `stance` is the measured state (the earlier plan's stance with
/// the perturbation applied; its forces re-solved) and the later stances are re-planned.
/// The checker holds the measured stance only to what a measurement must satisfy:
/// (2), (3), (4) and the keep-out, not (6)–(9), (11), nor (5) and (10) on the way into it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Replanned {
    /// The measured stance (1-based, at least 2).
    pub stance: usize,
    /// The offset applied to both CoMs of that stance (m).
    pub com_offset: Vec3,
    /// The feet given a measured position, by name (`"FR"`), with that position (m).
    #[serde(default)]
    pub feet: std::collections::BTreeMap<String, Vec3>,
}

fn scenario_with_defaults<'de, D: Deserializer<'de>>(d: D) -> Result<Scenario, D::Error> {
    let v = serde_json::Value::deserialize(d)?;
    Scenario::from_value(v).map_err(serde::de::Error::custom)
}

/// The `solver` block as far as it reads: the checker does not use it, so a field of
/// another type than [`SolverInfo`]'s (`"iterations": "many"`) or a block that is not a
/// table is read as unknown (the field's default) instead of rejecting the plan.
fn lenient_solver<'de, D: Deserializer<'de>>(d: D) -> Result<SolverInfo, D::Error> {
    let v = serde_json::Value::deserialize(d)?;
    let mut info = SolverInfo::default();
    let Some(t) = v.as_object() else {
        return Ok(info);
    };
    let text = |k: &str| t.get(k).and_then(|v| v.as_str()).map(str::to_string);
    let number = |k: &str| t.get(k).and_then(serde_json::Value::as_f64);
    if let Some(v) = text("name") {
        info.name = v;
    }
    if let Some(v) = text("status") {
        info.status = v;
    }
    if let Some(v) = t.get("iterations").and_then(serde_json::Value::as_u64) {
        info.iterations = v as usize;
    }
    info.objective = number("objective").unwrap_or(f64::NAN);
    info.objective_without_10 = number("objective_without_10");
    info.max_constraint_violation = number("max_constraint_violation").unwrap_or(f64::NAN);
    info.solve_seconds = number("solve_seconds").unwrap_or(f64::NAN);
    info.reason = text("reason");
    Ok(info)
}

impl SolutionFile {
    /// Assembles a solution file.
    pub fn new(scenario: Scenario, solver: SolverInfo, plan: Plan) -> SolutionFile {
        SolutionFile {
            scenario,
            solver,
            stances: plan.stances,
            replanned: None,
        }
    }

    /// The stances as a [`Plan`].
    pub fn plan(&self) -> Plan {
        Plan {
            stances: self.stances.clone(),
        }
    }

    /// Parses the JSON text of a solution file (`origin` names it in errors). A key
    /// repeated within one object is an error ([`crate::strict_json`]).
    pub fn from_json(text: &str, origin: &Path) -> Result<SolutionFile, PlanError> {
        crate::strict_json::parse(text)
            .and_then(serde_json::from_value)
            .map_err(|e| PlanError::Format {
                path: origin.to_path_buf(),
                message: e.to_string(),
            })
    }

    /// Whether every number of the stances is finite: JSON has no NaN or infinity (serde
    /// writes them as `null`), so only such a file reads back ([`SolutionFile::read`]).
    pub fn stances_finite(&self) -> bool {
        self.plan().to_flat().iter().all(|v| v.is_finite())
    }

    /// Reads a solution file.
    pub fn read(path: &Path) -> Result<SolutionFile, PlanError> {
        SolutionFile::read_with_scenario(path, None)
    }

    /// Reads a solution file; with `scenario`, the plan is read against that scenario
    /// instead of the file's own `scenario` block (which may then be absent), e.g. to
    /// check a plan written by another tool against a separate scenario file.
    pub fn read_with_scenario(
        path: &Path,
        scenario: Option<&Scenario>,
    ) -> Result<SolutionFile, PlanError> {
        let text = std::fs::read_to_string(path).map_err(|source| PlanError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let Some(s) = scenario else {
            return SolutionFile::from_json(&text, path);
        };
        let format = |message: String| PlanError::Format {
            path: path.to_path_buf(),
            message,
        };
        let mut v = crate::strict_json::parse(&text).map_err(|e| format(e.to_string()))?;
        let Some(t) = v.as_object_mut() else {
            return Err(format("expected a JSON object".into()));
        };
        t.insert(
            "scenario".into(),
            serde_json::to_value(s).expect("a scenario serialises"),
        );
        serde_json::from_value(v).map_err(|e| format(e.to_string()))
    }

    /// Pretty JSON text of this file.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("solution file serialises")
    }

    /// Writes the file atomically (a temporary file renamed into place), so a failed
    /// write never leaves a partial file that looks like a result.
    pub fn write(&self, path: &Path) -> Result<(), PlanError> {
        crate::output::write_atomic(path, self.to_json().as_bytes()).map_err(|source| {
            PlanError::Io {
                path: path.to_path_buf(),
                source,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_round_trip_and_offsets() {
        let s = Scenario {
            n_step: 3,
            ..Scenario::default()
        };
        let x: Vec<f64> = (0..90).map(|i| i as f64).collect();
        let p = Plan::from_flat(&s, &x).unwrap();
        assert_eq!(p.stances[1].com.f, [33.0, 34.0, 35.0]);
        assert_eq!(p.stances[2].feet.fl, [75.0, 76.0, 77.0]);
        assert_eq!(p.stances[0].forces.br, [18.0, 19.0, 20.0]);
        assert_eq!(p.to_flat(), x);
        assert!(Plan::from_flat(&s, &x[..89]).is_err());
    }

    #[test]
    fn spec_example_parses() {
        let text = r#"{
          "scenario": { "n_step": 2 },
          "solver": { "name": "ipm", "status": "solved", "iterations": 0,
                      "objective": 0.0, "max_constraint_violation": 0.0, "solve_seconds": 0.0 },
          "stances": [
            { "com":    { "B": [0.0, 0.5, 0.5], "F": [2.0, 0.5, 0.5] },
              "feet":   { "BR": [0,0,0], "BL": [0,1,0], "FR": [2,0,0], "FL": [2,1,0] },
              "forces": { "BR": [0,0,245.25], "BL": [0,0,245.25], "FR": [0,0,245.25], "FL": [0,0,245.25] } }
          ]
        }"#;
        let f = SolutionFile::from_json(text, Path::new("x.json")).unwrap();
        assert_eq!(f.scenario.n_step, 2);
        assert_eq!(f.scenario.gap.min, 2.25);
        assert_eq!(f.stances[0].forces.fl, [0.0, 0.0, 245.25]);
        let back = SolutionFile::from_json(&f.to_json(), Path::new("y.json")).unwrap();
        assert_eq!(back, f);
        let bad = text.replace("\"com\"", "\"cmo\"");
        let e = SolutionFile::from_json(&bad, Path::new("x.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("cmo"), "{e}");
    }
}
