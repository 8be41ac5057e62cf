//! The corpus in CI: every instance builds; the smallest instance of every
//! optimal-control family is solved by symnlp's interior-point method to IPOPT's optimum
//! within an iteration bound; exported text parses back to the compiled problem; symx's
//! derivatives pass the derivative checker on small instances. The full comparison with
//! IPOPT is a documented command (docs/corpus.md), not a test.
use corpus::{export, run};
use nlp::derivative_check::{check_derivatives, DerivativeCheckOptions};

/// (instance, IPOPT 3.14.19's objective on the same exported formulation, IPOPT's
/// iterations, iteration bound for symnlp). Objectives and IPOPT iterations come from
/// `python3 benches/reference/corpus_ipopt.py` (benches/reference/results/corpus.jsonl).
/// The bound is twice IPOPT's count (the target of issue 10); symnlp meets it on every
/// family since 2026-11-25 (rocket_trap_400: 34 iterations, bound 202 before).
const SMALLEST: &[(&str, f64, usize, usize)] = &[
    ("rocket_trap_400", -1.0128352213043499, 27, 54),
    ("steering_trap_200", 0.5545770161030464, 14, 28),
    ("robot_trap_200", 9.141396951323673, 20, 40),
    ("catmix_colloc_100", -0.04805538299701119, 20, 40),
    ("channel_colloc_100", 1.0, 5, 10),
    ("pinene_colloc_100", 19.872170145335872, 15, 30),
    ("race_car_rk4_100", 1.9046342735147384, 39, 78),
    ("vdp_rk4_20", 3.7324355529062423, 9, 18),
    ("vdp_trap_50", 3.6734170050089268, 13, 26),
    ("cartpole_trap_50", 59.14775732337834, 12, 24),
    ("cartpole_rk4_50", 59.13194620767747, 12, 24),
    ("quadrotor_rk4_50", 194.8824168265576, 12, 24),
    ("arm2_trap_50", 3.915687197194579, 17, 34),
];

fn solves_like_ipopt(name: &str) {
    let &(_, f_ipopt, _, bound) = SMALLEST.iter().find(|r| r.0 == name).expect("listed");
    let inst = corpus::instance(name).expect("instance exists");
    let out = run::solve(&inst, &run::options(120.0)).expect("solves");
    assert!(out.success, "{name}: {}", out.status);
    // The target: the same optimum to 1e-6 relative (or a better one).
    let gap = (out.objective - f_ipopt) / f_ipopt.abs().max(1.0);
    assert!(
        gap < 1e-6,
        "{name}: f = {:.12e}, IPOPT {f_ipopt:.12e}",
        out.objective
    );
    assert!(
        out.iterations <= bound,
        "{name}: {} iterations > {bound}",
        out.iterations
    );
    if let Some(r) = inst.reference() {
        // COPS 3.0 publishes 6 significant digits.
        assert!(
            (out.objective - r.value).abs() <= 1e-5 * r.value.abs(),
            "{name}: published {}",
            r.value
        );
    }
}

macro_rules! smallest {
    ($($test:ident => $name:literal),* $(,)?) => {$(
        #[test]
        fn $test() {
            solves_like_ipopt($name);
        }
    )*};
}

smallest! {
    rocket_trap => "rocket_trap_400",
    steering_trap => "steering_trap_200",
    robot_trap => "robot_trap_200",
    catmix_colloc => "catmix_colloc_100",
    channel_colloc => "channel_colloc_100",
    pinene_colloc => "pinene_colloc_100",
    race_car_rk4 => "race_car_rk4_100",
    vdp_rk4 => "vdp_rk4_20",
    vdp_trap => "vdp_trap_50",
    cartpole_trap => "cartpole_trap_50",
    cartpole_rk4 => "cartpole_rk4_50",
    quadrotor_rk4 => "quadrotor_rk4_50",
    arm2_trap => "arm2_trap_50",
}

