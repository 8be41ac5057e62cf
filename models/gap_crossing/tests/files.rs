//! Limits and files (issue 11, item 5), through the binary: outputs are all or nothing,
//! too-large problems are refused before building, `check` reads plans written by other
//! tools, `sweep --solutions` writes only files that read back, duplicate JSON keys are
//! errors.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;
use common::run;

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A fresh directory per test.
fn tmp(name: &str) -> PathBuf {
    common::fresh_dir("files", name)
}

/// Every entry of `dir` with its content (`<dir>` for a directory), sorted.
fn listing(dir: &Path) -> Vec<(String, String)> {
    let mut v: Vec<(String, String)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let c = std::fs::read_to_string(e.path()).unwrap_or_else(|_| "<dir>".into());
            (e.file_name().to_string_lossy().into_owned(), c)
        })
        .collect();
    v.sort();
    v
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The spec's example stance twice, goal = start: a valid plan (no solver block).
fn plan_without_solver() -> serde_json::Value {
    let stance = serde_json::json!({
        "com":    { "B": [0.0, 0.5, 0.5], "F": [2.0, 0.5, 0.5] },
        "feet":   { "BR": [0,0,0], "BL": [0,1,0], "FR": [2,0,0], "FL": [2,1,0] },
        "forces": { "BR": [0,0,245.25], "BL": [0,0,245.25], "FR": [0,0,245.25], "FL": [0,0,245.25] }
    });
    serde_json::json!({
        "scenario": { "n_step": 2, "goal": { "B": [0.0, 0.5, 0.5], "F": [2.0, 0.5, 0.5] } },
        "stances": [stance.clone(), stance]
    })
}

/// `solve` into a directory whose `plan.svg` is a directory: exit 2 naming it, and the
/// directory is exactly as before (the old solution.json kept, nothing new, no
/// temporary file).
#[test]
fn failed_solve_output_leaves_the_directory_untouched() {
    let d = tmp("solve_out");
    std::fs::write(d.join("solution.json"), "old solution").unwrap();
    std::fs::create_dir(d.join("plan.svg")).unwrap();
    let before = listing(&d);
    let out = run(&common::small_crawl_solve(&d));
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("plan.svg"), "{}", text(&out));
    assert_eq!(listing(&d), before);
    // With the obstacle gone the same run writes every file.
    std::fs::remove_dir(d.join("plan.svg")).unwrap();
    let out = run(&common::small_crawl_solve(&d));
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let names: Vec<String> = listing(&d).into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        names,
        [
            "convergence.json",
            "convergence.svg",
            "plan.html",
            "plan.svg",
            "solution.json"
        ]
    );
}

/// `render` and `guess` are all or nothing too.
#[test]
fn failed_render_and_guess_outputs_leave_the_directory_untouched() {
    let d = tmp("render_out");
    let plan = d.join("in.json");
    std::fs::write(&plan, plan_without_solver().to_string()).unwrap();
    let out_dir = d.join("out");
    std::fs::create_dir_all(out_dir.join("plan.svg")).unwrap();
    std::fs::write(out_dir.join("guess.json"), "old guess").unwrap();
    let before = listing(&out_dir);
    let out = run(&["render", s(&plan), "--out", s(&out_dir)]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert_eq!(listing(&out_dir), before);
    let out = run(&["guess", "--out", s(&out_dir)]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert_eq!(listing(&out_dir), before);
}

/// A horizon beyond the memory available is refused at once (no building: well under
/// the minutes the build took), with the estimate, and nothing is written.
#[test]
fn too_large_n_step_is_refused_before_building() {
    let d = tmp("too_large");
    let started = std::time::Instant::now();
    let out = run(&["solve", "--out", s(&d), "--set", "n_step=100000000"]);
    let secs = started.elapsed().as_secs_f64();
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    let msg = text(&out);
    assert!(
        msg.contains("n_step = 100000000 is too large") && msg.contains("GiB"),
        "{msg}"
    );
    // Generous: a process start, on a loaded machine (building took minutes).
    assert!(secs < 5.0, "{secs} s");
    assert!(listing(&d).is_empty());
}

/// `check` reads a plan without a solver block, and one whose solver block is another
/// tool's (other fields, `null` numbers).
#[test]
fn check_reads_plans_of_other_tools() {
    let d = tmp("other_tools");
    let bare = d.join("bare.json");
    std::fs::write(&bare, plan_without_solver().to_string()).unwrap();
    let out = run(&["check", s(&bare)]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let mut v = plan_without_solver();
    v["solver"] = serde_json::json!({ "name": "casadi", "return_status": "Solve_Succeeded",
                                      "objective": null, "t_wall_total": 1.5 });
    let other = d.join("other.json");
    std::fs::write(&other, v.to_string()).unwrap();
    let out = run(&["check", s(&other)]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let out = run(&["render", s(&other), "--out", s(&d.join("r"))]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
}

/// A key repeated in a JSON scenario, grid or solution file is an error naming it.
#[test]
fn duplicate_json_keys_are_errors() {
    let d = tmp("dup");
    let sc = d.join("s.json");
    std::fs::write(
        &sc,
        r#"{"n_step": 20, "gap": {"min": 2.0, "max": 2.1, "min": 2.2}}"#,
    )
    .unwrap();
    let out = run(&["solve", "--scenario", s(&sc), "--out", s(&d.join("o"))]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(
        text(&out).contains("duplicate key `gap.min`"),
        "{}",
        text(&out)
    );
    let grid = d.join("g.json");
    std::fs::write(&grid, r#"{"axes": {"n_step": [10], "n_step": [12]}}"#).unwrap();
    let out = run(&["sweep", "--grid", s(&grid), "--out", s(&d.join("sw"))]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(
        text(&out).contains("duplicate key `axes.n_step`"),
        "{}",
        text(&out)
    );
    let plan = d.join("p.json");
    let t = plan_without_solver().to_string().replacen(
        "\"stances\":",
        "\"scenario\":{},\"stances\":",
        1,
    );
    std::fs::write(&plan, t).unwrap();
    let out = run(&["check", s(&plan)]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(
        text(&out).contains("duplicate key `scenario`"),
        "{}",
        text(&out)
    );
}

/// `sweep --solutions` with points that fail (an iteration limit the solver cannot
/// meet): every file written reads back in `check` (exit 0 or 1, never 2) and `render`.
#[test]
fn sweep_files_of_failed_points_read_back() {
    let d = tmp("sweep_failed");
    let grid = d.join("g.toml");
    std::fs::write(
        &grid,
        "[base]\ngait = \"crawl\"\n[axes]\nn_step = [8, 10]\n",
    )
    .unwrap();
    let out_dir = d.join("out");
    let out = run(&[
        "sweep",
        "--grid",
        s(&grid),
        "--out",
        s(&out_dir),
        "--solutions",
        "--opt",
        "max_iter=2",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    let points: Vec<PathBuf> = std::fs::read_dir(out_dir.join("points"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert!(!points.is_empty());
    for p in points {
        let c = run(&["check", s(&p)]);
        assert!(
            matches!(c.status.code(), Some(0 | 1)),
            "{}: {}",
            p.display(),
            text(&c)
        );
        let r = run(&["render", s(&p), "--out", s(&d.join("r"))]);
        assert_eq!(r.status.code(), Some(0), "{}: {}", p.display(), text(&r));
    }
}
