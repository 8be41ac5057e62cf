//! Issue 20 item 7: optional motion limits (the scenario's `motion` table).
//!
//! - unset, the scenario (and so the model and every solution file) is the spec's;
//! - bad values are refused with the field named;
//! - on flat ground (`crawl-flat.toml`) the unlimited plan lowers a CoM to 0.08 m and
//!   moves one 0.78 m in one transition; with `body_height_min = 0.45` and
//!   `com_travel_max = 0.3` the plan changes, is `solved`, and satisfies both limits
//!   (recomputed here from the plan's numbers, and by the binary's `check`);
//! - the checker rejects the unlimited plan against those limits, naming them.

use gap_crossing::check;
use gap_crossing::scenario::{Biped, MotionLimits, Scenario};
use gap_crossing::solve::{self, Settings};
use gap_crossing::status::StatusKind;
use std::path::Path;

mod common;
use common::run;

fn flat() -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/crawl-flat.toml");
    Scenario::load(&path).unwrap()
}

const LIMITS: MotionLimits = MotionLimits {
    body_height_min: Some(0.45),
    body_height_max: None,
    com_travel_max: Some(0.3),
};

/// The lowest CoM height above the (flat, z = 0) ground from stance 2 on, and the
/// longest CoM travel of a transition.
fn extremes(file: &gap_crossing::plan::SolutionFile) -> (f64, f64) {
    let st = &file.stances;
    let low = st[1..]
        .iter()
        .flat_map(|s| Biped::ALL.map(|j| s.com.get(j)[2]))
        .fold(f64::INFINITY, f64::min);
    let travel = st
        .windows(2)
        .flat_map(|w| {
            Biped::ALL.map(|j| {
                let (a, b) = (w[0].com.get(j), w[1].com.get(j));
                (0..3).map(|d| (a[d] - b[d]).powi(2)).sum::<f64>().sqrt()
            })
        })
        .fold(0.0, f64::max);
    (low, travel)
}

#[test]
fn unset_limits_leave_the_scenario_unchanged_and_bad_ones_are_refused() {
    let s = Scenario::default();
    assert!(s.motion.is_unset());
    let v = serde_json::to_value(&s).unwrap();
    assert!(v.get("motion").is_none(), "no `motion` key when unset");
    let mut t = Scenario::default();
    t.apply_overrides(&["motion.com_travel_max=0.2", "motion.body_height_max=0.7"])
        .unwrap();
    assert_eq!(t.motion.com_travel_max, Some(0.2));
    assert_eq!(t.motion.body_height_max, Some(0.7));
    t.validate().unwrap();
    t.apply_overrides(&["motion.body_height_min=0.8"]).unwrap();
    let e = t.validate().unwrap_err().to_string();
    assert!(
        e.contains("motion.body_height_min") && e.contains("0.7"),
        "{e}"
    );
    let mut u = Scenario::default();
    u.apply_overrides(&["motion.com_travel_max=-1"]).unwrap();
    let e = u.validate().unwrap_err().to_string();
    assert!(e.contains("motion.com_travel_max"), "{e}");
}

#[test]
fn binding_limits_change_the_plan_and_the_checker_enforces_them() {
    let free = flat();
    let o = solve::plan(&free, &Settings::default()).unwrap();
    assert_eq!(o.status.kind(), StatusKind::Solved, "{}", o.status);
    let (low, travel) = extremes(&o.file);
    // Both limits bind: the unlimited plan breaks them.
    assert!(low < 0.45 - 0.1 && travel > 0.3 + 0.1, "{low} {travel}");

    // The checker rejects the unlimited plan under the limits, naming each.
    let mut judged = o.file.clone();
    judged.scenario.motion = LIMITS;
    let report = check::check(&judged);
    let names: Vec<String> = report
        .violations
        .iter()
        .filter(|v| v.equation == "motion")
        .map(|v| v.name.clone())
        .collect();
    assert!(
        names
            .iter()
            .any(|n| n.contains("motion.body_height_min = 0.45"))
            && names
                .iter()
                .any(|n| n.contains("motion.com_travel_max = 0.3")),
        "{names:?}"
    );

    // With the limits the plan changes and keeps them.
    let mut limited = flat();
    limited.motion = LIMITS;
    let o = solve::plan(&limited, &Settings::default()).unwrap();
    assert_eq!(o.status.kind(), StatusKind::Solved, "{}", o.status);
    let (low, travel) = extremes(&o.file);
    // The checker's tolerance, 1e-6 m.
    assert!(low >= 0.45 - 1e-6 && travel <= 0.3 + 1e-6, "{low} {travel}");
    let dir = common::fresh_dir("motion_limits", "limited");
    let path = dir.join("solution.json");
    o.file.write(&path).unwrap();
    let out = run(&["check", path.to_str().unwrap(), "--goal", "required"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}
