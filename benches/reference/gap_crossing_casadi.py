#!/usr/bin/env python3
"""CasADi + IPOPT on symnlp's own gap-crossing formulation (no second formulation to drift).

The problem is not re-written here: it is read from the JSON dump written by the Rust example
`models/gap_crossing/examples/export.rs` (module `gap_crossing::export`): variables (symbol
names, bounds, initial values), constraint rows (expressions as printed by symx, bounds,
names, value at x0) and the objective. symx prints fully parenthesised infix `+ - * /`,
`(-e)` for negation, calls `sq(e)`, `sqrt(e)`, `atan(e)`, `pow(a,b)`, `if_else(c,a,b)`, ...,
symbols by name (`r_BR^3[0]`, `F_FL^12[2]`) and shared subexpressions as bindings
`@1=...; @2=...; result`. This script parses that text into CasADi SX (names -> x[i] of one
SX vector, exact tokens), checks f(x0) and g(x0) against the values symnlp computed, and
solves with nlpsol('ipopt') from the same x0 with the same bounds.

IPOPT options: tol 1e-8 (IPOPT's default), exact Hessian, defaults otherwise (MUMPS),
`record_time` True so that stats() has t_wall_total. Timing: `build_s` (parse text -> SX),
`nlpsol_s` (nlpsol construction: CasADi's AD + code generation of the SX functions),
`solve_s` (the solver call; t_wall_total of stats(), and the Python wall time around it).

Usage:
  # one run, both solvers, same process tree: the Rust example writes the dump and times
  # symnlp's own solve (--solve --repeat R); then IPOPT solves the dump R times.
  python3 benches/reference/gap_crossing_casadi.py --export-bin target/release/examples/export \\
      --repeat 3 --set n_step=60 --set gap.depth=0 > results/gap_crossing_flat60.json
  # or an existing dump:
  python3 benches/reference/gap_crossing_casadi.py --dump dump.json
Options: --print-level K (IPOPT print level, default 0), --max-iter N (default 3000),
--max-wall S (IPOPT max_wall_time, default 600).
"""
import argparse
import json
import math
import re
import statistics
import subprocess
import sys
import threading
import time

import casadi as ca

TOKEN = re.compile(
    r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
    r"|(?P<bind>@\d+)"
    r"|(?P<name>[A-Za-z_][A-Za-z0-9_^]*(?:\[\d+\])?)"
    r"|(?P<punct>[()+\-*/,=;]))"
)


def _bool(f):
    return f


FUNCTIONS = {
    "neg": lambda a: -a,
    "sq": lambda a: a * a,
    "sqrt": ca.sqrt,
    "exp": ca.exp,
    "log": ca.log,
    "sin": ca.sin,
    "cos": ca.cos,
    "tan": ca.tan,
    "asin": ca.asin,
    "acos": ca.acos,
    "atan": ca.atan,
    "sinh": ca.sinh,
    "cosh": ca.cosh,
    "tanh": ca.tanh,
    "abs": ca.fabs,
    "sign": ca.sign,
    "not": ca.logic_not,
    "add": lambda a, b: a + b,
    "sub": lambda a, b: a - b,
    "mul": lambda a, b: a * b,
    "div": lambda a, b: a / b,
    "pow": lambda a, b: a ** b,
    "atan2": ca.atan2,
    "min": ca.fmin,
    "max": ca.fmax,
    "lt": ca.lt,
    "le": ca.le,
    "eq": ca.eq,
    "ne": ca.ne,
    "and": ca.logic_and,
    "or": ca.logic_or,
    "if_else": lambda c, a, b: ca.if_else(c, a, b),
}


