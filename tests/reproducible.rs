//! Same input, same iterates: a problem built, compiled and solved twice gives
//! bit-identical iterates — twice in one thread (the second build meets the first's
//! nodes in symx's per-thread arena), and in two threads at once (other heap addresses,
//! concurrent allocation). Every iterate's x and λ (through the iteration callback) and
//! the final x, λ, z_L, z_U and objective are compared as bit patterns, on both back ends.
//!
//! The problems include hs056, hs061 and hs078, whose SQP outcomes were once observed to
//! change between runs (docs/solvers.md, "Reproducibility").
use std::ops::ControlFlow;

use symnlp::nlp;

use nlp::{Ipm, IpmOptions, IterationView, Solution, SolveError, Sqp, SqpOptions};

#[path = "hs/problems.rs"]
#[allow(dead_code)]
mod problems;

use problems::Built;

/// Bit patterns of everything a solve produced, iterate by iterate.
#[derive(Debug, PartialEq, Eq)]
struct Trace {
    iterates: Vec<Vec<u64>>,
    status: String,
    final_point: Vec<u64>,
}

fn bits(v: &[f64]) -> impl Iterator<Item = u64> + '_ {
    v.iter().map(|x| x.to_bits())
}

#[derive(Clone, Copy, Debug)]
enum Backend {
    Ipm,
    Sqp,
}

fn trace(build: fn() -> Built, backend: Backend) -> Trace {
    let case = build().expect("builds");
    let mut c = case.problem.compile().expect("compiles");
    let mut iterates = Vec::new();
    let cb = |v: &IterationView<'_>| {
        iterates.push(bits(v.x()).chain(bits(v.lambda())).collect());
        ControlFlow::Continue(())
    };
    let sol: Result<Solution, SolveError> = match backend {
        Backend::Ipm => Ipm::new(IpmOptions::default()).solve_with_callback(&mut c, cb),
        Backend::Sqp => Sqp::new(SqpOptions::default()).solve_with_callback(&mut c, cb),
    };
    let sol = sol.expect("solves");
    let final_point = bits(&sol.x)
        .chain(bits(&sol.lambda))
        .chain(bits(&sol.z_l))
        .chain(bits(&sol.z_u))
        .chain([sol.objective.to_bits()])
        .collect();
    Trace {
        iterates,
        status: format!("{:?}", sol.status),
        final_point,
    }
}

fn check(name: &str, build: fn() -> Built, backend: Backend) {
    // Twice in one fresh thread.
    let (a, b) = std::thread::spawn(move || (trace(build, backend), trace(build, backend)))
        .join()
        .expect("solve thread");
    // Twice at once, in two threads.
    let (c, d) = std::thread::scope(|s| {
        let c = s.spawn(|| trace(build, backend));
        let d = s.spawn(|| trace(build, backend));
        (c.join().expect("thread"), d.join().expect("thread"))
    });
    assert!(
        !a.iterates.is_empty(),
        "{name}: the callback saw no iterate"
    );
    for (what, t) in [("same thread", &b), ("thread 1", &c), ("thread 2", &d)] {
        assert_eq!(
            a.status, t.status,
            "{name} {backend:?}: status differs ({what})"
        );
        assert_eq!(
            a.iterates.len(),
            t.iterates.len(),
            "{name} {backend:?}: iteration count differs ({what})"
        );
        if let Some(k) = (0..a.iterates.len()).find(|&k| a.iterates[k] != t.iterates[k]) {
            panic!("{name} {backend:?}: iterate {k} differs ({what})");
        }
        assert_eq!(
            a.final_point, t.final_point,
            "{name} {backend:?}: final point differs ({what})"
        );
    }
}

macro_rules! reproducible {
    ($($name:ident),* $(,)?) => {
        mod ipm { $( #[test] fn $name() { super::check(stringify!($name), super::problems::$name, super::Backend::Ipm); } )* }
        mod sqp { $( #[test] fn $name() { super::check(stringify!($name), super::problems::$name, super::Backend::Sqp); } )* }
    };
}

reproducible!(hs013, hs056, hs061, hs071, hs078, hs116);
