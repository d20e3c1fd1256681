"""planning.ompl.goals.goal_from_pose on the UR5e shelf cell of issue 29: the candidates are every
closed-form branch with all its whole-turn copies; the goal is the valid one nearest the start among
those on the start's side of every window — checked against an independent enumeration (numpy FK,
the windows' own membership, the world's clearance, the signs of sin q3 and sin q5 that the elbow and
wrist slabs fix); poses in the cell frame; no valid goal named by the best candidate's reason."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.transforms import make_transform, rpy_to_matrix
from planning.certify import free_cells
from planning.collision import collision_world
from planning.ompl.goals import REASONS, GoalPoseError, goal_from_pose
from planning.ompl.planner import plan
from planning.ompl.validity import JointSpaceChecker
from planning.windows import build_windows
from tests.dh_numpy import fk_numpy

CELL = "studies/cells/ur5e_shelf_cell.toml"
HOME_DEG = [0, -90, 90, -90, -90, 0]


@pytest.fixture(scope="module")
def setup():
    robot = kin.load_robot("ur5e")
    ws = build_windows(robot, margin=math.radians(5))
    world = collision_world(robot, CELL)
    checker = JointSpaceChecker(robot, ws, None, (), None, world)
    cells = free_cells(robot.chain.lower, robot.chain.upper, ws)
    return robot, ws, world, checker, cells


def _cell_pose(x, y, z, r, p, yw):
    return make_transform(rpy_to_matrix(np.radians([r, p, yw])), np.array([x, y, z]))


def _independent_candidates(robot, pose_base):
    """Every configuration in the limits reaching the pose: the branches (one per 8 sign choices found by
    the numeric IK from a grid of starts would be slow; the closed form's branches are re-verified by the
    numpy FK here) and every ±360° copy of each joint, by plain enumeration."""
    from kin.ik.analytic import analytic_ik
    B = analytic_ik(robot, pose_base)
    out = []
    for b in B:
        assert np.abs(fk_numpy(robot.chain, b) - pose_base).max() < 1e-9
        choices = [[v + k * 2 * math.pi for k in (-2, -1, 0, 1, 2)
                    if -2 * math.pi - 1e-9 <= v + k * 2 * math.pi <= 2 * math.pi + 1e-9] for v in b]
        grids = np.meshgrid(*choices, indexing="ij")
        out.append(np.stack([g.ravel() for g in grids], axis=1))
    return np.concatenate(out)


def test_pick_a_goal_is_the_nearest_valid_candidate_on_the_start_side(setup):
    robot, ws, world, checker, cells = setup
    start = robot.chain.to_si(HOME_DEG)
    pose = np.linalg.inv(world.base) @ _cell_pose(0.45, -0.20, 0.95, 180, 0, 0)
    q, info = goal_from_pose(robot, pose, start, checker, cells, 0, frame="cell frame")
    assert np.abs(fk_numpy(robot.chain, q) - pose).max() < 1e-9
    Q = _independent_candidates(robot, pose)
    assert info["candidates"] == len(Q) and info["source"] == "closed form"
    ok = (ws.which(Q) < 0) & (world.clearance(Q) > 0)
    # the elbow and wrist slabs (sin q3 = 0, sin q5 = 0) cannot be crossed: the signs must match the start's
    sgn = np.sign(np.sin(Q))
    side = (sgn[:, 2] == np.sign(np.sin(start[2]))) & (sgn[:, 4] == np.sign(np.sin(start[4])))
    good = Q[ok & side]
    assert info["valid"] == ok.sum() and info["refused"]["in collision"] == (ws.which(Q) < 0).sum() - ok.sum()
    d = np.linalg.norm(good - start, axis=1)
    assert len(good) >= 1 and abs(np.linalg.norm(q - start) - d.min()) < 1e-9
    assert np.abs(q - start).max() <= math.pi              # no joint turns more than half a turn
    assert sum(info["refused"].values()) + info["in_start_cell"] == len(Q)
    assert "in the start's free cell; the nearest such one chosen" in info["why"]


def test_place_low_on_capsules_alone_has_no_goal_on_the_start_side_and_says_why():
    """With the UR5e's capsules alone (its hulls dropped), from pick A the place-low pose's only branches with
    sin q3 > 0 and sin q5 < 0 (the start's sides of the elbow and wrist slabs) collide: the forearm with
    wrist 2, the upper arm with the table — the query is answered at once, saying why."""
    from dataclasses import replace
    full = kin.load_robot("ur5e")
    robot = kin.Robot(replace(full.chain, geometry=replace(full.chain.geometry, hulls=())))
    ws = build_windows(robot, margin=math.radians(5))
    world = collision_world(robot, CELL)
    start = robot.chain.to_si([-39.668, -76.876, 121.77, -134.89, -90, -129.67])
    pose = np.linalg.inv(world.base) @ _cell_pose(0.10, 0.40, 1.08, -90, 0, 0)
    Q = _independent_candidates(robot, pose)
    side = (np.sin(Q[:, 2]) > 0) & (np.sin(Q[:, 4]) < 0)
    assert side.any() and (world.clearance(Q[side]) < 0).all()          # independent: all collide
    res = plan(robot, start, None, ws, goal_pose=_cell_pose(0.10, 0.40, 1.08, -90, 0, 0), world=world,
               goal_frame="cell", time_limit=1.0)
    assert not res.success and res.separation is not None and res.separation.windows[0].startswith("elbow")
    assert res.goal_branch["in_start_cell"] == 0
    assert "in collision (link 3 (elbow) against link 5 (wrist2)" in res.goal_branch["start_cell_reason"]
    assert "no joint path exists" in res.status and "in collision" in res.status


def test_place_low_with_the_hulls_has_a_goal_on_the_start_side(setup):
    """The bundled UR5e's hulls of its maker's meshes clear one of those branches (the capsules stand out of
    the forearm and wrist 2 by more than the 12 mm between them): the goal is in the start's free cell."""
    robot, ws, world, checker, cells = setup
    start = robot.chain.to_si([-39.668, -76.876, 121.77, -134.89, -90, -129.67])
    pose = np.linalg.inv(world.base) @ _cell_pose(0.10, 0.40, 1.08, -90, 0, 0)
    q, info = goal_from_pose(robot, pose, start, checker, cells, 0)
    assert info["in_start_cell"] > 0 and cells.same_cell(start, q)
    assert np.sin(q[2]) > 0 and np.sin(q[4]) < 0
    assert world.model.clear_one(q) < 0 < world.clearance(q)           # the capsules touch, the hulls do not
    assert np.abs(fk_numpy(robot.chain, q) - pose).max() < 1e-9


def test_no_valid_goal_names_the_reason_and_the_frame(setup):
    robot, ws, world, checker, cells = setup
    start = robot.chain.to_si(HOME_DEG)
    far = _cell_pose(3.0, 0.0, 1.0, 180, 0, 0)
    res = plan(robot, start, None, ws, goal_pose=far, world=world, goal_frame="cell", time_limit=1.0)
    assert not res.success and res.goal is None and res.goal_branch["reason"] == "out of reach"
    assert "goal pose (cell frame of 'ur5e shelf cell')" in res.status and "out of reach" in res.status
    # a pose inside the table: every candidate collides, the nearest with the table or the robot itself
    sunk = _cell_pose(0.45, -0.20, 0.70, 180, 0, 0)
    res = plan(robot, start, None, ws, goal_pose=sunk, world=world, goal_frame="cell", time_limit=1.0)
    assert not res.success and res.goal_branch["reason"] == "in collision"
    assert "in collision (" in res.status and "obstacle 'table'" in res.status
    assert res.goal_branch["refused"]["in collision"] == res.goal_branch["candidates"]
    with pytest.raises(Exception, match="cell frame needs a world"):
        plan(robot, start, None, ws, goal_pose=sunk, goal_frame="cell")


def test_candidates_in_a_window_are_counted(setup):
    """A pose reached with q5 = 0: those branches (and their copies) are in the wrist window, counted as such;
    the chosen goal is in none."""
    robot, ws, world, checker, cells = setup
    pose = fk_numpy(robot.chain, robot.chain.to_si([0, -90, 90, -90, 0, 0]))
    g, info = goal_from_pose(robot, pose, robot.chain.to_si(HOME_DEG), JointSpaceChecker(robot, ws), cells, 0)
    Q = _independent_candidates(robot, pose)
    inside = ws.which(Q) >= 0
    assert (inside[np.abs(np.sin(Q[:, 4])) < 1e-9]).all()
    assert info["refused"]["in a window"] == inside.sum() > 0 and ws.which(g[None])[0] < 0
    assert set(info["refused"]) == set(REASONS)


def test_a_window_is_named_when_it_refuses_the_best_candidate():
    """With the wrist window as wide as ±90° every branch of a pose lies in it: the error names it."""
    robot = kin.load_robot("ur5e")
    ws = build_windows(robot, margin=math.radians(89))
    cells = free_cells(robot.chain.lower, robot.chain.upper, ws)
    pose = fk_numpy(robot.chain, robot.chain.to_si([0, -90, 90, -90, 20, 0]))
    start = robot.chain.to_si([0, -60, 150, -90, -90, 0])
    with pytest.raises(GoalPoseError, match=r"goal pose \(base frame\): no valid configuration .* in a window \(") as e:
        goal_from_pose(robot, pose, start, JointSpaceChecker(robot, ws), cells, 0)
    assert e.value.reason == "in a window"
