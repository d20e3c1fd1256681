"""Tests of studies.benchmarks.bench_waypoints: the report holds every figure, rmtkit's spline holds
its limits on the dense samples and beats its own blends on the bench path (no timing asserted)."""
from __future__ import annotations

import json

import pytest

import studies.benchmarks.bench_waypoints as bench


def test_json_report_holds_every_figure(monkeypatch, capsys):
    monkeypatch.setattr(bench, "PATHS", {"bench": (0.3, 1.5)})
    monkeypatch.setattr(bench, "QUICK_REPEATS", 1)
    monkeypatch.setattr(bench, "DENSE", 4000)
    assert bench.main(["--json", "--quick"]) == 0
    R = json.loads(capsys.readouterr().out)
    rec = R["paths"]["bench"]
    for shape in ("spline", "blend"):
        assert rec[shape]["velocity_ratio"] <= 1 + 1e-9 and rec[shape]["acceleration_ratio"] <= 1 + 1e-9
    assert rec["spline"]["duration_s"] < rec["blend"]["duration_s"]
    if R["environment"]["toppra"]:
        t = rec["toppra"]
        assert t["duration_holding_limits_s"] >= t["duration_s"]
        assert rec["duration_ratio"] == pytest.approx(rec["spline"]["duration_s"] / t["duration_s"])
        assert rec["duration_ratio"] <= 1.0          # the target on the bench path
    assert "bench_waypoints" in bench.format_report(R)
