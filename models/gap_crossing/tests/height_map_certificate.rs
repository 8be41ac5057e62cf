//! Issue 20 item 2 on height maps: a certificate, before solving, that every path from
//! start to goal crosses ground no foot can stand on wider than the step reach
//! (`gap_crossing::footing`; docs/gap-crossing.md, "Certificates").
//!
//! The map: flat at 0 up to x = 2.2 m, a smootherstep ramp up to `rise` over `run`, flat
//! beyond, over x ∈ [−1, 9], y ∈ [−1, 2] every 0.05 m, with μ = 0.1 (below it, the
//! friction test is tried only when F_thr (1 + μ) > μ W = 89 N).
//! - a 0.6 m rise over 0.6 m with F_thr = 150 N: the cells of slope ≥ 1.46 cannot hold a
//!   foot; the ground left is split by them 0.40 m apart (3-D), beyond the 0.3 m reach:
//!   `gap_not_crossable` before any solve, exit 3, with the numbers in the message and in
//!   `solution.json`;
//! - just inside the bound, no certificate: the same map with F_thr = 125 N (no cell
//!   excluded) and with F_thr = 130 N (two cell columns excluded, but the ground on both
//!   sides within the reach of each other); and a 1 m rise over 0.3 m with the spec's
//!   μ = 0.5 and F_thr = 10 N (nothing is excluded with the spec's friction).

use gap_crossing::footing;
use gap_crossing::reach;
use gap_crossing::scenario::{Foot, Scenario, TerrainSpec};
use gap_crossing::terrain::HeightMap;

mod common;
use common::run;

const SPACING: f64 = 0.05;

/// The ramp's heights, one row per y (61), one column per x (201).
fn heights(rise: f64, run: f64) -> Vec<Vec<f64>> {
    // Smootherstep 6t⁵ − 15t⁴ + 10t³ from x = 2.2 over `run` (largest slope
    // 1.875·rise/run).
    let h = |x: f64| {
        let t = ((x - 2.2) / run).clamp(0.0, 1.0);
        rise * t * t * t * (10.0 + t * (6.0 * t - 15.0))
    };
    (0..61)
        .map(|_| (0..201).map(|i| h(-1.0 + SPACING * i as f64)).collect())
        .collect()
}

/// The default scenario on the ramp, goal CoMs 0.5 m above the top, μ = 0.1.
fn ramp(rise: f64, run: f64, f_thr: f64) -> Scenario {
    let mut s = Scenario {
        terrain: TerrainSpec::HeightMap {
            file: "ramp.csv".into(),
            origin: [-1.0, -1.0],
            spacing: [SPACING, SPACING],
            heights: heights(rise, run),
        },
        ..Scenario::default()
    };
    s.goal.b[2] = rise + 0.5;
    s.goal.f[2] = rise + 0.5;
    s.friction.mu = 0.1;
    s.friction.f_thr = f_thr;
    s.validate().unwrap();
    s
}

fn unstandable(s: &Scenario) -> Option<footing::Unstandable> {
    let TerrainSpec::HeightMap {
        origin,
        spacing,
        heights,
        ..
    } = &s.terrain
    else {
        unreachable!("a height map")
    };
    let map = HeightMap::new(*origin, *spacing, heights.clone());
    footing::unstandable_cells(s, &map).map(|(_, u)| u)
}

