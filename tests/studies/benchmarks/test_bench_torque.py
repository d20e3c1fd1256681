"""Tests of studies.benchmarks.bench_torque: the JSON report holds every figure, rmtkit holds its torque
limits between grid points, and the uniform time scale that makes a trajectory hold its limits is
exact on a case worked by hand (no timing asserted)."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
import studies.benchmarks.bench_torque as bench


def test_json_report_holds_every_figure(monkeypatch, capsys):
    monkeypatch.setattr(bench, "GRIDS", (61,))
    monkeypatch.setattr(bench, "QUICK_REPEATS", 1)
    assert bench.main(["--json", "--quick"]) == 0
    R = json.loads(capsys.readouterr().out)
    r = R["grids"]["61"]["rmtkit"]
    assert r["torque_ratio"] <= 1 + 1e-6 and r["overshoot"] <= 1e-9 and r["duration_s"] > 0
    if "toppra" in R["grids"]["61"]:
        t = R["grids"]["61"]["toppra"]
        assert t["duration_holding_limits_s"] >= t["duration_s"]
    assert "bench_torque" in bench.format_report(R)


def test_slowed_to_hold_is_the_exact_scale():
    """At rest nothing scales (f = 1 when the gravity torque holds); speeds at 1.21 × v_max need
    f = 1.21, accelerations at 1.21 × A_MAX need f = 1.1."""
    robot = kin.load_robot(bench.ROBOT)
    v = np.array([j.max_velocity for j in robot.chain.joints])
    q = np.tile(robot.chain.limits.mean(axis=1), (3, 1))
    z = np.zeros_like(q)
    assert bench.slowed_to_hold(robot, q, z, z, v) == 1.0
    qd = z.copy()
    qd[1, 2] = 1.21 * v[2]
    assert bench.slowed_to_hold(robot, q, qd, z, v) == pytest.approx(1.21, rel=1e-9)
    qdd = z.copy()
    qdd[2, 6] = 1.21 * bench.A_MAX[6]
    f = bench.slowed_to_hold(robot, q, z, qdd, v)
    tau = robot.inverse_dynamics(q, z, qdd / f ** 2)
    assert f >= 1.1 * (1 - 1e-9) and np.max(np.abs(tau) / bench.TAU_MAX) <= 1 + 1e-9
