#!/bin/bash
# Builds, once, everything benches/reference/native_side_by_side.sh needs (issue 24): CasADi's
# generated C for each function compiled by gcc (its compile time recorded next to the
# object as NAME.gcc_s, the level as NAME.gcc_opt), the inputs, and symx's bench binary.
#   OUT/gap              the gap-crossing model's grad_f, jac_g, hess_L (SX, gcc -O3)
#   OUT/quadrotor        the quadrotor OCP (N = 320), RK4 inlined in SX: grad_f only (gcc -O3
#                        on the inlined J's 21 MB of C did not finish in an hour; set
#                        QUADROTOR_INLINED="grad_f jac_g" and GCC_OPT=-O2 to try)
#   OUT/quadrotor_calls  the same OCP with the RK4 step one Function applied by F.map(320)
#                        in MX (the form a CasADi user writes at this size): all three
# Takes 10-20 minutes on a quiet machine, mostly gcc. Needs casadi (benches/reference/setup.sh).
# Run: bash benches/reference/native_prebuild.sh OUT
set -euo pipefail
out=$1
mkdir -p "$out"
out=$(cd "$out" && pwd)
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
cargo build --release --workspace --example export
cargo bench --workspace --bench symx_eval --no-run
py=benches/reference/native_casadi.py
inlined=${QUADROTOR_INLINED:-grad_f}
python3 $py --export-bin target/release/examples/export --keep "$out/gap" --no-symx
python3 $py --problem quadrotor --only "${inlined// /,}" --gcc-opt="${GCC_OPT:--O3}" \
  --keep "$out/quadrotor" --no-symx
python3 $py --problem quadrotor_calls --keep "$out/quadrotor_calls" --no-symx
echo "prebuilt in $out: now bash benches/reference/native_side_by_side.sh $out"