/// The certified ramp: 240 cells (4 columns of 60) excluded, from slope 1.4586 on; the
/// back right foot can stand only up to x = 2.4 m; the next standable ground is at least
/// 0.4015 m away; its goal CoM (3, 0.5, 1.1) is at least 1.1440 m from the ground it can
/// reach (it must end within ρ = 0.7571 m). The numbers are those of this map, printed by
/// the certificate; what the test pins is their meaning: slope bound above the slope at
/// which q + R c > R W / F_thr starts, exit distance ≥ reach, nearest > ρ.
#[test]
fn a_ramp_too_steep_for_the_friction_is_certified() {
    let s = ramp(0.6, 0.6, 150.0);
    let u = unstandable(&s).expect("cells excluded");
    assert_eq!((u.cells, u.unstandable), (12000, 240), "{u}");
    // The smootherstep's largest slope is 1.875: the excluded cells are steep ones.
    assert!(u.least_slope > 1.4 && u.least_slope < 1.875, "{u}");
    // R is at least μ (flat ground pushes back with μ per newton), and not much more
    // (the ramp's foot dips by Catmull-Rom overshoot).
    assert!(u.ratio >= 0.1 && u.ratio < 0.12, "{u}");
    let c = reach::uncrossable(&s).expect("certificate");
    assert_eq!(c.foot, Foot::BR, "{c}");
    assert!(c.unstandable.is_some());
    let exit = c.shortest_exit.unwrap();
    assert!((0.3..0.45).contains(&exit), "{c}");
    assert!(c.nearest > c.need_within, "{c}");
    assert!(c.reachable_x[1] < 2.5, "{c}");
    let msg = c.to_string();
    for part in [
        "240 of the height map's 12000 cells cannot hold a foot",
        "F_thr = 150 N with μ = 0.1",
        "not less than the step reach 0.3000 m",
    ] {
        assert!(msg.contains(part), "{msg}");
    }
}

/// Just inside the bound: nothing certified.
#[test]
fn just_inside_the_bound_nothing_is_certified() {
    // F_thr = 125 N: no cell fails the friction test.
    let s = ramp(0.6, 0.6, 125.0);
    assert_eq!(unstandable(&s), None);
    assert_eq!(reach::uncrossable(&s), None);
    // F_thr = 130 N: two columns fail it, but the ground either side is within the reach.
    let s = ramp(0.6, 0.6, 130.0);
    let u = unstandable(&s).expect("cells excluded");
    assert_eq!(u.unstandable, 120, "{u}");
    assert_eq!(reach::uncrossable(&s), None);
    // The spec's friction on a much steeper ramp (slope up to 6.25): the test is not
    // even tried (F_thr (1 + μ) = 15 N ≤ μ W = 490.5 N), and nothing is certified.
    let mut s = ramp(1.0, 0.3, 10.0);
    s.friction.mu = 0.5;
    assert_eq!(unstandable(&s), None);
    assert_eq!(reach::uncrossable(&s), None);
}

/// The CLI refuses the certified ramp before solving: exit 3, the status and the numbers
/// in the solution file, 0 iterations.
#[test]
fn the_cli_reports_the_certificate_with_exit_code_3() {
    let dir = common::fresh_dir("height_map_certificate", "cli");
    let csv: String = heights(0.6, 0.6)
        .iter()
        .map(|row| {
            let cols: Vec<String> = row.iter().map(|v| format!("{v:?}")).collect();
            cols.join(",") + "\n"
        })
        .collect();
    std::fs::write(dir.join("ramp.csv"), csv).unwrap();
    let toml = "[terrain]\nkind = \"height_map\"\nfile = \"ramp.csv\"\norigin = [-1.0, -1.0]\n\
                spacing = [0.05, 0.05]\n\n[goal]\nB = [3.0, 0.5, 1.1]\nF = [5.0, 0.5, 1.1]\n\n\
                [friction]\nmu = 0.1\nf_thr = 150\n";
    std::fs::write(dir.join("ramp.toml"), toml).unwrap();
    let out_dir = dir.join("out");
    let out = run(&[
        "solve",
        "--scenario",
        dir.join("ramp.toml").to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("gap not crossable: 240 of the height map's 12000 cells"),
        "{stderr}"
    );
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("solution.json")).unwrap())
            .unwrap();
    assert_eq!(file["solver"]["status"], "gap_not_crossable");
    assert_eq!(file["solver"]["iterations"], 0);
    let reason = file["solver"]["reason"].as_str().unwrap();
    assert!(
        reason.contains("cannot hold a foot") && reason.contains("step reach 0.3000 m"),
        "{reason}"
    );
}
