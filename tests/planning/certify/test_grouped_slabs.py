"""planning.certify.cells: a single-joint slab separates even when it shares its joint's group with other
windows (UR's elbow window q3 ∈ [175°, 185°] + 360°k inside the (q2, q3, q4) shoulder group, issue 29
finding 2) — decided exactly before any grid and at once by plan(); the grid's edges follow the slab
bounds, so the slab's cells are blocked in the group's grid."""
from __future__ import annotations

import math
import time

import numpy as np
import pytest

import kin
from planning.certify.cells import FreeCells
from planning.ompl.planner import plan
from planning.windows import build_windows


@pytest.fixture(scope="module")
def ur5e():
    robot = kin.load_robot("ur5e")
    ws = build_windows(robot, margin=math.radians(5))
    return robot, ws


def test_the_elbow_slab_shares_the_shoulder_group(ur5e):
    robot, ws = ur5e
    fc = FreeCells(robot.chain.lower, robot.chain.upper, ws)
    groups = {js: sorted(w.name.split(":")[0] for w in g) for js, g in fc.groups}
    assert groups[(1, 2, 3)] == ["elbow", "shoulder"]


def test_the_separated_query_of_finding_2_is_answered_at_once(ur5e):
    robot, ws = ur5e
    c = robot.chain
    start = c.to_si([0, -90, 121.8, -90, -90, 0])
    goal = c.to_si([276.5, -79.9, 237.2, 202.7, -83.5, -360])
    assert (ws.which(np.array([start, goal])) < 0).all()             # both valid
    # independent: q3 = 180° (in the elbow window, sin q3 = 0) lies between 121.8° and 237.2°
    assert start[2] < math.pi < goal[2]
    t = time.perf_counter()
    res = plan(robot, start, goal, ws, time_limit=2.0)
    dt = time.perf_counter() - t
    print(f"separated query answered in {dt * 1e3:.1f} ms")
    assert not res.success and res.separation is not None
    assert res.separation.kind == "slab" and res.separation.joints == (3,)
    assert res.separation.windows[0].startswith("elbow") and "elbow window q3" in res.status
    assert "no joint path exists" in res.status
    assert dt < 0.5                                                  # the planner (2 s) never ran


def test_slab_cells_are_blocked_in_the_group_grid(ur5e):
    robot, ws = ur5e
    fc = FreeCells(robot.chain.lower, robot.chain.upper, ws)
    labels, edges, free, used = fc._grid((1, 2, 3), [w for js, g in fc.groups if js == (1, 2, 3) for w in g])
    e3 = edges[1]
    for lo_deg in (-185, 175):                                        # the slab's bounds are cell edges
        for v in (math.radians(lo_deg), math.radians(lo_deg + 10)):
            assert np.abs(e3 - v).min() < 1e-12
    inside = (e3[:-1] >= math.radians(175) - 1e-12) & (e3[1:] <= math.radians(185) + 1e-12)
    assert inside.any() and not free[:, inside, :].any()
    outside = (e3[1:] <= math.radians(170)) & (e3[:-1] >= math.radians(10))
    assert free[:, outside, :].any()


def test_same_side_of_every_slab_gives_no_slab_verdict(ur5e):
    robot, ws = ur5e
    fc = FreeCells(robot.chain.lower, robot.chain.upper, ws)
    a = robot.chain.to_si([0, -90, 121.8, -90, -90, 0])
    b = robot.chain.to_si([30, -60, 100, -80, -60, 40])
    sep = fc.separation(a, b)
    assert sep is None or sep.kind != "slab"
