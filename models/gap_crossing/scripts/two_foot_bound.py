"""An estimate of a lower bound on the cost (1) of the default scenario, keeping both
feet of each biped (indicative, not certified: each per-stance problem is solved by
IPOPT from 6 starting points, a local method).

Relaxation (each step can only lower the optimum):
- the bipeds are decoupled: no whole-body balance (2) and no same-side distances
  (6), (7); the forces cost at least (M g)^2 / 4 per stance (sum_i F_z,i = M g);
- after a and b moves of its two feet, a biped's feet are anywhere within 0.3 a and
  0.3 b of their starts (horizontally, on the ground z = 0), and after m moves a foot
  is at most at reach(x0, m) in x (it cannot stand in the default keep-out
  (2.22, 2.38)); each stance picks its feet afresh (no single trajectory);
- the CoM is at distance sqrt(0.5) from both feet (11), the feet 0.5-1.5 m apart (8),
  (9); the biped's stance cost is min 1000 |CoM - goal|^2 (table over a, b < 16);
- the four feet's move counts follow a path through the 4-D lattice, one count up by
  one per transition (10); the cheapest path is found by dynamic programming.
Stance 1 is the fixed start (CoM cost 18000). Prints the estimate (1.6505e5 when
written, 2026-11-25; CoM part 1.5062e5 against the plan's 1.5283e5, forces 1.4436e4
against the plan's 1.7838e4). Usage: python3 two_foot_bound.py (needs casadi).
"""
import math

import casadi as ca

from lower_bound import reach
MAX_MOVES = 16
N_STEP = 60


def biped_table(s_r, s_l, goal):
    """1000 x the least CoM cost of a biped whose feet made (a, b) moves."""
    c = ca.MX.sym("c", 3)
    p_r = ca.MX.sym("pR", 2)
    p_l = ca.MX.sym("pL", 2)
    par = ca.MX.sym("par", 4)  # reach radii of both feet, x caps of both feet
    d_r = ca.vertcat(c[0] - p_r[0], c[1] - p_r[1], c[2])
    d_l = ca.vertcat(c[0] - p_l[0], c[1] - p_l[1], c[2])
    g = ca.vertcat(
        ca.sumsqr(d_r) - 0.5,
        ca.sumsqr(d_l) - 0.5,
        ca.sumsqr(p_r - p_l),
        ca.sumsqr(p_r - ca.DM(s_r)) - par[0] ** 2,
        ca.sumsqr(p_l - ca.DM(s_l)) - par[1] ** 2,
        p_r[0] - par[2],
        p_l[0] - par[3],
    )
    nlp = {"x": ca.vertcat(c, p_r, p_l), "f": ca.sumsqr(c - ca.DM(goal)), "g": g, "p": par}
    opts = {"ipopt.print_level": 0, "print_time": 0, "ipopt.sb": "yes"}
    solver = ca.nlpsol("S", "ipopt", nlp, opts)
    lbg = [0, 0, 0.25, -ca.inf, -ca.inf, -ca.inf, -ca.inf]
    ubg = [0, 0, 2.25, 0, 0, 0, 0]
    table = {}
    for a in range(MAX_MOVES):
        for b in range(MAX_MOVES):
            ra, rb = 0.3 * a, 0.3 * b
            cap_r, cap_l = reach(s_r[0], a), reach(s_l[0], b)
            best = math.inf
            for sx in (0.0, 0.3, 0.6):
                for sz in (0.1, 0.4):
                    xr, xl = min(s_r[0] + ra, cap_r), min(s_l[0] + rb, cap_l)
                    x0 = [xr + sx, 0.5, sz, xr, s_r[1] * 0.7 + 0.15, xl, s_l[1] * 0.7 + 0.15]
                    r = solver(x0=x0, p=[ra + 1e-9, rb + 1e-9, cap_r, cap_l], lbg=lbg, ubg=ubg)
                    if solver.stats()["success"]:
                        best = min(best, float(r["f"]))
            table[(a, b)] = 1000.0 * best
    return table


def main():
    back = biped_table([0.0, 0.0], [0.0, 1.0], [3.0, 0.5, 0.5])
    front = biped_table([2.0, 0.0], [2.0, 1.0], [5.0, 0.5, 0.5])
    layer = {(0, 0, 0, 0): 0.0}
    for _ in range(2, N_STEP + 1):
        nxt = {}
        for counts, v in layer.items():
            for i in range(4):
                s = list(counts)
                s[i] = min(s[i] + 1, MAX_MOVES - 1)
                s = tuple(s)
                cost = v + back[(s[0], s[1])] + front[(s[2], s[3])]
                if cost < nxt.get(s, math.inf):
                    nxt[s] = cost
        layer = nxt
    com = 18000.0 + min(layer.values())
    force = N_STEP * 0.001 * (100 * 9.81) ** 2 / 4
    print(f"CoM part {com:.6e}, forces {force:.6e}, estimate {com + force:.6e}")


if __name__ == "__main__":
    main()
