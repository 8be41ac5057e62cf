//! The convergence history: one entry per iteration of each solver run, with the (10)
//! residual of the iterate, consistent with the end-of-run figures and the checker.

use gap_crossing::check;
use gap_crossing::convergence::{Convergence, ResidualProbe};
use gap_crossing::gait;
use gap_crossing::model::{self, Formulation};
use gap_crossing::plan::{foot_offset, Plan, SolutionFile, SolverInfo};
use gap_crossing::render;
use gap_crossing::scenario::{Foot, Gait, Scenario};
use gap_crossing::solve::{self, complementarity_residual, Settings};
use gap_crossing::terrain::GapTerrain;
use nlp::NumericNlp;

/// Starting rows of restoration phases (they repeat an iteration number).
fn restoration_entries(p: &solve::Phase) -> usize {
    (1..p.records.len())
        .filter(|&k| p.records[k].restoration && !p.records[k - 1].restoration)
        .count()
}

#[test]
fn free_gait_history_has_every_iteration_and_the_checkers_residual() {
    let s = Scenario::default();
    assert_eq!(s.gait, Gait::Free);
    let out = solve::plan(&s, &Settings::default()).unwrap();
    let report = check::check(&out.file);
    assert!(report.ok(), "{report}");
    // The runs of the free gait: crawl schedule, biped-pair schedule, the crossing
    // search from the better of the two (on the default scenario three runs: both back
    // feet crossing one move earlier, then the back right again), then the schedule
    // search's rounds from each (two from the crawl plan, one from the pair plan).
    let names: Vec<&str> = out.phases.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names.len(), 8, "{names:?}");
    assert_eq!(names[0], "free gait: crawl schedule");
    assert_eq!(names[1], "free gait: biped-pair schedule");
    assert!(
        names[2..5].iter().all(|n| n.starts_with("crossing search")),
        "{names:?}"
    );
    assert!(
        names[5].starts_with("free gait: search from crawl 1"),
        "{names:?}"
    );
    assert!(
        names[7].starts_with("free gait: search from biped-pair 1"),
        "{names:?}"
    );
    let history = Convergence::from_phases(&out.phases);
    assert_eq!(history.phases.len(), 8);
    let mut total = 0;
    for (k, p) in out.phases.iter().enumerate() {
        // One entry per iteration (and per restoration start), in the solver's order.
        assert_eq!(p.records.len(), p.iterations + 1 + restoration_entries(p));
        assert_eq!(p.residuals.len(), p.records.len(), "{}", p.name);
        let rows = history.phase_iterations(k);
        assert_eq!(rows.len(), p.records.len(), "{}", p.name);
        assert_eq!(history.phases[k].iterations, p.iterations);
        for (r, rec) in rows.iter().zip(&p.records) {
            assert_eq!(
                (r.phase, r.iter, r.objective, r.inf_pr),
                (k, rec.iter, rec.objective, rec.inf_pr)
            );
            assert_eq!(r.index, total);
            total += 1;
        }
        // The last iterate is the run's solution: its residual is the end-of-run figure.
        assert_eq!(
            *p.residuals.last().unwrap(),
            p.complementarity,
            "{}",
            p.name
        );
        if p.scheduled {
            assert!(p.residuals.iter().all(|&v| v == 0.0), "{}", p.name);
        } else {
            assert!(p.residuals.iter().any(|&v| v > 0.0), "{}", p.name);
        }
    }
    assert_eq!(total, history.iterations.len());
    assert_eq!(
        out.file.solver.iterations,
        out.phases.iter().map(|p| p.iterations).sum::<usize>()
    );
    // The plan is the chosen run's last iterate: same (10) figure as the checker's.
    let chosen = &out.phases[out.chosen];
    assert_eq!(*chosen.residuals.last().unwrap(), report.residual_10);

    // The JSON round trip, and the figure marks the runs and the scheduled zeros.
    let json = serde_json::to_string(&history).unwrap();
    assert_eq!(Convergence::from_json(&json).unwrap(), history);
    let svg = render::convergence_svg(&history, "t");
    assert_eq!(
        svg.matches("stroke-dasharray").count(),
        7,
        "seven run boundaries"
    );
    assert!(svg.contains("≡ 0"));
}

