//! The plan figure: top view (x–y) above side view (x–z) of every stance.

use super::terrain_view;
use super::{esc, fmt_tick, nice_step, ramp, svg_open, ticks, FONT, MARGIN_L, MARGIN_R, WIDTH};
use crate::plan::SolutionFile;
use crate::scenario::{Biped, Foot, Scenario, TerrainSpec, Vec3};
use crate::terrain::{self, Terrain};
use std::fmt::Write;

/// A linear map from data to pixels for one panel with equal scales on both axes.
struct Panel {
    x0: f64,
    y0: f64,
    /// Data range.
    xr: (f64, f64),
    yr: (f64, f64),
    scale: f64,
}

impl Panel {
    fn px(&self, x: f64) -> f64 {
        self.x0 + (x - self.xr.0) * self.scale
    }
    fn py(&self, y: f64) -> f64 {
        self.y0 + (self.yr.1 - y) * self.scale
    }
    fn w(&self) -> f64 {
        (self.xr.1 - self.xr.0) * self.scale
    }
    fn h(&self) -> f64 {
        (self.yr.1 - self.yr.0) * self.scale
    }

    /// Frame, grid, ticks and axis labels.
    fn axes(&self, svg: &mut String, xlabel: &str, ylabel: &str, title: &str) {
        let (w, h) = (self.w(), self.h());
        let _ = writeln!(
            svg,
            r##"<rect x="{:.1}" y="{:.1}" width="{w:.1}" height="{h:.1}" fill="white" stroke="#333" stroke-width="1"/>"##,
            self.x0, self.y0
        );
        let xs = nice_step(self.xr.1 - self.xr.0, 12.0);
        for t in ticks(self.xr.0, self.xr.1, 12.0) {
            let x = self.px(t);
            let _ = writeln!(
                svg,
                r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#ddd" stroke-width="0.6"/><line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#333"/><text x="{x:.1}" y="{:.1}" font-size="11" text-anchor="middle" {FONT}>{}</text>"##,
                self.y0,
                self.y0 + h,
                self.y0 + h,
                self.y0 + h + 5.0,
                self.y0 + h + 17.0,
                fmt_tick(t, xs)
            );
        }
        let ys = nice_step(self.yr.1 - self.yr.0, (h / 40.0).max(2.0));
        for t in ticks(self.yr.0, self.yr.1, (h / 40.0).max(2.0)) {
            let y = self.py(t);
            let _ = writeln!(
                svg,
                r##"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd" stroke-width="0.6"/><line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#333"/><text x="{:.1}" y="{:.1}" font-size="11" text-anchor="end" {FONT}>{}</text>"##,
                self.x0,
                self.x0 + w,
                self.x0 - 5.0,
                self.x0,
                self.x0 - 8.0,
                y + 4.0,
                fmt_tick(t, ys)
            );
        }
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle" {FONT}>{}</text>"#,
            self.x0 + w / 2.0,
            self.y0 + h + 34.0,
            esc(xlabel)
        );
        let (lx, ly) = (self.x0 - 45.0, self.y0 + h / 2.0);
        let _ = writeln!(
            svg,
            r#"<text x="{lx:.1}" y="{ly:.1}" font-size="12" text-anchor="middle" transform="rotate(-90 {lx:.1} {ly:.1})" {FONT}>{}</text>"#,
            esc(ylabel)
        );
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" font-size="13" font-weight="bold" {FONT}>{}</text>"#,
            self.x0,
            self.y0 - 8.0,
            esc(title)
        );
    }

    fn clip(&self, svg: &mut String, id: &str) {
        let _ = writeln!(
            svg,
            r#"<clipPath id="{id}"><rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}"/></clipPath>"#,
            self.x0,
            self.y0,
            self.w(),
            self.h()
        );
    }
}

/// Marker for a foot (circle for back feet, square for front) or CoM (diamond).
fn foot_marker(svg: &mut String, x: f64, y: f64, foot: Foot, colour: &str) {
    match foot.biped() {
        Biped::B => {
            let _ = writeln!(
                svg,
                r#"<circle cx="{x:.1}" cy="{y:.1}" r="4" fill="{colour}" stroke="black" stroke-width="0.4"/>"#
            );
        }
        Biped::F => {
            let _ = writeln!(
                svg,
                r#"<rect x="{:.1}" y="{:.1}" width="7" height="7" fill="{colour}" stroke="black" stroke-width="0.4"/>"#,
                x - 3.5,
                y - 3.5
            );
        }
    }
}

