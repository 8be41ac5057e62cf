//! The SQP back end (`--solver sqp`) on the flagship model: the crawl gait over the gap
//! with 12 stances, through the built binary. Status solved, the independent checker
//! passes, and the objective matches the interior-point method's on the same scenario.
use gap_crossing::plan::SolutionFile;
use gap_crossing::status::StatusKind;
use std::path::Path;
use std::process::Command;

mod common;

fn solve(solver: &str, dir: &Path) -> SolutionFile {
    let _ = std::fs::remove_dir_all(dir);
    // Goals 0.5 m ahead (the front feet cross the gap): reachable in 12 stances.
    let mut args = common::small_crawl_solve(dir);
    args.extend(["--solver".to_string(), solver.to_string()]);
    let out = common::run(&args);
    assert!(
        out.status.success(),
        "{solver}: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let path = dir.join("solution.json");
    let check = Command::new(env!("CARGO_BIN_EXE_gap-crossing"))
        .args(["check", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        check.status.success(),
        "{solver}: {}",
        String::from_utf8_lossy(&check.stdout)
    );
    SolutionFile::read(&path).unwrap()
}

#[test]
fn sqp_solves_the_crawl_gait_and_matches_the_ipm() {
    let base = std::env::temp_dir().join(format!("gap_crossing_sqp_{}", std::process::id()));
    let sqp = solve("sqp", &base.join("sqp"));
    assert_eq!(sqp.solver.name, "sqp");
    assert_eq!(
        StatusKind::from_word(&sqp.solver.status),
        StatusKind::Solved
    );
    let ipm = solve("ipm", &base.join("ipm"));
    assert_eq!(
        StatusKind::from_word(&ipm.solver.status),
        StatusKind::Solved
    );
    let rel = (sqp.solver.objective - ipm.solver.objective).abs() / ipm.solver.objective;
    assert!(
        rel <= 1e-4,
        "SQP objective {} vs IPM {}",
        sqp.solver.objective,
        ipm.solver.objective
    );
    let _ = std::fs::remove_dir_all(&base);
}
