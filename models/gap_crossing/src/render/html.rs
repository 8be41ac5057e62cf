//! The animated plan: one self-contained HTML file (`plan.html`) with the top (x–y) and
//! side (x–z) views of one stance at a time, a stance slider and a play button.
//!
//! Nothing is loaded from the network: the plan's numbers are embedded as JSON in an
//! inline script, which draws both views as inline SVG. Each view shows every stance's
//! CoMs faintly (the path), the terrain as `plan.svg` draws it ([`terrain_view`]: the
//! keep-out, allowed regions, gaps, stones, a step's edge, a height map's cells in the
//! top view; the profile, keep-out bands and stones in the side view), the goals, and the current stance in full: feet, support polygon, CoMs, legs
//! and contact forces (side view, scaled). Feet that moved into this stance are ringed.
use super::{esc, terrain_view};
use crate::plan::SolutionFile;
use crate::scenario::{Biped, Foot};
use serde_json::json;

/// Lowest terrain drawn in the side view, relative to the floor (m): a deep gap is cut.
const PROFILE_FLOOR: f64 = -1.0;

/// Where an unbounded edge of a terrain rectangle is put in the page's data (m).
const FAR: f64 = 1e6;

/// The page for `file`, with `title` as its heading.
pub fn plan_html(file: &SolutionFile, title: &str) -> String {
    let s = &file.scenario;
    let stances: Vec<serde_json::Value> = file
        .stances
        .iter()
        .map(|st| {
            json!({
                "com": Biped::ALL.map(|j| st.com.get(j)),
                "feet": Foot::ALL.map(|i| st.feet.get(i)),
                "forces": Foot::ALL.map(|i| st.forces.get(i)),
            })
        })
        .collect();
    let terrain = crate::terrain::of(s);
    let xs = file
        .stances
        .iter()
        .flat_map(|st| Foot::ALL.map(|i| st.feet.get(i)[0]))
        .chain([s.goal.b[0], s.goal.f[0]]);
    let (xmin, xmax) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    let (x0, x1) = (xmin - 0.6, xmax + 0.6);
    let profile: Vec<[f64; 2]> =
        terrain_view::profile(s, &*terrain, &terrain_view::profile_xs(s, x0, x1))
            .into_iter()
            .map(|[x, h]| [x, h.max(PROFILE_FLOOR)])
            .collect();
    // JSON has no infinity: unbounded edges become far-away finite ones, clipped to the
    // view by the script.
    let finite = |v: [f64; 2]| v.map(|e| e.clamp(-FAR, FAR));
    let rects: Vec<serde_json::Value> = terrain_view::top_rects(s, &*terrain)
        .into_iter()
        .map(|r| {
            json!({
                "x": finite(r.x),
                "y": finite(r.y),
                "fill": r.fill,
                "opacity": r.opacity.unwrap_or(1.0),
                "stroke": r.stroke.map(|(c, _)| c),
                "strokeWidth": r.stroke.map_or(0.0, |(_, w)| w),
            })
        })
        .collect();
    let data = json!({
        "stances": stances,
        "feet": Foot::ALL.map(|i| i.name()),
        "goal": [s.goal.b, s.goal.f],
        "xRange": [x0, x1],
        "sideY": terrain_view::side_y(s),
        "topRects": rects,
        "stepEdge": terrain_view::step_edge(s),
        "profile": profile,
        "keepOutBands": terrain_view::keep_out_bands(s, &*terrain, &terrain_view::profile_xs(s, x0, x1)),
        "stones": terrain_view::stone_blocks(s),
        "objective": file.solver.objective,
        "status": file.solver.status,
    });
    // `</` would end the script element early.
    let data = data.to_string().replace("</", "<\\/");
    TEMPLATE
        .replace("__TITLE__", &esc(title))
        .replace("__DATA__", &data)
}

