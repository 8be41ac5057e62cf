//! The scenario: every number that defines one gap-crossing problem.
//!
//! Defaults are exactly the table "Default scenario" of `docs/gap-crossing.md`.
//! A scenario file (TOML or JSON, chosen by extension) need only name the values it
//! changes; everything else keeps its default. Unknown fields are rejected with their full
//! dotted path (e.g. `gap.widht`), and [`Scenario::validate`] rejects values that make
//! the problem meaningless, naming the field, foot and value.
//!
//! Units: metres, kilograms, newtons, seconds. Positions are `[x, y, z]` with z up.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::PathBuf;

pub use crate::terrain_spec::{read_height_csv, TerrainSpec};

mod read;
pub use read::ALIASES;

/// A point or vector in metres (positions) or newtons (forces): `[x, y, z]`.
pub type Vec3 = [f64; 3];

/// Absolute tolerance used when checking that the start configuration satisfies the
/// equations; the same 1e-6 the spec gives the checker (units of each equation).
pub const START_TOL: f64 = 1e-6;

/// How far a start foot may sit off the terrain, (3) (m): the spec allows 1e-5, since a
/// deep gap's atan tail lowers the ground near its edges by about 1e-6 m (1.1e-6 m at
/// x = 2 for a 3 m deep default gap). The checker applies it to feet still at their start.
pub const START_TERRAIN_TOL: f64 = 1e-5;

/// The two bipeds of the robot: B (back, mass m1) and F (front, mass m2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Biped {
    /// Back biped, owns feet BR and BL.
    B,
    /// Front biped, owns feet FR and FL.
    F,
}

impl Biped {
    /// Both bipeds, in the variable order B, F.
    pub const ALL: [Biped; 2] = [Biped::B, Biped::F];

    /// The name used in files and messages ("B" or "F").
    pub fn name(self) -> &'static str {
        match self {
            Biped::B => "B",
            Biped::F => "F",
        }
    }

    /// The two feet of this biped (right first).
    pub fn feet(self) -> [Foot; 2] {
        match self {
            Biped::B => [Foot::BR, Foot::BL],
            Biped::F => [Foot::FR, Foot::FL],
        }
    }
}

impl fmt::Display for Biped {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The four feet, in the variable order of the spec: BR, BL, FR, FL.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Foot {
    /// Back right.
    BR,
    /// Back left.
    BL,
    /// Front right.
    FR,
    /// Front left.
    FL,
}

impl Foot {
    /// All feet, in the variable order BR, BL, FR, FL.
    pub const ALL: [Foot; 4] = [Foot::BR, Foot::BL, Foot::FR, Foot::FL];

    /// Position of this foot in [`Foot::ALL`] (0..4).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The name used in files and messages ("BR", ...).
    pub fn name(self) -> &'static str {
        match self {
            Foot::BR => "BR",
            Foot::BL => "BL",
            Foot::FR => "FR",
            Foot::FL => "FL",
        }
    }

    /// The biped that owns this foot.
    pub fn biped(self) -> Biped {
        match self {
            Foot::BR | Foot::BL => Biped::B,
            Foot::FR | Foot::FL => Biped::F,
        }
    }
}

impl fmt::Display for Foot {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One value per biped CoM, serialised as `{ "B": ..., "F": ... }`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Coms {
    /// Back biped's CoM (m).
    #[serde(rename = "B")]
    pub b: Vec3,
    /// Front biped's CoM (m).
    #[serde(rename = "F")]
    pub f: Vec3,
}

impl Coms {
    /// The value for biped `j`.
    pub fn get(&self, j: Biped) -> Vec3 {
        match j {
            Biped::B => self.b,
            Biped::F => self.f,
        }
    }

    /// Mutable access to the value for biped `j`.
    pub fn get_mut(&mut self, j: Biped) -> &mut Vec3 {
        match j {
            Biped::B => &mut self.b,
            Biped::F => &mut self.f,
        }
    }
}

/// One value per foot, serialised as `{ "BR": ..., "BL": ..., "FR": ..., "FL": ... }`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Feet {
    /// Back right.
    #[serde(rename = "BR")]
    pub br: Vec3,
    /// Back left.
    #[serde(rename = "BL")]
    pub bl: Vec3,
    /// Front right.
    #[serde(rename = "FR")]
    pub fr: Vec3,
    /// Front left.
    #[serde(rename = "FL")]
    pub fl: Vec3,
}

