//! The binary: exit codes and messages of `check`, `render`, `guess`, `solve`, `sweep`.

use gap_crossing::status::StatusKind;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

mod common;
use common::run;

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A fresh directory per test.
fn tmp(name: &str) -> PathBuf {
    common::fresh_dir("cli", name)
}

/// The spec's example stance, twice, with goal = start: a valid plan.
fn valid_json() -> serde_json::Value {
    let stance = serde_json::json!({
        "com":    { "B": [0.0, 0.5, 0.5], "F": [2.0, 0.5, 0.5] },
        "feet":   { "BR": [0,0,0], "BL": [0,1,0], "FR": [2,0,0], "FL": [2,1,0] },
        "forces": { "BR": [0,0,245.25], "BL": [0,0,245.25], "FR": [0,0,245.25], "FL": [0,0,245.25] }
    });
    serde_json::json!({
        "scenario": { "n_step": 2, "goal": { "B": [0.0, 0.5, 0.5], "F": [2.0, 0.5, 0.5] } },
        "solver": { "name": "ipm", "status": "solved", "iterations": 0, "objective": 0.0,
                    "max_constraint_violation": 0.0, "solve_seconds": 0.0 },
        "stances": [stance.clone(), stance]
    })
}

fn write(dir: &Path, name: &str, v: &serde_json::Value) -> String {
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string_pretty(v).unwrap()).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn check_passes_a_valid_plan() {
    let d = tmp("valid");
    let f = write(&d, "solution.json", &valid_json());
    let out = run(&["check", &f]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        text(&out.stdout),
        text(&out.stderr)
    );
    assert!(
        text(&out.stdout).starts_with("OK: 2 stances"),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn check_reports_each_violation_and_exits_1() {
    let d = tmp("violations");
    let mut v = valid_json();
    // Stance 2: CoM B raised so both back legs are 1e-4 m² too long; FR loses 10 N.
    v["stances"][1]["com"]["B"][2] = serde_json::json!(0.2501f64.sqrt());
    v["stances"][1]["forces"]["FR"][2] = serde_json::json!(235.25);
    let f = write(&d, "bad.json", &v);
    let out = run(&["check", &f]);
    assert_eq!(out.status.code(), Some(1));
    let s = text(&out.stdout);
    let lines: Vec<&str> = s.lines().collect();
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("(11)") && l.contains("stance 2") && l.contains("BR")),
        "{s}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("(11)") && l.contains("BL")),
        "{s}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("(2) force balance") && l.contains("1.000e1")),
        "{s}"
    );
    assert!(lines.last().unwrap().starts_with("FAILED"), "{s}");
}

#[test]
fn check_goal_modes() {
    let d = tmp("goal");
    let mut v = valid_json();
    v["scenario"]["goal"]["B"] = serde_json::json!([0.3, 0.5, 0.5]);
    let f = write(&d, "g.json", &v);
    // 0.3 m in one stance is out of the crawl heuristic's reach: auto skips the goal.
    assert_eq!(run(&["check", &f]).status.code(), Some(0));
    assert_eq!(
        run(&["check", "--goal", "required", &f]).status.code(),
        Some(1)
    );
}

