"""Counts the lines of the side-by-side programs of docs/casadi.md (issue 22 item 6):
non-blank lines that are neither comments nor docstrings (Python: `#` lines and
triple-quoted blocks that start a line; Rust: `//`, `//!` and `///` lines; the Rust
after `cargo fmt`). Prints one row per pair and the ratio Rust / CasADi.

Run from the repository root: python3 benches/reference/count_lines.py"""
import sys

PAIRS = [
    ("Goddard rocket", "examples/src/goddard_rocket.rs", "python/examples/casadi/goddard_rocket.py"),
    ("hanging chain, 20 re-solves", "examples/examples/chain_sweep.rs", "benches/reference/chain_sweep_casadi.py"),
    ("cart-pole MPC loop", "examples/examples/cart_pole_mpc_loop.rs", "python/examples/casadi/cartpole_mpc.py"),
]


def python_lines(path):
    count, in_doc = 0, False
    for line in open(path, encoding="utf-8"):
        s = line.strip()
        if in_doc:
            in_doc = '"""' not in s
            continue
        if s.startswith('"""'):
            in_doc = s.count('"""') == 1
            continue
        if s and not s.startswith("#"):
            count += 1
    return count


def rust_lines(path):
    return sum(1 for line in open(path, encoding="utf-8") if (s := line.strip()) and not s.startswith("//"))


def main():
    worst = 0.0
    print("| program | symnlp (Rust) | CasADi (Python) | ratio |")
    print("|---|---|---|---|")
    for name, rust, python in PAIRS:
        r, p = rust_lines(rust), python_lines(python)
        worst = max(worst, r / p)
        print(f"| {name} | {r} | {p} | {r / p:.2f}x |")
    return 0 if worst <= 1.2 else 1


if __name__ == "__main__":
    sys.exit(main())
