"""studies/benchmarks/load.py: the foreign-CPU-share meter and the bounded busy process (no timing)."""
from __future__ import annotations

import os

import pytest

from studies.benchmarks.load import UNRELIABLE_SHARE, ForeignLoad, busy_process


def test_foreign_load_fields():
    with ForeignLoad() as load:
        sum(i * i for i in range(200_000))  # our own CPU time is not "foreign"
    d = load.as_dict()
    assert set(d) == {"foreign_cpu_share", "reliable", "loadavg_1min_before", "loadavg_1min_after"}
    if os.path.exists("/proc/stat"):
        assert d["foreign_cpu_share"] >= 0.0
        assert d["reliable"] == (d["foreign_cpu_share"] <= UNRELIABLE_SHARE)
    assert isinstance(d["reliable"], bool)


def test_busy_process_stops_by_itself():
    proc = busy_process(0.3)
    assert proc.wait(timeout=60) == 0  # exits on its own bound, with status 0


def test_busy_process_can_be_stopped_early():
    proc = busy_process(600)
    proc.terminate()
    assert proc.wait(timeout=60) != 0


@pytest.mark.parametrize("bound", [0, -1, 601, float("inf"), float("nan")])
def test_busy_process_bound_checked(bound):
    with pytest.raises(ValueError, match="allowed"):
        busy_process(bound)
