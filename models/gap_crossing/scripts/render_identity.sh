#!/usr/bin/env bash
# Byte-identity check for refactorings of the renderers and the model builder.
#
#   render_identity.sh BIN RENDER_SWEEP OUTDIR
#   render_identity.sh --compare OUTDIR_A OUTDIR_B
#
# The first form runs the gap-crossing binary BIN on a fixed set of cases (the default
# scenario, the crawl, scenarios with other terrains, a small sweep, `guess`, and
# `render` of the solved plans), each into its own directory under OUTDIR, and redraws
# sweep heat maps from fixed files with RENDER_SWEEP (the `render_sweep` example):
#
#   cargo build --release -p gap_crossing --bin gap-crossing --example render_sweep
#   render_identity.sh target/release/gap-crossing target/release/examples/render_sweep OUT
#
# Run it with the binaries of the base branch and of the changed one, then compare the
# two trees with the second form: every file must be byte-identical except the lines
# that carry wall times (`solve_seconds`, the solver's `Time:` lines, the sweep's
# seconds) and the output paths in the logs; the solved sweep's heat map, which colours
# wall times, is skipped: the redraws from fixed inputs under sweep-fixed/ stand for it.
set -u
# A file with its wall times and its output directory's name taken out.
untimed() {
    sed -E -e "s#$1/#OUT/#g" -e '/solve_seconds|"seconds"|"wall_seconds"/d' -e '/^[Tt]ime: /d' \
        -e 's/ +[0-9.]+s$//' -e 's/[0-9.]+ s wall/T s wall/' -e 's/,[0-9]+\.[0-9]{3},/,T,/' "$2"
}
if [ "${1:-}" = "--compare" ]; then
    a=$2
    b=$3
    status=0
    while IFS= read -r f; do
        case $f in
        ./sweep/sweep.svg) continue ;;
        esac
        if ! cmp -s "$a/$f" "$b/$f"; then
            # Allowed differences: wall times and the directory names in the logs.
            if diff <(untimed "$a" "$a/$f") <(untimed "$b" "$b/$f") >/dev/null; then
                echo "same but times: $f"
            else
                echo "DIFFERENT: $f"
                status=1
            fi
        fi
    done < <(cd "$a" && find . -type f | sort)
    if [ "$(cd "$a" && find . -type f | sort)" != "$(cd "$b" && find . -type f | sort)" ]; then
        echo "DIFFERENT: the two trees hold different files"
        status=1
    fi
    [ $status = 0 ] && echo "identical (up to wall times)"
    exit $status
fi
bin=$(realpath "$1")
render_sweep=$(realpath "$2")
out=$3
here=$(cd "$(dirname "$0")/.." && pwd)
sc=$here/scenarios
rm -rf "$out"
mkdir -p "$out"
run() {
    local name=$1
    shift
    "$bin" "$@" >"$out/$name.stdout" 2>"$out/$name.stderr"
    echo "exit $?" >"$out/$name.exit"
}
run default solve --out "$out/default"
run crawl solve --gait crawl --out "$out/crawl"
run step solve --scenario "$sc/step.toml" --out "$out/step"
run stones solve --scenario "$sc/stones.toml" --out "$out/stones"
run hills solve --scenario "$sc/hills.toml" --out "$out/hills"
run guess guess --out "$out/guess"
cat >"$out/grid.toml" <<'GRID'
[base]
n_step = 60
gap = { max = 2.75 }
[axes]
gap.min = [2.55, 2.6]
gap.depth = [0.5, 1.0]
gait = ["crawl"]
GRID
run sweep sweep --grid "$out/grid.toml" --out "$out/sweep"
for case in default crawl step stones hills; do
    if [ -f "$out/$case/solution.json" ]; then
        run "render-$case" render "$out/$case/solution.json" --out "$out/render-$case"
    fi
done
# Convergence figures from made-up histories (the solves above have no restoration
# phase and only scheduled runs): restoration spans, runs whose (10) residual is
# positive, not recorded, or 0 throughout, and an empty history.
if [ -f "$out/crawl/convergence.json" ]; then
    for case in conv-mixed conv-empty; do
        mkdir -p "$out/$case"
        cp "$out/crawl/solution.json" "$out/$case/solution.json"
    done
    python3 - "$out/crawl/convergence.json" "$out" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
