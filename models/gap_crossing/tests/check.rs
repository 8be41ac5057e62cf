//! The independent checker: a valid plan passes; each deliberate corruption is caught
//! with the right equation label (and, where the corruption can be made surgical, with
//! no other label).

use gap_crossing::check::{self, GoalCheck, Options};
use gap_crossing::gait;
use gap_crossing::plan::{SolutionFile, SolverInfo, Stance};
use gap_crossing::scenario::{Feet, Foot, Gait, Scenario};

fn info() -> SolverInfo {
    SolverInfo {
        name: "test".into(),
        status: "solved".into(),
        iterations: 0,
        objective: 0.0,
        objective_without_10: None,
        max_constraint_violation: 0.0,
        solve_seconds: 0.0,
        reason: None,
    }
}

/// Two stances standing still at the default start with equal vertical forces
/// (m1 + m2)·9.81/4, goal = start: satisfies every requirement.
fn tiny() -> SolutionFile {
    let mut s = Scenario {
        n_step: 2,
        ..Scenario::default()
    };
    s.goal = s.start.com;
    let share = s.masses.total() * s.gravity / 4.0;
    let st = Stance {
        com: s.start.com,
        feet: s.start.feet,
        forces: Feet::from_array([[0.0, 0.0, share]; 4]),
    };
    SolutionFile {
        scenario: s,
        solver: info(),
        stances: vec![st; 2],
        replanned: None,
    }
}

/// Replaces stance 2's feet, re-deriving its CoMs (legs exact) and forces (balanced),
/// so that only what the feet themselves break is violated.
fn set_feet(f: &mut SolutionFile, feet: Feet) {
    let s = &f.scenario;
    let com = gait::coms_for(s, &feet);
    f.stances[1] = Stance {
        com,
        feet,
        forces: gait::balance_forces(s, &com, &feet),
    };
}

/// Checks without the goal requirement: the corruptions below move feet of the tiny plan,
/// which moves its CoMs away from the goal (= start); that is not what they test.
fn run(f: &SolutionFile) -> check::Report {
    check::check_with(
        f,
        &Options {
            goal: GoalCheck::Skip,
            ..Options::default()
        },
    )
}

fn labels(f: &SolutionFile) -> Vec<String> {
    run(f).equations()
}

#[track_caller]
fn assert_only(f: &SolutionFile, label: &str) {
    let r = run(f);
    assert_eq!(r.equations(), vec![label.to_string()], "report:\n{r}");
}

#[test]
fn valid_tiny_plan_passes() {
    let f = tiny();
    let r = check::check(&f);
    assert!(r.ok(), "{r}");
    assert!(r.summary().starts_with("OK:"), "{}", r.summary());
    assert_eq!(r.moves, 0);
}

#[test]
fn rebuilt_stance_without_change_still_passes() {
    // Guards the helper: re-deriving CoMs and forces of an unchanged stance is valid.
    let mut f = tiny();
    let feet = f.stances[1].feet;
    set_feet(&mut f, feet);
    assert!(run(&f).ok(), "{}", run(&f));
}

#[test]
fn foot_in_the_widened_gap() {
    // Gap moved to (0.10, 0.20), flat (depth 0) so that only the keep-out is at stake;
    // BR steps 0.1 m forward into (0.07, 0.23).
    let mut f = tiny();
    f.scenario.gap.min = 0.10;
    f.scenario.gap.max = 0.20;
    f.scenario.gap.depth = 0.0;
    let mut feet = f.stances[1].feet;
    feet.br[0] = 0.1;
    set_feet(&mut f, feet);
    assert_only(&f, "gap");
    let v = &run(&f).violations[0];
    assert_eq!((v.stance, v.foot.as_deref()), (2, Some("BR")));
    // 0.1 is 0.03 inside the near edge 0.07.
    assert!((v.amount - 0.03).abs() < 1e-12, "{v}");
}

#[test]
fn foot_in_the_real_gap_is_caught_too() {
    // On the default terrain a foot at the bottom of the gap: on the terrain (z = h),
    // but in the keep-out.
    let mut f = tiny();
    let mut feet = f.stances[1].feet;
    feet.fr = [2.3, 0.0, f.scenario.gap.height(2.3)];
    set_feet(&mut f, feet);
    let l = labels(&f);
    assert!(l.contains(&"gap".to_string()), "{l:?}");
    assert!(!l.contains(&"(3)".to_string()), "{l:?}");
}

