//! The per-iteration callback (`solve_with_callback`) of both back ends and of
//! `solve_mpcc`: one call per iteration record, the user-space point, stop requests.

mod ipm_common;

use std::ops::ControlFlow;

use ipm_common::{lower, DenseNlp};
use nlp::{
    solve_mpcc_with_callback, Compiled, Ipm, IpmOptions, IterationRecord, IterationView,
    MpccBackend, MpccOptions, PhaseLabel, Problem, Relation, Solution, Sqp, SqpOptions, Status,
};

const INF: f64 = f64::INFINITY;

/// A problem whose solve exercises the un-reduction and unscaling of the view: x₃ is
/// fixed (removed by the interior point), gradients of f and of g₀ are far above
/// `nlp_scaling_max_gradient` = 100 (both scaled), x₂ ends on its bound and one row has
/// no bounds (dropped by the interior point).
fn scaled_with_fixed() -> Compiled {
    let mut pb = Problem::new();
    let x = pb.variable("x", 4).unwrap();
    pb.set_initial(&x, &[1.0, 1.5, 0.2, 2.0]).unwrap();
    pb.set_bounds(&[x[3]], 2.0, 2.0).unwrap();
    pb.set_bounds(&[x[2]], 0.0, INF).unwrap();
    pb.minimize(1000.0 * ((x[0] - 1.0).sq() + (x[1] - 2.0).sq()) + x[0] * x[3] + 10.0 * x[2]);
    pb.subject_to((500.0 * (x[0].sq() + x[1].sq() + x[2].sq())).le(2000.0))
        .unwrap();
    pb.subject_to((x[0] + x[1] + x[2] - x[3]).eq(0.5)).unwrap();
    pb.subject_to((x[0] * x[1]).ge(-INF)).unwrap();
    pb.compile().unwrap()
}

/// Everything the callback saw, per call.
#[derive(Default)]
struct Seen {
    records: Vec<IterationRecord>,
    x: Vec<f64>,
    lambda: Vec<f64>,
    restoration: Vec<bool>,
    phases: Vec<Option<PhaseLabel>>,
}

