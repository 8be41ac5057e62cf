"""A certified lower bound on the cost (1) of any plan of the default scenario: the
relaxation of window_bound.py (footholds shared over windows of W stances, every
schedule, move count and crossing move), with every small problem bounded by a global
solver (SCIP's spatial branch and bound: its dual bound is a valid lower bound whether
or not it closes the gap), so that the result is a bound, not an estimate.

Differences from window_bound.py, each keeping the relaxation valid:
- forces: on the ground z = 0 the moment balance (2) about the whole-body CoM r_W says
  exactly that r_W's horizontal position is the force-weighted mean of the feet,
  sum_i lambda_i p_i with lambda_i = F_z,i / (M g) (the horizontal forces drop out
  because they sum to zero); horizontal forces only add cost, so the least force cost
  of a stance is w_F (M g)^2 sum_i lambda_i^2 with lambda_i >= F_thr / (M g) and
  sum_i lambda_i = 1: the same stance problem with 4 force variables instead of 12;
- a foot whose count reached the lattice's cap (MAXM moves) may have made any number
  up to 59, so its disc and x cap are those of 59 moves (window_bound.py uses MAXM's);
- a stance or window the solver does not solve to the gap keeps SCIP's dual bound, and
  the decoupled two-feet tables that bound unsolved stances are SCIP dual bounds too;
- the real terrain, not z = 0: outside the keep-out the ground is within 1e-5 m of
  z = 0 (8.2e-6 at the keep-out's edges) and its normals within 4e-4 rad of vertical,
  so legs (11) hold to LEG_TOL, the force-weighted mean of the feet matches r_W to
  COP_TOL, F_z >= 9.9 N, and distances, steps, discs and x caps get 1e-6 (these
  margins also absorb residuals of 1e-6 in those equations; with all of them 0, W = 1
  gives 1.685393e5 instead of 1.685358e5).
What it bounds: every plan whose equations (2)-(11) hold exactly on the real terrain,
so the optimum of the model. Not quite every plan the checker accepts: the checker lets
a foot that does not move drift by 1e-6 m per transition, which the windows do not
(its effect on the bound is of order 1, far below the margins reported).
The search is window_bound.py's lazy shortest path over the 4-D lattice of move counts.
Usage (needs pyscipopt: pip install -r requirements.txt): python3 global_bound.py W
[--cache FILE] [--jobs N] [--target T]; --cache keeps every bound (pickle) so that an
interrupted run resumes; --jobs solves N problems at once; --target stops as soon as
the cheapest path's bound reaches T (every plan then costs at least T); --plan FILE
instead checks the models and the cached bounds on a solution file (see check_plan).
Result (2026-11-26): W = 1 1.685358e5; W = 3 with --target 1.69e5 1.690342e5, so every
plan costs more than 1.69e5 (docs/performance.md, "Free gait: 1.69e5 is below a
certified lower bound").
"""
import hashlib
import inspect
import json
import math
import multiprocessing
import os
import pickle
import sys
import time

from pyscipopt import Model, quicksum

from lower_bound import reach
from window_bound import FEET, FMIN, GB, GF, MAXM, MG, START, plan_path, shortest, stances_of

HORIZON = 59  # transitions of the default scenario: at most 59 moves of any foot
LAMBDA_MIN = 9.9 / MG  # F_thr / (M g), less the tilt of the normals and residuals
COP_TOL = 1e-5  # m: moment of the horizontal forces at feet 1e-5 m below z = 0
TOL = 1e-6  # the checker's residual on distances and the keep-out
MOVE_SLACK = 2e-6  # m per move: a step with |d|^2 <= 0.09 + TOL is <= 0.3 + 1.7e-6 m
LEG_TOL = 2e-5  # |leg^2 - 0.5|: the ground's 1e-5 m below z = 0, and residuals of 1e-6
LEG = math.sqrt(0.5 + LEG_TOL)  # the longest leg: bounds of the CoMs about their feet
STANCE_GAP, WINDOW_GAP = 1e-4, 1e-3  # relative gaps at which SCIP may stop
WINDOW_ABS_GAP = 2.0  # or absolute, on a window's mean cost
TIME_LIMIT = 300.0  # seconds per problem; at the limit the dual bound is kept