impl Feet {
    /// Builds from an array in the order BR, BL, FR, FL.
    pub fn from_array(a: [Vec3; 4]) -> Feet {
        Feet {
            br: a[0],
            bl: a[1],
            fr: a[2],
            fl: a[3],
        }
    }

    /// The values in the order BR, BL, FR, FL.
    pub fn to_array(&self) -> [Vec3; 4] {
        [self.br, self.bl, self.fr, self.fl]
    }

    /// The value for foot `i`.
    pub fn get(&self, i: Foot) -> Vec3 {
        match i {
            Foot::BR => self.br,
            Foot::BL => self.bl,
            Foot::FR => self.fr,
            Foot::FL => self.fl,
        }
    }

    /// Mutable access to the value for foot `i`.
    pub fn get_mut(&mut self, i: Foot) -> &mut Vec3 {
        match i {
            Foot::BR => &mut self.br,
            Foot::BL => &mut self.bl,
            Foot::FR => &mut self.fr,
            Foot::FL => &mut self.fl,
        }
    }
}

/// A full-contact configuration: both CoMs and all four feet.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Configuration {
    /// CoM of each biped (m).
    pub com: Coms,
    /// Position of each foot (m).
    pub feet: Feet,
}

/// The gap: the terrain is a flat floor z = 0 with a gap across the whole width for
/// x in (min, max), smoothed as
/// h(x) = (D/π) [atan(k (x − max)) − atan(k (x − min))].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gap {
    /// Near edge of the gap, x (m). Default 2.25.
    pub min: f64,
    /// Far edge of the gap, x (m). Default 2.35.
    pub max: f64,
    /// Depth D of the gap (m); 0 gives flat ground. Default 1.0.
    pub depth: f64,
    /// Steepness k of the atan edges (1/m). Default 1e6.
    pub steepness: f64,
    /// Safety margin added on each side: no foot may be in (min − margin, max + margin) (m).
    /// Default 0.03.
    pub margin: f64,
}

impl Gap {
    /// Terrain height h(x) (m); ≈ −depth inside the gap, ≈ 0 outside.
    pub fn height(&self, x: f64) -> f64 {
        let k = self.steepness;
        self.depth / std::f64::consts::PI
            * ((k * (x - self.max)).atan() - (k * (x - self.min)).atan())
    }

    /// dh/dx at x.
    pub fn slope(&self, x: f64) -> f64 {
        let k = self.steepness;
        let a = k * (x - self.max);
        let b = k * (x - self.min);
        self.depth / std::f64::consts::PI * (k / (1.0 + a * a) - k / (1.0 + b * b))
    }

    /// Unit surface normal at x: n = −∇f_env/‖∇f_env‖ with f_env = h(x, y) − z, i.e.
    /// (−h'(x), 0, 1)/√(1 + h'²); it points up, out of the ground.
    pub fn normal(&self, x: f64) -> Vec3 {
        let s = self.slope(x);
        let n = (1.0 + s * s).sqrt();
        [-s / n, 0.0, 1.0 / n]
    }

    /// The widened gap (min − margin, max + margin) as an open interval (lo, hi).
    pub fn keep_out(&self) -> (f64, f64) {
        (self.min - self.margin, self.max + self.margin)
    }

    /// True when x lies strictly inside the widened gap.
    pub fn in_keep_out(&self, x: f64) -> bool {
        let (lo, hi) = self.keep_out();
        x > lo && x < hi
    }
}

/// Friction at every foot.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Friction {
    /// Friction coefficient μ (tangential ≤ μ · normal force). Default 0.5.
    pub mu: f64,
    /// Minimum normal force F_thr (N) each foot must push with. Default 10.
    pub f_thr: f64,
}

/// Weights of the cost (1).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Weights {
    /// w_CoM, on Σ_k Σ_j ‖r_j^k − goal_j‖² (1/m²). Default 1000.
    pub com: f64,
    /// w_F, on Σ_k Σ_i ‖F_i^k‖² (1/N²). Default 0.001.
    pub force: f64,
}

