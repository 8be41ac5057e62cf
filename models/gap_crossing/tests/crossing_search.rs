//! The crossing search's candidates (`crossing::earlier_crossings`): a foot that walks
//! up to the near edge of a keep-out and jumps at its next move gets the candidate that
//! crosses one move earlier, also when that is only in reach with its approach
//! stretched; candidates that no plan could realise (the far region more than the
//! remaining moves' reach from the start) are not built.
use gap_crossing::crossing::{self, CANDIDATE_REACH};
use gap_crossing::gait;
use gap_crossing::plan::Plan;
use gap_crossing::scenario::{dist2, Biped, Foot, Scenario};
use gap_crossing::solve::{self, Settings};
use gap_crossing::terrain;

/// The footholds of foot `i` in `plan` of `schedule`: the start, then one per move.
fn holds(plan: &Plan, schedule: &[Foot], i: Foot) -> Vec<[f64; 3]> {
    std::iter::once(plan.stances[0].feet.get(i))
        .chain(
            (0..schedule.len())
                .filter(|&t| schedule[t] == i)
                .map(|t| plan.stances[t + 1].feet.get(i)),
        )
        .collect()
}

/// Index of the first foothold beyond the keep-out.
fn crossing(s: &Scenario, h: &[[f64; 3]]) -> usize {
    let (_, hi) = s.gap.keep_out();
    h.iter().position(|p| p[0] >= hi).expect("the foot crosses")
}

/// The biped-pair guess on the default gap: each back foot walks 0.28 m steps to
/// x = 1.96, steps to the near edge (2.219) and jumps (2.499) one move later, 0.54 m
/// from its foothold two moves before: beyond `CANDIDATE_REACH` × reach, a candidate
/// only because its approach could be stretched (7 steps of 0.28 + 0.034 m). Its
/// candidate crosses one move earlier at the same crossing foothold, keeps the approach
/// (the solver moves it) and every foothold out of the keep-out, and changes nothing
/// of the other feet.
#[test]
fn back_feet_get_earlier_crossings_beyond_a_plain_shift() {
    let s = Scenario::default();
    let t = terrain::of(&s);
    let schedule = gait::pair_schedule(s.n_step);
    let plan = gait::plan_for_footholds(&s, &gait::footholds_for_schedule(&s, &schedule));
    let reach = s.step_radius_sq.sqrt();
    let cands = crossing::earlier_crossings(&s, &*t, &plan, &schedule);
    for i in [Foot::BR, Foot::BL] {
        let old = holds(&plan, &schedule, i);
        let m = crossing(&s, &old);
        let jump = dist2(old[m], old[m - 2]).sqrt();
        assert!(jump > CANDIDATE_REACH * reach, "{i}: jump {jump}");
        let c = cands
            .iter()
            .find(|c| c.foot == i)
            .unwrap_or_else(|| panic!("no candidate for {i}"));
        let new = holds(&c.plan, &schedule, i);
        assert_eq!(crossing(&s, &new), m - 1, "{i} crosses one move earlier");
        assert_eq!(new[m - 1], old[m], "{i}: the same crossing foothold");
        assert_eq!(new[..m - 1], old[..m - 1], "{i}: the approach is kept");
        assert!(new.iter().all(|p| !s.gap.in_keep_out(p[0])), "{i}: {new:?}");
        for (a, b) in plan.stances.iter().zip(&c.plan.stances) {
            for j in Foot::ALL.into_iter().filter(|&j| j != i) {
                assert_eq!(a.feet.get(j), b.feet.get(j));
            }
        }
    }
    // The front feet start 0.22 m before the keep-out (2.22–2.38): one move cannot
    // cross it, so no candidate makes them cross at their first move.
    assert!(cands.iter().all(|c| c.foot.biped() != Biped::F));
}

/// A keep-out 2.17–2.43 m (gap 2.2–2.4): a back foot would have to reach x ≥ 2.43 in
/// 8 moves of at most 0.3 m from x = 0 to cross one move earlier than the guess: no
/// plan can, and no candidate is built.
#[test]
fn impossible_earlier_crossings_are_not_built() {
    let mut s = Scenario::default();
    s.apply_overrides(&["gap.min=2.2", "gap.max=2.4"]).unwrap();
    let t = terrain::of(&s);
    let schedule = gait::pair_schedule(s.n_step);
    let plan = gait::plan_for_footholds(&s, &gait::footholds_for_schedule(&s, &schedule));
    let back = holds(&plan, &schedule, Foot::BR);
    assert_eq!(crossing(&s, &back), 9, "the guess crosses at the 9th move");
    let cands = crossing::earlier_crossings(&s, &*t, &plan, &schedule);
    assert!(
        cands.iter().all(|c| c.foot.biped() != Biped::B),
        "{:?}",
        cands.iter().map(|c| c.foot).collect::<Vec<_>>()
    );
}

