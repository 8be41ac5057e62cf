//! The golden record: status, iteration count and objective of every reference solve,
//! kept in `tests/golden/solves.json` and compared on every run. It is the safety net of
//! refactorings of the solvers: a change that is meant to leave the algorithms alone
//! must leave every record unchanged; a change that alters a record is an algorithm
//! change (or a bug fix) and says so in the file's `notes`.
//!
//! Recorded, each solve in a fresh thread (symx's expression arena is per thread, and
//! the node order of a problem built after others differs, see `hs/harness.rs`):
//! - every Hock–Schittkowski problem (`hs/problems.rs`) on both back ends, default
//!   options (`hs/ipm/<name>`, `hs/sqp/<name>`);
//! - every MPCC case (`mpcc/problems.rs`) through `solve_mpcc` on both back ends, total
//!   iterations over the phases (`mpcc/<backend>/<name>`);
//! - the SOCP problems (`socp/problems.rs`) on both back ends (`socp/<backend>/<name>`);
//! - the race car (examples/src/race_car.rs, N = 100, IPM) (`race_car/ipm/n100`);
//! - the gap-crossing planner's default scenario (free gait) and its crawl gait, IPM
//!   (`planner/ipm/free`, `planner/ipm/crawl`).
//!
//! Comparison: status and iteration count exactly; the objective to a relative
//! tolerance of [`OBJECTIVE_RTOL`] (see there why).
//!
//! Regenerating the record after an intentional change (then add a line to `notes`
//! in the file saying what changed and why, and commit both):
//!
//! ```text
//! GOLDEN_UPDATE=1 cargo test --release --test golden
//! ```
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Mutex;

use serde_json::{json, Value};
use symnlp::nlp;

use nlp::{
    solve_mpcc, Compiled, Ipm, IpmOptions, MpccBackend, MpccOptions, Solution, SolveError, Sqp,
    SqpOptions,
};

use testkit::hs::{harness, SUITE};
use testkit::mpcc as mpcc_problems;
use testkit::mpcc_names;
use testkit::socp as socp_problems;

use symnlp_examples::race_car;

/// Relative tolerance on the objective, relative to max(1, |f|). The iteration count
/// pins the path; the objective catches an end point that differs at the same count.
/// A refactoring may reorder floating-point sums (an ulp-level change per operation);
/// through a converging Newton-type method that stays orders of magnitude below 1e-9
/// relative, while a different local solution, or a different last iterate, moves f by
/// far more on these problems (the solvers stop at a scaled KKT error of 1e-8). Solves
/// are meant to be bit-identical from run to run, so the slack is for refactorings only.
const OBJECTIVE_RTOL: f64 = 1e-9;

/// One record: what a solve returned.
#[derive(Clone, Debug, PartialEq)]
struct Record {
    status: String,
    iterations: usize,
    objective: f64,
}

/// The file: notes (one line per intentional change) and the records by key.
#[derive(Debug, Default)]
struct Golden {
    notes: Vec<Value>,
    records: BTreeMap<String, Record>,
}

impl Golden {
    fn from_json(v: &Value) -> Golden {
        let records = v["records"]
            .as_object()
            .expect("records")
            .iter()
            .map(|(k, r)| {
                let rec = Record {
                    status: r["status"].as_str().expect("status").to_string(),
                    iterations: r["iterations"].as_u64().expect("iterations") as usize,
                    // NaN (an error) is written as null.
                    objective: r["objective"].as_f64().unwrap_or(f64::NAN),
                };
                (k.clone(), rec)
            })
            .collect();
        Golden {
            notes: v["notes"].as_array().cloned().unwrap_or_default(),
            records,
        }
    }

    fn to_json(&self) -> Value {
        let records: serde_json::Map<String, Value> = self
            .records
            .iter()
            .map(|(k, r)| {
                let rec = json!({
                    "status": r.status,
                    "iterations": r.iterations,
                    "objective": r.objective,
                });
                (k.clone(), rec)
            })
            .collect();
        json!({ "notes": self.notes, "records": records })
    }
}

fn path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden/solves.json")
}

/// Serialises the read-modify-write of the file between the tests of this binary.
static FILE: Mutex<()> = Mutex::new(());

fn load() -> Golden {
    let text = std::fs::read_to_string(path()).unwrap_or_default();
    if text.is_empty() {
        return Golden::default();
    }
    Golden::from_json(&serde_json::from_str(&text).expect("tests/golden/solves.json parses"))
}

fn updating() -> bool {
    std::env::var_os("GOLDEN_UPDATE").is_some_and(|v| v == "1")
}

fn record(sol: &Solution) -> Record {
    Record {
        status: format!("{:?}", sol.status),
        iterations: sol.stats.iterations,
        objective: sol.objective,
    }
}

fn record_of(result: Result<Solution, SolveError>) -> Record {
    match result {
        Ok(sol) => record(&sol),
        Err(e) => Record {
            status: format!("Error: {e}"),
            iterations: 0,
            objective: f64::NAN,
        },
    }
}

/// Runs `solve` in a fresh thread.
fn fresh<T: Send + 'static>(solve: impl FnOnce() -> T + Send + 'static) -> T {
    std::thread::spawn(solve).join().expect("solve thread")
}