rows = c["iterations"]
n = len(rows)
cuts = [0, n // 3, 2 * n // 3, n - 3, n]
c["phases"] = [
    {"name": f"run {k} <&>", "status": "SolveSucceeded", "scheduled": k == 3,
     "first": cuts[k], "len": cuts[k + 1] - cuts[k], "iterations": cuts[k + 1] - cuts[k] - 1}
    for k in range(4)
]
for r in rows:
    i = r["index"]
    r["restoration"] = 10 <= i < 20 or 40 <= i < 43
    r["residual_10"] = (1e-3 / (1 + i) if i < cuts[1] else None if i < cuts[2] else 0.0)
    if i == 5:
        r["objective"] = -r["objective"]
    if i == 6:
        r["inf_pr"] = 0.0
json.dump(c, open(f"{sys.argv[2]}/conv-mixed/convergence.json", "w"))
json.dump({"version": 2, "phases": [], "iterations": []},
          open(f"{sys.argv[2]}/conv-empty/convergence.json", "w"))
PY
    for case in conv-mixed conv-empty; do
        run "render-$case" render "$out/$case/solution.json" --out "$out/render-$case"
    done
fi
# Sweep heat maps from fixed inputs: the small sweep above, and made-up outcomes on
# the 3-axis grid of scenarios/sweep-gap.toml and on a 1-axis grid (every status,
# missing objectives, a spread of times).
mkdir -p "$out/sweep-fixed"
cat >"$out/grid1.toml" <<'GRID'
[axes]
gap.min = [2.2, 2.3, 2.4, 2.5, 2.6, 2.7, 2.8, 2.9]
GRID
python3 - "$sc/sweep-gap.toml" "$out/grid1.toml" "$out/sweep-fixed" "$out/sweep/sweep.json" <<'PY'
import itertools, json, sys, tomllib
small = json.load(open(sys.argv[4]))
for p in small["points"]:
    p["seconds"] = 0.1 * (p["index"] + 1)
json.dump({"points": small["points"]}, open(f"{sys.argv[3]}/small.json", "w"))
words = ["solved", "gap_not_crossable", "goal_not_reached", "solver_failed",
         "check_failed", "invalid_scenario", "error", "panic"]
for name, path in (("three", sys.argv[1]), ("one", sys.argv[2])):
    axes = tomllib.load(open(path, "rb"))["axes"]
    flat = {}
    def walk(prefix, v):
        if isinstance(v, dict):
            for k, w in v.items():
                walk(prefix + [k], w)
        else:
            flat[".".join(prefix)] = v
    walk([], axes)
    points = []
    for i, combo in enumerate(itertools.product(*flat.values())):
        st = words[(i * 5) % len(words)] if i % 3 else "solved"
        has_plan = st in ("solved", "goal_not_reached", "check_failed", "solver_failed")
        points.append({
            "index": i, "overrides": dict(zip(flat.keys(), combo)), "status": st,
            "check_ok": st == "solved", "violations": 0 if st == "solved" else i % 4,
            "violated": [] if st == "solved" else ["(10)"] * (i % 2),
            "objective": 1.5e5 + 1000.0 * i if has_plan else None,
            "iterations": 100 + 7 * i if has_plan else None,
            "seconds": 0.05 + 0.37 * ((i * 7919) % 23) / 7.0,
            "error": None if has_plan or st == "gap_not_crossable" else f"reason {i} <&\">",
        })
    json.dump({"points": points}, open(f"{sys.argv[3]}/{name}.json", "w"))
PY
"$render_sweep" "$sc/sweep-gap.toml" "$out/sweep-fixed/three.json" "$out/sweep-fixed/three.svg"
"$render_sweep" "$out/grid1.toml" "$out/sweep-fixed/one.json" "$out/sweep-fixed/one.svg"
"$render_sweep" "$out/grid.toml" "$out/sweep-fixed/small.json" "$out/sweep-fixed/small.svg"
