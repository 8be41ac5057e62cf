//! Exploration of free-gait starting points for the default-scenario target (issue 11
//! item 4), not part of the planner: each start is solved as a scheduled problem and
//! then improved by the lattice schedule search (as `solve` does), and the objectives
//! are printed. Figures and conclusions: docs/performance.md, "Free gait: what was tried
//! for 1.69e5".
//!
//! ```text
//! cargo run --release -p gap_crossing --example gait_explore -- orders FR,FL,BR,BL BR,FR,BL,FL
//! cargo run --release -p gap_crossing --example gait_explore -- even FR,FL,BR,BL 0.3 10 10 [0.6]
//! cargo run --release -p gap_crossing --example gait_explore -- random 12345 12
//! cargo run --release -p gap_crossing --example gait_explore -- mpcc pair 1e7
//! ```
//!
//! - `orders O...`: periodic schedules (comma-separated feet, optionally after a prefix:
//!   `FR,FL|BR,BL,FR,FL`), guess by the landing rule;
//! - `even O a mB mF [w]`: each foot walks `m` even moves straight to its final foothold
//!   (`a` m behind its goal CoM, on the circle of radius 0.5 m about it; footholds in
//!   the keep-out snapped to its nearer edge), feet `w` m apart laterally from their
//!   first move on when `w` is given;
//! - `random seed count`: random sequences of biped pairs (20 % single moves), kept
//!   balanced between the bipeds;
//! - `mpcc crawl|pair π,...`: the lifted complementarity problem with penalty π (a
//!   continuation when several are given), from the solved crawl or pair plan, rounded
//!   to a schedule (at each transition the foot that moves most).
//!
//! Any `KEY=VALUE` argument is a scenario override, as `--set` of the CLI.
use gap_crossing::gait;
use gap_crossing::model::{self, Formulation};
use gap_crossing::plan::Plan;
use gap_crossing::scenario::{Feet, Foot, Scenario, Vec3};
use gap_crossing::schedule_search::{self, StanceSolver};
use gap_crossing::solve::Settings;
use gap_crossing::terrain::{self, Terrain};

fn solve(
    s: &Scenario,
    t: &dyn Terrain,
    sched: &[Foot],
    guess: &[f64],
    warm: bool,
) -> Option<(f64, Vec<f64>, usize)> {
    let m = match model::build(s, t, &Formulation::Scheduled(sched.to_vec()), guess) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("build: {e}");
            return None;
        }
    };
    let mut c = m.problem.compile().ok()?;
    let mut st = Settings::default();
    st.set_print_level(0);
    st.ipm.max_iter = 400;
    if warm {
        st.ipm.mu_init = 1e-6;
        st.ipm.bound_push = 1e-8;
        st.ipm.bound_frac = 1e-8;
        st.ipm.slack_bound_push = 1e-8;
        st.ipm.slack_bound_frac = 1e-8;
    }
    let sol = st.solver().solve(&mut c).ok()?;
    if !sol.status.is_success() {
        eprintln!("status {:?} after {} it", sol.status, sol.stats.iterations);
        return None;
    }
    let flat = m.problem.evaluate(&m.layout, &sol.x).ok()?;
    let cost = Plan::from_flat(s, &flat).ok()?.cost(s);
    Some((cost, flat, sol.stats.iterations))
}

fn search(
    s: &Scenario,
    t: &dyn Terrain,
    mut sched: Vec<Foot>,
    mut flat: Vec<f64>,
    mut cost: f64,
) -> (f64, Vec<f64>, Vec<Foot>) {
    let mut ss = StanceSolver::new(s, t).unwrap();
    for _ in 0..8 {
        let plan = Plan::from_flat(s, &flat).unwrap();
        let Some(p) = schedule_search::propose(s, &mut ss, &plan, &sched) else {
            break;
        };
        match solve(s, t, &p.schedule, &p.plan.to_flat(), true) {
            Some((c, f, _)) if c < cost => {
                cost = c;
                flat = f;
                sched = p.schedule;
            }
            _ => break,
        }
    }
    (cost, flat, sched)
}

/// A schedule from `PREFIX|PERIOD` (or just `PERIOD`): the prefix once, then the period
/// repeated.
fn parse_sched(s: &str, n: usize) -> Vec<Foot> {
    let (prefix, period) = s.split_once('|').unwrap_or(("", s));
    let mut out = if prefix.is_empty() {
        Vec::new()
    } else {
        parse_order(prefix)
    };
    let order = parse_order(period);
    let mut k = 0;
    while out.len() < n - 1 {
        out.push(order[k % order.len()]);
        k += 1;
    }
    out.truncate(n - 1);
    out
}