/// Masses of the two bipeds (kg).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Masses {
    /// m1, the back biped (kg). Default 50.
    #[serde(rename = "B")]
    pub b: f64,
    /// m2, the front biped (kg). Default 50.
    #[serde(rename = "F")]
    pub f: f64,
}

impl Masses {
    /// m1 + m2 (kg).
    pub fn total(&self) -> f64 {
        self.b + self.f
    }
}

/// Bounds `min ≤ value ≤ max` on a squared distance (m²).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bounds {
    /// Lower bound (m²).
    pub min: f64,
    /// Upper bound (m²).
    pub max: f64,
}

/// Which foot may move between consecutive stances.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Gait {
    /// The source's problem: equation (10), the optimiser picks which foot moves.
    #[default]
    Free,
    /// Prescribed order BR, FR, BL, FL, repeated: only the scheduled foot may move.
    Crawl,
}

impl fmt::Display for Gait {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Gait::Free => "free",
            Gait::Crawl => "crawl",
        })
    }
}

/// One gap-crossing problem. Every field has the spec's default ([`Scenario::default`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Number of stances n_step, stance 1 being the start. Default 60; at least 2.
    pub n_step: usize,
    /// Masses m1 (B) and m2 (F), kg. Default 50 and 50.
    pub masses: Masses,
    /// Magnitude of gravity, m/s²; g = (0, 0, −gravity). Default 9.81.
    pub gravity: f64,
    /// Start configuration (stance 1). Default CoMs B (0, 0.5, 0.5), F (2, 0.5, 0.5);
    /// feet BR (0, 0, 0), BL (0, 1, 0), FR (2, 0, 0), FL (2, 1, 0).
    pub start: Configuration,
    /// Goal CoMs. Default B (3, 0.5, 0.5), F (5, 0.5, 0.5).
    pub goal: Coms,
    /// The gap in the terrain. Default min 2.25, max 2.35, depth 1, steepness 1e6, margin 0.03.
    pub gap: Gap,
    /// Friction cones (4). Default μ 0.5, F_thr 10 N.
    pub friction: Friction,
    /// Cost weights (1). Default w_CoM 1000, w_F 0.001.
    pub weights: Weights,
    /// Squared leg length of (11): ‖r_j − r_i‖² for each foot of biped j (m²). Default 0.5.
    pub leg_length_sq: f64,
    /// Squared step radius of (5): ‖r_i^k − r_i^{k+1}‖² ≤ this (m²). Default 0.09.
    pub step_radius_sq: f64,
    /// Bounds of (6),(7) on ‖r_BR − r_FR‖² and ‖r_BL − r_FL‖² (m²). Default [1, 9].
    pub same_side_sq: Bounds,
    /// Bounds of (8),(9) on ‖r_BR − r_BL‖² and ‖r_FR − r_FL‖² (m²). Default [0.25, 2.25].
    pub same_biped_sq: Bounds,
    /// Gait mode: `free` (default) or `crawl`.
    pub gait: Gait,
    /// The ground (default: the `gap` table's gap).
    #[serde(default)]
    pub terrain: TerrainSpec,
    /// Optional limits on the body's motion (the `motion` table; all off by default, and
    /// then the model is the spec's).
    #[serde(default, skip_serializing_if = "MotionLimits::is_unset")]
    pub motion: MotionLimits,
}

/// Optional limits on the body's motion, a user's additions to the spec's model (the
/// scenario's `motion` table; each off when absent). They hold from stance 2 on (the
/// start is as given); the model states them as constraints and `check` verifies them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionLimits {
    /// Least height of each CoM above the ground under it, `z − h(x, y)` (m; over a
    /// gap, h is its bottom).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_height_min: Option<f64>,
    /// Greatest height of each CoM above the ground under it (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_height_max: Option<f64>,
    /// Greatest distance each CoM travels per transition, `‖c^{k+1} − c^k‖` (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub com_travel_max: Option<f64>,
}

impl MotionLimits {
    /// No limit set (the spec's model).
    pub fn is_unset(&self) -> bool {
        *self == MotionLimits::default()
    }

