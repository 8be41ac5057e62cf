//! Re-planning from a measured stance (issue 19 item 5): `replan::replan` and
//! `gap-crossing replan` on the default scenario's plan, solved once per test process.
mod common;

use gap_crossing::check;
use gap_crossing::plan::SolutionFile;
use gap_crossing::replan::{replan, schedule_of, Perturbation, ReplanError};
use gap_crossing::scenario::{Biped, Foot, Scenario};
use gap_crossing::solve::{self, Settings};
use gap_crossing::status::{PlanStatus, StatusKind};
use std::sync::OnceLock;

/// Quiet default settings.
fn settings() -> Settings {
    let mut s = Settings::default();
    s.set_print_level(0);
    s
}

/// The default scenario's plan (solved and checked once).
fn default_plan() -> &'static SolutionFile {
    static PLAN: OnceLock<SolutionFile> = OnceLock::new();
    PLAN.get_or_init(|| {
        let out = solve::plan(&Scenario::default(), &settings()).unwrap();
        assert!(out.status.is_solved(), "{}", out.status);
        out.file
    })
}

/// The default plan written to a fresh directory, for the binary.
fn default_plan_file(name: &str) -> std::path::PathBuf {
    let dir = common::fresh_dir("replan", name);
    let path = dir.join("solution.json");
    default_plan().write(&path).unwrap();
    path
}

/// A 2 cm CoM offset at stance 20: solved, accepted by the independent checker, stances
/// 1–19 bit-identical to the old plan, stance 20's CoMs exactly the measured ones; the
/// same input gives the same file; without its `replanned` block the checker rejects
/// the file at stance 20's legs (the measured CoM is off its legs' spheres), so the
/// re-plan did start from the perturbed state.
#[test]
fn com_offset_is_replanned_and_checked() {
    let old = default_plan();
    let p = Perturbation {
        com_offset: [0.02, 0.0, 0.0],
        feet: vec![],
    };
    let out = replan(old, 20, &p, &settings()).unwrap();
    assert!(out.status.is_solved(), "{}", out.status);
    let file = &out.file;
    let report = check::check(file);
    assert!(report.ok(), "{report}");
    assert_eq!(file.stances.len(), old.stances.len());
    assert_eq!(file.stances[..19], old.stances[..19]);
    for j in Biped::ALL {
        let (a, b) = (old.stances[19].com.get(j), file.stances[19].com.get(j));
        assert_eq!(b, [a[0] + 0.02, a[1], a[2]]);
    }
    assert_eq!(file.stances[19].feet, old.stances[19].feet);
    assert_eq!(file.replanned.as_ref().unwrap().stance, 20);
    // Deterministic, and the file reads back to the same plan.
    let again = replan(old, 20, &p, &settings()).unwrap();
    assert_eq!(again.file.stances, file.stances);
    let back = SolutionFile::from_json(&file.to_json(), std::path::Path::new("x")).unwrap();
    assert_eq!(back.stances, file.stances);
    assert!(check::check(&back).ok());
    let mut unmarked = file.clone();
    unmarked.replanned = None;
    let r = check::check(&unmarked);
    assert!(
        r.violations
            .iter()
            .any(|v| v.equation == "(11)" && v.stance == 20),
        "{r}"
    );
}

/// The foot that lands at stance 20 lands 2 cm off (in y): solved and checked, earlier
/// stances kept, the foot at the measured spot from stance 20 until its next move.
#[test]
fn foot_landing_off_is_replanned_and_checked() {
    let old = default_plan();
    let schedule = schedule_of(&old.stances);
    let lands = schedule[18]; // transition from stance 19 to 20
    let planned = old.stances[19].feet.get(lands);
    let measured = [planned[0], planned[1] + 0.02, planned[2]];
    let p = Perturbation {
        com_offset: [0.0; 3],
        feet: vec![(lands, measured)],
    };
    let out = replan(old, 20, &p, &settings()).unwrap();
    assert!(out.status.is_solved(), "{}", out.status);
    let report = check::check(&out.file);
    assert!(report.ok(), "{report}");
    assert_eq!(out.file.stances[..19], old.stances[..19]);
    assert_eq!(out.file.stances[19].feet.get(lands), measured);
    let next = schedule[19..].iter().position(|&f| f == lands).unwrap() + 20;
    for k in 19..next {
        assert_eq!(
            out.file.stances[k].feet.get(lands),
            measured,
            "stance {}",
            k + 1
        );
    }
}

/// Without a perturbation the re-plan is the old plan again: the old plan is a KKT point
/// of the re-plan's problem (its suffix, on the same schedule), so the warm solve stays
/// there up to the solver's tolerance (tol 1e-8 on the scaled KKT residual): positions
/// within 1e-5 m and forces within 1e-3 N (of ~245 N) of the old plan, the objective
/// within 1e-9 relative.
#[test]
fn unperturbed_replan_returns_the_same_plan() {
    let old = default_plan();
    let out = replan(old, 20, &Perturbation::default(), &settings()).unwrap();
    assert!(out.status.is_solved(), "{}", out.status);
    assert!(check::check(&out.file).ok());
    assert_eq!(out.file.stances[..19], old.stances[..19]);
    assert_eq!(out.file.stances[19].com, old.stances[19].com);
    assert_eq!(out.file.stances[19].feet, old.stances[19].feet);
    let (mut pos, mut force) = (0.0f64, 0.0f64);
    for (a, b) in old.stances.iter().zip(&out.file.stances) {
        for j in Biped::ALL {
            for d in 0..3 {
                pos = pos.max((a.com.get(j)[d] - b.com.get(j)[d]).abs());
            }
        }
        for i in Foot::ALL {
            for d in 0..3 {
                pos = pos.max((a.feet.get(i)[d] - b.feet.get(i)[d]).abs());
                force = force.max((a.forces.get(i)[d] - b.forces.get(i)[d]).abs());
            }
        }
    }
    assert!(pos <= 1e-5, "positions moved by {pos} m");
    assert!(force <= 1e-3, "forces moved by {force} N");
    let (f0, f1) = (old.solver.objective, out.file.solver.objective);
    assert!((f0 - f1).abs() <= 1e-9 * f0, "{f0} vs {f1}");
}