impl Seen {
    /// A callback recording into `self` that stops at iteration `stop_at`.
    fn watch(
        &mut self,
        stop_at: Option<usize>,
    ) -> impl FnMut(&IterationView<'_>) -> ControlFlow<()> + '_ {
        move |v| {
            self.records.push(*v.record());
            self.x.clear();
            self.x.extend_from_slice(v.x());
            self.lambda.clear();
            self.lambda.extend_from_slice(v.lambda());
            self.restoration.push(v.in_restoration());
            self.phases.push(v.phase());
            assert_eq!(v.iter(), v.record().iter);
            if Some(v.iter()) == stop_at {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Backend {
    Ipm,
    /// The SQP from the problem's guess (`cold_start_ipm` off).
    SqpAlone,
    /// The default SQP: the IPM's solve, then the SQP from its solution; the callback
    /// sees both, numbered on.
    Sqp,
}

fn solve(b: Backend, c: &mut Compiled, seen: &mut Seen, stop_at: Option<usize>) -> Solution {
    let sqp = |cold_start_ipm| {
        Sqp::new(SqpOptions {
            cold_start_ipm,
            ..SqpOptions::default()
        })
    };
    match b {
        Backend::Ipm => Ipm::new(IpmOptions::default())
            .solve_with_callback(c, seen.watch(stop_at))
            .unwrap(),
        Backend::SqpAlone => sqp(false)
            .solve_with_callback(c, seen.watch(stop_at))
            .unwrap(),
        Backend::Sqp => sqp(true)
            .solve_with_callback(c, seen.watch(stop_at))
            .unwrap(),
    }
}

fn assert_last_point(seen: &Seen, sol: &Solution, what: &str) {
    assert_eq!(seen.x, sol.x, "{what}: x of the last call vs the solution");
    assert_eq!(seen.lambda.len(), sol.lambda.len());
    for (a, b) in seen.lambda.iter().zip(&sol.lambda) {
        assert!(
            (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
            "{what}: λ of the last call {:?} vs the solution {:?}",
            seen.lambda,
            sol.lambda
        );
    }
}

#[test]
fn called_once_per_iteration_with_the_user_point() {
    for b in [Backend::Ipm, Backend::SqpAlone, Backend::Sqp] {
        let mut c = scaled_with_fixed();
        let mut seen = Seen::default();
        let sol = solve(b, &mut c, &mut seen, None);
        assert_eq!(sol.status, Status::SolveSucceeded, "{b:?}: {}", sol.message);
        assert!(sol.stats.obj_scaling < 1.0, "{b:?}: scaling inactive");
        assert_eq!(sol.stats.restoration_iterations, 0);
        assert_eq!(seen.records.len(), sol.stats.iterations + 1, "{b:?}");
        assert_eq!(seen.records, sol.stats.records, "{b:?}");
        for (k, r) in seen.records.iter().enumerate() {
            assert_eq!(r.iter, k);
        }
        assert_eq!(seen.x.len(), 4);
        assert_eq!(seen.x[3], 2.0, "{b:?}: the fixed variable");
        assert!(seen.phases.iter().all(Option::is_none));
        if let Backend::Sqp = b {
            // The SQP's start is not reported (the IPM's last row stands for it): when
            // the SQP stops there, its x is the IPM's clamped into the bounds, which the
            // IPM may leave by its bound relaxation (1e-8 relative: IPOPT's default).
            for (a, b) in seen.x.iter().zip(&sol.x) {
                assert!((a - b).abs() <= 1e-8 * (1.0 + b.abs()), "{a} vs {b}");
            }
            assert!(sol.stats.start_iterations > 0);
        } else {
            assert_last_point(&seen, &sol, &format!("{b:?}"));
        }
        // The solution is what we think it is: x₂ on its bound, λ of the sum row ≠ 0.
        assert!(sol.x[2].abs() < 1e-7, "{b:?}: {:?}", sol.x);
        assert!(sol.lambda[1].abs() > 1.0, "{b:?}: {:?}", sol.lambda);
    }
}

#[test]
fn stop_request_ends_the_solve_at_that_iteration() {
    for b in [Backend::Ipm, Backend::SqpAlone, Backend::Sqp] {
        let full = solve(b, &mut scaled_with_fixed(), &mut Seen::default(), None);
        let n = full.stats.iterations;
        assert!(n >= 2, "{b:?}: {n} iterations");
        // The callback runs before the convergence test: even the last iterate can be
        // stopped (IPOPT's order).
        for k in [0, 1, n / 2, n] {
            let mut c = scaled_with_fixed();
            let mut seen = Seen::default();
            let sol = solve(b, &mut c, &mut seen, Some(k));
            assert_eq!(sol.status, Status::UserRequestedStop, "{b:?} k={k}");
            assert!(!sol.status.is_success());
            assert_eq!(sol.stats.iterations, k, "{b:?} k={k}");
            assert_eq!(seen.records.len(), k + 1);
            assert_eq!(seen.records, sol.stats.records, "{b:?} k={k}");
            assert_last_point(&seen, &sol, &format!("{b:?} stopped at {k}"));
        }
    }
}

#[test]
fn warm_start_with_callback() {
    let mut c = scaled_with_fixed();
    let ipm = Ipm::default();
    let first = ipm.solve(&mut c).unwrap();
    let mut seen = Seen::default();
    let again = ipm
        .solve_warm_with_callback(&mut c, &first, seen.watch(None))
        .unwrap();
    assert_eq!(seen.records, again.stats.records);
    let sqp = Sqp::default();
    let mut seen = Seen::default();
    let again = sqp
        .solve_warm_with_callback(&mut c, &first, seen.watch(None))
        .unwrap();
    assert_eq!(seen.records, again.stats.records);
    assert_last_point(&seen, &again, "sqp warm");
}

/// The Wächter–Biegler example from (−8, 1, 1) needs the restoration phase, which ends at
/// a point of local infeasibility as IPOPT's does (tests/ipm_mechanisms.rs): restoration
/// iterations are reported too, marked.
fn wachter_biegler() -> DenseNlp {
    DenseNlp::new(
        vec![-INF, 0.0, 0.0],
        vec![INF, INF, INF],
        vec![0.0, 0.0],
        vec![0.0, 0.0],
        vec![-8.0, 1.0, 1.0],
        Box::new(|x| x[0]),
        Box::new(|_, g| {
            g.copy_from_slice(&[1.0, 0.0, 0.0]);
        }),
        Box::new(|x, g| {
            g[0] = x[0] * x[0] - x[1] - 1.0;
            g[1] = x[0] - x[2] - 0.5;
        }),
        Box::new(|x, j| {
            j.copy_from_slice(&[2.0 * x[0], 1.0, -1.0, 0.0, 0.0, -1.0]);
        }),
        Box::new(|_, _, l, h| {
            h.iter_mut().for_each(|v| *v = 0.0);
            h[lower(3, 0, 0)] = 2.0 * l[0];
        }),
    )
}

#[test]
fn restoration_iterations_are_reported_and_can_be_stopped() {
    let mut seen = Seen::default();
    let sol = Ipm::default()
        .solve_with_callback(&mut wachter_biegler(), seen.watch(None))
        .unwrap();
    assert_eq!(
        sol.status,
        Status::InfeasibleProblemDetected,
        "{}",
        sol.message
    );
    assert_eq!(seen.records, sol.stats.records);
    let first_resto = seen
        .restoration
        .iter()
        .position(|&r| r)
        .expect("restoration");
    // One call per record and one record per iteration number (IPOPT's convention: the
    // iteration whose line search failed is the restoration phase's first row, "kr" with
    // alpha_pr char 'R'), plus row 0.
    assert_eq!(seen.records.len(), sol.stats.iterations + 1);
    for (k, r) in seen.records.iter().enumerate() {
        assert_eq!(r.iter, k);
    }
    let entries: Vec<_> = (1..seen.records.len())
        .filter(|&k| seen.restoration[k] && !seen.restoration[k - 1])
        .collect();
    assert!(!entries.is_empty());
    for &k in &entries {
        assert_eq!(seen.records[k].alpha_pr_char, 'R');
    }
    // The last call shows the restoration iterate; the solve ends there. (Its λ are the
    // restoration problem's, −500 and −1000 here, while `Solution::lambda` holds the
    // original problem's multipliers at that point, −1/3 and −4/3: not compared.)
    assert_eq!(
        seen.x, sol.x,
        "restoration problem: x of the last call vs the solution"
    );

    // Stop at the first restoration row: the point is the restoration iterate's x.
    let mut stop = Seen::default();
    let at = seen.records[first_resto].iter;
    let sol = Ipm::default()
        .solve_with_callback(&mut wachter_biegler(), |v: &IterationView<'_>| {
            stop.x = v.x().to_vec();
            stop.records.push(*v.record());
            if v.in_restoration() && v.iter() == at {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .unwrap();
    assert_eq!(sol.status, Status::UserRequestedStop);
    assert!(stop.records.last().unwrap().restoration);
    assert_eq!(stop.records, sol.stats.records);
    assert_eq!(stop.x, sol.x);
}

/// 0 ≤ x ⊥ y ≥ 0, min (x − 1)² + (y − 1)²: two phases per back end at least (first
/// phase, exact final phase), labelled in the view.
fn mpcc_problem() -> Problem {
    let mut pb = Problem::new();
    let v = pb.variable("v", 2).unwrap();
    pb.set_initial(&v, &[0.5, 0.4]).unwrap();
    pb.minimize((v[0] - 1.0).sq() + (v[1] - 1.0).sq());
    pb.complementarity("xy", v[0], v[1]).unwrap();
    pb
}

#[test]
fn mpcc_phases_are_labelled() {
    for backend in [MpccBackend::Sqp, MpccBackend::Ipm] {
        let pb = mpcc_problem();
        let mut seen = Seen::default();
        let sol = solve_mpcc_with_callback(&pb, backend, &MpccOptions::default(), seen.watch(None))
            .unwrap();
        assert!(sol.solution.status.is_success(), "{backend:?}");
        let calls: usize = sol.phases.iter().map(|p| p.iterations + 1).sum();
        assert_eq!(seen.records.len(), calls, "{backend:?}");
        let mut at = 0;
        for (i, p) in sol.phases.iter().enumerate() {
            for k in 0..=p.iterations {
                let label = seen.phases[at].expect("labelled");
                assert_eq!((label.index, label.kind), (i, p.kind), "{backend:?}");
                assert_eq!(label.penalty, p.penalty);
                assert_eq!(seen.records[at].iter, k);
                at += 1;
            }
        }
        assert_eq!(sol.phases.last().unwrap().kind, "final");
        assert_last_point(&seen, &sol.solution, &format!("mpcc {backend:?}"));

        // A stop in the first phase ends the driver there.
        let mut n = 0;
        let stopped = solve_mpcc_with_callback(&pb, backend, &MpccOptions::default(), |_| {
            n += 1;
            if n == 2 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .unwrap();
        assert_eq!(stopped.solution.status, Status::UserRequestedStop);
        assert_eq!(stopped.phases.len(), 1);
        assert_eq!(stopped.iterations, 1);
    }
}