/// COPS's hang glider: IPOPT converges in 655 iterations to −1255.0586 (corpus.jsonl).
/// symnlp stopped with SearchDirectionBecomesTooSmall at −1255.0568 until the Jacobian
/// degeneracy was decided as IPOPT decides it; now 556 iterations to IPOPT's optimum.
/// Bound: 2× IPOPT's count.
#[test]
fn glider_trap() {
    let inst = corpus::instance("glider_trap_100").expect("instance exists");
    let out = run::solve(&inst, &run::options(120.0)).expect("solves");
    assert!(out.success, "{}", out.status);
    assert!(
        (out.objective + 1255.0586012855729).abs() < 1e-6 * 1255.06,
        "{}",
        out.objective
    );
    assert!(out.iterations <= 1310, "{} iterations", out.iterations);
}

#[test]
fn every_instance_builds_with_distinct_names_and_sizes_in_range() {
    let instances = corpus::instances();
    let mut names: Vec<String> = instances.iter().map(|i| i.name()).collect();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), instances.len(), "instance names are unique");
    let ocp: Vec<_> = corpus::families()
        .into_iter()
        .filter(|f| f.kind == corpus::Kind::Ocp)
        .collect();
    assert!(ocp.len() >= 12, "{} optimal-control families", ocp.len());
    for family in ocp {
        assert_eq!(family.sizes.len(), 3, "{}", family.name);
        let largest = corpus::Instance {
            family,
            size: family.sizes[2],
        }
        .build()
        .expect("builds");
        assert!(
            largest.n_variables() >= 20_000,
            "{}: n = {}",
            family.name,
            largest.n_variables()
        );
    }
    let cute = corpus::families()
        .into_iter()
        .filter(|f| f.kind == corpus::Kind::Cute)
        .count();
    assert!(cute >= 50, "{cute} CUTEst-style problems");
    for inst in corpus::instances()
        .iter()
        .filter(|i| i.family.kind == corpus::Kind::Cute)
    {
        inst.build()
            .unwrap_or_else(|e| panic!("{}: {e}", inst.name()));
    }
}

#[test]
fn exported_text_is_the_compiled_problem() {
    for name in [
        "rocket_trap_400",
        "glider_trap_100",
        "channel_colloc_100",
        "race_car_rk4_100",
        "quadrotor_rk4_50",
        "elec_50",
        "helical_3",
    ] {
        let inst = corpus::instance(name).expect("instance exists");
        let pb = inst.build().expect("builds");
        let mut compiled = pb.compile().expect("compiles");
        let dump = export::dump(&inst, &pb, &mut compiled).expect("dumps");
        // Printing and parsing keep every operation and constant (Debug-formatted f64
        // round-trips exactly), so the values agree to the last bits of rounding.
        let err = export::verify(&dump).expect("parses");
        assert!(
            err <= 1e-12 * (1.0 + dump.problem.f0.abs()),
            "{name}: {err}"
        );
    }
}

#[test]
fn symx_derivatives_pass_the_checker_on_small_instances() {
    for name in [
        "vdp_rk4_20",
        "cartpole_rk4_50",
        "quadrotor_rk4_50",
        "arm2_trap_50",
        "robot_trap_200",
        "bard_3",
        "allinitc_4",
        "camshape_1000",
    ] {
        let inst = corpus::instance(name).expect("instance exists");
        let mut compiled = inst.build().and_then(|p| p.compile()).expect("compiles");
        let report =
            check_derivatives(&mut compiled, &DerivativeCheckOptions::default()).expect("checks");
        assert!(report.passed(), "{name}: {report}");
    }
}

/// catenary_999 (CUTEst CATENARY, 999 variables, 332 equality rows) once took 1307
/// iterations against IPOPT's 70 (benches/reference/results/corpus.jsonl): δ_c was on in
/// 1281 of them and 1159 steps had α_pr < 1e-8. IPOPT decides once, in the first
/// iterations, whether the Jacobian is degenerate (its log shows "Nj" at iteration 2 and
/// never δ_c); so does symnlp now. Bound: 2× IPOPT's 70 (the target).
#[test]
fn catenary_solves_within_twice_ipopt() {
    let inst = corpus::instance("catenary_999").expect("instance exists");
    let out = run::solve(&inst, &run::options(120.0)).expect("solves");
    assert!(out.success, "{}", out.status);
    // IPOPT's objective on the same formulation (corpus.jsonl): -6.970608952126e5.
    let f_ipopt = -6.970608952126e5_f64;
    assert!(((out.objective - f_ipopt) / f_ipopt.abs()).abs() < 1e-9);
    assert!(out.iterations <= 140, "{} iterations", out.iterations);
}

