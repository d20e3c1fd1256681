"""The budgeted worker (kin.singular.budget): answers, time-outs, memory caps, failures."""
from __future__ import annotations

import os
import time

import pytest

from kin.singular.budget import BudgetError, run_with_budget


def _answer(x):
    return {"twice": 2 * x}


def _sleep_and_report(path):
    with open(path, "w") as fh:
        fh.write(str(os.getpid()))
    time.sleep(60)
    return 1


def _allocate(n_bytes):
    block = bytearray(n_bytes)
    return len(block)


def _fail():
    raise ZeroDivisionError("on purpose")


def test_answer_comes_back_as_data():
    res = run_with_budget(_answer, (21,), timeout=30)
    assert res.status == "done" and res.value == {"twice": 42}


def test_timeout_kills_the_worker(tmp_path):
    pidfile = tmp_path / "pid"
    res = run_with_budget(_sleep_and_report, (str(pidfile),), timeout=1.0)
    assert res.status == "timeout" and res.value is None
    pid = int(pidfile.read_text())
    with pytest.raises(ProcessLookupError):      # killed and reaped: no such process any more
        os.kill(pid, 0)


def test_memory_cap_stops_a_large_allocation():
    res = run_with_budget(_allocate, (4 << 30,), timeout=30, memory=64 << 20)
    assert res.status == "memory"
    assert run_with_budget(_allocate, (1 << 20,), timeout=30, memory=256 << 20).value == 1 << 20


def test_worker_failure_is_reported():
    res = run_with_budget(_fail, (), timeout=30)
    assert res.status == "error" and "ZeroDivisionError" in res.detail


@pytest.mark.parametrize("timeout", [-1, float("nan"), float("inf"), "3", True, 1e9])
def test_bad_timeout_is_refused(timeout):
    with pytest.raises(BudgetError, match="exact_timeout"):
        run_with_budget(_answer, (1,), timeout=timeout)


def test_zero_timeout_does_not_start_a_worker():
    assert run_with_budget(_answer, (1,), timeout=0).status == "timeout"
