//! Sweeps beyond one machine (issue 20 item 6): a grid run as 3 shards and merged gives
//! the summary of one unsharded run.
//!
//! The only numbers of a summary that depend on the run are measured times (each point's
//! `seconds`, which also colour the SVG; the summary's `wall_seconds` and `threads`):
//! with those set alike, the merged `sweep.csv`, `sweep.json` and `sweep.svg` are
//! byte-identical to the unsharded run's; through the binary, everything but those
//! fields is.
use gap_crossing::shard::{self, Shard, ShardError, ShardFile};
use gap_crossing::solve::Settings;
use gap_crossing::sweep::{self, Grid, PointResult};
use std::path::{Path, PathBuf};

mod common;
use common::run;

fn tmp(name: &str) -> PathBuf {
    common::fresh_dir("shards", name)
}

/// 8 points, 4 of them solved (short crawl plans, a fraction of a second each) and 4
/// invalid scenarios (gap.min above gap.max): both kinds of result cross the merge.
const GRID: &str = "[base]\nn_step = 9\ngait = \"crawl\"\ngoal = { B = [0.5, 0.5, 0.5], F = [2.5, 0.5, 0.5] }\n[axes]\ngap.min = [2.25, 2.4]\n\"gap.depth\" = [0.5, 2]\nn_step = [9, 10]\n";

fn grid() -> Grid {
    Grid::parse(GRID, "toml", Path::new("grid.toml")).unwrap()
}

/// The results with every measured time set to 0.
fn untimed(mut r: Vec<PointResult>) -> Vec<PointResult> {
    for p in &mut r {
        p.seconds = 0.0;
    }
    r
}

/// The three summary files of a sweep, as bytes.
fn summary(grid: &Grid, results: &[PointResult], dir: &Path) -> Vec<Vec<u8>> {
    sweep::write_outputs(dir, grid, results, 1.0, 2)
        .unwrap()
        .iter()
        .map(|p| std::fs::read(p).unwrap())
        .collect()
}

#[test]
fn three_shards_merged_are_one_run() {
    let d = tmp("lib");
    let g = grid();
    let settings = Settings::default();
    let whole = sweep::run(&g, &settings, &|_, _| {});
    assert_eq!(whole.len(), 8);
    assert_eq!(whole.iter().filter(|r| r.ok()).count(), 4);
    let shards_dir = d.join("shards");
    for index in 1..=3 {
        let shard = Shard { index, count: 3 };
        let results = shard::run(&g, shard, &settings, &|_, _| {});
        // Disjoint shares, round robin over the point index.
        assert!(results.iter().all(|r| r.index % 3 == index - 1));
        let file = ShardFile {
            grid: g.clone(),
            shard,
            results,
            wall_seconds: index as f64,
            threads: 1,
        };
        file.write(&shards_dir).unwrap();
    }
    let files = shard::find(std::slice::from_ref(&shards_dir)).unwrap();
    assert_eq!(files.len(), 3);
    let merged = shard::merge(shard::read(&files).unwrap()).unwrap();
    assert_eq!(merged.grid, g);
    assert_eq!((merged.wall_seconds, merged.threads), (3.0, 3));
    let (a, b) = (untimed(whole), untimed(merged.results));
    assert_eq!(a, b);
    assert_eq!(
        summary(&g, &a, &d.join("whole")),
        summary(&merged.grid, &b, &d.join("merged"))
    );
}