fn com_marker(svg: &mut String, x: f64, y: f64, colour: &str) {
    let _ = writeln!(
        svg,
        r#"<path d="M{:.1},{y:.1} L{x:.1},{:.1} L{:.1},{y:.1} L{x:.1},{:.1} Z" fill="{colour}" stroke="black" stroke-width="0.4"/>"#,
        x - 5.0,
        y - 5.0,
        x + 5.0,
        y + 5.0
    );
}

fn goal_marker(svg: &mut String, x: f64, y: f64, label: &str) {
    let _ = writeln!(
        svg,
        r##"<circle cx="{x:.1}" cy="{y:.1}" r="8" fill="none" stroke="#d62728" stroke-width="1.6"/><line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#d62728"/><line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#d62728"/><text x="{:.1}" y="{:.1}" font-size="11" fill="#d62728" {FONT}>{}</text>"##,
        x - 11.0,
        x + 11.0,
        y - 11.0,
        y + 11.0,
        x + 10.0,
        y - 10.0,
        esc(label)
    );
}

/// A data rectangle clipped to the panel, as an SVG rect.
fn rect(svg: &mut String, p: &Panel, x: [f64; 2], y: [f64; 2], style: &str) {
    let (x0, x1) = (x[0].max(p.xr.0), x[1].min(p.xr.1));
    let (y0, y1) = (y[0].max(p.yr.0), y[1].min(p.yr.1));
    if x0 >= x1 || y0 >= y1 {
        return;
    }
    let _ = writeln!(
        svg,
        r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" {style}/>"#,
        p.px(x0),
        p.py(y1),
        (p.px(x1) - p.px(x0)).max(0.5),
        (p.py(y0) - p.py(y1)).max(0.5)
    );
}

