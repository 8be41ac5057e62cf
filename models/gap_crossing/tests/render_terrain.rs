//! plan.html draws the scenario's own terrain (issue 20: it used to draw the default gap
//! on flat ground for every terrain). Each example scenario's crawl guess is rendered and
//! the page's embedded drawing data is compared with the scenario file's numbers: the
//! side profile with the terrain's height, the gaps, stones and step edge with the
//! scenario's table, and every foot of every stance lies on ground drawn as allowed.
use gap_crossing::gait;
use gap_crossing::plan::{SolutionFile, SolverInfo};
use gap_crossing::render::plan_html;
use gap_crossing::scenario::{Foot, Scenario, TerrainSpec};
use gap_crossing::terrain;
use serde_json::Value;
use std::path::Path;

/// The JSON data embedded in a plan page.
fn page_data(html: &str) -> Value {
    let tag = "application/json\">";
    let start = html.find(tag).unwrap() + tag.len();
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end].replace("<\\/", "</")).unwrap()
}

fn pair(v: &Value) -> [f64; 2] {
    [v[0].as_f64().unwrap(), v[1].as_f64().unwrap()]
}

/// The rectangles of the top view with fill colour `fill`, as (x, y) ranges.
fn rects(data: &Value, fill: &str) -> Vec<([f64; 2], [f64; 2])> {
    data["topRects"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["fill"] == fill)
        .map(|r| (pair(&r["x"]), pair(&r["y"])))
        .collect()
}

fn render(name: &str) -> (Scenario, Value) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut s = Scenario::load(&dir.join(name)).unwrap();
    s.load_terrain_files(&dir).unwrap();
    s.validate().unwrap();
    let plan = gait::crawl_plan(&s);
    let file = SolutionFile::new(s.clone(), SolverInfo::default(), plan);
    (s, page_data(&plan_html(&file, name)))
}

/// Every terrain kind: the profile is the terrain's height along the drawn line (cut at
/// 1 m below the floor, as documented), and each foot of each stance stands inside a
/// rectangle drawn as ground where feet may stand (white, or a stone).
#[test]
fn page_draws_the_scenarios_terrain() {
    for name in [
        "default.toml",
        "gaps.toml",
        "step.toml",
        "stones.toml",
        "hills.toml",
    ] {
        let (s, data) = render(name);
        let t = terrain::of(&s);
        let y = data["sideY"].as_f64().unwrap();
        let profile = data["profile"].as_array().unwrap();
        assert!(profile.len() > 400, "{name}");
        for p in profile {
            let [x, h] = pair(p);
            assert_eq!(h, t.height_at(x, y).max(-1.0), "{name}: profile at x = {x}");
        }
        let mut ground = rects(&data, "white");
        ground.extend(rects(&data, "#e8dcc0"));
        let on_ground = |p: [f64; 3]| {
            ground
                .iter()
                .any(|(gx, gy)| p[0] >= gx[0] && p[0] <= gx[1] && p[1] >= gy[0] && p[1] <= gy[1])
        };
        for st in gait::crawl_plan(&s).stances {
            for i in Foot::ALL {
                assert!(
                    on_ground(st.feet.get(i)),
                    "{name}: foot {i} off the drawn ground"
                );
            }
        }
        // Gaps drawn are exactly the scenario's gaps: none where the terrain has none
        // (the old page drew the default gap at 2.25–2.35 m on every terrain).
        let gaps: Vec<[f64; 2]> = rects(&data, "#7f1d1d").into_iter().map(|r| r.0).collect();
        let expected: Vec<[f64; 2]> = match &s.terrain {
            TerrainSpec::Gap => vec![[s.gap.min, s.gap.max]],
            TerrainSpec::Gaps { gaps } => gaps.iter().map(|g| [g.min, g.max]).collect(),
            _ => vec![],
        };
        assert_eq!(gaps, expected, "{name}");
        match &s.terrain {
            TerrainSpec::Stones { stones } => {
                let drawn: Vec<[f64; 4]> = rects(&data, "#e8dcc0")
                    .into_iter()
                    .map(|(x, y)| [x[0], x[1], y[0], y[1]])
                    .collect();
                assert_eq!(&drawn, stones, "{name}");
                let blocks: Vec<[f64; 2]> = data["stones"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(pair)
                    .collect();
                assert_eq!(blocks.len(), stones.len());
            }
            TerrainSpec::Step { edge, rise, .. } => {
                assert_eq!(pair(&data["stepEdge"]), [*edge, *rise]);
                // The profile rises by the step (to the atan's round-off) past its edge.
                let after: Vec<f64> = profile
                    .iter()
                    .map(pair)
                    .filter(|p| p[0] > edge + 0.05)
                    .map(|p| p[1])
                    .collect();
                assert!(!after.is_empty());
                assert!(after.iter().all(|h| (h - rise).abs() < 1e-4), "{name}");
            }
            TerrainSpec::HeightMap { .. } => {
                let cells = rects(&data, "#8c6d3f");
                assert_eq!(cells.len(), 60 * 24, "{name}");
            }
            _ => assert!(data["stepEdge"].is_null()),
        }
    }
}
