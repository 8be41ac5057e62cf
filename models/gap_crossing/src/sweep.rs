//! Sweeps: solve a grid of scenarios and summarise success and solve time.
//!
//! A grid file (TOML or JSON, by extension) holds an optional `base` scenario (the
//! scenario-file schema: fields not given keep the spec's defaults) and `axes`: for each
//! dotted scenario key (as for `--set`), the list of values it takes. Every point of the
//! Cartesian product of the axes is the base scenario with one value of each axis set by
//! [`Scenario::set`].
//!
//! ```toml
//! [base]
//! n_step = 60
//!
//! [axes]
//! gap.min = [2.0, 2.25, 2.5]         # nested or quoted ("gap.min") keys, either way
//! gap.depth = [0.5, 1, 3]
//! gait = ["crawl", "free"]
//! ```
//!
//! The axes keep their order in the file: the first one is the x axis of the SVG, the
//! second its y axis, the third (if any) gives one panel per value, and any others are
//! aggregated inside each cell. Unknown keys and values of the wrong kind are rejected
//! (naming the key) before anything is solved; a combination that makes the scenario
//! invalid, a failed solve or a plan the checker rejects is recorded for its point and
//! the sweep goes on.

use crate::check;
use crate::output::{self, OutputError};
use crate::plan::SolutionFile;
use crate::scenario::{Scenario, ScenarioError};
use crate::solve::{self, Settings};
use crate::status::StatusKind;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One axis of a grid: a dotted scenario key and the values it takes, in order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    /// Dotted scenario key, e.g. `gap.min`.
    pub key: String,
    /// The values, as in the grid file (numbers, text, arrays).
    pub values: Vec<Value>,
}

/// A parsed grid: the base scenario and the axes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Grid {
    /// The scenario every point starts from (validated only with each point's values).
    pub base: Scenario,
    /// The axes, in file order.
    pub axes: Vec<Axis>,
}

/// One point of the grid: one value per axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// Position in the sweep (row-major over the axes, the last axis fastest).
    pub index: usize,
    /// The index of this point's value on each axis.
    pub coords: Vec<usize>,
    /// `(key, value)` per axis.
    pub overrides: Vec<(String, Value)>,
}

/// What happened at one point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointResult {
    /// Position in the sweep.
    pub index: usize,
    /// The axis values of this point, `key → value`, in axis order.
    pub overrides: Vec<(String, Value)>,
    /// The outcome: the planner's status, or `invalid_scenario`, `error`, `panic`.
    pub status: StatusKind,
    /// True when the independent checker found no violation.
    pub check_ok: bool,
    /// Number of violations the checker found (0 when not checked).
    pub violations: usize,
    /// Distinct equation labels of the violations, e.g. `["(2)", "gap"]`.
    pub violated: Vec<String>,
    /// Cost (1) of the returned plan, when there is one.
    pub objective: Option<f64>,
    /// Solver iterations over all runs, when there is a plan.
    pub iterations: Option<usize>,
    /// Wall time of the point: model building, solving and checking (s).
    pub seconds: f64,
    /// Why there is no plan (invalid scenario, build error, panic), if so.
    pub error: Option<String>,
}

impl PointResult {
    /// Solved and accepted by the checker.
    pub fn ok(&self) -> bool {
        self.status.is_solved() && self.check_ok
    }
}

/// Why a grid could not be read.
#[derive(Debug, thiserror::Error)]
pub enum GridError {
    /// The file could not be read.
    #[error("cannot read grid file {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Neither `.toml` nor `.json`.
    #[error("grid file {0}: unknown extension (expected .toml or .json)")]
    Extension(PathBuf),
    /// Not valid TOML/JSON, or not of the grid's shape.
    #[error("grid file {path}: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The base scenario, or an axis value, is not a valid scenario field.
    #[error("grid file {path}: {context}: {source}")]
    Scenario {
        /// The file.
        path: PathBuf,
        /// `base`, or `axis KEY, value V`.
        context: String,
        /// The scenario's error (names the field).
        source: ScenarioError,
    },
}

/// A table with its keys in file order (serde's maps would sort them).
#[derive(Debug)]
enum Node {
    Table(Vec<(String, Node)>),
    Leaf(Value),
}

