#!/usr/bin/env bash
# Build time of a fresh crate depending on symnlp (issue 22 item 7): a new binary crate
# outside the workspace, `symnlp = { path = ... }`, default features vs
# `default-features = false`, each a clean `cargo build --release` into a fresh
# CARGO_TARGET_DIR (CARGO_HOME warm: sources already downloaded), the two configurations
# interleaved, RUNS rounds. Prints CPU time (user + sys, from /usr/bin/time -v), wall time,
# peak memory and the number of crates compiled.
# Usage: bash benches/reference/build_time.sh [RUNS]   (default 2)
set -euo pipefail
runs=${1:-2}
repo=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d /tmp/symnlp-build-time.XXXXXX)
trap 'rm -rf "$work"' EXIT
make_crate() { # $1 = name, $2 = dependency line
  mkdir -p "$work/$1/src"
  cat > "$work/$1/Cargo.toml" <<TOML
[package]
name = "$1"
version = "0.1.0"
edition = "2021"

[dependencies]
$2

[workspace]
TOML
  cat > "$work/$1/src/main.rs" <<'RS'
use symnlp::nlp::{Ipm, Problem, Solver};
fn main() {
    let mut pb = Problem::new();
    let x = pb.variable("x", 2).unwrap();
    pb.minimize((1.0 - x[0]).sq() + 100.0 * (x[1] - x[0].sq()).sq());
    let sol = Ipm::default().solve(&mut pb.compile().unwrap()).unwrap();
    println!("{:?} {}", sol.x, sol.status);
}
RS
  cp "$repo/Cargo.lock" "$work/$1/Cargo.lock" # the workspace's versions
}
make_crate with-default "symnlp = { path = \"$repo\" }"
make_crate no-default "symnlp = { path = \"$repo\", default-features = false }"
(cd "$work/with-default" && cargo fetch -q)
(cd "$work/no-default" && cargo fetch -q)
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores, $(cargo --version)"
printf '| run | configuration | crates | CPU user+sys (s) | wall (s) | peak RSS (MiB) |\n|---|---|---|---|---|---|\n'
for r in $(seq 1 "$runs"); do
  for c in with-default no-default; do
    target="$work/target-$c-$r"
    log="$work/time-$c-$r.txt"
    (cd "$work/$c" && CARGO_TARGET_DIR="$target" /usr/bin/time -v cargo build --release -q 2> "$log")
    "$target/release/$c" > /dev/null # it runs
    user=$(awk -F': ' '/User time/ {print $2}' "$log")
    sys=$(awk -F': ' '/System time/ {print $2}' "$log")
    wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {print $2}' "$log" | awk -F: '{ if (NF == 3) print $1*3600+$2*60+$3; else print $1*60+$2 }')
    rss=$(awk -F': ' '/Maximum resident/ {printf "%.0f", $2/1024}' "$log")
    crates=$(ls "$target/release/.fingerprint" | sed 's/-[0-9a-f]*$//' | sort -u | wc -l)
    printf '| %d | %s | %d | %.1f | %.1f | %s |\n' "$r" "$c" "$crates" "$(echo "$user + $sys" | bc)" "$wall" "$rss"
    rm -rf "$target"
  done
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
