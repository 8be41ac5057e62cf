//! The convergence figure: three stacked panels sharing the iteration axis — |objective|,
//! constraint violation and the residual of (10) — each on its own log scale, with the
//! solver runs (phases) separated by dashed lines and numbered.
//!
//! Values that a log axis cannot show (0, negative, non-finite) break the line. In
//! scheduled runs the (10) residual is exactly 0 by construction; the panel says so in
//! that run's span instead of drawing a made-up floor.

use super::{esc, nice_step, svg_open, ticks, FONT, MARGIN_L, WIDTH};
use crate::convergence::{Convergence, Iteration};
use std::fmt::Write;

const PANEL_H: f64 = 150.0;
const PANEL_GAP: f64 = 34.0;
const TOP: f64 = 80.0;
const RIGHT: f64 = 40.0;

/// One series: a panel's quantity.
struct Series {
    title: &'static str,
    colour: &'static str,
    get: fn(&Iteration) -> Option<f64>,
}

const SERIES: [Series; 3] = [
    Series {
        title: "|objective| (cost (1); + penalty π·Σ sᵢsⱼ while choosing the steps)",
        colour: "#1f77b4",
        get: |r| Some(r.objective.abs()),
    },
    Series {
        title: "constraint violation inf_pr (max-norm)",
        colour: "#d62728",
        get: |r| Some(r.inf_pr),
    },
    Series {
        title: "residual of (10): max over transitions of Σ_{i<j} ‖Δrᵢ‖²‖Δrⱼ‖² (m⁴)",
        colour: "#2ca02c",
        get: |r| r.residual_10,
    },
];

fn drawable(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// The horizontal map of the figure: history index → pixels.
struct XAxis {
    x0: f64,
    w: f64,
    n: f64,
}

impl XAxis {
    fn px(&self, i: f64) -> f64 {
        self.x0 + i / self.n.max(1.0) * self.w
    }
}

/// One panel: a log-scale y axis over decades `lo..hi`.
struct LogPanel {
    y0: f64,
    lo: f64,
    hi: f64,
}

impl LogPanel {
    /// Decades spanning the drawable values (1e-1..1e1 when there are none).
    fn fit(y0: f64, values: impl Iterator<Item = f64>) -> LogPanel {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| drawable(*v)) {
            lo = lo.min(v.log10().floor());
            hi = hi.max(v.log10().ceil());
        }
        if !lo.is_finite() {
            (lo, hi) = (-1.0, 1.0);
        }
        if hi <= lo {
            hi = lo + 1.0;
        }
        LogPanel { y0, lo, hi }
    }

    fn py(&self, v: f64) -> f64 {
        self.y0 + (self.hi - v.log10()) / (self.hi - self.lo) * PANEL_H
    }

    /// Frame, decade grid and labels, title.
    fn axes(&self, svg: &mut String, x: &XAxis, title: &str) {
        let _ = writeln!(
            svg,
            r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{PANEL_H}" fill="white" stroke="#333"/>"##,
            x.x0, self.y0, x.w
        );
        let decades = (self.hi - self.lo) as i64;
        let every = ((decades as f64) / 6.0).ceil().max(1.0) as i64;
        for e in (self.lo as i64)..=(self.hi as i64) {
            let y = self.py(10f64.powi(e as i32));
            let _ = writeln!(
                svg,
                r##"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e4e4e4" stroke-width="0.6"/>"##,
                x.x0,
                x.x0 + x.w
            );
            if (e - self.lo as i64) % every == 0 {
                let _ = writeln!(
                    svg,
                    r##"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#333"/><text x="{:.1}" y="{:.1}" font-size="11" text-anchor="end" {FONT}>1e{e}</text>"##,
                    x.x0 - 5.0,
                    x.x0,
                    x.x0 - 8.0,
                    y + 4.0
                );
            }
        }
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" font-size="12" font-weight="bold" {FONT}>{}</text>"#,
            x.x0,
            self.y0 - 6.0,
            esc(title)
        );
    }

    /// The series as a polyline, broken where a value cannot be drawn.
    fn line(&self, svg: &mut String, x: &XAxis, rows: &[Iteration], s: &Series) {
        let mut d = String::new();
        let mut pen_up = true;
        let mut points = Vec::new();
        for r in rows {
            match (s.get)(r).filter(|v| drawable(*v)) {
                Some(v) => {
                    let p = (x.px(r.index as f64), self.py(v));
                    let _ = write!(
                        d,
                        "{}{:.1},{:.1} ",
                        if pen_up { "M" } else { "L" },
                        p.0,
                        p.1
                    );
                    pen_up = false;
                    points.push(p);
                }
                None => pen_up = true,
            }
        }
        if !d.is_empty() {
            let _ = writeln!(
                svg,
                r#"<path d="{}" fill="none" stroke="{}" stroke-width="1.5"/>"#,
                d.trim_end(),
                s.colour
            );
        }
        // A lone point (one iteration) would be invisible as a path.
        if let [(px, py)] = points[..] {
            let _ = writeln!(
                svg,
                r#"<circle cx="{px:.1}" cy="{py:.1}" r="2.5" fill="{}"/>"#,
                s.colour
            );
        }
    }

    /// A grey note centred in a horizontal span of the panel (kept inside the frame).
    fn note(&self, svg: &mut String, x: &XAxis, x_mid: f64, text: &str) {
        let half = 3.2 * text.chars().count() as f64;
        let x_mid = x_mid.clamp(x.x0 + half + 4.0, x.x0 + x.w - half - 4.0);
        let _ = writeln!(
            svg,
            r##"<text x="{x_mid:.1}" y="{:.1}" font-size="11" text-anchor="middle" fill="#777" {FONT}>{}</text>"##,
            self.y0 + PANEL_H / 2.0 + 4.0,
            esc(text)
        );
    }
}

