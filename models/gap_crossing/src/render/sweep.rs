//! The sweep figure (`sweep.svg`): a heat map of a parameter sweep's points.

use super::{esc, ramp, svg_open, FONT};
use crate::sweep::{label, Grid, PointResult};
use std::fmt::Write as _;

/// Text colour readable on a `#rrggbb` fill.
fn ink(fill: &str) -> &'static str {
    let c = |i: usize| u8::from_str_radix(&fill[i..i + 2], 16).unwrap_or(0) as f64;
    if fill.len() == 7 && 0.299 * c(1) + 0.587 * c(3) + 0.114 * c(5) > 140.0 {
        "#111"
    } else {
        "#fff"
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn fmt_secs(s: f64) -> String {
    if s < 10.0 {
        format!("{s:.2} s")
    } else {
        format!("{s:.1} s")
    }
}

const FAIL_FILL: &str = "#e7a3a0";
/// The log-scale colour map of wall times, fitted to the points that succeeded.
struct TimeScale {
    /// log₁₀ of the shortest and longest time (s).
    lmin: f64,
    lmax: f64,
    /// False when no point succeeded (the bar is then unlabelled).
    any: bool,
}

impl TimeScale {
    fn of(results: &[PointResult]) -> TimeScale {
        let ok_times: Vec<f64> = results
            .iter()
            .filter(|r| r.ok())
            .map(|r| r.seconds)
            .collect();
        let (tmin, tmax) = ok_times
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
        let (lmin, lmax) = if ok_times.is_empty() {
            (0.0, 1.0)
        } else {
            let (a, b) = (tmin.max(1e-3).log10(), tmax.max(1e-3).log10());
            if b - a < 1e-9 {
                (a - 0.5, b + 0.5)
            } else {
                (a, b)
            }
        };
        TimeScale {
            lmin,
            lmax,
            any: !ok_times.is_empty(),
        }
    }

    fn colour(&self, t: f64) -> String {
        ramp((t.max(1e-3).log10() - self.lmin) / (self.lmax - self.lmin))
    }
}

/// Sizes (px) and counts: `nx` columns, `ny` rows, `np` panels, `per_row` panels a row.
struct Layout {
    nx: usize,
    ny: usize,
    np: usize,
    per_row: usize,
    /// Cell size, the grid's offset inside a panel, and a panel's size.
    cw: f64,
    ch: f64,
    left: f64,
    top: f64,
    panel_w: f64,
    panel_h: f64,
    width: f64,
    height: f64,
}

impl Layout {
    fn of(grid: &Grid) -> Layout {
        let n_of = |d: usize| grid.axes.get(d).map_or(1, |a| a.values.len());
        let (nx, ny, np) = (n_of(0), n_of(1), n_of(2));
        let (cw, ch) = (96.0, 54.0);
        let left = 110.0;
        let top = 70.0;
        let panel_w = left + nx as f64 * cw + 30.0;
        let panel_h = ch * ny as f64 + 70.0;
        let per_row = np.min(3);
        let panel_rows = np.div_ceil(per_row);
        let legend_w = 210.0;
        Layout {
            nx,
            ny,
            np,
            per_row,
            cw,
            ch,
            left,
            top,
            panel_w,
            panel_h,
            width: (per_row as f64 * panel_w + legend_w).max(560.0),
            height: top + panel_rows as f64 * panel_h + 40.0,
        }
    }
}

/// The results grouped by cell, indexed `(panel · ny + row) · nx + column`.
fn cells<'a>(grid: &Grid, l: &Layout, results: &'a [PointResult]) -> Vec<Vec<&'a PointResult>> {
    let mut cells: Vec<Vec<&PointResult>> = vec![Vec::new(); l.nx * l.ny * l.np];
    let points = grid.points();
    for r in results {
        let Some(pt) = points.get(r.index) else {
            continue;
        };
        let c = |d: usize| pt.coords.get(d).copied().unwrap_or(0);
        cells[(c(2) * l.ny + c(1)) * l.nx + c(0)].push(r);
    }
    cells
}

