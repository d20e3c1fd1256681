"""Restarts of the tree planners: a run that checks more motions than its budget starts again from a new
seed with twice the budget.  The budget counts motions, not seconds, so a seed gives the same path
every time; the path is still proven, and the dense check (every 0.1°, no proofs) agrees."""
from __future__ import annotations

from importlib.resources import files

import numpy as np
import pytest

import kin
import planning.ompl.planner as planner_module
from planning.collision import collision_world
from planning.motion import available
from planning.ompl import plan
from planning.ompl.validity import JointSpaceChecker
from planning.validate import check_path

pytestmark = pytest.mark.skipif(not available(), reason="restarts count the native checker's motions")

CAGE = files("studies") / "benchmarks" / "scenes" / "cage.toml"


def _blocked_pair(robot, world):
    """A valid start and a goal joined to it by a chain of proven motions (so a path exists), whose
    straight line collides."""
    chk = JointSpaceChecker(robot, world=world)
    rng = np.random.default_rng(11)
    lo, hi = robot.chain.lower, robot.chain.upper
    for start in robot.random_configurations(200, seed=11):
        if not chk.state_valid(list(start)):
            continue
        q = start
        for _ in range(300):                      # a random walk of proven steps
            step = np.clip(q + rng.normal(0.0, 0.25, robot.n), lo, hi)
            if chk.state_valid(list(step)) and chk.motion_valid(q, step):
                q = step
                if not chk.motion_valid(start, q):
                    return start, q
    raise AssertionError("no blocked, connected pair found")


def test_restarts_follow_the_motion_budget_and_keep_the_proofs(monkeypatch):
    robot = kin.load_robot("ur5e")
    world = collision_world(robot, str(CAGE))
    start, goal = _blocked_pair(robot, world)
    monkeypatch.setattr(planner_module, "RESTART_CHECKS", 2)       # every run but a late one is cut short
    a = plan(robot, start, goal, world=world, planner="RRTConnect", time_limit=20, seed=5)
    b = plan(robot, start, goal, world=world, planner="RRTConnect", time_limit=20, seed=5)
    assert a.success and a.proven, a.status
    assert "runs: a run restarts from a new seed after 2·2^k motion checks" in a.status
    np.testing.assert_array_equal(a.path, b.path)                  # the budget is in motions, not time
    np.testing.assert_array_equal(a.path[0], start)
    np.testing.assert_array_equal(a.path[-1], goal)
    dense = check_path(robot, a.path, world=world, dense=True)
    assert dense.valid and dense.min_clearance > 0, dense.first_violation


def test_without_restarts_the_seed_alone_decides(monkeypatch):
    robot = kin.load_robot("ur5e")
    world = collision_world(robot, str(CAGE))
    start, goal = _blocked_pair(robot, world)
    monkeypatch.setattr(planner_module, "RESTART_CHECKS", 10**9)
    r = plan(robot, start, goal, world=world, planner="RRTConnect", time_limit=20, seed=5)
    assert r.success and r.proven and "runs" not in r.status