def moves_allowed(m):
    """Moves a foot may have made when the lattice says m (the cap stands for >= MAXM)."""
    return HORIZON if m >= MAXM else m


def foot_box(model, name, m):
    """A foot that made m moves: within 0.3 m times m of its start, x <= reach."""
    x0, y0 = START[name]
    k = moves_allowed(m)
    r = (0.3 + MOVE_SLACK) * k
    x = model.addVar(lb=x0 - r, ub=min(x0 + r, reach(x0, k) + MOVE_SLACK * k + TOL))
    y = model.addVar(lb=y0 - r, ub=y0 + r)
    if k > 0:
        model.addCons((x - x0) ** 2 + (y - y0) ** 2 <= r * r)
    return x, y


def com(model, p, q):
    """A biped's CoM at leg length from both feet p, q (11), with bounds from theirs."""
    lo_x = min(p[0].getLbOriginal(), q[0].getLbOriginal()) - LEG
    hi_x = max(p[0].getUbOriginal(), q[0].getUbOriginal()) + LEG
    lo_y = min(p[1].getLbOriginal(), q[1].getLbOriginal()) - LEG
    hi_y = max(p[1].getUbOriginal(), q[1].getUbOriginal()) + LEG
    c = (model.addVar(lb=lo_x, ub=hi_x), model.addVar(lb=lo_y, ub=hi_y),
         model.addVar(lb=0, ub=LEG))  # a CoM below the ground mirrored up costs less
    for f in (p, q):
        leg = (c[0] - f[0]) ** 2 + (c[1] - f[1]) ** 2 + c[2] ** 2
        model.addCons(leg >= 0.5 - LEG_TOL)
        model.addCons(leg <= 0.5 + LEG_TOL)
    return c