/// The rule that ends a run of tiny accepted steps (`tiny_alpha_max_iter`), exercised
/// with a threshold that glider_trap_100's shortened steps reach (α_pr < 1e-2, 3 in a
/// row): every such run ends in a restoration phase, none is longer than 3 steps, and
/// the solve ends with a clear status (here `RestorationFailed` after 197 iterations),
/// not `max_iter`. With the rule off the same solve has a run of 11 such steps.
/// (rocket_trap_400 served until its crawl went away with the equality-row
/// regularisation floor of 2026-11-25.)
#[test]
fn tiny_alpha_run_leads_to_restoration() {
    let inst = corpus::instance("glider_trap_100").expect("instance exists");
    let solve = |max: usize| {
        let mut o = run::options(120.0);
        o.tiny_alpha = 1e-2;
        o.tiny_alpha_max_iter = max;
        let mut compiled = inst.build().unwrap().compile().unwrap();
        nlp::Ipm::new(o).solve(&mut compiled).unwrap()
    };
    // (longest run of accepted steps below 1e-2 outside restoration, restoration phases)
    let runs = |sol: &nlp::Solution| {
        let (mut run, mut best, mut phases, mut was) = (0usize, 0usize, 0usize, false);
        for r in sol.stats.records.iter().skip(1) {
            phases += usize::from(r.restoration && !was);
            was = r.restoration;
            run = if r.alpha_pr < 1e-2 && !r.restoration {
                run + 1
            } else {
                0
            };
            best = best.max(run);
        }
        (best, phases)
    };
    let off = solve(0);
    let on = solve(3);
    assert!(runs(&off).0 > 3, "{:?}", runs(&off));
    assert!(runs(&on).0 <= 3, "{:?}", runs(&on));
    // A restoration phase started by the rule: its first row is 'R' with ls 0.
    let forced = |sol: &nlp::Solution| {
        sol.stats
            .records
            .iter()
            .filter(|r| r.alpha_pr_char == 'R' && r.ls == 0)
            .count()
    };
    assert_eq!(forced(&off), 0);
    assert!(forced(&on) > 0 && runs(&on).1 > 0);
    assert_ne!(on.status, nlp::Status::MaximumIterationsExceeded);
}

