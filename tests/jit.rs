//! Native evaluators (`symx::Function::jit`, through `Compiled::with_evaluator`) on whole
//! problems, against the tape bit for bit: every corpus family at its smallest size, the
//! gap-crossing model (∇f, Jacobian, Hessian), and solves of the quadrotor and Van der Pol
//! multiple-shooting examples, whose iterates must be identical (same iteration count, same
//! solution bits). No tolerance: the JIT performs the tape's operations in the tape's order.
//! Times are printed for information only (`--nocapture`), never asserted.
use symnlp_examples::{quadrotor, vdp_multiple_shooting};

use std::time::Instant;
use symnlp::nlp::ocp::{ButcherTableau, Method, Transcription};
use symnlp::nlp::{Compiled, Ipm, NumericNlp};
use symnlp::symx::Evaluator;

/// All five evaluations of `c` at `x` (σ = 0.7, λᵢ = (i+1)/m − 0.5), stacked.
fn evaluations(c: &mut Compiled, x: &[f64]) -> Vec<f64> {
    let (n, m) = (c.n(), c.m());
    let mut out = vec![c.eval_f(x)];
    let mut grad = vec![0.0; n];
    c.eval_grad_f(x, &mut grad);
    let mut g = vec![0.0; m];
    c.eval_g(x, &mut g);
    let mut jac = vec![0.0; c.jac_g_sparsity().compute_nnz()];
    c.eval_jac_g(x, &mut jac);
    let lambda: Vec<f64> = (0..m).map(|i| (i + 1) as f64 / m as f64 - 0.5).collect();
    let mut hess = vec![0.0; c.hess_l_sparsity().compute_nnz()];
    c.eval_hess_l(x, 0.7, &lambda, &mut hess);
    for v in [grad, g, jac, hess] {
        out.extend(v);
    }
    out
}

/// Compiles `c`'s evaluators natively (timed) and checks them bit for bit against the
/// tape at the initial point and at a perturbed point; returns the compile time (s).
fn check_problem(name: &str, c: &Compiled) -> f64 {
    let t = Instant::now();
    let mut native = c.clone().with_evaluator(Evaluator::Jit).unwrap();
    let compile = t.elapsed().as_secs_f64();
    assert_eq!(native.evaluator(), Evaluator::Jit);
    let mut tape = c.clone();
    assert_eq!(tape.evaluator(), Evaluator::Tape);
    let mut x0 = vec![0.0; c.n()];
    tape.initial_point(&mut x0);
    let shifted: Vec<f64> = x0
        .iter()
        .enumerate()
        .map(|(i, v)| v + 0.01 * ((i % 7) as f64 - 3.0))
        .collect();
    for x in [&x0, &shifted] {
        let (want, got) = (evaluations(&mut tape, x), evaluations(&mut native, x));
        assert_eq!(want.len(), got.len());
        for (k, (a, b)) in want.iter().zip(&got).enumerate() {
            assert_eq!(
                a.to_bits(),
                b.to_bits(),
                "{name}: entry {k}: tape {a:e}, jit {b:e}"
            );
        }
    }
    compile
}

/// Every corpus family at its smallest size (optimal control and CUTEst-style).
#[test]
fn corpus_problems_match_the_tape() {
    let mut families = 0;
    for family in corpus::families() {
        let instance = corpus::Instance {
            family,
            size: family.sizes[0],
        };
        let c = instance.build().unwrap().compile().unwrap();
        let secs = check_problem(&instance.name(), &c);
        eprintln!("{}: jit compile {:.3} s", instance.name(), secs);
        families += 1;
    }
    assert!(families > 20, "the corpus has {families} families");
}

/// The gap-crossing model (crawl, default scenario, 60 stances): ∇f, g, the Jacobian and
/// the Hessian of the Lagrangian (the functions of `benches/symx_eval.rs`'s gap group).
#[test]
fn gap_model_matches_the_tape() {
    use gap_crossing::model::{self, Formulation};
    use gap_crossing::{gait, scenario::Scenario, terrain::GapTerrain};
    let s = Scenario::default();
    let m = model::build(
        &s,
        &GapTerrain { gap: s.gap },
        &Formulation::Scheduled(gait::crawl_schedule(s.n_step)),
        &gait::crawl(&s),
    )
    .unwrap();
    let c = m.problem.compile().unwrap();
    let secs = check_problem("gap crossing", &c);
    eprintln!(
        "gap crossing (n {}, m {}): jit compile of its 5 functions {secs:.2} s",
        c.n(),
        c.m()
    );
}

