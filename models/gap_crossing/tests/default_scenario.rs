//! The default scenario through the built binary (issue 5's acceptance test): status
//! solved, the independent checker passes, both CoMs end within 0.05 m of their goals and
//! every foot ends past the widened gap.
use gap_crossing::plan::SolutionFile;
use gap_crossing::scenario::{Foot, Scenario};
use std::process::Command;

#[test]
fn default_scenario_solves_and_checks() {
    let dir = std::env::temp_dir().join(format!("gap_crossing_default_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_gap-crossing"))
        .args(["solve", "--out", dir.to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}\n{}",
        stdout,
        String::from_utf8_lossy(&out.stderr)
    );
    let path = dir.join("solution.json");
    let check = Command::new(env!("CARGO_BIN_EXE_gap-crossing"))
        .args(["check", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stdout)
    );

    let file = SolutionFile::read(&path).unwrap();
    let s = Scenario::default();
    assert_eq!(
        gap_crossing::status::StatusKind::from_word(&file.solver.status),
        gap_crossing::status::StatusKind::Solved
    );
    let last = file.stances.last().unwrap();
    // 0.05 m: the specification's goal tolerance.
    for (com, goal) in [(last.com.b, s.goal.b), (last.com.f, s.goal.f)] {
        let d = (0..3)
            .map(|k| (com[k] - goal[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(d <= 0.05, "CoM {com:?} is {d} m from its goal {goal:?}");
    }
    let (_, far_edge) = s.gap.keep_out();
    for i in Foot::ALL {
        assert!(
            last.feet.get(i)[0] >= far_edge,
            "foot {} ends at x = {}",
            i.name(),
            last.feet.get(i)[0]
        );
    }
    // The free gait is no worse than the specification's crawl-gait plan (about 1.985e5).
    assert!(
        file.solver.objective <= 1.985e5,
        "objective {}",
        file.solver.objective
    );
}