/// Compares `got` (one suite: every key starts with `prefix`) with the file, or in
/// update mode replaces the suite's records in the file.
fn compare(prefix: &str, got: BTreeMap<String, Record>) {
    let _lock = FILE.lock().unwrap_or_else(|e| e.into_inner());
    let mut golden = load();
    if updating() {
        golden.records.retain(|k, _| !k.starts_with(prefix));
        golden.records.extend(got);
        let text = serde_json::to_string_pretty(&golden.to_json()).expect("serialises");
        std::fs::create_dir_all(path().parent().unwrap()).unwrap();
        std::fs::write(path(), text + "\n").expect("writes tests/golden/solves.json");
        return;
    }
    let want: BTreeMap<&String, &Record> = golden
        .records
        .iter()
        .filter(|(k, _)| k.starts_with(prefix))
        .collect();
    let mut diffs = Vec::new();
    for (key, g) in &got {
        match want.get(key) {
            None => diffs.push(format!("{key}: not in the record (got {g:?})")),
            Some(w) => {
                let scale = w.objective.abs().max(1.0);
                let same_f = (g.objective - w.objective).abs() <= OBJECTIVE_RTOL * scale
                    || (g.objective.is_nan() && w.objective.is_nan());
                if g.status != w.status || g.iterations != w.iterations || !same_f {
                    diffs.push(format!(
                        "{key}: recorded {} / {} it / f = {:.15e}, now {} / {} it / f = {:.15e}",
                        w.status, w.iterations, w.objective, g.status, g.iterations, g.objective
                    ));
                }
            }
        }
    }
    for key in want.keys() {
        if !got.contains_key(*key) {
            diffs.push(format!("{key}: recorded but no longer solved"));
        }
    }
    assert!(
        diffs.is_empty(),
        "{} of {} {prefix}* records differ from tests/golden/solves.json (if intended: \
         GOLDEN_UPDATE=1 cargo test --release --test golden, and add a note):\n{}",
        diffs.len(),
        got.len(),
        diffs.join("\n")
    );
}

/// A solve of a compiled problem by one back end.
type SolveFn = fn(&mut Compiled) -> Result<Solution, SolveError>;

fn solve_ipm(c: &mut Compiled) -> Result<Solution, SolveError> {
    Ipm::new(IpmOptions::default()).solve(c)
}

fn solve_sqp(c: &mut Compiled) -> Result<Solution, SolveError> {
    // The SQP alone from the problem's guess: the records guard its own iterations (by
    // default a cold solve starts from the IPM's solution, whose records are hs/ipm's).
    let options = SqpOptions {
        cold_start_ipm: false,
        ..SqpOptions::default()
    };
    Sqp::new(options).solve(c)
}

fn hs(backend: &str, solve: SolveFn) {
    let mut got = BTreeMap::new();
    for &(name, build) in SUITE {
        let rec = fresh(move || record_of(harness::run(name, build, solve).result));
        got.insert(format!("hs/{backend}/{name}"), rec);
    }
    compare(&format!("hs/{backend}/"), got);
}

#[test]
fn hs_ipm() {
    hs("ipm", solve_ipm);
}

#[test]
fn hs_sqp() {
    hs("sqp", solve_sqp);
}

macro_rules! mpcc_list {
    ($($name:ident),* $(,)?) => {
        const MPCC: &[fn() -> mpcc_problems::Case] = &[$(mpcc_problems::$name),*];
    };
}
mpcc_names!(mpcc_list);

#[test]
fn mpcc() {
    let mut got = BTreeMap::new();
    for &case in MPCC {
        for (backend, key) in [(MpccBackend::Sqp, "sqp"), (MpccBackend::Ipm, "ipm")] {
            let (name, rec) = fresh(move || {
                let case = case();
                let rec = match solve_mpcc(&(case.build)(), backend, &MpccOptions::default()) {
                    Ok(s) => Record {
                        iterations: s.iterations,
                        ..record(&s.solution)
                    },
                    Err(e) => Record {
                        status: format!("Error: {e}"),
                        iterations: 0,
                        objective: f64::NAN,
                    },
                };
                (case.name, rec)
            });
            got.insert(format!("mpcc/{key}/{name}"), rec);
        }
    }
    compare("mpcc/", got);
}

#[test]
fn socp() {
    let mut got = BTreeMap::new();
    for &(name, build) in socp_problems::ALL {
        for (key, solve) in [("ipm", solve_ipm as SolveFn), ("sqp", solve_sqp)] {
            let rec = fresh(move || {
                let mut c = build().compile().expect("compiles");
                record_of(solve(&mut c))
            });
            got.insert(format!("socp/{key}/{name}"), rec);
        }
    }
    compare("socp/", got);
}

#[test]
fn race_car() {
    let rec = fresh(|| {
        let (sol, _) = race_car::solve(100, IpmOptions::default()).expect("builds and solves");
        record(&sol)
    });
    compare(
        "race_car/",
        BTreeMap::from([("race_car/ipm/n100".into(), rec)]),
    );
}

#[test]
fn planner() {
    use gap_crossing::scenario::{Gait, Scenario};
    use gap_crossing::solve::{self, Settings};
    let mut got = BTreeMap::new();
    for (gait, key) in [(Gait::Free, "free"), (Gait::Crawl, "crawl")] {
        let rec = fresh(move || {
            let s = Scenario {
                gait,
                ..Scenario::default()
            };
            let out = solve::plan(&s, &Settings::default()).expect("plans");
            Record {
                status: out.file.solver.status,
                iterations: out.file.solver.iterations,
                objective: out.file.solver.objective,
            }
        });
        got.insert(format!("planner/ipm/{key}"), rec);
    }
    compare("planner/", got);
}
