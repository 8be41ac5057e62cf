"""Timing of the Python package against Rust and CasADi (docs/performance.md, "Python").

    .venv/bin/python benches/reference/python_timing.py [--reps 7]

Prints three ratios, each from interleaved repetitions (medians), in one process:
1. Python overhead of a solve: the wall time of `pb.solve()` seen from Python over the
   solver's own total time measured inside Rust (`stats["t_wall_total"]`), for the
   hanging chain (the problem is compiled once before timing; every solve starts cold).
2. Building the 1000-link hanging chain (variables, objective, 999 link constraints, end
   conditions) in symnlp vs casadi.Opti, same formulation, same process.
3. Two threads each solving a chain at once vs the same two solves one after the other,
   then the speed-up in words: met or not, and whether the load average at the time lets
   it count (it needs two free cores: run it on an idle machine, e.g.
   `.venv/bin/python benches/reference/python_timing.py --reps 9 --n 1000`).
"""
import argparse
import os
import statistics
import threading
import time

import symnlp as s


def chain_symnlp_vec(n):
    """The same chain with the link constraints as one vector expression."""
    pb = s.Problem()
    px = pb.variable("px", n)
    py = pb.variable("py", n)
    pb.minimize(s.sum1(py))
    seg = 1.4 / (n - 1)
    pb.subject_to((px[1:] - px[:-1]) ** 2 + (py[1:] - py[:-1]) ** 2 <= seg**2)
    pb.subject_to(s.vertcat(px[0], py[0], px[n - 1], py[n - 1]) == [0.0, 1.0, 1.0, 0.5])
    pb.set_initial(px, [i / (n - 1) for i in range(n)])
    pb.set_initial(py, [1 - 0.5 * i / (n - 1) for i in range(n)])
    return pb


def chain_casadi_vec(n):
    import casadi

    opti = casadi.Opti()
    px = opti.variable(n)
    py = opti.variable(n)
    opti.minimize(casadi.sum1(py))
    seg = 1.4 / (n - 1)
    opti.subject_to((px[1:] - px[:-1]) ** 2 + (py[1:] - py[:-1]) ** 2 <= seg**2)
    opti.subject_to(casadi.vertcat(px[0], py[0], px[n - 1], py[n - 1]) == casadi.DM([0.0, 1.0, 1.0, 0.5]))
    opti.set_initial(px, [i / (n - 1) for i in range(n)])
    opti.set_initial(py, [1 - 0.5 * i / (n - 1) for i in range(n)])
    return opti


def chain_symnlp(n):
    pb = s.Problem()
    px = pb.variable("px", n)
    py = pb.variable("py", n)
    pb.minimize(s.sum1(py))
    seg = 1.4 / (n - 1)
    for i in range(n - 1):
        pb.subject_to((px[i + 1] - px[i]) ** 2 + (py[i + 1] - py[i]) ** 2 <= seg**2)
    pb.subject_to(s.vertcat(px[0], py[0], px[n - 1], py[n - 1]) == [0.0, 1.0, 1.0, 0.5])
    pb.set_initial(px, [i / (n - 1) for i in range(n)])
    pb.set_initial(py, [1 - 0.5 * i / (n - 1) for i in range(n)])
    return pb


def chain_casadi(n):
    import casadi

    opti = casadi.Opti()
    px = opti.variable(n)
    py = opti.variable(n)
    opti.minimize(casadi.sum1(py))
    seg = 1.4 / (n - 1)
    for i in range(n - 1):
        opti.subject_to((px[i + 1] - px[i]) ** 2 + (py[i + 1] - py[i]) ** 2 <= seg**2)
    opti.subject_to(casadi.vertcat(px[0], py[0], px[n - 1], py[n - 1]) == casadi.DM([0.0, 1.0, 1.0, 0.5]))
    opti.set_initial(px, [i / (n - 1) for i in range(n)])
    opti.set_initial(py, [1 - 0.5 * i / (n - 1) for i in range(n)])
    return opti


