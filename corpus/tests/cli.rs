//! The `corpus` binary with its standard output closed early (`corpus list | head -1`):
//! it ends quietly with exit 0 instead of panicking (exit 101).

use std::process::{Command, Stdio};

#[test]
fn a_closed_standard_output_ends_the_listing_quietly() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_corpus"))
        .args(["list", "--max-n", "50"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs");
    // The reader is gone before the first line: every write fails with EPIPE.
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("binary ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.is_empty(), "{stderr}");
}