/// Front-right foot measured 1 m behind its planned spot at stance 59: with one
/// transition left it needs two moves of at most 0.3 m to bring the front CoM to its
/// goal, so the re-plan is `goal_not_reached` by the stance-count certificate, decided
/// before any solve, and the reason names the stance.
#[test]
fn unreachable_goal_after_perturbation_is_reported() {
    let old = default_plan();
    let p = Perturbation {
        com_offset: [0.0; 3],
        feet: vec![(Foot::FR, [4.1, 0.02, 0.0])],
    };
    let out = replan(old, 59, &p, &settings()).unwrap();
    assert!(
        matches!(out.status, PlanStatus::GoalNotReached(_)),
        "{}",
        out.status
    );
    assert!(out.phases.is_empty());
    assert_eq!(
        StatusKind::from_word(&out.file.solver.status),
        StatusKind::GoalNotReached
    );
    let reason = out.file.solver.reason.as_deref().unwrap();
    assert!(reason.contains("from stance 59"), "{reason}");
    assert_eq!(out.file.stances[..58], old.stances[..58]);
}

/// Bad input is an error naming what is wrong, never a panic.
#[test]
fn bad_input_is_refused() {
    let old = default_plan();
    let none = Perturbation::default();
    for k in [0, 1, 60, 61] {
        let e = replan(old, k, &none, &settings()).unwrap_err();
        assert!(matches!(e, ReplanError::Stance { .. }), "{e}");
    }
    // On the gap's floor: on the terrain, but in the keep-out.
    let floor = gap_crossing::terrain::of(&old.scenario).height_at(2.3, 0.0);
    let in_gap = Perturbation {
        com_offset: [0.0; 3],
        feet: vec![(Foot::FR, [2.3, 0.0, floor])],
    };
    let e = replan(old, 20, &in_gap, &settings())
        .unwrap_err()
        .to_string();
    assert!(e.contains("FR") && e.contains("keep-out"), "{e}");
    let floating = Perturbation {
        com_offset: [0.0; 3],
        feet: vec![(Foot::FR, [3.0, 0.0, 0.1])],
    };
    let e = replan(old, 20, &floating, &settings())
        .unwrap_err()
        .to_string();
    assert!(e.contains("terrain's height"), "{e}");
    let nan = Perturbation {
        com_offset: [f64::NAN, 0.0, 0.0],
        feet: vec![],
    };
    assert!(matches!(
        replan(old, 20, &nan, &settings()).unwrap_err(),
        ReplanError::NotFinite(_)
    ));
}

/// The command: a perturbed re-plan exits 0 and its file passes `check`; the
/// unreachable one exits 4 (goal not reached) and writes its file with that status; bad
/// arguments exit 2 with the reason on stderr.
#[test]
fn replan_command_exit_codes() {
    let plan = default_plan_file("cli");
    let dir = plan.parent().unwrap();
    let out = dir.join("perturbed");
    let o = common::run(&[
        "replan",
        "--plan",
        plan.to_str().unwrap(),
        "--stance",
        "20",
        "--com-offset",
        "0.02,0,-0.01",
        "--out",
        out.to_str().unwrap(),
        "--opt",
        "print_level=0",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let solution = out.join("solution.json");
    let c = common::run(&["check", solution.to_str().unwrap()]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stdout));

    let far = dir.join("far");
    let o = common::run(&[
        "replan",
        "--plan",
        plan.to_str().unwrap(),
        "--stance",
        "59",
        "--foot",
        "FR=4.1,0.02,0",
        "--out",
        far.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(4),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let f = SolutionFile::read(&far.join("solution.json")).unwrap();
    assert_eq!(f.solver.status, "goal_not_reached");

    for (args, needle) in [
        (vec!["--stance", "1"], "--stance 1"),
        (
            vec!["--stance", "20", "--com-offset", "0.02,0"],
            "3 numbers",
        ),
        (vec!["--stance", "20", "--foot", "XX=1,2,3"], "unknown foot"),
        (vec!["--stance", "20", "--foot", "FR"], "FOOT=X,Y,Z"),
    ] {
        let mut all = vec!["replan", "--plan", plan.to_str().unwrap()];
        all.extend(args);
        let o = common::run(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {err}");
        assert!(err.contains(needle), "{all:?}: {err}");
    }
}

/// `improve`: the schedule search from the re-plan keeps the best plan, so the result is
/// checked, keeps stances 1–9, and costs no more than the plain re-plan.
#[test]
fn improved_replan_is_no_worse() {
    let old = default_plan();
    let p = Perturbation {
        com_offset: [0.03, 0.02, 0.0],
        feet: vec![],
    };
    let plain = replan(old, 10, &p, &settings()).unwrap();
    let better = gap_crossing::replan::replan_with(old, 10, &p, &settings(), true).unwrap();
    assert!(better.status.is_solved(), "{}", better.status);
    assert!(check::check(&better.file).ok());
    assert_eq!(better.file.stances[..9], old.stances[..9]);
    assert!(better.file.solver.objective <= plain.file.solver.objective);
}