    /// Everything wrong with the limits: finite, body heights and travel positive, the
    /// least body height not above the greatest.
    pub fn validate(&self) -> Vec<Invalid> {
        let mut bad = Vec::new();
        for (name, v) in [
            ("body_height_min", self.body_height_min),
            ("body_height_max", self.body_height_max),
            ("com_travel_max", self.com_travel_max),
        ] {
            if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0)) {
                bad.push(Invalid {
                    field: format!("motion.{name}"),
                    message: format!("must be a positive finite number (m), got {v}"),
                });
            }
        }
        if let (Some(lo), Some(hi)) = (self.body_height_min, self.body_height_max) {
            if lo > hi {
                bad.push(Invalid {
                    field: "motion.body_height_min".into(),
                    message: format!("must not exceed body_height_max ({hi}), got {lo}"),
                });
            }
        }
        bad
    }
}

impl Default for Scenario {
    fn default() -> Self {
        Scenario {
            n_step: 60,
            masses: Masses { b: 50.0, f: 50.0 },
            gravity: 9.81,
            start: Configuration {
                com: Coms {
                    b: [0.0, 0.5, 0.5],
                    f: [2.0, 0.5, 0.5],
                },
                feet: Feet {
                    br: [0.0, 0.0, 0.0],
                    bl: [0.0, 1.0, 0.0],
                    fr: [2.0, 0.0, 0.0],
                    fl: [2.0, 1.0, 0.0],
                },
            },
            goal: Coms {
                b: [3.0, 0.5, 0.5],
                f: [5.0, 0.5, 0.5],
            },
            gap: Gap {
                min: 2.25,
                max: 2.35,
                depth: 1.0,
                steepness: 1e6,
                margin: 0.03,
            },
            friction: Friction {
                mu: 0.5,
                f_thr: 10.0,
            },
            weights: Weights {
                com: 1000.0,
                force: 0.001,
            },
            leg_length_sq: 0.5,
            step_radius_sq: 0.09,
            same_side_sq: Bounds { min: 1.0, max: 9.0 },
            same_biped_sq: Bounds {
                min: 0.25,
                max: 2.25,
            },
            gait: Gait::Free,
            terrain: TerrainSpec::Gap,
            motion: MotionLimits::default(),
        }
    }
}

/// One thing wrong with a scenario's values.
#[derive(Clone, Debug, PartialEq)]
pub struct Invalid {
    /// Dotted path of the offending field, e.g. `gap.min` or `start.feet.BR`.
    pub field: String,
    /// What is wrong, with the value.
    pub message: String,
}

impl fmt::Display for Invalid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.message)
    }
}

/// Why a scenario could not be read, changed or accepted.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("cannot read scenario file {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file's extension is neither `.toml` nor `.json`.
    #[error("scenario file {0}: unknown extension (expected .toml or .json)")]
    Extension(PathBuf),
    /// The file is not valid TOML/JSON.
    #[error("scenario file {path}: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A field that the scenario does not have.
    #[error("unknown field `{field}` (fields here: {known})")]
    UnknownField {
        /// Dotted path of the unknown field.
        field: String,
        /// The fields allowed at that level, comma-separated.
        known: String,
    },
    /// A field given a value of the wrong kind (e.g. text for a number).
    #[error("field `{field}`: expected {expected}, found {found}")]
    WrongType {
        /// Dotted path of the field.
        field: String,
        /// What the field takes.
        expected: String,
        /// What was given.
        found: String,
    },
    /// A `--set` argument that is not `key=value`.
    #[error("override `{0}`: expected key=value, e.g. gap.min=2.0")]
    Override(String),
    /// A value that parsed but could not be converted (e.g. an unknown gait name).
    #[error("scenario: {0}")]
    Value(String),
    /// Values that make the problem meaningless; each names field, foot and value.
    #[error("invalid scenario: {}", .0.iter().map(|i| i.to_string()).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<Invalid>),
}

impl Scenario {
    /// g = (0, 0, −gravity) (m/s²).
    pub fn gravity_vector(&self) -> Vec3 {
        [0.0, 0.0, -self.gravity]
    }

