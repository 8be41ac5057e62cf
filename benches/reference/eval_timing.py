"""Timing helpers shared by the CasADi evaluation benchmarks
(symx_eval_casadi.py and symx_eval_gap_casadi.py)."""

import statistics
import timeit

import numpy as np


def time_call(fn, reps, target=0.2):
    """Median seconds per call of fn() over `reps` repetitions, and the samples.

    The loop length is auto-sized so that one repetition lasts about `target` seconds.
    """
    timer = timeit.Timer(fn)
    number, _ = timer.autorange()
    one = timer.timeit(number) / number
    number = max(1, int(target / max(one, 1e-9)))
    samples = [timer.timeit(number) / number for _ in range(reps)]
    return statistics.median(samples), samples


def internal_times(f_timed, ins, reps, calls):
    """CasADi's own `record_time` wall time (t_wall_total) of single calls of f_timed.

    Returns (median over reps of the per-rep median, minimum, per-rep medians), seconds.
    """
    rec = []
    for _ in range(reps):
        ts = []
        for _ in range(calls):
            f_timed(*ins)
            ts.append(f_timed.stats()["t_wall_total"])
        rec.append(ts)
    rep_medians = [statistics.median(ts) for ts in rec]
    return statistics.median(rep_medians), min(min(ts) for ts in rec), rep_medians


def nz_stats(dm):
    """Nonzero count and checksums of a CasADi DM (compared with symx's output)."""
    v = np.asarray(dm.nonzeros(), dtype=float)
    return {
        "nnz": int(dm.nnz()),
        "sum": float(v.sum()),
        "sum_abs": float(np.abs(v).sum()),
        "norm2": float(np.linalg.norm(v)),
    }
