"""A parameter sweep of the hanging chain fanned out over a local Dask distributed cluster
of 2 worker processes; the results equal a serial loop's, bit for bit."""
import numpy as np
import pytest

import symnlp as s
from problems import build_chain

distributed = pytest.importorskip("dask.distributed")

HEIGHTS = list(np.linspace(0.4, 0.9, 6))  # right-end heights, all within reach (> 0.25)


def solve_at(pb, height):
    """Runs on a worker, with the problem unpickled there: set the parameter, solve.
    Returns the picklable Solution."""
    pb.set_value(pb.lookup("ends"), [0.0, 1.0, 1.0, height])
    return pb.solve()


def test_dask_sweep_equals_serial_loop():
    pb = s.Problem()
    ys, ends = build_chain(pb, s)

    serial = []
    for h in HEIGHTS:
        pb.set_value(ends, [0.0, 1.0, 1.0, h])
        serial.append(pb.solve())

    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        futures = client.map(solve_at, [pb] * len(HEIGHTS), HEIGHTS, pure=False)
        remote = client.gather(futures)

    for a, b, h in zip(serial, remote, HEIGHTS):
        assert a.success and b.success
        assert a.objective == b.objective
        assert list(a.x) == list(b.x)
        # The worker's solution reads the client's expressions (symbols by name).
        assert b.value(ys[-1]) == pytest.approx(h, abs=1e-9)
