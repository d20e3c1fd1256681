"""Dask executors: ``rmt sweep --dask-local 2`` (a 2-worker LocalCluster, processes, one thread each,
on 127.0.0.1) gives rows identical to the local executor's; ``scheduler=`` connects to a running
LocalCluster, where a worker process that dies while evaluating loses only its chunk, which is
resubmitted, and the rows again equal the local executor's."""
import pytest

pytest.importorskip("distributed")

from distributed import LocalCluster

from design.sweep import DaskExecutor, LocalExecutor, load_sweep, read_sweep, run_sweep
from tests.design.sweep.helpers import evaluate_dying_once, write_sweep

SKIP = ("time_s", "worker", "id")


def table(db):
    return {r["key"]: {k: v for k, v in r.items() if k not in SKIP} for r in read_sweep(db)[1]}


@pytest.fixture(scope="module")
def cluster():
    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None)
    yield c
    c.close()


def test_dask_local_rows_equal_local_rows(tmp_path):
    from studies.cli.main import main
    p = write_sweep(tmp_path, counts=(4, 3))
    run_sweep(load_sweep(p), tmp_path / "local.sqlite", LocalExecutor(1))
    assert main(["sweep", str(p), "--db", str(tmp_path / "dask.sqlite"), "--dask-local", "2", "--quiet"]) == 0
    assert table(tmp_path / "dask.sqlite") == table(tmp_path / "local.sqlite")
    assert all(r["worker"] for r in read_sweep(tmp_path / "dask.sqlite")[1])


def test_a_dead_workers_chunk_is_resubmitted(tmp_path, cluster):
    sw = load_sweep(write_sweep(tmp_path, counts=(3, 2)))
    rep = run_sweep(sw, tmp_path / "d.sqlite", DaskExecutor(scheduler=cluster.scheduler_address),
                    evaluate=evaluate_dying_once, chunk_seconds=0.02)
    assert rep.executor.startswith("dask:tcp://127.0.0.1")
    assert (tmp_path / "died").exists()                                   # a worker process did die
    assert rep.counts == {"pending": 0, "running": 0, "done": 6, "failed": 0}
    run_sweep(sw, tmp_path / "l.sqlite", LocalExecutor(1))
    assert table(tmp_path / "d.sqlite") == table(tmp_path / "l.sqlite")