/// The opening `<svg>`, background, title and subtitle.
fn header(svg: &mut String, grid: &Grid, l: &Layout, results: &[PointResult]) {
    svg_open(svg, l.width, l.height, &format!(" {FONT} font-size=\"12\""));
    let ok = results.iter().filter(|r| r.ok()).count();
    let _ = writeln!(
        svg,
        r#"<text x="16" y="26" font-size="17" font-weight="bold">Sweep: {ok} of {} points solved and checked</text>"#,
        results.len()
    );
    let aggregated: Vec<&str> = grid.axes.iter().skip(3).map(|a| a.key.as_str()).collect();
    let sub = if aggregated.is_empty() {
        "cell colour: wall time of the solve (log scale)".to_string()
    } else {
        format!(
            "each cell aggregates {}: colour = median wall time of its points (log scale)",
            aggregated.join(", ")
        )
    };
    let _ = writeln!(
        svg,
        r##"<text x="16" y="46" fill="#444">{}</text>"##,
        esc(&sub)
    );
}

/// What one cell shows: its fill, one or two lines of text, and whether it gets the
/// red "some points failed" frame.
struct CellLook {
    fill: String,
    line1: String,
    line2: String,
    frame: bool,
}

impl CellLook {
    fn of(cell: &[&PointResult], scale: &TimeScale) -> CellLook {
        let good: Vec<&&PointResult> = cell.iter().filter(|r| r.ok()).collect();
        let (fill, line1, line2, frame) = if cell.is_empty() {
            (
                "#eeeeee".to_string(),
                "not run".to_string(),
                String::new(),
                false,
            )
        } else if good.is_empty() {
            let status = &cell[0].status;
            let why = if status.is_solved() {
                "check failed".to_string()
            } else {
                status.word().replace('_', " ")
            };
            let first = if cell.len() > 1 {
                format!("0/{} ok", cell.len())
            } else {
                "failed".into()
            };
            (FAIL_FILL.to_string(), first, why, false)
        } else {
            let t = median(good.iter().map(|r| r.seconds).collect());
            let l2 = if good.len() < cell.len() {
                format!("{}/{} ok", good.len(), cell.len())
            } else if cell.len() > 1 {
                format!("{} points", cell.len())
            } else {
                String::new()
            };
            (scale.colour(t), fmt_secs(t), l2, good.len() < cell.len())
        };
        CellLook {
            fill,
            line1,
            line2,
            frame,
        }
    }

    /// Draws the cell with its top-left corner at `(x, y)`.
    fn draw(&self, svg: &mut String, l: &Layout, x: f64, y: f64) {
        let (cw, ch, fill) = (l.cw, l.ch, &self.fill);
        let _ = writeln!(
            svg,
            r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{fill}" stroke="white" stroke-width="2"/>"##,
            x, y, cw, ch
        );
        if self.frame {
            let _ = writeln!(
                svg,
                r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#c0392b" stroke-width="3"/>"##,
                x + 2.5,
                y + 2.5,
                cw - 5.0,
                ch - 5.0
            );
        }
        let tc = ink(fill);
        let (y1, y2) = if self.line2.is_empty() {
            (y + ch / 2.0, 0.0)
        } else {
            (y + ch / 2.0 - 8.0, y + ch / 2.0 + 9.0)
        };
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{y1:.1}" text-anchor="middle" dominant-baseline="middle" fill="{tc}" font-weight="bold">{}</text>"#,
            x + cw / 2.0,
            esc(&self.line1)
        );
        if !self.line2.is_empty() {
            let _ = writeln!(
                svg,
                r#"<text x="{:.1}" y="{y2:.1}" text-anchor="middle" dominant-baseline="middle" fill="{tc}" font-size="11">{}</text>"#,
                x + cw / 2.0,
                esc(&self.line2)
            );
        }
    }
}