/// IPOPT's soft restoration phase (`soft_resto_pderror_reduction_factor` = 1 − 1e-4,
/// IPOPT's default; off by default in symnlp because chain_800 then fails) on
/// catenary_999. With default options the line search fails at iteration 25 and a
/// restoration phase starts there ('R'); with the soft restoration on, the same failure
/// is answered by soft steps instead ('s', accepted for their lower primal-dual error,
/// then 'S', acceptable to the filter, which ends the phase: iterations 25–27), no
/// restoration phase is needed, and the solve ends at IPOPT's optimum. The two runs are
/// identical up to the failed line search (same options otherwise), so the first soft
/// step must sit exactly where the default run's restoration starts.
/// (rocket_trap_400 served until its line search stopped failing with the equality-row
/// regularisation floor of 2026-11-25; from then on that test took no soft step.)
#[test]
fn soft_restoration_replaces_catenarys_restoration_phase() {
    let inst = corpus::instance("catenary_999").expect("instance exists");
    let solve = |factor: f64| {
        let mut o = run::options(120.0);
        o.soft_resto_pderror_reduction_factor = factor;
        let mut compiled = inst.build().unwrap().compile().unwrap();
        nlp::Ipm::new(o).solve(&mut compiled).unwrap()
    };
    let chars = |sol: &nlp::Solution| -> String {
        sol.stats.records.iter().map(|r| r.alpha_pr_char).collect()
    };
    let off = solve(0.0);
    let on = solve(1.0 - 1e-4);
    let (off_log, on_log) = (chars(&off), chars(&on));
    // Default: a restoration phase, no soft step.
    let resto_start = off_log
        .find('R')
        .expect("the default run enters restoration");
    assert!(!off_log.contains(['s', 'S']), "{off_log}");
    // Soft restoration on: soft steps from the failed line search on, ended by 'S'.
    assert_eq!(on_log.find('s'), Some(resto_start), "{on_log}");
    let phase: String = on_log[resto_start..]
        .chars()
        .take_while(|&c| c == 's' || c == 'S')
        .collect();
    assert!(phase.ends_with('S') && phase.len() >= 2, "{on_log}");
    assert!(on.stats.records.iter().all(|r| !r.restoration), "{on_log}");
    assert_eq!(on.status, nlp::Status::SolveSucceeded);
    // IPOPT's objective on the same formulation (corpus.jsonl: -6.970608952126496e5, 70
    // iterations); tol 1e-8 on the scaled KKT error puts both ends within 1e-15 of each
    // other here, so 1e-9 leaves room only for a different end point, not for round-off.
    let f_ipopt = -6.970608952126496e5_f64;
    assert!(
        ((on.objective - f_ipopt) / f_ipopt.abs()).abs() < 1e-9,
        "{}",
        on.objective
    );
    assert!(
        on.stats.iterations <= 140,
        "{} iterations",
        on.stats.iterations
    );
}

/// catmix_colloc_100 with IPOPT's `residual_ratio_singular` (1e-5): the refinement of
/// iterations 16–17 ends at residual ratios 1.7e-10 and 5.2e-10, just above
/// `residual_ratio_max` (1e-10); without the refinement retry (the default since
/// 2026-11-25, next test) such a solve counted as singular and δ_w was raised (27
/// iterations, 9 regularised); with 1e-5 it is taken as it is and the solve takes IPOPT's
/// 20 iterations (corpus.jsonl) with no δ_w. Not the default: race_car_rk4_400 then takes
/// 580 iterations instead of 61 (docs/solvers.md §6).
#[test]
fn catmix_with_ipopts_residual_ratio_singular_takes_ipopts_count() {
    use nlp::NamedOptions;
    let inst = corpus::instance("catmix_colloc_100").expect("instance exists");
    let mut o = run::options(120.0);
    o.set_by_name(&["residual_ratio_singular=1e-5"]).unwrap();
    let mut compiled = inst.build().unwrap().compile().unwrap();
    let sol = nlp::Ipm::new(o).solve(&mut compiled).unwrap();
    assert_eq!(sol.status, nlp::Status::SolveSucceeded);
    let f_ipopt = -0.04805538299701119_f64;
    assert!((sol.objective - f_ipopt).abs() < 1e-6, "{}", sol.objective);
    assert!(
        sol.stats.iterations <= 20,
        "{} iterations",
        sol.stats.iterations
    );
    assert!(sol.stats.records.iter().all(|r| r.regularization == 0.0));
}

/// catmix_colloc_100 with default options: the failed refinements at μ = 2.5e-9 are
/// repeated on a factor with the static regularisations lowered ×1e-2 (symnlp's
/// counterpart of IPOPT's IncreaseQuality, docs/solvers.md §6), which refines them to
/// ≈1e-15, so no δ_w is raised and the solve takes IPOPT's 20 iterations (corpus.jsonl;
/// 27 before, with δ_w on 9 iterations). Objective to 1e-6 absolute: both solvers stop at
/// a KKT error of 1e-8, far below that.
#[test]
fn catmix_default_takes_ipopts_count_without_hessian_regularisation() {
    let inst = corpus::instance("catmix_colloc_100").expect("instance exists");
    let o = run::options(120.0);
    let mut compiled = inst.build().unwrap().compile().unwrap();
    let sol = nlp::Ipm::new(o).solve(&mut compiled).unwrap();
    assert_eq!(sol.status, nlp::Status::SolveSucceeded);
    let f_ipopt = -0.04805538299701119_f64;
    assert!((sol.objective - f_ipopt).abs() < 1e-6, "{}", sol.objective);
    assert!(
        sol.stats.iterations <= 20,
        "{} iterations",
        sol.stats.iterations
    );
    assert!(sol.stats.records.iter().all(|r| r.regularization == 0.0));
}

