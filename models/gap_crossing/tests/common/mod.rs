//! What the binary's integration tests share: running `gap-crossing`, a fresh scratch
//! directory per test, the arguments of a small solve. Each test file that includes this
//! module uses part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test.
pub const BIN: &str = env!("CARGO_BIN_EXE_gap-crossing");

/// Runs the binary with `args`.
pub fn run<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    Command::new(BIN).args(args).output().expect("binary runs")
}

/// A fresh, empty directory for test `name` of the test file `tag` (per process).
pub fn fresh_dir(tag: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("gap_crossing_{tag}_{}_{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The arguments of `solve` for a small crawl plan writing to `out`: n_step 12 with
/// goals 0.5 m ahead (the front feet cross the gap), solved in a few hundredths of a
/// second.
pub fn small_crawl_solve(out: &Path) -> Vec<String> {
    [
        "solve",
        "--gait",
        "crawl",
        "--set",
        "n_step=12",
        "--set",
        "goal.B=[0.5, 0.5, 0.5]",
        "--set",
        "goal.F=[2.5, 0.5, 0.5]",
        "--out",
        out.to_str().expect("UTF-8 path"),
    ]
    .map(String::from)
    .to_vec()
}
