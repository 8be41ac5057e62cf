"""A valid (loose) lower bound on the cost (1) of any plan of the default scenario.

Relaxations, each of which can only lower the optimum:
- each biped alone: its CoM is at distance sqrt(0.5) from each of its feet, so its x is
  x_rear + l with l its x offset from the rear foot, and its height is
  z = sqrt(0.5 - l^2 - dy^2) for some dy, so any z <= sqrt(0.5 - l^2); the CoM cost of
  the biped is at least min over l of (D - l)^2 + (0.5 - min(0.5, sqrt(0.5 - l^2)))^2,
  D = goal x - x_rear (0 when D < 0; l < 0 never helps then);
- the rear foot has made at most half of its biped's moves, each <= 0.3 m, and a foot may
  not land in the default keep-out (2.22, 2.38): from x0 after m moves it is at most at
  reach(x0, m) below;
- forces: sum_i F_z,i = M g, so sum_i |F_i|^2 >= (M g)^2 / 4 at every stance;
- the bipeds are coupled only through "one foot moves per transition": the best
  interleaving of their moves is found by dynamic programming over (n_B, n_F).
Stance 1 is the fixed start (CoM cost 18000). Prints the bound (1.537e5 when written, the same to 5 digits with a 10× finer grid;
the planner's plan: 1.706639e5). Usage: python3 lower_bound.py
"""
import math

N_STEP = 60
KEEP_OUT = (2.22, 2.38)
W_COM, W_F = 1000.0, 0.001
M_G = 100 * 9.81


def reach(x0, m):
    """Largest x a foot starting at x0 can stand at after m moves of <= 0.3 m."""
    x = x0
    for _ in range(m):
        x += 0.3
        if KEEP_OUT[0] < x < KEEP_OUT[1]:
            x = KEEP_OUT[0]
    return x


def com_cost(d):
    """min over the lean l of (d - l)^2 + (0.5 - min(0.5, sqrt(0.5 - l^2)))^2 on a fine
    grid (4000 points over [0, sqrt(0.5)], plus l = d when d is in that range)."""
    n = 4000
    grid = [math.sqrt(0.5) * i / n for i in range(n + 1)]
    if d <= math.sqrt(0.5):
        grid.append(d)
    best = math.inf
    for l in grid:
        z = min(0.5, math.sqrt(max(0.5 - l * l, 0.0)))
        best = min(best, (d - l) ** 2 + (0.5 - z) ** 2)
    return best


def biped_costs(x0, goal):
    return [W_COM * com_cost(max(goal - reach(x0, k // 2), 0.0)) for k in range(N_STEP)]


def main():
    cb, cf = biped_costs(0.0, 3.0), biped_costs(2.0, 5.0)
    best = {(0, 0): 0.0}
    for _ in range(2, N_STEP + 1):
        nxt = {}
        for (a, b), v in best.items():
            for a2, b2 in ((a + 1, b), (a, b + 1)):
                c = v + cb[a2] + cf[b2]
                if c < nxt.get((a2, b2), math.inf):
                    nxt[(a2, b2)] = c
        best = nxt
    force = N_STEP * W_F * M_G ** 2 / 4
    print(f"lower bound {18000 + min(best.values()) + force:.6e}")


if __name__ == "__main__":
    main()
