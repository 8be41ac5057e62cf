//! The scenario's `terrain` table: which ground, with its numbers (see
//! [`crate::terrain`] for the geometry and docs/gap-crossing.md, "Terrains").
use crate::scenario::{Gap, Invalid, ScenarioError};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The ground, chosen by the scenario's `terrain` table (`kind` names the terrain; see
/// [`crate::terrain`]). The default, `kind = "gap"`, is the specification's gap described
/// by the scenario's `gap` table; the other kinds ignore `gap`.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TerrainSpec {
    /// The specification's gap (the `gap` table).
    #[default]
    Gap,
    /// A smoothed step `h(x) = rise·(½ + atan(k(x − edge))/π)`; feet stay `margin` away
    /// from the edge.
    Step {
        /// x of the edge (m).
        edge: f64,
        /// Height change across the edge (m; negative: a step down).
        rise: f64,
        /// Steepness k of the edge (1/m), positive.
        steepness: f64,
        /// Keep-out half-width around the edge (m), not negative.
        margin: f64,
    },
    /// Several gaps across the whole width, each as the `gap` table.
    Gaps {
        /// The gaps.
        gaps: Vec<Gap>,
    },
    /// Flat ground `z = 0` where feet may stand only on the stones.
    Stones {
        /// Each stone `[x_min, x_max, y_min, y_max]` (m).
        stones: Vec<[f64; 4]>,
    },
    /// Heights on a regular grid, read from a CSV file, interpolated by a C¹
    /// Catmull-Rom spline; feet stay on the grid's rectangle.
    HeightMap {
        /// The CSV file (relative to the scenario file): one row per y, one column per
        /// x, numbers separated by commas; `#` starts a comment line.
        file: String,
        /// `(x, y)` of the first number of the first row (m).
        origin: [f64; 2],
        /// Node spacing `(Δx, Δy)` (m), positive.
        spacing: [f64; 2],
        /// The heights (m), filled from `file` when the scenario is loaded (a solution
        /// file carries them, so it can be checked without the CSV).
        #[serde(default)]
        heights: Vec<Vec<f64>>,
    },
}

impl TerrainSpec {
    /// Everything wrong with the table's values: finite, steepness and spacing positive, margins not
    /// negative, each gap and stone ordered, a height map's grid at least 2 × 2.
    pub fn validate(&self) -> Vec<Invalid> {
        let mut bad = Vec::new();
        let mut push = |field: String, message: String| bad.push(Invalid { field, message });
        let mut finite = |field: String, v: f64| {
            if !v.is_finite() {
                push(field, format!("must be a finite number, got {v}"));
                false
            } else {
                true
            }
        };
        let mut checks: Vec<(String, String)> = Vec::new();
        match self {
            TerrainSpec::Gap => {}
            TerrainSpec::Step {
                edge,
                rise,
                steepness,
                margin,
            } => {
                for (n, v) in [
                    ("edge", edge),
                    ("rise", rise),
                    ("steepness", steepness),
                    ("margin", margin),
                ] {
                    finite(format!("terrain.{n}"), *v);
                }
                if *steepness <= 0.0 {
                    checks.push((
                        "terrain.steepness".into(),
                        format!("must be positive, got {steepness}"),
                    ));
                }
                if *margin < 0.0 {
                    checks.push((
                        "terrain.margin".into(),
                        format!("must not be negative, got {margin}"),
                    ));
                }
            }
            TerrainSpec::Gaps { gaps } => {
                if gaps.is_empty() {
                    checks.push(("terrain.gaps".into(), "must list at least one gap".into()));
                }
                for (k, g) in gaps.iter().enumerate() {
                    let f = |n: &str| format!("terrain.gaps[{k}].{n}");
                    for (n, v) in [
                        ("min", g.min),
                        ("max", g.max),
                        ("depth", g.depth),
                        ("steepness", g.steepness),
                        ("margin", g.margin),
                    ] {
                        finite(f(n), v);
                    }
                    if g.min >= g.max {
                        checks.push((
                            f("min"),
                            format!("must be less than max ({}), got {}", g.max, g.min),
                        ));
                    }
                    if g.steepness <= 0.0 {
                        checks.push((
                            f("steepness"),
                            format!("must be positive, got {}", g.steepness),
                        ));
                    }
                    if g.depth < 0.0 || g.margin < 0.0 {
                        checks.push((
                            f("depth"),
                            format!(
                                "depth and margin must not be negative, got {} and {}",
                                g.depth, g.margin
                            ),
                        ));
                    }
                }
            }
            TerrainSpec::Stones { stones } => {
                if stones.is_empty() {
                    checks.push((
                        "terrain.stones".into(),
                        "must list at least one stone".into(),
                    ));
                }
                for (k, b) in stones.iter().enumerate() {
                    let ok = b.iter().all(|v| finite(format!("terrain.stones[{k}]"), *v));
                    if ok && (b[0] >= b[1] || b[2] >= b[3]) {
                        checks.push((
                            format!("terrain.stones[{k}]"),
                            format!(
                                "must be [x_min, x_max, y_min, y_max] with min < max, got {b:?}"
                            ),
                        ));
                    }
                }
            }
            TerrainSpec::HeightMap {
                file,
                origin,
                spacing,
                heights,
            } => {
                for (c, v) in origin.iter().chain(spacing).enumerate() {
                    finite(
                        format!("terrain.{}", if c < 2 { "origin" } else { "spacing" }),
                        *v,
                    );
                }
                if spacing.iter().any(|d| *d <= 0.0) {
                    checks.push((
                        "terrain.spacing".into(),
                        format!("must be positive, got {spacing:?}"),
                    ));
                }
                let cols = heights.first().map_or(0, Vec::len);
                if heights.len() < 2 || cols < 2 || heights.iter().any(|r| r.len() != cols) {
                    checks.push(("terrain.heights".into(), format!("a rectangular grid of at least 2 × 2 numbers is needed (from {file}), got {} rows", heights.len())));
                } else if heights.iter().flatten().any(|v| !v.is_finite()) {
                    checks.push(("terrain.heights".into(), "must be finite numbers".into()));
                } else if spacing.iter().chain(origin).all(|v| v.is_finite())
                    && spacing.iter().all(|d| *d > 0.0)
                {
                    let max_abs = heights.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
                    let n = [cols, heights.len()];
                    if let Some(why) =
                        crate::terrain::HeightMap::grid_problem(*origin, *spacing, n, max_abs)
                    {
                        checks.push(("terrain.spacing".into(), why));
                    }
                }
            }
        }
        for (field, message) in checks {
            bad.push(Invalid { field, message });
        }
        bad
    }

