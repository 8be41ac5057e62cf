"""Estimates of a lower bound on the cost (1) of the default scenario that keep the
bipeds coupled (balance (2), friction (4), distances (6)-(9)) and share footholds over
windows of W consecutive stances (indicative, not certified: every small problem is
solved by IPOPT from a few starting points, a local method).

Relaxation (each step can only lower the optimum):
- a plan is a path of move counts (c_BR, c_BL, c_FR, c_FL) through the 4-D lattice, one
  count up by one per transition (10); a foot that has made m moves stands within
  0.3 m times m of its start horizontally, at x <= reach(x0, m) (the default keep-out
  (2.22, 2.38) cannot be stood in), on the ground z = 0 (the real ground is within
  1e-5 m of it outside the keep-out); a foot with no move is at its start; counts stop
  at 15 (a stance there costs within 0.5 of its floor (Mg)^2/4 w_F);
- the cost of stances 2..60 is split over windows of W consecutive stances,
  sum_k c_k = sum_windows (1/W) sum_{k in window} c_k + (boundary stances, covered by
  fewer than W windows, bounded by their single-stance relaxation); in a window the
  footholds are shared exactly (the three feet that do not move keep their positions,
  the moving one steps <= 0.3 m), the stances are otherwise independent of the rest of
  the plan (each window chooses its footholds afresh);
- each stance has the full stance equations: CoMs at leg length (11), feet 0.5-1.5 m
  (8), (9) and 1-3 m (6), (7) apart, force and moment balance (2) about the whole-body
  CoM, friction cones with F_z >= 10 N and mu = 0.5 (4) about the vertical, cost (1);
- the cheapest path is found by a lazy shortest path (unsolved windows bounded by the
  decoupled tables of two_foot_bound.py plus (Mg)^2/4 per stance, refined until the
  path runs through solved windows only; a window IPOPT cannot solve keeps its bound).
W = 1 lets every stance choose its four feet afresh; W = 2, 3 share them between 2, 3
consecutive stances. Results (2026-11-26, docs/performance.md, "Free gait: how far is
1.69e5"): W = 1 1.685518e5, W = 2 1.689763e5, W = 3 1.692479e5; the plan 1.706639e5.
Usage (needs casadi): python3 window_bound.py W [--cache FILE] [--plan solution.json]
  --cache FILE: keep the single-stance solutions in FILE (pickle) and reuse them;
  --plan FILE: instead of the search, where that plan's cost goes and the relaxation
    on its own move counts.
W = 1 takes ~3 min of CPU; W = 3 took 63 min wall (35 rounds, 725 stances and windows) on a shared
machine with the cache of W = 1.
global_bound.py turns these estimates into a certified bound (a global solver).
"""
import itertools
import json
import math
import os
import pickle
import sys

import casadi as ca

from lower_bound import reach
from two_foot_bound import biped_table

MAXM = 15
N_STEP = 60
MG = 100 * 9.81
FMIN = 0.001 * MG ** 2 / 4
START = {"BR": (0.0, 0.0), "BL": (0.0, 1.0), "FR": (2.0, 0.0), "FL": (2.0, 1.0)}
FEET = ["BR", "BL", "FR", "FL"]
GB, GF = [3.0, 0.5, 0.5], [5.0, 0.5, 0.5]
IPOPT = {"ipopt.print_level": 0, "print_time": 0, "ipopt.sb": "yes", "ipopt.max_iter": 500}


def succ(s, j):
    t = list(s)
    t[j] = min(t[j] + 1, MAXM)
    return tuple(t)


def stances_of(s, moves):
    seq = [s]
    for j in moves:
        seq.append(succ(seq[-1], j))
    return seq


