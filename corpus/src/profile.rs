//! The comparison report: a table of symnlp against IPOPT per instance and Dolan–Moré
//! performance profiles (E. D. Dolan, J. J. Moré, "Benchmarking optimization software with
//! performance profiles", Math. Program. 91, 2002) as plain SVG.
//!
//! For a metric t (iterations or seconds) and solver s, the ratio of problem p is
//! `r = t(p, s) / min over solvers t(p, ·)` (∞ if s failed); the profile is
//! `ρ_s(τ) = share of problems with r ≤ τ`, drawn against log₂ τ. A solve counts as a
//! success when its status is a success; instances where neither solver succeeded are left
//! out.
use crate::CorpusError;
use serde_json::Value;
use std::fmt::Write;

/// One solver's result on one instance.
#[derive(Clone, Debug, PartialEq)]
pub struct SolverResult {
    /// Status in the solver's own words.
    pub status: String,
    /// Whether the status is a success.
    pub success: bool,
    /// Iterations.
    pub iterations: f64,
    /// Final objective.
    pub objective: f64,
    /// Solve wall time in seconds.
    pub seconds: f64,
}

/// One line of a results file: an instance solved by both solvers.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Instance name.
    pub instance: String,
    /// `Ocp` or `Cute`.
    pub kind: String,
    /// Variables.
    pub n: usize,
    /// Constraint rows.
    pub m: usize,
    /// Published optimum, if any.
    pub reference: Option<f64>,
    /// symnlp's interior-point method.
    pub symnlp: SolverResult,
    /// IPOPT through CasADi.
    pub ipopt: SolverResult,
}

fn field<'a>(v: &'a Value, key: &str, line: usize) -> Result<&'a Value, CorpusError> {
    v.get(key)
        .ok_or_else(|| CorpusError::Results(format!("line {line}: no field '{key}'")))
}

fn number(v: &Value, key: &str, line: usize) -> Result<f64, CorpusError> {
    let x = field(v, key, line)?;
    // serde_json writes non-finite numbers as null.
    Ok(x.as_f64().unwrap_or(f64::NAN))
}

fn solver(v: &Value, line: usize) -> Result<SolverResult, CorpusError> {
    Ok(SolverResult {
        status: field(v, "status", line)?
            .as_str()
            .unwrap_or("?")
            .to_string(),
        success: field(v, "success", line)?.as_bool().unwrap_or(false),
        iterations: number(v, "iterations", line)?,
        objective: number(v, "objective", line)?,
        seconds: number(v, "solve_s", line)?,
    })
}

/// Reads the JSON-lines results written by `benches/reference/corpus_ipopt.py`.
pub fn read(text: &str) -> Result<Vec<Row>, CorpusError> {
    let mut rows = Vec::new();
    for (k, line) in text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
    {
        let v: Value = serde_json::from_str(line)
            .map_err(|e| CorpusError::Results(format!("line {}: {e}", k + 1)))?;
        let s = field(&v, "symnlp", k + 1)?;
        rows.push(Row {
            instance: field(&v, "instance", k + 1)?
                .as_str()
                .unwrap_or("?")
                .to_string(),
            kind: field(s, "kind", k + 1)?.as_str().unwrap_or("?").to_string(),
            n: number(s, "n", k + 1)? as usize,
            m: number(s, "m", k + 1)? as usize,
            reference: s.get("reference").and_then(Value::as_f64),
            symnlp: solver(s, k + 1)?,
            ipopt: solver(field(&v, "ipopt", k + 1)?, k + 1)?,
        });
    }
    Ok(rows)
}

/// Relative difference `|a − b| / max(1, |b|)`.
pub fn relative_gap(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1.0)
}

/// The profile curves `[symnlp, ipopt]` as sorted performance ratios (∞ for failures) of
/// the instances where at least one solver succeeded.
pub fn ratios(rows: &[Row], metric: fn(&SolverResult) -> f64) -> [Vec<f64>; 2] {
    let mut out = [Vec::new(), Vec::new()];
    for r in rows.iter().filter(|r| r.symnlp.success || r.ipopt.success) {
        let t = [&r.symnlp, &r.ipopt].map(|s| {
            if s.success {
                metric(s).max(1e-4)
            } else {
                f64::INFINITY
            }
        });
        let best = t[0].min(t[1]);
        for s in 0..2 {
            out[s].push(t[s] / best);
        }
    }
    for o in &mut out {
        o.sort_by(f64::total_cmp);
    }
    out
}

