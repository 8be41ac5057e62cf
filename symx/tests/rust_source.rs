//! `Function::to_rust`: the generated module is compiled by rustc (as a subprocess, with
//! `-O`, as a user's release build would) into a program that evaluates it and prints the
//! outputs' bits; they must equal the tape's bit for bit (same IEEE operations, same C
//! library math functions as Rust's std), except for the sign and payload of NaNs.
use std::process::Command;
use symx::{gradient, hessian, if_else, lt, Expr, Function, Matrix, SymxError};
use testkit::special::same_or_both_nan;

/// Compiles `f.to_rust()` with a `main` evaluating it at `point` with a work vector of
/// exactly `WORK_SIZE` entries, checking that the generated code writes every one of them
/// and none after; returns `WORK_SIZE` and the outputs.
fn run_generated(f: &Function, point: &[f64], tag: &str) -> (usize, Vec<f64>) {
    let dir = std::env::temp_dir().join(format!("symx_rust_source_{}_{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let module = f.to_rust().unwrap();
    std::fs::write(dir.join("generated.rs"), &module).unwrap();
    let bits: Vec<String> = point
        .iter()
        .map(|v| format!("f64::from_bits({:#x})", v.to_bits()))
        .collect();
    let main = format!(
        r#"mod f {{ include!("generated.rs"); }}
fn main() {{
    let x = [{}];
    let mut outs: Vec<Vec<f64>> = f::OUTPUT_SIZES.iter().map(|&n| vec![0.0; n]).collect();
    let mut refs: Vec<&mut [f64]> = outs.iter_mut().map(|v| v.as_mut_slice()).collect();
    // A signalling NaN no operation produces marks every slot, and 16 more after the end.
    let mark = f64::from_bits(0x7ff0_dead_beef_0001);
    let mut work = vec![mark; f::WORK_SIZE + 16];
    f::eval(&[&x], &mut refs, &mut work[..f::WORK_SIZE]).unwrap();
    let written = |v: &f64| v.to_bits() != mark.to_bits();
    assert!(work[..f::WORK_SIZE].iter().all(written), "an unused slot in WORK_SIZE");
    assert!(!work[f::WORK_SIZE..].iter().any(written), "a write past WORK_SIZE");
    assert_eq!(f::eval(&[], &mut refs, &mut work), Err("wrong number of inputs"));
    assert_eq!(f::INPUT_SIZES.len(), 1);
    println!("{{}}", f::WORK_SIZE);
    for v in outs.concat() {{ println!("{{:x}}", v.to_bits()); }}
}}"#,
        bits.join(", ")
    );
    std::fs::write(dir.join("main.rs"), main).unwrap();
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let exe = dir.join("main");
    let status = Command::new(rustc)
        .args(["-O", "--edition", "2021", "-o"])
        .arg(&exe)
        .arg(dir.join("main.rs"))
        .status()
        .expect("rustc runs");
    assert!(status.success(), "the generated module does not compile");
    let out = Command::new(&exe).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    let work_size = lines.next().unwrap().parse().unwrap();
    let outputs = lines
        .map(|l| f64::from_bits(u64::from_str_radix(l, 16).unwrap()))
        .collect();
    (work_size, outputs)
}

/// Values, gradient and Hessian of a function with transcendental functions, powers,
/// branches, NaN-producing operations and a call of another function.
#[test]
fn generated_rust_matches_the_tape() {
    let y = Matrix::sym_vec("y", 2);
    let inner = Function::named(
        "inner",
        &[("y", &y)],
        &[("v", &[y[0].sin() * y[1], y[1].exp() - y[0].powi(3)])],
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
    let fun = Function::new(&[&x], &[&[f], &g, h.values()]).unwrap();
    for (k, p) in [
        [0.3, 1.7, -0.4],
        [-2.0, 0.5, 3.0],
        [0.0, -1.0, f64::INFINITY],
    ]
    .iter()
    .enumerate()
    {
        let want = fun.call(&[p]).unwrap().concat();
        let (work_size, got) = run_generated(&fun, p, &k.to_string());
        // Only temporaries: not the tape's inputs, constants and output slots.
        let kept_elsewhere = 3 + want.len();
        assert!(
            work_size + kept_elsewhere <= fun.work_size(),
            "WORK_SIZE {work_size}"
        );
        assert_eq!(want.len(), got.len());
        for (i, (a, b)) in want.iter().zip(&got).enumerate() {
            // A NaN's sign and payload are not kept: rustc may swap the operands of a
            // commutative operation, and x86 returns the first operand's NaN.
            let same = same_or_both_nan(*a, *b);
            assert!(same, "point {k}, output {i}: tape {a:e}, generated {b:e}");
        }
    }
}

/// Operations without an exact dependency-free counterpart are refused, by name.
#[test]
fn unsupported_operations_are_errors() {
    let x = Matrix::sym_vec("x", 1);
    let f = Function::new(&[&x], &[&[x[0].erf()]]).unwrap();
    match f.to_rust() {
        Err(SymxError::Jit { message }) => assert!(message.contains("erf"), "{message}"),
        other => panic!("{other:?}"),
    }
}

/// docs/dsl.md's `build.rs` recipe, compiled: the build script's body runs here (writing
/// the module into an `OUT_DIR`), and the firmware crate's `src/lib.rs`, verbatim from the
/// docs plus `#![no_std]`, is compiled by rustc as a library with that `OUT_DIR`, then
/// called from a program that checks its value against the tape.
#[test]
fn the_docs_build_rs_recipe_compiles_and_computes_the_tape_values() {
    let dir = std::env::temp_dir().join(format!("symx_build_rs_{}", std::process::id()));
    let out_dir = dir.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    // build.rs, as in the docs (OUT_DIR given here rather than by cargo).
    let x = Matrix::sym_vec("x", 2);
    let f = Function::new(&[&x], &[&[x[0].sin() * x[1]]]).unwrap();
    std::fs::write(out_dir.join("model.rs"), f.to_rust().unwrap()).unwrap();
    // src/lib.rs, as in the docs.
    let lib = r#"#![no_std]
mod model {
    include!(concat!(env!("OUT_DIR"), "/model.rs"));
}
pub fn step(x: &[f64; 2], y: &mut [f64; 1]) -> Result<(), &'static str> {
    let mut work = [0.0; model::WORK_SIZE];
    model::eval(&[x], &mut [y], &mut work)
}
"#;
    std::fs::write(dir.join("lib.rs"), lib).unwrap();
    std::fs::write(
        dir.join("main.rs"),
        "fn main() { let mut y = [0.0]; firmware::step(&[0.3, -1.7], &mut y).unwrap(); println!(\"{:x}\", y[0].to_bits()); }",
    )
    .unwrap();
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let status = Command::new(&rustc)
        .args([
            "-O",
            "--edition",
            "2021",
            "--crate-type",
            "rlib",
            "--crate-name",
            "firmware",
            "-o",
        ])
        .arg(dir.join("libfirmware.rlib"))
        .arg(dir.join("lib.rs"))
        .env("OUT_DIR", &out_dir)
        .status()
        .expect("rustc runs");
    assert!(status.success(), "the docs' src/lib.rs does not compile");
    let exe = dir.join("main");
    let status = Command::new(&rustc)
        .args(["-O", "--edition", "2021", "--extern"])
        .arg(format!(
            "firmware={}",
            dir.join("libfirmware.rlib").display()
        ))
        .arg("-o")
        .arg(&exe)
        .arg(dir.join("main.rs"))
        .status()
        .expect("rustc runs");
    assert!(
        status.success(),
        "the program calling the firmware crate does not compile"
    );
    let out = Command::new(&exe).output().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let bits = u64::from_str_radix(String::from_utf8(out.stdout).unwrap().trim(), 16).unwrap();
    let want = f.call(&[&[0.3, -1.7]]).unwrap()[0][0];
    assert_eq!(bits, want.to_bits());
}

/// A tape several bodies long (the generated code keeps values in local variables within a
/// body of 256 instructions and only those read by a later body in the work vector):
/// early outputs and temporaries read far later, through a call as well; the values must
/// equal the tape's, and `WORK_SIZE` hold exactly the slots written (see
/// [`run_generated`]), fewer than the tape's temporaries.
#[test]
fn long_tapes_keep_values_across_bodies() {
    let y = Matrix::sym_vec("y", 2);
    let inner =
        Function::named("inner", &[("y", &y)], &[("v", &[y[0] * y[1], y[1] - y[0]])]).unwrap();
    let x = Matrix::sym_vec("x", 3);
    let early: Vec<Expr> = (0..4).map(|k| x[k % 3] * (k as f64 + 0.5) - x[2]).collect();
    let temp = x[0].sin() * x[1];
    let mut s = x[2];
    for k in 0..1500 {
        s = s * 0.999 + (early[k % 4] * 1e-3).sin();
    }
    let c = inner.apply(&[&[s, temp]]).unwrap().remove(0);
    let late = [early[0] * s + temp, c[0] + early[3], c[1] * temp];
    let fun = Function::new(&[&x], &[&early, &late]).unwrap();
    assert!(fun.instruction_count() > 3000);
    let p = [0.3, -1.2, 0.7];
    let want = fun.call(&[&p]).unwrap().concat();
    let (work_size, got) = run_generated(&fun, &p, "long");
    assert!(work_size < fun.work_size() / 2, "WORK_SIZE {work_size}");
    for (i, (a, b)) in want.iter().zip(&got).enumerate() {
        assert!(
            same_or_both_nan(*a, *b),
            "output {i}: tape {a:e}, generated {b:e}"
        );
    }
}

/// The generated functions of the tape's bodies take the inputs they read as shared
/// references (`x0: &[f64]`), which rustc marks `noalias`, so that LLVM may load inputs
/// above the stores to outputs and pair operations into SIMD instructions (on the gap
/// model's ∇f, 4 451 → 2 366 instructions per call; performance-notebook.md, tenth round),
/// and never read an input through the caller's raw pointers. Checked on the text, for the
/// caller and for a called function (whose inputs are a block of the caller's work vector);
/// the values of such a module are checked by the tests above.
#[test]
fn bodies_take_their_inputs_as_references() {
    let y = Matrix::sym_vec("y", 2);
    let inner =
        Function::named("inner", &[("y", &y)], &[("v", &[y[0] * y[1], y[1] - y[0]])]).unwrap();
    let x = Matrix::sym_vec("x", 2);
    let z = Matrix::sym_vec("z", 1);
    let c = inner.apply(&[&[x[0] + z[0], x[1]]]).unwrap().remove(0);
    let f = Function::new(&[&x, &z], &[&[c[0] * x[1], c[1] + z[0]], &[x[0] * 2.0]]).unwrap();
    let module = f.to_rust().unwrap();
    let bodies: Vec<&str> = module
        .split("#[inline(never)]\nunsafe fn ")
        .skip(1)
        .map(|b| &b[..b.find("\n}\n").unwrap()])
        .collect();
    // The callee's body and the caller's.
    assert_eq!(bodies.len(), 2, "{module}");
    for body in &bodies {
        let signature = body.lines().next().unwrap();
        let reads = |k: usize| body.contains(&format!("*x{k}.add("));
        for k in 0..2 {
            let declared = signature.contains(&format!("x{k}: &[f64]"));
            assert_eq!(reads(k), declared, "input {k}: {signature}");
        }
        assert!(reads(0), "{signature}");
        assert!(!body.contains("*x.add("), "{body}");
    }
}

/// Square roots (the generated code's own, not the C library's, on x86-64) against the
/// tape's `f64::sqrt`, both correctly rounded: at zeros of both signs, subnormal, huge,
/// infinite, negative and NaN arguments, and in the first and second derivatives.
#[test]
fn square_roots_match_the_tape() {
    let x = Matrix::sym_vec("x", 3);
    let f = (x[0] * x[1] + x[2] * x[2]).sqrt() + x[1].sqrt() * x[2];
    let g = gradient(f, &x).unwrap();
    let h = hessian(f, &x).unwrap();
    let values = [x[0].sqrt(), x[1].sqrt(), x[2].sqrt()];
    let fun = Function::new(&[&x], &[&values, &[f], &g, h.values()]).unwrap();
    for (k, p) in [
        [2.0, 3.0, 0.1],
        [0.0, -0.0, 1e300],
        [5e-324, f64::INFINITY, -1.0],
        [f64::NAN, 1.7, 0.3],
    ]
    .iter()
    .enumerate()
    {
        let want = fun.call(&[p]).unwrap().concat();
        let (_, got) = run_generated(&fun, p, &format!("sqrt{k}"));
        for (i, (a, b)) in want.iter().zip(&got).enumerate() {
            let same = same_or_both_nan(*a, *b);
            assert!(same, "point {k}, output {i}: tape {a:e}, generated {b:e}");
        }
    }
}