fn parse_order(s: &str) -> Vec<Foot> {
    s.split(',')
        .map(|w| match w.trim() {
            "BR" => Foot::BR,
            "BL" => Foot::BL,
            "FR" => Foot::FR,
            "FL" => Foot::FL,
            o => panic!("{o}"),
        })
        .collect()
}

/// Per-foot foothold sequences: `m` even moves from start to target, keep-out snapped.
fn per_foot(
    s: &Scenario,
    targets: [Vec3; 4],
    moves: [usize; 4],
    width: Option<f64>,
) -> [Vec<Vec3>; 4] {
    let (lo, hi) = s.gap.keep_out();
    std::array::from_fn(|i| {
        let f = Foot::ALL[i];
        let p0 = s.start.feet.get(f);
        let t = targets[i];
        let m = moves[i];
        let mut out = vec![p0];
        for j in 1..=m {
            let a = j as f64 / m as f64;
            let mut x = p0[0] + (t[0] - p0[0]) * a;
            let y = match width {
                Some(w) => {
                    let narrow = 0.5 + (p0[1] - 0.5).signum() * w / 2.0;
                    narrow + (t[1] - narrow) * a
                }
                None => p0[1] + (t[1] - p0[1]) * a,
            };
            if x > lo && x < hi {
                x = if x - lo < hi - x {
                    lo - 1e-3
                } else {
                    hi + 1e-3
                };
            }
            out.push([x, y, 0.0]);
        }
        out
    })
}

