//! The example files under `scenarios/`: every scenario file loads, validates and is
//! solved (crawl gait) to a plan the checker accepts; every grid file parses and all its
//! points are valid scenarios; `default.toml` spells out exactly the defaults; and the
//! scenario-field table of `docs/gap-crossing.md` lists every field with its default.

use gap_crossing::check;
use gap_crossing::scenario::{Gait, Scenario};
use gap_crossing::solve::{self, Settings};
use gap_crossing::status::StatusKind;
use gap_crossing::sweep::Grid;
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

/// (path, is a grid) for every .toml/.json file in `scenarios/`.
fn files() -> Vec<(PathBuf, bool)> {
    let mut out: Vec<(PathBuf, bool)> = std::fs::read_dir(dir())
        .expect("scenarios/ exists")
        .map(|e| e.unwrap().path())
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("toml" | "json")
            )
        })
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            // A grid has an `axes` table; a scenario file never does.
            let grid = text.contains("[axes]") || text.contains("\"axes\"");
            (p, grid)
        })
        .collect();
    out.sort();
    out
}

#[test]
fn there_are_examples_of_both_kinds() {
    let f = files();
    assert!(f.iter().filter(|(_, g)| !g).count() >= 5, "{f:?}");
    assert!(f.iter().any(|(_, g)| *g), "{f:?}");
}

#[test]
fn default_toml_is_the_default_scenario() {
    let s = Scenario::load(&dir().join("default.toml")).unwrap();
    assert_eq!(s, Scenario::default());
}

#[test]
fn grid_files_parse_and_every_point_is_valid() {
    for (p, _) in files().into_iter().filter(|(_, g)| *g) {
        let grid = Grid::load(&p).unwrap_or_else(|e| panic!("{e}"));
        assert!(grid.len() > 1, "{}", p.display());
        for pt in grid.points() {
            let s = grid.scenario(&pt).unwrap();
            s.validate()
                .unwrap_or_else(|e| panic!("{} point {:?}: {e}", p.display(), pt.overrides));
        }
    }
}

/// Each example scenario, in the crawl gait (the free gait is exercised by the root
/// test `tests/gap_crossing.rs`): solved, and the checker finds nothing.
#[test]
fn scenario_files_solve_and_check() {
    let scenarios: Vec<(PathBuf, Scenario)> = files()
        .into_iter()
        .filter(|(_, g)| !g)
        .map(|(p, _)| {
            let s = Scenario::load(&p).unwrap_or_else(|e| panic!("{e}"));
            (p, s)
        })
        .collect();
    // Two at a time (the machine's cores), results in file order.
    let results: Vec<(String, StatusKind, check::Report)> = std::thread::scope(|scope| {
        let chunks: Vec<_> = scenarios
            .chunks(scenarios.len().div_ceil(2))
            .map(|chunk| {
                scope.spawn(move || {
                    chunk
                        .iter()
                        .map(|(p, s)| {
                            let s = Scenario {
                                gait: Gait::Crawl,
                                ..s.clone()
                            };
                            let o = solve::plan(&s, &Settings::default())
                                .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
                            let name = p.file_name().unwrap().to_string_lossy().into_owned();
                            (name, o.status.kind(), check::check(&o.file))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        chunks.into_iter().flat_map(|h| h.join().unwrap()).collect()
    });
    for (name, status, report) in &results {
        println!("{name:<22} {status:<17} {}", report.summary());
    }
    for (name, status, report) in &results {
        assert_eq!(*status, StatusKind::Solved, "{name}");
        assert!(report.ok(), "{name}: {report}");
    }
}

/// Every scenario field (dotted path, as for `--set`) has a row in the docs' table, with
/// its default value.
#[test]
fn docs_list_every_field_with_its_default() {
    let doc_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/gap-crossing.md");
    let doc = std::fs::read_to_string(&doc_path).expect("docs/gap-crossing.md");
    let value = serde_json::to_value(Scenario::default()).unwrap();
    let mut leaves = Vec::new();
    fn walk(v: &serde_json::Value, path: String, out: &mut Vec<(String, serde_json::Value)>) {
        match v {
            serde_json::Value::Object(m) => {
                for (k, x) in m {
                    let p = if path.is_empty() {
                        k.clone()
                    } else {
                        format!("{path}.{k}")
                    };
                    walk(x, p, out);
                }
            }
            other => out.push((path, other.clone())),
        }
    }
    walk(&value, String::new(), &mut leaves);
    assert!(leaves.len() > 20);
    for (path, default) in leaves {
        let row = doc
            .lines()
            .find(|l| l.starts_with(&format!("| `{path}` |")))
            .unwrap_or_else(|| panic!("docs/gap-crossing.md has no row for `{path}`"));
        let shown = match &default {
            serde_json::Value::String(s) => format!("`\"{s}\"`"),
            serde_json::Value::Array(a) => format!(
                "`[{}]`",
                a.iter()
                    .map(|x| x.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            serde_json::Value::Number(n) => {
                let f = n.as_f64().unwrap();
                if n.is_u64() || f != 1e6 {
                    format!("`{n}`")
                } else {
                    "`1e6`".to_string()
                }
            }
            other => format!("`{other}`"),
        };
        assert!(
            row.contains(&shown),
            "docs row for `{path}` does not show its default {shown}: {row}"
        );
    }
}
