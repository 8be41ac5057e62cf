//! `Function::to_c`: the generated C file is compiled by the system's C compiler (`cc`, or
//! `$CC`; `-std=c99 -O2`, ISO mode, so no FMA contraction) with a driver calling it through
//! CasADi's calling convention; its outputs must equal the tape's bit for bit (same IEEE
//! operations, same C library math functions as Rust's std), except for the sign and
//! payload of NaNs (the C compiler may swap the operands of a commutative operation, and
//! x86 returns the first operand's NaN).
use proptest::prelude::*;
use std::io::Write;
use std::process::{Command, Stdio};
use symx::{
    gradient, hessian, if_else, jacobian, lt, parse, Expr, Function, Interpolant, Matrix,
    SourceOptions, Sparsity, SymxError,
};
use testkit::special::{same_or_both_nan, SPECIAL};

/// Reads the points (every input's entries, as hex bits, one number per line) from stdin
/// until its end, evaluates each through the CasADi interface (the work sizes from
/// `f_work`, the input sizes from `f_sparsity_in`; the work vector exactly `sz_w` numbers,
/// NaN-filled before every call, and a guard after it that must stay untouched) and prints
/// every output's bits. Also prints the interface's metadata once, first.
const DRIVER: &str = r#"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
typedef long long casadi_int;
int NAME(const double** arg, double** res, casadi_int* iw, double* w, int mem);
casadi_int NAME_n_in(void);
casadi_int NAME_n_out(void);
const char* NAME_name_in(casadi_int i);
const char* NAME_name_out(casadi_int i);
const casadi_int* NAME_sparsity_in(casadi_int i);
const casadi_int* NAME_sparsity_out(casadi_int i);
int NAME_work(casadi_int* sz_arg, casadi_int* sz_res, casadi_int* sz_iw, casadi_int* sz_w);
static casadi_int nnz(const casadi_int* sp) { return sp[2 + sp[1]]; }
int main(void) {
  casadi_int n_in = NAME_n_in(), n_out = NAME_n_out(), sa, sr, si, sw;
  NAME_work(&sa, &sr, &si, &sw);
  printf("in %lld out %lld arg %lld res %lld iw %lld w %lld\n", n_in, n_out, sa, sr, si, sw);
  for (casadi_int k = 0; k < n_out; k++) {
    const casadi_int* sp = NAME_sparsity_out(k);
    printf("out %s %lld x %lld:", NAME_name_out(k), sp[0], sp[1]);
    for (casadi_int i = 0; i < sp[1] + 1 + nnz(sp); i++) printf(" %lld", sp[2 + i]);
    printf("\n");
  }
  const double* arg[64]; double* res[64];
  /* Exactly sz_w numbers, then a guard: NaN-filled before every call. */
  double* w = malloc(8 * (sw + 16));
  for (casadi_int k = 0; k < n_in; k++) arg[k] = malloc(8 * (nnz(NAME_sparsity_in(k)) + 1));
  for (casadi_int k = 0; k < n_out; k++) res[k] = malloc(8 * (nnz(NAME_sparsity_out(k)) + 1));
  for (;;) {
    for (casadi_int k = 0; k < n_in; k++)
      for (casadi_int i = 0; i < nnz(NAME_sparsity_in(k)); i++) {
        unsigned long long b;
        if (scanf("%llx", &b) != 1) return 0;
        ((unsigned long long*)arg[k])[i] = b;
      }
    unsigned long long mark = 0x7ff8dead0000beefULL;
    for (casadi_int i = 0; i < sw + 16; i++) memcpy(w + i, &mark, 8);
    if (NAME(arg, res, 0, w, 0) != 0) return 1;
    for (casadi_int i = sw; i < sw + 16; i++)
      if (memcmp(w + i, &mark, 8) != 0) { fprintf(stderr, "a write past sz_w\n"); return 2; }
    for (casadi_int k = 0; k < n_out; k++)
      for (casadi_int i = 0; i < nnz(NAME_sparsity_out(k)); i++)
        printf("%llx\n", ((unsigned long long*)res[k])[i]);
    /* Again with each output skipped in turn (null res[k]): the others must not change. */
    for (casadi_int skip = 0; skip < n_out && n_out > 1; skip++) {
      double* again[64];
      for (casadi_int k = 0; k < n_out; k++) again[k] = k == skip ? 0 : malloc(8 * (nnz(NAME_sparsity_out(k)) + 1));
      if (NAME(arg, again, 0, w, 0) != 0) return 1;
      for (casadi_int k = 0; k < n_out; k++) {
        if (k == skip) continue;
        if (memcmp(again[k], res[k], 8 * nnz(NAME_sparsity_out(k))) != 0) { fprintf(stderr, "output %lld changed with res[%lld] null\n", k, skip); return 3; }
        free(again[k]);
      }
    }
  }
}
"#;

