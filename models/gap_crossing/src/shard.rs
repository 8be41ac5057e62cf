//! Sweeps beyond one machine: a grid split into disjoint shards, each run anywhere, and
//! the shards' results merged into the summary of one run.
//!
//! Shard `I/N` (1-based) holds the points whose index `k` has `k mod N = I − 1`
//! ([`Shard::holds`]): round robin, so that neighbouring points (which cost about the
//! same) spread over the shards. `gap-crossing sweep --shard I/N --out DIR` runs one
//! shard and writes `DIR/shard-I-of-N.json` ([`ShardFile`]: the grid, the shard, its
//! points' results, its wall time and threads); `gap-crossing sweep merge DIR…` reads
//! every such file in the directories (or the files) given, checks that they come from
//! one grid and cover each point exactly once ([`merge`]), and writes `sweep.csv`,
//! `sweep.json` and `sweep.svg` as an unsharded run does: point for point the same
//! results, so the same bytes except the measured times (each point's `seconds`, which
//! also colour the SVG; the summary's `wall_seconds`, the longest shard's, and
//! `threads`, their sum).
use crate::output::{self, OutputError};
use crate::plan::SolutionFile;
use crate::scenario::{Scenario, ScenarioError};
use crate::solve::Settings;
use crate::sweep::{self, Axis, Grid, PointResult};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// One share of a grid's points: number `index` (1-based) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Which shard, 1..=count.
    pub index: usize,
    /// How many shards the grid is split into.
    pub count: usize,
}

impl Shard {
    /// Whether point `k` (its index in the sweep) belongs to this shard.
    pub fn holds(&self, k: usize) -> bool {
        k % self.count == self.index - 1
    }

    /// The file name of this shard's result: `shard-I-of-N.json`.
    pub fn file_name(&self) -> String {
        format!("shard-{}-of-{}.json", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = ShardError;

    /// Parses `I/N` with 1 ≤ I ≤ N.
    fn from_str(text: &str) -> Result<Shard, ShardError> {
        let bad = || ShardError::Spec(text.to_string());
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if count == 0 || index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

/// What can go wrong with shards.
#[derive(Debug, thiserror::Error)]
pub enum ShardError {
    /// `--shard` is not of the form `I/N` with 1 ≤ I ≤ N.
    #[error("shard `{0}`: expected I/N with 1 ≤ I ≤ N, e.g. --shard 2/8")]
    Spec(String),
    /// A shard file or directory could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A shard file is not a shard result.
    #[error("{path}: not a sweep shard result: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Nothing to merge.
    #[error("no shard files (shard-I-of-N.json) found in {0}")]
    NoShards(String),
    /// Shards of different grids or splits.
    #[error(
        "{path}: {what} differs from that of {first}: shards of different sweeps cannot be merged"
    )]
    Mismatch {
        /// The shard file that differs.
        path: PathBuf,
        /// The first shard file read.
        first: PathBuf,
        /// `the grid` or `the shard count`.
        what: &'static str,
    },
    /// The same shard given twice.
    #[error("shard {index}/{count} is given twice: {a} and {b}")]
    Duplicate {
        /// Shard number.
        index: usize,
        /// Shard count.
        count: usize,
        /// One file.
        a: PathBuf,
        /// The other.
        b: PathBuf,
    },
    /// Shards missing.
    #[error("shards missing: {missing:?} of {count} (the merge needs every shard)")]
    Missing {
        /// The missing shard numbers.
        missing: Vec<usize>,
        /// Shard count.
        count: usize,
    },
    /// A shard's results are not exactly its points.
    #[error("{path}: its results are not the points of shard {index}/{count} of the grid")]
    Points {
        /// The file.
        path: PathBuf,
        /// Shard number.
        index: usize,
        /// Shard count.
        count: usize,
    },
}

/// The mergeable result of one shard (`shard-I-of-N.json`).
#[derive(Clone, Debug, PartialEq)]
pub struct ShardFile {
    /// The whole grid (every shard carries it, so the merge can check they agree).
    pub grid: Grid,
    /// Which share of it.
    pub shard: Shard,
    /// The results of this shard's points, in point order.
    pub results: Vec<PointResult>,
    /// Wall time of the shard's run (s).
    pub wall_seconds: f64,
    /// Worker threads of the shard's run.
    pub threads: usize,
}

/// `ShardFile` as written: the grid's base scenario as a scenario value.
#[derive(Serialize, Deserialize)]
struct Stored {
    base: Value,
    axes: Vec<Axis>,
    shard: Shard,
    results: Vec<PointResult>,
    wall_seconds: f64,
    threads: usize,
}

impl ShardFile {
    /// The file's JSON text.
    pub fn to_json(&self) -> String {
        let stored = Stored {
            base: serde_json::to_value(&self.grid.base).expect("a scenario serialises"),
            axes: self.grid.axes.clone(),
            shard: self.shard,
            results: self.results.clone(),
            wall_seconds: self.wall_seconds,
            threads: self.threads,
        };
        serde_json::to_string_pretty(&stored).expect("shard results serialise")
    }

    /// Parses a shard file's text (`origin` names it in errors).
    pub fn parse(text: &str, origin: &Path) -> Result<ShardFile, ShardError> {
        let format = |message: String| ShardError::Format {
            path: origin.to_path_buf(),
            message,
        };
        let stored: Stored = serde_json::from_str(text).map_err(|e| format(e.to_string()))?;
        let base = Scenario::from_value(stored.base)
            .map_err(|e: ScenarioError| format(format!("base scenario: {e}")))?;
        Ok(ShardFile {
            grid: Grid {
                base,
                axes: stored.axes,
            },
            shard: stored.shard,
            results: stored.results,
            wall_seconds: stored.wall_seconds,
            threads: stored.threads,
        })
    }

    /// Writes `dir/shard-I-of-N.json` (atomically, [`output::write_all`]).
    pub fn write(&self, dir: &Path) -> Result<PathBuf, OutputError> {
        let name = self.shard.file_name();
        let text = self.to_json();
        let mut written = output::write_all(dir, &[(name.as_str(), text.as_bytes())])?;
        Ok(written.remove(0))
    }
}

/// Runs the points of `shard` of `grid` in parallel on the current rayon pool (as
/// [`sweep::run`], calling `done` after each), results in point order.
pub fn run(
    grid: &Grid,
    shard: Shard,
    settings: &Settings,
    done: &(dyn Fn(&PointResult, Option<&SolutionFile>) + Sync),
) -> Vec<PointResult> {
    let points: Vec<_> = grid
        .points()
        .into_iter()
        .filter(|p| shard.holds(p.index))
        .collect();
    sweep::run_points(grid, &points, settings, done)
}

/// The shard files to merge: each argument is a shard file, or a directory whose
/// `shard-*-of-*.json` files are taken (sorted by name).
pub fn find(paths: &[PathBuf]) -> Result<Vec<PathBuf>, ShardError> {
    let mut out = Vec::new();
    for p in paths {
        let io = |source| ShardError::Io {
            path: p.clone(),
            source,
        };
        if !std::fs::metadata(p).map_err(io)?.is_dir() {
            out.push(p.clone());
            continue;
        }
        let mut found: Vec<PathBuf> = std::fs::read_dir(p)
            .map_err(io)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|f| {
                f.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with("shard-") && n.ends_with(".json"))
            })
            .collect();
        found.sort();
        out.extend(found);
    }
    if out.is_empty() {
        let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
        return Err(ShardError::NoShards(names.join(", ")));
    }
    Ok(out)
}