    /// Every numeric field with its dotted path, for finiteness checks and messages.
    pub fn numbers(&self) -> Vec<(String, f64)> {
        let mut out = vec![
            ("masses.B".to_string(), self.masses.b),
            ("masses.F".into(), self.masses.f),
            ("gravity".into(), self.gravity),
            ("gap.min".into(), self.gap.min),
            ("gap.max".into(), self.gap.max),
            ("gap.depth".into(), self.gap.depth),
            ("gap.steepness".into(), self.gap.steepness),
            ("gap.margin".into(), self.gap.margin),
            ("friction.mu".into(), self.friction.mu),
            ("friction.f_thr".into(), self.friction.f_thr),
            ("weights.com".into(), self.weights.com),
            ("weights.force".into(), self.weights.force),
            ("leg_length_sq".into(), self.leg_length_sq),
            ("step_radius_sq".into(), self.step_radius_sq),
            ("same_side_sq.min".into(), self.same_side_sq.min),
            ("same_side_sq.max".into(), self.same_side_sq.max),
            ("same_biped_sq.min".into(), self.same_biped_sq.min),
            ("same_biped_sq.max".into(), self.same_biped_sq.max),
        ];
        let mut point = |name: String, p: Vec3| {
            for (c, v) in p.iter().enumerate() {
                out.push((format!("{name}[{c}]"), *v));
            }
        };
        for j in Biped::ALL {
            point(format!("start.com.{j}"), self.start.com.get(j));
            point(format!("goal.{j}"), self.goal.get(j));
        }
        for i in Foot::ALL {
            point(format!("start.feet.{i}"), self.start.feet.get(i));
        }
        out
    }

    /// Checks that the scenario describes a meaningful problem: finite values, positive
    /// masses, gravity, μ, steepness and squared distances, gap.min < gap.max,
    /// n_step ≥ 2, non-negative margin, depth, F_thr and weights, ordered bounds, and a
    /// start that satisfies (3), (6)–(9), (11) and the gap keep-out (tolerance
    /// [`START_TOL`]). Returns every problem found, each naming field, foot and value.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        let mut bad = Vec::new();
        let mut push = |field: &str, message: String| {
            bad.push(Invalid {
                field: field.to_string(),
                message,
            })
        };
        let mut finite = true;
        for (name, v) in self.numbers() {
            if !v.is_finite() {
                push(&name, format!("must be a finite number, got {v}"));
                finite = false;
            }
        }
        if self.n_step < 2 {
            push(
                "n_step",
                format!(
                    "must be at least 2 (the start and one more stance), got {}",
                    self.n_step
                ),
            );
        }
        let positive = [
            ("masses.B", self.masses.b),
            ("masses.F", self.masses.f),
            ("gravity", self.gravity),
            ("friction.mu", self.friction.mu),
            ("gap.steepness", self.gap.steepness),
            ("leg_length_sq", self.leg_length_sq),
            ("step_radius_sq", self.step_radius_sq),
        ];
        for (name, v) in positive {
            if v <= 0.0 {
                push(name, format!("must be positive, got {v}"));
            }
        }
        let non_negative = [
            ("gap.margin", self.gap.margin),
            ("gap.depth", self.gap.depth),
            ("friction.f_thr", self.friction.f_thr),
            ("weights.com", self.weights.com),
            ("weights.force", self.weights.force),
            ("same_side_sq.min", self.same_side_sq.min),
            ("same_biped_sq.min", self.same_biped_sq.min),
        ];
        for (name, v) in non_negative {
            if v < 0.0 {
                push(name, format!("must not be negative, got {v}"));
            }
        }
        if self.gap.min >= self.gap.max {
            push(
                "gap.min",
                format!(
                    "must be less than gap.max ({}), got {}",
                    self.gap.max, self.gap.min
                ),
            );
        }
        for (name, b) in [
            ("same_side_sq", self.same_side_sq),
            ("same_biped_sq", self.same_biped_sq),
        ] {
            if b.min > b.max {
                push(
                    &format!("{name}.min"),
                    format!("must not exceed {name}.max ({}), got {}", b.max, b.min),
                );
            }
        }
        bad.extend(self.terrain.validate());
        bad.extend(self.motion.validate());
        if bad.is_empty() && finite {
            self.validate_start(&mut bad);
        }
        if bad.is_empty() {
            Ok(())
        } else {
            Err(ScenarioError::Invalid(bad))
        }
    }

    /// The start configuration must satisfy the equations that involve no forces.
    fn validate_start(&self, bad: &mut Vec<Invalid>) {
        let s = &self.start;
        let terrain = crate::terrain::of(self);
        for i in Foot::ALL {
            let p = s.feet.get(i);
            let field = format!("start.feet.{i}");
            let h = terrain.height_at(p[0], p[1]);
            if (h - p[2]).abs() > START_TERRAIN_TOL {
                bad.push(Invalid {
                    field: field.clone(),
                    message: format!(
                        "violates (3) feet on the terrain: foot {i} at z = {} but the terrain height at x = {} is {h:.6e}",
                        p[2], p[0]
                    ),
                });
            }
            let depth = terrain.keep_out_depth(p[0], p[1]);
            if depth > START_TOL {
                bad.push(Invalid {
                    field: field.clone(),
                    message: format!(
                        "foot {i} at (x, y) = ({}, {}) is {depth:.3e} m inside the keep-out (outside every region where the {} terrain allows feet)",
                        p[0], p[1], self.terrain.kind()
                    ),
                });
            }
            let j = i.biped();
            let d2 = dist2(s.com.get(j), p);
            if (d2 - self.leg_length_sq).abs() > START_TOL {
                bad.push(Invalid {
                    field,
                    message: format!(
                        "violates (11) rigid legs: ‖r_{j} − r_{i}‖² = {d2} but leg_length_sq is {} (start.com.{j} = {:?}, foot {i} = {:?})",
                        self.leg_length_sq,
                        s.com.get(j),
                        p
                    ),
                });
            }
        }
        let pairs = [
            ("(6)", Foot::BR, Foot::FR, self.same_side_sq, "same_side_sq"),
            ("(7)", Foot::BL, Foot::FL, self.same_side_sq, "same_side_sq"),
            (
                "(8)",
                Foot::BR,
                Foot::BL,
                self.same_biped_sq,
                "same_biped_sq",
            ),
            (
                "(9)",
                Foot::FR,
                Foot::FL,
                self.same_biped_sq,
                "same_biped_sq",
            ),
        ];
        for (eq, a, b, bounds, name) in pairs {
            let d2 = dist2(s.feet.get(a), s.feet.get(b));
            if d2 < bounds.min - START_TOL || d2 > bounds.max + START_TOL {
                bad.push(Invalid {
                    field: format!("start.feet.{a}"),
                    message: format!(
                        "violates {eq}: ‖r_{a} − r_{b}‖² = {d2} is outside {name} [{}, {}]",
                        bounds.min, bounds.max
                    ),
                });
            }
        }
    }
}

