"""Tests of studies.benchmarks.bench_timing: the path is the FANUC's and inside its limits, TOPP-RA
sees exactly rmtkit's geometric path, and the JSON report holds every figure (no timing asserted)."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
import studies.benchmarks.bench_timing as bench
from planning.timing import blend_path


def test_fanuc_path_is_smooth_and_inside_the_joint_limits():
    W = bench.fanuc_path()
    lim = kin.load_robot("fanuc_m16ib20").chain.limits
    assert W.shape == (bench.WAYPOINTS, 6)
    assert np.all(W >= lim[:, 0]) and np.all(W <= lim[:, 1])
    assert np.max(np.abs(np.diff(W, axis=0))) < 0.3          # consecutive waypoints close together


def test_toppra_sees_the_same_geometric_path():
    pytest.importorskip("toppra", reason="toppra (the `bench` extra) is not installed")
    bp = blend_path(bench.fanuc_path(), bench.BLEND)
    path = bench.ToppraPath(bp)
    s = np.linspace(0.0, bp.length, 57)
    for order in range(3):
        np.testing.assert_array_equal(path(s, order), bp.evaluate(s)[order])
    assert path(0.3, 1).shape == (6,) and path.dof == 6
    np.testing.assert_array_equal(path.path_interval, [0.0, bp.length])


def test_json_report_holds_every_figure(monkeypatch, capsys):
    monkeypatch.setattr(bench, "GRIDS", (31,))
    monkeypatch.setattr(bench, "QUICK_REPEATS", 1)
    assert bench.main(["--json", "--quick"]) == 0
    R = json.loads(capsys.readouterr().out)
    rec = R["grids"]["31"]
    assert rec["rmtkit"]["overshoot"] <= 1e-9 and rec["rmtkit"]["duration_s"] > 0
    assert rec["rmtkit_qp"]["duration_s"] == pytest.approx(rec["rmtkit"]["duration_s"], rel=5e-3)
    if R["environment"]["toppra"]:
        assert {"time_ratio", "duration_ratio", "targets"} <= set(rec)
        assert rec["duration_ratio"] == pytest.approx(rec["rmtkit"]["duration_s"] / rec["toppra"]["duration_s"])
    assert "bench_timing" in bench.format_report(R)