/// Compiles `code` (the C of a function named `name`) with the driver; returns the
/// driver's metadata lines and the outputs at each point (inputs stacked per point).
fn run_c(code: &str, name: &str, points: &[Vec<f64>], tag: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let dir = std::env::temp_dir().join(format!("symx_c_source_{}_{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("f.c"), code).unwrap();
    std::fs::write(dir.join("main.c"), DRIVER.replace("NAME", name)).unwrap();
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let exe = dir.join("main");
    let out = Command::new(cc)
        .args(["-std=c99", "-O2", "-Wall", "-Werror", "-o"])
        .arg(&exe)
        .arg(dir.join("f.c"))
        .arg(dir.join("main.c"))
        .arg("-lm")
        .output()
        .expect("a C compiler (cc) runs");
    assert!(
        out.status.success(),
        "the generated C does not compile:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut child = Command::new(&exe)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut input = String::new();
    for p in points {
        for v in p {
            input.push_str(&format!("{:x}\n", v.to_bits()));
        }
    }
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "the driver failed");
    let _ = std::fs::remove_dir_all(&dir);
    let text = String::from_utf8(out.stdout).unwrap();
    let (meta, values): (Vec<&str>, Vec<&str>) = text
        .lines()
        .partition(|l| l.starts_with("in ") || l.starts_with("out "));
    let values: Vec<f64> = values
        .iter()
        .map(|l| f64::from_bits(u64::from_str_radix(l, 16).unwrap()))
        .collect();
    let per = values.len() / points.len().max(1);
    (
        meta.iter().map(|s| s.to_string()).collect(),
        values.chunks(per.max(1)).map(|c| c.to_vec()).collect(),
    )
}

/// Asserts the C outputs equal the tape's at every point (NaN sign and payload aside).
fn same_as_tape(f: &Function, points: &[Vec<f64>], tag: &str) {
    let code = f.to_c().unwrap();
    let (_, got) = run_c(&code, f.name(), points, tag);
    assert_eq!(got.len(), points.len());
    for (k, (p, g)) in points.iter().zip(&got).enumerate() {
        let mut at = 0;
        let inputs: Vec<&[f64]> = f
            .input_sizes()
            .iter()
            .map(|&n| {
                at += n;
                &p[at - n..at]
            })
            .collect();
        let want = f.call(&inputs).unwrap().concat();
        assert_eq!(want.len(), g.len());
        for (i, (a, b)) in want.iter().zip(g).enumerate() {
            let same = same_or_both_nan(*a, *b);
            assert!(
                same,
                "{tag}: point {k} {p:?}, output {i}: tape {a:e}, C {b:e}"
            );
        }
    }
}

/// Every operation the C generator supports, and `if_else`, on every pair of special
/// operands.
#[test]
fn every_operation_matches_the_tape_on_special_values() {
    let x = Expr::sym("x");
    let y = Expr::sym("y");
    let z = Expr::sym("z");
    let names = [
        "neg(x)",
        "sq(x)",
        "sqrt(x)",
        "exp(x)",
        "log(x)",
        "sin(x)",
        "cos(x)",
        "tan(x)",
        "asin(x)",
        "acos(x)",
        "atan(x)",
        "sinh(x)",
        "cosh(x)",
        "tanh(x)",
        "abs(x)",
        "sign(x)",
        "not(x)",
        "floor(x)",
        "ceil(x)",
        "log1p(x)",
        "expm1(x)",
        "add(x,y)",
        "sub(x,y)",
        "mul(x,y)",
        "div(x,y)",
        "pow(x,y)",
        "atan2(x,y)",
        "min(x,y)",
        "max(x,y)",
        "lt(x,y)",
        "le(x,y)",
        "eq(x,y)",
        "ne(x,y)",
        "and(x,y)",
        "or(x,y)",
        "strong_mul(x,y)",
        "fmod(x,y)",
        "hypot(x,y)",
    ];
    let syms = [x, y, z];
    let mut outs: Vec<Expr> = names.iter().map(|n| parse(n, &syms).unwrap()).collect();
    for (e, n) in outs.iter().zip(&names) {
        assert!(n.starts_with(e.op().name()), "{n} parsed as {:?}", e.op());
    }
    outs.push(if_else(x, y, z));
    let f = Function::new(&[&[x, y, z]], &[&outs]).unwrap();
    let mut points = Vec::new();
    for &a in &SPECIAL {
        for &b in &SPECIAL {
            points.push(vec![a, b, -b]);
        }
    }
    same_as_tape(&f, &points, "special");
}

/// Values, gradient and Hessian of a function with transcendental functions, powers,
/// branches and a (nested) call of another function; the CasADi metadata (names, sizes,
/// sparsity, work) as declared.
#[test]
fn derivatives_and_calls_match_the_tape() {
    let y = Matrix::sym_vec("y", 2);
    let leaf = Function::named("leaf", &[("y", &y)], &[("v", &[y[0].cos() / y[1]])]).unwrap();
    let l = leaf.apply(&[&[y[1], y[0]]]).unwrap().remove(0);
    let inner = Function::named(
        "inner",
        &[("y", &y)],
        &[("v", &[y[0].sin() * y[1] + l[0], y[1].exp() - y[0].powi(3)])],
    )
    .unwrap();
    let x = Matrix::sym_vec("x", 3);
    let c = inner.apply(&[&[x[0], x[2]]]).unwrap().remove(0);
    let f = (x[0] * x[1]).cos()
        + x[2].pow(x[0])
        + if_else(lt(x[0], x[1]), x[0].atan2(x[2]), x[1].sqrt())
        + x[1].ln() * c[0]
        + c[1].tanh()
        + x[0].hypot(x[1])
        + x[2].abs().sign()
        + x[0].min(x[2])
        + x[1].powi(-2);
    let g = gradient(f, &x).unwrap();
    let h = hessian(f, &x).unwrap();
    let p = Matrix::sym_vec("p", 1);
    let fun = Function::named(
        "model",
        &[("x", &x), ("p", &p)],
        &[("f", &[f * p[0]]), ("g", &g), ("h", h.values())],
    )
    .unwrap();
    let points = vec![
        vec![0.3, 1.7, -0.4, 2.0],
        vec![-2.0, 0.5, 3.0, -1.0],
        vec![0.0, -1.0, f64::INFINITY, 0.5],
    ];
    same_as_tape(&fun, &points, "calls");

    // The interface: 2 inputs, 3 outputs, no integer work, the tape's work vector.
    let opts = SourceOptions {
        output_sparsity: vec![None, None, Some(h.sparsity().clone())],
    };
    let (meta, _) = run_c(&fun.to_c_with(&opts).unwrap(), "model", &[], "meta");
    // The work vector: less than the whole tape, and no less than the generated Rust's
    // `WORK_SIZE` (which keeps only the temporaries a later body reads, the others in
    // local variables; C keeps every temporary, plus at most one slot per output entry
    // read back).
    let rust = fun.to_rust().unwrap();
    let work_size: usize = rust
        .split("pub const WORK_SIZE: usize = ")
        .nth(1)
        .and_then(|t| t.split(';').next())
        .unwrap()
        .parse()
        .unwrap();
    let sz_w: usize = meta[0].rsplit(' ').next().unwrap().parse().unwrap();
    let outputs: usize = fun.output_sizes().iter().sum();
    assert!(
        work_size <= sz_w && sz_w < fun.work_size(),
        "sz_w {sz_w}, WORK_SIZE {work_size}, outputs {outputs}, tape {}",
        fun.work_size()
    );
    assert_eq!(meta[0], format!("in 2 out 3 arg 2 res 3 iw 0 w {sz_w}"));
    assert_eq!(meta[1], "out f 1 x 1: 0 1 0");
    let s = h.sparsity();
    let mut want = format!("out h {} x {}:", s.nrows(), s.ncols());
    for v in s.col_ptr().iter().chain(s.row_idx()) {
        want.push_str(&format!(" {v}"));
    }
    assert_eq!(meta[3], want);
}

fn program() -> impl Strategy<Value = Vec<(u8, usize, usize, usize)>> {
    prop::collection::vec(
        (0u8..20, any::<usize>(), any::<usize>(), any::<usize>()),
        1..120,
    )
}

fn build(prog: &[(u8, usize, usize, usize)], v: &mut Vec<Expr>) {
    for &(op, i, j, k) in prog {
        let n = v.len();
        let (a, b, c) = (v[i % n], v[j % n], v[k % n]);
        v.push(match op {
            0 => a + b,
            1 => a * b,
            2 => a - b,
            3 => a / b,
            4 => a.sin(),
            5 => a.exp(),
            6 => a.sqrt(),
            7 => a.ln(),
            8 => a.powi(3),
            9 => a.pow(b),
            10 => if_else(lt(a, b), b, c),
            11 => a.tanh(),
            12 => a.min(b),
            13 => a.max(b),
            14 => a.abs(),
            15 => a.atan2(b),
            16 => -a,
            17 => a.cos() * b,
            18 => a.hypot(c),
            _ => a.sign() * c,
        });
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]
    /// Random expression graphs and their Jacobians: C equals the tape.
    #[test]
    fn random_graphs_match_the_tape(prog in program(), p in prop::collection::vec(-3.0f64..3.0, 3)) {
        let x = Matrix::sym_vec("x", 3);
        let mut v: Vec<Expr> = x.iter().copied().collect();
        build(&prog, &mut v);
        let outs: Vec<Expr> = v[v.len().saturating_sub(4)..].to_vec();
        let j = jacobian(&outs, &x).unwrap();
        let f = Function::new(&[&x], &[&outs, j.values()]).unwrap();
        same_as_tape(&f, &[p], "random");
    }
}

/// Output entries that the computation reads back (an output the tape computes in its
/// output slot and reads for the other outputs): with `res[0]` null (CasADi: output 0 not
/// wanted) the other outputs must come out the same (the driver checks every output
/// skipped in turn), and the work vector of `sz_w` numbers must hold those entries.
#[test]
fn outputs_read_back_survive_a_null_res() {
    let x = Matrix::sym_vec("x", 2);
    let a = x[0].sin() * x[1];
    let b = a.exp();
    let f = Function::named(
        "back",
        &[("x", &x)],
        &[("o", &[a, b]), ("p", &[a * 3.0, b + a])],
    )
    .unwrap();
    let points = vec![
        vec![0.3, 1.7],
        vec![-2.0, f64::NAN],
        vec![f64::INFINITY, 0.0],
    ];
    same_as_tape(&f, &points, "back");
}

/// What cannot be generated is refused with an error naming it.
#[test]
fn refusals_name_what_is_wrong() {
    let x = Matrix::sym_vec("x", 1);
    let expect = |r: Result<String, SymxError>, what: &str| match r {
        Err(SymxError::Jit { message }) => assert!(message.contains(what), "{message}"),
        other => panic!("{other:?}"),
    };
    let erf = Function::new(&[&x], &[&[x[0].erf()]]).unwrap();
    expect(erf.to_c(), "'erf'");
    let table = Interpolant::linear(&[0.0, 1.0, 2.0], &[0.0, 1.0, 4.0]).unwrap();
    let t = Function::new(&[&x], &[&[table.eval(x[0])]]).unwrap();
    expect(t.to_c(), "lookup tables");
    let bad = Function::named("my-f", &[("x", &x)], &[("y", &[x[0]])]).unwrap();
    expect(bad.to_c(), "'my-f' is not a C identifier");
    let f = Function::new(&[&x], &[&[x[0], x[0]]]).unwrap();
    let wrong = SourceOptions {
        output_sparsity: vec![Some(Sparsity::new_checked(
            3,
            1,
            vec![0, 3],
            None,
            vec![0, 1, 2],
        ))],
    };
    expect(f.to_c_with(&wrong), "has 3 nonzeros, but the output has 2");
    let too_many = SourceOptions {
        output_sparsity: vec![None, None],
    };
    expect(f.to_c_with(&too_many), "2 output sparsity patterns");
}
