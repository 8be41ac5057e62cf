//! The gap-crossing planner: solve a scenario, check a plan (JSON in, JSON out).
use gap_crossing::plan::SolutionFile;
use gap_crossing::scenario::Scenario;
use gap_crossing::solve::{Backend, Settings};
use pyo3::prelude::*;
use std::path::Path;

use crate::error::{build_err, option_err, solve_err};

/// Solves a scenario given as JSON text (`None`: the default scenario) or a file path
/// (.toml/.json); returns `(status word, solved, solution file JSON)`.
#[pyfunction]
#[pyo3(signature = (scenario_json = None, scenario_path = None, solver = "ipm", options = Vec::new()))]
fn gap_crossing_solve(
    py: Python<'_>,
    scenario_json: Option<String>,
    scenario_path: Option<String>,
    solver: &str,
    options: Vec<String>,
) -> PyResult<(String, bool, String)> {
    let s = match (scenario_json, scenario_path) {
        (Some(text), _) => Scenario::parse(&text, "json", Path::new("scenario.json")),
        (None, Some(p)) => Scenario::load(Path::new(&p)),
        (None, None) => Ok(Scenario::default()),
    }
    .map_err(build_err)?;
    s.validate().map_err(build_err)?;
    let mut settings = Settings {
        backend: match solver {
            "ipm" => Backend::Ipm,
            "sqp" => Backend::Sqp,
            other => {
                return Err(crate::error::OptionError::new_err(format!(
                    "unknown solver '{other}': expected 'ipm' or 'sqp'"
                )))
            }
        },
        ..Settings::default()
    };
    settings.set_print_level(0);
    settings.set_by_name(&options).map_err(option_err)?;
    let outcome = py
        .allow_threads(|| gap_crossing::solve::plan(&s, &settings))
        .map_err(solve_err)?;
    Ok((
        outcome.status.to_string(),
        outcome.status.is_solved(),
        outcome.file.to_json(),
    ))
}

/// Checks a solution file (JSON text) independently; returns `(ok, summary, violations)`.
#[pyfunction]
fn gap_crossing_check(py: Python<'_>, plan_json: &str) -> PyResult<(bool, String, Vec<String>)> {
    let file = SolutionFile::from_json(plan_json, Path::new("plan.json")).map_err(build_err)?;
    file.scenario.validate().map_err(build_err)?;
    let report = py.allow_threads(|| gap_crossing::check::check(&file));
    let violations = report.violations.iter().map(|v| v.to_string()).collect();
    Ok((report.ok(), report.summary(), violations))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(gap_crossing_solve, m)?)?;
    m.add_function(wrap_pyfunction!(gap_crossing_check, m)?)?;
    Ok(())
}
