"""The driver with local worker processes: a design that raises is stored failed and the sweep
finishes; 1 and 2 workers give identical rows, each equal to a fresh in-process evaluation of the
design; resume never recomputes done rows; --retry-failed evaluates failed rows again."""
import pytest

from design.sweep import LocalExecutor, Store, load_sweep, make_job, read_sweep, run_sweep
from design.sweep.evaluate import evaluate_design, job_robot
from design.sweep.space import Design
from tests.design.sweep.helpers import evaluate_dying_once, evaluate_failing, write_sweep

SKIP = ("time_s", "worker", "id")


def table(db):
    return {r["key"]: {k: v for k, v in r.items() if k not in SKIP} for r in read_sweep(db)[1]}


def fresh(sweep, row):
    job = make_job(sweep)
    d = Design.make(row["architecture"], row["params"])
    return evaluate_design(job, job_robot(job, d.architecture), d)


def test_one_and_two_workers_give_identical_rows_equal_to_fresh_evaluations(tmp_path):
    sw = load_sweep(write_sweep(tmp_path, counts=(4, 4)))
    r1 = run_sweep(sw, tmp_path / "w1.sqlite", LocalExecutor(1))
    r2 = run_sweep(sw, tmp_path / "w2.sqlite", LocalExecutor(2))
    assert r1.counts == r2.counts == {"pending": 0, "running": 0, "done": 16, "failed": 0}
    t1, t2 = table(tmp_path / "w1.sqlite"), table(tmp_path / "w2.sqlite")
    assert t1 == t2
    for row in list(t1.values())[::5]:
        assert row["metrics"] == pytest.approx(fresh(sw, row), rel=0, abs=0)
    assert {r["worker"] for r in read_sweep(tmp_path / "w2.sqlite")[1]}.__len__() >= 1


def test_failing_designs_are_stored_and_retried(tmp_path):
    sw = load_sweep(write_sweep(tmp_path, counts=(4, 2)))       # A1 = 0.4 (2 designs) fails
    db = tmp_path / "f.sqlite"
    rep = run_sweep(sw, db, LocalExecutor(1), evaluate=evaluate_failing)
    assert rep.counts == {"pending": 0, "running": 0, "done": 6, "failed": 2} and rep.failed_now == 2
    failed = [r for r in read_sweep(db)[1] if r["status"] == "failed"]
    assert all(r["error"].startswith("ValueError: test failure for A1 = 0.4") for r in failed)
    assert all(r["params"]["A1"] == pytest.approx(0.4) and r["metrics"] is None for r in failed)
    # resume: nothing to do (failed rows stay failed without --retry-failed)
    again = run_sweep(sw, db, LocalExecutor(1), resume=True, evaluate=evaluate_failing)
    assert again.evaluated == 0 and again.counts["failed"] == 2
    retried = run_sweep(sw, db, LocalExecutor(1), resume=True, retry_failed=True, evaluate=evaluate_failing)
    assert retried.evaluated == 2 and retried.retried == 2
    assert [r["attempts"] for r in read_sweep(db)[1] if r["status"] == "failed"] == [2, 2]


def test_resume_extends_a_sweep_and_never_recomputes_done_rows(tmp_path):
    db = tmp_path / "r.sqlite"
    run_sweep(load_sweep(write_sweep(tmp_path, counts=(2, 2))), db, LocalExecutor(1))
    before = {r["key"]: r for r in read_sweep(db)[1]}
    rep = run_sweep(load_sweep(write_sweep(tmp_path, counts=(3, 2))), db, LocalExecutor(1), resume=True)
    after = {r["key"]: r for r in read_sweep(db)[1]}
    assert rep.added == 2 and rep.evaluated == 2 and len(after) == 6   # A1 ∈ {0.1, 0.25, 0.4}: 0.25 is new
    for k, r in before.items():
        assert after[k]["attempts"] == 1 and after[k]["time_s"] == r["time_s"] and after[k]["worker"] == r["worker"]
    with Store(db, {"fingerprint": read_sweep(db)[0]["fingerprint"]}, resume=True) as s:
        assert s.counts()["done"] == 6


def test_a_dead_worker_process_loses_only_its_chunk(tmp_path):
    sw = load_sweep(write_sweep(tmp_path, counts=(3, 2)))
    rep = run_sweep(sw, tmp_path / "d.sqlite", LocalExecutor(1), evaluate=evaluate_dying_once)
    assert (tmp_path / "died").exists()                      # a worker process did die
    assert rep.counts == {"pending": 0, "running": 0, "done": 6, "failed": 0}
    for r in read_sweep(tmp_path / "d.sqlite")[1]:
        assert r["metrics"] == fresh(sw, r)