/// End to end on the default scenario: the stretched earlier crossing of the back feet
/// is solved and kept (its phase is the lowest of the crossing search's), and the free
/// gait ends below the 1.706830e5 it reached without it.
#[test]
fn default_free_gait_uses_the_earlier_back_crossing() {
    let s = Scenario::default();
    let out = solve::plan(&s, &Settings::default()).unwrap();
    let pair = out
        .phases
        .iter()
        .find(|p| p.name == "free gait: biped-pair schedule")
        .unwrap();
    let pair_cost = pair.records.last().unwrap().objective;
    let crossed = out
        .phases
        .iter()
        .filter(|p| p.name.starts_with("crossing search") && p.status.is_success())
        .map(|p| p.records.last().unwrap().objective)
        .fold(f64::INFINITY, f64::min);
    assert!(crossed < pair_cost, "{crossed:.6e} vs pair {pair_cost:.6e}");
    let f = out.file.solver.objective;
    assert!(f < 1.70683e5, "free gait {f:.6e}");
}

/// The walking horizon ends `TAIL_MARGIN` stances after the last move longer than
/// `NULL_MOVE` (a 0.5 mm move does not count), and never beyond the plan.
#[test]
fn walking_horizon_counts_from_the_last_real_move() {
    use gap_crossing::crossing_search::{walking_horizon, TAIL_MARGIN};
    let s = Scenario::default();
    let mut plan = gait::plan_for_footholds(&s, &vec![s.start.feet; 40]);
    for k in 5..40 {
        plan.stances[k].feet.get_mut(Foot::BR)[0] += 0.1;
    }
    for k in 12..40 {
        plan.stances[k].feet.get_mut(Foot::FL)[1] += 5e-4;
    }
    assert_eq!(walking_horizon(&plan), 5 + 1 + TAIL_MARGIN);
    plan.stances[39].feet.get_mut(Foot::BL)[0] += 0.01;
    assert_eq!(walking_horizon(&plan), 40);
}

/// A plan extended by repeating its last stance: the first stances unchanged, every
/// later stance equal to the last, and its cost (1) the short plan's plus one last
/// stance's cost per added stance (computed here stance by stance).
#[test]
fn extended_plan_repeats_its_last_stance() {
    use gap_crossing::crossing_search::extend;
    use gap_crossing::schedule_search::stance_cost;
    let short = Scenario {
        n_step: 20,
        ..Scenario::default()
    };
    let long = Scenario {
        n_step: 35,
        ..Scenario::default()
    };
    let plan = gait::crawl_plan(&short);
    let ext = extend(&plan, long.n_step);
    assert_eq!(ext.to_flat().len(), long.n_step * 30);
    assert_eq!(ext.stances[..20], plan.stances[..]);
    assert!(ext.stances[20..].iter().all(|st| *st == plan.stances[19]));
    let expected = plan.cost(&short) + 15.0 * stance_cost(&long, &plan.stances[19]);
    let got = ext.cost(&long);
    // Sums of the same terms in another order: rounding only.
    assert!(
        (got - expected).abs() <= 1e-9 * expected,
        "{got} vs {expected}"
    );
}

/// A long horizon (n_step 200; the default plan walks about 45 stances): the crossing
/// candidates are solved on the walking horizon, extended, and the plan built on them
/// is solved, passes the checker, and is cheaper than the biped-pair plan it started
/// from.
#[test]
fn long_horizon_candidates_are_solved_on_the_walking_horizon() {
    let s = Scenario {
        n_step: 200,
        ..Scenario::default()
    };
    let out = solve::plan(&s, &Settings::default()).unwrap();
    assert!(out.status.is_solved(), "{}", out.status);
    let report = gap_crossing::check::check(&out.file);
    assert!(report.ok(), "{report}");
    let crossing: Vec<&str> = out
        .phases
        .iter()
        .filter(|p| p.name.starts_with("crossing search"))
        .map(|p| p.name.as_str())
        .collect();
    assert!(!crossing.is_empty());
    for name in &crossing {
        let n: usize = name
            .rsplit_once("(on ")
            .and_then(|(_, r)| r.strip_suffix(" stances)"))
            .unwrap_or_else(|| panic!("{name}: not on a shorter horizon"))
            .parse()
            .unwrap();
        assert!(n < 100, "{name}");
    }
    let pair = out
        .phases
        .iter()
        .find(|p| p.name == "free gait: biped-pair schedule")
        .unwrap();
    let f = out.file.solver.objective;
    assert!(f < pair.records.last().unwrap().objective);
}
