//! Scenario files: defaults, unknown fields, invalid values and their messages.

use gap_crossing::scenario::{Gait, Scenario, ScenarioError};
use std::path::Path;

fn toml(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::parse(text, "toml", Path::new("test.toml"))
}

fn json(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::parse(text, "json", Path::new("test.json"))
}

/// Parses and validates; returns the error message (panics if accepted).
fn rejected(text: &str) -> String {
    let err = match toml(text) {
        Err(e) => e,
        Ok(s) => s.validate().expect_err("scenario should be rejected"),
    };
    err.to_string()
}

#[test]
fn defaults_equal_the_spec_table() {
    let s = Scenario::default();
    assert_eq!(s.n_step, 60);
    assert_eq!((s.masses.b, s.masses.f), (50.0, 50.0));
    assert_eq!(s.gravity, 9.81);
    assert_eq!(s.start.com.b, [0.0, 0.5, 0.5]);
    assert_eq!(s.start.com.f, [2.0, 0.5, 0.5]);
    assert_eq!(s.start.feet.br, [0.0, 0.0, 0.0]);
    assert_eq!(s.start.feet.bl, [0.0, 1.0, 0.0]);
    assert_eq!(s.start.feet.fr, [2.0, 0.0, 0.0]);
    assert_eq!(s.start.feet.fl, [2.0, 1.0, 0.0]);
    assert_eq!(s.goal.b, [3.0, 0.5, 0.5]);
    assert_eq!(s.goal.f, [5.0, 0.5, 0.5]);
    assert_eq!(s.gap.min, 2.25);
    assert_eq!(s.gap.max, 2.35);
    assert_eq!(s.gap.depth, 1.0);
    assert_eq!(s.gap.steepness, 1e6);
    assert_eq!(s.gap.margin, 0.03);
    assert_eq!(s.friction.mu, 0.5);
    assert_eq!(s.friction.f_thr, 10.0);
    assert_eq!(s.weights.com, 1000.0);
    assert_eq!(s.weights.force, 0.001);
    assert_eq!(s.leg_length_sq, 0.5);
    assert_eq!(s.step_radius_sq, 0.09);
    assert_eq!((s.same_side_sq.min, s.same_side_sq.max), (1.0, 9.0));
    assert_eq!((s.same_biped_sq.min, s.same_biped_sq.max), (0.25, 2.25));
    assert_eq!(s.gait, Gait::Free);
    s.validate().expect("the default scenario is valid");
}

/// An empty scenario file is refused (it used to plan the default silently, issue 20);
/// a file naming one value takes the defaults for the rest.
#[test]
fn empty_files_are_refused() {
    for e in [toml("").unwrap_err(), json("{}").unwrap_err()] {
        assert!(e.to_string().contains("sets no value"), "{e}");
    }
    assert_eq!(toml("n_step = 60").unwrap(), Scenario::default());
}

#[test]
fn full_json_round_trip() {
    let s = Scenario::default();
    let text = serde_json::to_string_pretty(&s).unwrap();
    assert_eq!(json(&text).unwrap(), s);
}