def stance(p, cb, cf, F, par):
    """Constraints and cost (1) of one stance; p: the four feet, par: radii, x caps."""
    g, lb, ub = [], [], []
    for i, com in [(0, cb), (1, cb), (2, cf), (3, cf)]:
        g.append(ca.sumsqr(com - p[i]) - 0.5); lb.append(0); ub.append(0)
    for a, b, lo, hi in [(0, 1, 0.25, 2.25), (2, 3, 0.25, 2.25), (0, 2, 1, 9), (1, 3, 1, 9)]:
        g.append(ca.sumsqr(p[a] - p[b])); lb.append(lo); ub.append(hi)
    for i, n in enumerate(FEET):
        s = START[n]
        g.append((p[i][0] - s[0]) ** 2 + (p[i][1] - s[1]) ** 2 - par[i] ** 2)
        lb.append(-ca.inf); ub.append(0)
        g.append(p[i][0] - par[4 + i]); lb.append(-ca.inf); ub.append(0)
    fs = [F[3 * i:3 * i + 3] for i in range(4)]
    g.append(fs[0] + fs[1] + fs[2] + fs[3] + ca.vertcat(0, 0, -MG)); lb += [0] * 3; ub += [0] * 3
    rw = (cb + cf) / 2
    g.append(sum((ca.cross(p[i] - rw, fs[i]) for i in range(4)), ca.MX.zeros(3)))
    lb += [0] * 3; ub += [0] * 3
    for f in fs:
        g.append(f[2]); lb.append(10); ub.append(ca.inf)
        g.append(f[0] ** 2 + f[1] ** 2 - 0.25 * f[2] ** 2); lb.append(-ca.inf); ub.append(0)
    cost = 1000 * (ca.sumsqr(cb - ca.DM(GB)) + ca.sumsqr(cf - ca.DM(GF))) + 0.001 * ca.sumsqr(F)
    return g, lb, ub, cost


SOLVERS = {}


def solver(moves):
    """x = first stance's feet (8), each move's new foothold (2), per stance CoMs, forces."""
    if moves not in SOLVERS:
        nm = len(moves)
        x = ca.MX.sym("x", 8 + 2 * nm + 18 * (nm + 1))
        par = ca.MX.sym("par", 8 * (nm + 1))
        feet = [ca.vertcat(x[2 * i], x[2 * i + 1], 0) for i in range(4)]
        g, lb, ub, cost, o = [], [], [], 0, 8 + 2 * nm
        for k in range(nm + 1):
            if k > 0:
                j = moves[k - 1]
                q = ca.vertcat(x[8 + 2 * (k - 1)], x[9 + 2 * (k - 1)], 0)
                g.append(ca.sumsqr(q - feet[j])); lb.append(0); ub.append(0.09)
                feet = feet[:j] + [q] + feet[j + 1:]
            gs, ls, us, cs = stance(feet, x[o:o + 3], x[o + 3:o + 6], x[o + 6:o + 18],
                                    par[8 * k:8 * k + 8])
            g += gs; lb += ls; ub += us; cost = cost + cs; o += 18
        nlp = {"x": x, "f": cost / (nm + 1), "g": ca.vertcat(*g), "p": par}
        SOLVERS[moves] = (ca.nlpsol("W", "ipopt", nlp, IPOPT), lb, ub)
    return SOLVERS[moves]


def node_guesses(counts):
    """Starting points of a single stance: walking guesses and a standing one."""
    out = []
    for lean, narrow in [(0.55, 0.2), (0.45, 0.0), (0.6, 0.3)]:
        p = []
        for i, n in enumerate(FEET):
            s = START[n]
            x = min(s[0] + 0.3 * counts[i] * 0.97, reach(s[0], counts[i]))
            p += [x, s[1] + (narrow if s[1] < 0.5 else -narrow) * min(1, counts[i])]
        coms = [(p[0] + p[2]) / 2 + lean, 0.5, 0.25, (p[4] + p[6]) / 2 + lean, 0.5, 0.25]
        out.append(p + coms + [0, 0, MG / 4] * 4)
    p = []
    for i, n in enumerate(FEET):
        p += [START[n][0] + (min(0.1, 0.3 * counts[i]) if counts[i] else 0), START[n][1]]
    coms = []
    for a, b in ((0, 1), (2, 3)):
        w2 = (p[2 * a] - p[2 * b]) ** 2 + (p[2 * a + 1] - p[2 * b + 1]) ** 2
        coms += [(p[2 * a] + p[2 * b]) / 2, (p[2 * a + 1] + p[2 * b + 1]) / 2,
                 math.sqrt(max(0.5 - w2 / 4, 0.01))]
    out.append(p + coms + [0, 0, MG / 4] * 4)
    return out