/// Squared Euclidean distance.
pub fn dist2(a: Vec3, b: Vec3) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn default_is_valid() {
        Scenario::default().validate().unwrap();
    }

    #[test]
    fn toml_partial_overrides() {
        let s = Scenario::parse(
            "n_step = 30\n[gap]\nmin = 1.0\nmax = 1.2\n",
            "toml",
            Path::new("x.toml"),
        )
        .unwrap();
        assert_eq!(s.n_step, 30);
        assert_eq!(s.gap.min, 1.0);
        assert_eq!(s.gap.depth, 1.0);
        assert_eq!(s.goal, Scenario::default().goal);
    }

    #[test]
    fn set_paths() {
        let mut s = Scenario::default();
        s.set("gap.min", "2.0").unwrap();
        s.set("n_step", "30").unwrap();
        s.set("gait", "crawl").unwrap();
        s.set("goal.B[1]", "0.7").unwrap();
        s.set("start.feet.BR", "[0, 0.1, 0]").unwrap();
        assert_eq!(s.gap.min, 2.0);
        assert_eq!(s.n_step, 30);
        assert_eq!(s.gait, Gait::Crawl);
        assert_eq!(s.goal.b, [3.0, 0.7, 0.5]);
        assert_eq!(s.start.feet.br, [0.0, 0.1, 0.0]);
        let e = s.set("gap.widht", "1").unwrap_err().to_string();
        assert!(e.contains("gap.widht"), "{e}");
        let e = s.set("n_step", "2.5").unwrap_err().to_string();
        assert!(e.contains("n_step"), "{e}");
        let e = s.set("gait", "trot").unwrap_err().to_string();
        assert!(e.contains("trot"), "{e}");
    }

    #[test]
    fn terrain_is_flat_away_from_gap() {
        let g = Scenario::default().gap;
        assert!(g.height(0.0).abs() < 1e-7);
        assert!((g.height(2.3) + 1.0).abs() < 1e-4);
        assert_eq!(g.normal(0.0)[2], 1.0);
    }
}
