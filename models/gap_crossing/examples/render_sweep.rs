//! Redraws a sweep's heat map from its files, without solving:
//!
//! ```text
//! cargo run --release -p gap_crossing --example render_sweep -- GRID SWEEP_JSON OUT_SVG
//! ```
//!
//! GRID is the grid file the sweep ran (`sweep --grid`), SWEEP_JSON its `sweep.json` (or
//! any file of that shape, e.g. made-up statuses and times). The drawing depends on the
//! recorded wall times, so a re-run sweep never reproduces `sweep.svg` byte for byte; this
//! renders the same points twice, which `scripts/render_identity.sh` compares across
//! builds.
use gap_crossing::render::sweep_svg;
use gap_crossing::sweep::{Grid, PointResult};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [grid, json, out] = args.as_slice() else {
        return Err("usage: render_sweep GRID SWEEP_JSON OUT_SVG".into());
    };
    let grid = Grid::load(Path::new(grid))?;
    let file: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json)?)?;
    let points = file["points"]
        .as_array()
        .ok_or("SWEEP_JSON has no `points` array")?;
    let mut results = Vec::with_capacity(points.len());
    for p in points {
        // sweep.json writes `overrides` as an object; PointResult keeps them as pairs in
        // axis order.
        let mut p = p.clone();
        let pairs: Vec<(String, serde_json::Value)> = grid
            .axes
            .iter()
            .map(|a| (a.key.clone(), p["overrides"][&a.key].clone()))
            .collect();
        p["overrides"] = serde_json::to_value(pairs)?;
        results.push(serde_json::from_value::<PointResult>(p)?);
    }
    std::fs::write(out, sweep_svg(&grid, &results))?;
    Ok(())
}