/// A plan in which several feet move at once: the probe (solver iterate → layout →
/// (10) residual) and the checker (solution file, plain arithmetic) agree.
#[test]
fn probe_matches_the_checker_off_complementarity() {
    let s = Scenario::default();
    let terrain = GapTerrain { gap: s.gap };
    let mut guess = gait::crawl(&s);
    // From stance 11 on, each foot is shifted sideways by a different amount: at the
    // transition 10 → 11 all four feet move.
    for k in 10..s.n_step {
        for (j, foot) in Foot::ALL.into_iter().enumerate() {
            guess[foot_offset(k, foot) + 1] += 0.01 * (j + 1) as f64;
        }
    }
    let model = model::build(&s, &terrain, &Formulation::Complementarity, &guess).unwrap();
    let compiled = model.problem.compile().unwrap();
    let mut x0 = vec![0.0; compiled.n()];
    compiled.initial_point(&mut x0);
    let mut probe = ResidualProbe::new(&s, &model).unwrap();
    let residual = probe.at(&x0);
    assert!(residual > 1e-9, "{residual}");
    assert_eq!(residual, complementarity_residual(&s, &guess));

    let info = SolverInfo {
        name: "test".into(),
        status: "guess".into(),
        iterations: 0,
        objective: 0.0,
        objective_without_10: None,
        max_constraint_violation: 0.0,
        solve_seconds: 0.0,
        reason: None,
    };
    let file = SolutionFile::new(s.clone(), info, Plan::from_flat(&s, &guess).unwrap());
    let report = check::check(&file);
    assert!(report.equations().contains(&"(10)".to_string()));
    assert_eq!(report.residual_10, residual);
}

#[test]
fn version_1_history_still_renders() {
    let v1 = r#"[{"iter": 0, "objective": 3e5, "inf_pr": 1.0, "compl": 0.1},
                 {"iter": 1, "objective": 2e5, "inf_pr": 1e-9, "compl": 1e-10}]"#;
    let c = Convergence::from_json(v1).unwrap();
    assert_eq!(c.version, 1);
    assert_eq!(c.iterations.len(), 2);
    assert!(c.iterations.iter().all(|r| r.residual_10.is_none()));
    let svg = render::convergence_svg(&c, "old");
    assert!(svg.contains("not recorded"));
}

/// The planner records the (10) residual of every iterate of a scheduled solve as an
/// exact 0 without evaluating it (`solve::solve_scheduled`): the probe evaluates it at
/// every iterate of the crawl schedule's solve on the default scenario and finds
/// exactly 0 each time, and the solve's plan has several feet moving over the run (so
/// the zeros come from the shared variables, not from a plan that stands still).
#[test]
fn scheduled_iterates_satisfy_10_exactly() {
    let s = Scenario::default();
    let terrain = GapTerrain { gap: s.gap };
    let guess = gait::crawl(&s);
    let formulation = Formulation::Scheduled(gait::crawl_schedule(s.n_step));
    let model = model::build(&s, &terrain, &formulation, &guess).unwrap();
    let mut compiled = model.problem.compile().unwrap();
    let mut probe = ResidualProbe::new(&s, &model).unwrap();
    let mut residuals = Vec::new();
    let mut callback = |v: &nlp::IterationView<'_>| {
        residuals.push(probe.at(v.x()));
        std::ops::ControlFlow::Continue(())
    };
    let solution = Settings::default()
        .solver()
        .solve_with_callback(&mut compiled, &mut callback)
        .unwrap();
    assert!(solution.status.is_success(), "{:?}", solution.status);
    assert!(residuals.len() > 10, "{}", residuals.len());
    assert!(residuals.iter().all(|&r| r == 0.0), "{residuals:?}");
    let flat = model.problem.evaluate(&model.layout, &solution.x).unwrap();
    let moved = (1..s.n_step)
        .filter(|&k| {
            Foot::ALL.iter().any(|&i| {
                (0..3).any(|d| flat[foot_offset(k, i) + d] != flat[foot_offset(k - 1, i) + d])
            })
        })
        .count();
    assert!(moved >= 40, "{moved} transitions move a foot");
}