/// CPU seconds this process has used (user + system, all threads; Linux's
/// `/proc/self/stat` in ticks of 1/100 s), or NaN elsewhere: less sensitive than wall time
/// to the other processes of a loaded machine. For printed information only.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // The fields after the command name (which ends with the last ')'): utime and stime
    // are the 12th and 13th of them.
    let rest = stat.rsplit(')').next().unwrap_or("");
    let ticks: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|t| t.parse().ok())
        .collect();
    if ticks.len() == 2 {
        (ticks[0] + ticks[1]) / 100.0
    } else {
        f64::NAN
    }
}

/// Solves `tr` with the tape and with native evaluators, three times each, interleaved:
/// identical iteration counts and solution bits; prints the JIT's compile time and the
/// median solve times (wall and CPU) with the number of solves after which the JIT's
/// compile time is paid back (the measurement behind `Problem::compile`'s default).
fn same_solve(name: &str, tr: &Transcription) {
    let t = Instant::now();
    let tape = tr.compile().unwrap();
    let build = t.elapsed().as_secs_f64();
    let (t, cpu) = (Instant::now(), cpu_seconds());
    let native = tape.clone().with_evaluator(Evaluator::Jit).unwrap();
    let (jit_compile, jit_compile_cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - cpu);
    let mut times = [Vec::new(), Vec::new()];
    let mut cpu_times = [Vec::new(), Vec::new()];
    let mut sols = Vec::new();
    for _ in 0..3 {
        for (k, c) in [&tape, &native].into_iter().enumerate() {
            let mut c = c.clone();
            let (t, cpu) = (Instant::now(), cpu_seconds());
            let sol = Ipm::default().solve(&mut c).unwrap();
            times[k].push(t.elapsed().as_secs_f64());
            cpu_times[k].push(cpu_seconds() - cpu);
            sols.push(sol);
        }
    }
    let first = &sols[0];
    for s in &sols[1..] {
        assert_eq!(s.status, first.status, "{name}: status");
        assert_eq!(
            s.stats.iterations, first.stats.iterations,
            "{name}: iterations"
        );
        let same =
            s.x.iter()
                .zip(&first.x)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{name}: solutions differ");
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[1]
    };
    let (t_tape, t_jit) = (median(&mut times[0]), median(&mut times[1]));
    let (c_tape, c_jit) = (median(&mut cpu_times[0]), median(&mut cpu_times[1]));
    eprintln!(
        "{name}: {} iterations; wall: transcribe+compile {:.0} ms, jit compile {:.0} ms, solve tape {:.1} ms, jit {:.1} ms ({:.2}x), jit pays after {:.1} solves; CPU: jit compile {:.2} s, solve tape {:.2} s, jit {:.2} s, pays after {:.1} solves",
        first.stats.iterations,
        1e3 * build,
        1e3 * jit_compile,
        1e3 * t_tape,
        1e3 * t_jit,
        t_jit / t_tape,
        jit_compile / (t_tape - t_jit),
        jit_compile_cpu,
        c_tape,
        c_jit,
        jit_compile_cpu / (c_tape - c_jit)
    );
}

/// The quadrotor (N = 320, RK4 multiple shooting) and Van der Pol (N = 20, RK4 with four
/// steps per interval) examples, inlined and through call nodes.
#[test]
fn ocp_examples_solve_identically() {
    same_solve("quadrotor N=320", &quadrotor::transcription(320).unwrap());
    same_solve(
        "quadrotor N=320 calls",
        &quadrotor::transcription_with_calls(320).unwrap(),
    );
    let rk4 = || Method::multiple_shooting(ButcherTableau::rk4(), 4);
    let calls = || Method::multiple_shooting_with_calls(ButcherTableau::rk4(), 4);
    let vdp = vdp_multiple_shooting::van_der_pol().unwrap();
    same_solve("van der pol N=20", &vdp.transcribe(&rk4(), 20).unwrap());
    let vdp = vdp_multiple_shooting::van_der_pol_with_calls().unwrap();
    same_solve(
        "van der pol N=20 calls",
        &vdp.transcribe(&calls(), 20).unwrap(),
    );
}

