#!/usr/bin/env python3
"""Side by side: `gap-crossing solve` (default scenario) against `gap-crossing replan`
of its plan from stance 20 with a 2 cm CoM offset, interleaved (solve, replan, solve,
...), whole process: wall and CPU (user + sys of the child) medians, and the ratio.

usage: time_replan.py BIN [PAIRS]
"""
import json, os, resource, statistics, subprocess, sys, tempfile, time

def timed(args):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if p.returncode != 0:
        sys.exit(f"{args}: exit {p.returncode}: {p.stderr.decode()}")
    return wall, cpu

def main():
    bin_, pairs = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 5
    d = tempfile.mkdtemp()
    solve = [bin_, "solve", "--out", f"{d}/full", "--opt", "print_level=0"]
    replan = [bin_, "replan", "--plan", f"{d}/full/solution.json", "--stance", "20",
              "--com-offset", "0.02,0,0", "--out", f"{d}/re", "--opt", "print_level=0"]
    timed(solve)
    rows = {"solve": [], "replan": []}
    for _ in range(pairs):
        rows["solve"].append(timed(solve))
        rows["replan"].append(timed(replan))
    full = json.load(open(f"{d}/full/solution.json"))["solver"]
    re = json.load(open(f"{d}/re/solution.json"))["solver"]
    print(f"load average before/after: {os.getloadavg()}")
    med = {k: (statistics.median(w for w, _ in v), statistics.median(c for _, c in v))
           for k, v in rows.items()}
    for k, (w, c) in med.items():
        print(f"{k:7} median wall {w:.3f} s, CPU {c:.3f} s over {pairs} runs")
    print(f"replan/solve: wall {med['replan'][0] / med['solve'][0]:.3f}, "
          f"CPU {med['replan'][1] / med['solve'][1]:.3f}")
    print(f"solve: {full['status']} {full['objective']:.6e}, {full['iterations']} iterations; "
          f"replan: {re['status']} {re['objective']:.6e}, {re['iterations']} iterations")

main()