class Parser:
    """Recursive-descent parser of symx's printed form into CasADi SX."""

    def __init__(self, symbols):
        self.symbols = symbols  # name -> SX

    def parse(self, text):
        toks = []
        pos = 0
        while pos < len(text):
            m = TOKEN.match(text, pos)
            if not m or m.end() == pos:
                if text[pos:].strip() == "":
                    break
                raise ValueError(f"bad character at {pos}: {text[pos:pos + 20]!r}")
            pos = m.end()
            kind = m.lastgroup
            toks.append((kind, m.group(kind)))
        self.t, self.i, self.bindings = toks, 0, {}
        while self.peek() and self.peek()[0] == "bind" and self.peek(1) == ("punct", "="):
            k = self.t[self.i][1]
            self.i += 2
            self.bindings[k] = self.expr()
            self.expect(";")
        e = self.expr()
        if self.i != len(self.t):
            raise ValueError(f"trailing tokens: {self.t[self.i:self.i + 5]}")
        return e

    def peek(self, d=0):
        return self.t[self.i + d] if self.i + d < len(self.t) else None

    def expect(self, p):
        if self.peek() != ("punct", p):
            raise ValueError(f"expected {p!r}, got {self.peek()}")
        self.i += 1

    def expr(self):
        kind, v = self.peek()
        if kind == "num":
            self.i += 1
            return float(v)
        if kind == "bind":
            self.i += 1
            return self.bindings[v]
        if kind == "name":
            self.i += 1
            if self.peek() == ("punct", "("):
                self.i += 1
                args = [self.expr()]
                while self.peek() == ("punct", ","):
                    self.i += 1
                    args.append(self.expr())
                self.expect(")")
                return FUNCTIONS[v](*args)
            if v == "inf":
                return math.inf
            if v == "NaN":
                return math.nan
            return self.symbols[v]
        if (kind, v) == ("punct", "-") and self.peek(1) and self.peek(1)[0] == "num":
            # A negative constant.
            self.i += 2
            return -float(self.t[self.i - 1][1])
        if (kind, v) == ("punct", "("):
            self.i += 1
            if self.peek() == ("punct", "-") and self.peek(1)[0] != "num":
                self.i += 1
                a = self.expr()
                self.expect(")")
                return -a
            a = self.expr()
            if self.peek() == ("punct", ")"):  # "(-3)": negation of a constant
                self.i += 1
                return a
            kind, op = self.peek()
            self.i += 1
            b = self.expr()
            self.expect(")")
            if op == "+":
                return a + b
            if op == "-":
                return a - b
            if op == "*":
                return a * b
            if op == "/":
                return a / b
            raise ValueError(f"unknown operator {op!r}")
        raise ValueError(f"unexpected token {(kind, v)}")


def bound(v, default):
    return default if v is None else v