#[test]
fn two_feet_moving_in_one_step() {
    let mut f = tiny();
    let mut feet = f.stances[1].feet;
    feet.br[0] += 0.1;
    feet.fr[0] += 0.1;
    set_feet(&mut f, feet);
    assert_only(&f, "(10)");
    let r = run(&f);
    assert_eq!(r.violations[0].foot.as_deref(), Some("BR+FR"));
}

#[test]
fn a_move_of_one_micrometre_is_not_a_move() {
    // (10) counts a foot as moved above 1e-6 m; 5e-7 m beside a real move is allowed.
    let mut f = tiny();
    let mut feet = f.stances[1].feet;
    feet.br[0] += 0.1;
    feet.fr[1] += 5e-7;
    set_feet(&mut f, feet);
    let r = run(&f);
    assert!(r.ok(), "{r}");
    assert_eq!(r.moves, 1);
}

#[test]
fn leg_length_off_by_1e_4() {
    let mut f = tiny();
    // ‖r_B − r_BR‖² = 0.25 (horizontal) + z²; z² = 0.2501 makes it 0.5001 for BR and BL.
    f.stances[1].com.b[2] = 0.2501f64.sqrt();
    assert_only(&f, "(11)");
    let r = run(&f);
    assert_eq!(r.violations.len(), 2, "{r}");
    for v in &r.violations {
        // 1e-4 up to rounding of the square root.
        assert!((v.amount - 1e-4).abs() < 1e-12, "{v}");
    }
}

#[test]
fn force_outside_its_cone() {
    let mut f = tiny();
    // Squeeze BR and BL toward each other along their joining line: no net force or
    // moment, but 150 N tangential > μ·245.25 N.
    f.stances[1].forces.br[1] += 150.0;
    f.stances[1].forces.bl[1] -= 150.0;
    assert_only(&f, "(4)");
    let feet: Vec<_> = run(&f)
        .violations
        .iter()
        .map(|v| v.foot.clone().unwrap())
        .collect();
    assert_eq!(feet, vec!["BR", "BL"]);
}

#[test]
fn normal_force_below_threshold() {
    let mut f = tiny();
    // The statically indeterminate "twist" of four vertical loads: +t on BR and FL,
    // −t on BL and FR keeps force and moments balanced; t = 240.25 N leaves 5 N < F_thr
    // on BL and FR.
    let t = 240.25;
    f.stances[1].forces.br[2] += t;
    f.stances[1].forces.fl[2] += t;
    f.stances[1].forces.bl[2] -= t;
    f.stances[1].forces.fr[2] -= t;
    assert_only(&f, "(4)");
    let r = run(&f);
    let feet: Vec<_> = r
        .violations
        .iter()
        .map(|v| v.foot.clone().unwrap())
        .collect();
    assert_eq!(feet, vec!["BL", "FR"], "{r}");
    assert!((r.violations[0].amount - 5.0).abs() < 1e-9, "{r}");
}

#[test]
fn unbalanced_moments() {
    let mut f = tiny();
    // Same total force, but 10 N moved from BL to BR: a 10 N·m roll moment.
    f.stances[1].forces.br[2] += 10.0;
    f.stances[1].forces.bl[2] -= 10.0;
    assert_only(&f, "(2)");
    let r = run(&f);
    assert!(r.violations[0].name.contains("moment"), "{r}");
    assert!((r.violations[0].amount - 10.0).abs() < 1e-9, "{r}");
}

#[test]
fn unbalanced_forces() {
    let mut f = tiny();
    for i in Foot::ALL {
        f.stances[1].forces.get_mut(i)[2] += 1e-3;
    }
    let r = run(&f);
    assert_eq!(r.equations(), vec!["(2)"], "{r}");
    assert!(r.violations[0].name.contains("force balance"));
}