#[test]
fn merge_rejects_missing_duplicate_and_foreign_shards() {
    let d = tmp("errors");
    let g = grid();
    let empty = |index, count, grid: &Grid| ShardFile {
        grid: grid.clone(),
        shard: Shard { index, count },
        results: Vec::new(),
        wall_seconds: 0.0,
        threads: 1,
    };
    // Results that are not the shard's points.
    let e = shard::merge(vec![(d.join("a"), empty(1, 2, &g))]).unwrap_err();
    assert!(matches!(e, ShardError::Points { index: 1, .. }), "{e}");
    // A grid with one axis less: 2 points, shard 1/2 holds point 0, shard 2/2 point 1.
    let small = Grid::parse(
        "[axes]\ngap.min = [2.25, 2.4]\n",
        "toml",
        Path::new("s.toml"),
    )
    .unwrap();
    let with = |index: usize, count| {
        let mut f = empty(index, count, &small);
        f.results = shard::run(&small, f.shard, &Settings::default(), &|_, _| {})
            .into_iter()
            .filter(|r| r.index == index - 1)
            .collect();
        f
    };
    let (one, two) = (with(1, 2), with(2, 2));
    let e = shard::merge(vec![(d.join("1"), one.clone())]).unwrap_err();
    assert!(
        matches!(&e, ShardError::Missing { missing, count: 2 } if missing == &[2]),
        "{e}"
    );
    let e = shard::merge(vec![
        (d.join("1"), one.clone()),
        (d.join("1b"), one.clone()),
    ])
    .unwrap_err();
    assert!(matches!(e, ShardError::Duplicate { index: 1, .. }), "{e}");
    let mut foreign = two.clone();
    foreign.grid = g.clone();
    let e = shard::merge(vec![(d.join("1"), one.clone()), (d.join("2"), foreign)]).unwrap_err();
    assert!(e.to_string().contains("the grid differs"), "{e}");
    let e = shard::merge(vec![(d.join("1"), one.clone()), (d.join("3"), with(1, 3))]).unwrap_err();
    assert!(e.to_string().contains("shard count"), "{e}");
    assert_eq!(
        shard::merge(vec![(d.join("2"), two), (d.join("1"), one)])
            .unwrap()
            .results
            .len(),
        2
    );
    for bad in ["0/3", "4/3", "1/0", "x/2", "2", "1/2/3"] {
        let e = bad.parse::<Shard>().unwrap_err().to_string();
        assert!(e.contains(bad) && e.contains("I/N"), "{e}");
    }
    assert!(shard::find(&[d.join("nothing-here")]).is_err());
}

/// Drops the columns/fields that are measured times.
fn csv_without_seconds(text: &str) -> String {
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "seconds").unwrap();
    text.lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(col);
            f.join(",")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn json_without_times(path: &Path) -> serde_json::Value {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let summary = v["summary"].as_object_mut().unwrap();
    summary.remove("wall_seconds");
    summary.remove("threads");
    for p in v["points"].as_array_mut().unwrap() {
        p.as_object_mut().unwrap().remove("seconds");
    }
    v
}

#[test]
fn shards_and_merge_through_the_binary() {
    let d = tmp("cli");
    let grid = d.join("grid.toml");
    std::fs::write(&grid, GRID).unwrap();
    let g = grid.to_str().unwrap();
    let whole = d.join("whole");
    let out = run(&["sweep", "--grid", g, "--out", whole.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "4 of 8 points are invalid");
    let shards = d.join("shards");
    for i in 1..=3 {
        let spec = format!("{i}/3");
        let out = run(&[
            "sweep",
            "--grid",
            g,
            "--shard",
            &spec,
            "--out",
            shards.to_str().unwrap(),
        ]);
        assert!(
            out.status.code().is_some_and(|c| c <= 1),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(shards.join(format!("shard-{i}-of-3.json")).is_file());
    }
    // A shard writes only its mergeable result.
    assert!(!shards.join("sweep.csv").exists());
    let merged = d.join("merged");
    let out = run(&[
        "sweep",
        "merge",
        shards.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("4 of 8 points solved and checked"),
        "{stdout}"
    );
    let read = |dir: &Path, f: &str| std::fs::read_to_string(dir.join(f)).unwrap();
    assert_eq!(
        csv_without_seconds(&read(&whole, "sweep.csv")),
        csv_without_seconds(&read(&merged, "sweep.csv"))
    );
    assert_eq!(
        json_without_times(&whole.join("sweep.json")),
        json_without_times(&merged.join("sweep.json"))
    );
    assert!(read(&merged, "sweep.svg").contains("4 of 8 points"));
    // A missing shard: exit 2, named.
    std::fs::remove_file(shards.join("shard-2-of-3.json")).unwrap();
    let out = run(&[
        "sweep",
        "merge",
        shards.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("shards missing: [2] of 3"));
}
