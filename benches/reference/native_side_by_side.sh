#!/bin/bash
# symx's JIT against CasADi's generated C, side by side in one run (issue 24), on the gap
# model (grad_f, jac_g, hess_L), the quadrotor OCP at N = 320 with the RK4 step inlined
# (grad_f: gcc does not finish the inlined J and H) and the same OCP with the step called
# (CasADi: F.map(320) in MX; symx: one compiled step called at every stage), from the
# artefacts benches/reference/native_prebuild.sh OUT built once:
#  1. wall time per call: every round runs, for each function in turn, CasADi's C (a C loop
#     timing single calls, 7 x up to 300: median of medians) and then symx's JIT (the same
#     statistic, `per_call` of benches/symx_eval.rs under SYMX_NATIVE_PROFILE); the table
#     gives the medians over ROUNDS rounds and their ratio;
#  2. compile time: the JIT's (median over the rounds; each round compiles afresh) against
#     gcc's (recorded once by native_prebuild.sh), with the functions' sizes;
#  3. with COUNT=1, instructions per call counted by callgrind (exact whatever the load):
#     the C function called 20 times in `hot_loop`, the JIT's `hot_loop` of symx_eval.rs,
#     instrumented only after the JIT compile (SYMX_NATIVE_PAUSE).
# Run: bash benches/reference/native_side_by_side.sh OUT [ROUNDS=5]   (≈ 3 minutes, 5 rounds)
#      COUNT=1 bash benches/reference/native_side_by_side.sh OUT 1    (+ callgrind, ≈ 10 min)
set -euo pipefail
out=$(cd "$1" && pwd)
rounds=${2:-5}
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=$(ls -t "$root"/target/release/deps/symx_eval-* | grep -v '\.d$' | head -1)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# A C loop calling NAME exactly CALLS times (the region callgrind counts), or (CALLS = 0)
# timing single calls as native_casadi.py's driver does; prints the median and the sum of
# the outputs.
cat > "$work/driver.c" <<'C'
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
typedef long long casadi_int;
int NAME(const double** arg, double** res, casadi_int* iw, double* w, int mem);
int NAME_work(casadi_int* sz_arg, casadi_int* sz_res, casadi_int* sz_iw, casadi_int* sz_w);
const casadi_int* NAME_sparsity_out(casadi_int i);
__attribute__((noinline)) void hot_loop(const double** arg, double** res, casadi_int* iw, double* w, int calls) {
  for (int c = 0; c < calls; c++) { NAME(arg, res, iw, w, 0); __asm__ volatile("" ::: "memory"); }
}
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
static int cmp(const void* a, const void* b) { double x = *(const double*)a, y = *(const double*)b; return (x > y) - (x < y); }
int main(int argc, char** argv) {
  /* argv: input file, calls (0: time instead), input sizes... */
  FILE* f = fopen(argv[1], "rb"); int calls = atoi(argv[2]);
  int nin = 0; long sizes[8];
  for (int k = 3; k < argc; k++) sizes[nin++] = atol(argv[k]);
  casadi_int sa, sr, si, sw; NAME_work(&sa, &sr, &si, &sw);
  /* sz_arg and sz_res entries: MX functions use those after the inputs as scratch. */
  const double** arg = calloc(sa + 1, sizeof(double*)); double** res = calloc(sr + 1, sizeof(double*));
  for (int i = 0; i < nin; i++) { double* a = malloc(8 * (sizes[i] + 1)); if (fread(a, 8, sizes[i], f) != (size_t)sizes[i]) return 1; arg[i] = a; }
  /* CasADi's compressed pattern; a dense one is written nrow, ncol, 1. */
  const casadi_int* sp = NAME_sparsity_out(0); long nnz = sp[2] == 1 ? sp[0] * sp[1] : sp[2 + sp[1]];
  res[0] = calloc(nnz + 1, 8);
  casadi_int* iw = calloc(si + 1, sizeof(casadi_int)); double* w = calloc(sw + 1, 8);
  for (int i = nin; i < sa; i++) arg[i] = 0;
  for (int i = 1; i < sr; i++) res[i] = 0;
  if (calls > 0) { hot_loop(arg, res, iw, w, calls); return 0; }
  double t0 = now(); if (NAME(arg, res, iw, w, 0)) return 1; double once = now() - t0;
  int n = (int)(0.3 / once); if (n < 10) n = 10; if (n > 300) n = 300;
  double medians[7]; double* times = malloc(sizeof(double) * n);
  for (int r = 0; r < 7; r++) {
    for (int c = 0; c < n; c++) { double t = now(); NAME(arg, res, iw, w, 0); times[c] = now() - t; }
    qsort(times, n, sizeof(double), cmp); medians[r] = times[n / 2];
  }
  qsort(medians, 7, sizeof(double), cmp);
  double sum = 0; for (long i = 0; i < nnz; i++) sum += res[0][i];
  printf("%.4f %.16e\n", 1e6 * medians[3], sum);
  return 0;
}
C

# The functions whose C was prebuilt, and their drivers.
functions=()
for problem in gap quadrotor quadrotor_calls; do
  for name in grad_f jac_g hess_L; do
    [ -f "$out/$problem/$name.c.o" ] || continue
    functions+=("$problem:$name")
    sed "s/NAME/$name/g" "$work/driver.c" > "$work/${problem}_$name.c"
    gcc -O2 "$work/${problem}_$name.c" "$out/$problem/$name.c.o" -o "$work/${problem}_$name" -lm
  done
done
# Input sizes from the kept inputs: grad_f.bin holds x; hess_L.bin x, sigma, lambda.
sizes() { # problem name
  local n=$(( $(stat -c %s "$out/$1/grad_f.bin") / 8 ))
  case $2 in
    hess_L) echo "$n 1 $(( $(stat -c %s "$out/$1/hess_L.bin") / 8 - n - 1 ))" ;;
    *) echo "$n" ;;
  esac
}