const TEMPLATE: &str = r##"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>__TITLE__</title>
<style>
body { font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; margin: 16px; color: #222; }
h1 { font-size: 18px; margin: 0 0 8px 0; }
#controls { display: flex; align-items: center; gap: 12px; margin: 8px 0; }
#slider { width: 520px; }
#label { font-variant-numeric: tabular-nums; min-width: 360px; }
button { font-size: 14px; min-width: 72px; }
svg { display: block; background: white; border: 1px solid #ccc; margin-bottom: 8px; }
.caption { font-size: 12px; color: #555; margin: 2px 0 10px 0; }
</style>
</head>
<body>
<h1>__TITLE__</h1>
<div id="controls">
  <button id="play" type="button">Play</button>
  <input id="slider" type="range" min="1" value="1" step="1">
  <span id="label"></span>
</div>
<svg id="top" width="1000" height="330"></svg>
<div class="caption">Top view (x–y): feet (circles: back feet BR, BL; squares: front feet FR, FL, as in plan.svg), support polygon, CoMs (B blue, F orange) of the current stance; dots: the CoM path of every stance; terrain as in plan.svg (pale red: keep-out; white: where feet may stand; dark red: gaps; sand: stones; brown shading: a height map, darker is higher); rings: goals. A ringed foot has just moved.</div>
<svg id="side" width="1000" height="300"></svg>
<div class="caption">Side view (x–z): terrain, feet, legs (CoM to its feet) and CoMs of the current stance; green arrows: contact forces (1 m per 1000 N).</div>
<script id="plan-data" type="application/json">__DATA__</script>
<script>
(function () {
  "use strict";
  var D = JSON.parse(document.getElementById("plan-data").textContent);
  var NS = "http://www.w3.org/2000/svg";
  var n = D.stances.length;
  var COL = { B: "#1f77b4", F: "#ff7f0e", foot: "#444", moved: "#d62728" };
  function el(parent, tag, attrs, text) {
    var e = document.createElementNS(NS, tag);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    parent.appendChild(e);
    return e;
  }
  // A view: equal scales on both axes, the same x scale in both views (so they line
  // up); the height follows the y range.
  function view(svg, yr) {
    var w = 1000, m = 50, xr = D.xRange;
    var scale = (w - 2 * m) / (xr[1] - xr[0]);
    var height = (yr[1] - yr[0]) * scale + 2 * m;
    var v = {
      svg: svg,
      px: function (x) { return m + (x - xr[0]) * scale; },
      py: function (y) { return height - m - (y - yr[0]) * scale; },
      scale: scale
    };
    svg.setAttribute("height", height);
    var g = el(svg, "g", { "font-size": "11", fill: "#555" });
    for (var t = Math.ceil(xr[0] * 2) / 2; t <= xr[1]; t += 0.5) {
      el(g, "line", { x1: v.px(t), x2: v.px(t), y1: v.py(yr[0]), y2: v.py(yr[1]), stroke: "#eee" });
      el(g, "text", { x: v.px(t), y: v.py(yr[0]) + 14, "text-anchor": "middle" }, t.toFixed(1));
    }
    for (var u = Math.ceil(yr[0] * 2) / 2; u <= yr[1]; u += 0.5) {
      el(g, "line", { x1: v.px(xr[0]), x2: v.px(xr[1]), y1: v.py(u), y2: v.py(u), stroke: "#eee" });
      el(g, "text", { x: v.px(xr[0]) - 6, y: v.py(u) + 4, "text-anchor": "end" }, u.toFixed(1));
    }
    v.dyn = el(svg, "g", {});
    return v;
  }
  function range(axis, extra) {
    var lo = Infinity, hi = -Infinity;
    D.stances.forEach(function (s) {
      s.feet.concat(s.com).forEach(function (p) { lo = Math.min(lo, p[axis]); hi = Math.max(hi, p[axis]); });
    });
    extra.forEach(function (e) { lo = Math.min(lo, e); hi = Math.max(hi, e); });
    return [lo - 0.3, hi + 0.3];
  }
  var top = view(document.getElementById("top"), range(1, [D.goal[0][1], D.goal[1][1]]));
  var side = view(document.getElementById("side"), range(2, D.profile.map(function (p) { return p[1]; })));
  // Static layers: terrain, goals, CoM paths.
  var topStatic = el(top.svg, "g", {});
  top.svg.insertBefore(topStatic, top.dyn);
  var yr = range(1, [D.goal[0][1], D.goal[1][1]]);
  var zr = range(2, D.profile.map(function (p) { return p[1]; }));
  // A data rectangle clipped to the view's ranges.
  function rect(g, v, x, y, xr2, yr2, attrs) {
    var a = Math.max(x[0], xr2[0]), b = Math.min(x[1], xr2[1]);
    var c = Math.max(y[0], yr2[0]), d = Math.min(y[1], yr2[1]);
    if (!(a < b && c < d)) return;
    attrs.x = v.px(a); attrs.y = v.py(d);
    attrs.width = Math.max(0.5, v.px(b) - v.px(a)); attrs.height = Math.max(0.5, v.py(c) - v.py(d));
    el(g, "rect", attrs);
  }
  D.topRects.forEach(function (r) {
    var attrs = { fill: r.fill, "fill-opacity": r.opacity, "class": "terrain" };
    if (r.stroke) { attrs.stroke = r.stroke; attrs["stroke-width"] = r.strokeWidth; }
    rect(topStatic, top, r.x, r.y, D.xRange, yr, attrs);
  });
  if (D.stepEdge) {
    el(topStatic, "line", { x1: top.px(D.stepEdge[0]), x2: top.px(D.stepEdge[0]), y1: top.py(yr[0]), y2: top.py(yr[1]),
      stroke: "#6b4f2a", "stroke-width": 2 });
    el(topStatic, "text", { x: top.px(D.stepEdge[0]) + 4, y: top.py(yr[1]) + 14, "font-size": 11 },
      "step " + (D.stepEdge[1] >= 0 ? "+" : "") + D.stepEdge[1] + " m");
  }
  var sideStatic = el(side.svg, "g", {});
  side.svg.insertBefore(sideStatic, side.dyn);
  D.keepOutBands.forEach(function (b) {
    rect(sideStatic, side, b, [-1e6, 1e6], D.xRange, zr, { fill: "#d62728", "fill-opacity": 0.12 });
  });
  D.stones.forEach(function (b) {
    rect(sideStatic, side, b, [-0.03, 0], D.xRange, zr, { fill: "#8c7a55" });
  });
  el(sideStatic, "polyline", { points: D.profile.map(function (p) { return side.px(p[0]) + "," + side.py(p[1]); }).join(" "),
    fill: "none", stroke: "#7b5a3c", "stroke-width": 2 });
  [0, 1].forEach(function (j) {
    var c = j === 0 ? COL.B : COL.F;
    D.stances.forEach(function (s) {
      el(topStatic, "circle", { cx: top.px(s.com[j][0]), cy: top.py(s.com[j][1]), r: 1.6, fill: c, opacity: 0.35 });
      el(sideStatic, "circle", { cx: side.px(s.com[j][0]), cy: side.py(s.com[j][2]), r: 1.6, fill: c, opacity: 0.35 });
    });
    el(topStatic, "circle", { cx: top.px(D.goal[j][0]), cy: top.py(D.goal[j][1]), r: 8, fill: "none", stroke: "#d62728", "stroke-width": 2 });
    el(sideStatic, "circle", { cx: side.px(D.goal[j][0]), cy: side.py(D.goal[j][2]), r: 8, fill: "none", stroke: "#d62728", "stroke-width": 2 });
  });
  function moved(k, i) {
    if (k === 0) return false;
    var a = D.stances[k - 1].feet[i], b = D.stances[k].feet[i];
    return Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]) > 1e-6;
  }
  function foot(v, g, p, i, k, ya) {
    var x = v.px(p[0]), y = v.py(p[ya]), c = moved(k, i) ? COL.moved : COL.foot;
    if (i < 2) el(g, "circle", { cx: x, cy: y, r: 5.5, fill: c });
    else el(g, "rect", { x: x - 5, y: y - 5, width: 10, height: 10, fill: c });
    if (moved(k, i)) el(g, "circle", { cx: x, cy: y, r: 10, fill: "none", stroke: COL.moved, "stroke-width": 1.5 });
    el(g, "text", { x: x + 8, y: y - 8, "font-size": 11, fill: "#333" }, D.feet[i]);
  }
  function draw(k) {
    var s = D.stances[k];
    [top, side].forEach(function (v) { while (v.dyn.firstChild) v.dyn.removeChild(v.dyn.firstChild); });
    // Top: support polygon BR, FR, FL, BL.
    var poly = [0, 2, 3, 1].map(function (i) { return top.px(s.feet[i][0]) + "," + top.py(s.feet[i][1]); }).join(" ");
    el(top.dyn, "polygon", { points: poly, fill: "#9ecae1", "fill-opacity": 0.35, stroke: "#3182bd" });
    el(top.dyn, "line", { x1: top.px(s.com[0][0]), y1: top.py(s.com[0][1]), x2: top.px(s.com[1][0]), y2: top.py(s.com[1][1]),
      stroke: "#555", "stroke-dasharray": "4 3" });
    for (var i = 0; i < 4; i++) foot(top, top.dyn, s.feet[i], i, k, 1);
    // Side: legs, forces, feet.
    for (i = 0; i < 4; i++) {
      var j = i < 2 ? 0 : 1, f = s.forces[i], p = s.feet[i];
      el(side.dyn, "line", { x1: side.px(s.com[j][0]), y1: side.py(s.com[j][2]), x2: side.px(p[0]), y2: side.py(p[2]),
        stroke: j === 0 ? COL.B : COL.F, "stroke-width": 2.5 });
      el(side.dyn, "line", { x1: side.px(p[0]), y1: side.py(p[2]), x2: side.px(p[0] + f[0] / 1000), y2: side.py(p[2] + f[2] / 1000),
        stroke: "#2ca02c", "stroke-width": 2 });
      foot(side, side.dyn, p, i, k, 2);
    }
    [0, 1].forEach(function (j) {
      el(top.dyn, "circle", { cx: top.px(s.com[j][0]), cy: top.py(s.com[j][1]), r: 7, fill: j === 0 ? COL.B : COL.F, stroke: "white" });
      el(side.dyn, "circle", { cx: side.px(s.com[j][0]), cy: side.py(s.com[j][2]), r: 7, fill: j === 0 ? COL.B : COL.F, stroke: "white" });
    });
    var who = [];
    for (i = 0; i < 4; i++) if (moved(k, i)) who.push(D.feet[i]);
    document.getElementById("label").textContent = "stance " + (k + 1) + " of " + n +
      (k === 0 ? " (start)" : who.length ? " — " + who.join(", ") + " moved" : " — no foot moved");
  }
  var slider = document.getElementById("slider"), button = document.getElementById("play");
  slider.max = n;
  var timer = null;
  function show(k) { slider.value = k + 1; draw(k); }
  function stop() { clearInterval(timer); timer = null; button.textContent = "Play"; }
  slider.addEventListener("input", function () { stop(); draw(slider.value - 1); });
  button.addEventListener("click", function () {
    if (timer) { stop(); return; }
    if (+slider.value >= n) show(0);
    button.textContent = "Pause";
    timer = setInterval(function () {
      var k = +slider.value;
      if (k >= n) { stop(); return; }
      show(k);
    }, 250);
  });
  var q = /[?#&]stance=(\d+)/.exec(location.href);
  show(q ? Math.min(Math.max(+q[1], 1), n) - 1 : 0);
  if (/[?#&]play\b/.test(location.href)) button.click();
})();
</script>
</body>
</html>
"##;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gait;
    use crate::plan::SolverInfo;
    use crate::scenario::Scenario;

    #[test]
    fn self_contained_with_every_stance() {
        let s = Scenario {
            n_step: 9,
            ..Scenario::default()
        };
        let plan = gait::crawl_plan(&s);
        let file = SolutionFile::new(s, SolverInfo::default(), plan.clone());
        let html = plan_html(&file, "a <b> & c");
        assert!(html.contains("<title>a &lt;b&gt; &amp; c</title>"));
        // No network: no external source, link or URL.
        for bad in ["src=\"http", "href=\"http", "<link", "@import", "src=\"//"] {
            assert!(!html.contains(bad), "{bad}");
        }
        // The embedded data holds every stance, and reads back as JSON.
        let start = html.find("application/json\">").unwrap() + "application/json\">".len();
        let end = start + html[start..].find("</script>").unwrap();
        let data: serde_json::Value = serde_json::from_str(&html[start..end]).unwrap();
        let st = data["stances"].as_array().unwrap();
        assert_eq!(st.len(), 9);
        assert_eq!(
            st[4]["feet"][2].as_array().unwrap().len(),
            3,
            "three coordinates"
        );
        assert_eq!(
            st[4]["feet"][2][0].as_f64(),
            Some(plan.stances[4].feet.fr[0])
        );
    }
}