#[test]
fn check_errors_exit_2_with_the_reason() {
    let d = tmp("errors");
    let out = run(&["check", d.join("missing.json").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("missing.json"),
        "{}",
        text(&out.stderr)
    );

    let mut v = valid_json();
    v["stances"][0]["feat"] = serde_json::json!(1);
    let f = write(&d, "unknown.json", &v);
    let out = run(&["check", &f]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("feat"), "{}", text(&out.stderr));

    let mut v = valid_json();
    v["scenario"]["gap"] = serde_json::json!({ "min": 3.0 });
    let f = write(&d, "invalid.json", &v);
    let out = run(&["check", &f]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("gap.min"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn solve_writes_a_plan_that_check_accepts() {
    let d = tmp("solve");
    let out_dir = d.join("out");
    let args = common::small_crawl_solve(&out_dir);
    let out = run(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    for f in [
        "solution.json",
        "plan.svg",
        "convergence.svg",
        "convergence.json",
    ] {
        assert!(out_dir.join(f).exists(), "{f} missing");
    }
    assert!(
        text(&out.stdout).contains("status:     solved"),
        "{}",
        text(&out.stdout)
    );
    // Goals 0.5 m ahead (the front feet cross the gap): reached, and required.
    let sol = out_dir.join("solution.json");
    let out = run(&["check", sol.to_str().unwrap(), "--goal", "required"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
}

/// A small sweep: crawl gait, short horizon; one combination is an invalid scenario
/// (gap.min ≥ gap.max), which is recorded for its point while the others are solved;
/// the exit code is 1 because not every point succeeded.
#[test]
fn sweep_solves_a_grid_and_records_failures() {
    let d = tmp("sweep");
    let grid = d.join("grid.toml");
    std::fs::write(
        &grid,
        "[base]\nn_step = 9\ngait = \"crawl\"\ngoal = { B = [0.5, 0.5, 0.5], F = [2.5, 0.5, 0.5] }\n[axes]\ngap.min = [2.25, 2.4]\n\"gap.depth\" = [0.5, 2]\n",
    )
    .unwrap();
    let out_dir = d.join("out");
    let out = run(&[
        "sweep",
        "--grid",
        grid.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
        "--solutions",
    ]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}{}", text(&out.stderr));
    assert!(
        stdout.contains("2 of 4 points solved and checked"),
        "{stdout}"
    );

    let csv = std::fs::read_to_string(out_dir.join("sweep.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert!(
        rows[0].starts_with("index,gap.min,gap.depth,status,check_ok,"),
        "{csv}"
    );
    assert_eq!(rows.len(), 5, "{csv}");
    assert!(rows[1].starts_with("0,2.25,0.5,solved,true,0,"), "{csv}");
    assert!(
        rows[3].starts_with("2,2.4,0.5,invalid_scenario,false,"),
        "{csv}"
    );
    assert!(rows[3].contains("gap.min"), "{csv}");

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("sweep.json")).unwrap())
            .unwrap();
    assert_eq!(json["summary"]["points"], 4);
    assert_eq!(json["summary"]["ok"], 2);
    let p1 = &json["points"][1];
    assert_eq!(p1["overrides"]["gap.depth"], 2.0);
    assert_eq!(
        StatusKind::from_word(p1["status"].as_str().unwrap()),
        StatusKind::Solved
    );
    assert_eq!(p1["check_ok"], true);
    assert!(p1["objective"].as_f64().unwrap() > 0.0);
    assert!(p1["iterations"].as_u64().unwrap() > 0);
    assert!(p1["seconds"].as_f64().unwrap() > 0.0);

    let svg = std::fs::read_to_string(out_dir.join("sweep.svg")).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("2 of 4 points"),
        "{svg}"
    );
    assert!(svg.contains("gap.min") && svg.contains("invalid scenario"));

    // --solutions: each solved point's plan, which the checker accepts.
    let p0 = out_dir.join("points").join("0000.json");
    let out = run(&["check", p0.to_str().unwrap(), "--goal", "required"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
    assert!(!out_dir.join("points").join("0002.json").exists());
}

#[test]
fn sweep_succeeds_with_exit_0_and_rejects_bad_grids_with_2() {
    let d = tmp("sweep_ok");
    let grid = write(
        &d,
        "grid.json",
        &serde_json::json!({
            "base": { "n_step": 9, "gait": "crawl", "goal": { "B": [0.5, 0.5, 0.5] } },
            "axes": { "goal.F": [[2.5, 0.5, 0.5], [2.5, 0.6, 0.5]] }
        }),
    );
    let out_dir = d.join("out");
    let out = run(&[
        "sweep",
        "--grid",
        &grid,
        "--out",
        out_dir.to_str().unwrap(),
        "--threads",
        "1",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        text(&out.stdout),
        text(&out.stderr)
    );
    assert!(out_dir.join("sweep.svg").exists());

    for (name, body, needle) in [
        (
            "unknown_axis.toml",
            "[axes]\ngap.widht = [0.1, 0.2]\n",
            "gap.widht",
        ),
        ("unknown_base.toml", "[base]\nn_stpe = 3\n", "n_stpe"),
        ("unknown_top.toml", "[axis]\ngap.min = [2.0]\n", "axis"),
        ("not_a_list.toml", "[axes]\ngap.min = 2.0\n", "list"),
        (
            "bad_value.toml",
            "[axes]\ngait = [\"crawl\", \"trot\"]\n",
            "trot",
        ),
        ("grid.yaml", "axes: {}\n", "extension"),
    ] {
        let p = d.join(name);
        std::fs::write(&p, body).unwrap();
        let out = run(&[
            "sweep",
            "--grid",
            p.to_str().unwrap(),
            "--out",
            out_dir.join(name).to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let err = text(&out.stderr);
        assert!(err.contains(needle) && err.contains(name), "{name}: {err}");
        assert!(!out_dir.join(name).exists(), "{name}: outputs written");
    }
    let out = run(&["sweep", "--grid", d.join("missing.toml").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("missing.toml"));
}

#[test]
fn scenario_errors_come_first() {
    let out = run(&["solve", "--set", "gap.widht=0.2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("gap.widht"),
        "{}",
        text(&out.stderr)
    );
    let out = run(&["--set", "n_step=1"]);
    assert!(
        text(&out.stderr).contains("n_step"),
        "{}",
        text(&out.stderr)
    );
    let d = tmp("scenario_file");
    let p = d.join("s.toml");
    std::fs::write(&p, "[friction]\nmu = 0").unwrap();
    let out = run(&["solve", "--scenario", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("friction.mu"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn guess_then_check_then_render() {
    let d = tmp("guess");
    let out = run(&["guess", "--out", d.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let g = d.join("guess.json");
    assert_eq!(run(&["check", g.to_str().unwrap()]).status.code(), Some(0));
    let svg = std::fs::read_to_string(d.join("plan.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("Top view") && svg.contains("Side view"));

    // render into another directory; with iteration records beside the file it also
    // draws convergence.svg.
    let records = serde_json::json!([
        { "iter": 0, "objective": 3e5, "inf_pr": 1.0, "compl": 0.1 },
        { "iter": 1, "objective": 2e5, "inf_pr": 1e-9, "compl": 1e-10 }
    ]);
    write(&d, "convergence.json", &records);
    let r = d.join("redrawn");
    let out = run(&["render", g.to_str().unwrap(), "--out", r.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(r.join("plan.svg").exists() && r.join("convergence.svg").exists());

    // The standing guess misses the goal.
    let s = d.join("standing");
    run(&["guess", "--kind", "standing", "--out", s.to_str().unwrap()]);
    let out = run(&["check", s.join("guess.json").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stdout).contains("goal"));
}

/// `--opt KEY=VALUE` sets an option of the chosen back end by its serde name.
#[test]
fn solve_opt_sets_backend_options() {
    let d = tmp("opt");
    let out_dir = d.join("out");
    let solve = |opts: &[&str]| {
        let mut args = vec![
            "solve",
            "--gait",
            "crawl",
            "--set",
            "n_step=9",
            "--set",
            "goal.B=[0.5, 0.5, 0.5]",
            "--set",
            "goal.F=[2.5, 0.5, 0.5]",
            "--out",
            out_dir.to_str().unwrap(),
        ];
        args.extend_from_slice(opts);
        run(&args)
    };
    // Valid: print_level=0 silences the iteration table; tol is a float, max_iter an
    // integer; the plan is still solved.
    let out = solve(&[
        "--opt",
        "print_level=0",
        "--opt",
        "tol=1e-9",
        "--opt",
        "max_iter=500",
    ]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}{}", text(&out.stderr));
    assert!(stdout.contains("status:     solved"), "{stdout}");
    assert!(!stdout.contains("objective    inf_pr"), "{stdout}");
    // The option really reaches the solver: one iteration is not enough.
    let out = solve(&["--opt", "max_iter=1", "--opt", "print_level=0"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stdout));
    assert!(
        text(&out.stderr).contains("solver_failed")
            && text(&out.stderr).contains("MaximumIterationsExceeded"),
        "{}",
        text(&out.stderr)
    );
    // Enum options by their serde (kebab-case) value; SQP options with --solver sqp.
    let out = solve(&["--opt", "mu_strategy=adaptive", "--opt", "print_level=0"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let out = solve(&[
        "--solver",
        "sqp",
        "--opt",
        "second_order_correction=false",
        "--opt",
        "print_level=0",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));

    // Unknown key: exit 2, the key named, the nearest and all valid keys listed.
    let out = solve(&["--opt", "toll=1e-9"]);
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(
        err.contains("toll")
            && err.contains("did you mean 'tol'?")
            && err.contains("valid options")
            && err.contains("max_iter"),
        "{err}"
    );
    // An IPM-only option with the SQP back end is unknown there.
    let out = solve(&["--solver", "sqp", "--opt", "mu_strategy=adaptive"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("mu_strategy"));

    // Bad values: exit 2 naming the key.
    for (opt, key) in [
        ("max_iter=many", "max_iter"),
        ("max_iter=1.5", "max_iter"),
        ("print_level=300", "print_level"),
        ("tol=-1", "tol"),
        ("mu_strategy=fast", "mu_strategy"),
        ("tol", "tol"),
    ] {
        let out = solve(&["--opt", opt]);
        assert_eq!(out.status.code(), Some(2), "{opt}");
        let err = text(&out.stderr);
        assert!(err.contains(key), "{opt}: {err}");
    }
    let out = solve(&["--solver", "sqp", "--opt", "individual_penalties=maybe"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("individual_penalties"));
}

#[test]
fn sweep_takes_solver_options() {
    let d = tmp("sweep_opt");
    let grid = write(
        &d,
        "grid.json",
        &serde_json::json!({ "base": { "n_step": 9, "gait": "crawl",
            "goal": { "B": [0.5, 0.5, 0.5], "F": [2.5, 0.5, 0.5] } }, "axes": {} }),
    );
    let out_dir = d.join("out");
    let sweep = |opts: &[&str]| {
        let mut args = vec![
            "sweep",
            "--grid",
            &grid,
            "--out",
            out_dir.to_str().unwrap(),
            "--threads",
            "1",
        ];
        args.extend_from_slice(opts);
        run(&args)
    };
    let out = sweep(&["--opt", "max_iter=1"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stdout));
    assert!(
        text(&out.stdout).contains("solver_failed")
            && text(&out.stdout).contains("MaximumIterationsExceeded"),
        "{}",
        text(&out.stdout)
    );
    let out = sweep(&["--solver", "sqp", "--opt", "max_iter=200"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        text(&out.stdout),
        text(&out.stderr)
    );
    let out = sweep(&["--opt", "bogus=1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("bogus"));
}

/// A plan written by another implementation: its scenario spells values as the
/// specification does (`F_thr`, `mu`, `gap_min`, `m1`) and its solver block has fields
/// of other types (`"iterations": "many"`), which the checker does not use.
#[test]
fn check_reads_other_tools_key_names_and_solver_blocks() {
    let dir = tmp("aliases");
    let mut v = valid_json();
    v["scenario"]["F_thr"] = 10.0.into();
    v["scenario"]["mu"] = 0.5.into();
    v["scenario"]["gap_min"] = 2.25.into();
    v["scenario"]["m1"] = 50.0.into();
    v["solver"]["iterations"] = "many".into();
    let f = write(&dir, "other.json", &v);
    let out = run(&["check", &f]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // A value given under two names is refused, naming both.
    v["scenario"]["friction"] = serde_json::json!({ "f_thr": 10.0 });
    let f = write(&dir, "twice.json", &v);
    let out = run(&["check", &f]);
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(
        err.contains("F_thr") && err.contains("friction.f_thr"),
        "{err}"
    );
}

/// `check --scenario FILE` checks a plan (here without a scenario block) against a
/// separate scenario file; the plan breaks that scenario's F_thr of 300 N (its forces
/// are 245.25 N) and passes the default's.
#[test]
fn check_against_a_separate_scenario() {
    let dir = tmp("separate");
    let mut v = valid_json();
    let scenario = v["scenario"].clone();
    v.as_object_mut().unwrap().remove("scenario");
    let plan = write(&dir, "plan.json", &v);
    let ok = write(&dir, "ok.json", &scenario);
    let out = run(&["check", &plan, "--scenario", &ok]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let mut strict = scenario;
    strict["friction"] = serde_json::json!({ "f_thr": 300.0, "mu": 0.5 });
    let strict = write(&dir, "strict.json", &strict);
    let out = run(&["check", &plan, "--scenario", &strict]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stdout).contains("(4)"), "{}", text(&out.stdout));
    // Without --scenario a plan needs its own.
    assert_eq!(run(&["check", &plan]).status.code(), Some(2));
}

/// An empty scenario file (or one of comments only) is an error, not the default.
#[test]
fn empty_scenario_file_is_an_error() {
    let dir = tmp("empty");
    for (name, text_) in [
        ("empty.toml", ""),
        ("comments.toml", "# nothing\n"),
        ("empty.json", "{}"),
    ] {
        let p = dir.join(name);
        std::fs::write(&p, text_).unwrap();
        let out = run(&[
            "solve",
            "--scenario",
            p.to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        assert!(
            text(&out.stderr).contains("sets no value"),
            "{}",
            text(&out.stderr)
        );
        assert!(!dir.join("out").exists());
    }
}

/// No stale result in `--out`: a solve proved impossible before solving writes its
/// status and certificate over an earlier result, and a solve stopped by an error
/// removes the earlier files.
#[test]
fn failed_solves_leave_no_stale_result() {
    let dir = tmp("stale");
    let out_dir = dir.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    for f in [
        "solution.json",
        "plan.svg",
        "plan.html",
        "convergence.svg",
        "convergence.json",
    ] {
        std::fs::write(out_dir.join(f), "old").unwrap();
    }
    let o = out_dir.to_str().unwrap();
    let out = run(&["solve", "--set", "friction.f_thr=246", "--out", o]);
    assert_eq!(
        out.status.code(),
        Some(StatusKind::Infeasible.exit_code().into())
    );
    let file = gap_crossing::plan::SolutionFile::read(&out_dir.join("solution.json")).unwrap();
    assert_eq!(file.solver.status, "infeasible");
    let reason = file.solver.reason.unwrap();
    assert!(
        reason.contains("F_thr = 246 N") && reason.contains("981.0000 N"),
        "{reason}"
    );
    assert_ne!(
        std::fs::read_to_string(out_dir.join("plan.svg")).unwrap(),
        "old"
    );
    // An error (invalid scenario): the earlier files are removed.
    let out = run(&["solve", "--set", "n_step=1", "--out", o]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("removed the earlier results"));
    assert_eq!(std::fs::read_dir(&out_dir).unwrap().count(), 0);
}

/// Standard output closed before anything is printed (`gap-crossing | head -1` once
/// `head` has exited): every write to it fails, yet the solve writes its files and exits
/// with its status, without a panic (it used to exit 101 with no files written); `check`
/// likewise.
#[test]
fn a_closed_standard_output_stops_nothing() {
    let d = tmp("closed_stdout");
    let out_dir = d.join("out");
    let spawn = |args: &[String]| {
        let mut child = Command::new(common::BIN)
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("binary runs");
        // The reader is gone before the first write: each write fails with EPIPE.
        drop(child.stdout.take());
        child.wait_with_output().expect("binary ends")
    };
    let out = spawn(&common::small_crawl_solve(&out_dir));
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        !text(&out.stderr).contains("panicked"),
        "{}",
        text(&out.stderr)
    );
    let sol = out_dir.join("solution.json");
    assert!(sol.exists(), "solution.json missing");
    let out = spawn(&["check".to_string(), sol.to_str().unwrap().to_string()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(out.stderr.is_empty(), "{}", text(&out.stderr));
}