    /// The word of `kind`.
    pub fn kind(&self) -> &'static str {
        match self {
            TerrainSpec::Gap => "gap",
            TerrainSpec::Step { .. } => "step",
            TerrainSpec::Gaps { .. } => "gaps",
            TerrainSpec::Stones { .. } => "stones",
            TerrainSpec::HeightMap { .. } => "height_map",
        }
    }
}

/// The largest height-map CSV file read (bytes): 16 MiB, about a million nodes written
/// with 15 characters each, whose lookup tables need about 4 GiB
/// ([`crate::limits::BYTES_PER_GRID_NODE`]); a 2000 × 2000 CSV used to be read and
/// planned for minutes with no output.
pub const MAX_HEIGHT_CSV_BYTES: u64 = 16 << 20;

/// Reads a height-map CSV (at most [`MAX_HEIGHT_CSV_BYTES`]): rows of comma-separated numbers, `#` comment lines and blank
/// lines ignored. Every row must have the same number of columns (at least 2), and there
/// must be at least 2 rows.
pub fn read_height_csv(path: &Path) -> Result<Vec<Vec<f64>>, ScenarioError> {
    let io = |source| ScenarioError::Io {
        path: path.to_path_buf(),
        source,
    };
    let bad = |message: String| ScenarioError::Syntax {
        path: path.to_path_buf(),
        message,
    };
    let size = std::fs::metadata(path).map_err(io)?.len();
    if size > MAX_HEIGHT_CSV_BYTES {
        return Err(bad(format!(
            "the file is {size} bytes, more than the {} MiB a height map may have (about a million nodes; \
             the planner's memory grows with the grid's nodes, see docs/gap-crossing.md, \"Size limit\"): use a coarser grid",
            MAX_HEIGHT_CSV_BYTES >> 20
        )));
    }
    let text = std::fs::read_to_string(path).map_err(io)?;
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let row = line
            .split(',')
            .map(|c| {
                c.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        bad(format!(
                            "line {}: `{}` is not a finite number",
                            n + 1,
                            c.trim()
                        ))
                    })
            })
            .collect::<Result<Vec<f64>, _>>()?;
        if let Some(first) = rows.first() {
            if first.len() != row.len() {
                return Err(bad(format!(
                    "line {}: {} columns, the first row has {}",
                    n + 1,
                    row.len(),
                    first.len()
                )));
            }
        }
        rows.push(row);
    }
    if rows.len() < 2 || rows[0].len() < 2 {
        return Err(bad(format!(
            "a height map needs at least 2 rows and 2 columns, got {} × {}",
            rows.len(),
            rows.first().map_or(0, Vec::len)
        )));
    }
    Ok(rows)
}