def sq_dist(p, q):
    return (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2


def new_model(gap):
    model = Model()
    model.hideOutput()
    model.setParam("limits/time", TIME_LIMIT)
    model.setParam("limits/gap", gap)
    return model


def window_model(s, moves):
    """The window (s, moves) of window_bound.py: its mean stance cost, minimised. (Its
    stances' bounds as floors of their cost variables stall SCIP at the floors: a
    window that closes its gap in 4 s did not in 300; bound() uses them afterwards.)"""
    seq = stances_of(s, moves)
    model = new_model(STANCE_GAP if not moves else WINDOW_GAP)
    if moves:
        model.setParam("limits/absgap", WINDOW_ABS_GAP)
    feet = [foot_box(model, n, s[i]) for i, n in enumerate(FEET)]
    costs = []
    for k, t in enumerate(seq):
        if k > 0:  # the moving foot steps <= 0.3 m to a point its count allows
            j = moves[k - 1]
            q = foot_box(model, FEET[j], t[j])
            model.addCons(sq_dist(q, feet[j]) <= 0.09 + TOL)
            feet = feet[:j] + [q] + feet[j + 1:]
        cb, cf = com(model, feet[0], feet[1]), com(model, feet[2], feet[3])
        for a, b, lo, hi in [(0, 1, 0.25, 2.25), (2, 3, 0.25, 2.25), (0, 2, 1, 9), (1, 3, 1, 9)]:
            model.addCons(sq_dist(feet[a], feet[b]) >= lo - TOL)
            model.addCons(sq_dist(feet[a], feet[b]) <= hi + TOL)
        lam = [model.addVar(lb=LAMBDA_MIN, ub=1 - 3 * LAMBDA_MIN) for _ in range(4)]
        model.addCons(quicksum(lam) == 1)
        for axis in (0, 1):  # (2): r_W's ground projection is the force-weighted mean
            cop = (cb[axis] + cf[axis]) / 2 - quicksum(lam[i] * feet[i][axis] for i in range(4))
            model.addCons(cop <= COP_TOL)
            model.addCons(cop >= -COP_TOL)
        cost = model.addVar(lb=0, ub=1e7)
        model.addCons(1000 * quicksum((v - g) ** 2 for c, goal in ((cb, GB), (cf, GF))
                                      for v, g in zip(c, goal))
                      + 0.001 * MG * MG * quicksum(v * v for v in lam) <= cost)
        costs.append(cost)
    mean = model.addVar(lb=0, ub=1e7)
    model.addCons(mean * len(seq) >= quicksum(costs))
    model.setObjective(mean, "minimize")
    return model


def biped_model(names, goal, counts):
    """One biped alone (no balance, no same-side distances): 1000 |CoM - goal|^2."""
    model = new_model(STANCE_GAP)
    p, q = (foot_box(model, n, m) for n, m in zip(names, counts))
    model.addCons(sq_dist(p, q) >= 0.25 - TOL)
    model.addCons(sq_dist(p, q) <= 2.25 + TOL)
    c = com(model, p, q)
    cost = model.addVar(lb=0, ub=1e7)
    model.addCons(1000 * quicksum((v - g) ** 2 for v, g in zip(c, goal)) <= cost)
    model.setObjective(cost, "minimize")
    return model


def lower(model):
    """SCIP's dual bound and its status. Every window contains a feasible point (the
    robot standing at its start, the feet's counts only widen their discs), so a claim
    of infeasibility would be a numerical failure: it stops the run."""
    start = time.time()
    model.optimize()
    status = model.getStatus()
    if status == "infeasible":
        raise RuntimeError("SCIP declared a window infeasible: numerical trouble")
    return model.getDualbound(), status, time.time() - start


def model_tag():
    """A fingerprint of everything that defines the bounded problems: a cache made by
    other problems is refused, not mixed in."""
    parts = [inspect.getsource(f) for f in (foot_box, com, sq_dist, new_model, window_model,
                                            biped_model, reach, stances_of)]
    parts.append(repr((HORIZON, LAMBDA_MIN, COP_TOL, TOL, MOVE_SLACK, LEG_TOL, STANCE_GAP,
                       WINDOW_GAP, WINDOW_ABS_GAP, TIME_LIMIT, MAXM, START, GB, GF)))
    return hashlib.sha256("".join(parts).encode()).hexdigest()[:16]


def settle(key):
    kind, rest = key
    if kind == "biped":
        names, goal, counts = rest
        return key, lower(biped_model(names, goal, counts))
    return key, lower(window_model(*rest))


def check_plan(file, w, solved):
    """A check of the models and the bounds on a real plan: along its own move counts,
    its stances' point must be feasible in every window's model (CoM heights mirrored,
    lambda_i = F_z,i / sum F_z) and cost no less than the window's bound."""
    stances = json.load(open(file))["stances"]
    cost = [1000 * (math.dist(st["com"]["B"], GB) ** 2 + math.dist(st["com"]["F"], GF) ** 2)
            + 0.001 * sum(v * v for n in FEET for v in st["forces"][n]) for st in stances]
    path, moved, _ = plan_path(file)
    infeasible, least = 0, math.inf
    for k in range(len(path) - w + 1):
        window, moves = stances[1 + k:1 + k + w], tuple(moved[k + 1:k + w])
        values = sum((window[0]["feet"][n][:2] for n in FEET), [])
        for i, st in enumerate(window):
            if i > 0:
                values += st["feet"][FEET[moves[i - 1]]][:2]
            for c in "BF":
                values += [st["com"][c][0], st["com"][c][1], abs(st["com"][c][2])]
            fz = [st["forces"][n][2] for n in FEET]
            values += [f / sum(fz) for f in fz] + [cost[1 + k + i]]
        mean = sum(cost[1 + k:1 + k + w]) / w
        model = window_model(path[k], moves)
        point = model.createSol()
        for var, value in zip(model.getVars(), values + [mean]):
            model.setSolVal(point, var, value)
        if not model.checkSol(point, completely=True, original=True):
            infeasible += 1
        if ("win", (path[k], moves)) in solved:
            least = min(least, mean - solved[("win", (path[k], moves))])
    print(f"{file}: cost {sum(cost):.6e}; its point infeasible in {infeasible} of "
          f"{len(path) - w + 1} windows (W = {w}); least (plan's mean - bound) over the "
          f"bounded ones {least:.3f}")


def main():
    args = sys.argv[1:]
    w = int(args[0]) if args else 1
    opts = dict(zip(args[1::2], args[2::2]))
    cache = opts.get("--cache")
    jobs = int(opts.get("--jobs", "1"))
    target = float(opts.get("--target", "inf"))
    solved, tag = {}, model_tag()
    if cache and os.path.exists(cache):
        with open(cache, "rb") as f:
            stored = pickle.load(f)
        if stored.get("model") != tag:
            sys.exit(f"{cache} holds bounds of other problems (model {stored.get('model')}, "
                     f"this file's {tag}): use another cache")
        solved.update(stored["bounds"])
    if "--plan" in opts:
        check_plan(opts["--plan"], w, solved)
        return
    pool = multiprocessing.Pool(jobs)

    def run(keys):
        for key, (bound, status, secs) in pool.imap_unordered(
                settle, [k for k in keys if k not in solved]):
            solved[key] = bound
            if status not in ("optimal", "gaplimit"):
                print(f"  {key}: {status} after {secs:.0f} s, dual bound {bound:.3f} kept",
                      flush=True)
            if cache:  # after every problem: an interrupted run loses nothing
                with open(cache + ".tmp", "wb") as f:
                    pickle.dump({"model": tag, "bounds": solved}, f)
                os.replace(cache + ".tmp", cache)

    back_keys = [("biped", (("BR", "BL"), tuple(GB), (a, b)))
                 for a in range(MAXM + 1) for b in range(MAXM + 1)]
    front_keys = [("biped", (("FR", "FL"), tuple(GF), (a, b)))
                  for a in range(MAXM + 1) for b in range(MAXM + 1)]

    def biped(names, goal, a, b):
        return solved[("biped", (names, tuple(goal), (a, b)))]

    def stance_bound(t):
        """The better of the stance's own dual bound and the decoupled bipeds' bound."""
        apart = biped(("BR", "BL"), GB, *t[:2]) + biped(("FR", "FL"), GF, *t[2:]) + FMIN
        return max(solved.get(("win", (t, ())), -math.inf), apart)

    def bound(s, ms):
        """Two valid bounds of a window's mean cost: its own (when bounded) and the mean
        of its stances' (SCIP may stop a window below the latter, at WINDOW_GAP)."""
        seq = stances_of(s, ms)
        mean = sum(stance_bound(t) for t in seq) / len(seq)
        return max(solved.get(("win", (s, ms)), -math.inf), mean)

    run(back_keys + front_keys)
    rnd = 0
    while True:
        rnd += 1
        total, path = shortest(w, bound)
        stances = {t for s, ms in path for t in stances_of(s, ms)}
        todo_n = [("win", (t, ())) for t in stances if ("win", (t, ())) not in solved]
        todo_w = [("win", k) for k in path if ("win", k) not in solved and k[1]]
        print(f"round {rnd}: {total:.6e}, new stances {len(todo_n)}, new windows "
              f"{len(todo_w)}, bounded {len(solved)}", flush=True)
        if not todo_n and not todo_w:
            break
        if total >= target:
            print(f"W = {w}: every plan costs at least {total:.6e} >= {target:.6e}")
            return
        run(todo_n if todo_n else todo_w)  # re-route on the stances first: cheap
    for k, (s, ms) in enumerate(path):
        print(k + 2, s, [FEET[j] for j in ms], round(bound(s, ms), 1))
    print(f"W = {w}: certified lower bound {total:.6e} (the plan: 1.706639e5)")


if __name__ == "__main__":
    main()
