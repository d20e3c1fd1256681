"""The scara_cycle study in quick mode, against values computed here: the sweep's best feasible design
re-read from its SQLite store, and a lower bound of the best design's cycle time from the SCARA's
closed-form IK (elbow branches) and the rest-to-rest time of each joint's travel.

The task (studies/tasks/scara_cycle.toml): pick (180, −160, −150) mm, place (380, 70, −150) mm, 25 mm
lifts; J1, J2 at 300, 500 deg/s and 1500, 3000 deg/s², J3 at 1000 mm/s, 10000 mm/s²; torque limits
32 N·m, 15 N·m, 100 N.
"""
from __future__ import annotations

import json
import math
import sqlite3

import numpy as np
import pytest

from tests.studies.bundled.common import assert_report_holds, assert_report_renders, quick_run

PICK, PLACE = (180.0, -160.0), (380.0, 70.0)                    # mm
V = np.radians([300.0, 500.0])
A = np.radians([1500.0, 3000.0])
LIM1, LIM2 = 2.22, 2.53
TAU = np.array([32.0, 15.0, 100.0])


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    q = quick_run("scara_cycle", tmp_path_factory)
    return q.copied, q.results, q.report.parent


def _branches(l1: float, l2: float, x: float, y: float) -> list[np.ndarray]:
    c2 = (x * x + y * y - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    out = []
    for q2 in (math.acos(c2), -math.acos(c2)):
        q1 = math.atan2(y, x) - math.atan2(l2 * math.sin(q2), l1 + l2 * math.cos(q2))
        if abs(q1) <= LIM1 and abs(q2) <= LIM2:
            out.append(np.array([q1, q2]))
    return out


def _trap(d: np.ndarray) -> float:
    d = np.abs(d)
    return float(np.max(np.where(d <= V * V / A, 2 * np.sqrt(d / A), d / V + V / A)))


def test_the_study_passed(run):
    copied, results, _ = run
    assert copied.returncode == 0 and results["ok"] is True and results["quick"] is True
    assert [f["ok"] for f in results["findings"]] == [True, True, True]


def test_best_design_meets_every_limit_and_beats_the_lower_bound(run):
    _, results, _ = run
    b = results["best"]
    assert b["ok"] and b["within_torque_limits"]
    peaks = np.array([b["peak_torque"][k] for k in ("J1", "J2", "J3")])
    assert np.all(peaks <= TAU * (1 + 1e-6))
    # any rest-to-rest move takes at least the trapezoid time of its largest joint travel (the best branch
    # pair); stopping at both lift corners instead of blending them adds the 25 mm lifts' own rest-to-rest
    # times, 2·√(0.025/10) = 0.1 s each, four per cycle: an upper bound (1e-3: the timing's grid)
    travel = min(_trap(p - q) for p in _branches(b["A1_mm"], b["A2_mm"], *PICK)
                 for q in _branches(b["A1_mm"], b["A2_mm"], *PLACE))
    assert 2 * travel <= b["cycle_time_s"] <= (2 * travel + 0.4) * (1 + 1e-3), (travel, b["cycle_time_s"])
    assert results["check"]["max_diff"] < 1e-9


def test_sweep_store_best_is_the_fastest_feasible_row(run):
    _, results, d = run
    con = sqlite3.connect(d / "sweep.sqlite")
    rows = [(json.loads(p), json.loads(m)) for p, m in con.execute("SELECT params, metrics FROM designs")]
    con.close()
    feas = [(m["cycle_time"], dict(p)) for p, m in rows if m["feasible"]]
    assert feas and all(m["torque_ratio"] <= 1 + 1e-6 for _, m in rows if m["feasible"])
    t, p = min(feas, key=lambda x: x[0])
    best = results["sweep"]["best"]
    assert t == pytest.approx(best["cycle_time_s"]) and 1e3 * p["A1"] == pytest.approx(best["A1_mm"])
    # the limit binds: the fastest design that reaches both points is over a torque limit
    reached = [m for _, m in rows if m["cycle_time"] is not None]
    assert min(reached, key=lambda m: m["cycle_time"])["torque_ratio"] > 1


def test_report_holds_the_numbers(run):
    _, results, d = run
    b = results["best"]
    assert_report_holds(d / "report.html", results, (f"{b['cycle_time_s']:.3f} s", "Independent check"),
                        ("maps.png", "cycle.png", "cycle_pareto.png"))


def test_report_renders_in_a_browser(run, report_browser):
    _, results, d = run
    assert_report_renders(report_browser, d / "report.html", results)


def test_nominal_design_timed_under_its_torque_limits(run):
    """torque = "limit": the nominal design, over J1's limit when timed under speed and acceleration
    only, holds every motor limit once timed under them too, and is no faster for it."""
    _, results, _ = run
    nom, lim = results["nominal"], results["nominal_torque_limited"]
    assert nom["torque_ratio"] > 1 and lim["torque_ratio"] <= 1 + 1e-6 and lim["within_torque_limits"]
    assert lim["cycle_time_s"] >= nom["cycle_time_s"] * (1 - 1e-9)

