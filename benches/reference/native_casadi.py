"""CasADi's SX virtual machine and CasADi's generated C (gcc -O3 -march=native, called in a
C loop) against symx's tape and JIT, side by side in one run, on the gap-crossing model's
grad_f, jac_g and hess_L (the functions, point and checksums of benches/symx_eval.rs's
`symx_eval_gap` group; issue 24).

For each function:
  * CasADi VM: `internal_us` as in symx_eval_gap_casadi.py (record_time's t_wall_total,
    median of calls, median of repetitions);
  * CasADi C: `Function.generate` (default options), compile time of `gcc -O3
    -march=native -c`, then a C driver calls the function 7 x K times at the same point and
    prints the median of the per-round medians (µs per call) and a checksum;
  * symx: runs `cargo bench --bench symx_eval -- native_gap` (the `native_gap` lines: JIT
    compile time, tape and JIT per-call medians) right after, and prints the ratios.

Run (takes several minutes, mostly gcc):
  cargo build --release -p gap_crossing --example export
  python3 benches/reference/native_casadi.py --export-bin target/release/examples/export
With `--problem quadrotor` (and `--stages N`, default 320) the functions are those of the
quadrotor OCP of benches/reference/ocp_chain_casadi.py (RK4 inlined), the `native_quadrotor`
group; `--export-bin` is then not needed. `--only grad_f,jac_g` limits the functions (gcc
on the inlined quadrotor's J and H takes hours). With `--problem quadrotor_calls` the same
OCP is written as a CasADi user writes it at large N: the RK4 step one `Function`, applied
to the stages by `F.map(N)` in MX (its C compiles in seconds to minutes); the symx side is
the `native_quadrotor_calls` group (one compiled step called at every stage). `--gcc-opt
-O2` changes gcc's level (recorded next to the kept object as NAME.gcc_opt).
With `--keep DIR` the C files and objects stay in DIR, and a later run with the same DIR
reuses the objects (the gcc time recorded the first time), so repeated side-by-side timings
take seconds.
"""
import argparse
import contextlib
import json
import os
import re
import subprocess
import sys
import tempfile
import threading
import time

import casadi as ca
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from eval_timing import internal_times  # noqa: E402
from symx_eval_gap_casadi import build_all  # noqa: E402

DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
typedef long long casadi_int;
int NAME(const double** arg, double** res, casadi_int* iw, double* w, int mem);
int NAME_work(casadi_int* sz_arg, casadi_int* sz_res, casadi_int* sz_iw, casadi_int* sz_w);
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
static int cmp(const void* a, const void* b) { double x = *(const double*)a, y = *(const double*)b; return (x > y) - (x < y); }
int main(int argc, char** argv) {
  /* argv: input file (all inputs' doubles stacked), input sizes..., then "--", output nnz */
  FILE* f = fopen(argv[1], "rb");
  int nin = 0; long sizes[8]; int k = 2;
  while (argv[k][0] != '-') sizes[nin++] = atol(argv[k++]);
  long nout = atol(argv[k + 1]);
  casadi_int sa, sr, si, sw; NAME_work(&sa, &sr, &si, &sw);
  /* sz_arg and sz_res entries: MX functions use those after the inputs as scratch. */
  const double** arg = calloc(sa + 1, sizeof(double*)); double** res = calloc(sr + 1, sizeof(double*));
  for (int i = 0; i < nin; i++) { double* a = malloc(8 * (sizes[i] + 1)); fread(a, 8, sizes[i], f); arg[i] = a; }
  double* out = calloc(nout + 1, 8); res[0] = out;
  casadi_int* iw = calloc(si + 1, sizeof(casadi_int)); double* w = calloc(sw + 1, 8);
  for (int i = nin; i < sa; i++) arg[i] = 0;
  for (int i = 1; i < sr; i++) res[i] = 0;
  double t0 = now(); if (NAME(arg, res, iw, w, 0)) return 1; double once = now() - t0;
  int calls = (int)(0.3 / once); if (calls < 10) calls = 10; if (calls > 300) calls = 300;
  double medians[7]; double* times = malloc(sizeof(double) * calls);
  for (int r = 0; r < 7; r++) {
    for (int c = 0; c < calls; c++) { double t = now(); NAME(arg, res, iw, w, 0); times[c] = now() - t; }
    qsort(times, calls, sizeof(double), cmp); medians[r] = times[calls / 2];
  }
  qsort(medians, 7, sizeof(double), cmp);
  double sum = 0; for (long i = 0; i < nout; i++) sum += out[i];
  printf("%.6f %.16e\n", 1e6 * medians[3], sum);
  return 0;
}
"""


def casadi_c(name, F, inputs, out_nnz, tmp, opt="-O3"):
    src = os.path.join(tmp, f"{name}.c")
    exe = os.path.join(tmp, name)
    timing = os.path.join(tmp, f"{name}.gcc_s")
    if os.path.exists(src + ".o") and os.path.exists(timing):
        # Kept from an earlier run (--keep): time it again, no gcc on the function.
        with open(timing) as fh:
            gcc_s = float(fh.read())
    else:
        cwd = os.getcwd()
        os.chdir(tmp)
        try:
            F.generate(f"{name}.c")
        finally:
            os.chdir(cwd)
        t = time.perf_counter()
        subprocess.run(["gcc", opt, "-march=native", "-c", src, "-o", src + ".o"], check=True)
        gcc_s = time.perf_counter() - t
        with open(timing, "w") as fh:
            fh.write(f"{gcc_s}")
        with open(os.path.join(tmp, f"{name}.gcc_opt"), "w") as fh:
            fh.write(opt)
    drv = os.path.join(tmp, f"{name}_main.c")
    with open(drv, "w") as fh:
        fh.write(DRIVER.replace("NAME", name))
    subprocess.run(["gcc", "-O2", drv, src + ".o", "-o", exe, "-lm"], check=True)
    data = os.path.join(tmp, f"{name}.bin")
    np.concatenate([np.atleast_1d(np.asarray(a, dtype=float)) for a in inputs]).tofile(data)
    sizes = [str(np.atleast_1d(a).size) for a in inputs]
    out = subprocess.run([exe, data, *sizes, "--", str(out_nnz)], check=True,
                         stdout=subprocess.PIPE, text=True).stdout.split()
    return gcc_s, float(out[0]), float(out[1]), os.path.getsize(src)


def derivatives(kind, w, f, g):
    """∇f, ∂g/∂w and the lower triangle of ∇²(σf + λᵀg) (σ, λ symbols of `kind`, SX or
    MX) as Functions named grad_f, jac_g, hess_L, and their expressions."""
    sigma = kind.sym("sigma")
    lam = kind.sym("lambda", g.numel())
    exprs = {"grad_f": ([w], ca.gradient(f, w)), "jac_g": ([w], ca.jacobian(g, w)),
             "hess_L": ([w, sigma, lam], ca.tril(ca.hessian(sigma * f + ca.dot(lam, g), w)[0]))}
    funcs = [ca.Function(k, v[0], [v[1]]) for k, v in exprs.items()]
    return funcs, exprs


def quadrotor(stages):
    """The quadrotor OCP's three functions, expressions and initial point (as
    `build_all` returns them for the gap model)."""
    import ocp_chain_casadi as oc
    w, f, g = oc.build(stages)
    return derivatives(ca.SX, w, f, g) + (np.array(oc.point(stages)), g.numel())


def quadrotor_calls(stages):
    """The same OCP as a CasADi user writes it for speed at large N: the RK4 step one SX
    `Function` F, applied to all stages by `F.map(N)` in an MX graph (call nodes; the
    derivative functions call F's derivatives, so the generated C holds each once and
    compiles in seconds). Same variables, constraints, objective and point as
    `quadrotor` (the symx side: testkit's `build(n, true)`, group
    `native_quadrotor_calls`)."""
    import ocp_chain_casadi as oc
    nx, nu, n = oc.NX, oc.NU, stages
    x, u = ca.SX.sym("x", nx), ca.SX.sym("u", nu)
    step = ca.Function("F", [x, u], [ca.vertcat(*oc.rk4([x[i] for i in range(nx)],
                                                         [u[i] for i in range(nu)]))])
    w = ca.MX.sym("w", n * (nx + nu) + nx)
    stages_xu = ca.reshape(w[: n * (nx + nu)], nx + nu, n)
    xs, us = stages_xu[:nx, :], stages_xu[nx:, :]
    x_all = ca.horzcat(xs, w[n * (nx + nu):])
    xr = ca.DM([1.0 if i < 3 else 0.0 for i in range(nx)])
    g = ca.vertcat(ca.vec(step.map(n)(xs, us) - x_all[:, 1:]), x_all[:, 0])
    f = ca.sumsqr(xs - ca.repmat(xr, 1, n)) + 0.1 * ca.sumsqr(us) + 10 * ca.sumsqr(x_all[:, n] - xr)
    return derivatives(ca.MX, w, f, g) + (np.array(oc.point(stages)), g.numel())


def run(d, args):
    if args.problem == "quadrotor":
        funcs, exprs, x0, m = quadrotor(args.stages)
    elif args.problem == "quadrotor_calls":
        funcs, exprs, x0, m = quadrotor_calls(args.stages)
    else:
        (x, f, g), funcs, syms, _, exprs = build_all(d)
        x0 = np.array([v["x0"] for v in d["variables"]])
        m = d["m"]
    lam0 = np.array([(i + 1) / m for i in range(m)])
    inputs = {"grad_f": [x0], "jac_g": [x0], "hess_L": [x0, 1.0, lam0]}
    rows = {}
    with (contextlib.nullcontext(args.keep) if args.keep else tempfile.TemporaryDirectory()) as tmp:
        os.makedirs(tmp, exist_ok=True)
        for name, F in zip(["grad_f", "jac_g", "hess_L"], funcs):
            if args.only and name not in args.only.split(","):
                continue
            ins = [ca.DM(a) for a in inputs[name]]
            nnz = F(*ins).nnz()
            rec = ca.Function(name + "_timed", exprs[name][0], [exprs[name][1]], {"record_time": True})
            vm, _, _ = internal_times(rec, ins, 7, 300)
            gcc_s, c_us, c_sum, size = casadi_c(name, F, inputs[name], nnz, tmp, args.gcc_opt)
            rows[name] = {"vm_us": vm * 1e6, "c_us": c_us, "gcc_s": gcc_s, "c_sum": c_sum, "c_bytes": size}
            print(f"{name:7} casadi vm {vm * 1e6:9.2f} us  C {c_us:8.2f} us  gcc {gcc_s:7.1f} s  "
                  f"({size / 1e6:.1f} MB)  sum {c_sum:.16e}", file=sys.stderr)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--export-bin", help="the gap model's export example (for --problem gap)")
    ap.add_argument("--problem", choices=["gap", "quadrotor", "quadrotor_calls"], default="gap")
    ap.add_argument("--gcc-opt", default="-O3", help="gcc's optimisation level for the generated "
                    "C (default -O3; the inlined quadrotor's J and H need hours at -O3)")
    ap.add_argument("--stages", type=int, default=320, help="stages of the quadrotor OCP")
    ap.add_argument("--only", help="comma-separated functions to measure (default: all three)")
    ap.add_argument("--no-symx", action="store_true", help="skip running the symx bench")
    ap.add_argument("--keep", metavar="DIR", help="keep the generated C and executables in DIR and "
                    "reuse them on later runs (no gcc: repeat the timings side by side)")
    args = ap.parse_args()
    if args.problem == "gap":
        if not args.export_bin:
            ap.error("--export-bin is required for --problem gap")
        d = json.loads(subprocess.run([args.export_bin], check=True, stdout=subprocess.PIPE).stdout)
    else:
        d = None
    result = {}
    sys.setrecursionlimit(1_000_000)
    threading.stack_size(512 * 1024 * 1024)
    t = threading.Thread(target=lambda: result.update(rows=run(d, args)))
    t.start()
    t.join()
    rows = result["rows"]
    if not args.no_symx:
        log = subprocess.run(["cargo", "bench", "--bench", "symx_eval", "--", f"native_{args.problem}", "--noplot",
                              "--warm-up-time", "0.1", "--measurement-time", "0.1"],
                             check=True, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True).stderr
        pat = re.compile(r"^native_\w+ (\w+)\s+instructions\s+(\d+)\s+jit compile\s+([\d.]+) ms\s+tape\s+([\d.]+) us\s+jit\s+([\d.]+) us")
        for line in log.splitlines():
            mt = pat.match(line)
            if mt and mt.group(1) in rows:
                rows[mt.group(1)].update(instructions=int(mt.group(2)), jit_ms=float(mt.group(3)),
                                         tape_us=float(mt.group(4)), jit_us=float(mt.group(5)))
        print("| function | symx tape | symx JIT | CasADi VM | CasADi C (gcc -O3 -march=native) "
              "| JIT / C | JIT compile | gcc compile |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|")
        for name, r in rows.items():
            print(f"| {name} | {r['tape_us']:.1f} µs | {r['jit_us']:.2f} µs | {r['vm_us']:.1f} µs | "
                  f"{r['c_us']:.2f} µs | {r['jit_us'] / r['c_us']:.2f} | {r['jit_ms'] / 1e3:.2f} s | "
                  f"{r['gcc_s']:.1f} s |")
    print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
