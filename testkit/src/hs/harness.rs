//! What the Hock–Schittkowski test files share: the list of problems (one `#[test]`
//! each), one timed solve of a problem, the success criteria, the JSON report and the
//! summary. `nlp/tests/hs.rs` runs the interior-point method, `nlp/tests/sqp_hs.rs` the
//! SQP.
use std::time::Instant;

use nlp::{Compiled, Solution, SolveError, Status};

use super::problems::{self, Built};

/// Calls macro `$then!` with every problem name of the suite, in order: the one list
/// of problems, shared by [`SUITE`] and `hs_suite!` (one `#[test]` each).
#[macro_export]
macro_rules! hs_names {
    ($($then:tt)+) => {
        $($then)+! {
            // bounds only
            hs001, hs002, hs003, hs004, hs005, hs025, hs038, hs045, hs110,
            // equality constraints
            hs006, hs007, hs008, hs009, hs026, hs027, hs028, hs039, hs040, hs042, hs046, hs047,
            hs048, hs049, hs050, hs051, hs052, hs053, hs056, hs061, hs077, hs078, hs079,
            // inequality constraints (hs013: degenerate, no constraint qualification)
            hs010, hs011, hs012, hs013, hs014, hs015, hs016, hs017, hs018, hs019, hs020, hs021,
            hs022, hs023, hs024, hs029, hs030, hs031, hs032, hs033, hs034, hs035, hs036, hs037,
            hs043, hs044, hs064, hs065, hs066, hs076, hs100, hs113,
            // mixed equalities and inequalities
            hs071, hs073, hs080, hs081, hs106, hs108, hs114, hs116, hs118,
        }
    };
}

/// One `#[test]` per problem of the suite (in a module `solve`), each calling the test
/// file's `check(name, build)`; the list itself is [`SUITE`].
#[macro_export]
macro_rules! hs_suite {
    () => {
        $crate::hs_names!($crate::hs_suite);
    };
    ($($name:ident),* $(,)?) => {
        mod solve {
            $(
                #[test]
                fn $name() {
                    super::check(stringify!($name), $crate::hs::problems::$name);
                }
            )*
        }
    };
}

macro_rules! hs_list {
    ($($name:ident),* $(,)?) => {
        /// Every problem of the suite with its name, in order.
        pub const SUITE: &[Entry] = &[$((stringify!($name), problems::$name)),*];
    };
}
hs_names!(hs_list);

