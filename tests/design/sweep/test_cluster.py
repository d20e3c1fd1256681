"""Dask executors: a 2-worker LocalCluster (processes, one thread each, on 127.0.0.1) gives rows
identical to the local executor's; ``scheduler=`` connects to a running cluster; a worker process
that dies while evaluating loses only its chunk, which is resubmitted."""
import pytest

pytest.importorskip("distributed")

from distributed import LocalCluster  # noqa: E402

from design.sweep import DaskExecutor, LocalExecutor, load_sweep, read_sweep, run_sweep  # noqa: E402
from tests.design.sweep.helpers import evaluate_dying_once, write_sweep  # noqa: E402

SKIP = ("time_s", "worker", "id")


def table(db):
    return {r["key"]: {k: v for k, v in r.items() if k not in SKIP} for r in read_sweep(db)[1]}


@pytest.fixture(scope="module")
def cluster():
    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None)
    yield c
    c.close()


def test_dask_rows_equal_local_rows(tmp_path, cluster):
    sw = load_sweep(write_sweep(tmp_path, counts=(4, 3)))
    run_sweep(sw, tmp_path / "local.sqlite", LocalExecutor(1))
    rep = run_sweep(sw, tmp_path / "dask.sqlite", DaskExecutor(scheduler=cluster.scheduler_address), chunk_seconds=0.02)
    assert rep.counts["done"] == 12 and rep.executor.startswith("dask:tcp://127.0.0.1")
    assert table(tmp_path / "dask.sqlite") == table(tmp_path / "local.sqlite")
    workers = {r["worker"] for r in read_sweep(tmp_path / "dask.sqlite")[1]}
    assert len(workers) >= 1 and all(w for w in workers)


def test_a_dead_workers_chunk_is_resubmitted(tmp_path, cluster):
    sw = load_sweep(write_sweep(tmp_path, counts=(3, 2)))
    rep = run_sweep(sw, tmp_path / "d.sqlite", DaskExecutor(scheduler=cluster.scheduler_address),
                    evaluate=evaluate_dying_once)
    assert (tmp_path / "died").exists()                                   # a worker process did die
    assert rep.counts == {"pending": 0, "running": 0, "done": 6, "failed": 0}
    run_sweep(sw, tmp_path / "l.sqlite", LocalExecutor(1))
    assert table(tmp_path / "d.sqlite") == table(tmp_path / "l.sqlite")