/// `instance_at_any_size` (used by `corpus export|diagnose|trace`): any size of a known
/// family, family names with underscores, no size 0, no unknown family.
#[test]
fn instances_at_any_size() {
    let i = corpus::instance_at_any_size("noncvxu2_37").expect("any size");
    assert_eq!((i.family.name, i.size), ("noncvxu2", 37));
    let i = corpus::instance_at_any_size("rocket_trap_400").expect("listed size");
    assert_eq!((i.family.name, i.size), ("rocket_trap", 400));
    for bad in [
        "noncvxu2_0",
        "noncvxu2_",
        "noncvxu2",
        "nosuch_10",
        "noncvxu2_x",
    ] {
        assert!(corpus::instance_at_any_size(bad).is_none(), "{bad}");
    }
}

/// noncvxu2 at n = 10 (not a corpus size): the same minimum as IPOPT 3.14.19 on the same
/// exported formulation (`benches/reference/ipopt_trace.py`: 23.16808419788213, 14
/// iterations; symnlp 13, the inertia of the exactly singular W at iterate 9 being
/// decided by round-off, docs/performance.md "noncvxu2 / noncvxun"). symnlp reaches this
/// minimum from all 21 starts x0·(1 ± k·1e-15); from n = 50 on the minimum reached depends
/// on round-off in both solvers (n = 100: 6 minima over the same 21 starts).
/// 1e-9: both ends agree to 1e-15 here; the tolerance leaves room for round-off only.
/// Iteration bound: 2× IPOPT's 14 (issue 10's target).
#[test]
fn noncvxu2_10_reaches_ipopts_minimum() {
    let inst = corpus::instance_at_any_size("noncvxu2_10").unwrap();
    let out = run::solve(&inst, &run::options(60.0)).expect("solves");
    assert!(out.success, "{}", out.status);
    let f_ipopt = 23.16808419788213_f64;
    assert!(
        ((out.objective - f_ipopt) / f_ipopt).abs() < 1e-9,
        "{}",
        out.objective
    );
    assert!(out.iterations <= 28, "{} iterations", out.iterations);
}

/// The COPS rocket exactly as COPS writes it (issue 23 item 7): boundary values as rows
/// `h[0] − 1 = 0`, … with those entries' bounds dropped. IPOPT (CasADi 3.8.2 defaults, rows
/// kept as rows; `python3 benches/reference/cops_rocket_rows.py 400 1600`) takes 27 and
/// 26 iterations to −1.0128352213043499 and −1.012831339180924. symnlp detects the affine
/// single-variable rows as bounds (as CasADi's `detect_simple_bounds` does) and must take
/// at most 1.3× IPOPT's count (the target); before, the rows stayed rows and the
/// IPM took 55 and 150 iterations (docs/corpus.md, "The rocket with boundary rows").
#[test]
fn rocket_with_boundary_rows_like_ipopt() {
    for (name, f_ipopt, ipopt_iterations) in [
        ("rocket_rows_trap_400", -1.0128352213043499, 27),
        ("rocket_rows_trap_1600", -1.012831339180924, 26),
    ] {
        let inst = corpus::instance(name).expect("instance exists");
        let out = run::solve(&inst, &run::options(120.0)).expect("solves");
        assert!(out.success, "{name}: {}", out.status);
        // The same optimum to 1e-6 relative, or a better one (as `solves_like_ipopt`).
        assert!(
            out.objective - f_ipopt < 1e-6 * f_ipopt.abs(),
            "{name}: f = {:.12e}",
            out.objective
        );
        let bound = (1.3 * ipopt_iterations as f64).floor() as usize;
        assert!(
            out.iterations <= bound,
            "{name}: {} > {bound}",
            out.iterations
        );
    }
}