#[test]
fn step_longer_than_0_3() {
    let mut f = tiny();
    let mut feet = f.stances[1].feet;
    feet.br[0] += 0.31;
    set_feet(&mut f, feet);
    assert_only(&f, "(5)");
    let v = &run(&f).violations[0];
    assert_eq!((v.stance, v.foot.as_deref()), (1, Some("BR")));
    assert!((v.amount - (0.31f64.powi(2) - 0.09)).abs() < 1e-12, "{v}");
}

#[test]
fn foot_off_the_terrain() {
    let mut f = tiny();
    let mut feet = f.stances[1].feet;
    feet.fl[2] = 1e-3;
    set_feet(&mut f, feet);
    let l = labels(&f);
    assert!(l.contains(&"(3)".to_string()), "{l:?}");
}

#[test]
fn feet_too_close_or_too_far() {
    let mut f = tiny();
    let mut feet = f.stances[1].feet;
    feet.bl[1] = 0.45; // BR–BL 0.45 m: squared 0.2025 < 0.25
    set_feet(&mut f, feet);
    // Moving BL by 0.55 m also breaks (5); (8) must be among the labels.
    let l = labels(&f);
    assert!(l.contains(&"(8)".to_string()), "{l:?}");
    let mut f = tiny();
    f.stances[1].feet.fr[0] = 3.2; // BR–FR 3.2 m: squared 10.24 > 9
    let l = labels(&f);
    assert!(l.contains(&"(6)".to_string()), "{l:?}");
}

#[test]
fn start_must_match() {
    let mut f = tiny();
    f.stances[0].com.f[0] += 1e-3;
    f.stances[0].feet.fr[0] += 1e-3;
    f.stances[0].feet.fl[0] += 1e-3;
    let l = labels(&f);
    assert!(l.contains(&"start".to_string()), "{l:?}");
}

#[test]
fn goal_requirement() {
    // The default goal is 3 m ahead: standing still for 60 stances misses it, and the
    // crawl heuristic proves 60 stances are enough, so Auto requires it.
    let s = Scenario::default();
    let x = gait::standing(&s);
    let plan = gap_crossing::plan::Plan::from_flat(&s, &x).unwrap();
    let f = SolutionFile::new(s, info(), plan);
    let r = check::check(&f);
    assert!(r.goal_checked);
    assert_eq!(r.equations(), vec!["goal"], "{r}");
    // With n_step 5 the goal cannot be reached: Auto skips it, Required does not.
    let mut short = f.clone();
    short.scenario.n_step = 5;
    short.stances.truncate(5);
    assert!(check::check(&short).ok());
    let r = check::check_with(
        &short,
        &Options {
            goal: GoalCheck::Required,
            ..Options::default()
        },
    );
    assert_eq!(r.equations(), vec!["goal"], "{r}");
}

#[test]
fn stance_count_must_match() {
    let mut f = tiny();
    f.stances.push(f.stances[1]);
    assert_only(&f, "n_step");
}

#[test]
fn crawl_mode_enforces_the_schedule() {
    // Transition 1 is BR's turn; moving FR there is out of turn.
    let mut f = tiny();
    f.scenario.gait = Gait::Crawl;
    let mut feet = f.stances[1].feet;
    feet.fr[0] += 0.1;
    set_feet(&mut f, feet);
    assert_only(&f, "crawl");
    let mut f = tiny();
    f.scenario.gait = Gait::Crawl;
    let mut feet = f.stances[1].feet;
    feet.br[0] += 0.1;
    set_feet(&mut f, feet);
    assert!(run(&f).ok());
}

#[test]
fn nan_is_a_violation() {
    let mut f = tiny();
    f.stances[1].forces.br[0] = f64::NAN;
    let r = run(&f);
    assert!(!r.ok());
    assert!(r.to_string().contains("NaN"), "{r}");
}

#[test]
fn report_lines_name_equation_stance_foot_amount() {
    let mut f = tiny();
    f.stances[1].com.b[2] = 0.2501f64.sqrt();
    let text = run(&f).to_string();
    let first = text.lines().next().unwrap();
    assert!(
        first.starts_with("(11) leg length")
            && first.contains("stance 2")
            && first.contains("BR")
            && first.contains("1.000e-4"),
        "{first}"
    );
}