#[test]
fn partial_files_keep_other_defaults() {
    let s = toml("n_step = 30\ngait = \"crawl\"\n[goal]\nF = [5.0, 0.7, 0.5]\n").unwrap();
    assert_eq!(s.n_step, 30);
    assert_eq!(s.gait, Gait::Crawl);
    assert_eq!(s.goal.f, [5.0, 0.7, 0.5]);
    assert_eq!(s.goal.b, [3.0, 0.5, 0.5]);
    let s = json(r#"{"gap": {"depth": 2}}"#).unwrap();
    assert_eq!(s.gap.depth, 2.0);
    assert_eq!(s.gap.min, 2.25);
}

#[test]
fn unknown_fields_are_rejected_by_name() {
    let e = toml("n_stpe = 30").unwrap_err().to_string();
    assert!(e.contains("unknown field `n_stpe`"), "{e}");
    let e = toml("[gap]\nwidht = 0.1").unwrap_err().to_string();
    assert!(e.contains("`gap.widht`") && e.contains("margin"), "{e}");
    let e = json(r#"{"start": {"feet": {"XR": [0,0,0]}}}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("`start.feet.XR`"), "{e}");
}

#[test]
fn wrong_types_are_rejected_by_name() {
    let e = toml("[gap]\nmin = \"wide\"").unwrap_err().to_string();
    assert!(
        e.contains("gap.min") && e.contains("expected a number"),
        "{e}"
    );
    let e = toml("n_step = 2.5").unwrap_err().to_string();
    assert!(e.contains("n_step") && e.contains("integer"), "{e}");
    let e = toml("[goal]\nB = [1.0, 2.0]").unwrap_err().to_string();
    assert!(e.contains("goal.B") && e.contains("3 numbers"), "{e}");
    let e = toml("[gap]\nmin = nan").unwrap_err().to_string();
    assert!(e.contains("gap.min") && e.contains("finite"), "{e}");
    let e = toml("gait = \"trot\"").unwrap_err().to_string();
    assert!(e.contains("trot") && e.contains("crawl"), "{e}");
}

#[test]
fn invalid_values_are_rejected_with_field_and_value() {
    let cases: &[(&str, &[&str])] = &[
        ("[masses]\nB = 0.0", &["masses.B", "positive", "0"]),
        ("[masses]\nF = -5.0", &["masses.F", "positive", "-5"]),
        ("[gap]\nmin = 2.4", &["gap.min", "less than gap.max", "2.4"]),
        ("[gap]\nmin = 2.35", &["gap.min", "less than gap.max"]),
        ("n_step = 1", &["n_step", "at least 2", "1"]),
        ("[friction]\nmu = 0.0", &["friction.mu", "positive"]),
        (
            "[friction]\nmu = -0.1",
            &["friction.mu", "positive", "-0.1"],
        ),
        (
            "[gap]\nmargin = -0.01",
            &["gap.margin", "negative", "-0.01"],
        ),
        ("gravity = inf", &["gravity", "finite"]),
    ];
    for (text, needles) in cases {
        let msg = rejected(text);
        for n in *needles {
            assert!(msg.contains(n), "for {text:?}: message {msg:?} lacks {n:?}");
        }
    }
}

#[test]
fn non_finite_values_set_in_code_are_rejected() {
    let mut s = Scenario::default();
    s.goal.b[1] = f64::NAN;
    let e = s.validate().unwrap_err().to_string();
    assert!(e.contains("goal.B[1]") && e.contains("finite"), "{e}");
}

#[test]
fn start_violating_the_equations_is_rejected() {
    // (11): CoM too high above its feet.
    let e = rejected("[start.com]\nB = [0.0, 0.5, 0.6]");
    assert!(
        e.contains("(11)") && e.contains("start.feet.BR") && e.contains("foot BR"),
        "{e}"
    );
    // (3): a foot in the air.
    let e = rejected("[start.feet]\nBL = [0.0, 1.0, 0.01]");
    assert!(
        e.contains("(3)") && e.contains("start.feet.BL") && e.contains("0.01"),
        "{e}"
    );
    // (6)/(7): front feet too far ahead (also breaks nothing else: CoM moved with them).
    let e = rejected(
        "[start.com]\nF = [4.5, 0.5, 0.5]\n[start.feet]\nFR = [4.5, 0.0, 0.0]\nFL = [4.5, 1.0, 0.0]\n[gap]\nmin = 5.0\nmax = 5.1",
    );
    assert!(e.contains("(6)") && e.contains("(7)"), "{e}");
    // (8): back feet too close; keep (11) satisfied by lowering nothing: CoM at the
    // midpoint height sqrt(0.5 - 0.2^2) = sqrt(0.46).
    let z = 0.46f64.sqrt();
    let e = rejected(&format!(
        "[start.com]\nB = [0.0, 0.5, {z}]\n[start.feet]\nBR = [0.0, 0.3, 0.0]\nBL = [0.0, 0.7, 0.0]"
    ));
    assert!(e.contains("(8)") && !e.contains("(11)"), "{e}");
    // A foot in the widened gap (the gap moved under the front feet).
    let e = rejected("[gap]\nmin = 1.98\nmax = 2.1\ndepth = 0.0");
    assert!(
        e.contains("keep-out") && e.contains("start.feet.FR") && e.contains("FL"),
        "{e}"
    );
}

#[test]
fn overrides_use_dotted_paths() {
    let mut s = Scenario::default();
    s.apply_overrides(&[
        "gap.min=2.0",
        "n_step=30",
        "gait=crawl",
        "start.feet.BR[1]=0.0",
    ])
    .unwrap();
    assert_eq!((s.gap.min, s.n_step, s.gait), (2.0, 30, Gait::Crawl));
    let e = s.apply_overrides(&["gap.minn=1"]).unwrap_err().to_string();
    assert!(e.contains("gap.minn"), "{e}");
    let e = s.apply_overrides(&["gap.min"]).unwrap_err().to_string();
    assert!(e.contains("key=value"), "{e}");
    // Beyond f64's range: named as such, not taken for text.
    let e = s
        .apply_overrides(&["gap.min=1e400"])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("gap.min") && e.contains("finite") && e.contains("range"),
        "{e}"
    );
    let e = s
        .apply_overrides(&["gap.min=-1e999"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("range"), "{e}");
}

#[test]
fn files_by_extension() {
    let dir = std::env::temp_dir().join(format!("gap_crossing_scn_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let t = dir.join("s.toml");
    std::fs::write(&t, "n_step = 12").unwrap();
    assert_eq!(Scenario::load(&t).unwrap().n_step, 12);
    let j = dir.join("s.json");
    std::fs::write(&j, r#"{"n_step": 13}"#).unwrap();
    assert_eq!(Scenario::load(&j).unwrap().n_step, 13);
    let y = dir.join("s.yaml");
    std::fs::write(&y, "n_step: 13").unwrap();
    assert!(Scenario::load(&y)
        .unwrap_err()
        .to_string()
        .contains("extension"));
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "n_step = 1").unwrap();
    assert!(Scenario::load(&bad)
        .unwrap_err()
        .to_string()
        .contains("n_step"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn unknown_fields_in_nested_tables_name_the_full_path() {
    let cases: &[(&str, &str, &[&str])] = &[
        // (file text, unknown path, fields the message must offer)
        (
            "[start.com]\nC = [0.0, 0.5, 0.5]",
            "start.com.C",
            &["B", "F"],
        ),
        (
            "[start.feet]\nBX = [0.0, 0.0, 0.0]",
            "start.feet.BX",
            &["BR", "FL"],
        ),
        ("[start]\nfoot = 1", "start.foot", &["com", "feet"]),
        ("[friction]\nmuu = 0.4", "friction.muu", &["mu", "f_thr"]),
        ("[weights]\ncomm = 1.0", "weights.comm", &["com", "force"]),
        ("[masses]\nM = 60.0", "masses.M", &["B", "F"]),
        (
            "[same_side_sq]\nmid = 4.0",
            "same_side_sq.mid",
            &["min", "max"],
        ),
        (
            "[goal]\nB = [3.0, 0.5, 0.5]\nW = [0.0, 0.0, 0.0]",
            "goal.W",
            &["B", "F"],
        ),
        ("gap = { min = 2.2, widht = 0.1 }", "gap.widht", &["depth"]),
    ];
    for (text, path, known) in cases {
        let e = toml(text).unwrap_err().to_string();
        assert!(
            e.contains(&format!("unknown field `{path}`")),
            "{text:?}: {e}"
        );
        for k in *known {
            assert!(e.contains(k), "{text:?}: {e} does not offer {k}");
        }
    }
    let e = json(r#"{"start": {"com": {"B": [0, 0.5, 0.5], "Q": [0, 0, 0]}}}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown field `start.com.Q`"), "{e}");
    let e = json(r#"{"friction": {"mu": 0.5, "kinetic": 0.4}}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown field `friction.kinetic`"), "{e}");
}

#[test]
fn n_step_below_two_is_rejected() {
    for n in [0, 1] {
        let msg = rejected(&format!("n_step = {n}"));
        assert!(
            msg.contains("n_step")
                && msg.contains("at least 2")
                && msg.contains(&format!("got {n}")),
            "{msg}"
        );
        let e = json(&format!(r#"{{"n_step": {n}}}"#))
            .unwrap()
            .validate()
            .unwrap_err()
            .to_string();
        assert!(e.contains("n_step") && e.contains("at least 2"), "{e}");
    }
    // A negative count is not a count at all.
    let e = toml("n_step = -3").unwrap_err().to_string();
    assert!(
        e.contains("n_step") && e.contains("non-negative integer"),
        "{e}"
    );
    // n_step = 2 (the start and one more stance) is the smallest valid value.
    toml("n_step = 2").unwrap().validate().unwrap();
}

#[test]
fn friction_coefficient_must_be_positive() {
    for mu in ["0", "0.0", "-0.0", "-0.5", "-1e-9"] {
        let msg = rejected(&format!("[friction]\nmu = {mu}"));
        assert!(
            msg.contains("friction.mu") && msg.contains("must be positive"),
            "{mu}: {msg}"
        );
    }
    let mut s = Scenario::default();
    s.apply_overrides(&["friction.mu=0"]).unwrap();
    let e = s.validate().unwrap_err().to_string();
    assert!(e.contains("friction.mu") && e.contains("got 0"), "{e}");
    // Small but positive is accepted.
    toml("[friction]\nmu = 0.01").unwrap().validate().unwrap();
}

#[test]
fn gap_min_must_be_below_gap_max() {
    for (min, max) in [(2.35, 2.35), (2.5, 2.4), (3.0, 1.0)] {
        let msg = rejected(&format!("[gap]\nmin = {min:?}\nmax = {max:?}"));
        assert!(
            msg.contains("gap.min")
                && msg.contains("less than gap.max")
                && msg.contains(&format!("({max})"))
                && msg.contains(&format!("got {min}")),
            "{min} {max}: {msg}"
        );
    }
    let e = json(r#"{"gap": {"min": 2.4}}"#)
        .unwrap()
        .validate()
        .unwrap_err()
        .to_string();
    assert!(e.contains("gap.min") && e.contains("2.35"), "{e}");
}

#[test]
fn start_violating_rigid_legs_is_rejected_naming_foot_and_values() {
    // (11) with the front CoM moved 0.1 m sideways: ‖r_F − r_FR‖² = 0.61 and
    // ‖r_F − r_FL‖² = 0.41 instead of 0.5; the back legs are untouched.
    let e = rejected("[start.com]\nF = [2.0, 0.6, 0.5]");
    assert!(e.contains("(11) rigid legs"), "{e}");
    assert!(
        e.contains("start.feet.FR") && e.contains("start.feet.FL"),
        "{e}"
    );
    assert!(!e.contains("start.feet.BR"), "back legs are fine: {e}");
    assert!(e.contains("0.5") && e.contains("leg_length_sq"), "{e}");
    // A foot moved without its CoM: (11) for that foot only.
    let e = rejected("[start.feet]\nBL = [0.1, 1.0, 0.0]");
    assert!(e.contains("(11)") && e.contains("foot BL"), "{e}");
    assert!(!e.contains("foot BR"), "{e}");
    // Changing leg_length_sq without moving the start breaks all four legs.
    let e = rejected("leg_length_sq = 0.6");
    for f in ["BR", "BL", "FR", "FL"] {
        assert!(e.contains(&format!("start.feet.{f}")), "{f}: {e}");
    }
    // Off by 2e-6 m² (beyond the 1e-6 tolerance) is rejected; by 5e-7 it is accepted.
    let z = |d: f64| (0.25f64 + d).sqrt();
    rejected(&format!("[start.com]\nB = [0.0, 0.5, {}]", z(2e-6)));
    toml(&format!("[start.com]\nB = [0.0, 0.5, {}]", z(5e-7)))
        .unwrap()
        .validate()
        .unwrap();
}

#[test]
fn every_problem_is_reported_at_once() {
    let msg = rejected("n_step = 1\n[masses]\nB = 0.0\n[friction]\nmu = -1.0\n[gap]\nmin = 3.0");
    for needle in ["n_step", "masses.B", "friction.mu", "gap.min"] {
        assert!(msg.contains(needle), "{needle}: {msg}");
    }
    match toml("[friction]\nmu = 0.0\n[masses]\nF = -1.0")
        .unwrap()
        .validate()
    {
        Err(ScenarioError::Invalid(list)) => {
            let fields: Vec<&str> = list.iter().map(|i| i.field.as_str()).collect();
            assert!(
                fields.contains(&"friction.mu") && fields.contains(&"masses.F"),
                "{fields:?}"
            );
        }
        other => panic!("expected Invalid, got {other:?}"),
    }
}

/// The `terrain` table: each kind parses from TOML and JSON; a bad value is rejected
/// naming its field; a height map's CSV is read relative to the scenario file, and a
/// malformed CSV is rejected naming its line.
#[test]
fn terrain_kinds_parse_and_bad_ones_are_rejected() {
    use gap_crossing::scenario::TerrainSpec;
    let dir = std::env::temp_dir().join(format!("gap_crossing_terrain_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let load = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        Scenario::load(&p)
    };
    let s = load(
        "step.toml",
        "[terrain]\nkind = \"step\"\nedge = 2.3\nrise = 0.1\nsteepness = 1e6\nmargin = 0.04\n",
    )
    .unwrap();
    assert!(matches!(s.terrain, TerrainSpec::Step { rise, .. } if rise == 0.1));
    let s = load(
        "stones.json",
        r#"{ "terrain": { "kind": "stones", "stones": [[-0.5, 2.15, -0.3, 1.3], [2.3, 2.5, 0, 1]] } }"#,
    )
    .unwrap();
    assert!(matches!(&s.terrain, TerrainSpec::Stones { stones } if stones.len() == 2));
    let bad = |name: &str, text: &str| load(name, text).unwrap_err().to_string();
    let e = bad(
        "a.toml",
        "[terrain]\nkind = \"step\"\nedge = 2.3\nrise = 0.1\nsteepness = -1.0\nmargin = 0.04\n",
    );
    assert!(e.contains("terrain.steepness") && e.contains("-1"), "{e}");
    let e = bad("b.toml", "[terrain]\nkind = \"step\"\nedge = 2.3\n");
    assert!(e.contains("terrain") && e.contains("rise"), "{e}");
    let e = bad("c.toml", "[terrain]\nkind = \"lava\"\n");
    assert!(e.contains("terrain") && e.contains("lava"), "{e}");
    let e = bad(
        "d.toml",
        "[terrain]\nkind = \"stones\"\nstones = [[1.0, 0.5, 0.0, 1.0]]\n",
    );
    assert!(e.contains("terrain.stones[0]"), "{e}");
    // The start feet are not on any stone.
    let e = bad(
        "d2.toml",
        "[terrain]\nkind = \"stones\"\nstones = [[3.0, 3.5, 0.0, 1.0]]\n",
    );
    assert!(e.contains("keep-out") && e.contains("start.feet.BR"), "{e}");
    let e = bad("e.toml", "[terrain]\nkind = \"gaps\"\ngaps = [{ min = 1.0, max = 0.9, depth = 1.0, steepness = 1e6, margin = 0.03 }]\n");
    assert!(e.contains("terrain.gaps[0].min"), "{e}");
    // Height maps: the CSV next to the scenario file.
    std::fs::write(dir.join("flat.csv"), "# flat\n0, 0, 0\n0, 0, 0\n").unwrap();
    let hm = "[terrain]\nkind = \"height_map\"\nfile = \"flat.csv\"\norigin = [-1.0, -1.0]\nspacing = [3.0, 3.0]\n";
    let s = load("hm.toml", hm).unwrap();
    assert!(
        matches!(&s.terrain, TerrainSpec::HeightMap { heights, .. } if heights.len() == 2 && heights[0].len() == 3)
    );
    std::fs::write(dir.join("flat.csv"), "0, 0, 0\n0, 0\n").unwrap();
    let e = bad("hm2.toml", hm);
    assert!(e.contains("line 2") && e.contains("2 columns"), "{e}");
    std::fs::write(dir.join("flat.csv"), "0, 0, x\n0, 0, 0\n").unwrap();
    let e = bad("hm3.toml", hm);
    assert!(e.contains("line 1") && e.contains("`x`"), "{e}");
    // Overrides: a field of the same kind, or a whole new kind.
    let mut s = Scenario::default();
    s.set(
        "terrain",
        "{kind=\"step\", edge=2.3, rise=0.1, steepness=1e6, margin=0.04}",
    )
    .unwrap();
    s.set("terrain.rise", "0.2").unwrap();
    assert!(
        matches!(s.terrain, TerrainSpec::Step { rise, edge, .. } if rise == 0.2 && edge == 2.3)
    );
    s.validate().unwrap();
}

/// A height-map CSV above the size limit is refused before it is read, with the limit
/// and what to do in the message (a 2000 × 2000 CSV used to be planned for minutes).
#[test]
fn oversized_height_csv_is_refused() {
    let dir = std::env::temp_dir().join(format!("gap_crossing_csv_size_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("big.csv");
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(gap_crossing::terrain_spec::MAX_HEIGHT_CSV_BYTES + 1)
        .unwrap();
    let e = gap_crossing::scenario::read_height_csv(&path)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("big.csv") && e.contains("16 MiB") && e.contains("coarser grid"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
