//! Solution files: round trips bit for bit, a stored fixture (format version 1) that a
//! format change breaks, and the refusal of other versions and of non-finite numbers.
use nlp::{Ipm, IpmOptions, Problem, Relation, Solution, SolutionFileError};

const FIXTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/solution_v1.json"
);

/// Hock–Schittkowski problem 71 (IPOPT's tutorial problem).
fn solve_hs071() -> Solution {
    let mut pb = Problem::new();
    let x = pb.variable("x", 4).unwrap();
    pb.set_bounds(&x, &[1.0; 4], &[5.0; 4]).unwrap();
    pb.set_initial(&x, &[1.0, 5.0, 5.0, 1.0]).unwrap();
    pb.minimize(x[0] * x[3] * (x[0] + x[1] + x[2]) + x[2]);
    pb.subject_to((x[0] * x[1] * x[2] * x[3]).ge(25.0)).unwrap();
    pb.subject_to(x.sumsqr().eq(40.0)).unwrap();
    Ipm::new(IpmOptions::default())
        .solve(&mut pb.compile().unwrap())
        .unwrap()
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|a| a.to_bits()).collect()
}

/// Everything but the wall-clock timings, bit for bit.
fn assert_same(a: &Solution, b: &Solution) {
    assert_eq!(a.status, b.status);
    for (p, q) in [
        (&a.x, &b.x),
        (&a.lambda, &b.lambda),
        (&a.z_l, &b.z_l),
        (&a.z_u, &b.z_u),
        (&a.g, &b.g),
    ] {
        assert_eq!(bits(p), bits(q));
    }
    assert_eq!(
        bits(&[a.objective, a.constr_viol, a.dual_inf, a.compl]),
        bits(&[b.objective, b.constr_viol, b.dual_inf, b.compl])
    );
    assert_eq!(a.stats.iterations, b.stats.iterations);
    assert_eq!(a.stats.records, b.stats.records);
}

#[test]
fn round_trip_is_bit_identical() {
    let sol = solve_hs071();
    assert!(sol.status.is_success());
    let path = std::env::temp_dir().join(format!("symnlp_solution_{}.json", std::process::id()));
    sol.save(&path).unwrap();
    let back = Solution::load(&path).unwrap();
    std::fs::remove_file(&path).ok();
    assert_same(&sol, &back);
    assert_eq!(back, sol);
}

#[test]
fn stored_fixture_reads_and_matches_a_fresh_solve() {
    // Regenerate (after an intended format change, with a new version) by running this
    // test with SYMNLP_WRITE_FIXTURE=1.
    if std::env::var_os("SYMNLP_WRITE_FIXTURE").is_some() {
        solve_hs071().save(FIXTURE).unwrap();
    }
    let stored = Solution::load(FIXTURE).unwrap();
    // HS071's optimum f* = 17.0140173 (Hock & Schittkowski 1981).
    assert!((stored.objective - 17.0140173).abs() < 1e-6);
    assert_same(&stored, &solve_hs071());
}

#[test]
fn other_versions_and_formats_are_refused() {
    let text = std::fs::read_to_string(FIXTURE).unwrap();
    let v2 = text.replacen("\"version\": 1", "\"version\": 2", 1);
    assert_ne!(v2, text);
    let err = Solution::from_json(&v2).unwrap_err();
    assert!(matches!(
        err,
        SolutionFileError::Version {
            found: 2,
            expected: 1
        }
    ));
    let msg = err.to_string();
    assert!(
        msg.contains("version 2") && msg.contains("version 1"),
        "{msg}"
    );
    let other = text.replacen("symnlp.solution", "symnlp.function", 1);
    assert!(Solution::from_json(&other)
        .unwrap_err()
        .to_string()
        .contains("symnlp.function"));
    assert!(matches!(
        Solution::from_json("[1, 2]"),
        Err(SolutionFileError::Format { .. })
    ));
    let mut sol = solve_hs071();
    sol.x[0] = f64::NAN;
    assert!(matches!(sol.to_json(), Err(SolutionFileError::NonFinite)));
    assert!(matches!(
        Solution::load("/nonexistent/symnlp.json"),
        Err(SolutionFileError::Io { .. })
    ));
}
