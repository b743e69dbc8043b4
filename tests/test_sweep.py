"""The sweep facility (comparisons/sweep.py): a local process pool and a Dask cluster of
two workers give the same results, in the items' order."""
import pytest

from mbfidelity.analytic.strutt import mathieu_point
from mbfidelity.comparisons.sweep import sweep

POINTS = [(lam, gamma) for lam in (-0.5, 0.0, 0.25, 1.0, 2.0) for gamma in (0.0, 0.5, 1.5)]


def test_local_pool_equals_in_process():
    assert sweep(mathieu_point, POINTS, workers=2) == sweep(mathieu_point, POINTS, workers=1)


def test_dask_local_cluster_equals_local_pool():
    distributed = pytest.importorskip("dask.distributed")
    local = sweep(mathieu_point, POINTS, workers=2)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        remote = sweep(mathieu_point, POINTS, scheduler=cluster.scheduler_address)
    assert remote == local
    assert [(p["lambda"], p["gamma"]) for p in remote] == [tuple(map(float, p)) for p in POINTS]