def solve(d, repeat, print_level, max_iter, max_wall):
    n, m = d["n"], d["m"]
    t0 = time.perf_counter()
    x = ca.SX.sym("x", n)
    symbols = {v["name"]: x[i] for i, v in enumerate(d["variables"])}
    p = Parser(symbols)
    f = p.parse(d["objective"])
    g = ca.vertcat(*[p.parse(c["expr"]) for c in d["constraints"]])
    build_s = time.perf_counter() - t0
    x0 = [v["x0"] for v in d["variables"]]
    lbx = [bound(v["lower"], -math.inf) for v in d["variables"]]
    ubx = [bound(v["upper"], math.inf) for v in d["variables"]]
    lbg = [bound(c["lower"], -math.inf) for c in d["constraints"]]
    ubg = [bound(c["upper"], math.inf) for c in d["constraints"]]

    # The parsed problem is the dumped one: f(x0), g(x0) against symnlp's values.
    fg = ca.Function("fg", [x], [f, g])
    f0, g0 = fg(x0)
    f0 = float(f0)
    g0 = g0.full().ravel()
    f_err = abs(f0 - d["f0"])
    g_err = max((abs(a - c["g0"]) for a, c in zip(g0, d["constraints"])), default=0.0)

    opts = {
        "ipopt.tol": 1e-8,
        "ipopt.print_level": print_level,
        "ipopt.max_iter": max_iter,
        "ipopt.max_wall_time": max_wall,
        "ipopt.sb": "yes",
        "print_time": False,
        "record_time": True,
    }
    t0 = time.perf_counter()
    S = ca.nlpsol("S", "ipopt", {"x": x, "f": f, "g": g}, opts)
    nlpsol_s = time.perf_counter() - t0
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = S(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
        wall = time.perf_counter() - t0
        st = S.stats()
        xs = r["x"].full().ravel()
        gs = r["g"].full().ravel()
        viol = 0.0
        for i in range(m):
            viol = max(viol, lbg[i] - gs[i], gs[i] - ubg[i])
        for i in range(n):
            viol = max(viol, lbx[i] - xs[i], xs[i] - ubx[i])
        runs.append({
            "status": st["return_status"],
            "success": bool(st["success"]),
            "iterations": st["iter_count"],
            "objective": float(r["f"]),
            "constr_viol": viol,
            "solve_s": st["t_wall_total"],
            "call_wall_s": wall,
            "callbacks_s": sum(v for k, v in st.items() if k.startswith("t_wall_nlp_")),
        })
        print(f"ipopt: {st['return_status']} in {st['iter_count']} iterations, f = {float(r['f']):.12e}, "
              f"solve {st['t_wall_total']:.3f} s", file=sys.stderr)
    return {
        "n": n,
        "m": m,
        "casadi": ca.__version__,
        "build_s": build_s,
        "nlpsol_s": nlpsol_s,
        "f0_error": f_err,
        "g0_error": g_err,
        "runs": runs,
        "solve_s_median": statistics.median(r["solve_s"] for r in runs),
        "total_s_median": build_s + nlpsol_s + statistics.median(r["solve_s"] for r in runs),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dump", help="dump JSON written by the export example")
    ap.add_argument("--export-bin", help="path of the export example binary (target/release/examples/export)")
    ap.add_argument("--set", action="append", default=[], help="scenario override for the export binary")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--print-level", type=int, default=0)
    ap.add_argument("--max-iter", type=int, default=3000)
    ap.add_argument("--max-wall", type=float, default=600.0)
    a = ap.parse_args()
    if a.dump:
        with open(a.dump) as fh:
            d = json.load(fh)
    elif a.export_bin:
        cmd = [a.export_bin, "--solve", "--repeat", str(a.repeat)]
        for s in a.set:
            cmd += ["--set", s]
        print("running " + " ".join(cmd), file=sys.stderr)
        d = json.loads(subprocess.run(cmd, check=True, stdout=subprocess.PIPE).stdout)
    else:
        ap.error("give --dump or --export-bin")

    result = {}

    def work():
        result["ipopt"] = solve(d, a.repeat, a.print_level, a.max_iter, a.max_wall)

    # Deeply nested sums: parse recursively on a thread with a large stack.
    sys.setrecursionlimit(1_000_000)
    threading.stack_size(512 * 1024 * 1024)
    t = threading.Thread(target=work)
    t.start()
    t.join()
    if "ipopt" not in result:
        sys.exit(1)

    out = {
        "description": d.get("description"),
        "overrides": a.set,
        "n": d["n"],
        "m": d["m"],
        "f0": d["f0"],
        "ipopt": result["ipopt"],
    }
    if "symnlp" in d:
        out["symnlp"] = d["symnlp"]
        ours, theirs = d["symnlp"], result["ipopt"]
        out["ratio_solve"] = theirs["solve_s_median"] / ours["solve_s_median"]
        out["ratio_total"] = theirs["total_s_median"] / ours["total_s_median"]
        out["objective_symnlp"] = ours["runs"][0]["objective"]
        out["objective_ipopt"] = theirs["runs"][0]["objective"]
        print(f"ratio (IPOPT / symnlp): solve {out['ratio_solve']:.2f}x, total {out['ratio_total']:.2f}x",
              file=sys.stderr)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
