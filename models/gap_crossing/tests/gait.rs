//! Initial guesses: the crawl heuristic of the spec on the default scenario.

use gap_crossing::check;
use gap_crossing::gait;
use gap_crossing::plan::{Plan, SolutionFile, SolverInfo};
use gap_crossing::scenario::{dist2, Biped, Foot, Scenario};

fn as_file(s: &Scenario, plan: Plan) -> SolutionFile {
    SolutionFile::new(
        s.clone(),
        SolverInfo {
            name: "guess".into(),
            status: "initial_guess".into(),
            iterations: 0,
            objective: plan.cost(s),
            objective_without_10: None,
            max_constraint_violation: 0.0,
            solve_seconds: 0.0,
            reason: None,
        },
        plan,
    )
}

#[test]
fn crawl_reaches_the_goals_within_60_stances() {
    let s = Scenario::default();
    let feet = gait::crawl_footholds(&s);
    assert_eq!(feet.len(), 60);
    let plan = Plan::from_flat(&s, &gait::crawl(&s)).unwrap();
    let last = plan.stances.last().unwrap();
    for j in Biped::ALL {
        // The spec's goal tolerance, 0.05 m.
        assert!(
            dist2(last.com.get(j), s.goal.get(j)).sqrt() <= 0.05,
            "{j}: {:?}",
            last.com.get(j)
        );
    }
    let needed = gait::crawl_stances_to_goal(&s, 0.05, 200).unwrap();
    assert!(needed <= 60, "{needed}");
    // All feet end past the gap.
    for p in last.feet.to_array() {
        assert!(p[0] > s.gap.max + s.gap.margin);
    }
}

#[test]
fn crawl_footholds_avoid_the_gap_and_respect_the_step_radius() {
    let s = Scenario::default();
    let feet = gait::crawl_footholds(&s);
    let schedule = gait::crawl_schedule(s.n_step);
    for (k, w) in feet.windows(2).enumerate() {
        for i in Foot::ALL {
            let (a, b) = (w[0].get(i), w[1].get(i));
            assert!(
                !s.gap.in_keep_out(b[0]),
                "stance {}: {i} at x = {}",
                k + 2,
                b[0]
            );
            // (5) with no tolerance needed: moves are ≤ 0.28 m (or a 0.27 m jump).
            assert!(
                dist2(a, b) <= 0.09,
                "stance {}: {i} steps {}",
                k + 1,
                dist2(a, b).sqrt()
            );
            if i != schedule[k] {
                assert_eq!(a, b, "only the scheduled foot moves");
            } else if a != b {
                // A landing is on the numeric terrain: z = h(x) exactly (the start's z
                // is the scenario's, h(x) to within 1e-6).
                assert_eq!(b[2], s.gap.height(b[0]));
            }
        }
    }
}

#[test]
fn crawl_guess_passes_the_checker_on_the_default_scenario() {
    // Not required of a guess, but the heuristic's CoMs (legs exact) and minimum-norm
    // balancing forces happen to satisfy every requirement: the default is feasible.
    let s = Scenario::default();
    let f = as_file(&s, gait::crawl_plan(&s));
    let r = check::check(&f);
    assert!(r.ok(), "{r}");
    assert!(r.goal_checked);
    // Same plan in crawl mode: only scheduled feet move.
    let mut c = f.clone();
    c.scenario.gait = gap_crossing::scenario::Gait::Crawl;
    assert!(check::check(&c).ok());
}

#[test]
fn standing_guess_is_valid_except_the_goal() {
    let s = Scenario::default();
    let plan = Plan::from_flat(&s, &gait::standing(&s)).unwrap();
    let r = check::check(&as_file(&s, plan));
    assert_eq!(r.equations(), vec!["goal"], "{r}");
}

#[test]
fn crawl_handles_a_gap_too_wide_to_jump_and_backward_goals() {
    // A 0.3 m gap (0.36 m widened): the heuristic stops before it and never lands in it.
    let mut s = Scenario::default();
    s.gap.min = 2.6;
    s.gap.max = 2.9;
    for f in gait::crawl_footholds(&s) {
        for p in f.to_array() {
            assert!(!s.gap.in_keep_out(p[0]));
        }
    }
    // Walking backwards (goal behind, gap behind).
    let mut s = Scenario::default();
    s.gap.min = -1.2;
    s.gap.max = -1.1;
    s.goal.b[0] = -3.0;
    s.goal.f[0] = -1.0;
    let feet = gait::crawl_footholds(&s);
    for w in feet.windows(2) {
        for i in Foot::ALL {
            assert!(!s.gap.in_keep_out(w[1].get(i)[0]));
            assert!(dist2(w[0].get(i), w[1].get(i)) <= 0.09);
        }
    }
    assert!((feet.last().unwrap().br[0] + 3.0).abs() < 1e-9);
}

/// Stepping stones approached at 45° (`scenarios/stones-45.toml`): the straight moves
/// toward the goals converge on the start pad's corner; the guess still satisfies every
/// equation the landing rule controls — (5)–(9), the keep-out — at every stance (the
/// feet used to pile into the corner, breaking (8) and (9) at 83 stances).
#[test]
fn guess_keeps_feet_apart_on_a_diagonal_approach() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let s = Scenario::load(&dir.join("stones-45.toml")).unwrap();
    let f = as_file(&s, gait::crawl_plan(&s));
    let report = gap_crossing::check::check_with(
        &f,
        &gap_crossing::check::Options {
            goal: gap_crossing::check::GoalCheck::Skip,
            ..Default::default()
        },
    );
    let bad: Vec<_> = report
        .violations
        .iter()
        .filter(|v| ["(5)", "(6)", "(7)", "(8)", "(9)", "gap"].contains(&v.equation.as_str()))
        .collect();
    assert!(bad.is_empty(), "{report}");
}
