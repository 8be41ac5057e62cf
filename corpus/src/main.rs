//! `corpus`: list, solve, export and report on the corpus (see `docs/corpus.md`).
//!
//! ```text
//! corpus list [--filter S] [--kind ocp|cute] [--max-n N]      # one JSON line per instance
//! corpus solve [--filter S] [--kind K] [--max-n N] [--max-wall S]   # symnlp, one JSON line each
//! corpus export NAME [--solve] [--max-wall S]                 # the dump IPOPT reads (JSON)
//! corpus diagnose NAME... [--max-wall S]                     # how the IPM's iterations went
//! corpus trace NAME [--perturb EPS] [--opt K=V]... [--max-wall S]  # every iteration record
//! corpus report FILE [--svg-dir DIR]                          # markdown + profile SVGs
//! ```
use clap::{Parser, Subcommand};
use corpus::{export, profile, run, CorpusError, Instance, Kind};
use std::process::ExitCode;

#[derive(Parser)]
#[command(about = "symnlp's open test corpus")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args, Clone)]
struct Selection {
    /// Only instances whose name contains one of these comma-separated strings.
    #[arg(long)]
    filter: Option<String>,
    /// Only optimal-control (`ocp`) or CUTEst-style (`cute`) instances.
    #[arg(long)]
    kind: Option<String>,
    /// Only instances with at most this many variables.
    #[arg(long)]
    max_n: Option<usize>,
}

#[derive(Subcommand)]
enum Command {
    /// Lists the selected instances (name, family, n, m, source) as JSON lines.
    List(Selection),
    /// Solves the selected instances with symnlp's IPM; one JSON line per instance.
    Solve {
        #[command(flatten)]
        selection: Selection,
        /// Wall-time cap per solve in seconds.
        #[arg(long, default_value_t = 600.0)]
        max_wall: f64,
    },
    /// Writes one instance as the JSON dump the IPOPT reference script reads.
    Export {
        /// Instance name (`family_size`; any size of a family).
        name: String,
        /// Also solve with symnlp and include the outcome.
        #[arg(long)]
        solve: bool,
        /// Wall-time cap of that solve in seconds.
        #[arg(long, default_value_t = 600.0)]
        max_wall: f64,
    },
    /// Solves one instance with symnlp and prints a summary of its iteration records.
    Diagnose {
        /// Instance names (`family_size`; any size of a family).
        names: Vec<String>,
        /// Wall-time cap per solve in seconds.
        #[arg(long, default_value_t = 600.0)]
        max_wall: f64,
        /// The IPM's print level (5: IPOPT-style iteration table on stdout, before the summary).
        #[arg(long, default_value_t = 0)]
        print_level: u8,
    },
    /// Solves one instance with symnlp and prints every iteration record as a JSON line
    /// (full precision, for comparing paths with `benches/reference/ipopt_trace.py`), then
    /// the outcome. Any size of a family is accepted (`noncvxu2_100`).
    Trace {
        /// Instance name (`family_size`).
        name: String,
        /// Relative perturbation of the starting point: x0[i] *= 1 + EPS·(+1, −1, +1, …),
        /// as `ipopt_trace.py --perturb` does.
        #[arg(long, default_value_t = 0.0)]
        perturb: f64,
        /// Wall-time cap of the solve in seconds.
        #[arg(long, default_value_t = 600.0)]
        max_wall: f64,
        /// An IPM option `NAME=VALUE` (IpmOptions' field names), repeatable.
        #[arg(long = "opt")]
        opts: Vec<String>,
        /// Also print the final x in the outcome line (e.g. with `--opt max_iter=K`).
        #[arg(long)]
        print_x: bool,
    },
    /// Prints the markdown table and summary of a results file and writes the profiles.
    Report {
        /// JSON-lines results of `benches/reference/corpus_ipopt.py`.
        file: String,
        /// Directory for corpus_profile_iterations.svg and corpus_profile_time.svg.
        #[arg(long)]
        svg_dir: Option<String>,
    },
}

