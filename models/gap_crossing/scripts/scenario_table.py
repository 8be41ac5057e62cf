#!/usr/bin/env python3
"""Objective, status, wall and CPU time of the planner on the test scenarios, for one or
more binaries side by side.

The scenarios: the default, the 12 of `tests/gap_crossing.rs` (free gait) and the
crossable family of `models/gap_crossing/tests/crossing.rs` (each with its own gait).
Each scenario is run `--repeat` times per binary, the binaries alternated within each
repetition (so that a change of load hits both alike); the table gives the objective and
status of the first run and the medians of wall and CPU (user + system of the child
process) time.

    python3 models/gap_crossing/scripts/scenario_table.py \
        --bin new=target/release/gap-crossing --bin old=/path/to/old/gap-crossing \
        --repeat 3 [--only default] [--json out.jsonl]

A binary that cannot read a scenario (an older one, for terrain files) shows `error`.
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SCENARIOS = os.path.join(HERE, "..", "scenarios")


def gap(name, lo, width, dy, gait, more=()):
    """The family's `gap(min, width, dy, gait, more)` of tests/crossing.rs as CLI flags."""
    hi = lo + width - 2 * 0.03
    y = 0.5 + dy
    args = [
        f"gap.min={lo}",
        f"gap.max={hi!r}",
        f"goal.B=[3.0, {y}, 0.5]",
        f"goal.F=[5.0, {y}, 0.5]",
        *more,
    ]
    flags = [a for kv in args for a in ("--set", kv)]
    return name, flags + ["--gait", gait]


def sets(name, *kv):
    return name, [a for x in kv for a in ("--set", x)] + ["--gait", "free"]


def file(name, path, gait):
    return name, ["--scenario", os.path.join(SCENARIOS, path), "--gait", gait]


def cases():
    twelve = [
        sets("default"),
        sets("gap at 1.2-1.3", "gap.min=1.2", "gap.max=1.3"),
        sets("gap at 3.5-3.6", "gap.min=3.5", "gap.max=3.6"),
        sets("width 0.05", "gap.min=2.25", "gap.max=2.30"),
        sets("width 0.2", "gap.min=2.2", "gap.max=2.4"),
        sets("width 0.25, margin 0.005", "gap.min=2.5", "gap.max=2.75", "gap.margin=0.005"),
        sets("depth 0.5", "gap.depth=0.5"),
        sets("depth 3 at 2.5-2.6", "gap.depth=3", "gap.min=2.5", "gap.max=2.6"),
        sets("goal y + 0.3", "goal.B=[3.0, 0.8, 0.5]", "goal.F=[5.0, 0.8, 0.5]"),
        sets(
            "goal y - 0.4, width 0.15, depth 2",
            "goal.B=[3.0, 0.1, 0.5]",
            "goal.F=[5.0, 0.1, 0.5]",
            "gap.min=2.5",
            "gap.max=2.65",
            "gap.depth=2",
        ),
        sets("n_step 30", "n_step=30"),
        sets("n_step 120", "n_step=120"),
        sets(
            "step terrain",
            'terrain={kind="step", edge=2.3, rise=0.1, steepness=1e6, margin=0.04}',
            "goal.B=[3.0, 0.5, 0.6]",
            "goal.F=[5.0, 0.5, 0.6]",
        ),
    ]
    family = [
        gap("family: w 0.270, lateral +1.5", 2.25, 0.27, 1.5, "free"),
        gap("family: w 0.280", 2.25, 0.28, 0.0, "crawl"),
        gap("family: w 0.290, lateral -1.5", 2.25, 0.29, -1.5, "crawl"),
        gap("family: w 0.295, lateral +0.5", 2.25, 0.295, 0.5, "free"),
        gap("family: w 0.299", 2.25, 0.299, 0.0, "free"),
        gap("family: w 0.299, lateral +1.5", 2.25, 0.299, 1.5, "crawl"),
        gap("family: w 0.299 at 2.6", 2.6, 0.299, 0.0, "free"),
        gap("family: w 0.285 at 1.2, lateral -1.5", 1.2, 0.285, -1.5, "free"),
        gap("family: w 0.270, 45°", 2.25, 0.27, 3.0, "crawl", ["n_step=90"]),
        gap("family: w 0.299, 45°", 2.25, 0.299, 3.0, "crawl", ["n_step=90"]),
        file("family: step.toml", "step.toml", "crawl"),
        file("family: gaps.toml", "gaps.toml", "free"),
        file("family: stones.toml", "stones.toml", "crawl"),
        file("family: hills.toml", "hills.toml", "crawl"),
        # The family's free-gait twins (the family runs these with the crawl gait).
        file("family (free): step.toml", "step.toml", "free"),
        file("family (free): stones.toml", "stones.toml", "free"),
        file("family (free): hills.toml", "hills.toml", "free"),
        gap("family (free): w 0.270, 45°", 2.25, 0.27, 3.0, "free", ["n_step=90"]),
    ]
    return twelve + family


def run(binary, flags):
    out = tempfile.mkdtemp(prefix="gap-table-")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(
        [binary, "solve", "--out", out, "--opt", "print_level=0", *flags],
        capture_output=True,
        text=True,
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    try:
        with open(os.path.join(out, "solution.json")) as f:
            solver = json.load(f)["solver"]
        return solver["status"], solver["objective"], wall, cpu
    except (OSError, KeyError, ValueError):
        return "error", float("nan"), wall, cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", action="append", required=True, help="NAME=PATH")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", action="append", help="scenario names (substring)")
    ap.add_argument("--json", help="append one JSON line per scenario and binary")
    a = ap.parse_args()
    bins = [b.split("=", 1) for b in a.bin]
    todo = [c for c in cases() if not a.only or any(o in c[0] for o in a.only)]
    print(f"load average at start: {os.getloadavg()}", file=sys.stderr)
    print("| scenario | binary | status | objective | wall (median) | CPU (median) |")
    print("|---|---|---|---:|---:|---:|")
    for name, flags in todo:
        got = {n: [] for n, _ in bins}
        for _ in range(a.repeat):
            for n, path in bins:
                got[n].append(run(path, flags))
        for n, _ in bins:
            runs = got[n]
            status, objective = runs[0][0], runs[0][1]
            wall = statistics.median(r[2] for r in runs)
            cpu = statistics.median(r[3] for r in runs)
            print(
                f"| {name} | {n} | {status} | {objective:.6e} | {wall:.2f} s | {cpu:.2f} s |",
                flush=True,
            )
            if a.json:
                with open(a.json, "a") as f:
                    row = dict(scenario=name, binary=n, status=status, objective=objective)
                    row.update(wall=[r[2] for r in runs], cpu=[r[3] for r in runs])
                    row.update(load=os.getloadavg()[0])
                    f.write(json.dumps(row) + "\n")
    print(f"load average at end: {os.getloadavg()}", file=sys.stderr)


if __name__ == "__main__":
    main()
