//! `gap-crossing`: the quadruped gap-crossing planner's command line.
//!
//! Exit codes (docs/gap-crossing.md, "Exit codes"; `status::StatusKind::exit_code`):
//! 0 success; 1 `solve`: solver failure or checker rejection, `check`: violations,
//! `sweep`: some point not solved; 2 any error (bad arguments, bad files, invalid
//! scenario or grid); 3 gap not crossable; 4 goal not reached; 5 infeasible; 6 no plan
//! found (`solve` and `replan`).
//! Errors go to stderr.

use clap::{Args, Parser, Subcommand, ValueEnum};
use gap_crossing::check::{self, GoalCheck, Options};
use gap_crossing::convergence::Convergence;
use gap_crossing::gait;
use gap_crossing::output::{self, OutputError};
use gap_crossing::plan::{PlanError, SolutionFile, SolverInfo};
use gap_crossing::render;
use gap_crossing::scenario::{Gait, Scenario, ScenarioError};
use gap_crossing::shard::{self, Shard, ShardError, ShardFile};
use gap_crossing::solve::{self, Backend, PlanningError, Settings};
use gap_crossing::sweep::{self, Grid, GridError, PointResult};
use gap_crossing::{errln, outln};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Quadruped gap-crossing footstep and force planner.
///
/// With no subcommand, `solve` runs with its defaults (the spec's default scenario).
#[derive(Parser, Debug)]
#[command(name = "gap-crossing", version, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    solve: SolveArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Solve a scenario; writes DIR/solution.json, plan.svg, plan.html, convergence.svg/json.
    Solve(SolveArgs),
    /// Check a solution file independently; prints each violation, exits 1 on any.
    Check(CheckArgs),
    /// Redraw the SVGs and plan.html of a solution file.
    Render(RenderArgs),
    /// Solve a grid of scenarios in parallel and summarise (or one shard of it, `--shard
    /// I/N`; `sweep merge DIR…` merges the shards).
    Sweep(SweepCmd),
    /// Write an initial guess (not a solution) as a plan file, with its plan.svg.
    Guess(GuessArgs),
    /// Re-plan the rest of a plan from a measured stance (a perturbed CoM or foot): the
    /// stances before it are kept, the rest re-solved warm; writes the files of `solve`.
    Replan(ReplanArgs),
}

#[derive(Args, Debug)]
struct ReplanArgs {
    /// The plan to re-plan (a solution file, e.g. out/solution.json).
    #[arg(long, value_name = "FILE")]
    plan: PathBuf,
    /// The measured stance K (1-based, 2..n_step−1): stances before it are kept.
    #[arg(long, value_name = "K")]
    stance: usize,
    /// Measured offset of the CoM at stance K (added to both bipeds' CoMs), m.
    #[arg(long, value_name = "DX,DY,DZ", allow_hyphen_values = true)]
    com_offset: Option<String>,
    /// Measured position of a foot at stance K, m (repeatable), e.g. `--foot FR=2.02,0,0`.
    #[arg(long = "foot", value_name = "FOOT=X,Y,Z", allow_hyphen_values = true)]
    foot: Vec<String>,
    /// Then improve the re-plan by the free gait's schedule search (slower; the foot
    /// schedule from stance K on may change).
    #[arg(long)]
    improve: bool,
    /// Output directory.
    #[arg(long, value_name = "DIR", default_value = "out")]
    out: PathBuf,
    #[command(flatten)]
    solver: SolverArgs,
}

/// Scenario selection shared by `solve` and `guess`.
#[derive(Args, Debug, Default)]
struct ScenarioArgs {
    /// Scenario file (.toml or .json); missing fields take the spec's defaults.
    #[arg(long, value_name = "FILE")]
    scenario: Option<PathBuf>,
    /// Gait mode, overriding the scenario's `gait`.
    #[arg(long, value_enum)]
    gait: Option<GaitArg>,
    /// Override one scenario value by dotted path, e.g. `--set gap.min=2.0 --set n_step=30`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
}