/// A problem of the suite: its name and its builder.
pub type Entry = (&'static str, fn() -> Built);

/// IPOPT's default `constr_viol_tol`: the largest final violation a success may have.
pub const CONSTR_VIOL_TOL: f64 = 1e-4;

/// One solve of one problem.
pub struct Run {
    pub name: &'static str,
    pub f_star: f64,
    pub local: &'static [f64],
    pub tol: f64,
    pub compile_seconds: f64,
    pub solve_seconds: f64,
    pub result: Result<Solution, SolveError>,
}

/// Builds, compiles and solves one problem with `solve`, timing compile and solve.
pub fn run(
    name: &'static str,
    build: fn() -> Built,
    solve: impl FnOnce(&mut Compiled) -> Result<Solution, SolveError>,
) -> Run {
    let case = build().unwrap_or_else(|e| panic!("{name}: building the problem failed: {e}"));
    let t0 = Instant::now();
    let mut compiled = case
        .problem
        .compile()
        .unwrap_or_else(|e| panic!("{name}: compile failed: {e}"));
    let compile_seconds = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let result = solve(&mut compiled);
    Run {
        name,
        f_star: case.f_star,
        local: case.local,
        tol: case.tol,
        compile_seconds,
        solve_seconds: t1.elapsed().as_secs_f64(),
        result,
    }
}

/// Error of `f` against an optimal value: relative, or absolute when it is 0.
pub fn objective_error(f: f64, f_star: f64) -> f64 {
    if f_star == 0.0 {
        f.abs()
    } else {
        (f - f_star).abs() / f_star.abs()
    }
}

impl Run {
    /// Which optimum `f` matches within the problem's tolerance: "f*", "local" (a
    /// documented local minimiser), or `None`.
    pub fn matched(&self, f: f64) -> Option<&'static str> {
        if objective_error(f, self.f_star) <= self.tol {
            Some("f*")
        } else if self
            .local
            .iter()
            .any(|&l| objective_error(f, l) <= self.tol)
        {
            Some("local")
        } else {
            None
        }
    }

    /// Success by the suite's criteria: solved, feasible, at a documented optimum.
    pub fn succeeded(&self, sol: &Solution) -> bool {
        sol.status == Status::SolveSucceeded
            && sol.constr_viol <= CONSTR_VIOL_TOL
            && self.matched(sol.objective).is_some()
    }

    /// Asserts success, with a message that says which criterion failed.
    pub fn assert_solved(&self, sol: &Solution) {
        let name = self.name;
        assert_eq!(
            sol.status,
            Status::SolveSucceeded,
            "{name}: status {:?} after {} iterations, f = {}, constr_viol = {:e}, dual_inf = {:e}: {}",
            sol.status,
            sol.stats.iterations,
            sol.objective,
            sol.constr_viol,
            sol.dual_inf,
            sol.message
        );
        assert!(
            sol.constr_viol <= CONSTR_VIOL_TOL,
            "{name}: constraint violation {:e} at the solution",
            sol.constr_viol
        );
        assert!(
            self.matched(sol.objective).is_some(),
            "{name}: f = {:.12e}, published f* = {:.12e} (error {:.1e} > {:.0e}), known local minima {:?}",
            sol.objective,
            self.f_star,
            objective_error(sol.objective, self.f_star),
            self.tol,
            self.local
        );
    }

    /// The report line of docs/performance.md's comparison with IPOPT.
    pub fn json(&self) -> serde_json::Value {
        match &self.result {
            Ok(sol) => serde_json::json!({
                "name": self.name,
                "status": sol.status,
                "iterations": sol.stats.iterations,
                "objective": sol.objective,
                "f_star": self.f_star,
                "matches": self.matched(sol.objective),
                "constr_viol": sol.constr_viol,
                "delta_w_iterations": sol.stats.records.iter().filter(|r| r.regularization > 0.0).count(),
                "delta_c_iterations": sol.stats.records.iter().filter(|r| r.jacobian_regularization() > 0.0).count(),
                "seconds": self.solve_seconds,
                "compile_seconds": self.compile_seconds,
                "message": sol.message,
            }),
            Err(e) => serde_json::json!({
                "name": self.name,
                "status": "Error",
                "error": e.to_string(),
                "f_star": self.f_star,
                "seconds": self.solve_seconds,
                "compile_seconds": self.compile_seconds,
            }),
        }
    }
}

/// Runs every problem of `suite` (each in a fresh thread, as each `#[test]` runs: symx's
/// expression arena is per thread; a problem built after others solves bit-identically,
/// see `nlp/tests/reproducible.rs`, but a fresh thread keeps the arena small), prints one
/// JSON line per problem on stdout and a summary on stderr.
pub fn summary(suite: &[Entry], run_one: fn(&'static str, fn() -> Built) -> Run) {
    let mut iterations = Vec::new();
    let mut failed = Vec::new();
    let mut seconds = 0.0;
    for &(name, build) in suite {
        let run = std::thread::spawn(move || run_one(name, build))
            .join()
            .expect("solve thread");
        seconds += run.solve_seconds;
        match &run.result {
            Ok(sol) if run.succeeded(sol) => iterations.push(sol.stats.iterations),
            _ => failed.push(name),
        }
        println!("{}", run.json());
    }
    iterations.sort_unstable();
    let n = iterations.len();
    let median = match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => iterations[n / 2] as f64,
        _ => (iterations[n / 2 - 1] + iterations[n / 2]) as f64 / 2.0,
    };
    eprintln!(
        "{} problems: {n} solved, median iterations of the solved {median}, total iterations {}, total solve seconds {seconds:.3}; failed: {failed:?}",
        suite.len(),
        iterations.iter().sum::<usize>()
    );
}

/// The problem named `name` (for the diagnostics tests that read names from `HS`).
pub fn find(suite: &[Entry], name: &str) -> (&'static str, fn() -> Built) {
    *suite
        .iter()
        .find(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("no problem named {name}"))
}

/// The names listed in the environment variable `HS` (comma-separated).
pub fn names_from_env() -> Vec<String> {
    std::env::var("HS")
        .unwrap_or_default()
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(String::from)
        .collect()
}
