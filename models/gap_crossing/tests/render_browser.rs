//! plan.html in a real headless browser (issue 20 item 5): the page's script runs in
//! Chromium (`--dump-dom`, the DOM after the script drew the views), and the side view's
//! drawn terrain profile is compared, pixel by pixel, with the terrain's height.
//!
//! Needs Chromium (`chromium` or `chromium-browser` on PATH, Debian's `chromium`
//! package), so it is ignored by default: `cargo test --release -p gap_crossing --test
//! render_browser -- --ignored`. Without Chromium it fails saying so.
use gap_crossing::gait;
use gap_crossing::plan::{SolutionFile, SolverInfo};
use gap_crossing::render::plan_html;
use gap_crossing::scenario::Scenario;
use gap_crossing::terrain;
use std::path::Path;
use std::process::Command;

fn chromium() -> &'static str {
    ["chromium", "chromium-browser"]
        .into_iter()
        .find(|b| Command::new(b).arg("--version").output().is_ok())
        .expect("Chromium not found: install Debian's `chromium` package")
}

#[test]
#[ignore = "needs Chromium"]
fn browser_draws_the_terrain_profile() {
    for name in ["step.toml", "hills.toml", "gaps.toml"] {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
        let mut s = Scenario::load(&dir.join(name)).unwrap();
        s.load_terrain_files(&dir).unwrap();
        let file = SolutionFile::new(s.clone(), SolverInfo::default(), gait::crawl_plan(&s));
        let html = plan_html(&file, name);
        let out = std::env::temp_dir().join(format!(
            "gap_crossing_browser_{}_{name}.html",
            std::process::id()
        ));
        std::fs::write(&out, &html).unwrap();
        let dom = Command::new(chromium())
            .args(["--headless", "--no-sandbox", "--disable-gpu", "--dump-dom"])
            .arg(format!("file://{}", out.display()))
            .output()
            .unwrap();
        let _ = std::fs::remove_file(&out);
        let dom = String::from_utf8_lossy(&dom.stdout);
        // The profile: the polyline stroked in the terrain's brown, drawn by the script.
        let at = dom
            .find(r##"stroke="#7b5a3c""##)
            .unwrap_or_else(|| panic!("{name}: no profile in the DOM"));
        let start = dom[..at].rfind("<polyline").unwrap();
        let tag = &dom[start..at];
        let p0 = tag.find("points=\"").unwrap() + 8;
        let points: Vec<[f64; 2]> = tag[p0..p0 + tag[p0..].find('"').unwrap()]
            .split(' ')
            .map(|p| {
                let (x, y) = p.split_once(',').unwrap();
                [x.parse().unwrap(), y.parse().unwrap()]
            })
            .collect();
        assert!(points.len() > 400, "{name}: {} points", points.len());
        // The page's x map: 50 px margin, 900 px for its x range (html.rs's `view`).
        let tag = "application/json\">";
        let d0 = html.find(tag).unwrap() + tag.len();
        let data: serde_json::Value =
            serde_json::from_str(&html[d0..d0 + html[d0..].find("</script>").unwrap()]).unwrap();
        let xr = [
            data["xRange"][0].as_f64().unwrap(),
            data["xRange"][1].as_f64().unwrap(),
        ];
        let y_side = data["sideY"].as_f64().unwrap();
        let scale = 900.0 / (xr[1] - xr[0]);
        // Pixel y + height·scale is the same for every point when the drawn profile is
        // the terrain's (y grows downwards). 1e-3 px: x read back from a pixel carries
        // ~1e-13 m of round-off, which a 1e6-steep atan edge turns into ~1e-5 px.
        let t = terrain::of(&s);
        let level: Vec<f64> = points
            .iter()
            .map(|&[px, py]| {
                let x = xr[0] + (px - 50.0) / scale;
                py + t.height_at(x, y_side).max(-1.0) * scale
            })
            .collect();
        let (lo, hi) = level
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        assert!(
            hi - lo < 1e-3,
            "{name}: drawn profile off the terrain by {} px",
            hi - lo
        );
        // And it is not flat: the terrain's relief shows (a step's rise, hills, gaps).
        let ys: Vec<f64> = points.iter().map(|p| p[1]).collect();
        let spread = ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - ys.iter().cloned().fold(f64::INFINITY, f64::min);
        assert!(spread > 5.0, "{name}: flat profile ({spread} px)");
    }
}