def solve(s, moves, nodes, starts=None):
    """Least mean cost of the window (s, moves); single stances from node_guesses, windows
    from their stances' single-stance solutions."""
    S, lb, ub = solver(moves)
    seq = stances_of(s, moves)
    par = []
    for t in seq:
        par += [0.3 * k if k else 1.0 for k in t] + [reach(START[n][0], k) for n, k in zip(FEET, t)]
    n = 8 + 2 * len(moves) + 18 * len(seq)
    lbx, ubx = [-ca.inf] * n, [ca.inf] * n
    for i, name in enumerate(FEET):  # a foot that has not moved stands at its start
        if s[i] == 0:
            lbx[2 * i] = ubx[2 * i] = START[name][0]
            lbx[2 * i + 1] = ubx[2 * i + 1] = START[name][1]
    if starts is not None:
        pass
    elif not moves:
        starts = node_guesses(s)
    else:
        xs = [nodes[(t, ())][1] for t in seq]
        if any(x is None for x in xs):
            return math.inf, None
        starts = []
        for b in (0, len(seq) - 1):
            x0 = list(xs[b][:8])
            for j in set(moves):
                x0[2 * j:2 * j + 2] = xs[0][2 * j:2 * j + 2]
            for k, j in enumerate(moves):
                x0 += list(xs[k + 1][2 * j:2 * j + 2])
            for x in xs:
                x0 += list(x[8:26])
            starts.append(x0)
    best, bx = math.inf, None
    for x0 in starts:
        r = S(x0=x0, p=par, lbg=lb, ubg=ub, lbx=lbx, ubx=ubx)
        if S.stats()["success"] and float(r["f"]) < best:
            best, bx = float(r["f"]), [float(v) for v in r["x"].full().ravel()]
    return best, bx


def shortest(w, value):
    """Cheapest path of windows; value(s, moves) is a window's (or stance's) mean cost.
    Returns (total cost, the path's windows)."""
    n_win = N_STEP - 1 - w + 1
    layer = {}
    for first in range(4):
        for ms in itertools.product(range(4), repeat=w - 1):
            s2 = succ((0, 0, 0, 0), first)
            seq = stances_of(s2, ms)
            head = sum((1 - (i + 1) / w) * value(t, ()) for i, t in enumerate(seq[:-1]))
            layer[(s2, ms)] = (head + value(s2, ms), None)
    hist = [layer]
    for _ in range(n_win - 1):
        nxt = {}
        for (s, ms), (v, _) in layer.items():
            for j in range(4):
                full = ms + (j,)
                st = (succ(s, full[0]), full[1:])
                cost = v + value(*st)
                if cost < nxt.get(st, (math.inf,))[0]:
                    nxt[st] = (cost, (s, ms))
        hist.append(nxt)
        layer = nxt

    def tail(st):
        seq = stances_of(*st)[1:]
        return sum((1 - (len(seq) - i) / w) * value(t, ()) for i, t in enumerate(seq))

    end = min(layer, key=lambda st: layer[st][0] + tail(st))
    path, st = [end], end
    for k in range(len(hist) - 1, 0, -1):
        st = hist[k][st][1]
        path.append(st)
    path.reverse()
    return 18000 + FMIN + layer[end][0] + tail(end), path


def plan_path(file):
    """A solution file's stances 2..60 as a lattice path: the move counts of each stance,
    the foot moved at each transition (one that moves no foot counts as a move of BR,
    so that the path goes one count up per transition, as in the search; the counts stop
    at MAXM) and each stance's variables (feet x, y; CoMs; forces) in the order of
    solve()'s single-stance x."""
    stances = json.load(open(file))["stances"]
    counts, path, moved, xs = [0, 0, 0, 0], [], [], []
    for prev, st in zip(stances, stances[1:]):
        j = next((i for i, n in enumerate(FEET)
                  if math.dist(prev["feet"][n], st["feet"][n]) > 1e-6), 0)
        counts[j] = min(counts[j] + 1, MAXM)
        path.append(tuple(counts))
        moved.append(j)
        xs.append(sum((st["feet"][n][:2] for n in FEET), []) + st["com"]["B"] + st["com"]["F"]
                  + sum((st["forces"][n] for n in FEET), []))
    return path, moved, xs


def nearest_com(p1, p2, goal):
    """The point at leg length sqrt(0.5) from both feet nearest the goal (a circle)."""
    mid = [(a + b) / 2 for a, b in zip(p1, p2)]
    u = [b - a for a, b in zip(p1, p2)]
    length = math.hypot(*u)
    u = [v / length for v in u]
    rho = math.sqrt(max(0.5 - length ** 2 / 4, 0.0))
    d = [g - m for g, m in zip(goal, mid)]
    along = sum(a * b for a, b in zip(d, u))
    v = [a - along * b for a, b in zip(d, u)]
    nv = math.hypot(*v)
    return [m + rho * a / nv for m, a in zip(mid, v)]