results=$work/results
for round in $(seq "$rounds"); do
  for pf in "${functions[@]}"; do
    problem=${pf%%:*}; name=${pf#*:}
    read -r c_us c_sum < <("$work/${problem}_$name" "$out/$problem/$name.bin" 0 $(sizes $problem $name))
    log=$(SYMX_NATIVE_PROFILE=$problem:$name:jit:1 "$bin" 2>&1)
    instructions=$(sed -n 's/.*: \([0-9]*\) instructions, jit compile.*/\1/p' <<<"$log")
    jit_ms=$(sed -n 's/.*jit compile \([0-9.]*\) ms.*/\1/p' <<<"$log")
    jit_us=$(sed -n 's/.*per-call median \([0-9.]*\) us.*/\1/p' <<<"$log")
    jit_sum=$(sed -n 's/.*sum \([-0-9.e]*\), per-call.*/\1/p' <<<"$log")
    gcc_s=$(cat "$out/$problem/$name.gcc_s")
    gcc_opt=$(cat "$out/$problem/$name.gcc_opt" 2>/dev/null || echo -O3)
    echo "$problem $name $round $c_us $jit_us $jit_ms $gcc_s $gcc_opt $instructions $c_sum $jit_sum" >> "$results"
  done
done

count() { # output-file command... -> instructions counted in hot_loop
  valgrind --tool=callgrind --callgrind-out-file="$1" --collect-atstart=no \
    --toggle-collect='*hot_loop*' "${@:2}" >/dev/null 2>&1
  callgrind_annotate "$1" | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); print $1}'
}
count_jit() { # problem name calls -> instructions counted in hot_loop, instrumented after set-up
  local log=$work/cg_jit.log
  SYMX_NATIVE_PAUSE=5 SYMX_NATIVE_PROFILE=$1:$2:jit:$3 valgrind --tool=callgrind \
    --callgrind-out-file="$work/cg_jit.out" --instr-atstart=no --collect-atstart=no \
    --toggle-collect='*hot_loop*' "$bin" >"$log" 2>&1 &
  local pid=$!
  until grep -q ready "$log" 2>/dev/null || ! kill -0 $pid 2>/dev/null; do sleep 1; done
  callgrind_control -i on $pid >/dev/null 2>&1 || true
  wait $pid
  callgrind_annotate "$work/cg_jit.out" | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); print $1}'
}
if [ "${COUNT:-0}" = 1 ]; then
  calls=20
  for pf in "${functions[@]}"; do
    problem=${pf%%:*}; name=${pf#*:}
    c_ir=$(count "$work/cg_c.out" "$work/${problem}_$name" "$out/$problem/$name.bin" $calls $(sizes $problem $name))
    jit_ir=$(count_jit $problem $name $calls)
    echo "$problem $name $((c_ir / calls)) $((jit_ir / calls))" >> "$work/counts"
  done
fi

python3 - "$results" "$work/counts" <<'PY'
import collections, os, statistics, sys
rows = collections.OrderedDict()
for line in open(sys.argv[1]):
    p, f, _, c_us, j_us, j_ms, gcc_s, opt, n, c_sum, j_sum = line.split()
    r = rows.setdefault((p, f), {"c": [], "j": [], "ms": [], "gcc": float(gcc_s), "opt": opt, "n": int(n),
                                 "sums": (float(c_sum), float(j_sum))})
    r["c"].append(float(c_us)); r["j"].append(float(j_us)); r["ms"].append(float(j_ms))
counts = {}
if os.path.exists(sys.argv[2]):
    for line in open(sys.argv[2]):
        p, f, c, j = line.split()
        counts[(p, f)] = (int(c), int(j))
med = statistics.median
print(f"Wall time per call, median of {len(next(iter(rows.values()))['c'])} interleaved rounds "
      "(each: median of 7 medians of single calls)")
print("| problem | function | CasADi C µs | JIT µs | JIT / C | C rounds | JIT rounds | outputs' sums C / JIT (rel. diff.) |")
print("|---|---|---:|---:|---:|---|---|---|")
for (p, f), r in rows.items():
    c, j = med(r["c"]), med(r["j"])
    cs, js = r["sums"]
    rel = abs(cs - js) / max(abs(cs), 1e-300)
    print(f"| {p} | {f} | {c:.3f} | {j:.3f} | **{j / c:.2f}** | {' '.join(map(str, r['c']))} | "
          f"{' '.join(map(str, r['j']))} | {cs:.6e} / {js:.6e} ({rel:.0e}) |")
print()
print("Compile time: the JIT's (median of the rounds) against gcc's on CasADi's C (recorded once)")
print("| problem | function | tape instructions | JIT ms | JIT ms per 1000 instructions | gcc s (level) | JIT / gcc |")
print("|---|---|---:|---:|---:|---:|---:|")
for (p, f), r in rows.items():
    ms = med(r["ms"])
    print(f"| {p} | {f} | {r['n']} | {ms:.1f} | {1e3 * ms / r['n']:.2f} | {r['gcc']:.1f} ({r['opt']}) | "
          f"{ms / 1e3 / r['gcc']:.4f} |")
if counts:
    print()
    print("Instructions per call (callgrind, 20 calls in hot_loop)")
    print("| problem | function | CasADi C | JIT | JIT / C |")
    print("|---|---|---:|---:|---:|")
    for (p, f), (c, j) in counts.items():
        print(f"| {p} | {f} | {c} | {j} | **{j / c:.2f}** |")
PY
echo "load: $(uptime)"
