//! Plots as plain, hand-written SVG (no plotting crate), one figure per module:
//!
//! - [`plan`] ([`plan_svg`]): top view (x–y) of every stance — feet, CoMs and the support
//!   polygon coloured by stance index, the gap and its safety margin shaded — above a
//!   side view (x–z) with the terrain profile, feet, CoMs and legs. Both views use equal
//!   scales on their two axes, so distances and leg geometry read true.
//! - [`convergence`] ([`convergence_svg`]): objective, constraint violation and the
//!   residual of (10) per iteration of every solver run, each on its own log scale, with
//!   the runs' boundaries marked.
//! - [`sweep`] ([`sweep_svg`]): a sweep's points as a heat map of wall time and failures.
//! - [`html`] ([`plan_html`]): the plan animated, one stance at a time, with a slider and
//!   a play button (a self-contained HTML page with inline SVG and script).
//!
//! - [`terrain_view`]: the terrain as drawn (data coordinates), shared by `plan.svg`
//!   and `plan.html`.
//!
//! This module holds what they share: sizes, fonts, the colour ramp, escaping and ticks.

pub mod convergence;
pub mod html;
pub mod plan;
pub mod sweep;
pub mod terrain_view;

pub use convergence::convergence_svg;
pub use html::plan_html;
pub use plan::plan_svg;
pub use sweep::sweep_svg;

use std::fmt::Write;

/// Width of every figure (px).
pub(crate) const WIDTH: f64 = 1000.0;
pub(crate) const MARGIN_L: f64 = 70.0;
pub(crate) const MARGIN_R: f64 = 170.0;
pub(crate) const FONT: &str = "font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\"";

/// Opens a figure `width` × `height` px (whole pixels) with `attrs` on the `<svg>`
/// element (empty, or starting with a space) and paints its background white.
pub(crate) fn svg_open(svg: &mut String, width: f64, height: f64, attrs: &str) {
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}"{attrs}>"#
    );
    let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
}

/// Viridis-like colour ramp, t in [0, 1] → `#rrggbb`.
pub fn ramp(t: f64) -> String {
    const STOPS: [[f64; 3]; 6] = [
        [68.0, 1.0, 84.0],
        [65.0, 68.0, 135.0],
        [42.0, 120.0, 142.0],
        [34.0, 168.0, 132.0],
        [122.0, 209.0, 81.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let c: Vec<u8> = (0..3)
        .map(|a| (STOPS[i][a] * (1.0 - f) + STOPS[i + 1][a] * f).round() as u8)
        .collect();
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// Escapes text for SVG/HTML content and attribute values.
pub(crate) fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A "nice" tick step (1, 2 or 5 × 10ⁿ) giving about `target` ticks over `span`.
pub(crate) fn nice_step(span: f64, target: f64) -> f64 {
    if !span.is_finite() || span <= 0.0 {
        return 1.0;
    }
    let raw = span / target;
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    let n = if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    };
    n * p
}

pub(crate) fn ticks(lo: f64, hi: f64, target: f64) -> Vec<f64> {
    let step = nice_step(hi - lo, target);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + step * 1e-9 && out.len() < 100 {
        out.push(if t.abs() < step * 1e-9 { 0.0 } else { t });
        t += step;
    }
    out
}

pub(crate) fn fmt_tick(v: f64, step: f64) -> String {
    let decimals = if step >= 1.0 {
        0
    } else {
        (-step.log10()).ceil() as usize
    };
    format!("{v:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_ends() {
        assert_eq!(ramp(0.0), "#440154");
        assert_eq!(ramp(1.0), "#fde725");
        assert_eq!(ramp(f64::NAN), "#440154");
    }

    #[test]
    fn nice_ticks() {
        assert_eq!(nice_step(6.0, 12.0), 0.5);
        assert_eq!(ticks(-0.4, 1.3, 4.0), vec![0.0, 0.5, 1.0]);
    }
}
