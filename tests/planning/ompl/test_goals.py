"""planning.ompl.goals: wrist twins reach the same pose (checked by FK), and a pose goal whose
given configuration is across the wrist window is planned to a branch on the start's side."""
import numpy as np
import pytest

import kin
from planning.ompl import plan, wrist_twins
from planning.validate import check_path
from planning.windows import build_windows


@pytest.mark.parametrize("name", ["fanuc_m16ib20", "puma560", "abb_irb120"])
def test_wrist_twins_reach_the_same_pose(name):
    robot = kin.load_robot(name)
    Q = robot.random_configurations(50, seed=2)
    found = 0
    for q in Q:
        T = robot.fk(q)
        for f in wrist_twins(robot, q, T):
            found += 1
            assert np.abs(robot.fk(f) - T).max() < 1e-9 and robot.within_limits(f)
            assert f[4] == pytest.approx(-q[4]) and f[:3] == pytest.approx(q[:3])
    assert found >= 10


def test_no_twins_for_a_chain_without_a_wrist():
    robot = kin.load_robot("scara_rrp")
    q = robot.random_configurations(1, seed=0)[0]
    assert wrist_twins(robot, q, robot.fk(q)) == []


def test_pose_goal_across_the_wrist_window_uses_the_flipped_wrist():
    robot = kin.load_robot("fanuc_m16ib20")
    ws = build_windows(robot, margin=0.05)
    start = np.array([0.0, -0.3, 0.4, 0.2, -0.6, 0.0])
    far = np.array([0.4, -0.2, 0.3, -0.2, 0.8, 0.1])      # q5 > 0: across the wrist window
    pose = robot.fk(far)
    res = plan(robot, start, goal_pose=pose, windows=ws, time_limit=5.0, seed=0)
    assert res.success and res.proven
    assert res.path[-1][4] < 0                            # the goal branch on the start's side
    assert np.abs(robot.fk(res.path[-1]) - pose).max() < 1e-9
    assert res.goal_branch["in_start_cell"] >= 1 and res.goal_branch["candidates"] >= 2
    assert check_path(robot, res.path, ws).valid