#[derive(Args, Debug, Default)]
struct SolveArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Output directory.
    #[arg(long, value_name = "DIR", default_value = "out")]
    out: PathBuf,
    #[command(flatten)]
    solver: SolverArgs,
}

/// Back end and its options, shared by `solve` and `sweep`.
#[derive(Args, Debug, Default)]
struct SolverArgs {
    /// Solver: interior point (`ipm`) or SQP (`sqp`).
    #[arg(long, value_enum)]
    solver: Option<SolverArg>,
    /// Set an option of the chosen back end by its name in `IpmOptions` / `SqpOptions`
    /// (IPOPT-style), e.g. `--opt tol=1e-10 --opt max_iter=500 --opt print_level=0`.
    #[arg(long = "opt", value_name = "KEY=VALUE")]
    opt: Vec<String>,
}

#[derive(Args, Debug)]
struct CheckArgs {
    /// Solution file (JSON, the spec's schema).
    file: PathBuf,
    /// Goal requirement: `auto` = required when n_step allows it (the crawl heuristic
    /// reaches the goals in n_step stances); `required`; `skip`.
    #[arg(long, value_enum, default_value_t = GoalArg::Auto)]
    goal: GoalArg,
    /// Check the plan against this scenario file (.toml or .json) instead of the
    /// solution file's own `scenario` block (which may then be absent).
    #[arg(long, value_name = "FILE")]
    scenario: Option<PathBuf>,
}