/// The opening `<svg>`, background, title and subtitle.
fn header(svg: &mut String, x: &XAxis, height: f64, title: &str) {
    svg_open(svg, WIDTH, height, "");
    let _ = writeln!(
        svg,
        r#"<text x="{:.1}" y="24" font-size="16" font-weight="bold" {FONT}>{}</text>"#,
        x.x0,
        esc(title)
    );
    let _ = writeln!(
        svg,
        r##"<text x="{:.1}" y="42" font-size="12" fill="#555" {FONT}>per iteration of every solver run, log scales; dashed lines separate the runs (numbered, listed below)</text>"##,
        x.x0
    );
}

/// Restoration iterations, shaded in every panel.
fn restoration_shading(svg: &mut String, x: &XAxis, panels: &[LogPanel], rows: &[Iteration]) {
    let mut k = 0;
    while k < rows.len() {
        if !rows[k].restoration {
            k += 1;
            continue;
        }
        let start = k;
        while k < rows.len() && rows[k].restoration {
            k += 1;
        }
        let a = x.px(start as f64 - 0.5).max(x.x0);
        let b = x.px(k as f64 - 0.5).min(x.x0 + x.w);
        for p in panels {
            let _ = writeln!(
                svg,
                r##"<rect x="{a:.1}" y="{:.1}" width="{:.1}" height="{PANEL_H}" fill="#f5b041" fill-opacity="0.18"/>"##,
                p.y0,
                b - a
            );
        }
    }
}

/// Iteration ticks under the last panel (whose bottom is at `bottom`), grid lines
/// through all, and the axis name.
fn iteration_axis(svg: &mut String, x: &XAxis, panels: &[LogPanel], bottom: f64) {
    let step = nice_step(x.n.max(1.0), 10.0).max(1.0);
    for t in ticks(0.0, x.n.max(1.0), 10.0) {
        if (t / step).fract().abs() > 1e-9 || t > x.n {
            continue;
        }
        let px = x.px(t);
        for p in panels {
            let _ = writeln!(
                svg,
                r##"<line x1="{px:.1}" y1="{:.1}" x2="{px:.1}" y2="{:.1}" stroke="#eee" stroke-width="0.6"/>"##,
                p.y0,
                p.y0 + PANEL_H
            );
        }
        let _ = writeln!(
            svg,
            r##"<line x1="{px:.1}" y1="{bottom:.1}" x2="{px:.1}" y2="{:.1}" stroke="#333"/><text x="{px:.1}" y="{:.1}" font-size="11" text-anchor="middle" {FONT}>{}</text>"##,
            bottom + 5.0,
            bottom + 18.0,
            t as i64
        );
    }
    let _ = writeln!(
        svg,
        r#"<text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle" {FONT}>iteration (all runs, numbered on)</text>"#,
        x.x0 + x.w / 2.0,
        bottom + 36.0
    );
}

/// The runs: dashed boundaries, numbers above the panels, and the (10) panel's note
/// for a run with nothing to draw there.
fn runs(svg: &mut String, x: &XAxis, resid: &LogPanel, c: &Convergence, bottom: f64) {
    let rows = &c.iterations;
    for (k, span) in c.phases.iter().enumerate() {
        let a = x.px(span.first as f64);
        let b = x.px((span.first + span.len).saturating_sub(1) as f64);
        if k > 0 {
            let _ = writeln!(
                svg,
                r##"<line x1="{a:.1}" y1="{:.1}" x2="{a:.1}" y2="{bottom:.1}" stroke="#555" stroke-width="1" stroke-dasharray="5,4"/>"##,
                TOP - 14.0
            );
        }
        let _ = writeln!(
            svg,
            r##"<text x="{:.1}" y="{:.1}" font-size="12" font-weight="bold" text-anchor="middle" fill="#555" {FONT}>{}</text>"##,
            (a + b) / 2.0,
            TOP - 22.0,
            k + 1
        );
        let rows_k = &rows[span.first.min(rows.len())..(span.first + span.len).min(rows.len())];
        if span.scheduled {
            let text = if b - a > 130.0 {
                "≡ 0: schedule fixed"
            } else {
                "≡ 0"
            };
            resid.note(svg, x, (a + b) / 2.0, text);
        } else if rows_k.iter().all(|r| r.residual_10.is_none()) {
            resid.note(svg, x, (a + b) / 2.0, "not recorded");
        } else if !rows_k.iter().any(|r| r.residual_10.is_some_and(drawable)) {
            resid.note(svg, x, (a + b) / 2.0, "0 at every iterate");
        }
    }
}