def plan_costs(file):
    """Where a plan's cost (1) goes: CoM part, forces at equal shares and above them,
    and the CoM part if every CoM stood at the best point its two feet allow."""
    stances = json.load(open(file))["stances"]
    com = best = force = 0.0
    for st in stances[1:]:
        for j, goal, (a, b) in (("B", GB, ("BR", "BL")), ("F", GF, ("FR", "FL"))):
            com += 1000 * math.dist(st["com"][j], goal) ** 2
            best += 1000 * math.dist(nearest_com(st["feet"][a], st["feet"][b], goal), goal) ** 2
        force += 0.001 * sum(sum(f * f for f in st["forces"][n]) for n in FEET)
    n = len(stances) - 1
    print(f"stances 2..{n + 1}: CoM part {com:.1f} (at the best points of the plan's feet "
          f"{best:.1f}), forces {force:.1f} = {n} x (Mg)^2/4 w_F {n * FMIN:.1f} "
          f"+ {force - n * FMIN:.1f}")


def check_plan(w, file):
    """The relaxation along a plan's own count path, each window solved from its stances'
    single-stance solutions (as in the search) and also from the plan's own variables:
    prints the plan's cost, the relaxation's, and in how many windows the plan's point
    found a lower minimum than the search's starts (a check of the local solves)."""
    path, moved, xs = plan_path(file)
    nodes = {}
    for t in set(path):
        nodes[(t, ())] = solve(t, (), nodes)
    n = len(path)
    total, lower, failed = 18000 + FMIN, 0, 0
    for i in range(n):  # boundary stances, covered by fewer than w windows
        total += (1 - min(i + 1, w, n - i) / w) * nodes[(path[i], ())][0]
    for k in range(n - w + 1):
        seq, moves = path[k:k + w], tuple(moved[k + 1:k + w])
        x0 = list(xs[k][:8])
        for i, j in enumerate(moves):
            x0 += xs[k + i + 1][2 * j:2 * j + 2]
        for x in xs[k:k + w]:
            x0 += x[8:26]
        v = solve(seq[0], moves, nodes)[0] if moves else nodes[(seq[0], ())][0]
        vp = solve(seq[0], moves, nodes, starts=[x0])[0]
        if vp < v - 1e-6 * max(1.0, abs(v)):
            lower += 1
            v = vp
        if math.isinf(v):  # no start solved it: the mean of its stances bounds it
            failed += 1
            v = sum(nodes[(t, ())][0] for t in seq) / w
        total += v
    print(f"W = {w} on the plan's own counts: relaxation {total:.6e}; the plan's own "
          f"point found a lower minimum in {lower} of {n - w + 1} windows; "
          f"{failed} not solved (bounded by their stances)")


def main():
    args = sys.argv[1:]
    w = int(args[0]) if args else 1
    opts = dict(zip(args[1::2], args[2::2]))
    if "--plan" in opts:
        plan_costs(opts["--plan"])
        check_plan(w, opts["--plan"])
        return
    cache = opts.get("--cache")  # single-stance solutions, shared between runs of any W
    back = biped_table([0.0, 0.0], [0.0, 1.0], GB)
    front = biped_table([2.0, 0.0], [2.0, 1.0], GF)
    solved = {}
    if cache and os.path.exists(cache):
        with open(cache, "rb") as f:
            solved.update(pickle.load(f))

    def bound(s, ms):
        if (s, ms) in solved:
            return solved[(s, ms)][0]
        seq = stances_of(s, ms)
        return sum(solved[(t, ())][0] if (t, ()) in solved
                   else back[t[:2]] + front[t[2:]] + FMIN for t in seq) / len(seq)

    def settle(key):
        """Solve a window or stance; where IPOPT fails, keep the lower bound (stays valid)."""
        lower = bound(*key)
        value = solve(key[0], key[1], solved)
        if value[1] is None:
            print(f"  no solution for {key}: its bound {lower:.1f} kept", flush=True)
            value = (lower, None)
        solved[key] = value

    rnd = 0
    while True:
        rnd += 1
        total, path = shortest(w, bound)
        stances = {t for s, ms in path for t in stances_of(s, ms)}
        todo_n = [t for t in stances if (t, ()) not in solved]
        todo_w = [k for k in path if k not in solved and k[1]]
        print(f"round {rnd}: {total:.6e}, new stances {len(todo_n)}, new windows "
              f"{len(todo_w)}, solved {len(solved)}", flush=True)
        if not todo_n and not todo_w:
            break
        for t in todo_n:
            settle((t, ()))
        if todo_n:
            if cache:
                with open(cache, "wb") as f:
                    pickle.dump({k: v for k, v in solved.items() if not k[1]}, f)
            continue  # re-route on the stances first: cheap
        for k in todo_w:
            settle(k)
    for k, (s, ms) in enumerate(path):
        print(k + 2, s, [FEET[j] for j in ms], round(solved[(s, ms)][0]))
    print(f"W = {w}: estimate {total:.6e} (the plan: 1.706639e5)")


if __name__ == "__main__":
    main()