fn selected(sel: &Selection) -> Result<Vec<(Instance, nlp::Problem)>, CorpusError> {
    let filters: Vec<String> = sel
        .filter
        .iter()
        .flat_map(|f| f.split(',').map(str::to_string))
        .collect();
    let mut out = Vec::new();
    for inst in corpus::instances() {
        let name = inst.name();
        if !filters.is_empty() && !filters.iter().any(|f| name.contains(f.as_str())) {
            continue;
        }
        let kind = match inst.family.kind {
            Kind::Ocp => "ocp",
            Kind::Cute => "cute",
        };
        if sel.kind.as_deref().is_some_and(|k| k != kind) {
            continue;
        }
        let pb = inst.build()?;
        if sel.max_n.is_some_and(|max| pb.n_variables() > max) {
            continue;
        }
        out.push((inst, pb));
    }
    Ok(out)
}

/// `println!` for a stream of results that never panics: when standard output is
/// closed (`corpus list | head`) the reader wants no more, so the command ends quietly
/// (exit 0); any other failure to write ends it with the error (exit 2).
macro_rules! emit {
    ($($arg:tt)*) => {{
        use std::io::Write;
        if let Err(e) = writeln!(std::io::stdout().lock(), $($arg)*) {
            stdout_failed(e);
        }
    }};
}

/// Ends the process after a failed write to standard output (see `emit!`).
fn stdout_failed(e: std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    eprintln!("corpus: standard output: {e}");
    std::process::exit(2);
}

fn main() -> ExitCode {
    match real_main() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("corpus: {e}");
            ExitCode::from(2)
        }
    }
}