/// The list of runs under the figure from `legend_y` down, the restoration key when
/// there was any, and a note when nothing was recorded.
fn legend(svg: &mut String, x: &XAxis, c: &Convergence, legend_y: f64) {
    let rows = &c.iterations;
    for (k, span) in c.phases.iter().enumerate() {
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" font-size="12" {FONT}><tspan font-weight="bold">{}</tspan>  {} — {}, {} iterations{}</text>"#,
            x.x0,
            legend_y + 18.0 * k as f64,
            k + 1,
            esc(&span.name),
            esc(&span.status),
            span.iterations,
            if span.scheduled {
                " (scheduled: (10) exact by construction)"
            } else {
                ""
            }
        );
    }
    if rows.iter().any(|r| r.restoration) {
        let _ = writeln!(
            svg,
            r##"<rect x="{:.1}" y="{:.1}" width="14" height="10" fill="#f5b041" fill-opacity="0.35"/><text x="{:.1}" y="{:.1}" font-size="12" {FONT}>restoration phase (its objective is the restoration problem's, not (1))</text>"##,
            x.x0,
            legend_y + 18.0 * c.phases.len() as f64 - 9.0,
            x.x0 + 20.0,
            legend_y + 18.0 * c.phases.len() as f64
        );
    }
    if rows.is_empty() {
        let _ = writeln!(
            svg,
            r##"<text x="{:.1}" y="{:.1}" font-size="14" text-anchor="middle" fill="#777" {FONT}>no iterations recorded</text>"##,
            x.x0 + x.w / 2.0,
            TOP + PANEL_H / 2.0
        );
    }
}

/// The convergence figure of a planning run's history.
pub fn convergence_svg(c: &Convergence, title: &str) -> String {
    let rows = &c.iterations;
    let x = XAxis {
        x0: MARGIN_L + 10.0,
        w: WIDTH - MARGIN_L - 10.0 - RIGHT,
        n: rows.len().saturating_sub(1) as f64,
    };
    let panels: Vec<LogPanel> = SERIES
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let y0 = TOP + k as f64 * (PANEL_H + PANEL_GAP);
            LogPanel::fit(y0, rows.iter().filter_map(s.get))
        })
        .collect();
    let bottom = TOP + 3.0 * PANEL_H + 2.0 * PANEL_GAP;
    let legend_y = bottom + 52.0;
    let height = legend_y + 18.0 * (c.phases.len() + 1) as f64 + 10.0;

    let mut svg = String::new();
    header(&mut svg, &x, height, title);
    for (p, s) in panels.iter().zip(&SERIES) {
        p.axes(&mut svg, &x, s.title);
    }
    restoration_shading(&mut svg, &x, &panels, rows);
    iteration_axis(&mut svg, &x, &panels, bottom);
    runs(&mut svg, &x, &panels[2], c, bottom);
    for (p, s) in panels.iter().zip(&SERIES) {
        p.line(&mut svg, &x, rows, s);
    }
    legend(&mut svg, &x, c, legend_y);
    let _ = writeln!(svg, "</svg>");
    svg
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convergence::PhaseSpan;

    fn row(index: usize, phase: usize, residual_10: Option<f64>) -> Iteration {
        Iteration {
            index,
            phase,
            iter: index,
            restoration: false,
            objective: if index == 0 { -3.0 } else { 2.0 },
            inf_pr: if index == 0 { 1.0 } else { 0.0 },
            residual_10,
            mu: 0.1,
        }
    }

    #[test]
    fn handles_zeros_scheduled_runs_and_empty() {
        let span = |name: &str, first, len, scheduled| PhaseSpan {
            name: name.into(),
            status: "SolveSucceeded".into(),
            scheduled,
            first,
            len,
            iterations: len - 1,
        };
        let c = Convergence {
            version: 2,
            phases: vec![span("crawl", 0, 2, true), span("choose", 2, 2, false)],
            iterations: vec![
                row(0, 0, Some(0.0)),
                row(1, 0, Some(0.0)),
                row(2, 1, Some(1e-3)),
                row(3, 1, Some(1e-12)),
            ],
        };
        let s = convergence_svg(&c, "t");
        assert!(s.starts_with("<svg") && s.trim_end().ends_with("</svg>"));
        assert!(!s.contains("NaN") && !s.contains("\"inf"));
        assert!(s.contains("≡ 0: schedule fixed"));
        assert!(s.contains("stroke-dasharray"), "run boundary");
        assert_eq!(s.matches("<path").count(), 3, "one line per panel");
        let empty = Convergence {
            version: 2,
            phases: vec![],
            iterations: vec![],
        };
        assert!(convergence_svg(&empty, "t").contains("no iterations"));
    }
}