/// Reads the shard files at `paths` ([`find`] lists them from directories).
pub fn read(paths: &[PathBuf]) -> Result<Vec<(PathBuf, ShardFile)>, ShardError> {
    paths
        .iter()
        .map(|p| {
            let text = std::fs::read_to_string(p).map_err(|source| ShardError::Io {
                path: p.clone(),
                source,
            })?;
            Ok((p.clone(), ShardFile::parse(&text, p)?))
        })
        .collect()
}

/// The merged sweep: the grid, every point's result in point order, the longest
/// shard's wall time and the shards' threads summed.
#[derive(Clone, Debug, PartialEq)]
pub struct Merged {
    /// The grid the shards share.
    pub grid: Grid,
    /// Every point's result, in point order.
    pub results: Vec<PointResult>,
    /// The longest shard's wall time (s): the sweep's, with the shards run at once.
    pub wall_seconds: f64,
    /// The threads of all shards.
    pub threads: usize,
}

/// Merges shard results (file path, contents): they must share the grid and the shard
/// count, give every shard exactly once, and each hold exactly its shard's points.
pub fn merge(shards: Vec<(PathBuf, ShardFile)>) -> Result<Merged, ShardError> {
    let Some((first_path, first)) = shards.first().cloned() else {
        return Err(ShardError::NoShards("the arguments".into()));
    };
    let count = first.shard.count;
    let mut seen: Vec<Option<PathBuf>> = vec![None; count];
    let mut results = Vec::with_capacity(first.grid.len());
    let (mut wall, mut threads) = (0.0f64, 0);
    for (path, s) in shards {
        let mismatch = |what| ShardError::Mismatch {
            path: path.clone(),
            first: first_path.clone(),
            what,
        };
        if s.grid != first.grid {
            return Err(mismatch("the grid"));
        }
        if s.shard.count != count || s.shard.index == 0 || s.shard.index > count {
            return Err(mismatch("the shard count"));
        }
        let slot = &mut seen[s.shard.index - 1];
        if let Some(a) = slot {
            return Err(ShardError::Duplicate {
                index: s.shard.index,
                count,
                a: a.clone(),
                b: path,
            });
        }
        let expected: Vec<usize> = (0..first.grid.len())
            .filter(|&k| s.shard.holds(k))
            .collect();
        let got: Vec<usize> = s.results.iter().map(|r| r.index).collect();
        if got != expected {
            return Err(ShardError::Points {
                path,
                index: s.shard.index,
                count,
            });
        }
        *slot = Some(path);
        wall = wall.max(s.wall_seconds);
        threads += s.threads;
        results.extend(s.results);
    }
    let missing: Vec<usize> = (1..=count).filter(|&i| seen[i - 1].is_none()).collect();
    if !missing.is_empty() {
        return Err(ShardError::Missing { missing, count });
    }
    results.sort_by_key(|r| r.index);
    Ok(Merged {
        grid: first.grid,
        results,
        wall_seconds: wall,
        threads,
    })
}