fn interleave(s: &Scenario, seqs: &[Vec<Vec3>; 4], sched: &[Foot]) -> Vec<Feet> {
    let mut cnt = [0usize; 4];
    let mut feet = s.start.feet;
    let mut out = vec![feet];
    for &f in sched {
        let i = f.index();
        if cnt[i] + 1 < seqs[i].len() {
            cnt[i] += 1;
            *feet.get_mut(f) = seqs[i][cnt[i]];
        }
        out.push(feet);
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut s = Scenario::default();
    let sets: Vec<String> = args.iter().filter(|a| a.contains('=')).cloned().collect();
    s.apply_overrides(&sets).unwrap();
    let t = terrain::of(&s);
    let mode = args.first().map(String::as_str).unwrap_or("orders");
    match mode {
        "orders" => {
            for o in &args[1..] {
                if o.contains('=') {
                    continue;
                }
                let sched = parse_sched(o, s.n_step);
                let g = gait::plan_for_footholds(&s, &gait::footholds_for_schedule(&s, &sched))
                    .to_flat();
                report(&s, &*t, o, &sched, &g);
            }
        }
        "even" => {
            // even <order> <a> <mB> <mF>
            let o = &args[1];
            let a: f64 = args[2].parse().unwrap();
            let mb: usize = args[3].parse().unwrap();
            let mf: usize = args[4].parse().unwrap();
            let width: Option<f64> = args
                .get(5)
                .filter(|w| !w.contains('='))
                .map(|w| w.parse().unwrap());
            let b = (0.25 - a * a).sqrt();
            let gb = s.goal.b;
            let gf = s.goal.f;
            let targets = [
                [gb[0] - a, gb[1] - b, 0.0],
                [gb[0] - a, gb[1] + b, 0.0],
                [gf[0] - a, gf[1] - b, 0.0],
                [gf[0] - a, gf[1] + b, 0.0],
            ];
            let seqs = per_foot(&s, targets, [mb, mb, mf, mf], width);
            let sched = parse_sched(o, s.n_step);
            let g = gait::plan_for_footholds(&s, &interleave(&s, &seqs, &sched)).to_flat();
            report(
                &s,
                &*t,
                &format!("even {o} a={a} mB={mb} mF={mf}"),
                &sched,
                &g,
            );
        }
        "mpcc" => {
            // mpcc <start: crawl|pair> <pi list comma-separated>
            let start = &args[1];
            let pis: Vec<f64> = args[2].split(',').map(|x| x.parse().unwrap()).collect();
            let sched0 = if start == "pair" {
                gait::pair_schedule(s.n_step)
            } else {
                gait::crawl_schedule(s.n_step)
            };
            let g =
                gait::plan_for_footholds(&s, &gait::footholds_for_schedule(&s, &sched0)).to_flat();
            let (_, flat0, _) = solve(&s, &*t, &sched0, &g, false).unwrap();
            mpcc(&s, &*t, &flat0, &pis);
        }
        "random" => {
            // random <seed> <count>: random sequences of biped pairs, kept balanced
            let mut state: u64 = args[1].parse().unwrap();
            let count: usize = args[2].parse().unwrap();
            let mut rnd = move || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            for _ in 0..count {
                let mut sched = Vec::new();
                let (mut nb, mut nf) = (0i32, 0i32);
                while sched.len() < s.n_step - 1 {
                    let p_front = 0.5 + 0.25 * ((nb - nf) as f64).clamp(-2.0, 2.0);
                    let front = rnd() < p_front;
                    let pair = if front {
                        [Foot::FR, Foot::FL]
                    } else {
                        [Foot::BR, Foot::BL]
                    };
                    let pair = if rnd() < 0.5 {
                        pair
                    } else {
                        [pair[1], pair[0]]
                    };
                    let single = rnd() < 0.2;
                    for (q, f) in pair.iter().enumerate() {
                        if single && q == 1 {
                            break;
                        }
                        if sched.len() < s.n_step - 1 {
                            sched.push(*f);
                        }
                    }
                    if front {
                        nf += if single { 1 } else { 2 }
                    } else {
                        nb += if single { 1 } else { 2 }
                    }
                }
                let name: String = sched
                    .iter()
                    .take(24)
                    .map(|f| f.name())
                    .collect::<Vec<_>>()
                    .join(" ");
                let g = gait::plan_for_footholds(&s, &gait::footholds_for_schedule(&s, &sched))
                    .to_flat();
                report(&s, &*t, &name, &sched, &g);
            }
        }
        _ => panic!("mode"),
    }
}

fn report(s: &Scenario, t: &dyn Terrain, name: &str, sched: &[Foot], g: &[f64]) {
    let t0 = std::time::Instant::now();
    match solve(s, t, sched, g, false) {
        Some((c, f, it)) => {
            let (c2, _, _) = search(s, t, sched.to_vec(), f, c);
            println!(
                "{name}: {c:.6e} ({it} it) -> search {c2:.6e}  [{:.2}s]",
                t0.elapsed().as_secs_f64()
            );
        }
        None => println!("{name}: failed"),
    }
}

fn mpcc(s: &Scenario, t: &dyn Terrain, start: &[f64], pis: &[f64]) {
    use gap_crossing::plan::foot_offset;
    let m = model::build(s, t, &Formulation::Complementarity, start).unwrap();
    let mut c = m.problem.compile().unwrap();
    let mut st = Settings::default();
    st.set_print_level(0);
    st.ipm.max_iter = 1000;
    let mut prev: Option<nlp::Solution> = None;
    for &pi in pis {
        c.set_value(model::PENALTY, &[pi]).unwrap();
        let mut w = st.clone();
        if prev.is_some() {
            w.ipm.mu_init = 1e-4;
            w.ipm.bound_push = 1e-6;
            w.ipm.bound_frac = 1e-6;
            w.ipm.slack_bound_push = 1e-6;
            w.ipm.slack_bound_frac = 1e-6;
        }
        let sol = match &prev {
            Some(p) => w.solver().solve_warm(&mut c, p),
            None => w.solver().solve(&mut c),
        }
        .unwrap();
        let flat = m.problem.evaluate(&m.layout, &sol.x).unwrap();
        let cost = Plan::from_flat(s, &flat).unwrap().cost(s);
        let res = gap_crossing::solve::complementarity_residual(s, &flat);
        // Round: at each transition the foot with the largest step moves.
        let n = s.n_step;
        let mut sched = Vec::new();
        let mut feet = s.start.feet;
        let mut holds = vec![feet];
        for k in 1..n {
            let mut best = (0.0, Foot::BR);
            for i in Foot::ALL {
                let (a, b) = (foot_offset(k - 1, i), foot_offset(k, i));
                let d: f64 = (0..3).map(|q| (flat[b + q] - flat[a + q]).powi(2)).sum();
                if d > best.0 {
                    best = (d, i);
                }
            }
            sched.push(best.1);
            let o = foot_offset(k, best.1);
            *feet.get_mut(best.1) = [flat[o], flat[o + 1], flat[o + 2]];
            holds.push(feet);
        }
        let g = gait::plan_for_footholds(s, &holds).to_flat();
        let rounded = solve(s, t, &sched, &g, false);
        let names: String = sched
            .iter()
            .take(44)
            .map(|f| f.name())
            .collect::<Vec<_>>()
            .join(" ");
        match rounded {
            Some((rc, rf, _)) => {
                let (c2, _, _) = search(s, t, sched.clone(), rf, rc);
                println!("pi {pi:e}: {:?} {} it, cost {cost:.6e}, (10) res {res:.2e}; rounded {rc:.6e} -> search {c2:.6e}\n   {names}", sol.status, sol.stats.iterations);
            }
            None => println!("pi {pi:e}: {:?} {} it, cost {cost:.6e}, (10) res {res:.2e}; rounded failed\n   {names}", sol.status, sol.stats.iterations),
        }
        prev = Some(sol);
    }
}