fn real_main() -> Result<(), CorpusError> {
    match Cli::parse().command {
        Command::List(sel) => {
            for (inst, pb) in selected(&sel)? {
                let line = serde_json::json!({
                    "instance": inst.name(), "family": inst.family.name, "kind": inst.family.kind,
                    "transcription": inst.family.transcription, "size": inst.size,
                    "n": pb.n_variables(), "m": pb.n_constraints(), "source": inst.family.source,
                    "reference": inst.reference().map(|r| r.value),
                });
                emit!("{line}");
            }
        }
        Command::Solve {
            selection,
            max_wall,
        } => {
            for (inst, _) in selected(&selection)? {
                let outcome = run::solve(&inst, &run::options(max_wall))?;
                eprintln!(
                    "{}: {} in {} iterations, f = {:.10e}",
                    outcome.instance, outcome.status, outcome.iterations, outcome.objective
                );
                emit!("{}", serde_json::to_string(&outcome).expect("serialisable"));
            }
        }
        Command::Export {
            name,
            solve,
            max_wall,
        } => {
            let inst = corpus::instance_at_any_size(&name)
                .ok_or_else(|| CorpusError::UnknownInstance(name.clone()))?;
            let t = std::time::Instant::now();
            let pb = inst.build()?;
            let mut compiled = pb.compile()?;
            let compile_s = t.elapsed().as_secs_f64();
            let mut d = export::dump(&inst, &pb, &mut compiled)?;
            if solve {
                let outcome =
                    run::solve_compiled(&inst, &mut compiled, compile_s, &run::options(max_wall))?;
                eprintln!(
                    "symnlp: {} in {} iterations, f = {:.12e}, solve {:.3} s",
                    outcome.status, outcome.iterations, outcome.objective, outcome.solve_s
                );
                d.symnlp = Some(outcome);
            }
            emit!("{}", serde_json::to_string(&d).expect("serialisable"));
        }
        Command::Diagnose {
            names,
            max_wall,
            print_level,
        } => {
            for name in names {
                let inst = corpus::instance_at_any_size(&name)
                    .ok_or_else(|| CorpusError::UnknownInstance(name.clone()))?;
                let mut compiled = inst.build()?.compile()?;
                let mut options = run::options(max_wall);
                options.print_level = print_level;
                let sol = nlp::Ipm::new(options).solve(&mut compiled)?;
                let d = corpus::diagnose::diagnose(&sol);
                let line = serde_json::json!({"instance": name, "status": format!("{:?}", sol.status), "diagnosis": d});
                emit!("{line}");
            }
        }
        Command::Trace {
            name,
            perturb,
            max_wall,
            opts,
            print_x,
        } => trace(&name, perturb, max_wall, &opts, print_x)?,
        Command::Report { file, svg_dir } => {
            let text = std::fs::read_to_string(&file)
                .map_err(|e| CorpusError::Results(format!("{file}: {e}")))?;
            let rows = profile::read(&text)?;
            if let Some(dir) = svg_dir {
                let write = |name: &str, body: String| {
                    let path = format!("{dir}/{name}");
                    std::fs::write(&path, body)
                        .map_err(|e| CorpusError::Results(format!("{path}: {e}")))
                };
                type Metric = fn(&profile::SolverResult) -> f64;
                let metrics: [(&str, &str, Metric); 2] = [
                    ("iterations", "Performance profile: iterations", |s| {
                        s.iterations
                    }),
                    (
                        "time",
                        "Performance profile: solve wall time (provisional: shared, noisy machine)",
                        |s| s.seconds,
                    ),
                ];
                for (file, title, metric) in metrics {
                    let panels: Vec<(String, [Vec<f64>; 2])> =
                        [("Ocp", "optimal control"), ("Cute", "CUTEst-style")]
                            .iter()
                            .map(|(kind, label)| {
                                let part: Vec<_> =
                                    rows.iter().filter(|r| r.kind == *kind).cloned().collect();
                                let r = profile::ratios(&part, metric);
                                let n = (r[0].len(), part.len());
                                (
                                    format!(
                                        "{label}: {} of {} instances solved by either",
                                        n.0, n.1
                                    ),
                                    r,
                                )
                            })
                            .collect();
                    write(
                        &format!("corpus_profile_{file}.svg"),
                        profile::svg(title, &panels),
                    )?;
                }
            }
            for kind in ["Ocp", "Cute"] {
                let part: Vec<_> = rows.iter().filter(|r| r.kind == kind).cloned().collect();
                let (total, ours, theirs, same, lost, slow, gmean) = profile::summary(&part);
                emit!("\n**{kind}**: {total} instances; symnlp solves {ours}, IPOPT {theirs}; both to the same objective (1e-6): {same}; symnlp fails where IPOPT succeeds: {lost}; symnlp > 2x IPOPT's iterations: {slow}; geometric-mean iteration ratio (both solved): {gmean:.2}\n");
                emit!("{}", profile::table(&part));
            }
        }
    }
    Ok(())
}

/// `corpus trace`: every iteration record of one (possibly perturbed) solve, then the outcome.
fn trace(
    name: &str,
    perturb: f64,
    max_wall: f64,
    opts: &[String],
    print_x: bool,
) -> Result<(), CorpusError> {
    use nlp::{NamedOptions, NumericNlp};
    let mut options = run::options(max_wall);
    options
        .set_by_name(opts)
        .map_err(|e| CorpusError::Options(e.to_string()))?;
    let inst = corpus::instance_at_any_size(name)
        .ok_or_else(|| CorpusError::UnknownInstance(name.to_string()))?;
    let mut compiled = inst.build()?.compile()?;
    if perturb != 0.0 {
        let mut x0 = vec![0.0; compiled.n()];
        compiled.initial_point(&mut x0);
        for (i, v) in x0.iter_mut().enumerate() {
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            *v *= 1.0 + perturb * sign;
        }
        compiled.set_initial_point(&x0)?;
    }
    let sol = nlp::Ipm::new(options).solve(&mut compiled)?;
    for r in &sol.stats.records {
        emit!("{}", serde_json::to_string(r).expect("serialisable"));
    }
    let mut line = serde_json::json!({"instance": name, "perturb": perturb,
        "status": format!("{:?}", sol.status), "iterations": sol.stats.iterations,
        "objective": sol.objective});
    if print_x {
        line["x"] = serde_json::json!(sol.x);
    }
    emit!("{line}");
    Ok(())
}