#[derive(Args, Debug)]
struct RenderArgs {
    /// Solution file (JSON).
    file: PathBuf,
    /// Output directory (default: the solution file's directory). Writes plan.svg, plan.html, and
    /// convergence.svg when a convergence.json (convergence history) sits beside FILE.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
struct SweepCmd {
    #[command(subcommand)]
    merge: Option<SweepSub>,
    #[command(flatten)]
    run: SweepArgs,
}

#[derive(Subcommand, Debug)]
enum SweepSub {
    /// Merge the results of every shard of a sweep (`sweep --shard I/N`) into the
    /// summary of one run: sweep.csv, sweep.json and sweep.svg.
    Merge(MergeArgs),
}

#[derive(Args, Debug)]
struct MergeArgs {
    /// Shard result files, or directories holding them (shard-I-of-N.json).
    #[arg(required = true, value_name = "DIR")]
    dirs: Vec<PathBuf>,
    /// Output directory; writes sweep.csv, sweep.json and sweep.svg.
    #[arg(long, value_name = "DIR", default_value = "out/sweep")]
    out: PathBuf,
}

#[derive(Args, Debug)]
struct SweepArgs {
    /// Grid file (.toml or .json): an optional `base` scenario and `axes`, lists of values
    /// for dotted scenario keys, e.g. `gap.min = [2.0, 2.25, 2.5]`.
    #[arg(long, value_name = "FILE", required = true)]
    grid: Option<PathBuf>,
    /// Output directory; writes sweep.csv, sweep.json and sweep.svg (with `--shard`:
    /// shard-I-of-N.json, for `sweep merge`).
    #[arg(long, value_name = "DIR", default_value = "out/sweep")]
    out: PathBuf,
    /// Run only shard I of N (1-based): the points whose index k has k mod N = I − 1.
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Also write each point's solution file as DIR/points/NNNN.json (solved or not).
    #[arg(long)]
    solutions: bool,
    #[command(flatten)]
    solver: SolverArgs,
}

#[derive(Args, Debug)]
struct GuessArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Which guess.
    #[arg(long, value_enum, default_value_t = GuessKind::Crawl)]
    kind: GuessKind,
    /// Output directory; writes guess.json and plan.svg.
    #[arg(long, value_name = "DIR", default_value = "out")]
    out: PathBuf,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum GaitArg {
    Free,
    Crawl,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum SolverArg {
    Ipm,
    Sqp,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum GoalArg {
    Auto,
    Required,
    Skip,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum GuessKind {
    Standing,
    Crawl,
}

#[derive(Debug, thiserror::Error)]
enum CliError {
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Plan(#[from] PlanError),
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a convergence history: {message}")]
    Records { path: PathBuf, message: String },
    #[error("solution file {path}: its scenario is invalid: {source}")]
    FileScenario {
        path: PathBuf,
        source: ScenarioError,
    },
    #[error(transparent)]
    Planning(#[from] PlanningError),
    #[error(transparent)]
    Grid(#[from] GridError),
    #[error(transparent)]
    Shard(#[from] ShardError),
    #[error("writing the output (nothing was changed): {0}")]
    Output(#[from] OutputError),
    #[error("cannot start {0} worker threads: {1}")]
    Threads(usize, String),
    #[error("{0}")]
    Opt(String),
    #[error(transparent)]
    Replan(#[from] gap_crossing::replan::ReplanError),
    #[error("{0}")]
    Perturbation(String),
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> CliError + '_ {
    move |source| CliError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Reads the scenario (file or defaults), applies `--gait` and `--set`, validates.
fn scenario(a: &ScenarioArgs) -> Result<Scenario, CliError> {
    let mut s = match &a.scenario {
        Some(p) => Scenario::load(p)?,
        None => Scenario::default(),
    };
    s.apply_overrides(&a.set)?;
    // A height map's CSV named by `--set` is read relative to the working directory.
    s.load_terrain_files(Path::new("."))?;
    if let Some(g) = a.gait {
        s.gait = match g {
            GaitArg::Free => Gait::Free,
            GaitArg::Crawl => Gait::Crawl,
        };
    }
    s.validate()?;
    Ok(s)
}

/// The back end chosen by `--solver` with its `--opt` options applied.
fn settings(a: &SolverArgs, print_level: u8) -> Result<Settings, CliError> {
    let mut settings = Settings {
        backend: match a.solver {
            None | Some(SolverArg::Ipm) => Backend::Ipm,
            Some(SolverArg::Sqp) => Backend::Sqp,
        },
        ..Settings::default()
    };
    settings.set_print_level(print_level);
    settings
        .set_by_name(&a.opt)
        .map_err(|e| CliError::Opt(format!("--opt: {e}")))?;
    Ok(settings)
}

/// [`solve`]; when it stops with an error before writing (an invalid scenario, a
/// planning error), the files an earlier solve wrote in DIR are removed, so that no
/// stale result is left looking like this run's. A failed write itself leaves DIR as it
/// was (all or nothing, [`output::write_all`]) and says so.
fn solve_or_clear(a: &SolveArgs) -> Result<ExitCode, CliError> {
    solve(a).inspect_err(|e| {
        if matches!(e, CliError::Output(_)) {
            return;
        }
        let removed = output::remove_files(&a.out, &SOLVE_FILES);
        if !removed.is_empty() {
            errln!(
                "removed the earlier results in {}: {}",
                a.out.display(),
                removed.join(", ")
            );
        }
    })
}

/// The files `solve` writes.
const SOLVE_FILES: [&str; 5] = [
    "solution.json",
    "convergence.json",
    "plan.svg",
    "convergence.svg",
    "plan.html",
];

fn solve(a: &SolveArgs) -> Result<ExitCode, CliError> {
    let s = scenario(&a.scenario)?;
    let settings = settings(&a.solver, 5)?;
    let outcome = solve::plan(&s, &settings)?;
    report(&outcome, &a.out)
}

/// Writes a planning outcome's files in `out` (all or none) and prints its summary;
/// the exit code of its status.
fn report(outcome: &solve::Outcome, out: &Path) -> Result<ExitCode, CliError> {
    let file = &outcome.file;
    let s = &file.scenario;
    let report = check::check(file);

    // Convergence history of all solver runs, numbered on, with the residual of (10) at
    // every iterate (recorded by the solvers' iteration callback).
    let history = Convergence::from_phases(&outcome.phases);
    let title = format!(
        "Convergence: {} gait, {} iterations",
        s.gait, file.solver.iterations
    );
    // Every file is rendered first, then all are written or none.
    let history_json = serde_json::to_string_pretty(&history).unwrap_or_default();
    let plan_svg = render::plan_svg(file);
    let conv_svg = render::convergence_svg(&history, &title);
    let plan_html = render::plan_html(file, &html_title(file));
    // A plan that is not solved is written too, so that no older result stays in DIR:
    // its solution.json says why (`solver.status`, `solver.reason`).
    output::write_all(
        out,
        &[
            ("solution.json", file.to_json().as_bytes()),
            ("convergence.json", history_json.as_bytes()),
            ("plan.svg", plan_svg.as_bytes()),
            ("convergence.svg", conv_svg.as_bytes()),
            ("plan.html", plan_html.as_bytes()),
        ],
    )?;
    if !outcome.status.is_solved() {
        let kind = outcome.status.kind();
        errln!(
            "error: no valid plan: status {kind} (exit code {}): {}",
            kind.exit_code(),
            outcome.status
        );
        // A certificate decided before solving: the file holds the guess, whose
        // violations say nothing more.
        if !report.ok() && !kind.is_proved_impossible() {
            errln!("checker: {report}");
        }
        errln!(
            "wrote {}/solution.json with status {kind} (not a valid plan) and its drawings",
            out.display()
        );
        return Ok(ExitCode::from(kind.exit_code()));
    }

    let moves = foot_moves(&file.plan());
    outln!();
    for phase in &outcome.phases {
        outln!(
            "  {:<42} {:?}, {} iterations, (10) residual {:.1e}",
            phase.name,
            phase.status,
            phase.iterations,
            phase.complementarity
        );
    }
    outln!("status:     {} ({} gait)", file.solver.status, s.gait);
    outln!("objective:  {:.6e}", file.solver.objective);
    if let Some(r) = file.solver.objective_without_10 {
        outln!(
            "reference:  {r:.6e} without (10) (every foot free at every transition; what (10) costs: {:.1} %)",
            100.0 * (file.solver.objective - r) / file.solver.objective
        );
    }
    outln!(
        "steps:      {} of {} transitions move a foot; moves per foot: {}",
        report.moves,
        s.n_step - 1,
        moves
    );
    outln!("time:       {:.3} s", file.solver.solve_seconds);
    outln!("checker:    {}", report.summary());
    outln!(
        "wrote {}/{{solution.json, plan.svg, plan.html, convergence.svg, convergence.json}}",
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// Three comma-separated numbers.
fn triple(text: &str, what: &str) -> Result<[f64; 3], CliError> {
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| CliError::Perturbation(format!("{what} {text:?}: {e}")))?;
    <[f64; 3]>::try_from(v).map_err(|v| {
        CliError::Perturbation(format!(
            "{what} {text:?}: expected 3 numbers x,y,z, got {}",
            v.len()
        ))
    })
}

fn replan_cmd(a: &ReplanArgs) -> Result<ExitCode, CliError> {
    use gap_crossing::replan::{self, Perturbation};
    use gap_crossing::scenario::Foot;
    let old = SolutionFile::read(&a.plan)?;
    old.scenario
        .validate()
        .map_err(|source| CliError::FileScenario {
            path: a.plan.clone(),
            source,
        })?;
    let com_offset = match &a.com_offset {
        Some(t) => triple(t, "--com-offset")?,
        None => [0.0; 3],
    };
    let mut feet = Vec::new();
    for f in &a.foot {
        let (name, at) = f.split_once('=').ok_or_else(|| {
            CliError::Perturbation(format!(
                "--foot {f:?}: expected FOOT=X,Y,Z, e.g. FR=2.02,0,0"
            ))
        })?;
        let foot = Foot::ALL
            .into_iter()
            .find(|i| i.name().eq_ignore_ascii_case(name.trim()))
            .ok_or_else(|| {
                CliError::Perturbation(format!(
                    "--foot {f:?}: unknown foot {name:?} (BR, BL, FR or FL)"
                ))
            })?;
        feet.push((foot, triple(at, &format!("--foot {}", foot.name()))?));
    }
    let settings = settings(&a.solver, 5)?;
    let outcome = replan::replan_with(
        &old,
        a.stance,
        &Perturbation { com_offset, feet },
        &settings,
        a.improve,
    )?;
    report(&outcome, &a.out)
}

/// "BR 15, BL 14, ..." from a plan.
fn foot_moves(p: &gap_crossing::plan::Plan) -> String {
    use gap_crossing::scenario::Foot;
    Foot::ALL
        .iter()
        .map(|&i| {
            let n = p
                .stances
                .windows(2)
                .filter(|w| {
                    let (a, b) = (w[0].feet.get(i), w[1].feet.get(i));
                    (0..3).map(|d| (a[d] - b[d]).powi(2)).sum::<f64>().sqrt() > 1e-6
                })
                .count();
            format!("{} {n}", i.name())
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn sweep(a: &SweepArgs) -> Result<ExitCode, CliError> {
    let path = a
        .grid
        .as_ref()
        .ok_or_else(|| CliError::Opt("sweep needs --grid FILE".into()))?;
    let grid = Grid::load(path)?;
    // Points run in parallel: no iteration logs (`print_level` is ignored here).
    let mut settings = settings(&a.solver, 0)?;
    settings.set_print_level(0);
    let threads = a.threads.unwrap_or_else(rayon::current_num_threads).max(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| CliError::Threads(threads, e.to_string()))?;
    let points_dir = a.out.join("points");
    if a.solutions {
        std::fs::create_dir_all(&points_dir).map_err(io(&points_dir))?;
    }
    let bar = progress_bar(announce_sweep(&grid, a.shard, threads));
    let failed = std::sync::atomic::AtomicUsize::new(0);
    let save_errors = std::sync::Mutex::new(Vec::<String>::new());
    let started = std::time::Instant::now();
    let done = |r: &PointResult, file: Option<&SolutionFile>| {
        if !r.ok() {
            let f = failed.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            bar.set_message(format!("{f} failed"));
        }
        // A plan with a non-finite number would not read back (JSON has no NaN): such a
        // point's file is not written.
        if let (true, Some(file)) = (a.solutions, file.filter(|f| f.stances_finite())) {
            let p = points_dir.join(format!("{:04}.json", r.index));
            if let Err(e) = file.write(&p) {
                save_errors
                    .lock()
                    .expect("not poisoned")
                    .push(e.to_string());
            }
        }
        bar.inc(1);
    };
    let results = pool.install(|| match a.shard {
        Some(sh) => shard::run(&grid, sh, &settings, &done),
        None => sweep::run(&grid, &settings, &done),
    });
    bar.finish_and_clear();
    let wall = started.elapsed().as_secs_f64();
    for e in save_errors.into_inner().unwrap_or_default() {
        errln!("warning: {e}");
    }

    let files = write_sweep(&a.out, a.shard, &grid, &results, wall, threads)?;
    Ok(report_sweep(&grid, &results, wall, threads, &files))
}

/// Prints what a sweep is about to run (points, axes, shard, threads) on stderr and
/// returns its number of points.
fn announce_sweep(grid: &Grid, shard: Option<Shard>, threads: usize) -> usize {
    let n = match shard {
        Some(sh) => (0..grid.len()).filter(|&k| sh.holds(k)).count(),
        None => grid.len(),
    };
    let axes: Vec<&str> = grid.axes.iter().map(|ax| ax.key.as_str()).collect();
    let of = shard.map_or(String::new(), |sh| {
        format!(" of shard {}/{}", sh.index, sh.count)
    });
    errln!(
        "sweep: {n} points{of} ({}) on {threads} threads",
        if axes.is_empty() {
            "no axes: the base scenario".to_string()
        } else {
            axes.join(" × ")
        }
    );
    n
}

/// The sweep's progress bar over `n` points, drawn on stderr (indicatif hides it when
/// stderr is not a terminal).
fn progress_bar(n: usize) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(n as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} points, {elapsed} elapsed, ~{eta} left  {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

/// Writes a sweep's results into `out`: a shard's mergeable file, or the summary and
/// plots of a whole run; returns the paths written.
fn write_sweep(
    out: &Path,
    shard: Option<Shard>,
    grid: &Grid,
    results: &[PointResult],
    wall: f64,
    threads: usize,
) -> Result<Vec<PathBuf>, CliError> {
    Ok(match shard {
        Some(shard) => {
            let file = ShardFile {
                grid: grid.clone(),
                shard,
                results: results.to_vec(),
                wall_seconds: wall,
                threads,
            };
            vec![file.write(out)?]
        }
        None => sweep::write_outputs(out, grid, results, wall, threads)?,
    })
}

/// `sweep merge`: the shards' results as the summary of one run.
fn sweep_merge(a: &MergeArgs) -> Result<ExitCode, CliError> {
    let files = shard::find(&a.dirs)?;
    let merged = shard::merge(shard::read(&files)?)?;
    errln!("sweep merge: {} shard files", files.len());
    let written = sweep::write_outputs(
        &a.out,
        &merged.grid,
        &merged.results,
        merged.wall_seconds,
        merged.threads,
    )?;
    Ok(report_sweep(
        &merged.grid,
        &merged.results,
        merged.wall_seconds,
        merged.threads,
        &written,
    ))
}

/// Prints a sweep's table and summary; exit code 0 when every point was solved and
/// checked, else 1.
fn report_sweep(
    grid: &Grid,
    results: &[PointResult],
    wall: f64,
    threads: usize,
    files: &[PathBuf],
) -> ExitCode {
    let widths: Vec<usize> = grid.axes.iter().map(|ax| ax.key.len().max(6)).collect();
    let mut head = String::from("point");
    for (ax, w) in grid.axes.iter().zip(&widths) {
        head += &format!("  {:>w$}", ax.key);
    }
    outln!(
        "{head}  {:<22} {:>6} {:>13} {:>6} {:>8}",
        "status",
        "check",
        "objective",
        "iter",
        "time"
    );
    for r in results {
        let mut line = format!("{:>5}", r.index);
        for ((_, v), w) in r.overrides.iter().zip(&widths) {
            line += &format!("  {:>w$}", sweep::label(v));
        }
        let check = if r.status.is_solved() || r.objective.is_some() {
            if r.check_ok {
                "ok".to_string()
            } else {
                format!("{} bad", r.violations)
            }
        } else {
            "-".to_string()
        };
        let obj = r.objective.map(|o| format!("{o:.6e}")).unwrap_or_default();
        let it = r.iterations.map(|i| i.to_string()).unwrap_or_default();
        outln!(
            "{line}  {:<22} {check:>6} {obj:>13} {it:>6} {:>7.2}s",
            r.status,
            r.seconds
        );
        if let Some(e) = &r.error {
            outln!("       {e}");
        }
    }
    let ok = results.iter().filter(|r| r.ok()).count();
    outln!(
        "sweep: {ok} of {} points solved and checked, {:.1} s wall on {threads} threads",
        results.len(),
        wall
    );
    let by_status: Vec<String> = sweep::counts(results)
        .into_iter()
        .map(|(k, n)| format!("{k} {n}"))
        .collect();
    outln!("outcomes: {}", by_status.join(", "));
    outln!(
        "wrote {}",
        files
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    if ok == results.len() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

fn check_cmd(a: &CheckArgs) -> Result<ExitCode, CliError> {
    let scenario = a.scenario.as_deref().map(Scenario::load).transpose()?;
    let file = SolutionFile::read_with_scenario(&a.file, scenario.as_ref())?;
    file.scenario
        .validate()
        .map_err(|source| CliError::FileScenario {
            path: a.file.clone(),
            source,
        })?;
    let goal = match a.goal {
        GoalArg::Auto => GoalCheck::Auto,
        GoalArg::Required => GoalCheck::Required,
        GoalArg::Skip => GoalCheck::Skip,
    };
    let report = check::check_with(
        &file,
        &Options {
            goal,
            ..Options::default()
        },
    );
    outln!("{report}");
    Ok(if report.ok() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The heading of plan.html: gait, solver status and objective.
fn html_title(file: &SolutionFile) -> String {
    format!(
        "Gap crossing: {} gait, {} stances, status {}, objective {:.6e}",
        file.scenario.gait,
        file.stances.len(),
        file.solver.status,
        file.solver.objective
    )
}

fn render_cmd(a: &RenderArgs) -> Result<ExitCode, CliError> {
    let file = SolutionFile::read(&a.file)?;
    let dir = match &a.out {
        Some(d) => d.clone(),
        None => a
            .file
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from(".")),
    };
    let records_path = a.file.with_file_name("convergence.json");
    let records: Option<Convergence> = if records_path.exists() {
        let text = std::fs::read_to_string(&records_path).map_err(io(&records_path))?;
        Some(
            Convergence::from_json(&text).map_err(|e| CliError::Records {
                path: records_path.clone(),
                message: e.to_string(),
            })?,
        )
    } else {
        None
    };
    let plan_svg = render::plan_svg(&file);
    let plan_html = render::plan_html(&file, &html_title(&file));
    let mut files: Vec<(&str, &[u8])> = vec![
        ("plan.svg", plan_svg.as_bytes()),
        ("plan.html", plan_html.as_bytes()),
    ];
    let conv_svg = records.map(|r| {
        let title = format!(
            "Convergence: solver {} ({}), {} iterations",
            file.solver.name, file.solver.status, file.solver.iterations
        );
        render::convergence_svg(&r, &title)
    });
    if let Some(svg) = &conv_svg {
        files.push(("convergence.svg", svg.as_bytes()));
    }
    for p in output::write_all(&dir, &files)? {
        outln!("wrote {}", p.display());
    }
    Ok(ExitCode::SUCCESS)
}

fn guess_cmd(a: &GuessArgs) -> Result<ExitCode, CliError> {
    let s = scenario(&a.scenario)?;
    let (plan, name) = match a.kind {
        GuessKind::Standing => (
            gap_crossing::plan::Plan::from_flat(&s, &gait::standing(&s))?,
            "standing",
        ),
        GuessKind::Crawl => (gait::crawl_plan(&s), "crawl"),
    };
    let info = SolverInfo {
        name: "guess".into(),
        status: format!("initial_guess_{name}"),
        iterations: 0,
        objective: plan.cost(&s),
        objective_without_10: None,
        max_constraint_violation: 0.0,
        solve_seconds: 0.0,
        reason: None,
    };
    let mut file = SolutionFile::new(s, info, plan);
    // A guess has no solver measure of infeasibility: record the checker's largest
    // residual instead.
    let report = check::check(&file);
    file.solver.max_constraint_violation = report.max_residual.max(0.0);
    let svg = render::plan_svg(&file);
    let written = output::write_all(
        &a.out,
        &[
            ("guess.json", file.to_json().as_bytes()),
            ("plan.svg", svg.as_bytes()),
        ],
    )?;
    let (json, svg) = (&written[0], &written[1]);
    outln!(
        "wrote {} and {} ({name} guess, cost {:.4e}); checker: {}",
        json.display(),
        svg.display(),
        file.solver.objective,
        report.summary()
    );
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        None => solve_or_clear(&cli.solve),
        Some(Command::Solve(a)) => solve_or_clear(a),
        Some(Command::Check(a)) => check_cmd(a),
        Some(Command::Render(a)) => render_cmd(a),
        Some(Command::Sweep(SweepCmd {
            merge: Some(SweepSub::Merge(a)),
            ..
        })) => sweep_merge(a),
        Some(Command::Sweep(a)) => sweep(&a.run),
        Some(Command::Guess(a)) => guess_cmd(a),
        Some(Command::Replan(a)) => replan_cmd(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            errln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
