#!/bin/bash
# symx's JIT against CasADi's generated C (gcc -O3 -march=native) on grad_f, jac_g and
# hess_L, side by side in one run (issue 24):
#  1. instructions per call, counted by callgrind: CasADi's function called K times in a C
#     loop, symx's in `hot_loop` of benches/symx_eval.rs (SYMX_NATIVE_PROFILE);
#  2. wall time per call, median of medians, the two alternated ROUNDS times.
# Needs the C objects and inputs that native_casadi.py keeps:
#   python3 benches/reference/native_casadi.py --export-bin target/release/examples/export --keep DIR
#   python3 benches/reference/native_casadi.py --problem quadrotor --keep DIR2 [--only grad_f,jac_g]
# and the bench binary: cargo bench --bench symx_eval --no-run.
# Run: benches/reference/native_side_by_side.sh PROBLEM DIR [ROUNDS=3] [FUNCTIONS]
#   PROBLEM gap | quadrotor (as DIR was made); FUNCTIONS default "grad_f jac_g hess_L"
#   (those whose C is in DIR). Prints one line per function and measure.
set -euo pipefail
problem=$1
dir=$(cd "$2" && pwd)
rounds=${3:-3}
functions=${4:-"grad_f jac_g hess_L"}
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=$(ls -t "$root"/target/release/deps/symx_eval-* | grep -v '\.d$' | head -1)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# A C loop calling NAME exactly CALLS times (the region callgrind counts), and once more
# timed per call as native_casadi.py's driver does.
cat > "$work/driver.c" <<'EOF'
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
typedef long long casadi_int;
int NAME(const double** arg, double** res, casadi_int* iw, double* w, int mem);
int NAME_work(casadi_int* sz_arg, casadi_int* sz_res, casadi_int* sz_iw, casadi_int* sz_w);
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
  const double* arg[16]; double* res[16];
  for (int i = 0; i < nin; i++) { double* a = malloc(8 * (sizes[i] + 1)); if (fread(a, 8, sizes[i], f) != (size_t)sizes[i]) return 1; arg[i] = a; }
  casadi_int sa, sr, si, sw; NAME_work(&sa, &sr, &si, &sw);
  res[0] = calloc(4000000, 8);
  casadi_int* iw = calloc(si + 1, sizeof(casadi_int)); double* w = calloc(sw + 1, 8);
  for (int i = nin; i < sa; i++) arg[i] = 0;
  for (int i = 1; i < sr; i++) res[i] = 0;
  if (calls > 0) { hot_loop(arg, res, iw, w, calls); return 0; }
  double t0 = now(); NAME(arg, res, iw, w, 0); double once = now() - t0;
  int n = (int)(0.3 / once); if (n < 10) n = 10; if (n > 300) n = 300;
  double medians[7]; double* times = malloc(sizeof(double) * n);
  for (int r = 0; r < 7; r++) {
    for (int c = 0; c < n; c++) { double t = now(); NAME(arg, res, iw, w, 0); times[c] = now() - t; }
    qsort(times, n, sizeof(double), cmp); medians[r] = times[n / 2];
  }
  qsort(medians, 7, sizeof(double), cmp);
  printf("%.4f\n", 1e6 * medians[3]);
  return 0;
}
EOF

# Input sizes from the kept inputs: grad_f.bin holds x; hess_L.bin x, sigma, lambda.
n=$(( $(stat -c %s "$dir/grad_f.bin") / 8 ))
sizes() {
  case $1 in
    hess_L) echo "$n 1 $(( $(stat -c %s "$dir/hess_L.bin") / 8 - n - 1 ))" ;;
    *) echo "$n" ;;
  esac
}
count() { # command... -> instructions counted in hot_loop
  local out=$work/cg.out
  valgrind --tool=callgrind --callgrind-out-file="$out" --collect-atstart=no \
    --toggle-collect='*hot_loop*' "$@" >/dev/null 2>&1
  callgrind_annotate "$out" | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); print $1}'
}
calls=20
for name in $functions; do
  sed "s/NAME/$name/g" "$work/driver.c" > "$work/$name.c"
  gcc -O2 "$work/$name.c" "$dir/$name.c.o" -o "$work/$name" -lm
  c_ir=$(count "$work/$name" "$dir/$name.bin" $calls $(sizes $name))
  jit_ir=$(SYMX_NATIVE_PROFILE=$problem:$name:jit:$calls count "$bin")
  echo "$problem $name instructions/call: CasADi C $((c_ir / calls))  symx JIT $((jit_ir / calls))  JIT/C $(python3 -c "print(f'{$jit_ir / $c_ir:.3f}')")"
done
for name in $functions; do
  c_us=(); jit_us=()
  for _ in $(seq "$rounds"); do
    c_us+=("$("$work/$name" "$dir/$name.bin" 0 $(sizes $name))")
    jit_us+=("$(SYMX_NATIVE_PROFILE=$problem:$name:jit:1 "$bin" 2>&1 | sed -n 's/.*per-call median \([0-9.]*\) us.*/\1/p')")
  done
  python3 - "$problem" "$name" "${c_us[*]}" "${jit_us[*]}" <<'EOF'
import statistics, sys
p, name, c, j = sys.argv[1], sys.argv[2], list(map(float, sys.argv[3].split())), list(map(float, sys.argv[4].split()))
mc, mj = statistics.median(c), statistics.median(j)
print(f"{p} {name} wall us/call (median of {len(c)} alternated rounds): CasADi C {mc:.3f} {c}  symx JIT {mj:.3f} {j}  JIT/C {mj / mc:.3f}")
EOF
done
uptime
