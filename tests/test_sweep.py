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
                                  dashboard_address=":0") as cluster:
        remote = sweep(mathieu_point, POINTS, scheduler=cluster.scheduler_address)
    assert remote == local
    assert [(p["lambda"], p["gamma"]) for p in remote] == [tuple(map(float, p)) for p in POINTS]


def test_the_matrix_on_a_dask_cluster_equals_the_local_pool(tmp_path):
    """`run --scheduler`: the same metrics, bitwise, and the same files the report reads
    (series and drawings saved by the client, not the workers)."""
    import json

    from typer.testing import CliRunner

    from mbfidelity.cli import app

    distributed = pytest.importorskip("dask.distributed")
    args = ["run", "--systems", "compound_pendulum,mass_spring_damper", "--sims", "pymunk"]
    local, remote = tmp_path / "local", tmp_path / "remote"
    res = CliRunner().invoke(app, args + ["--out", str(local)])
    assert res.exit_code == 0, res.output
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=":0") as cluster:
        res = CliRunner().invoke(app, args + ["--out", str(remote), "--scheduler",
                                              cluster.scheduler_address])
    assert res.exit_code == 0, res.output

    def metrics(folder):
        doc = json.loads((folder / "results.json").read_text())
        return [(c["system"], c["simulator"], m["name"], m["value"], m["status"])
                for c in doc["comparisons"] for m in c["metrics"]]
    assert metrics(remote) == metrics(local) and len(metrics(local)) > 10

    def files(folder):
        return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*")
                      if p.is_file() and "jobs" not in p.parts)
    assert files(remote) == files(local)