impl<'de> Deserialize<'de> for Node {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Node, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Node;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a table, a list or a value")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut m: A) -> Result<Node, A::Error> {
                let mut out = Vec::new();
                while let Some((k, v)) = m.next_entry::<String, Node>()? {
                    out.push((k, v));
                }
                Ok(Node::Table(out))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut s: A) -> Result<Node, A::Error> {
                let mut out = Vec::new();
                while let Some(v) = s.next_element::<Value>()? {
                    out.push(v);
                }
                Ok(Node::Leaf(Value::Array(out)))
            }
            fn visit_bool<E: de::Error>(self, v: bool) -> Result<Node, E> {
                Ok(Node::Leaf(Value::Bool(v)))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Node, E> {
                Ok(Node::Leaf(Value::from(v)))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Node, E> {
                Ok(Node::Leaf(Value::from(v)))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Node, E> {
                Ok(Node::Leaf(Value::from(v)))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Node, E> {
                Ok(Node::Leaf(Value::String(v.to_string())))
            }
            fn visit_unit<E: de::Error>(self) -> Result<Node, E> {
                Ok(Node::Leaf(Value::Null))
            }
        }
        d.deserialize_any(V)
    }
}

impl Node {
    fn into_value(self) -> Value {
        match self {
            Node::Leaf(v) => v,
            Node::Table(t) => {
                Value::Object(t.into_iter().map(|(k, v)| (k, v.into_value())).collect())
            }
        }
    }
}

/// Flattens nested axis tables into dotted keys, keeping file order.
fn flatten(node: Node, prefix: &str, out: &mut Vec<(String, Value)>) {
    match node {
        Node::Table(t) => {
            for (k, v) in t {
                let key = if prefix.is_empty() {
                    k
                } else {
                    format!("{prefix}.{k}")
                };
                flatten(v, &key, out);
            }
        }
        Node::Leaf(v) => out.push((prefix.to_string(), v)),
    }
}

/// A JSON value as the TOML text that [`Scenario::set`] parses.
fn toml_text(v: &Value) -> String {
    match v {
        Value::Array(a) => format!(
            "[{}]",
            a.iter().map(toml_text).collect::<Vec<_>>().join(", ")
        ),
        Value::Object(m) => format!(
            "{{ {} }}",
            m.iter()
                .map(|(k, v)| format!("{} = {}", Value::String(k.clone()), toml_text(v)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        // JSON's numbers, booleans and strings (escapes included) are valid TOML.
        other => other.to_string(),
    }
}

/// A value for labels and CSV: numbers and text as written, other values as JSON.
pub fn label(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

impl Grid {
    /// Parses grid text in the given format (`"toml"` or `"json"`); `origin` names the
    /// file in messages. Checks every axis value against the base scenario (unknown keys,
    /// wrong kinds) without solving anything.
    pub fn parse(text: &str, format: &str, origin: &Path) -> Result<Grid, GridError> {
        let syntax = |message: String| GridError::Syntax {
            path: origin.to_path_buf(),
            message,
        };
        let root: Node = match format {
            "toml" => toml::from_str(text).map_err(|e| syntax(e.to_string()))?,
            "json" => {
                // Duplicate keys are an error (as in TOML); Node keeps the file's order.
                crate::strict_json::parse(text).map_err(|e| syntax(e.to_string()))?;
                serde_json::from_str(text).map_err(|e| syntax(e.to_string()))?
            }
            _ => return Err(GridError::Extension(origin.to_path_buf())),
        };
        let Node::Table(top) = root else {
            return Err(syntax("expected a table with `base` and `axes`".into()));
        };
        let mut base = Scenario::default();
        let mut axes = Vec::new();
        for (key, node) in top {
            match key.as_str() {
                "base" => {
                    let v = node.into_value();
                    if !v.is_object() {
                        return Err(syntax("`base` must be a table (a scenario)".into()));
                    }
                    base = Scenario::from_value(v).map_err(|source| GridError::Scenario {
                        path: origin.to_path_buf(),
                        context: "base".into(),
                        source,
                    })?;
                }
                "axes" => {
                    if !matches!(node, Node::Table(_)) {
                        return Err(syntax("`axes` must be a table of `key = [values]`".into()));
                    }
                    let mut flat = Vec::new();
                    flatten(node, "", &mut flat);
                    for (k, v) in flat {
                        let Value::Array(values) = v else {
                            return Err(syntax(format!(
                                "axis `{k}`: expected a list of values, e.g. {k} = [1.0, 2.0], found {v}"
                            )));
                        };
                        if values.is_empty() {
                            return Err(syntax(format!("axis `{k}` has no values")));
                        }
                        if axes.iter().any(|a: &Axis| a.key == k) {
                            return Err(syntax(format!("axis `{k}` is given twice")));
                        }
                        axes.push(Axis { key: k, values });
                    }
                }
                other => {
                    return Err(syntax(format!(
                        "unknown field `{other}` (fields here: base, axes)"
                    )))
                }
            }
        }
        let grid = Grid { base, axes };
        // Every value must be a settable value of its key.
        for a in &grid.axes {
            for v in &a.values {
                let mut s = grid.base.clone();
                s.set(&a.key, &toml_text(v))
                    .map_err(|source| GridError::Scenario {
                        path: origin.to_path_buf(),
                        context: format!("axis `{}`, value {}", a.key, v),
                        source,
                    })?;
            }
        }
        Ok(grid)
    }

    /// Reads a grid file, TOML or JSON by extension.
    pub fn load(path: &Path) -> Result<Grid, GridError> {
        let format = match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("toml") => "toml",
            Some(e) if e.eq_ignore_ascii_case("json") => "json",
            _ => return Err(GridError::Extension(path.to_path_buf())),
        };
        let text = std::fs::read_to_string(path).map_err(|source| GridError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Grid::parse(&text, format, path)
    }

    /// Number of points (the product of the axes' lengths; 1 with no axes).
    pub fn len(&self) -> usize {
        self.axes.iter().map(|a| a.values.len()).product()
    }

    /// True when the grid has no point (never: an empty product is one point).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Every point, row-major (the last axis varies fastest).
    pub fn points(&self) -> Vec<Point> {
        let n = self.len();
        (0..n)
            .map(|index| {
                let mut rest = index;
                let mut coords = vec![0; self.axes.len()];
                for (d, a) in self.axes.iter().enumerate().rev() {
                    coords[d] = rest % a.values.len();
                    rest /= a.values.len();
                }
                let overrides = self
                    .axes
                    .iter()
                    .zip(&coords)
                    .map(|(a, &c)| (a.key.clone(), a.values[c].clone()))
                    .collect();
                Point {
                    index,
                    coords,
                    overrides,
                }
            })
            .collect()
    }

    /// The scenario of a point: the base with the point's values set (not validated).
    pub fn scenario(&self, p: &Point) -> Result<Scenario, ScenarioError> {
        let mut s = self.base.clone();
        for (k, v) in &p.overrides {
            s.set(k, &toml_text(v))?;
        }
        Ok(s)
    }
}

/// Solves and checks one point. Never fails: errors and panics become the result's
/// status. Returns the solution file too when the solver produced a plan.
pub fn run_point(
    grid: &Grid,
    p: &Point,
    settings: &Settings,
) -> (PointResult, Option<SolutionFile>) {
    let started = Instant::now();
    let mut r = PointResult {
        index: p.index,
        overrides: p.overrides.clone(),
        status: StatusKind::Error,
        check_ok: false,
        violations: 0,
        violated: Vec::new(),
        objective: None,
        iterations: None,
        seconds: 0.0,
        error: None,
    };
    let scenario = grid.scenario(p).and_then(|s| s.validate().map(|_| s));
    let s = match scenario {
        Ok(s) => s,
        Err(e) => {
            r.status = StatusKind::InvalidScenario;
            r.error = Some(e.to_string());
            r.seconds = started.elapsed().as_secs_f64();
            return (r, None);
        }
    };
    let outcome =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| solve::plan(&s, settings)));
    let mut file = None;
    match outcome {
        Ok(Ok(o)) => {
            let report = check::check(&o.file);
            r.status = o.status.kind();
            if !o.status.is_solved() {
                r.error = Some(o.status.to_string());
            }
            r.check_ok = report.ok();
            r.violations = report.violations.len();
            r.violated = report.equations();
            r.objective = Some(o.file.solver.objective);
            r.iterations = Some(o.file.solver.iterations);
            file = Some(o.file);
        }
        Ok(Err(e)) => {
            r.status = StatusKind::Error;
            r.error = Some(e.to_string());
        }
        Err(panic) => {
            r.status = StatusKind::Panic;
            let msg = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown panic".into());
            r.error = Some(msg);
        }
    }
    r.seconds = started.elapsed().as_secs_f64();
    (r, file)
}

/// Solves every point in parallel on the current rayon pool, calling `done` after each
/// point (from the worker thread) with its result and solution file. Results are in
/// point order.
pub fn run(
    grid: &Grid,
    settings: &Settings,
    done: &(dyn Fn(&PointResult, Option<&SolutionFile>) + Sync),
) -> Vec<PointResult> {
    run_points(grid, &grid.points(), settings, done)
}

/// [`run`] on some of the grid's points (a shard, [`crate::shard`]), results in the
/// order of `points`.
pub fn run_points(
    grid: &Grid,
    points: &[Point],
    settings: &Settings,
    done: &(dyn Fn(&PointResult, Option<&SolutionFile>) + Sync),
) -> Vec<PointResult> {
    use rayon::prelude::*;
    let settings = {
        let mut s = settings.clone();
        s.ipm.print_level = 0;
        s
    };
    points
        .par_iter()
        .with_max_len(1)
        .map(|p| {
            let (r, file) = run_point(grid, p, &settings);
            done(&r, file.as_ref());
            r
        })
        .collect()
}

/// Quotes a CSV field when needed (RFC 4180).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn opt_num(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.10e}")).unwrap_or_default()
}

/// How many points ended with each status, in [`StatusKind::ALL`] order, zero counts
/// left out.
pub fn counts(results: &[PointResult]) -> Vec<(StatusKind, usize)> {
    StatusKind::ALL
        .into_iter()
        .map(|k| (k, results.iter().filter(|r| r.status == k).count()))
        .filter(|&(_, n)| n > 0)
        .collect()
}

/// The CSV summary: one row per point; a column per axis (named by its key), then
/// `status, check_ok, violations, violated, objective, iterations, seconds, error`.
pub fn to_csv(grid: &Grid, results: &[PointResult]) -> String {
    let mut out = String::new();
    let mut header: Vec<String> = vec!["index".into()];
    header.extend(grid.axes.iter().map(|a| a.key.clone()));
    header.extend(
        [
            "status",
            "check_ok",
            "violations",
            "violated",
            "objective",
            "iterations",
            "seconds",
            "error",
        ]
        .map(String::from),
    );
    out.push_str(
        &header
            .iter()
            .map(|h| csv_field(h))
            .collect::<Vec<_>>()
            .join(","),
    );
    out.push('\n');
    for r in results {
        let mut row = vec![r.index.to_string()];
        row.extend(r.overrides.iter().map(|(_, v)| label(v)));
        row.push(r.status.word().to_string());
        row.push(r.check_ok.to_string());
        row.push(r.violations.to_string());
        row.push(r.violated.join(" "));
        row.push(opt_num(r.objective));
        row.push(r.iterations.map(|i| i.to_string()).unwrap_or_default());
        row.push(format!("{:.3}", r.seconds));
        row.push(r.error.clone().unwrap_or_default());
        out.push_str(
            &row.iter()
                .map(|f| csv_field(f))
                .collect::<Vec<_>>()
                .join(","),
        );
        out.push('\n');
    }
    out
}

/// The JSON summary: `{ "grid": {base, axes}, "summary": {...}, "points": [...] }`, each
/// point with its `overrides` as a `key → value` table.
pub fn to_json(grid: &Grid, results: &[PointResult], wall_seconds: f64, threads: usize) -> String {
    let points: Vec<Value> = results
        .iter()
        .map(|r| {
            let overrides: serde_json::Map<String, Value> = r.overrides.iter().cloned().collect();
            serde_json::json!({
                "index": r.index,
                "overrides": overrides,
                "status": r.status,
                "check_ok": r.check_ok,
                "ok": r.ok(),
                "violations": r.violations,
                "violated": r.violated,
                "objective": r.objective,
                "iterations": r.iterations,
                "seconds": r.seconds,
                "error": r.error,
            })
        })
        .collect();
    let ok = results.iter().filter(|r| r.ok()).count();
    let by_status: serde_json::Map<String, Value> = counts(results)
        .into_iter()
        .map(|(k, n)| (k.word().to_string(), Value::from(n)))
        .collect();
    let v = serde_json::json!({
        "grid": grid,
        "summary": {
            "points": results.len(),
            "ok": ok,
            "failed": results.len() - ok,
            "by_status": by_status,
            "wall_seconds": wall_seconds,
            "threads": threads,
        },
        "points": points,
    });
    serde_json::to_string_pretty(&v).expect("JSON values serialise")
}

/// Writes `sweep.csv`, `sweep.json` and `sweep.svg` into `dir` (created if needed), all
/// or nothing ([`output::write_all`]).
pub fn write_outputs(
    dir: &Path,
    grid: &Grid,
    results: &[PointResult],
    wall_seconds: f64,
    threads: usize,
) -> Result<Vec<PathBuf>, OutputError> {
    let csv = to_csv(grid, results);
    let json = to_json(grid, results, wall_seconds, threads);
    let svg = crate::render::sweep_svg(grid, results);
    output::write_all(
        dir,
        &[
            ("sweep.csv", csv.as_bytes()),
            ("sweep.json", json.as_bytes()),
            ("sweep.svg", svg.as_bytes()),
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(text: &str) -> Result<Grid, GridError> {
        Grid::parse(text, "toml", Path::new("g.toml"))
    }

    #[test]
    fn axes_keep_file_order_nested_or_quoted() {
        let g = grid(
            "[base]\nn_step = 20\n[axes]\ngap.min = [2.0, 2.25]\n\"gap.depth\" = [0.5, 1, 3]\ngait = [\"crawl\", \"free\"]\n",
        )
        .unwrap();
        let keys: Vec<&str> = g.axes.iter().map(|a| a.key.as_str()).collect();
        assert_eq!(keys, ["gap.min", "gap.depth", "gait"]);
        assert_eq!(g.base.n_step, 20);
        assert_eq!(g.len(), 12);
        let pts = g.points();
        assert_eq!(pts[0].coords, [0, 0, 0]);
        assert_eq!(pts[1].coords, [0, 0, 1]);
        assert_eq!(pts[11].coords, [1, 2, 1]);
        let s = g.scenario(&pts[11]).unwrap();
        assert_eq!((s.gap.min, s.gap.depth), (2.25, 3.0));
        assert_eq!(s.gait, crate::scenario::Gait::Free);
        assert_eq!(s.n_step, 20);
    }

    #[test]
    fn json_grids_and_array_values() {
        let g = Grid::parse(
            r#"{"axes": {"goal.F": [[5.0, 0.5, 0.5], [5.0, 0.8, 0.5]], "n_step": [30, 40]}}"#,
            "json",
            Path::new("g.json"),
        )
        .unwrap();
        assert_eq!(g.axes[0].key, "goal.F");
        assert_eq!(g.axes[1].key, "n_step");
        let s = g.scenario(&g.points()[3]).unwrap();
        assert_eq!((s.goal.f, s.n_step), ([5.0, 0.8, 0.5], 40));
    }

    #[test]
    fn bad_grids_are_rejected_by_name() {
        let e = grid("[axes]\ngap.widht = [0.1]").unwrap_err().to_string();
        assert!(e.contains("gap.widht"), "{e}");
        let e = grid("[axes]\nn_stpe = [10]").unwrap_err().to_string();
        assert!(e.contains("n_stpe"), "{e}");
        let e = grid("[base]\ngap = { widht = 1 }").unwrap_err().to_string();
        assert!(e.contains("base") && e.contains("gap.widht"), "{e}");
        let e = grid("[axes]\ngait = [\"trot\"]").unwrap_err().to_string();
        assert!(e.contains("trot"), "{e}");
        let e = grid("[axes]\ngap.min = 2.0").unwrap_err().to_string();
        assert!(e.contains("gap.min") && e.contains("list"), "{e}");
        let e = grid("[axes]\ngap.min = []").unwrap_err().to_string();
        assert!(e.contains("no values"), "{e}");
        let e = grid("[axis]\ngap.min = [1.0]").unwrap_err().to_string();
        assert!(e.contains("unknown field `axis`"), "{e}");
        let e = grid("[axes]\nn_step = [2.5]").unwrap_err().to_string();
        assert!(e.contains("n_step"), "{e}");
    }

    #[test]
    fn no_axes_is_one_point_and_csv_quotes() {
        let g = grid("").unwrap();
        assert_eq!(g.len(), 1);
        assert_eq!(g.points()[0].overrides, vec![]);
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
    }

    #[test]
    fn invalid_points_are_recorded_not_fatal() {
        let g = grid("[axes]\ngap.min = [2.25, 2.5]\n").unwrap();
        let pts = g.points();
        let (r, file) = run_point(&g, &pts[1], &Settings::default());
        assert_eq!(r.status, StatusKind::InvalidScenario);
        assert!(file.is_none() && !r.ok());
        assert!(r.error.unwrap().contains("gap.min"));
        let results = vec![PointResult {
            index: 1,
            overrides: pts[1].overrides.clone(),
            status: StatusKind::InvalidScenario,
            check_ok: false,
            violations: 0,
            violated: vec![],
            objective: None,
            iterations: None,
            seconds: 0.0,
            error: Some("x, \"y\"".into()),
        }];
        let csv = to_csv(&g, &results);
        assert!(csv.starts_with("index,gap.min,status,"), "{csv}");
        assert!(
            csv.contains("1,2.5,invalid_scenario,false,0,,,,0.000,\"x, \"\"y\"\"\""),
            "{csv}"
        );
        let svg = crate::render::sweep_svg(&g, &results);
        assert!(svg.contains("invalid scenario") && svg.contains("not run"));
    }
}