/// Top view of the terrain ([`terrain_view::top_rects`], [`terrain_view::step_edge`]).
fn terrain_top(svg: &mut String, p: &Panel, s: &Scenario, t: &dyn Terrain) {
    for r in terrain_view::top_rects(s, t) {
        let mut style = format!(r#"fill="{}""#, r.fill);
        if let Some(o) = r.opacity {
            let _ = write!(style, r#" fill-opacity="{o}""#);
        }
        if let Some((c, w)) = r.stroke {
            let _ = write!(style, r#" stroke="{c}" stroke-width="{w}""#);
        }
        rect(svg, p, r.x, r.y, &style);
    }
    if let Some((edge, rise)) = terrain_view::step_edge(s) {
        let _ = writeln!(
            svg,
            r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#6b4f2a" stroke-width="2"/><text x="{:.1}" y="{:.1}" font-size="11" {FONT}>step {rise:+} m</text>"##,
            p.y0,
            p.y0 + p.h(),
            p.px(edge) + 4.0,
            p.y0 + 14.0,
            x = p.px(edge)
        );
    }
}

/// Side view of the keep-out: pale red where no allowed region holds (x, y) along the
/// profile's line (stones: each stone as a block at z = 0 instead).
fn terrain_side(svg: &mut String, p: &Panel, s: &Scenario, t: &dyn Terrain, tx: &[f64]) {
    for b in terrain_view::stone_blocks(s) {
        rect(svg, p, b, [-0.03, 0.0], r##"fill="#8c7a55""##);
    }
    for [a, b] in terrain_view::keep_out_bands(s, t, tx) {
        let _ = writeln!(
            svg,
            r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="#d62728" fill-opacity="0.12"/>"##,
            p.px(a),
            p.y0,
            (p.px(b) - p.px(a)).max(0.5),
            p.h()
        );
    }
}

/// The colour of stance `k` of `n`: the ramp from first to last.
fn stance_colour(k: usize, n: usize) -> String {
    ramp(if n > 1 {
        k as f64 / (n - 1) as f64
    } else {
        0.0
    })
}

/// The two panels of the figure and what sets their vertical extent.
struct Layout {
    top: Panel,
    side: Panel,
    /// Height of the whole figure (px).
    height: f64,
    /// The deepest gap's depth (m), and the part of it the side view shows.
    depth: f64,
    shown_depth: f64,
}

impl Layout {
    /// Ranges over every point drawn (stances, start feet, goals) and the terrain; one
    /// scale for both panels, so x lines up between them.
    fn of(file: &SolutionFile, terrain: &dyn Terrain) -> Layout {
        let s = &file.scenario;
        let mut pts: Vec<Vec3> = Vec::new();
        for x in &file.stances {
            pts.extend(x.feet.to_array());
            pts.push(x.com.b);
            pts.push(x.com.f);
        }
        pts.extend(s.start.feet.to_array());
        pts.push(s.goal.b);
        pts.push(s.goal.f);
        let finite = |v: &f64| v.is_finite();
        let xs: Vec<f64> = pts.iter().map(|p| p[0]).filter(finite).collect();
        let ys: Vec<f64> = pts.iter().map(|p| p[1]).filter(finite).collect();
        let zs: Vec<f64> = pts.iter().map(|p| p[2]).filter(finite).collect();
        let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let depth = match &s.terrain {
            TerrainSpec::Gap => s.gap.depth,
            TerrainSpec::Gaps { gaps } => gaps.iter().map(|g| g.depth).fold(0.0, f64::max),
            _ => 0.0,
        };
        let xr = (min(&xs) - 0.4, max(&xs) + 0.4);
        let yr = (min(&ys) - 0.3, max(&ys) + 0.3);
        let shown_depth = depth.min(1.0);
        let (t_lo, t_hi) = terrain_view::height_range(s, terrain);
        let zr = (
            min(&zs)
                .min(t_lo.max(-1.0))
                .max(-shown_depth - 0.2)
                .min(-shown_depth)
                - 0.1,
            max(&zs).max(t_hi) + 0.15,
        );
        let scale = (WIDTH - MARGIN_L - MARGIN_R) / (xr.1 - xr.0);
        let top = Panel {
            x0: MARGIN_L,
            y0: 70.0,
            xr,
            yr,
            scale,
        };
        let side = Panel {
            x0: MARGIN_L,
            y0: top.y0 + top.h() + 80.0,
            xr,
            yr: zr,
            scale,
        };
        let height = side.y0 + side.h() + 50.0;
        Layout {
            top,
            side,
            height,
            depth,
            shown_depth,
        }
    }
}

/// One line describing the ground, for the subtitle.
fn ground_text(s: &Scenario) -> String {
    match &s.terrain {
        TerrainSpec::Gap => format!(
            "gap x ∈ ({}, {}) m, depth {} m, margin {} m",
            s.gap.min, s.gap.max, s.gap.depth, s.gap.margin
        ),
        TerrainSpec::Gaps { gaps } => format!("{} gaps", gaps.len()),
        TerrainSpec::Step {
            edge, rise, margin, ..
        } => format!("step {rise:+} m at x = {edge} m, margin {margin} m"),
        TerrainSpec::Stones { stones } => format!("{} stepping stones", stones.len()),
        TerrainSpec::HeightMap { file, heights, .. } => format!(
            "height map {} ({} × {} nodes, Catmull-Rom)",
            file,
            heights.first().map_or(0, Vec::len),
            heights.len()
        ),
    }
}

/// The opening `<svg>`, background, title, subtitle and both panels' clip paths.
fn header(svg: &mut String, file: &SolutionFile, l: &Layout) {
    let s = &file.scenario;
    svg_open(svg, WIDTH, l.height, "");
    let _ = writeln!(
        svg,
        r#"<text x="{MARGIN_L}" y="24" font-size="16" font-weight="bold" {FONT}>Gap crossing: {} stances, gait {}, solver {} ({}), objective {:.4e}</text>"#,
        file.stances.len(),
        s.gait,
        esc(&file.solver.name),
        esc(&file.solver.status),
        file.solver.objective
    );
    let _ = writeln!(
        svg,
        r##"<text x="{MARGIN_L}" y="42" font-size="12" fill="#555" {FONT}>{}; pale red = keep-out; squares = front feet, circles = back feet, diamonds = CoMs; colour = stance</text>"##,
        esc(&ground_text(s))
    );
    let _ = writeln!(svg, "<defs>");
    l.top.clip(svg, "clip-top");
    l.side.clip(svg, "clip-side");
    let _ = writeln!(svg, "</defs>");
}

/// `x,y x,y …` (px, one decimal) of points already mapped to the figure.
fn points_attr(points: impl Iterator<Item = (f64, f64)>) -> String {
    points
        .map(|(x, y)| format!("{x:.1},{y:.1}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Every stance's feet and CoMs as markers, then the goal CoMs; `at` maps a point to px.
fn stance_markers(svg: &mut String, file: &SolutionFile, at: impl Fn(Vec3) -> (f64, f64)) {
    let n = file.stances.len().max(1);
    for (k, x) in file.stances.iter().enumerate() {
        let c = stance_colour(k, n);
        for i in Foot::ALL {
            let (px, py) = at(x.feet.get(i));
            foot_marker(svg, px, py, i, &c);
        }
        for j in Biped::ALL {
            let (px, py) = at(x.com.get(j));
            com_marker(svg, px, py, &c);
        }
    }
    for j in Biped::ALL {
        let (px, py) = at(file.scenario.goal.get(j));
        goal_marker(svg, px, py, &format!("goal {j}"));
    }
}

/// The top view: terrain, foot trails, CoM paths, support polygons, markers.
fn top_view(svg: &mut String, file: &SolutionFile, top: &Panel, terrain: &dyn Terrain) {
    let st = &file.stances;
    let at = |p: Vec3| (top.px(p[0]), top.py(p[1]));
    top.axes(svg, "x (m)", "y (m)", "Top view (x–y)");
    let _ = writeln!(svg, r##"<g clip-path="url(#clip-top)">"##);
    terrain_top(svg, top, &file.scenario, terrain);
    // Foot trails (thin grey) and CoM paths.
    for i in Foot::ALL {
        let _ = writeln!(
            svg,
            r##"<polyline points="{}" fill="none" stroke="#999" stroke-width="0.8"/>"##,
            points_attr(st.iter().map(|x| at(x.feet.get(i))))
        );
    }
    for j in Biped::ALL {
        let _ = writeln!(
            svg,
            r##"<polyline points="{}" fill="none" stroke="#444" stroke-width="1" stroke-dasharray="3,2"/>"##,
            points_attr(st.iter().map(|x| at(x.com.get(j))))
        );
    }
    // Support polygons BR → FR → FL → BL.
    let n = st.len().max(1);
    for (k, x) in st.iter().enumerate() {
        let corners = [Foot::BR, Foot::FR, Foot::FL, Foot::BL];
        let _ = writeln!(
            svg,
            r#"<polygon points="{}" fill="{c}" fill-opacity="0.02" stroke="{c}" stroke-opacity="0.5" stroke-width="0.8"/>"#,
            points_attr(corners.iter().map(|&i| at(x.feet.get(i)))),
            c = stance_colour(k, n)
        );
    }
    stance_markers(svg, file, at);
    let _ = writeln!(svg, "</g>");
}

/// The side view: terrain profile, legs (CoM to foot), markers, and a note when the
/// gap is deeper than shown.
fn side_view(svg: &mut String, file: &SolutionFile, l: &Layout, terrain: &dyn Terrain) {
    let (s, side) = (&file.scenario, &l.side);
    let (xr, zr) = (side.xr, side.yr);
    side.axes(svg, "x (m)", "z (m)", "Side view (x–z)");
    let _ = writeln!(svg, r##"<g clip-path="url(#clip-side)">"##);
    let y_side = terrain_view::side_y(s);
    let tx = terrain_view::profile_xs(s, xr.0, xr.1);
    terrain_side(svg, side, s, terrain, &tx);
    let mut d = format!("M{:.1},{:.1}", side.px(xr.0), side.py(zr.0));
    for &x in &tx {
        let _ = write!(
            d,
            " L{:.2},{:.2}",
            side.px(x),
            side.py(terrain.height_at(x, y_side).max(zr.0))
        );
    }
    let _ = write!(d, " L{:.1},{:.1} Z", side.px(xr.1), side.py(zr.0));
    let _ = writeln!(
        svg,
        r##"<path d="{d}" fill="#c8b08a" stroke="#6b4f2a" stroke-width="1.2"/>"##
    );
    let n = file.stances.len().max(1);
    for (k, x) in file.stances.iter().enumerate() {
        let c = stance_colour(k, n);
        for i in Foot::ALL {
            let (p, q) = (x.com.get(i.biped()), x.feet.get(i));
            let _ = writeln!(
                svg,
                r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{c}" stroke-opacity="0.35" stroke-width="0.8"/>"#,
                side.px(p[0]),
                side.py(p[2]),
                side.px(q[0]),
                side.py(q[2])
            );
        }
    }
    stance_markers(svg, file, |p| (side.px(p[0]), side.py(p[2])));
    if l.depth > l.shown_depth {
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" font-size="11" text-anchor="middle" {FONT}>depth {} m (cut)</text>"#,
            side.px(terrain_view::edges(s).first().map_or(xr.0, |e| e.0)),
            side.py(zr.0) - 4.0,
            l.depth
        );
    }
    let _ = writeln!(svg, "</g>");
}

/// The legend right of the top view: the stance colour bar (1 to `n_stances`) and the
/// marker key.
fn legend(svg: &mut String, ly: f64, n_stances: usize) {
    let lx = WIDTH - MARGIN_R + 25.0;
    let _ = writeln!(
        svg,
        r#"<text x="{lx}" y="{:.1}" font-size="12" font-weight="bold" {FONT}>stance</text>"#,
        ly + 4.0
    );
    let bar_h = 160.0;
    let _ = writeln!(
        svg,
        r#"<defs><linearGradient id="ramp" x1="0" y1="1" x2="0" y2="0">"#
    );
    for i in 0..=10 {
        let _ = writeln!(
            svg,
            r#"<stop offset="{:.2}" stop-color="{}"/>"#,
            i as f64 / 10.0,
            ramp(i as f64 / 10.0)
        );
    }
    let _ = writeln!(svg, "</linearGradient></defs>");
    let _ = writeln!(
        svg,
        r##"<rect x="{lx}" y="{:.1}" width="16" height="{bar_h}" fill="url(#ramp)" stroke="#333" stroke-width="0.6"/>"##,
        ly + 14.0
    );
    let _ = writeln!(
        svg,
        r#"<text x="{:.1}" y="{:.1}" font-size="11" {FONT}>{}</text><text x="{:.1}" y="{:.1}" font-size="11" {FONT}>1</text>"#,
        lx + 22.0,
        ly + 24.0,
        n_stances,
        lx + 22.0,
        ly + 14.0 + bar_h
    );
    marker_key(svg, lx, ly + bar_h + 40.0);
}

/// The legend's marker key, one row per kind of mark, from `y` down.
fn marker_key(svg: &mut String, lx: f64, mut y: f64) {
    let grey = "#bbbbbb";
    let items: [(&str, u8); 5] = [
        ("back foot (BR, BL)", 0),
        ("front foot (FR, FL)", 1),
        ("CoM (B, F)", 2),
        ("goal CoM", 3),
        ("gap / keep-out", 4),
    ];
    for (label, kind) in items {
        match kind {
            0 => foot_marker(svg, lx + 8.0, y, Foot::BR, grey),
            1 => foot_marker(svg, lx + 8.0, y, Foot::FR, grey),
            2 => com_marker(svg, lx + 8.0, y, grey),
            3 => {
                let _ = writeln!(
                    svg,
                    r##"<circle cx="{:.1}" cy="{y:.1}" r="6" fill="none" stroke="#d62728" stroke-width="1.6"/>"##,
                    lx + 8.0
                );
            }
            _ => {
                let _ = writeln!(
                    svg,
                    r##"<rect x="{lx}" y="{:.1}" width="8" height="12" fill="#7f1d1d" fill-opacity="0.45"/><rect x="{:.1}" y="{:.1}" width="8" height="12" fill="#d62728" fill-opacity="0.15"/>"##,
                    y - 6.0,
                    lx + 8.0,
                    y - 6.0
                );
            }
        }
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" font-size="11" {FONT}>{label}</text>"#,
            lx + 22.0,
            y + 4.0
        );
        y += 22.0;
    }
}

/// The plan figure (top view above side view) of a solution file.
pub fn plan_svg(file: &SolutionFile) -> String {
    let terrain = terrain::of(&file.scenario);
    let layout = Layout::of(file, &*terrain);
    let mut svg = String::new();
    header(&mut svg, file, &layout);
    top_view(&mut svg, file, &layout.top, &*terrain);
    side_view(&mut svg, file, &layout, &*terrain);
    legend(&mut svg, layout.top.y0, file.stances.len());
    let _ = writeln!(svg, "</svg>");
    svg
}