/// Dolan–Moré profiles of the two solvers as one standalone SVG document: one panel per
/// `(title, ratios)`, side by side, under a common `title`.
pub fn svg(title: &str, panels: &[(String, [Vec<f64>; 2])]) -> String {
    let (w, h) = (640.0, 420.0);
    let mut s = String::new();
    let total = w * panels.len() as f64;
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{total}" height="{h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{total}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="20" text-anchor="middle" font-size="15">{title}</text>"#,
        total / 2.0
    );
    for (k, (name, ratios)) in panels.iter().enumerate() {
        let _ = writeln!(s, r#"<g transform="translate({},20)">"#, w * k as f64);
        panel(&mut s, name, ratios, w, h - 20.0);
        s.push_str("</g>\n");
    }
    s.push_str("</svg>\n");
    s
}

/// One profile panel of size `w × h` at the origin.
fn panel(s: &mut String, title: &str, ratios: &[Vec<f64>; 2], w: f64, h: f64) {
    let (left, right, top, bottom) = (60.0, 20.0, 30.0, 50.0);
    let finite_max = ratios
        .iter()
        .flatten()
        .copied()
        .filter(|r| r.is_finite())
        .fold(1.0, f64::max);
    let xmax = finite_max.log2().ceil().clamp(1.0, 12.0);
    let px = |t: f64| left + (w - left - right) * (t / xmax);
    let py = |rho: f64| top + (h - top - bottom) * (1.0 - rho);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="18" text-anchor="middle" font-size="13">{title}</text>"#,
        w / 2.0
    );
    for k in 0..=xmax as usize {
        let x = px(k as f64);
        let _ = writeln!(
            s,
            r##"<line x1="{x}" y1="{}" x2="{x}" y2="{}" stroke="#ddd"/><text x="{x}" y="{}" text-anchor="middle">{}</text>"##,
            py(0.0),
            py(1.0),
            py(0.0) + 16.0,
            1u64 << k
        );
    }
    for k in 0..=4 {
        let rho = k as f64 / 4.0;
        let y = py(rho);
        let _ = writeln!(
            s,
            r##"<line x1="{}" y1="{y}" x2="{}" y2="{y}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">{rho:.2}</text>"##,
            px(0.0),
            px(xmax),
            px(0.0) - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">τ (ratio to the better solver, log scale)</text>"#,
        w / 2.0,
        h - 10.0
    );
    let _ = writeln!(
        s,
        r#"<text x="16" y="{}" text-anchor="middle" transform="rotate(-90 16 {})">share of problems with ratio ≤ τ</text>"#,
        h / 2.0,
        h / 2.0
    );
    let colours = ["#1f77b4", "#ff7f0e"];
    let names = ["symnlp IPM", "IPOPT 3.14 (CasADi)"];
    for (k, r) in ratios.iter().enumerate() {
        let np = r.len().max(1) as f64;
        let mut points = vec![(0.0, r.iter().filter(|&&x| x <= 1.0).count() as f64 / np)];
        for (i, &x) in r
            .iter()
            .enumerate()
            .filter(|(_, x)| x.is_finite() && **x > 1.0)
        {
            let t = x.log2().min(xmax);
            points.push((t, points.last().expect("not empty").1));
            points.push((t, (i + 1) as f64 / np));
        }
        points.push((xmax, points.last().expect("not empty").1));
        let path: Vec<String> = points
            .iter()
            .map(|&(t, rho)| format!("{:.1},{:.1}", px(t), py(rho)))
            .collect();
        let _ = writeln!(
            s,
            r#"<polyline fill="none" stroke="{}" stroke-width="2" points="{}"/>"#,
            colours[k],
            path.join(" ")
        );
        let ly = py(0.2) + 18.0 * k as f64;
        let _ = writeln!(
            s,
            r#"<line x1="{}" y1="{ly}" x2="{}" y2="{ly}" stroke="{}" stroke-width="2"/><text x="{}" y="{}">{}</text>"#,
            px(xmax) - 170.0,
            px(xmax) - 145.0,
            colours[k],
            px(xmax) - 140.0,
            ly + 4.0,
            names[k]
        );
    }
}

fn cell(r: &SolverResult) -> String {
    let status = if r.success {
        String::new()
    } else {
        format!(" **{}**", r.status)
    };
    format!("{:.0}{status} | {:.8e}", r.iterations, r.objective)
}

/// The per-instance table (markdown), with the iteration ratio symnlp/IPOPT, the relative
/// objective gap and the distance to the published optimum.
pub fn table(rows: &[Row]) -> String {
    let mut s = String::from(
        "| instance | n | m | symnlp iter | symnlp f | IPOPT iter | IPOPT f | iter ratio | rel. Δf | Δ published | time symnlp / IPOPT (s, noisy) |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let ratio = r.symnlp.iterations / r.ipopt.iterations.max(1.0);
        let gap = relative_gap(r.symnlp.objective, r.ipopt.objective);
        let published = r.reference.map_or("-".to_string(), |v| {
            format!("{:.1e}", relative_gap(r.symnlp.objective, v))
        });
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {ratio:.2} | {gap:.1e} | {published} | {:.3} / {:.3} |",
            r.instance,
            r.n,
            r.m,
            cell(&r.symnlp),
            cell(&r.ipopt),
            r.symnlp.seconds,
            r.ipopt.seconds
        );
    }
    s
}

/// Counts for the summary: (instances, symnlp successes, IPOPT successes, both succeed with
/// the same objective to 1e-6, symnlp fails where IPOPT succeeds, symnlp needs more than
/// twice IPOPT's iterations, geometric mean of the iteration ratio over instances both solve).
pub fn summary(rows: &[Row]) -> (usize, usize, usize, usize, usize, usize, f64) {
    let ours = rows.iter().filter(|r| r.symnlp.success).count();
    let theirs = rows.iter().filter(|r| r.ipopt.success).count();
    let both: Vec<&Row> = rows
        .iter()
        .filter(|r| r.symnlp.success && r.ipopt.success)
        .collect();
    let same = both
        .iter()
        .filter(|r| relative_gap(r.symnlp.objective, r.ipopt.objective) <= 1e-6)
        .count();
    let lost = rows
        .iter()
        .filter(|r| !r.symnlp.success && r.ipopt.success)
        .count();
    let slow = both
        .iter()
        .filter(|r| r.symnlp.iterations > 2.0 * r.ipopt.iterations)
        .count();
    let logs: f64 = both
        .iter()
        .map(|r| (r.symnlp.iterations.max(1.0) / r.ipopt.iterations.max(1.0)).ln())
        .sum();
    let gmean = if both.is_empty() {
        f64::NAN
    } else {
        (logs / both.len() as f64).exp()
    };
    (rows.len(), ours, theirs, same, lost, slow, gmean)
}