/// Compiles `f.to_c()` (`cc -std=c99 -O0`: ISO mode, no FMA contraction; -O0 keeps the
/// compile of the large straight-line function to seconds) with a driver that reads the
/// inputs' bits from a file and prints the outputs' bits; returns the outputs.
fn c_outputs(f: &symnlp::symx::Function, inputs: &[&[f64]], tag: &str) -> Vec<f64> {
    use std::process::Command;
    let dir = std::env::temp_dir().join(format!("symnlp_gap_c_{}_{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("f.c"), f.to_c().unwrap()).unwrap();
    let sizes: Vec<String> = inputs.iter().map(|a| a.len().to_string()).collect();
    let n_out: usize = f.output_sizes().iter().sum();
    let driver = format!(
        r#"#include <stdio.h>
#include <stdlib.h>
typedef long long casadi_int;
int f(const double** arg, double** res, casadi_int* iw, double* w, int mem);
int f_work(casadi_int* sz_arg, casadi_int* sz_res, casadi_int* sz_iw, casadi_int* sz_w);
int main(int argc, char** argv) {{
  long sizes[] = {{{}}}; int n_in = {};
  FILE* in = fopen(argv[1], "rb");
  const double* arg[16]; double* res[16];
  for (int k = 0; k < n_in; k++) {{ double* a = malloc(8 * sizes[k] + 8); if (fread(a, 8, sizes[k], in) != (size_t)sizes[k]) return 2; arg[k] = a; }}
  casadi_int sa, sr, si, sw; f_work(&sa, &sr, &si, &sw);
  double* w = malloc(8 * sw + 8); res[0] = malloc(8 * {n_out} + 8);
  if (f(arg, res, 0, w, 0) != 0) return 1;
  for (long i = 0; i < {n_out}; i++) printf("%llx\n", ((unsigned long long*)res[0])[i]);
  return 0;
}}"#,
        sizes.join(", "),
        inputs.len()
    );
    std::fs::write(dir.join("main.c"), driver).unwrap();
    let bytes: Vec<u8> = inputs
        .concat()
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(dir.join("in.bin"), bytes).unwrap();
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let exe = dir.join("main");
    let status = Command::new(cc)
        .args(["-std=c99", "-O0", "-o"])
        .arg(&exe)
        .arg(dir.join("f.c"))
        .arg(dir.join("main.c"))
        .arg("-lm")
        .status()
        .expect("a C compiler (cc) runs");
    assert!(status.success(), "{tag}: the generated C does not compile");
    let out = Command::new(&exe).arg(dir.join("in.bin")).output().unwrap();
    assert!(out.status.success(), "{tag}: the C program failed");
    let _ = std::fs::remove_dir_all(&dir);
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| f64::from_bits(u64::from_str_radix(l, 16).unwrap()))
        .collect()
}

/// The gap-crossing model's ∇f (`"grad_f"`) or Jacobian of g (`"jac_g"`), the functions
/// of `benches/symx_eval.rs`'s gap group, through `Function::to_c`, compiled by the system's
/// C compiler: bit for bit the tape's values at the initial point (no NaN occurs there, so
/// NaN payloads, which C may order differently, do not matter).
fn gap_function_through_generated_c(which: &str) {
    use gap_crossing::model::{self, Formulation};
    use gap_crossing::{gait, scenario::Scenario, terrain::GapTerrain};
    use symnlp::symx::{gradient, jacobian, Function};
    let s = Scenario::default();
    let m = model::build(
        &s,
        &GapTerrain { gap: s.gap },
        &Formulation::Scheduled(gait::crawl_schedule(s.n_step)),
        &gait::crawl(&s),
    )
    .unwrap();
    let x = m.problem.variables().to_vec();
    let out = match which {
        "grad_f" => gradient(m.problem.objective(), &x).unwrap(),
        _ => jacobian(&m.problem.constraint_expressions(), &x)
            .unwrap()
            .values()
            .to_vec(),
    };
    let c = m.problem.compile().unwrap();
    let mut x0 = vec![0.0; c.n()];
    c.initial_point(&mut x0);
    let f = Function::new(&[&x], &[&out]).unwrap();
    let want = f.call(&[&x0]).unwrap().remove(0);
    let t = Instant::now();
    let got = c_outputs(&f, &[&x0], which);
    eprintln!(
        "{which}: {} instructions, cc and run {:.1} s",
        f.instruction_count(),
        t.elapsed().as_secs_f64()
    );
    assert_eq!(want.len(), got.len(), "{which}: output size");
    for (i, (a, b)) in want.iter().zip(&got).enumerate() {
        assert_eq!(
            a.to_bits(),
            b.to_bits(),
            "{which}[{i}]: tape {a:e}, C {b:e}"
        );
    }
}

/// The gap model's ∇f through generated C (a second or so of `cc`; 9 s on a loaded
/// machine).
#[test]
fn gap_model_gradient_through_generated_c_matches_the_tape() {
    gap_function_through_generated_c("grad_f");
}

/// The gap model's Jacobian through generated C: 1.2 MB of C, about 50 s of `cc -O0` on a
/// loaded machine, so not in CI's run. Run: `cargo test --release --test jit
/// gap_model_jacobian -- --ignored`.
#[test]
#[ignore]
fn gap_model_jacobian_through_generated_c_matches_the_tape() {
    gap_function_through_generated_c("jac_g");
}
