//! symx functions as C files for CasADi's `external()`: writes, into the directory given as
//! the first argument, `<name>.c` (`Function::to_c_with`, CasADi's calling convention) and
//! `<name>.json` (the inputs at a test point, symx's outputs there and each output's
//! sparsity pattern, numbers as the hexadecimal bits of the IEEE doubles) for
//!
//! - `small`: a few elementary operations of `x ∈ ℝ³, p ∈ ℝ` with its sparse Jacobian;
//! - `gap_grad_f`: the gap-crossing model's objective gradient (the ∇f of
//!   `benches/symx_eval.rs`'s gap group), at the model's initial point.
//!
//! `python/tests/test_casadi_external.py` compiles the C files with the system's C compiler,
//! loads them with `casadi.external` and checks CasADi's results against symx's bit for bit.
//!
//! Run: `cargo run --release -p symnlp-examples --example casadi_external -- <directory> [small|gap_grad_f]...`
//! (every function when none is named). In Python, after compiling `small.c` with
//! `cc -std=c99 -shared -fPIC -o small.so small.c -lm`:
//!
//! ```python
//! import casadi
//! f = casadi.external("small", "./small.so")
//! y, jac = f([0.3, -1.2, 0.7], 2.5)
//! ```
use gap_crossing::model::{self, Formulation};
use gap_crossing::{gait, scenario::Scenario, terrain::GapTerrain};
use symnlp::nlp::NumericNlp;
use symnlp::symx::{gradient, jacobian, Function, Matrix, SourceOptions, Sparsity};

/// A function, its output patterns (`None`: dense) and the point it is evaluated at.
struct Case {
    function: Function,
    patterns: Vec<Option<Sparsity>>,
    inputs: Vec<Vec<f64>>,
}

/// `y = [x₀ sin x₁ + p, exp(x₀ x₂) / (1 + x₁²), sqrt(x₂² + p) − atan2(x₀, p)]` and its
/// Jacobian with respect to `x`, sparse (`y₀` does not depend on `x₂`, nor `y₂` on `x₁`).
fn small() -> Case {
    let x = Matrix::sym_vec("x", 3);
    let p = Matrix::sym_vec("p", 1);
    let (x0, x1, x2, p0) = (x[0], x[1], x[2], p[0]);
    let y = [
        x0 * x1.sin() + p0,
        (x0 * x2).exp() / (1.0 + x1 * x1),
        (x2 * x2 + p0).sqrt() - x0.atan2(p0),
    ];
    let jac = jacobian(&y, &x).unwrap();
    let function = Function::named(
        "small",
        &[("x", &x), ("p", &p)],
        &[("y", &y), ("jac_y", jac.values())],
    )
    .unwrap();
    Case {
        function,
        patterns: vec![None, Some(jac.sparsity().clone())],
        inputs: vec![vec![0.3, -1.2, 0.7], vec![2.5]],
    }
}

/// The gap-crossing model's ∇f (default scenario) at its initial point.
fn gap_grad_f() -> Case {
    let s = Scenario::default();
    let m = model::build(
        &s,
        &GapTerrain { gap: s.gap },
        &Formulation::Scheduled(gait::crawl_schedule(s.n_step)),
        &gait::crawl(&s),
    )
    .expect("the default gap-crossing model builds");
    let x = m.problem.variables().to_vec();
    let grad = gradient(m.problem.objective(), &x).unwrap();
    let c = m
        .problem
        .compile()
        .expect("the gap-crossing model compiles");
    let mut x0 = vec![0.0; c.n()];
    c.initial_point(&mut x0);
    let function = Function::named("gap_grad_f", &[("x", &x)], &[("grad_f", &grad)]).unwrap();
    Case {
        function,
        patterns: vec![None],
        inputs: vec![x0],
    }
}

/// The hexadecimal bits of each number.
fn bits(v: &[f64]) -> Vec<String> {
    v.iter().map(|x| format!("{:016x}", x.to_bits())).collect()
}

/// `<name>.c` and `<name>.json` of `case` in `dir`.
fn write(dir: &std::path::Path, case: &Case) -> Result<(), Box<dyn std::error::Error>> {
    let f = &case.function;
    let options = SourceOptions {
        output_sparsity: case.patterns.clone(),
    };
    std::fs::write(dir.join(format!("{}.c", f.name())), f.to_c_with(&options)?)?;
    let args: Vec<&[f64]> = case.inputs.iter().map(|v| v.as_slice()).collect();
    let outputs = f.call(&args)?;
    let patterns: Vec<serde_json::Value> = case
        .patterns
        .iter()
        .zip(&outputs)
        .map(|(p, out)| match p {
            Some(s) => serde_json::json!({
                "nrow": s.nrows(), "ncol": s.ncols(), "colind": s.col_ptr(), "row": s.row_idx()
            }),
            None => serde_json::json!({
                "nrow": out.len(), "ncol": 1, "colind": [0, out.len()],
                "row": (0..out.len()).collect::<Vec<_>>()
            }),
        })
        .collect();
    let record = serde_json::json!({
        "name": f.name(),
        "inputs": case.inputs.iter().map(|v| bits(v)).collect::<Vec<_>>(),
        "outputs": outputs.iter().map(|v| bits(v)).collect::<Vec<_>>(),
        "sparsity_out": patterns,
    });
    std::fs::write(
        dir.join(format!("{}.json", f.name())),
        serde_json::to_string_pretty(&record)?,
    )?;
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = std::path::PathBuf::from(args.next().ok_or(
        "usage: cargo run --release -p symnlp-examples --example casadi_external -- <directory> [small|gap_grad_f]...",
    )?);
    let mut names: Vec<String> = args.collect();
    if names.is_empty() {
        names = vec!["small".into(), "gap_grad_f".into()];
    }
    std::fs::create_dir_all(&dir)?;
    for name in &names {
        let case = match name.as_str() {
            "small" => small(),
            "gap_grad_f" => gap_grad_f(),
            other => return Err(format!("unknown function '{other}' (small, gap_grad_f)").into()),
        };
        write(&dir, &case)?;
        println!("{}", dir.join(format!("{name}.c")).display());
    }
    Ok(())
}