/// Panel `pi` (the third axis's value `pi`): its title, rows of cells with their
/// labels, the column labels and both axis names.
fn panel(
    svg: &mut String,
    grid: &Grid,
    l: &Layout,
    cells: &[Vec<&PointResult>],
    pi: usize,
    scale: &TimeScale,
) {
    let axis = |d: usize| grid.axes.get(d);
    let (nx, ny, cw, ch) = (l.nx, l.ny, l.cw, l.ch);
    let ox = (pi % l.per_row) as f64 * l.panel_w;
    let oy = l.top + (pi / l.per_row) as f64 * l.panel_h;
    let gx = ox + l.left;
    let gy = oy + 24.0;
    if let Some(a) = axis(2) {
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" font-weight="bold">{} = {}</text>"#,
            gx,
            oy + 12.0,
            esc(&a.key),
            esc(&label(&a.values[pi]))
        );
    }
    for iy in 0..ny {
        // Row 0 at the top.
        let y = gy + iy as f64 * ch;
        let row_label = axis(1).map_or(String::new(), |a| label(&a.values[iy]));
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end" dominant-baseline="middle">{}</text>"#,
            gx - 8.0,
            y + ch / 2.0,
            esc(&row_label)
        );
        for ix in 0..nx {
            let cell = &cells[(pi * ny + iy) * nx + ix];
            CellLook::of(cell, scale).draw(svg, l, gx + ix as f64 * cw, y);
        }
    }
    // Column labels and axis names.
    let by = gy + ny as f64 * ch;
    for ix in 0..nx {
        let col_label = axis(0).map_or(String::new(), |a| label(&a.values[ix]));
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            gx + (ix as f64 + 0.5) * cw,
            by + 16.0,
            esc(&col_label)
        );
    }
    if let Some(a) = axis(0) {
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-weight="bold">{}</text>"#,
            gx + nx as f64 * cw / 2.0,
            by + 36.0,
            esc(&a.key)
        );
    }
    if let Some(a) = axis(1) {
        let cx = ox + 18.0;
        let cy = gy + ny as f64 * ch / 2.0;
        let _ = writeln!(
            svg,
            r#"<text x="{cx:.1}" y="{cy:.1}" text-anchor="middle" font-weight="bold" transform="rotate(-90 {cx:.1} {cy:.1})">{}</text>"#,
            esc(&a.key)
        );
    }
}

/// The legend right of the panels: the time colour bar and the failure swatches.
fn legend(svg: &mut String, l: &Layout, scale: &TimeScale) {
    let lx = l.per_row as f64 * l.panel_w + 10.0;
    let ly = l.top + 34.0;
    let _ = writeln!(
        svg,
        r#"<text x="{lx:.1}" y="{:.1}" font-weight="bold">wall time (s)</text>"#,
        ly - 16.0
    );
    let bar_h = 140.0;
    let steps = 28;
    for k in 0..steps {
        let t = 1.0 - (k as f64 + 0.5) / steps as f64;
        let _ = writeln!(
            svg,
            r#"<rect x="{lx:.1}" y="{:.2}" width="18" height="{:.2}" fill="{}"/>"#,
            ly + k as f64 * bar_h / steps as f64,
            bar_h / steps as f64 + 0.3,
            ramp(t)
        );
    }
    if !scale.any {
        let _ = writeln!(
            svg,
            r##"<text x="{:.1}" y="{:.1}" fill="#444">(no success)</text>"##,
            lx + 26.0,
            ly + bar_h / 2.0
        );
    } else {
        let (lmin, lmax) = (scale.lmin, scale.lmax);
        for (frac, log_t) in [(0.0, lmax), (0.5, 0.5 * (lmin + lmax)), (1.0, lmin)] {
            let _ = writeln!(
                svg,
                r#"<text x="{:.1}" y="{:.1}" dominant-baseline="middle">{}</text>"#,
                lx + 26.0,
                ly + frac * bar_h,
                fmt_secs(10f64.powf(log_t))
            );
        }
    }
    let sy = ly + bar_h + 24.0;
    let _ = writeln!(
        svg,
        r#"<rect x="{lx:.1}" y="{sy:.1}" width="18" height="14" fill="{FAIL_FILL}"/><text x="{:.1}" y="{:.1}">no point solved + checked</text>"#,
        lx + 26.0,
        sy + 11.0
    );
    let _ = writeln!(
        svg,
        r##"<rect x="{:.1}" y="{:.1}" width="15" height="11" fill="none" stroke="#c0392b" stroke-width="3"/><text x="{:.1}" y="{:.1}">some points failed</text>"##,
        lx + 1.5,
        sy + 25.5,
        lx + 26.0,
        sy + 35.0
    );
}

/// The SVG heat map: columns are the first axis's values, rows the second's, one panel
/// per value of the third; any further axes are aggregated in each cell. A cell whose
/// points all solved and checked is coloured by their median wall time (log scale) and
/// shows it; a cell with failures has a red frame and says how many of its points
/// succeeded; a cell with no success is pale red and names the first failure status.
pub fn sweep_svg(grid: &Grid, results: &[PointResult]) -> String {
    let layout = Layout::of(grid);
    let scale = TimeScale::of(results);
    let cells = cells(grid, &layout, results);
    let mut svg = String::new();
    header(&mut svg, grid, &layout, results);
    for pi in 0..layout.np {
        panel(&mut svg, grid, &layout, &cells, pi, &scale);
    }
    legend(&mut svg, &layout, &scale);
    svg.push_str("</svg>\n");
    svg
}