def timed(f):
    t = time.perf_counter()
    r = f()
    return time.perf_counter() - t, r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=7)
    ap.add_argument("--n", type=int, default=200, help="chain masses for ratios 1 and 3")
    ap.add_argument("--only", choices=["solve", "build", "threads"],
                    help="measure one ratio only (threads: the two-thread speed-up)")
    a = ap.parse_args()
    if a.only in (None, "solve"):
        solve_ratio(a)
    if a.only in (None, "build"):
        build_ratios(a)
    if a.only in (None, "threads"):
        threads_ratio(a)


def solve_ratio(a):
    # 1. Python vs Rust solve time.
    pb = chain_symnlp(a.n)
    pb.compile()
    py_t, rs_t = [], []
    for _ in range(a.reps):
        t, sol = timed(pb.solve)
        assert sol.success, sol.status
        py_t.append(t)
        rs_t.append(sol.stats["t_wall_total"])
    r1 = statistics.median(py_t) / statistics.median(rs_t)
    print(f"1. solve, chain n={a.n}: Python wall {statistics.median(py_t)*1e3:.2f} ms, "
          f"Rust total {statistics.median(rs_t)*1e3:.2f} ms, ratio {r1:.3f}")


def build_ratios(a):
    # 2. Build the 1000-link chain: symnlp vs CasADi, interleaved.
    sb, cb = [], []
    for _ in range(a.reps):
        sb.append(timed(lambda: chain_symnlp(1001))[0])
        cb.append(timed(lambda: chain_casadi(1001))[0])
    r2 = statistics.median(sb) / statistics.median(cb)
    print(f"2. build 1000-link chain: symnlp {statistics.median(sb)*1e3:.1f} ms, "
          f"casadi.Opti {statistics.median(cb)*1e3:.1f} ms, ratio {r2:.3f}")

    sv, cv = [], []
    for _ in range(a.reps):
        sv.append(timed(lambda: chain_symnlp_vec(1001))[0])
        cv.append(timed(lambda: chain_casadi_vec(1001))[0])
    r2v = statistics.median(sv) / statistics.median(cv)
    print(f"2b. same, link constraints as one vector expression: symnlp "
          f"{statistics.median(sv)*1e3:.1f} ms, casadi.Opti {statistics.median(cv)*1e3:.1f} ms, "
          f"ratio {r2v:.3f}")


def threads_ratio(a):
    # 3. Two threads vs serial. Problems are bound to the thread that builds them, so
    # each thread builds and compiles its own, waits at a barrier, then solves; only the
    # solves are timed (from the barrier to the last join). Serial: two problems built
    # here, solved one after the other.
    def job():
        p = chain_symnlp(a.n)
        p.compile()
        return p

    def threaded():
        barrier = threading.Barrier(3)

        def worker():
            p = job()
            barrier.wait()
            assert p.solve().success

        ts = [threading.Thread(target=worker) for _ in range(2)]
        for t in ts:
            t.start()
        barrier.wait()
        t0 = time.perf_counter()
        for t in ts:
            t.join()
        return time.perf_counter() - t0

    probs = [job(), job()]
    ser, par = [], []
    for _ in range(a.reps):
        ser.append(timed(lambda: [p.solve() for p in probs])[0])
        par.append(threaded())
    r3 = statistics.median(par) / statistics.median(ser)
    print(f"3. two solves: serial {statistics.median(ser)*1e3:.1f} ms, two threads "
          f"{statistics.median(par)*1e3:.1f} ms, ratio {r3:.3f}")
    two_threads_verdict(r3)


def two_threads_verdict(ratio, target=0.6):
    """States the two-thread result plainly, with the load it was measured under: the
    ratio only means something with two cores free (an idle machine)."""
    cores = os.cpu_count() or 1
    load = os.getloadavg()[0]
    met = "MET" if ratio <= target else "NOT MET"
    print(f"   two-thread speed-up: {1 / ratio:.2f}x (time ratio {ratio:.3f}, target <= {target}: {met})")
    print(f"   measured with load average {load:.1f} on {cores} cores", end="")
    if load > max(cores - 2, 0) + 0.5:
        print(": the machine is busy, so this does NOT show what the GIL release gives;"
              " re-run on an idle machine")
    else:
        print(": the machine was idle enough for this to count")

if __name__ == "__main__":
    main()
